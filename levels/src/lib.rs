//! ledge's level importers: OGMO Editor 3, Tiled and LDtk files into the
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
//!   used), `.tmx` (Tiled, through the `tiled` crate) or `.ldtk` (an LDtk
//!   project: `PATH.ldtk#LEVEL` one of its levels, `PATH.ldtk` the first;
//!   [`ldtk::level_names`] lists them);
//! * [`ogmo::load_str`], [`tmx::load_str`], [`ldtk::load_str`]: the same
//!   from text;
//! * [`default_level`], [`default_route`]: the embedded default level and the
//!   route a runner bot can follow through it;
//! * [`TileMapping`]: editor tile ids and grid values to [`Tile`](ledge_shared::tilemap::Tile)s;
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
mod assemble;
pub mod bundle;
mod collision;
mod default;
mod entities;
mod error;
pub mod ldtk;
pub mod limits;
mod load;
mod loaded;
mod mapping;
pub mod ogmo;
mod options;
pub mod overlay;
pub mod palette;
mod read;
#[cfg(feature = "render")]
pub mod render;
pub mod report;
pub mod scale;
mod settings;
mod spawn;
pub mod tmx;

pub use bundle::{BundleError, LevelBundle};
pub use default::{
    default_level, default_route, load_default_level, write_default_copies, DEFAULT_LEVEL_FILE,
    DEFAULT_PROJECT_FILE,
};
pub use entities::{
    PlacedEntity, PlacedPolygon, PropValue, Turn, DEFAULT_PLATFORM_SPEED, DEFAULT_SPRING_STRENGTH,
    DEFAULT_WALKER_SPEED, ENTITY_NAMES, MAX_PATH_NODES, SPAWN_NAMES,
};
pub use error::LevelError;
pub use ledge_shared::level::{
    EntityDef, EntityKind, Level, LevelFeatures, PlatformMotion, RouteAction, Trigger, Waypoint,
};
pub use load::{load_file, load_file_with, load_level};
pub use loaded::{entity_kind_name, LayerStats, LoadedLevel};
pub use mapping::{
    parse_tile_kind, tile_kind_name, TileMapping, TileTable, ECHO_SLOPES, LEDGE_TILESET,
    LEDGE_TILESET_NAME,
};
pub use options::{LoadOptions, SpeedUnit, MAX_FILE_BYTES, MAX_LEVEL_TILES, TICKS_PER_SECOND};
pub use settings::{settings_path_for, LevelSettings, MAX_SETTINGS_BYTES, SETTINGS_SUFFIX};
