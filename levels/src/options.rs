//! How a level is loaded: [`LoadOptions`] (set from a level's settings
//! file) and the sizes every importer is held to. Below the importers and
//! the settings reader, which all read them.

use std::collections::BTreeMap;

use ledge_shared::tilemap::Tile;

use crate::mapping::{self, TileMapping};

/// Largest level side, in tiles (grids up to 4096 x 4096).
pub const MAX_LEVEL_TILES: u32 = 4096;
/// Largest level file read from disk, in bytes (64 MiB).
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// How to load a level. [`LevelSettings`](crate::LevelSettings) (the settings file beside a
/// level) sets these from TOML.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoadOptions {
    /// Tile ids and grid values to tiles.
    pub mapping: TileMapping,
    /// Skip entities whose name is not in [`ENTITY_NAMES`](crate::ENTITY_NAMES) (each is listed in
    /// [`LoadedLevel::warnings`](crate::LoadedLevel::warnings)) instead of refusing the file. Default:
    /// skip.
    pub skip_unknown_entities: bool,
    /// Only these tile/grid layers (by name) collide, every tile of them
    /// (unless a tile says otherwise); `None` (the default): what the file's
    /// own data says.
    pub collision_layers: Option<Vec<String>>,
    /// Layers (by name) that never collide.
    pub decoration_layers: Vec<String>,
    /// Refuse a level without a player spawn; when false, or when a spawn
    /// can be placed, a level without one loads. Default: true (one is
    /// placed on the first free standing spot, with a warning).
    pub require_spawn: bool,
    /// Editor entity names (normalised: lower case, `_` for `-` and spaces)
    /// read as ledge entity names.
    pub entity_aliases: BTreeMap<String, String>,
    /// Tile kinds by (tileset name in lower case, tile id): they win over
    /// the file's own data.
    pub tile_kinds: BTreeMap<(String, u32), Tile>,
    /// Tile property names (normalised) that make a tile of a kind when set
    /// (and not false).
    pub tile_properties: BTreeMap<String, Tile>,
    /// Units of the speeds in the file.
    pub speed_unit: SpeedUnit,
    /// The level's player scale, in 1/256ths (the settings' `scale`);
    /// `None`: from the level (see `docs/LEVELS.md`, "Player scale").
    pub player_scale: Option<u32>,
    /// The player's size in units, even (the settings' `[player]`);
    /// `None`: from the level.
    pub player_size: Option<glam::IVec2>,
}

/// Units of entity speeds in a level file.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum SpeedUnit {
    /// Pixels per tick (ledge's own, the default).
    #[default]
    PxPerTick,
    /// Pixels per second, at [`TICKS_PER_SECOND`].
    PxPerSecond,
}

/// The tick rate speeds in pixels per second are converted at.
pub const TICKS_PER_SECOND: f64 = 60.0;

impl SpeedUnit {
    /// Pixels per tick of one unit of this kind.
    pub fn px_per_tick(self) -> f64 {
        match self {
            SpeedUnit::PxPerTick => 1.0,
            SpeedUnit::PxPerSecond => 1.0 / TICKS_PER_SECOND,
        }
    }

    /// Its name, for messages.
    pub fn name(self) -> &'static str {
        match self {
            SpeedUnit::PxPerTick => "px/tick",
            SpeedUnit::PxPerSecond => "px/s",
        }
    }
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            mapping: TileMapping::default(),
            skip_unknown_entities: true,
            collision_layers: None,
            decoration_layers: Vec::new(),
            require_spawn: true,
            entity_aliases: BTreeMap::new(),
            tile_kinds: BTreeMap::new(),
            tile_properties: BTreeMap::new(),
            speed_unit: SpeedUnit::PxPerTick,
            player_scale: None,
            player_size: None,
        }
    }
}

impl LoadOptions {
    /// The ledge entity name an editor name stands for: its alias, else
    /// itself.
    pub fn entity_name<'a>(&'a self, name: &'a str) -> &'a str {
        self.entity_aliases
            .get(&mapping::normalize(name))
            .map_or(name, |s| s.as_str())
    }

    /// Whether layer `name` collides by these options: `Some(true)` listed
    /// in [`LoadOptions::collision_layers`], `Some(false)` a decoration
    /// layer or left out of that list, `None` up to the file.
    pub fn layer_collides(&self, name: &str) -> Option<bool> {
        if self.decoration_layers.iter().any(|n| n == name) {
            return Some(false);
        }
        self.collision_layers
            .as_ref()
            .map(|names| names.iter().any(|n| n == name))
    }

    /// Whether the options give tileset `tileset` any tile kinds.
    pub(crate) fn has_tile_kinds(&self, tileset: &str) -> bool {
        let t = tileset.to_lowercase();
        self.tile_kinds
            .range((t.clone(), 0)..=(t, u32::MAX))
            .next()
            .is_some()
    }
}
