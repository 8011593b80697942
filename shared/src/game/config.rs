//! The platformer's tunable constants: every player rule reads
//! [`PlayerConfig`]; [`GameConfig`] adds the simulation knobs.
//!
//! Units: positions and sizes in units (256 per pixel), speeds in units per
//! tick, accelerations in units per tick per tick, durations in ticks (60 per
//! second). `docs/PLATFORMER.md` explains each rule and its default.

use glam::IVec2;
use serde::{Deserialize, Serialize};

use crate::fixed::{check_extent, MAX_SPEED};
use crate::world::SimConfig;

/// What a player keeps of a platform's velocity when it leaves it (walks or
/// jumps off).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum CarryMode {
    /// The platform's whole velocity is added to the player's.
    #[default]
    Add,
    /// Only an upward platform velocity is added (a rising platform gives a
    /// higher jump; sideways and downward motion is not kept).
    AddUpOnly,
    /// Nothing is added.
    None,
}

/// Every player constant (also used by walkers for gravity).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct PlayerConfig {
    /// Half extents of the player's box (default 6 x 8 px: a 12 x 16 px box).
    pub half: IVec2,
    /// Horizontal speed gained per tick on the ground while a direction is held.
    pub run_accel: i32,
    /// Horizontal speed lost per tick on the ground while no direction is held
    /// (also added to `run_accel` when reversing, and used to slow down to
    /// `max_run_speed` when faster).
    pub run_brake: i32,
    /// `run_accel` in the air.
    pub air_accel: i32,
    /// `run_brake` in the air.
    pub air_brake: i32,
    /// Largest horizontal speed a held direction reaches.
    pub max_run_speed: i32,
    /// Upward speed a jump starts with.
    pub jump_speed: i32,
    /// Gravity while rising with jump held, for at most `jump_hold_ticks`.
    pub jump_gravity: i32,
    /// Gravity otherwise: falling, after the apex, after releasing jump or
    /// once the hold time is over (the stronger one).
    pub gravity: i32,
    /// Largest downward speed gravity gives.
    pub max_fall_speed: i32,
    /// How long holding jump keeps the lighter `jump_gravity`.
    pub jump_hold_ticks: u8,
    /// Ticks after walking off the ground during which a jump still works.
    pub coyote_ticks: u8,
    /// A jump pressed up to this many ticks before landing fires on landing.
    pub jump_buffer_ticks: u8,
    /// Ticks during which a player that pressed down + jump on a one-way
    /// surface ignores one-way tiles and platforms.
    pub drop_through_ticks: u8,
    /// Largest drop the player is snapped down to the ground by after a tick
    /// in which it was grounded and walked off (down a slope): at least
    /// `max_run_speed` for 45 degree slopes.
    pub snap_distance: i32,
    /// Upward speed after stomping an enemy (`jump_speed` and a new jump
    /// hold when jump is held).
    pub stomp_bounce_speed: i32,
    /// How far below an enemy's top (at the start of the tick) the player's
    /// bottom may have been and still count as landing on it.
    pub stomp_tolerance: i32,
    /// What leaving a platform keeps of its velocity.
    pub carry_mode: CarryMode,
}

impl Default for PlayerConfig {
    fn default() -> Self {
        Self {
            half: IVec2::new(6 * 256, 8 * 256),
            run_accel: 40,
            run_brake: 64,
            air_accel: 32,
            air_brake: 16,
            max_run_speed: 640,
            jump_speed: 1280,
            jump_gravity: 44,
            gravity: 96,
            max_fall_speed: 1536,
            jump_hold_ticks: 30,
            coyote_ticks: 6,
            jump_buffer_ticks: 6,
            drop_through_ticks: 10,
            snap_distance: 1024,
            stomp_bounce_speed: 1024,
            stomp_tolerance: 1024,
            carry_mode: CarryMode::Add,
        }
    }
}

impl PlayerConfig {
    /// Checks every value: sizes positive within the extent bound, speeds and
    /// accelerations in `[0, MAX_SPEED / 4]`, `max_run_speed`, `jump_speed`
    /// and `max_fall_speed` positive, tick counts at most 254.
    pub fn validate(&self) -> Result<(), String> {
        for (what, v) in [("half.x", self.half.x), ("half.y", self.half.y)] {
            if v <= 0 {
                return Err(format!("player {what} = {v} must be positive"));
            }
            check_extent("player half extent", v as i64).map_err(|e| e.to_string())?;
        }
        let limit = MAX_SPEED / 4;
        for (what, v, min) in [
            ("run_accel", self.run_accel, 0),
            ("run_brake", self.run_brake, 0),
            ("air_accel", self.air_accel, 0),
            ("air_brake", self.air_brake, 0),
            ("max_run_speed", self.max_run_speed, 1),
            ("jump_speed", self.jump_speed, 1),
            ("jump_gravity", self.jump_gravity, 0),
            ("gravity", self.gravity, 0),
            ("max_fall_speed", self.max_fall_speed, 1),
            ("snap_distance", self.snap_distance, 0),
            ("stomp_bounce_speed", self.stomp_bounce_speed, 0),
            ("stomp_tolerance", self.stomp_tolerance, 0),
        ] {
            if v < min || v > limit {
                return Err(format!("player {what} = {v} is not in [{min}, {limit}]"));
            }
        }
        for (what, v) in [
            ("jump_hold_ticks", self.jump_hold_ticks),
            ("coyote_ticks", self.coyote_ticks),
            ("jump_buffer_ticks", self.jump_buffer_ticks),
            ("drop_through_ticks", self.drop_through_ticks),
        ] {
            if v == u8::MAX {
                return Err(format!("player {what} = {v} must be at most 254"));
            }
        }
        Ok(())
    }
}

/// Everything [`super::Game::with_config`] can tune.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct GameConfig {
    /// The player (and walker gravity) constants.
    pub player: PlayerConfig,
    /// The simulation knobs: substeps and restitution passes (these change
    /// results), broad phase, pipeline and detection threads (these never
    /// do).
    pub sim: SimConfig,
}
