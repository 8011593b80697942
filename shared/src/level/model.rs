//! The level data model.

use crate::tilemap::Tilemap;
use glam::IVec2;
use serde::{Deserialize, Serialize};

/// A level: a tile grid plus entities, all in world units (1 px = 256 units,
/// y down).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Level {
    /// Human-readable name (file stem or the editor's level name).
    pub name: String,
    /// The collision grid.
    pub tilemap: Tilemap,
    /// Every entity, in file order (the order is part of the level's identity:
    /// entity ids are assigned from it, deterministically).
    pub entities: Vec<EntityDef>,
}

/// One entity placed in a level.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct EntityDef {
    /// What it is.
    pub kind: EntityKind,
    /// Centre position, in units.
    pub pos: IVec2,
    /// Full size, in units (even numbers, so a centred box has integer half
    /// extents).
    pub size: IVec2,
}

/// How a moving platform moves.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlatformMotion {
    /// Path nodes (centre positions, in units), starting with the spawn
    /// position; the platform goes back and forth (ping-pong) or loops.
    pub path: Vec<IVec2>,
    /// Speed in units per tick along each leg (exact integer steps).
    pub speed: i32,
    /// Loop back to the first node instead of reversing.
    pub looped: bool,
}

/// The kinds of entity a level can hold (see the loaders' name table).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum EntityKind {
    /// Where players (re)spawn before reaching a checkpoint. A level has at
    /// least one.
    PlayerSpawn,
    /// A solid block outside the tile grid (static): the box of the entity's
    /// `size` around its `pos`.
    Block,
    /// A static solid convex polygon outside the tile grid (a ramp, a
    /// wedge): what Tiled polygon objects and OGMO `polygon` entities become.
    /// The entity's `size` is an even box around `pos` that holds every
    /// vertex (for drawing bounds and culling), not the shape.
    PolygonBlock {
        /// Vertices relative to the entity's `pos`, in units, in file order
        /// (either winding): 3 to [`crate::shape::MAX_POLYGON_VERTICES`],
        /// strictly convex, each component within [`crate::fixed::MAX_EXTENT`]
        /// ([`crate::shape::ConvexPolygon::new`] accepts them; the loaders
        /// and [`crate::game::Game`] check it).
        vertices: Vec<IVec2>,
    },
    /// A kinematic platform on a fixed path; `one_way` makes it solid only
    /// from above.
    MovingPlatform {
        /// The path it follows.
        motion: PlatformMotion,
        /// Solid only from above.
        one_way: bool,
    },
    /// An enemy that walks back and forth, turning at walls and ledges; its
    /// body hurts, its head can be stomped.
    Walker {
        /// Walking speed in units per tick.
        speed: i32,
    },
    /// Launches a player upwards once on contact.
    Springboard {
        /// Upward launch speed in units per tick.
        strength: i32,
    },
    /// Picked up once; counts toward the score.
    Coin,
    /// Touching it makes it the player's respawn point.
    Checkpoint,
    /// Touching it wins the level.
    Goal,
    /// Touching it hurts (respawn).
    Hazard,
}
