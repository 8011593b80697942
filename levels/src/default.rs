//! The embedded default level (`levels/default/`, OGMO Editor 3).
//!
//! Named "default"; 100 x 30 tiles of 16 px, ground at row 26, left to
//! right (columns): the spawn (col 5) beside the elevator (an up/down
//! platform, cols 1-3) to a one-way bonus shelf (row 10) with a walker and
//! spikes; a crate block (col 9); a 45 degree peak (cols 12-15); a 22.5
//! degree hill with the first checkpoint (cols 19-25); spike tiles (cols
//! 29-31) under a sideways platform; one-way tiles climbing over a walker
//! trench (cols 35-43) to a high plateau (row 20); two 22.5 degree ramps and
//! a 45 degree step down to a yard (row 23) with the springboard (col 62)
//! that launches to a ledge (row 17, second checkpoint) under a one-way
//! sideways platform; a long 45 degree slope down to the ground (cols
//! 73-81); spike tiles (cols 86-87) under a diagonal, looping platform; the
//! goal (col 96). Coins are scattered along the way and on the bonus areas;
//! a polygon wedge (1:4, 32 x 8 px, cols 9-10) sits on the bonus shelf.
//! `docs/LEVELS.md` draws the grid.
//!
//! The bot route ([`default_route`]) uses only static ground, one-way tiles
//! and the springboard (no platform timing), and asks for at most 2 tiles
//! (32 px) of jump height and 3 tiles (48 px) of gap; the springboard must
//! lift the player 6 tiles (96 px). The map keeps 3 tiles of headroom above
//! every waypoint.

use super::{ogmo, LoadOptions, LoadedLevel, Waypoint};
use super::{Level, LevelError};

/// Name of the embedded default level file (used in messages).
pub const DEFAULT_LEVEL_FILE: &str = "levels/default/default.json";
/// Name of the embedded default project file (used in messages).
pub const DEFAULT_PROJECT_FILE: &str = "levels/default/ledge.ogmo";

const LEVEL_JSON: &str = include_str!("../default/default.json");
const PROJECT_JSON: &str = include_str!("../default/ledge.ogmo");

/// Parses the embedded default level with the default options, with its
/// route. [`default_level`] and [`default_route`] call this; it never fails
/// (a test asserts it).
pub fn load_default_level() -> Result<LoadedLevel, LevelError> {
    ogmo::load_str(
        DEFAULT_LEVEL_FILE,
        LEVEL_JSON,
        Some((DEFAULT_PROJECT_FILE, PROJECT_JSON)),
        &LoadOptions::default(),
    )
}

/// The embedded default level (parsed at each call). It has every entity
/// kind and every tile kind; a test asserts that it loads.
pub fn default_level() -> Level {
    loaded().level
}

/// The runner bot's route through [`default_level`]: from the spawn to the
/// goal, in order (see [`Waypoint`] and the module docs for what it asks
/// of the physics).
pub fn default_route() -> Vec<Waypoint> {
    loaded().route
}

/// Writes the default level into `dir` once per name in `names`
/// (`NAME.json` each, beside one `ledge.ogmo`), returning the level files'
/// paths in order: levels with the default level's geometry and route
/// under other names, so other bundles (another content hash each), for
/// tests and trials of level rotation and downloads.
pub fn write_default_copies(
    dir: &std::path::Path,
    names: &[&str],
) -> std::io::Result<Vec<std::path::PathBuf>> {
    std::fs::write(dir.join("ledge.ogmo"), PROJECT_JSON)?;
    names
        .iter()
        .map(|name| {
            let path = dir.join(format!("{name}.json"));
            std::fs::write(&path, LEVEL_JSON)?;
            Ok(path)
        })
        .collect()
}

fn loaded() -> LoadedLevel {
    match load_default_level() {
        Ok(l) => l,
        // Unreachable: the embedded files are constants and the tests load
        // them (level_ogmo.rs `default_level_*`).
        Err(e) => unreachable!("the embedded default level is invalid: {e}"),
    }
}
