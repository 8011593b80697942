//! ledge's level importers: OGMO Editor 3 and Tiled files into the
//! simulation's [`Level`] model (`ledge_shared::level`), and the embedded
//! default level.
//!
//! Editor files are translated through a documented name table;
//! `ledge_shared::game::Game::from_level` turns the result into a running
//! simulation. This crate does the file I/O and format parsing so that
//! `ledge-shared` stays pure.
//!
//! * [`load_file`] / [`load_file_with`]: `.json` (OGMO Editor 3 level; the
//!   nearest `.ogmo` project in its folder or up to five folders above is
//!   used) or `.tmx` (Tiled, through the `tiled` crate);
//! * [`ogmo::load_str`], [`tmx::load_str`]: the same from text;
//! * [`default_level`], [`default_route`]: the embedded default level and the
//!   route a runner bot can follow through it;
//! * [`TileMapping`]: editor tile ids and grid values to [`Tile`]s;
//! * [`ENTITY_NAMES`]: the entity name table (see its docs for parameters);
//! * [`LevelError`]: every refusal names the file and the field.
//!
//! Collision layers (OGMO tile and grid layers, Tiled tile layers) are
//! overlaid into one grid in file order: a later layer's non-empty cell
//! replaces an earlier one. They must share one square cell size, cell count
//! and origin. Nothing here panics on any input, and sizes are bounded
//! ([`MAX_LEVEL_TILES`] per side, positions within
//! [`ledge_shared::fixed::MAX_COORD`]).
//! See `docs/LEVELS.md` for the user-facing description.

pub mod art;
pub mod bundle;
mod collision;
mod default;
mod entities;
mod error;
pub mod limits;
mod mapping;
pub mod ogmo;
mod settings;
mod spawn;
pub mod tmx;

use std::collections::BTreeMap;
use std::path::Path;

use glam::IVec2;

pub use bundle::{BundleError, LevelBundle};
pub use default::{
    default_level, default_route, load_default_level, DEFAULT_LEVEL_FILE, DEFAULT_PROJECT_FILE,
};
pub use entities::{
    PlacedEntity, PlacedPolygon, PropValue, DEFAULT_PLATFORM_SPEED, DEFAULT_SPRING_STRENGTH,
    DEFAULT_WALKER_SPEED, ENTITY_NAMES, MAX_PATH_NODES,
};
pub use error::LevelError;
pub use ledge_shared::level::{
    EntityDef, EntityKind, Level, LevelFeatures, PlatformMotion, RouteAction, Waypoint,
};
pub use mapping::{
    parse_tile_kind, tile_kind_name, TileMapping, TileTable, ECHO_SLOPES, LEDGE_TILESET,
    LEDGE_TILESET_NAME,
};
pub use settings::{settings_path_for, LevelSettings, MAX_SETTINGS_BYTES, SETTINGS_SUFFIX};

use entities::Classified;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::tilemap::{Tile, Tilemap, TilemapError};

/// Largest level side, in tiles (grids up to 4096 x 4096).
pub const MAX_LEVEL_TILES: u32 = 4096;
/// Largest level file read from disk, in bytes (64 MiB).
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// How to load a level. [`LevelSettings`] (the settings file beside a
/// level) sets these from TOML.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoadOptions {
    /// Tile ids and grid values to tiles.
    pub mapping: TileMapping,
    /// Skip entities whose name is not in [`ENTITY_NAMES`] (each is listed in
    /// [`LoadedLevel::warnings`]) instead of refusing the file. Default:
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

/// Loads a level the way the server, the client and `ledge-level` do: with
/// the settings file `settings` when given, else the one beside the level
/// ([`settings_path_for`]) when there is one.
pub fn load_level(path: &Path, settings: Option<&Path>) -> Result<LoadedLevel, LevelError> {
    let beside = settings_path_for(path);
    let settings = match settings {
        Some(s) => Some(s.to_path_buf()),
        None if beside.is_file() => Some(beside),
        None => None,
    };
    let options = match &settings {
        Some(s) => {
            LevelSettings::load(s)?.options(&s.display().to_string(), LoadOptions::default())?
        }
        None => LoadOptions::default(),
    };
    load_file_with(path, &options)
}

/// A loaded level and what came with it.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedLevel {
    /// The level.
    pub level: Level,
    /// The bot route: `waypoint` entities in file order (empty when the file
    /// has none).
    pub route: Vec<Waypoint>,
    /// Things skipped, one line each (unknown entities when
    /// [`LoadOptions::skip_unknown_entities`] is set).
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
    }
}

/// Loads a level file with the default options; see [`load_file_with`].
pub fn load_file(path: impl AsRef<Path>) -> Result<Level, LevelError> {
    load_file_with(path, &LoadOptions::default()).map(|l| l.level)
}

/// Loads a level file by extension: `.json` is an OGMO Editor 3 level (its
/// project is the first `.ogmo` file, by name, in the level's folder or the
/// nearest of up to five folders above it; without one, layer kinds are told
/// from their fields and entities need explicit sizes), `.tmx` a Tiled map.
pub fn load_file_with(
    path: impl AsRef<Path>,
    options: &LoadOptions,
) -> Result<LoadedLevel, LevelError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("json") => {
            let text = read_text(path)?;
            let project = match find_project(path) {
                Some(p) => Some((p.display().to_string(), read_text(&p)?)),
                None => None,
            };
            ogmo::load_str(
                &file,
                &text,
                project.as_ref().map(|(f, t)| (f.as_str(), t.as_str())),
                options,
            )
        }
        Some("tmx") => tmx::load_path(path, options),
        _ => Err(LevelError::UnsupportedFormat { file }),
    }
}

/// Reads a file of at most [`MAX_FILE_BYTES`] as UTF-8.
pub(crate) fn read_text(path: &Path) -> Result<String, LevelError> {
    let bytes = read_bytes(path)?;
    String::from_utf8(bytes).map_err(|e| LevelError::Syntax {
        file: path.display().to_string(),
        field: format!("byte {}", e.utf8_error().valid_up_to()),
        format: "UTF-8 text",
        message: e.to_string(),
    })
}

/// Reads a file of at most [`MAX_FILE_BYTES`].
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, LevelError> {
    read_bytes_capped(path, MAX_FILE_BYTES)
}

/// Reads a file of at most `cap` bytes (a larger one is refused unread
/// past the cap).
pub(crate) fn read_bytes_capped(path: &Path, cap: u64) -> Result<Vec<u8>, LevelError> {
    use std::io::Read;
    let io = |e: std::io::Error| LevelError::Io {
        file: path.display().to_string(),
        message: e.to_string(),
    };
    let f = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    f.take(cap + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > cap {
        return Err(LevelError::Io {
            file: path.display().to_string(),
            message: format!("larger than {cap} bytes"),
        });
    }
    Ok(bytes)
}

/// The OGMO project of a level: the first `.ogmo` file by name in the
/// level's folder, else in the nearest of up to five folders above.
fn find_project(level: &Path) -> Option<std::path::PathBuf> {
    let mut dir = level.parent();
    for _ in 0..6 {
        let d = dir?;
        let d = if d.as_os_str().is_empty() {
            Path::new(".")
        } else {
            d
        };
        if let Ok(rd) = std::fs::read_dir(d) {
            let mut found: Vec<_> = rd
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.is_file()
                        && p.extension()
                            .is_some_and(|e| e.eq_ignore_ascii_case("ogmo"))
                })
                .collect();
            found.sort();
            if let Some(p) = found.into_iter().next() {
                return Some(p);
            }
        }
        dir = d.parent();
    }
    None
}

/// One collision layer, decoded, before overlaying.
pub(crate) struct GridLayer {
    /// Path of the layer (`layers[0]`).
    pub field: String,
    /// The layer's name.
    pub name: String,
    /// Top-left corner in units.
    pub origin: IVec2,
    /// Cell width and height, pixels.
    pub cell: (u32, u32),
    /// Cells across and down.
    pub cells: (u32, u32),
    /// Row-major tiles.
    pub tiles: Vec<Tile>,
}

/// Overlays the collision layers, classifies the entities, and checks the
/// level as a whole.
pub(crate) fn assemble(
    file: &str,
    name: String,
    grids: Vec<GridLayer>,
    entities: Vec<PlacedEntity>,
    options: &LoadOptions,
) -> Result<LoadedLevel, LevelError> {
    let layers = grid_stats(&grids);
    let mut mismatched = Vec::new();
    let tilemap = overlay(file, &grids, &mut mismatched)?;
    let mut out = LoadedLevel {
        level: Level {
            name,
            tilemap,
            entities: Vec::with_capacity(entities.len()),
        },
        route: Vec::new(),
        warnings: mismatched,
        art: art::LevelArt::default(),
        layers,
    };
    for e in &entities {
        add_entity(file, e, options, &mut out)?;
    }
    if options.require_spawn
        && !out
            .level
            .entities
            .iter()
            .any(|e| e.kind == EntityKind::PlayerSpawn)
    {
        place_spawn(file, &mut out)?;
    }
    Ok(out)
}

/// The tiles of each collision layer, by kind (a layer is on the grid when
/// it lines up with the first).
fn grid_stats(grids: &[GridLayer]) -> Vec<LayerStats> {
    let mut layers: Vec<LayerStats> = Vec::new();
    for (i, g) in grids.iter().enumerate() {
        let mut st = LayerStats {
            name: g.name.clone(),
            field: g.field.clone(),
            on_grid: i == 0
                || (g.cell, g.cells, g.origin) == (grids[0].cell, grids[0].cells, grids[0].origin),
            ..LayerStats::default()
        };
        for t in &g.tiles {
            match t {
                Tile::Empty => {}
                Tile::Solid => st.solid += 1,
                Tile::OneWay => st.one_way += 1,
                Tile::Hazard => st.hazard += 1,
                Tile::Slope(_) => st.slopes += 1,
            }
        }
        layers.push(st);
    }
    layers
}

/// Overlays the collision layers in file order into the level's tilemap;
/// a layer that does not line up with the first is left out, with a line
/// in `mismatched`.
fn overlay(
    file: &str,
    grids: &[GridLayer],
    mismatched: &mut Vec<String>,
) -> Result<Tilemap, LevelError> {
    let Some((first, rest)) = grids.split_first() else {
        return Tilemap::new(IVec2::ZERO, 16 * UNITS_PER_PX, 0, 0, Vec::new())
            .map_err(|e| tilemap_error(file, "layers", e));
    };
    let (cw, ch) = first.cell;
    if cw != ch {
        return Err(LevelError::BadValue {
            file: file.into(),
            field: first.field.clone(),
            message: format!("collision cells must be square, got {cw} x {ch} px"),
        });
    }
    let mut tiles = first.tiles.clone();
    for g in rest {
        if (g.cell, g.cells, g.origin) != (first.cell, first.cells, first.origin) {
            // Grids of another cell size or origin are not merged
            // (yet): said, not guessed.
            mismatched.push(mismatch_warning(file, g, first));
            continue;
        }
        for (t, &n) in tiles.iter_mut().zip(&g.tiles) {
            if n != Tile::Empty {
                *t = n;
            }
        }
    }
    let size = cw as i64 * UNITS_PER_PX as i64;
    Tilemap::new(
        first.origin,
        size.min(i32::MAX as i64) as i32,
        first.cells.0,
        first.cells.1,
        tiles,
    )
    .map_err(|e| tilemap_error(file, &first.field, e))
}

/// The warning for collision layer `g`, which does not line up with
/// `first`, the level's grid.
fn mismatch_warning(file: &str, g: &GridLayer, first: &GridLayer) -> String {
    format!(
        "{file}: {}: this collision layer of {} x {} cells of {} x {} px at ({}, {}) px does not line up with {} ({} x {} cells of {} x {} px at ({}, {}) px), the level's grid: it does not collide (draw collision on one grid, or choose layers with LoadOptions::collision_layers)",
        g.field,
        g.cells.0,
        g.cells.1,
        g.cell.0,
        g.cell.1,
        g.origin.x / UNITS_PER_PX,
        g.origin.y / UNITS_PER_PX,
        first.field,
        first.cells.0,
        first.cells.1,
        first.cell.0,
        first.cell.1,
        first.origin.x / UNITS_PER_PX,
        first.origin.y / UNITS_PER_PX
    )
}

/// Classifies one placed entity (after the options' aliases) into `out`:
/// an entity (counted in its layer's stats), a route waypoint, or an
/// unknown name (skipped with a warning, or refused, by the options).
fn add_entity(
    file: &str,
    e: &PlacedEntity,
    options: &LoadOptions,
    out: &mut LoadedLevel,
) -> Result<(), LevelError> {
    let aliased;
    let e = match options.entity_name(&e.name) {
        n if n != e.name => {
            aliased = PlacedEntity {
                name: n.to_owned(),
                ..e.clone()
            };
            &aliased
        }
        _ => e,
    };
    match entities::classify(file, e, options.speed_unit)? {
        Classified::Entity(d) => {
            let kind = entity_kind_name(&d.kind);
            let st = match out.layers.iter().position(|l| l.name == e.layer) {
                Some(i) => &mut out.layers[i],
                None => {
                    out.layers.push(LayerStats {
                        name: e.layer.clone(),
                        ..LayerStats::default()
                    });
                    out.layers.last_mut().expect("just pushed")
                }
            };
            *st.entities.entry(kind).or_default() += 1;
            out.level.entities.push(d)
        }
        Classified::Waypoint(w) => out.route.push(w),
        Classified::Unknown if options.skip_unknown_entities => out.warnings.push(format!(
            "{file}: {}: skipped unknown entity {:?} in layer {:?}",
            e.field, e.name, e.layer
        )),
        Classified::Unknown => {
            return Err(LevelError::UnknownEntity {
                file: file.into(),
                field: format!("{}.name", e.field),
                layer: e.layer.clone(),
                name: e.name.clone(),
            });
        }
    }
    Ok(())
}

/// Places a player spawn in a level without one, with a warning saying
/// where: the first free standing spot, else on top of the level.
fn place_spawn(file: &str, out: &mut LoadedLevel) -> Result<(), LevelError> {
    let player = ledge_shared::game::PlayerConfig::default();
    let px = |u: i32| u as f64 / UNITS_PER_PX as f64;
    let (spawn, where_) = match spawn::find(&out.level, &player) {
        Some(s) => (s, "the first free standing spot from the left"),
        None => match spawn::above(&out.level, &player) {
            Some(s) => (
                s,
                "on top of the level at its left edge: there is no free spot to stand on inside it",
            ),
            None => {
                return Err(LevelError::MissingSpawn {
                    file: file.into(),
                    field: "entities".into(),
                })
            }
        },
    };
    out.warnings.push(format!(
        "{file}: no player spawn: players start at ({}, {}) px, {where_} (add an object or entity named \"player\" or \"spawn\" to choose)",
        px(spawn.pos.x),
        px(spawn.pos.y + spawn.size.y / 2)
    ));
    out.level.entities.push(spawn);
    Ok(())
}

fn tilemap_error(file: &str, field: &str, e: TilemapError) -> LevelError {
    match e {
        TilemapError::TileSize { value } => LevelError::BadValue {
            file: file.into(),
            field: format!("{field} (cell size)"),
            message: format!(
                "cell size {} px is not a tile size (whole pixels, at least 1 px)",
                value as f64 / UNITS_PER_PX as f64
            ),
        },
        e => LevelError::OutOfBounds {
            file: file.into(),
            field: field.into(),
            message: e.to_string(),
        },
    }
}
