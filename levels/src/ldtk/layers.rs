//! What collides in an LDtk level: its IntGrid layers, value by value, by
//! the values' identifiers (and the settings file), as the importers'
//! collision layers ([`GridLayer`]).
//!
//! * Which layers: the visible IntGrid layers named for collision
//!   (`Collisions`, `Collision`, `Solid`, `Walls`, `Ground`, ...: the
//!   collision words of `docs/LEVELS.md`) decide; when none is, every
//!   visible IntGrid layer does. The settings' `collision_layers` and
//!   `decoration_layers` choose instead; a tile or auto-layer listed in
//!   `collision_layers` collides too, every placed tile solid.
//! * The level's grid is the top-most deciding layer's that has a
//!   non-empty cell (else the top-most's): a deciding layer of another cell
//!   size, cell count or offset is not resampled but left out, with a
//!   warning (`assemble`'s; the warnings about its values are not given).
//!   Where deciding layers on the grid overlap, the upper one's non-empty
//!   cell wins.
//! * Values: by identifier ([`value_kind`]); hidden layers neither collide
//!   nor draw.

use std::collections::BTreeMap;

use ledge_shared::tilemap::Tile;

use super::model::{self, Defs, IntGridValueDef, LayerInstance};
use crate::assemble::GridLayer;
use crate::error::LevelError;
use crate::limits::MAX_LEVEL_CELLS;
use crate::mapping::{normalize, parse_tile_kind};
use crate::options::LoadOptions;

/// IntGrid identifiers read as solid (after `normalize`).
const SOLID: &[&str] = &[
    "solid",
    "solids",
    "wall",
    "walls",
    "ground",
    "block",
    "blocks",
    "terrain",
    "floor",
    "floors",
    "collision",
    "collisions",
    "collider",
    "solid_platform",
    "platform_solid",
    "dirt",
    "stone",
    "stones",
    "rock",
    "rocks",
    "brick",
    "bricks",
    "metal",
    "wood",
    "earth",
    "sand",
];
/// IntGrid identifiers read as one-way (solid from above only).
const ONE_WAY: &[&str] = &[
    "one_way",
    "oneway",
    "one_way_platform",
    "platform",
    "platforms",
    "jumpthrough",
    "jump_through",
    "semisolid",
    "semi_solid",
    "pass_through",
    "passthrough",
];
/// IntGrid identifiers read as hazards.
const HAZARD: &[&str] = &[
    "hazard", "hazards", "spike", "spikes", "lava", "death", "deadly", "kill", "acid",
];
/// IntGrid identifiers read as empty, silently.
const EMPTY: &[&str] = &[
    "empty",
    "none",
    "air",
    "nothing",
    "background",
    "bg",
    "decoration",
    "decor",
];
/// IntGrid identifiers of things ledge has no tile for: read as empty,
/// with a warning.
const UNSUPPORTED: &[&str] = &[
    "ladder",
    "ladders",
    "water",
    "deep_water",
    "liquid",
    "swim",
    "rope",
    "ropes",
    "vine",
    "vines",
    "climb",
    "climbable",
    "conveyor",
    "quicksand",
    "mud",
    "bounce",
    "bouncy",
    "door",
    "doors",
    "teleport",
];

/// What an IntGrid value is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ValueKind {
    /// A ledge tile, by its identifier (or the settings' `[grid]`).
    Known(Tile),
    /// Something ledge has no tile for (`ladder`, `water`): empty, warned.
    Unsupported,
    /// A name ledge does not know: solid, warned.
    Unknown,
    /// A value with no identifier: solid, warned.
    Unnamed,
    /// A value the layer's definition does not have: solid, warned.
    Undefined,
}

impl ValueKind {
    /// The tile the cell becomes.
    pub fn tile(self) -> Tile {
        match self {
            ValueKind::Known(t) => t,
            ValueKind::Unsupported => Tile::Empty,
            _ => Tile::Solid,
        }
    }
}

/// What IntGrid value `def` (`None`: not defined) is: the settings'
/// `[grid]` entry or a tile kind name for its identifier first, then the
/// tables above.
pub(crate) fn value_kind(def: Option<&IntGridValueDef>, options: &LoadOptions) -> ValueKind {
    let Some(def) = def else {
        return ValueKind::Undefined;
    };
    let Some(id) = def.identifier.as_deref().filter(|s| !s.trim().is_empty()) else {
        return ValueKind::Unnamed;
    };
    let n = normalize(id);
    if let Some(t) = options
        .mapping
        .grid_tile(id)
        .or_else(|| options.mapping.grid_tile(&n))
        .or_else(|| parse_tile_kind(id))
    {
        return ValueKind::Known(t);
    }
    let is = |list: &[&str]| list.contains(&n.as_str());
    if is(SOLID) {
        ValueKind::Known(Tile::Solid)
    } else if is(ONE_WAY) {
        ValueKind::Known(Tile::OneWay)
    } else if is(HAZARD) {
        ValueKind::Known(Tile::Hazard)
    } else if is(EMPTY) {
        ValueKind::Known(Tile::Empty)
    } else if is(UNSUPPORTED) {
        ValueKind::Unsupported
    } else {
        ValueKind::Unknown
    }
}

/// How a layer collides, before its cells are read.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    /// By its IntGrid values.
    Values,
    /// Every placed tile solid (a tile layer listed in `collision_layers`).
    AllSolid,
}

/// The collision layers of a level's `layers` (top-most first), in the
/// order `assemble` overlays them, and the warnings about them. `file`
/// names the level in errors and warnings.
pub(crate) fn collision(
    file: &str,
    layers: &[LayerInstance],
    defs: &Defs,
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Result<Vec<GridLayer>, LevelError> {
    let roles = roles(file, layers, options, warnings)?;
    let mut grids: Vec<GridLayer> = Vec::new();
    // Per grid, the warnings about its values (said only if it collides).
    let mut notes: Vec<Vec<String>> = Vec::new();
    // Every colliding layer's size is checked, and counted towards
    // MAX_LEVEL_CELLS, before any layer's cells are built.
    let mut cells = 0u64;
    let mut sizes = Vec::with_capacity(roles.len());
    for &(i, _) in &roles {
        let l = &layers[i];
        let field = format!("layerInstances[{i}]");
        let cell = model::grid_size(file, &field, l.grid_size)?;
        let (w, h) = model::cells(file, &field, l)?;
        cells += w as u64 * h as u64;
        crate::limits::check_count(
            file,
            &field,
            "IntGrid and collision cells in all layers",
            cells,
            MAX_LEVEL_CELLS,
            "MAX_LEVEL_CELLS",
        )?;
        sizes.push((cell, (w, h)));
    }
    for ((i, role), (cell, (w, h))) in roles.into_iter().zip(sizes) {
        let l = &layers[i];
        let field = format!("layerInstances[{i}]");
        let mut said = Vec::new();
        let tiles = match role {
            Role::Values => int_grid(file, &field, l, (w, h), defs, options, &mut said)?,
            Role::AllSolid => tile_cells(l, (w, h), cell),
        };
        let origin = model::offset_units(file, &field, l)?;
        grids.push(GridLayer {
            field,
            name: l.identifier.clone(),
            origin,
            cell: (cell, cell),
            cells: (w, h),
            tiles,
        });
        notes.push(said);
    }
    choose_grid(&mut grids, notes, warnings);
    mask_lower(&mut grids);
    Ok(grids)
}

/// Puts the layer that sets the level's grid first: the top-most deciding
/// layer with a non-empty cell (else the top-most). Gives the warnings
/// about the values (`notes`, one list per layer) of the layers on that
/// grid, and drops empty layers off it (they add nothing, and are not
/// reported as layers that do not line up).
fn choose_grid(
    grids: &mut Vec<GridLayer>,
    mut notes: Vec<Vec<String>>,
    warnings: &mut Vec<String>,
) {
    if let Some(k) = grids
        .iter()
        .position(|g| g.tiles.iter().any(|t| *t != Tile::Empty))
    {
        let g = grids.remove(k);
        grids.insert(0, g);
        let n = notes.remove(k);
        notes.insert(0, n);
    }
    if let Some(first) = grids.first() {
        let key = (first.cell, first.cells, first.origin);
        for (g, said) in grids.iter().zip(notes) {
            if (g.cell, g.cells, g.origin) == key {
                warnings.extend(said);
            }
        }
    }
    if let Some(first) = grids.first() {
        let key = (first.cell, first.cells, first.origin);
        let keep: Vec<bool> = grids
            .iter()
            .enumerate()
            .map(|(i, g)| {
                i == 0
                    || (g.cell, g.cells, g.origin) == key
                    || g.tiles.iter().any(|t| *t != Tile::Empty)
            })
            .collect();
        let mut keep = keep.into_iter();
        grids.retain(|_| keep.next().unwrap_or(true));
    }
}

/// The layers that collide (index into `layers`, top-most first) and how;
/// warnings for IntGrid layers that do not.
fn roles(
    file: &str,
    layers: &[LayerInstance],
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Result<Vec<(usize, Role)>, LevelError> {
    let mut int_grids = Vec::new();
    let mut out = Vec::new();
    for (i, l) in layers.iter().enumerate() {
        let listed = options.layer_collides(&l.identifier);
        let field = format!("layerInstances[{i}]");
        match l.kind.as_str() {
            "IntGrid" | "Tiles" | "AutoLayer" if !l.visible => {
                let filled = l.int_grid_csv.iter().any(|&v| v != 0);
                if listed == Some(true) || (l.kind == "IntGrid" && filled && listed.is_none()) {
                    warnings.push(format!(
                        "{file}: {field}: layer {:?} is hidden: it neither collides nor is drawn (make it visible in LDtk)",
                        l.identifier
                    ));
                }
            }
            "IntGrid" if listed != Some(false) => int_grids.push((i, listed)),
            "Tiles" | "AutoLayer" if listed == Some(true) => out.push((i, Role::AllSolid)),
            "IntGrid" | "Tiles" | "AutoLayer" | "Entities" => {}
            other => {
                return Err(LevelError::UnknownLayer {
                    file: file.into(),
                    field: format!("{field}.__type"),
                    kind: other.into(),
                })
            }
        }
    }
    let named: Vec<usize> = int_grids
        .iter()
        .filter(|(i, listed)| {
            *listed == Some(true)
                || crate::collision::is_collision_layer_name(&layers[*i].identifier)
        })
        .map(|(i, _)| *i)
        .collect();
    for &(i, _) in &int_grids {
        if named.is_empty() || named.contains(&i) {
            out.push((i, Role::Values));
        } else if layers[i].int_grid_csv.iter().any(|&v| v != 0) {
            let names: Vec<&str> = named
                .iter()
                .map(|&n| layers[n].identifier.as_str())
                .collect();
            warnings.push(format!(
                "{file}: layerInstances[{i}]: IntGrid layer {:?} does not collide: the IntGrid layers named for collision ({}) decide (list it in collision_layers in the level's settings file to make it collide)",
                layers[i].identifier,
                names.join(", ")
            ));
        }
    }
    out.sort_by_key(|&(i, _)| i);
    Ok(out)
}

/// An IntGrid layer's cells as tiles, with one warning per value that is
/// not a plain ledge tile (its first cell, how many cells, what it became).
fn int_grid(
    file: &str,
    field: &str,
    l: &LayerInstance,
    (w, h): (u32, u32),
    defs: &Defs,
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Result<Vec<Tile>, LevelError> {
    let n = w as usize * h as usize;
    let csv = &l.int_grid_csv;
    if csv.len() != n {
        return Err(LevelError::Length {
            file: file.into(),
            field: format!("{field}.intGridCsv"),
            expected: n as u64,
            got: csv.len() as u64,
        });
    }
    let def = defs
        .layers
        .iter()
        .find(|d| l.layer_def_uid == Some(d.uid))
        .or_else(|| defs.layers.iter().find(|d| d.identifier == l.identifier));
    let values = def.map_or(&[][..], |d| d.int_grid_values.as_slice());
    // value -> (kind, first cell, cells)
    let mut seen: BTreeMap<i64, (ValueKind, usize, usize)> = BTreeMap::new();
    let mut tiles = Vec::with_capacity(n);
    for (k, &v) in csv.iter().enumerate() {
        if v == 0 {
            tiles.push(Tile::Empty);
            continue;
        }
        if v < 0 {
            return Err(model::bad(
                file,
                format!("{field}.intGridCsv[{k}]"),
                format!("IntGrid value {v} is negative (0 is an empty cell, values start at 1)"),
            ));
        }
        let e = seen.entry(v).or_insert_with(|| {
            let kind = value_kind(values.iter().find(|d| d.value == v), options);
            (kind, k, 0)
        });
        e.2 += 1;
        tiles.push(e.0.tile());
    }
    for (v, (kind, first, count)) in seen {
        let ident = values
            .iter()
            .find(|d| d.value == v)
            .and_then(|d| d.identifier.clone())
            .unwrap_or_default();
        if let Some(said) = describe(v, &ident, kind) {
            warnings.push(format!(
                "{file}: {field}.intGridCsv[{first}] (column {}, row {}): IntGrid value {v}{} of layer {:?} ({count} cells) {said}",
                first % w.max(1) as usize,
                first / w.max(1) as usize,
                if ident.is_empty() { String::new() } else { format!(" {ident:?}") },
                l.identifier
            ));
        }
    }
    Ok(tiles)
}

/// The end of the warning for a value of kind `kind`; `None` for a plain
/// ledge tile.
fn describe(v: i64, ident: &str, kind: ValueKind) -> Option<String> {
    let key = if ident.is_empty() { "NAME" } else { ident };
    Some(match kind {
        ValueKind::Known(_) => return None,
        ValueKind::Unsupported => format!(
            "is not supported in ledge (it has no such tile): read as empty; make it solid, one-way or a hazard under [grid] in the level's settings file ({key} = \"solid\")"
        ),
        ValueKind::Unknown => format!(
            "is not a name ledge knows: read as solid (solid names: walls, ground, solid, ...; one-way: one_way, platform, jumpthrough; hazards: spikes, lava, death; or set {key} = \"KIND\" under [grid] in the level's settings file)"
        ),
        ValueKind::Unnamed => format!(
            "has no identifier: read as solid (name it in LDtk's layer settings: walls, one_way, spikes, ...; value {v})"
        ),
        ValueKind::Undefined => {
            "is not one of the layer's IntGrid values (its definition has no such value): read as solid".to_string()
        }
    })
}

/// The cells of a tile or auto-layer that hold a tile (every one solid);
/// tiles outside the layer's grid are left out.
fn tile_cells(l: &LayerInstance, (w, h): (u32, u32), cell: u32) -> Vec<Tile> {
    let mut tiles = vec![Tile::Empty; w as usize * h as usize];
    let (placed, _) = l.tiles();
    for t in placed {
        let (cx, cy) = (
            t.px[0].div_euclid(cell as i64),
            t.px[1].div_euclid(cell as i64),
        );
        if (0..w as i64).contains(&cx) && (0..h as i64).contains(&cy) {
            tiles[cy as usize * w as usize + cx as usize] = Tile::Solid;
        }
    }
    tiles
}

/// Empties each layer's cells that an upper layer on the same grid (the
/// first layer's) already fills, so the upper layer wins where they overlap
/// (`assemble` lets a later layer win).
fn mask_lower(grids: &mut [GridLayer]) {
    let Some((first, rest)) = grids.split_first_mut() else {
        return;
    };
    let same =
        |g: &GridLayer| (g.cell, g.cells, g.origin) == (first.cell, first.cells, first.origin);
    let mut taken: Vec<bool> = first.tiles.iter().map(|t| *t != Tile::Empty).collect();
    for g in rest.iter_mut().filter(|g| same(g)) {
        for (t, taken) in g.tiles.iter_mut().zip(taken.iter_mut()) {
            if *taken {
                *t = Tile::Empty;
            } else if *t != Tile::Empty {
                *taken = true;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn def(id: Option<&str>) -> IntGridValueDef {
        IntGridValueDef {
            value: 1,
            identifier: id.map(str::to_owned),
        }
    }

    #[test]
    fn values_by_identifier() {
        let o = LoadOptions::default();
        let k = |id| value_kind(Some(&def(Some(id))), &o);
        assert_eq!(k("Walls"), ValueKind::Known(Tile::Solid));
        assert_eq!(k("dirt"), ValueKind::Known(Tile::Solid));
        assert_eq!(k("One-Way"), ValueKind::Known(Tile::OneWay));
        assert_eq!(k("jumpthrough"), ValueKind::Known(Tile::OneWay));
        assert_eq!(k("Spikes"), ValueKind::Known(Tile::Hazard));
        assert_eq!(k("ladder"), ValueKind::Unsupported);
        assert_eq!(k("water"), ValueKind::Unsupported);
        assert_eq!(k("bouncy_goo"), ValueKind::Unknown);
        assert_eq!(value_kind(Some(&def(None)), &o), ValueKind::Unnamed);
        assert_eq!(value_kind(None, &o), ValueKind::Undefined);
        assert_eq!(ValueKind::Unsupported.tile(), Tile::Empty);
        assert_eq!(ValueKind::Unnamed.tile(), Tile::Solid);
        // The settings' [grid] wins.
        let mut o = LoadOptions::default();
        o.mapping = o.mapping.with_grid_value("ladder", Tile::OneWay);
        assert_eq!(
            value_kind(Some(&def(Some("ladder"))), &o),
            ValueKind::Known(Tile::OneWay)
        );
    }
}
