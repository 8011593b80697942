//! Controllers: turn one player's buttons into a body's velocity, once per
//! tick, before anything moves. Input slot `i` of [`super::World::step`]
//! drives controller `i` (a missing input is no button held); removing a
//! body drops its controllers and moves the later ones down one slot.
//!
//! The only controller is the top-down [`Mover`] (the warm-up room of
//! [`crate::scene`], the seeded [`super::scenes`]). The platformer is not a
//! controller: [`crate::game`] sets its player bodies' velocities by its own
//! rules before and after each [`super::World::step`], which it runs with
//! no inputs.

use crate::fixed::MAX_SPEED;
use crate::input::Buttons;
use glam::IVec2;
use serde::{Deserialize, Serialize};

use super::body::Body;
use super::error::BuildError;
use super::hash::Fnv1a;
use super::id::BodyId;

/// Tuning of the top-down [`Mover`], in units per tick (per tick for speeds,
/// per tick per tick for `accel` and `brake`). Each axis is independent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct MoverConfig {
    /// Speed gained per tick along an axis while one of its keys is held.
    pub accel: i32,
    /// Speed lost per tick, towards zero (never past it), along an axis
    /// while neither of its keys is held.
    pub brake: i32,
    /// Largest speed per axis.
    pub max_speed: i32,
}

impl MoverConfig {
    /// Checks `0 <= accel, brake <= MAX_SPEED` and `0 < max_speed <= MAX_SPEED`.
    pub fn validate(&self) -> Result<(), BuildError> {
        for (what, v, min) in [
            ("mover accel", self.accel, 0),
            ("mover brake", self.brake, 0),
            ("mover max_speed", self.max_speed, 1),
        ] {
            if v < min || v > MAX_SPEED {
                return Err(BuildError::Config {
                    what,
                    value: v as i64,
                });
            }
        }
        Ok(())
    }
}

/// A top-down mover: arrow keys accelerate the body in their direction,
/// an axis with no key held brakes towards zero, each axis is clamped to the
/// maximum speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Mover {
    /// The body it drives.
    pub body: BodyId,
    /// Its tuning.
    pub config: MoverConfig,
}

impl Mover {
    /// The velocity after one tick of `input`, starting from `vel`.
    pub fn next_velocity(&self, vel: IVec2, input: Buttons) -> IVec2 {
        IVec2::new(
            self.axis(vel.x, input.dir_x()),
            self.axis(vel.y, input.dir_y()),
        )
    }

    #[inline]
    fn axis(&self, v: i32, dir: i32) -> i32 {
        let c = &self.config;
        if dir != 0 {
            // |v| <= MAX_SPEED and accel <= MAX_SPEED: no overflow.
            (v + dir * c.accel).clamp(-c.max_speed, c.max_speed)
        } else if v > 0 {
            (v - c.brake).max(0)
        } else {
            (v + c.brake).min(0)
        }
    }
}

/// Something that drives a body from a player's input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Controller {
    /// The top-down mover.
    Mover(Mover),
}

impl Controller {
    /// The body it drives.
    pub fn body(&self) -> BodyId {
        match self {
            Controller::Mover(m) => m.body,
        }
    }

    pub(crate) fn validate(&self) -> Result<(), BuildError> {
        match self {
            Controller::Mover(m) => m.config.validate(),
        }
    }

    /// Applies one tick of `input` to the body it drives.
    pub(crate) fn apply(&self, input: Buttons, bodies: &mut [Body]) {
        match self {
            Controller::Mover(m) => {
                let b = &mut bodies[m.body.0 as usize];
                b.vel = m.next_velocity(b.vel, input);
            }
        }
    }

    /// Feeds the controller's whole state to the hash.
    pub(crate) fn hash(&self, h: &mut Fnv1a) {
        match self {
            Controller::Mover(m) => {
                h.u8(1);
                h.u32(m.body.0);
                h.i32(m.config.accel);
                h.i32(m.config.brake);
                h.i32(m.config.max_speed);
            }
        }
    }
}
