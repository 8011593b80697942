//! The settings file beside a level (`castle.tmx` → `castle.ledge.toml`):
//! what the editor file cannot say in ledge's terms, in one small TOML
//! file the level's author (or a server host) writes once.
//!
//! ```toml
//! # Tile and grid layers that collide (all of their tiles, unless a tile
//! # says otherwise); the other layers are decoration.
//! collision_layers = ["Ground", "Platforms"]
//! # Layers that never collide.
//! decoration_layers = ["Background"]
//! # Objects/entities with no ledge name: "skip" (default, with a warning)
//! # or "error".
//! unknown_entities = "skip"
//! # Units of the speeds in the file: "px_per_tick" (default) or
//! # "px_per_second" (60 ticks a second).
//! speed_unit = "px_per_second"
//! # Refuse a level without a player spawn instead of placing one.
//! require_spawn = false
//! # The player's scale: size, speeds and jump times this (default: from
//! # the level's spawn object or tile size).
//! scale = 4.0
//!
//! [entities]            # editor name = ledge entity name
//! hero = "player"
//! crab = "walker"
//!
//! [tiles.beach_tileset] # tileset name: tile id = tile kind
//! 0 = "solid"
//! 12 = "one_way"
//!
//! [tile_properties]     # tile property (true) = tile kind
//! water = "hazard"
//!
//! [grid]                # OGMO grid value = tile kind
//! g = "solid"
//!
//! [player]              # the player's size in px (the scale follows its height)
//! width = 48
//! height = 64
//! ```
//!
//! Unknown keys are errors that list the valid ones; every value is checked
//! (tile kinds against [`crate::parse_tile_kind`], entity names against
//! [`crate::ENTITY_NAMES`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::mapping::{normalize, parse_tile_kind};
use crate::{LevelError, LoadOptions, SpeedUnit};

/// The file name suffix of a level's settings file.
pub const SETTINGS_SUFFIX: &str = ".ledge.toml";
/// Largest settings file read, in bytes.
pub const MAX_SETTINGS_BYTES: u64 = 1 << 20;

/// A level's settings file, as written.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LevelSettings {
    /// Tile/grid layers that collide (by name); `None`: from the file's own
    /// data.
    pub collision_layers: Option<Vec<String>>,
    /// Layers that never collide (by name).
    #[serde(default)]
    pub decoration_layers: Vec<String>,
    /// `"skip"` or `"error"`.
    pub unknown_entities: Option<String>,
    /// `"px_per_tick"` or `"px_per_second"`.
    pub speed_unit: Option<String>,
    /// Refuse a level without a spawn.
    pub require_spawn: Option<bool>,
    /// Editor entity/object name = ledge entity name.
    #[serde(default)]
    pub entities: BTreeMap<String, String>,
    /// Tileset name = { tile id = tile kind }.
    #[serde(default)]
    pub tiles: BTreeMap<String, BTreeMap<String, String>>,
    /// Tile property name = tile kind (when the property is set and not
    /// false).
    #[serde(default)]
    pub tile_properties: BTreeMap<String, String>,
    /// OGMO grid value = tile kind.
    #[serde(default)]
    pub grid: BTreeMap<String, String>,
    /// The player's scale: its size, speeds and jump times this (1: ledge's
    /// own 12 x 16 px player), in [1/8, 256].
    pub scale: Option<f64>,
    /// The player's size in pixels.
    pub player: Option<PlayerSettings>,
}

/// The settings file's `[player]` table: the player's size in pixels (one
/// side alone: the other keeps ledge's 12:16 proportion).
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlayerSettings {
    /// Width, px.
    pub width: Option<f64>,
    /// Height, px.
    pub height: Option<f64>,
}

/// Where a level's settings file is looked for: beside it, named after it
/// (`levels/castle.tmx` → `levels/castle.ledge.toml`).
pub fn settings_path_for(level: &Path) -> PathBuf {
    let stem = level
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    level.with_file_name(format!("{stem}{SETTINGS_SUFFIX}"))
}

impl LevelSettings {
    /// Reads and checks a settings file.
    pub fn load(path: &Path) -> Result<Self, LevelError> {
        let file = path.display().to_string();
        let bytes = crate::read::read_bytes_capped(path, MAX_SETTINGS_BYTES)?;
        let text = String::from_utf8(bytes).map_err(|e| LevelError::Syntax {
            file: file.clone(),
            field: format!("byte {}", e.utf8_error().valid_up_to()),
            format: "UTF-8 text",
            message: e.to_string(),
        })?;
        Self::parse(&file, &text)
    }

    /// Parses and checks settings text; `file` names it in errors.
    pub fn parse(file: &str, text: &str) -> Result<Self, LevelError> {
        let s: Self = toml::from_str(text).map_err(|e| LevelError::Syntax {
            file: file.into(),
            field: match e.span() {
                Some(span) => {
                    let line = text[..span.start.min(text.len())].lines().count().max(1);
                    format!("line {line}")
                }
                None => "settings".into(),
            },
            format: "level settings TOML",
            message: e.message().to_owned(),
        })?;
        s.options(file, LoadOptions::default())?;
        Ok(s)
    }

    /// `base` with these settings applied.
    pub fn options(&self, file: &str, base: LoadOptions) -> Result<LoadOptions, LevelError> {
        let bad = |field: String, message: String| LevelError::BadValue {
            file: file.into(),
            field,
            message,
        };
        let kind = |field: String, v: &str| {
            parse_tile_kind(v).ok_or_else(|| {
                bad(
                    field,
                    format!(
                        "{v:?} is not a tile kind ({})",
                        crate::collision::KIND_NAMES
                    ),
                )
            })
        };
        let mut o = base;
        if let Some(layers) = &self.collision_layers {
            o.collision_layers = Some(layers.clone());
        }
        o.decoration_layers
            .extend(self.decoration_layers.iter().cloned());
        match self.unknown_entities.as_deref().map(normalize).as_deref() {
            None => {}
            Some("skip") => o.skip_unknown_entities = true,
            Some("error") => o.skip_unknown_entities = false,
            Some(other) => {
                return Err(bad(
                    "unknown_entities".into(),
                    format!("{other:?} is not \"skip\" or \"error\""),
                ))
            }
        }
        match self.speed_unit.as_deref().map(normalize).as_deref() {
            None => {}
            Some("px_per_tick") => o.speed_unit = SpeedUnit::PxPerTick,
            Some("px_per_second") => o.speed_unit = SpeedUnit::PxPerSecond,
            Some(other) => {
                return Err(bad(
                    "speed_unit".into(),
                    format!("{other:?} is not \"px_per_tick\" or \"px_per_second\""),
                ))
            }
        }
        if let Some(r) = self.require_spawn {
            o.require_spawn = r;
        }
        for (from, to) in &self.entities {
            if !crate::entities::is_entity_name(to) {
                return Err(bad(
                    format!("entities.{from}"),
                    format!(
                        "{to:?} is not a ledge entity (known: {})",
                        crate::ENTITY_NAMES.join(", ")
                    ),
                ));
            }
            o.entity_aliases.insert(normalize(from), to.clone());
        }
        for (tileset, ids) in &self.tiles {
            for (id, v) in ids {
                let field = format!("tiles.{tileset}.{id}");
                let n: u32 = id.trim().parse().map_err(|_| {
                    bad(
                        field.clone(),
                        format!("{id:?} is not a tile id (0, 1, 2, ...)"),
                    )
                })?;
                let k = kind(field, v)?;
                o.tile_kinds.insert((tileset.to_lowercase(), n), k);
            }
        }
        for (prop, v) in &self.tile_properties {
            let k = kind(format!("tile_properties.{prop}"), v)?;
            o.tile_properties.insert(normalize(prop), k);
        }
        for (value, v) in &self.grid {
            let k = kind(format!("grid.{value}"), v)?;
            o.mapping = o.mapping.with_grid_value(value, k);
        }
        if let Some(v) = self.scale {
            o.player_scale =
                Some(crate::scale::settings_scale(v).map_err(|m| bad("scale".into(), m))?);
        }
        if let Some(p) = &self.player {
            o.player_size = Some(
                crate::scale::settings_size(p.width, p.height)
                    .map_err(|(k, m)| bad(format!("player.{k}"), m))?,
            );
        }
        Ok(o)
    }
}
