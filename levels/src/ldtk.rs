//! LDtk (1.5.x) projects: `.ldtk` files and the `.ldtkl` files of their
//! levels, when saved separately.
//!
//! A project holds several levels; `PATH.ldtk#LEVEL` picks one by its
//! identifier ([`split_level_path`]), `PATH.ldtk` the first.
//! [`level_names`] lists them in order (the top-level `levels`, then each
//! world's), [`level_paths`] as `PATH.ldtk#LEVEL` paths for a server's
//! rotation. Read with `serde` into the `model` module's structs (only the
//! fields used), after the bounded scan every JSON document gets
//! (`limits::check_json`); every count is then checked against its bound
//! (`MAX_LDTK_*`, `MAX_LEVEL_CELLS`) before anything is built from it.
//!
//! * **IntGrid layers** collide by their values' identifiers (the `layers`
//!   module: walls/solid/ground → solid, one_way/platform → one-way,
//!   spikes/lava → hazard, ladder/water → refused with a warning, read as
//!   empty; unknown and unnamed values solid, with a warning).
//! * **Tile layers, auto-layers** and IntGrid auto-tiles are drawn (the
//!   `art` module); they collide only when the settings list them.
//! * **Entities** by identifier and fields (the `entities` module).
//! * **External levels** (`externalRelPath`) are read relative to the
//!   project, and must stay inside its folder: a path with `..`, a root or
//!   a drive, or one that resolves outside it, is refused.
//!
//! The level's name is its identifier; errors and warnings about a level
//! name it as `PROJECT.ldtk#LEVEL` (its `.ldtkl` file when it has one),
//! with the field path inside it (`layerInstances[2].intGridCsv[17]`).

mod art;
mod entities;
mod layers;
mod model;

use std::path::{Component, Path, PathBuf};

use crate::assemble::assemble;
use crate::error::LevelError;
use crate::limits::{
    check_count, MAX_LDTK_DEFS, MAX_LDTK_ENTITIES, MAX_LDTK_LAYERS, MAX_LDTK_LEVELS,
    MAX_LDTK_TILES, MAX_TILESETS,
};
use crate::loaded::LoadedLevel;
use crate::options::LoadOptions;
use crate::read::read_text;

/// The format name in syntax errors about a project.
const PROJECT_FORMAT: &str = "LDtk project JSON";
/// The format name in syntax errors about an external level.
const LEVEL_FORMAT: &str = "LDtk level JSON";

/// Splits `PATH.ldtk#LEVEL` into the project and the level identifier;
/// `PATH.ldtk` gives no level. `None` when the path is not an LDtk project
/// (by its extension, any case). `PATH.ldtk#` gives an empty name (refused
/// when loading).
pub fn split_level_path(path: &Path) -> Option<(PathBuf, Option<String>)> {
    let is_ldtk = |p: &Path| {
        p.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ldtk"))
    };
    if let Some(s) = path.to_str() {
        if let Some((project, level)) = s.rsplit_once('#') {
            let project = Path::new(project);
            if is_ldtk(project) {
                return Some((project.to_path_buf(), Some(level.to_owned())));
            }
        }
    }
    is_ldtk(path).then(|| (path.to_path_buf(), None))
}

/// The identifiers of an LDtk project's levels, in order (top-level
/// `levels`, then each world's). A `#LEVEL` suffix on `path` is ignored.
pub fn level_names(path: impl AsRef<Path>) -> Result<Vec<String>, LevelError> {
    let path = path.as_ref();
    let project = split_level_path(path).map_or_else(|| path.to_path_buf(), |(p, _)| p);
    let file = project.display().to_string();
    let text = read_text(&project)?;
    let names: model::Names = model::parse(&file, &text, PROJECT_FORMAT)?;
    let all: Vec<String> = names
        .levels
        .into_iter()
        .chain(names.worlds.into_iter().flat_map(|w| w.levels))
        .map(|l| l.identifier)
        .collect();
    check_count(
        &file,
        "levels",
        "levels",
        all.len() as u64,
        MAX_LDTK_LEVELS,
        "MAX_LDTK_LEVELS",
    )?;
    Ok(all)
}

/// Every level of an LDtk project as a path [`crate::load_level`] loads:
/// `PATH.ldtk#LEVEL`, in [`level_names`] order.
pub fn level_paths(path: impl AsRef<Path>) -> Result<Vec<PathBuf>, LevelError> {
    let path = path.as_ref();
    let project = split_level_path(path).map_or_else(|| path.to_path_buf(), |(p, _)| p);
    let base = project.as_os_str().to_os_string();
    Ok(level_names(&project)?
        .into_iter()
        .map(|name| {
            let mut p = base.clone();
            p.push("#");
            p.push(name);
            PathBuf::from(p)
        })
        .collect())
}

/// Loads level `level` (its identifier; `None`: the first) of the LDtk
/// project at `path`. External levels and images are read relative to the
/// project's folder.
pub fn load_path(
    path: &Path,
    level: Option<&str>,
    options: &LoadOptions,
) -> Result<LoadedLevel, LevelError> {
    let file = path.display().to_string();
    let text = read_text(path)?;
    // The project's folder (empty for a bare file name: paths then stay
    // relative to the working folder, as given).
    let dir = path.parent().unwrap_or(Path::new(""));
    load(&file, Some(dir), &text, level, options)
}

/// Loads level `level` (`None`: the first) of an LDtk project given as
/// text; `file` names it in errors. Nothing is read from disk: a level in
/// its own file is refused, and images are left out (with warnings).
pub fn load_str(
    file: &str,
    text: &str,
    level: Option<&str>,
    options: &LoadOptions,
) -> Result<LoadedLevel, LevelError> {
    crate::limits::check_count(
        file,
        "(document)",
        "bytes",
        text.len() as u64,
        crate::options::MAX_FILE_BYTES,
        "MAX_FILE_BYTES",
    )?;
    load(file, None, text, level, options)
}

/// The project's level `level` (`None`: the first): its index and entry.
fn pick<'p>(
    file: &str,
    levels: &[&'p model::Level],
    level: Option<&str>,
) -> Result<(usize, &'p model::Level), LevelError> {
    let known = || {
        let names: Vec<&str> = levels.iter().map(|l| l.identifier.as_str()).collect();
        if names.is_empty() {
            "none".to_owned()
        } else {
            names.join(", ")
        }
    };
    let unknown = |problem: String| LevelError::UnknownLevel {
        file: file.into(),
        field: "levels".into(),
        problem,
        known: known(),
    };
    match level {
        None => levels
            .first()
            .map(|l| (0, *l))
            .ok_or_else(|| unknown("the project has no levels".into())),
        Some("") => Err(unknown(
            "no level name after '#' (write PROJECT.ldtk#LEVEL_IDENTIFIER)".into(),
        )),
        Some(name) => levels
            .iter()
            .position(|l| l.identifier == name)
            .map(|i| (i, levels[i]))
            .ok_or_else(|| unknown(format!("no level {name:?} in this LDtk project"))),
    }
}

/// Parses the project, picks the level, reads its layers (from its own
/// file when it has one) and builds it.
fn load(
    file: &str,
    dir: Option<&Path>,
    text: &str,
    level: Option<&str>,
    options: &LoadOptions,
) -> Result<LoadedLevel, LevelError> {
    let project: model::Project = model::parse(file, text, PROJECT_FORMAT)?;
    check_defs(file, &project)?;
    let levels: Vec<&model::Level> = project
        .levels
        .iter()
        .chain(project.worlds.iter().flat_map(|w| &w.levels))
        .collect();
    check_count(
        file,
        "levels",
        "levels",
        levels.len() as u64,
        MAX_LDTK_LEVELS,
        "MAX_LDTK_LEVELS",
    )?;
    let (index, entry) = pick(file, &levels, level)?;
    let external;
    let (label, layers) = match (&entry.layer_instances, &entry.external_rel_path) {
        (Some(layers), _) => (format!("{file}#{}", entry.identifier), layers),
        (None, Some(rel)) => {
            let field = format!("levels[{index}].externalRelPath");
            let (label, lv) = read_external(file, dir, &field, rel)?;
            external = lv;
            let layers = external
                .layer_instances
                .as_ref()
                .ok_or_else(|| missing(&label))?;
            (label, layers)
        }
        (None, None) => return Err(missing(&format!("{file}#{}", entry.identifier))),
    };
    build(&label, dir, &project, entry, layers, options)
}

fn missing(file: &str) -> LevelError {
    LevelError::Missing {
        file: file.into(),
        field: "layerInstances".into(),
        hint: " (the level has neither layers nor an externalRelPath to its own file)".into(),
    }
}

/// The project's definitions within their bounds.
fn check_defs(file: &str, p: &model::Project) -> Result<(), LevelError> {
    let defs = &p.defs;
    check_count(
        file,
        "defs.tilesets",
        "tilesets",
        defs.tilesets.len() as u64,
        MAX_TILESETS,
        "MAX_TILESETS",
    )?;
    check_count(
        file,
        "defs.layers",
        "layer definitions",
        defs.layers.len() as u64,
        MAX_LDTK_DEFS,
        "MAX_LDTK_DEFS",
    )?;
    for (i, l) in defs.layers.iter().enumerate() {
        check_count(
            file,
            format!("defs.layers[{i}].intGridValues"),
            "IntGrid values",
            l.int_grid_values.len() as u64,
            MAX_LDTK_DEFS,
            "MAX_LDTK_DEFS",
        )?;
    }
    Ok(())
}

/// Reads an external level `rel` (`field` names it in the project), which
/// must lie inside the project's folder `dir`: its label (the file) and
/// its level.
fn read_external(
    file: &str,
    dir: Option<&Path>,
    field: &str,
    rel: &str,
) -> Result<(String, model::Level), LevelError> {
    let refuse = |why: String| model::bad(file, field, why);
    let Some(dir) = dir else {
        return Err(refuse(format!(
            "the level is in its own file {rel:?}, and the project was given as text: load the project from its file"
        )));
    };
    let relp = Path::new(rel);
    let escapes = rel.is_empty()
        || relp
            .components()
            .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir));
    if escapes {
        return Err(refuse(format!(
            "external level path {rel:?} leaves the project's folder (a '..', root or drive): a level's own file must be in the project's folder or below it"
        )));
    }
    let path = dir.join(relp);
    let here = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    if let (Ok(d), Ok(p)) = (here.canonicalize(), path.canonicalize()) {
        if !p.starts_with(&d) {
            return Err(refuse(format!(
                "external level path {rel:?} resolves to {}, outside the project's folder {} (a symbolic link?)",
                p.display(),
                d.display()
            )));
        }
    }
    let label = path.display().to_string();
    let text = read_text(&path)?;
    let level: model::Level = model::parse(&label, &text, LEVEL_FORMAT)?;
    Ok((label, level))
}

/// Builds one level from its layers (top-most first).
fn build(
    file: &str,
    dir: Option<&Path>,
    project: &model::Project,
    level: &model::Level,
    layers: &[model::LayerInstance],
    options: &LoadOptions,
) -> Result<LoadedLevel, LevelError> {
    check_level(file, layers)?;
    let mut warnings = Vec::new();
    let grids = layers::collision(file, layers, &project.defs, options, &mut warnings)?;
    if !layers.iter().any(|l| l.kind == "IntGrid") && grids.is_empty() {
        warnings.push(format!(
            "{file}: the level has no IntGrid layer, so its tiles do not collide (add an IntGrid layer named Collisions with a value named walls, or list a tile layer in collision_layers in the level's settings file)"
        ));
    }
    let mut placed = Vec::new();
    for (i, l) in layers.iter().enumerate() {
        if l.kind != "Entities" || l.entity_instances.is_empty() {
            continue;
        }
        let field = format!("layerInstances[{i}]");
        if !l.visible {
            warnings.push(format!(
                "{file}: {field}: entity layer {:?} is hidden: its {} entities are ignored (make it visible in LDtk to use them)",
                l.identifier,
                l.entity_instances.len()
            ));
            continue;
        }
        entities::placed(file, &field, l, options, &mut placed, &mut warnings)?;
    }
    let art = art::level_art(file, dir, project, level, layers)?;
    let mut loaded = assemble(file, level.identifier.clone(), grids, placed, options)?;
    loaded.warnings.splice(0..0, warnings);
    loaded.art = art;
    Ok(loaded)
}

/// A level's counts within their bounds: layers, entities, placed tiles.
fn check_level(file: &str, layers: &[model::LayerInstance]) -> Result<(), LevelError> {
    check_count(
        file,
        "layerInstances",
        "layers",
        layers.len() as u64,
        MAX_LDTK_LAYERS,
        "MAX_LDTK_LAYERS",
    )?;
    let (mut ents, mut tiles) = (0u64, 0u64);
    for (i, l) in layers.iter().enumerate() {
        ents += l.entity_instances.len() as u64;
        tiles += (l.auto_layer_tiles.len() + l.grid_tiles.len()) as u64;
        let field = format!("layerInstances[{i}]");
        check_count(
            file,
            &field,
            "entities in all layers",
            ents,
            MAX_LDTK_ENTITIES,
            "MAX_LDTK_ENTITIES",
        )?;
        check_count(
            file,
            &field,
            "placed tiles in all layers",
            tiles,
            MAX_LDTK_TILES,
            "MAX_LDTK_TILES",
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_paths_split() {
        let s = |p: &str| split_level_path(Path::new(p));
        assert_eq!(
            s("a/game.ldtk#Level_2"),
            Some((PathBuf::from("a/game.ldtk"), Some("Level_2".into())))
        );
        assert_eq!(s("a/game.LDtk"), Some((PathBuf::from("a/game.LDtk"), None)));
        assert_eq!(
            s("game.ldtk#"),
            Some((PathBuf::from("game.ldtk"), Some(String::new())))
        );
        assert_eq!(s("a#b.ldtk"), Some((PathBuf::from("a#b.ldtk"), None)));
        assert_eq!(s("level.json"), None);
        assert_eq!(s("level.json#x"), None);
    }
}
