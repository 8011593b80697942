//! What loading a level gives: [`LoadedLevel`] (the level, the bot route,
//! warnings, art, per-layer figures) and the names reports use.

use std::collections::BTreeMap;

use ledge_shared::level::{EntityKind, Level, Waypoint};

use crate::art;

/// A loaded level and what came with it.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedLevel {
    /// The level.
    pub level: Level,
    /// The bot route: `waypoint` entities in file order (empty when the file
    /// has none).
    pub route: Vec<Waypoint>,
    /// Things skipped, one line each (unknown entities when
    /// [`LoadOptions::skip_unknown_entities`](crate::LoadOptions::skip_unknown_entities) is set).
    pub warnings: Vec<String>,
    /// What a client draws: the editor's tile layers and tileset images.
    pub art: art::LevelArt,
    /// What each editor layer became, in file order (layers that gave
    /// nothing are left out).
    pub layers: Vec<LayerStats>,
}

/// What one editor layer became: for `ledge-level check` and the author.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LayerStats {
    /// The layer's name.
    pub name: String,
    /// Its path in the file (`layers[2]`), when it is a tile or grid layer.
    pub field: String,
    /// A tile/grid layer whose cells are in the level's grid (false: it did
    /// not line up with the grid, see the warnings).
    pub on_grid: bool,
    /// Tiles by kind: solid, one-way, hazard, slope.
    pub solid: usize,
    /// One-way tiles.
    pub one_way: usize,
    /// Hazard tiles.
    pub hazard: usize,
    /// Slope tiles.
    pub slopes: usize,
    /// Entities from this layer (static geometry from its tiles included),
    /// by [`entity_kind_name`].
    pub entities: BTreeMap<&'static str, usize>,
}

/// A short name of an entity kind, for reports: `spawn`, `block`,
/// `polygon`, `moving platform`, `walker`, `springboard`, `coin`,
/// `checkpoint`, `goal`, `hazard`.
pub fn entity_kind_name(kind: &EntityKind) -> &'static str {
    match kind {
        EntityKind::PlayerSpawn => "spawn",
        EntityKind::Block => "block",
        EntityKind::PolygonBlock { .. } => "polygon",
        EntityKind::MovingPlatform { .. } => "moving platform",
        EntityKind::Walker { .. } => "walker",
        EntityKind::Springboard { .. } => "springboard",
        EntityKind::Coin => "coin",
        EntityKind::Checkpoint => "checkpoint",
        EntityKind::Goal => "goal",
        EntityKind::Hazard => "hazard",
        EntityKind::Turned { trigger, .. } => entity_kind_name(&trigger.kind()),
    }
}
