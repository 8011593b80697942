//! Loading a level file by its extension (OGMO `.json` with its project,
//! Tiled `.tmx`, LDtk `.ldtk` with an optional `#LEVEL`), with its settings
//! file: the importers' entry points.

use std::path::Path;

use ledge_shared::level::Level;

use crate::error::LevelError;
use crate::loaded::LoadedLevel;
use crate::options::LoadOptions;
use crate::read::read_text;
use crate::settings::{settings_path_for, LevelSettings};
use crate::{ldtk, ogmo, tmx};

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

/// Loads a level file with the default options; see [`load_file_with`].
pub fn load_file(path: impl AsRef<Path>) -> Result<Level, LevelError> {
    load_file_with(path, &LoadOptions::default()).map(|l| l.level)
}

/// Loads a level file by extension: `.json` is an OGMO Editor 3 level (its
/// project is the first `.ogmo` file, by name, in the level's folder or the
/// nearest of up to five folders above it; without one, layer kinds are told
/// from their fields and entities need explicit sizes), `.tmx` a Tiled map,
/// `.ldtk` an LDtk project: `PATH.ldtk#LEVEL` loads the level of that
/// identifier, `PATH.ldtk` its first level (see [`ldtk::level_names`]). An
/// `.ldtkl` file (one level of a project) is refused: load its project.
pub fn load_file_with(
    path: impl AsRef<Path>,
    options: &LoadOptions,
) -> Result<LoadedLevel, LevelError> {
    let path = path.as_ref();
    if let Some((project, level)) = ldtk::split_level_path(path) {
        return ldtk::load_path(&project, level.as_deref(), options);
    }
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
        Some("ldtkl") => Err(LevelError::BadValue {
            file,
            field: "(document)".into(),
            message: "an .ldtkl file is one level of an LDtk project, without the project's definitions: load the project instead (PROJECT.ldtk#LEVEL_IDENTIFIER)".into(),
        }),
        _ => Err(LevelError::UnsupportedFormat { file }),
    }
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
