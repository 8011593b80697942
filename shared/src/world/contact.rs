//! The contact buffer's element: one overlapping pair of colliders found by
//! detection, consumed by restitution and events.

use crate::query::Proximity;
use glam::IVec2;

use super::collider::{Colliders, OneWay};
use super::id::{BodyId, ColliderId};

/// Re-runs the narrow phase for one pair, given the two *body* positions:
/// `fn(colliders, index of A in its set, body pos of A, index of B, body pos of B)`.
/// Detection stores the monomorphised instance for the pair's two kinds, so a
/// re-check is one indirect call, never a `match` on kinds.
pub(crate) type RecheckFn = fn(&Colliders, u32, IVec2, u32, IVec2) -> Proximity;

/// Whether a contact pushes or only reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ContactKind {
    /// Both colliders are solid: restitution separates them.
    Solid,
    /// One collider is a trigger: an event, never a push.
    Trigger,
}

/// One end of a contact: a collider and what restitution needs of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct End {
    pub body: u32,
    pub collider: u32,
    /// Index in its shape kind's set.
    pub index: u32,
    pub tag: u16,
    pub one_way: Option<OneWay>,
    pub solid: bool,
}

/// An overlapping pair of colliders. `a` and `b` are in detection order; the
/// MTV moves `a` out of `b`.
#[derive(Debug, Clone, Copy)]
pub struct ContactRecord {
    pub(crate) a: End,
    pub(crate) b: End,
    pub(crate) mtv: IVec2,
    pub(crate) kind: ContactKind,
    /// Body positions when `mtv` was computed: if either body has moved since,
    /// the MTV is stale and the pair is re-checked.
    pub(crate) pos_a: IVec2,
    pub(crate) pos_b: IVec2,
    /// Area of the overlap of the two bounding boxes: the second sort key.
    pub(crate) area: u64,
    pub(crate) recheck: RecheckFn,
    /// For a tile contact (B is [`BodyId::TILEMAP`]): the tile's coordinates,
    /// the last sort key. Zero otherwise.
    pub(crate) tile: IVec2,
}

impl ContactRecord {
    /// First body (the one the MTV moves).
    pub fn body_a(&self) -> BodyId {
        BodyId(self.a.body)
    }

    /// First collider.
    pub fn collider_a(&self) -> ColliderId {
        ColliderId(self.a.collider)
    }

    /// Second body.
    pub fn body_b(&self) -> BodyId {
        BodyId(self.b.body)
    }

    /// Second collider.
    pub fn collider_b(&self) -> ColliderId {
        ColliderId(self.b.collider)
    }

    /// The minimum translation vector that moves collider A out of B, as
    /// detected.
    pub fn mtv(&self) -> IVec2 {
        self.mtv
    }

    /// Solid or trigger.
    pub fn kind(&self) -> ContactKind {
        self.kind
    }

    /// The tile coordinates when B is the world's tilemap.
    pub fn tile(&self) -> Option<IVec2> {
        self.is_tile().then_some(self.tile)
    }

    /// Whether B is the world's tilemap ([`BodyId::TILEMAP`]).
    #[inline]
    pub fn is_tile(&self) -> bool {
        self.b.body == BodyId::TILEMAP.0
    }

    /// Restitution order: first the class (`0` for a contact with an
    /// immovable end, static, kinematic or the tilemap, `1` between two
    /// dynamic bodies), then `|mtv|^2` descending (`mtv` is the push
    /// restitution would apply, the stored MTV unless a covered face
    /// replaced it), then bounding-box overlap area descending, then the two
    /// collider ids (smaller first), then (tile contacts only: the tilemap is
    /// one collider) the tile's row and column. Collider pairs and tiles are
    /// unique within a detection, so this is a total order and an unstable
    /// sort is deterministic.
    ///
    /// The class puts the support a body rests on before the bodies resting
    /// on it: a body pushed out of immovable geometry is pinned along that
    /// push, so the dynamic contacts after it in the same pass treat it as
    /// immovable along that axis instead of splitting the push with it.
    ///
    /// The area key settles equal depths in favour of the surface the body
    /// rests on: crossing a floor seam, the box being entered can offer a
    /// sideways push exactly as deep as the floor's upward one, and resolving
    /// it first would snag.
    #[inline]
    pub(crate) fn order_key(&self, class: u8, mtv: IVec2) -> OrderKey {
        let (x, y) = (mtv.x.unsigned_abs() as u64, mtv.y.unsigned_abs() as u64);
        let l2 = x * x + y * y;
        let (lo, hi) = if self.a.collider < self.b.collider {
            (self.a.collider, self.b.collider)
        } else {
            (self.b.collider, self.a.collider)
        };
        (
            class,
            core::cmp::Reverse(l2),
            core::cmp::Reverse(self.area),
            lo,
            hi,
            self.tile.y,
            self.tile.x,
        )
    }
}

/// A contact's place in the restitution order ([`ContactRecord::order_key`]).
pub(crate) type OrderKey = (
    u8,
    core::cmp::Reverse<u64>,
    core::cmp::Reverse<u64>,
    u32,
    u32,
    i32,
    i32,
);
