//! The platformer's tunable constants: every player rule reads
//! [`PlayerConfig`]; [`GameConfig`] adds the simulation knobs.
//!
//! Units: positions and sizes in units (256 per pixel), speeds in units per
//! tick, accelerations in units per tick per tick, durations in ticks (60 per
//! second). `docs/PLATFORMER.md` explains each rule and its default.

use glam::IVec2;
use serde::{Deserialize, Serialize};

use crate::fixed::{check_extent, MAX_SPEED};
use crate::level::{Level, PlayerScale, MAX_PLAYER_SCALE, MIN_PLAYER_SCALE};
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

/// How faithfully the player's body is modelled: the shape-fidelity knob.
///
/// Both shapes span the same box (`half`), so every rule that reads the
/// player's extents (stomps, pickups, snapping, rendering) is unchanged;
/// only what the world collides differs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum PlayerShape {
    /// One box of half extents `half` (the default): cheapest, and its
    /// square corners catch on ledge corners and tile seams.
    #[default]
    Box,
    /// Three boxes on one body: a torso of full width, [`FOOT_HEIGHT`]
    /// shorter at both ends, and a feet box and a head box of that height,
    /// each [`FOOT_INSET`] narrower on both sides, at the bottom and top.
    /// The corners are chamfered: a jump that clips a ledge corner with
    /// the head, or a walk off an edge, catches less. Three colliders cost
    /// about three times the player's detection work. (All boxes: the
    /// tilemap only collides box colliders.)
    BoxFeetHead,
}

/// Height of the feet and head boxes of [`PlayerShape::BoxFeetHead`]: 2 px.
pub const FOOT_HEIGHT: i32 = 2 * 256;

/// How much narrower, on each side, the feet and head boxes of
/// [`PlayerShape::BoxFeetHead`] are than the torso: 2 px.
pub const FOOT_INSET: i32 = 2 * 256;

impl PlayerShape {
    /// The boxes of a player of half extents `half`: `(half extents, offset
    /// from the body)` each, torso first. For `BoxFeetHead` the box must be
    /// more than `FOOT_HEIGHT` tall and `FOOT_INSET` wide (per half);
    /// smaller players fall back to one box.
    pub fn boxes(self, half: IVec2) -> ([(IVec2, IVec2); 3], usize) {
        let one = [(half, IVec2::ZERO); 3];
        match self {
            PlayerShape::Box => (one, 1),
            PlayerShape::BoxFeetHead if half.x <= FOOT_INSET || half.y <= FOOT_HEIGHT => (one, 1),
            PlayerShape::BoxFeetHead => {
                let end = IVec2::new(half.x - FOOT_INSET, FOOT_HEIGHT / 2);
                let y = half.y - FOOT_HEIGHT / 2;
                (
                    [
                        (IVec2::new(half.x, half.y - FOOT_HEIGHT), IVec2::ZERO),
                        (end, IVec2::new(0, y)),
                        (end, IVec2::new(0, -y)),
                    ],
                    3,
                )
            }
        }
    }
}

/// Largest [`PlayerConfig::max_walkable_slope`]: 16 rises per run (86
/// degrees); steeper faces are walls whatever the configuration.
const MAX_WALKABLE_SLOPE: i32 = 16 * 256;

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
    /// Steepest face of a polygon solid the player stands and walks on, as
    /// a rise per 256 units of run (256: 45 degrees, 64: a 1:4 ramp). On
    /// such a face it is grounded, does not slide when standing still, and
    /// is snapped down onto it when walking down; a steeper face is a wall
    /// (not ground: the player slides off it). Tile slopes do not use it.
    pub max_walkable_slope: i32,
    /// Upward speed after stomping an enemy (`jump_speed` and a new jump
    /// hold when jump is held).
    pub stomp_bounce_speed: i32,
    /// How far below an enemy's top (at the start of the tick) the player's
    /// bottom may have been and still count as landing on it.
    pub stomp_tolerance: i32,
    /// What leaving a platform keeps of its velocity.
    pub carry_mode: CarryMode,
    /// How the player's body is modelled (default: one box).
    pub shape: PlayerShape,
    /// Ticks a player stays dead before it respawns at its checkpoint
    /// (default 24: 0.4 s at 60 ticks a second). While dead it neither
    /// moves, collides, collects nor is hurt. 0: it respawns in the tick it
    /// died. At most [`MAX_RESPAWN_DELAY_TICKS`].
    pub respawn_delay_ticks: u16,
}

/// Largest [`PlayerConfig::respawn_delay_ticks`]: 1200 ticks (20 s at 60
/// ticks a second, 1.2 s at the server's largest tick rate, 1000).
pub const MAX_RESPAWN_DELAY_TICKS: u16 = 1200;

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
            max_walkable_slope: 256,
            stomp_bounce_speed: 1024,
            stomp_tolerance: 1024,
            carry_mode: CarryMode::Add,
            shape: PlayerShape::Box,
            respawn_delay_ticks: 24,
        }
    }
}

impl PlayerConfig {
    /// Checks every value: sizes positive within the extent bound, speeds and
    /// accelerations in `[0, MAX_SPEED / 4]`, `max_run_speed`, `jump_speed`
    /// and `max_fall_speed` positive, `max_walkable_slope` in `[0, 4096]`
    /// (up to 86 degrees), tick counts at most 254, `respawn_delay_ticks` at
    /// most [`MAX_RESPAWN_DELAY_TICKS`].
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
        let v = self.max_walkable_slope;
        if !(0..=MAX_WALKABLE_SLOPE).contains(&v) {
            return Err(format!(
                "player max_walkable_slope = {v} is not in [0, {MAX_WALKABLE_SLOPE}]"
            ));
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
        let v = self.respawn_delay_ticks;
        if v > MAX_RESPAWN_DELAY_TICKS {
            return Err(format!(
                "player respawn_delay_ticks = {v} must be at most {MAX_RESPAWN_DELAY_TICKS}"
            ));
        }
        Ok(())
    }
}

impl PlayerConfig {
    /// This configuration for a level's player ([`PlayerScale`]): every
    /// length, speed and acceleration times `scale / 256` (rounded to the
    /// nearest unit; a positive value stays at least 1), the half extents
    /// the level's when it gives them; ticks and `max_walkable_slope` (a
    /// ratio) unchanged. Scale 256 without half extents changes nothing.
    /// Refused when the scale is outside [`MIN_PLAYER_SCALE`,
    /// `MAX_PLAYER_SCALE`] or the result breaks [`PlayerConfig::validate`].
    pub fn scaled(&self, s: &PlayerScale) -> Result<PlayerConfig, String> {
        if !(MIN_PLAYER_SCALE..=MAX_PLAYER_SCALE).contains(&s.scale) {
            return Err(format!(
                "player scale {}/256 is outside [{MIN_PLAYER_SCALE}, {MAX_PLAYER_SCALE}]/256",
                s.scale
            ));
        }
        let k = i64::from(s.scale);
        let mul = |v: i32| -> i32 {
            let r = (i64::from(v) * k + 128).div_euclid(256);
            let r = if v > 0 { r.max(1) } else { r };
            r.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
        };
        let mut c = *self;
        for v in [
            &mut c.run_accel,
            &mut c.run_brake,
            &mut c.air_accel,
            &mut c.air_brake,
            &mut c.max_run_speed,
            &mut c.jump_speed,
            &mut c.jump_gravity,
            &mut c.gravity,
            &mut c.max_fall_speed,
            &mut c.snap_distance,
            &mut c.stomp_bounce_speed,
            &mut c.stomp_tolerance,
        ] {
            *v = mul(*v);
        }
        c.half = match s.half {
            Some(h) => h,
            None => IVec2::new(mul(self.half.x), mul(self.half.y)),
        };
        c.validate()?;
        Ok(c)
    }
}

impl GameConfig {
    /// This configuration with the player scaled for `level`
    /// ([`PlayerConfig::scaled`] by [`Level::player`]): what a server plays
    /// the level with and sends its clients in `Welcome`.
    pub fn for_level(mut self, level: &Level) -> Result<GameConfig, String> {
        self.player = self
            .player
            .scaled(&level.player)
            .map_err(|e| format!("level {:?}: {e}", level.name))?;
        Ok(self)
    }
}

/// Everything [`super::Game::with_config`] can tune.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct GameConfig {
    /// The player (and walker gravity) constants.
    pub player: PlayerConfig,
    /// The simulation knobs: substeps, restitution passes and swept
    /// collision (these change results; the game marks no body swept, so
    /// only [`crate::world::SweepMode::Auto`] sweeps its fast movers),
    /// broad phase, pipeline and detection threads (these never do).
    pub sim: SimConfig,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::level::ScaleSource;

    fn scale(scale: u32, half: Option<IVec2>) -> PlayerScale {
        PlayerScale {
            scale,
            half,
            source: ScaleSource::Settings,
        }
    }

    #[test]
    fn scale_one_changes_nothing_and_others_scale_lengths_and_speeds() {
        let d = PlayerConfig::default();
        assert_eq!(d.scaled(&PlayerScale::default()), Ok(d));
        let twice = d.scaled(&scale(512, None)).unwrap();
        assert_eq!(twice.half, d.half * 2);
        assert_eq!(
            (twice.jump_speed, twice.gravity, twice.max_run_speed),
            (2 * d.jump_speed, 2 * d.gravity, 2 * d.max_run_speed)
        );
        assert_eq!(
            (twice.jump_hold_ticks, twice.max_walkable_slope),
            (d.jump_hold_ticks, d.max_walkable_slope)
        );
        let sized = d.scaled(&scale(512, Some(IVec2::new(100, 200)))).unwrap();
        assert_eq!(sized.half, IVec2::new(100, 200));
        // The smallest scale keeps every positive value positive.
        let small = d.scaled(&scale(MIN_PLAYER_SCALE, None)).unwrap();
        assert!(small.validate().is_ok() && small.air_brake >= 1);
        assert!(d.scaled(&scale(MAX_PLAYER_SCALE, None)).is_ok());
    }

    #[test]
    fn scales_out_of_bounds_are_refused() {
        let d = PlayerConfig::default();
        for s in [0, MIN_PLAYER_SCALE - 1, MAX_PLAYER_SCALE + 1, u32::MAX] {
            assert!(d.scaled(&scale(s, None)).is_err(), "{s}");
        }
        assert!(d.scaled(&scale(256, Some(IVec2::new(0, 5)))).is_err());
        assert!(d.scaled(&scale(256, Some(IVec2::splat(i32::MAX)))).is_err());
    }
}
