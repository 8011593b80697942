//! Tunnelling: boxes and circles shot at a 1 px wall at random speeds and
//! angles; a shot tunnels when its centre ends on the far side of the wall.
//!
//! Each world holds [`BATCH`] shots and one static wall 1 px thick and tall
//! enough for every shot. Shots are on a layer that ignores itself, so they
//! only meet the wall. A shot of velocity `v` (speed uniform in 1 px up to
//! [`MAX_SHOT_SPEED`], angle uniform within 60 degrees of the wall's normal)
//! starts with its leading edge a random distance in `[0, v.x)` before the
//! wall's near face, so it reaches the wall during the first tick at a
//! uniformly random phase of its motion. After two ticks a shot the wall
//! stopped rests against the near face (restitution pushed it out and
//! removed its velocity into the wall) and a shot that tunnelled is past the
//! far face: the centre's side of the wall's centre line is the exact
//! verdict.
//!
//! The counted shots are game-sized: half sizes 4 to 8 px (boxes of 8 to
//! 16 px, circles of radius 4 to 8 px), the smallest moving bodies of the
//! game and what [`ledge_shared::world::SweepMode::AUTO_MIN_SPEED`] assumes.
//! A quarter as many tiny shots (half sizes 1 to 3 px: debris, bullets) are
//! counted apart.

use anyhow::Result;
use glam::IVec2;
use ledge_shared::broad::standard::SplitMix64;
use ledge_shared::fixed::px;
use ledge_shared::shape::Circle;
use ledge_shared::world::{BodyDesc, BodyId, ColliderDesc, SimConfig, World};

use super::aabb;

/// Shots per world.
pub const BATCH: usize = 250;
/// Fastest shot, units per tick (64 px per tick: a bullet).
pub const MAX_SHOT_SPEED: i32 = px(64);
/// The fastest a body moves in the platformer, units per tick (8 px per
/// tick: above the player's 6 px per tick fall and 2.5 px per tick run).
pub const GAME_SPEED: i32 = px(8);
/// Half thickness of the wall: the wall is 1 px thick, centred on x = 0.
const WALL_HALF: i32 = px(1) / 2;
/// Shots start at y within this of 0.
const SPREAD: i32 = px(2000);
/// Collision layers: the wall (meets everything), the shots (meet only the
/// wall).
const WALL_LAYER: u32 = 1;
const SHOT_LAYER: u32 = 2;

/// What the shots did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ThinWalls {
    /// Shots fired.
    pub shots: u64,
    /// Shots whose centre ended beyond the wall.
    pub tunnels: u64,
    /// Shots at game speeds: at most [`GAME_SPEED`].
    pub slow_shots: u64,
    /// Of those, shots that tunnelled.
    pub slow_tunnels: u64,
    /// Tiny shots fired (half sizes 1 to 3 px, all speeds).
    pub tiny_shots: u64,
    /// Of those, shots that tunnelled.
    pub tiny_tunnels: u64,
}

impl ThinWalls {
    /// Tunnels per shot.
    pub fn rate(&self) -> f64 {
        self.tunnels as f64 / self.shots.max(1) as f64
    }

    /// Tunnels per shot at game speeds (at most [`GAME_SPEED`]).
    pub fn slow_rate(&self) -> f64 {
        self.slow_tunnels as f64 / self.slow_shots.max(1) as f64
    }

    /// Tunnels per tiny shot.
    pub fn tiny_rate(&self) -> f64 {
        self.tiny_tunnels as f64 / self.tiny_shots.max(1) as f64
    }
}

/// Fires `shots` game-sized shots and `shots / 4` tiny ones (seed `seed`)
/// in worlds configured with `config`; `marked` marks every shot for swept
/// collision ([`World::set_swept`]).
pub fn run(config: SimConfig, shots: u64, seed: u64, marked: bool) -> Result<ThinWalls> {
    let mut rng = SplitMix64(seed);
    let mut out = ThinWalls::default();
    let mut fired = 0;
    while fired < shots {
        let n = (shots - fired).min(BATCH as u64) as usize;
        for (speed, tunnelled) in batch(config, &mut rng, n, (4, 8), marked)? {
            out.shots += 1;
            out.tunnels += tunnelled as u64;
            if speed <= GAME_SPEED {
                out.slow_shots += 1;
                out.slow_tunnels += tunnelled as u64;
            }
        }
        fired += n as u64;
    }
    let tiny = shots / 4;
    let mut fired = 0;
    while fired < tiny {
        let n = (tiny - fired).min(BATCH as u64) as usize;
        for (_, tunnelled) in batch(config, &mut rng, n, (1, 3), marked)? {
            out.tiny_shots += 1;
            out.tiny_tunnels += tunnelled as u64;
        }
        fired += n as u64;
    }
    Ok(out)
}

/// One world of `n` shots with half sizes in `half` px: each shot's speed
/// and whether it tunnelled.
fn batch(
    config: SimConfig,
    rng: &mut SplitMix64,
    n: usize,
    half: (i32, i32),
    marked: bool,
) -> Result<Vec<(i32, bool)>> {
    let mut w = World::new(config)?;
    let wall = w.add_body(BodyDesc::fixed(IVec2::ZERO))?;
    let half_height = SPREAD + 3 * MAX_SHOT_SPEED + px(64);
    w.add_collider(
        wall,
        ColliderDesc::solid(aabb(IVec2::new(2 * WALL_HALF, 2 * half_height))?)
            .layers(WALL_LAYER, u32::MAX),
    )?;
    let mut bodies = Vec::with_capacity(n);
    for k in 0..n {
        let (body, speed) = add_shot(&mut w, rng, k % 2 == 0, half)?;
        if marked {
            w.set_swept(body, true)?;
        }
        bodies.push((body, speed));
    }
    for _ in 0..2 {
        w.step(&[]);
    }
    Ok(bodies
        .iter()
        .map(|&(b, speed)| (speed, w.body(b).map_or(0, |b| b.pos().x) > 0))
        .collect())
}

/// Adds one random shot: a box or a circle of half size in `half` px;
/// returns its body and speed.
fn add_shot(
    w: &mut World,
    rng: &mut SplitMix64,
    square: bool,
    half: (i32, i32),
) -> Result<(BodyId, i32)> {
    let half = px(rng.range(half.0, half.1));
    let speed = rng.range(px(1), MAX_SHOT_SPEED);
    // Setup only (the simulation itself is integer): angle within 60 degrees
    // of the wall's normal.
    let angle = (rng.range(-60_000, 60_000) as f64 / 1000.0).to_radians();
    let vx = ((speed as f64 * angle.cos()).round() as i32).max(1);
    let vy = (speed as f64 * angle.sin()).round() as i32;
    let lead = rng.range(0, vx - 1);
    let y = rng.range(-SPREAD, SPREAD);
    let pos = IVec2::new(-WALL_HALF - half - lead, y);
    let body = w.add_body(BodyDesc::dynamic(pos).with_vel(IVec2::new(vx, vy)))?;
    let desc = if square {
        ColliderDesc::solid(aabb(IVec2::splat(2 * half))?)
    } else {
        ColliderDesc::solid(Circle::new(half)?)
    };
    w.add_collider(body, desc.layers(SHOT_LAYER, WALL_LAYER))?;
    Ok((body, speed))
}
