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
    /// How big the level's player is and how fast it moves
    /// ([`crate::game::GameConfig::for_level`] applies it).
    pub player: PlayerScale,
}

/// Smallest [`PlayerScale::scale`]: 32 (1/8: a 1.5 x 2 px player).
pub const MIN_PLAYER_SCALE: u32 = 32;
/// Largest [`PlayerScale::scale`]: 65536 (256 times: a 3072 x 4096 px
/// player; every scaled speed stays far inside
/// [`crate::fixed::MAX_SPEED`] / 4, the bound
/// [`crate::game::PlayerConfig::validate`] holds them to).
pub const MAX_PLAYER_SCALE: u32 = 1 << 16;

/// A level's player relative to ledge's own (whose rules
/// [`crate::game::PlayerConfig`] holds, tuned for 16 px tiles): every
/// length, speed and acceleration of the rules times `scale / 256`, ticks
/// unchanged, so jumps, runs and falls keep their shape and cover `scale /
/// 256` times the distance. Integers only: the importers round a level's
/// scale to 1/256.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct PlayerScale {
    /// Scale in 1/256ths (256: ledge's own player), in
    /// [`MIN_PLAYER_SCALE`, `MAX_PLAYER_SCALE`].
    pub scale: u32,
    /// The player's half extents when the level gives them (its spawn
    /// object's size, the settings' `[player]`), units; `None`: the
    /// configuration's, times the scale.
    pub half: Option<IVec2>,
    /// Where the scale came from (for reports).
    pub source: ScaleSource,
}

impl Default for PlayerScale {
    fn default() -> Self {
        PlayerScale {
            scale: 256,
            half: None,
            source: ScaleSource::Default,
        }
    }
}

/// Where a [`PlayerScale`] came from.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ScaleSource {
    /// Ledge's own player: nothing in the level says otherwise.
    #[default]
    Default,
    /// The level's tile size over ledge's 16 px.
    TileSize,
    /// The spawn object's height over ledge's player's 16 px; the player
    /// has the spawn's size.
    SpawnSize,
    /// The level's settings file (`scale`, `[player]`).
    Settings,
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
    /// A hazard, coin, checkpoint or goal turned by an angle that is not a
    /// whole number of quarter turns (a quarter-turned one is the upright
    /// box of its turned extent): the oriented box of corners `pos ± u ±
    /// v`. The entity's `size` is an even box around it (for bounds and
    /// drawing), not the shape.
    Turned {
        /// What it is.
        trigger: Trigger,
        /// First half axis, units: not zero, not parallel to `v`, and
        /// `|u.x| + |v.x|`, `|u.y| + |v.y|` within
        /// [`crate::fixed::MAX_EXTENT`] ([`crate::shape::Obb::from_axes`]
        /// accepts them; [`crate::game::Game`] checks it).
        u: IVec2,
        /// Second half axis, units.
        v: IVec2,
    },
}

/// What a [`EntityKind::Turned`] entity is: one of the box-shaped
/// triggers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Trigger {
    /// A [`EntityKind::Hazard`].
    Hazard,
    /// A [`EntityKind::Coin`].
    Coin,
    /// A [`EntityKind::Checkpoint`].
    Checkpoint,
    /// A [`EntityKind::Goal`].
    Goal,
}

impl Trigger {
    /// The upright entity kind of this trigger.
    pub fn kind(self) -> EntityKind {
        match self {
            Trigger::Hazard => EntityKind::Hazard,
            Trigger::Coin => EntityKind::Coin,
            Trigger::Checkpoint => EntityKind::Checkpoint,
            Trigger::Goal => EntityKind::Goal,
        }
    }
}
