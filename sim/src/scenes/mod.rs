//! One deterministic, seeded scene per accuracy metric, built through the
//! public world and game APIs only.
//!
//! * [`thin_walls`]: tunnelling rate of fast small shots at 1 px walls;
//! * [`penetration`]: deepest overlap left after a tick in a landing pile;
//! * [`seams`]: motion lost by boxes sliding across floor seams;
//! * [`squish`]: squish events in stacks and piles nothing crushes;
//! * [`drift`]: how far a prediction run with a setting strays from an
//!   authority running the default configuration.

pub mod drift;
pub mod penetration;
pub mod seams;
pub mod squish;
pub mod thin_walls;

use anyhow::Result;
use glam::IVec2;
use ledge_shared::shape::Aabb;
use ledge_shared::world::{BodyId, World};

/// Gravity of the falling scenes, units per tick per tick: the player's
/// (`PlayerConfig::gravity`).
pub const GRAVITY: i32 = 96;
/// Largest fall speed of the falling scenes, units per tick: the player's
/// (`PlayerConfig::max_fall_speed`, 6 px per tick).
pub const MAX_FALL: i32 = 1536;

/// A box shape of full size `size` (units, even).
pub(crate) fn aabb(size: IVec2) -> Result<Aabb> {
    Ok(Aabb::new(size / 2)?)
}

/// Adds gravity to the velocity of every body of `bodies` (capped at
/// [`MAX_FALL`]), as the platformer does to players and walkers before each
/// step; the world removes the velocity a floor stops.
pub(crate) fn apply_gravity(w: &mut World, bodies: &[BodyId]) -> Result<()> {
    for &b in bodies {
        let v = w.body(b).map_or(IVec2::ZERO, |b| b.vel());
        w.set_velocity(b, IVec2::new(v.x, (v.y + GRAVITY).min(MAX_FALL)))?;
    }
    Ok(())
}
