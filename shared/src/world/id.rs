//! The world's handles, [`BodyId`] and [`ColliderId`], and the tilemap's
//! stand-ins for them ([`BodyId::TILEMAP`], [`ColliderId::TILEMAP`],
//! [`TILEMAP_TAG`], [`TILEMAP_LAYER`]).
//!
//! In a module of their own, below everything else in the world: bodies,
//! colliders, errors, events, contacts, detection and sweeps all name them,
//! and none of those needs to reach another of them (or the `World` facade)
//! just for an id.

use serde::{Deserialize, Serialize};

/// A body's index in its world: creation order, except that
/// [`super::World::add_body`] reuses the lowest slot freed by
/// [`super::World::remove_body`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct BodyId(pub u32);

impl BodyId {
    /// The world's tilemap, as the other body of a tile contact (in
    /// [`super::Event`]s and [`super::ContactRecord`]s). No real body has
    /// this id.
    pub const TILEMAP: BodyId = BodyId(u32::MAX);
}

/// A collider's index in its world, in creation order (stable for the world's
/// life, never reused; also the tie-breaker that makes every ordering
/// deterministic).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct ColliderId(pub u32);

impl ColliderId {
    /// The world's tilemap, as the other collider of a tile contact. No real
    /// collider has this id.
    pub const TILEMAP: ColliderId = ColliderId(u32::MAX);
}

/// The layer bit of the world's tilemap: a collider interacts with tiles when
/// its `mask` has this bit (the default mask has every bit).
pub const TILEMAP_LAYER: u32 = 1 << 31;

/// The tag tile contacts report for the tilemap end (in events).
pub const TILEMAP_TAG: u16 = u16::MAX;
