//! Bodies: what moves (or not), where it is, and what it touched this tick.

use crate::fixed::{check_coord, check_speed, MAX_COORD};
use glam::IVec2;
use serde::{Deserialize, Serialize};

pub use super::id::BodyId;

use super::error::BuildError;

/// How a body takes part in the simulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum BodyKind {
    /// Never moves (walls, floors, tiles).
    Static,
    /// Moved by code only (`pos += vel` each tick, velocity set by its owner);
    /// it pushes dynamic bodies and is never pushed.
    Kinematic,
    /// Moved by the simulation: its velocity moves it and contacts push it.
    Dynamic,
}

impl BodyKind {
    /// The byte this kind hashes as.
    pub(crate) fn code(self) -> u8 {
        match self {
            BodyKind::Static => 0,
            BodyKind::Kinematic => 1,
            BodyKind::Dynamic => 2,
        }
    }
}

/// Sides of a body touched by solid contacts during the last tick (a bitfield).
///
/// Sides are named from the body's point of view: a body pushed up out of a
/// floor touched it with its [`Sides::BOTTOM`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Sides(pub u8);

impl Sides {
    /// The left side (`-x`): pushed to the right.
    pub const LEFT: Sides = Sides(1 << 0);
    /// The right side (`+x`): pushed to the left.
    pub const RIGHT: Sides = Sides(1 << 1);
    /// The top side (`-y`): pushed down.
    pub const TOP: Sides = Sides(1 << 2);
    /// The bottom side (`+y`): pushed up (standing on something).
    pub const BOTTOM: Sides = Sides(1 << 3);
    /// No side.
    pub const NONE: Sides = Sides(0);

    /// Whether every side of `other` is in `self`.
    #[inline]
    pub fn contains(self, other: Sides) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether no side is set.
    #[inline]
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The sides a push of `m` says were touched.
    ///
    /// An axis counts when its component is non-zero and at least half the
    /// other component (the push is within about 63 degrees of that axis), so
    /// the one-unit rounding of a slanted MTV never marks a side, and a 45
    /// degree slope marks two.
    #[inline]
    pub fn from_push(m: IVec2) -> Sides {
        let (ax, ay) = (m.x.unsigned_abs() as u64, m.y.unsigned_abs() as u64);
        let mut s = 0;
        if ax != 0 && 2 * ax >= ay {
            s |= if m.x < 0 { Self::RIGHT.0 } else { Self::LEFT.0 };
        }
        if ay != 0 && 2 * ay >= ax {
            s |= if m.y < 0 { Self::BOTTOM.0 } else { Self::TOP.0 };
        }
        Sides(s)
    }
}

impl core::ops::BitOr for Sides {
    type Output = Sides;
    #[inline]
    fn bitor(self, rhs: Sides) -> Sides {
        Sides(self.0 | rhs.0)
    }
}

impl core::ops::BitOrAssign for Sides {
    #[inline]
    fn bitor_assign(&mut self, rhs: Sides) {
        self.0 |= rhs.0;
    }
}

/// What a swept body does when its sweep hits something (see
/// [`super::SweepMode`] and [`super::World::set_sweep_response`]). In every
/// case the body stops at the contact point for the rest of the substep:
/// the remaining motion is dropped, and the next substep (or tick) moves it
/// by its new velocity.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SweepResponse {
    /// Velocity into the surface removed, the rest kept (the default, and
    /// what the discrete contact pass does: a fast-falling body lands and
    /// keeps running).
    #[default]
    Slide,
    /// Velocity zeroed: a projectile sticks where it hit.
    Stop,
    /// Velocity reflected about the hit normal (exact for axis-aligned
    /// surfaces, rounded away from the surface on slanted ones; see
    /// [`crate::query::sweep::reflect`]): a bouncing projectile.
    Reflect,
}

impl SweepResponse {
    /// The bits this response hashes as (in [`Body`]'s flag byte).
    fn code(self) -> u8 {
        match self {
            SweepResponse::Slide => 0,
            SweepResponse::Stop => 1,
            SweepResponse::Reflect => 2,
        }
    }
}

/// What [`super::World::add_body`] needs to create a body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct BodyDesc {
    /// Static, kinematic or dynamic.
    pub kind: BodyKind,
    /// Position in units (each component within `±MAX_COORD`).
    pub pos: IVec2,
    /// Velocity in units per tick (each component within `±MAX_SPEED`; zero
    /// for a static body).
    pub vel: IVec2,
    /// Mass, used only to split a push between two dynamic bodies; positive.
    pub mass: u32,
}

impl BodyDesc {
    /// A static body at `pos`.
    pub fn fixed(pos: IVec2) -> Self {
        Self {
            kind: BodyKind::Static,
            pos,
            vel: IVec2::ZERO,
            mass: 1,
        }
    }

    /// A kinematic body at `pos`, at rest.
    pub fn kinematic(pos: IVec2) -> Self {
        Self {
            kind: BodyKind::Kinematic,
            pos,
            vel: IVec2::ZERO,
            mass: 1,
        }
    }

    /// A dynamic body of mass 1 at `pos`, at rest.
    pub fn dynamic(pos: IVec2) -> Self {
        Self {
            kind: BodyKind::Dynamic,
            pos,
            vel: IVec2::ZERO,
            mass: 1,
        }
    }

    /// The same with velocity `vel`.
    pub fn with_vel(mut self, vel: IVec2) -> Self {
        self.vel = vel;
        self
    }

    /// The same with mass `mass`.
    pub fn with_mass(mut self, mass: u32) -> Self {
        self.mass = mass;
        self
    }

    /// Checks the description against the numeric bounds.
    pub(crate) fn validate(&self) -> Result<(), BuildError> {
        check_coord("body position x", self.pos.x as i64)?;
        check_coord("body position y", self.pos.y as i64)?;
        validate_velocity(self.kind, self.vel)?;
        if self.mass == 0 {
            return Err(BuildError::Mass { value: self.mass });
        }
        Ok(())
    }
}

/// Checks a velocity for a body of `kind`.
pub(crate) fn validate_velocity(kind: BodyKind, vel: IVec2) -> Result<(), BuildError> {
    check_speed("body velocity x", vel.x as i64)?;
    check_speed("body velocity y", vel.y as i64)?;
    if kind == BodyKind::Static && vel != IVec2::ZERO {
        return Err(BuildError::StaticVelocity);
    }
    Ok(())
}

/// Most sweeps of one body in one substep (a slide continues after a hit;
/// see `sweep`).
pub(crate) const MAX_SWEEPS: usize = 3;

/// The surfaces a body's last sweep hit (`(other collider, normal)`), for
/// the sweep's "reported once" rule: kept in [`Body`], filled by `sweep`.
pub(crate) type Rest = [Option<(u32, IVec2)>; MAX_SWEEPS];

/// A body's state.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Body {
    pub(crate) kind: BodyKind,
    pub(crate) pos: IVec2,
    pub(crate) vel: IVec2,
    pub(crate) mass: u32,
    /// Sides touched this tick.
    pub(crate) sides: Sides,
    /// Position at the start of the current (or last) tick.
    pub(crate) start: IVec2,
    /// Sum of the restitution pushes received this tick (saturating; only
    /// the signs matter).
    pub(crate) push: IVec2,
    /// Takes part in the simulation (a disabled body neither moves nor
    /// collides, and keeps its state).
    pub(crate) enabled: bool,
    /// The slot is free (removed); implies disabled.
    pub(crate) removed: bool,
    /// Carried by the kinematic box it stands on.
    pub(crate) rider: bool,
    /// Ignores one-way colliders and one-way tiles.
    pub(crate) drop_through: bool,
    /// The kinematic body that carried it this tick.
    pub(crate) carrier: Option<u32>,
    /// Marked for swept collision ([`super::World::set_swept`]).
    pub(crate) swept: bool,
    /// What a sweep hit does to it.
    pub(crate) sweep_response: SweepResponse,
    /// The surfaces its last sweep hit, `(other collider, normal)`: a hit
    /// at time 0 on one of them (resting against it and still pushing) is
    /// not reported again.
    pub(crate) swept_rest: Rest,
}

impl Body {
    pub(crate) fn new(desc: &BodyDesc) -> Self {
        Self {
            kind: desc.kind,
            pos: desc.pos,
            vel: desc.vel,
            mass: desc.mass,
            sides: Sides::NONE,
            start: desc.pos,
            push: IVec2::ZERO,
            enabled: true,
            removed: false,
            rider: false,
            drop_through: false,
            carrier: None,
            swept: false,
            sweep_response: SweepResponse::Slide,
            swept_rest: [None; MAX_SWEEPS],
        }
    }

    /// Whether the body takes part in the simulation (see
    /// [`super::World::set_enabled`]).
    #[inline]
    pub fn is_enabled(&self) -> bool {
        self.enabled
    }

    /// Whether the body was removed ([`super::World::remove_body`]): its slot
    /// is free and will be reused.
    #[inline]
    pub fn is_removed(&self) -> bool {
        self.removed
    }

    /// Whether kinematic boxes it stands on carry it (see
    /// [`super::World::set_rider`]).
    #[inline]
    pub fn is_rider(&self) -> bool {
        self.rider
    }

    /// Whether it falls through one-way colliders and one-way tiles (see
    /// [`super::World::set_drop_through`]).
    #[inline]
    pub fn drops_through(&self) -> bool {
        self.drop_through
    }

    /// Whether it is marked for swept collision (see
    /// [`super::World::set_swept`]).
    #[inline]
    pub fn is_swept(&self) -> bool {
        self.swept
    }

    /// What a sweep hit does to it (see [`super::World::set_sweep_response`]).
    #[inline]
    pub fn sweep_response(&self) -> SweepResponse {
        self.sweep_response
    }

    /// The kinematic body that carried it during the last tick, if any.
    #[inline]
    pub fn carrier(&self) -> Option<BodyId> {
        self.carrier.map(BodyId)
    }

    /// The byte of boolean state the world hashes.
    pub(crate) fn flag_bits(&self) -> u8 {
        self.enabled as u8
            | (self.removed as u8) << 1
            | (self.rider as u8) << 2
            | (self.drop_through as u8) << 3
            | (self.swept as u8) << 4
            | self.sweep_response.code() << 5
    }

    /// Static, kinematic or dynamic.
    #[inline]
    pub fn kind(&self) -> BodyKind {
        self.kind
    }

    /// Position in units.
    #[inline]
    pub fn pos(&self) -> IVec2 {
        self.pos
    }

    /// Velocity in units per tick.
    #[inline]
    pub fn vel(&self) -> IVec2 {
        self.vel
    }

    /// Mass.
    #[inline]
    pub fn mass(&self) -> u32 {
        self.mass
    }

    /// Sides touched by solid contacts during the last tick.
    #[inline]
    pub fn sides(&self) -> Sides {
        self.sides
    }

    /// How far the body moved during the last tick (motion and pushes).
    #[inline]
    pub fn displacement(&self) -> IVec2 {
        self.pos - self.start
    }

    /// The sum of the restitution pushes the body received during the last
    /// tick (each component saturates; only the sign is used by the solver).
    #[inline]
    pub fn pushed(&self) -> IVec2 {
        self.push
    }

    /// Whether the simulation moves this body.
    #[inline]
    pub fn is_dynamic(&self) -> bool {
        self.kind == BodyKind::Dynamic
    }

    /// Moves the body by `d` (i64 so no intermediate overflows), clamping to
    /// `±MAX_COORD`; a clamped axis loses its velocity.
    #[inline]
    pub(crate) fn translate(&mut self, d: IVec2) {
        let x = self.pos.x as i64 + d.x as i64;
        let y = self.pos.y as i64 + d.y as i64;
        self.pos.x = clamp_axis(x, &mut self.vel.x);
        self.pos.y = clamp_axis(y, &mut self.vel.y);
    }
}

/// Clamps one coordinate to the world bound, zeroing `vel` when it clamps.
#[inline]
fn clamp_axis(c: i64, vel: &mut i32) -> i32 {
    let m = MAX_COORD as i64;
    if c > m {
        *vel = 0;
        MAX_COORD
    } else if c < -m {
        *vel = 0;
        -MAX_COORD
    } else {
        c as i32
    }
}
