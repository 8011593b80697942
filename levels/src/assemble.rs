//! The importers' common last step: the decoded collision layers overlaid
//! into one tilemap, the entities classified by the name table, a spawn
//! placed when the level has none ([`assemble`]).

use glam::IVec2;

use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::level::{EntityKind, Level};
use ledge_shared::tilemap::{Tile, Tilemap, TilemapError};

use crate::entities::{self, Classified, PlacedEntity};
use crate::error::LevelError;
use crate::loaded::{entity_kind_name, LayerStats, LoadedLevel};
use crate::options::LoadOptions;
use crate::{art, spawn};

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
            player: Default::default(),
        },
        route: Vec::new(),
        warnings: mismatched,
        art: art::LevelArt::default(),
        layers,
    };
    out.level.player = crate::scale::choose(
        file,
        &out.level.tilemap,
        &entities,
        options,
        &mut out.warnings,
    )?;
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
    let scale = out.level.player.scale;
    match entities::classify(file, e, (options.speed_unit, scale), &mut out.warnings)? {
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
    let player = ledge_shared::game::PlayerConfig::default()
        .scaled(&out.level.player)
        .unwrap_or_default();
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
