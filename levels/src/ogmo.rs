//! OGMO Editor 3: the project (`.ogmo`) and level (`.json`) files.
//!
//! Read with `serde_json` into a generic value and walked by hand, so every
//! error names the exact field (`layers[2].dataCoords[41]`). What is read:
//!
//! * **Project** (optional but usually needed): layer definitions (to tell a
//!   layer's kind, matched by export id, then name), entity definitions
//!   (default `size` and `origin` of entities whose level entry omits them),
//!   tilesets (tile size, separation, margin, and the embedded PNG's width,
//!   for the column count that turns tile coordinates into ids).
//! * **Tile layers**, in every export mode: `data` (ids, 1D), `data2D` (ids,
//!   rows), `dataCoords` (`[x, y]` or `[-1]` per cell, 1D), `dataCoords2D`;
//!   `exportMode` 0/1 is ids/coords and `arrayMode` 0/1 is 1D/2D, and when
//!   present they say which field must be there. `-1` is an empty cell.
//! * **Grid layers**: `grid` (1D) or `grid2D`, string cell values.
//! * **Entity layers**: `name`, `x`, `y` (the position of the entity's
//!   origin, in pixels), `width`/`height` (else the project's entity size),
//!   `originX`/`originY` (else the project's origin, else 0), `values`,
//!   `nodes` (each the position of the origin at that node). Positions become
//!   centres in units: `centre = offsets + (x - originX + width / 2) * 256`.
//!   Rotation and flips are ignored. A polygon entity (a `polygon` name of
//!   [`super::ENTITY_NAMES`]) is an outline instead: its vertices are its
//!   `x`, `y` followed by its `nodes`, as raw positions (plus offsets; no
//!   size or origin needed).
//! * **Decal layers** are ignored. Any other layer kind is an error.
//!
//! Level and layer `offsetX`/`offsetY` shift everything in the layer.
//! The decoded project and level are the `model` module's types,
//! re-exported here.

pub(crate) mod model;

use std::collections::BTreeMap;

use glam::IVec2;
use serde_json::{Map, Value};

use super::entities::{
    check_coord_field, is_polygon_name, place_box, px_to_units, PlacedEntity, PlacedPolygon,
    PropValue, Turn,
};
use crate::assemble::{assemble, GridLayer};
use crate::error::LevelError;
use crate::loaded::LoadedLevel;
use crate::options::{LoadOptions, MAX_LEVEL_TILES};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::tilemap::Tile;

pub use self::model::{
    LayerContent, OgmoLayer, OgmoLevel, Project, ProjectEntity, ProjectLayer, ProjectTileset,
};

type Obj = Map<String, Value>;

struct Cx<'a> {
    file: &'a str,
    warnings: std::cell::RefCell<Vec<String>>,
    /// Cells of the tile and grid layers decoded so far in this document,
    /// padded rows included (bounded by [`crate::limits::MAX_LEVEL_CELLS`]).
    cells: std::cell::Cell<u64>,
}

fn join(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_owned()
    } else {
        format!("{parent}.{key}")
    }
}

fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

impl Cx<'_> {
    fn bad(&self, field: &str, message: String) -> LevelError {
        LevelError::BadValue {
            file: self.file.into(),
            field: field.into(),
            message,
        }
    }

    fn expected(&self, field: &str, what: &str, v: &Value) -> LevelError {
        self.bad(field, format!("expected {what}, got {}", kind_of(v)))
    }

    fn parse(&self, text: &str, format: &'static str) -> Result<Obj, LevelError> {
        crate::limits::check_json(self.file, text)?;
        match serde_json::from_str::<Value>(text) {
            Ok(Value::Object(o)) => Ok(o),
            Ok(other) => Err(self.expected("(document)", "an object", &other)),
            Err(e) => Err(LevelError::Syntax {
                file: self.file.into(),
                field: format!("line {} column {}", e.line(), e.column()),
                format,
                message: e.to_string(),
            }),
        }
    }

    fn req<'v>(&self, o: &'v Obj, key: &str, parent: &str) -> Result<&'v Value, LevelError> {
        o.get(key).ok_or_else(|| LevelError::Missing {
            file: self.file.into(),
            field: join(parent, key),
            hint: String::new(),
        })
    }

    fn obj<'v>(&self, v: &'v Value, field: &str) -> Result<&'v Obj, LevelError> {
        v.as_object()
            .ok_or_else(|| self.expected(field, "an object", v))
    }

    fn arr<'v>(&self, v: &'v Value, field: &str) -> Result<&'v [Value], LevelError> {
        v.as_array()
            .map(Vec::as_slice)
            .ok_or_else(|| self.expected(field, "an array", v))
    }

    fn num(&self, v: &Value, field: &str) -> Result<f64, LevelError> {
        v.as_f64()
            .ok_or_else(|| self.expected(field, "a number", v))
    }

    fn int(&self, v: &Value, field: &str) -> Result<i64, LevelError> {
        match v.as_i64() {
            Some(i) => Ok(i),
            None => match v.as_f64() {
                Some(f) if f.fract() == 0.0 && f.abs() < 9.0e15 => Ok(f as i64),
                _ => Err(self.expected(field, "an integer", v)),
            },
        }
    }

    fn string<'v>(&self, v: &'v Value, field: &str) -> Result<&'v str, LevelError> {
        v.as_str()
            .ok_or_else(|| self.expected(field, "a string", v))
    }

    fn opt_str(&self, o: &Obj, key: &str, parent: &str) -> Result<Option<String>, LevelError> {
        o.get(key)
            .map(|v| self.string(v, &join(parent, key)).map(str::to_owned))
            .transpose()
    }

    fn opt_num(&self, o: &Obj, key: &str, parent: &str) -> Result<Option<f64>, LevelError> {
        o.get(key)
            .map(|v| self.num(v, &join(parent, key)))
            .transpose()
    }

    /// An `{x, y}` object of numbers.
    fn xy(&self, v: &Value, field: &str) -> Result<(f64, f64), LevelError> {
        let o = self.obj(v, field)?;
        Ok((
            self.num(self.req(o, "x", field)?, &join(field, "x"))?,
            self.num(self.req(o, "y", field)?, &join(field, "y"))?,
        ))
    }

    /// A cell count in `[0, MAX_LEVEL_TILES]`.
    fn count(&self, o: &Obj, key: &str, parent: &str) -> Result<u32, LevelError> {
        let field = join(parent, key);
        let n = self.int(self.req(o, key, parent)?, &field)?;
        if !(0..=MAX_LEVEL_TILES as i64).contains(&n) {
            return Err(LevelError::OutOfBounds {
                file: self.file.into(),
                field,
                message: format!("{n} cells is outside [0, {MAX_LEVEL_TILES}]"),
            });
        }
        Ok(n as u32)
    }

    /// A cell size in `[1, 4096]` pixels.
    fn cell_size(&self, o: &Obj, key: &str, parent: &str) -> Result<u32, LevelError> {
        let field = join(parent, key);
        let n = self.int(self.req(o, key, parent)?, &field)?;
        if !(1..=4096).contains(&n) {
            return Err(LevelError::OutOfBounds {
                file: self.file.into(),
                field,
                message: format!("{n} px is not a cell size in [1, 4096] px"),
            });
        }
        Ok(n as u32)
    }

    fn len_err(&self, field: &str, expected: u64, got: usize) -> LevelError {
        LevelError::Length {
            file: self.file.into(),
            field: field.into(),
            expected,
            got: got as u64,
        }
    }

    /// Adds a layer's `n` cells to the document's total, refused past
    /// [`crate::limits::MAX_LEVEL_CELLS`] (before anything is allocated for
    /// them: padded 2D rows make many cells of few JSON values).
    fn add_cells(&self, field: &str, n: u64) -> Result<(), LevelError> {
        use crate::limits::MAX_LEVEL_CELLS;
        let total = self.cells.get().saturating_add(n);
        self.cells.set(total);
        if total > MAX_LEVEL_CELLS {
            return Err(LevelError::Limit {
                file: self.file.into(),
                field: field.into(),
                what: "tile and grid cells in all layers".into(),
                limit: MAX_LEVEL_CELLS,
                found: total,
                bound: "MAX_LEVEL_CELLS",
            });
        }
        Ok(())
    }

    /// The cells of a 1D (`two_d == false`) or 2D array, row-major, each
    /// decoded by `f` with its field path. A 2D row shorter than the width
    /// (OGMO 3.2 writes such rows after a resize, as in the sample
    /// `uno.json`) is padded with `empty`, with a warning; every other
    /// length mismatch is an error. Every layer's width x height counts
    /// towards the document's [`crate::limits::MAX_LEVEL_CELLS`].
    fn cells<T>(
        &self,
        v: &Value,
        field: &str,
        (w, h): (u32, u32),
        two_d: bool,
        empty: &Value,
        mut f: impl FnMut(&Value, &str) -> Result<T, LevelError>,
    ) -> Result<Vec<T>, LevelError> {
        let a = self.arr(v, field)?;
        let mut out = Vec::new();
        if two_d {
            if a.len() != h as usize {
                return Err(self.len_err(field, h as u64, a.len()));
            }
            self.add_cells(field, w as u64 * h as u64)?;
            out.reserve(w as usize * h as usize);
            // Short rows: (row, entries), said in one warning per array.
            let mut short = Vec::new();
            for (r, row) in a.iter().enumerate() {
                let rf = format!("{field}[{r}]");
                let row = self.arr(row, &rf)?;
                if row.len() > w as usize {
                    return Err(self.len_err(&rf, w as u64, row.len()));
                }
                if row.len() < w as usize {
                    short.push((r, row.len()));
                }
                for c in 0..w as usize {
                    out.push(f(row.get(c).unwrap_or(empty), &format!("{rf}[{c}]"))?);
                }
            }
            if let Some(said) = short_rows(field, w, &short) {
                self.warnings
                    .borrow_mut()
                    .push(format!("{}: {said}, the rest read as empty", self.file));
            }
        } else {
            let n = w as u64 * h as u64;
            if a.len() as u64 != n {
                return Err(self.len_err(field, n, a.len()));
            }
            self.add_cells(field, n)?;
            out.reserve(a.len());
            for (i, cell) in a.iter().enumerate() {
                out.push(f(cell, &format!("{field}[{i}]"))?);
            }
        }
        Ok(out)
    }
}

/// What the short rows `(row, entries)` of 2D array `field` (rows of `w`
/// entries) are, in one phrase: the row itself when there is one, else the
/// rows as runs (`rows 20-29 of field: 37 of 40 entries`). `None` when no row
/// is short.
fn short_rows(field: &str, w: u32, short: &[(usize, usize)]) -> Option<String> {
    match short {
        [] => None,
        [(r, n)] => Some(format!("{field}[{r}]: {n} of {w} entries")),
        _ => {
            let mut runs: Vec<(usize, usize)> = Vec::new();
            for &(r, _) in short {
                match runs.last_mut() {
                    Some(run) if run.1 + 1 == r => run.1 = r,
                    _ => runs.push((r, r)),
                }
            }
            let rows: Vec<String> = runs
                .iter()
                .map(|&(a, b)| {
                    if a == b {
                        a.to_string()
                    } else {
                        format!("{a}-{b}")
                    }
                })
                .collect();
            let lo = short.iter().map(|s| s.1).min().unwrap_or(0);
            let hi = short.iter().map(|s| s.1).max().unwrap_or(0);
            let n = if lo == hi {
                lo.to_string()
            } else {
                format!("{lo} to {hi}")
            };
            Some(format!(
                "rows {} of {field}: {n} of {w} entries",
                rows.join(", ")
            ))
        }
    }
}

/// Parses an OGMO Editor 3 project (`.ogmo`). `file` names it in errors.
pub fn parse_project(file: &str, text: &str) -> Result<Project, LevelError> {
    let cx = Cx {
        file,
        warnings: Default::default(),
        cells: Default::default(),
    };
    let root = cx.parse(text, "OGMO project JSON")?;
    let mut p = Project {
        name: cx.opt_str(&root, "name", "")?.unwrap_or_default(),
        background_color: cx
            .opt_str(&root, "backgroundColor", "")?
            .unwrap_or_default(),
        ..Project::default()
    };
    if let Some(v) = root.get("layers") {
        for (i, l) in cx.arr(v, "layers")?.iter().enumerate() {
            let f = format!("layers[{i}]");
            let o = cx.obj(l, &f)?;
            p.layers.push(ProjectLayer {
                name: cx.opt_str(o, "name", &f)?.unwrap_or_default(),
                definition: cx.opt_str(o, "definition", &f)?.unwrap_or_default(),
                export_id: cx.opt_str(o, "exportID", &f)?.unwrap_or_default(),
                default_tileset: cx.opt_str(o, "defaultTileset", &f)?.unwrap_or_default(),
            });
        }
    }
    if let Some(v) = root.get("entities") {
        for (i, e) in cx.arr(v, "entities")?.iter().enumerate() {
            let f = format!("entities[{i}]");
            let o = cx.obj(e, &f)?;
            let size = match o.get("size") {
                Some(s) => cx.xy(s, &join(&f, "size"))?,
                None => (0.0, 0.0),
            };
            let origin = match o.get("origin") {
                Some(s) => cx.xy(s, &join(&f, "origin"))?,
                None => (0.0, 0.0),
            };
            p.entities.push(ProjectEntity {
                name: cx.opt_str(o, "name", &f)?.unwrap_or_default(),
                export_id: cx.opt_str(o, "exportID", &f)?.unwrap_or_default(),
                size,
                origin,
            });
        }
    }
    if let Some(v) = root.get("tilesets") {
        for (i, t) in cx.arr(v, "tilesets")?.iter().enumerate() {
            let f = format!("tilesets[{i}]");
            let o = cx.obj(t, &f)?;
            let dim = |key: &str, default: i64| -> Result<i64, LevelError> {
                match o.get(key) {
                    Some(v) => {
                        let field = join(&f, key);
                        let n = cx.int(v, &field)?;
                        if !(0..=65536).contains(&n) {
                            return Err(cx.bad(&field, format!("{n} px is outside [0, 65536]")));
                        }
                        Ok(n)
                    }
                    None => Ok(default),
                }
            };
            let (tw, th) = (dim("tileWidth", 0)?, dim("tileHeight", 0)?);
            let (sep, margin) = (dim("tileSeparationX", 0)?, dim("tileMarginX", 0)?);
            let image = cx.opt_str(o, "image", &f)?.unwrap_or_default();
            let columns = png_width(&image).and_then(|w| {
                let step = tw + sep;
                let n = (w as i64 - 2 * margin + sep).checked_div(step)?;
                (tw > 0 && n > 0).then_some(n as u32)
            });
            p.tilesets.push(ProjectTileset {
                label: cx.opt_str(o, "label", &f)?.unwrap_or_default(),
                tile_width: tw as u32,
                tile_height: th as u32,
                columns,
                margin: margin as u32,
                spacing: sep as u32,
                path: cx.opt_str(o, "path", &f)?.unwrap_or_default(),
                image,
            });
        }
    }
    Ok(p)
}

/// The width of the PNG in a `data:image/png;base64,` URI (from its IHDR).
fn png_width(uri: &str) -> Option<u32> {
    let b64 = uri.split_once("base64,")?.1.as_bytes();
    // The first 24 bytes hold the signature and IHDR's width.
    let bytes = crate::art::ogmo::decode_base64(std::str::from_utf8(b64.get(..32)?).ok()?)?;
    (bytes.get(..8)? == b"\x89PNG\r\n\x1a\n" && bytes.get(12..16)? == b"IHDR")
        .then(|| u32::from_be_bytes(bytes[16..20].try_into().unwrap_or_default()))
}

enum Kind {
    Tile,
    Grid,
    Entity,
    Decal,
}

/// Decodes an OGMO Editor 3 level (`.json`) into its layers. `project`
/// supplies layer kinds, entity default sizes and origins, and tileset
/// column counts; without it, layer kinds are told from the fields present
/// and every entity must carry its `width` and `height`.
pub fn parse_level(
    file: &str,
    text: &str,
    project: Option<&Project>,
) -> Result<OgmoLevel, LevelError> {
    let cx = Cx {
        file,
        warnings: Default::default(),
        cells: Default::default(),
    };
    let root = cx.parse(text, "JSON")?;
    let offset = (
        cx.opt_num(&root, "offsetX", "")?.unwrap_or(0.0),
        cx.opt_num(&root, "offsetY", "")?.unwrap_or(0.0),
    );
    let layers = cx.arr(cx.req(&root, "layers", "")?, "layers")?;
    let mut out = Vec::with_capacity(layers.len());
    for (i, l) in layers.iter().enumerate() {
        out.push(parse_layer(
            &cx,
            &format!("layers[{i}]"),
            l,
            project,
            offset,
        )?);
    }
    Ok(OgmoLevel {
        offset,
        layers: out,
        warnings: cx.warnings.take(),
    })
}

/// Decodes one level layer (`f`: its path), by its kind.
fn parse_layer(
    cx: &Cx<'_>,
    f: &str,
    l: &Value,
    project: Option<&Project>,
    level_offset: (f64, f64),
) -> Result<OgmoLayer, LevelError> {
    let o = cx.obj(l, f)?;
    let name = cx.opt_str(o, "name", f)?.unwrap_or_default();
    let eid = cx.opt_str(o, "_eid", f)?.unwrap_or_default();
    let def = project.and_then(|p| {
        p.layers
            .iter()
            .find(|d| !eid.is_empty() && d.export_id == eid)
            .or_else(|| p.layers.iter().find(|d| d.name == name))
    });
    let kind = layer_kind(cx, f, o, def)?;
    let lx = cx.opt_num(o, "offsetX", f)?.unwrap_or(0.0);
    let ly = cx.opt_num(o, "offsetY", f)?.unwrap_or(0.0);
    let ox = px_to_units(cx.file, &join(f, "offsetX"), level_offset.0 + lx)?;
    let oy = px_to_units(cx.file, &join(f, "offsetY"), level_offset.1 + ly)?;
    let mut layer = OgmoLayer {
        name,
        field: f.into(),
        origin: IVec2::new(ox as i32, oy as i32),
        cell: (0, 0),
        cells: (0, 0),
        content: LayerContent::Decals,
    };
    if matches!(kind, Kind::Decal) {
        return Ok(layer);
    }
    if matches!(kind, Kind::Tile | Kind::Grid) {
        layer.cell = (
            cx.cell_size(o, "gridCellWidth", f)?,
            cx.cell_size(o, "gridCellHeight", f)?,
        );
        layer.cells = (cx.count(o, "gridCellsX", f)?, cx.count(o, "gridCellsY", f)?);
    }
    layer.content = match kind {
        Kind::Decal => LayerContent::Decals,
        Kind::Tile => tile_content(cx, f, o, def, project, layer.cells)?,
        Kind::Grid => grid_content(cx, f, o, layer.cells)?,
        Kind::Entity => entity_content(cx, f, o, &layer, project)?,
    };
    Ok(layer)
}

/// A layer's kind: its project definition's, else told from its fields.
fn layer_kind(
    cx: &Cx<'_>,
    f: &str,
    o: &Obj,
    def: Option<&ProjectLayer>,
) -> Result<Kind, LevelError> {
    Ok(match def.map(|d| d.definition.as_str()) {
        Some("tile") => Kind::Tile,
        Some("grid") => Kind::Grid,
        Some("entity") => Kind::Entity,
        Some("decal") => Kind::Decal,
        Some(other) => {
            return Err(LevelError::UnknownLayer {
                file: cx.file.into(),
                field: f.into(),
                kind: other.into(),
            });
        }
        None => {
            let has = |keys: &[&str]| keys.iter().any(|k| o.contains_key(*k));
            if has(&["data", "data2D", "dataCoords", "dataCoords2D"]) {
                Kind::Tile
            } else if has(&["grid", "grid2D"]) {
                Kind::Grid
            } else if has(&["entities"]) {
                Kind::Entity
            } else if has(&["decals"]) {
                Kind::Decal
            } else {
                return Err(LevelError::UnknownLayer {
                    file: cx.file.into(),
                    field: f.into(),
                    kind: "none: no data, grid, entities or decals field, and no project layer of that name".into(),
                });
            }
        }
    })
}

/// A layer's `exportMode` or `arrayMode` (`key`): 0, 1, or absent.
fn export_mode(cx: &Cx<'_>, f: &str, o: &Obj, key: &str) -> Result<Option<i64>, LevelError> {
    match o.get(key) {
        None => Ok(None),
        Some(v) => {
            let field = join(f, key);
            match cx.int(v, &field)? {
                m @ (0 | 1) => Ok(Some(m)),
                m => Err(cx.bad(&field, format!("expected 0 or 1, got {m}"))),
            }
        }
    }
}

/// Which of the 1D and 2D fields `keys` holds a layer's cells, and whether
/// it is the 2D one: the one `arrayMode` (`two_d`) names, else the first
/// present.
fn pick_cells_key(
    cx: &Cx<'_>,
    f: &str,
    o: &Obj,
    keys: [&'static str; 2],
    two_d: Option<i64>,
) -> Result<(&'static str, bool), LevelError> {
    match two_d {
        Some(m) => {
            let key = keys[m as usize];
            if o.contains_key(key) {
                Ok((key, m == 1))
            } else {
                Err(LevelError::Missing {
                    file: cx.file.into(),
                    field: join(f, key),
                    hint: format!(" (arrayMode {m} stores the cells in {key:?})"),
                })
            }
        }
        None => keys
            .iter()
            .zip([false, true])
            .find(|(k, _)| o.contains_key(**k))
            .map(|(k, d)| (*k, d))
            .ok_or_else(|| LevelError::Missing {
                file: cx.file.into(),
                field: join(f, keys[0]),
                hint: format!(" (nor {:?})", keys[1]),
            }),
    }
}

/// A tile layer's ids (tile coordinates turned into ids), from whichever
/// of its four fields its modes name.
fn tile_content(
    cx: &Cx<'_>,
    f: &str,
    o: &Obj,
    def: Option<&ProjectLayer>,
    project: Option<&Project>,
    cells: (u32, u32),
) -> Result<LayerContent, LevelError> {
    let tileset = match cx.opt_str(o, "tileset", f)? {
        Some(t) => t,
        None => def.map(|d| d.default_tileset.clone()).unwrap_or_default(),
    };
    let coords = match export_mode(cx, f, o, "exportMode")? {
        Some(m) => m == 1,
        None => o.contains_key("dataCoords") || o.contains_key("dataCoords2D"),
    };
    let keys = if coords {
        ["dataCoords", "dataCoords2D"]
    } else {
        ["data", "data2D"]
    };
    let mode = export_mode(cx, f, o, "arrayMode")?;
    let (key, two_d) = pick_cells_key(cx, f, o, keys, mode)?;
    let v = &o[key];
    let field = join(f, key);
    let ids = if coords {
        let columns = project
            .and_then(|p| p.tilesets.iter().find(|t| t.label == tileset))
            .and_then(|t| t.columns);
        cx.cells(
            v,
            &field,
            cells,
            two_d,
            &serde_json::json!([-1]),
            |c, cf| coord_id(cx, c, cf, columns, &tileset),
        )?
    } else {
        cx.cells(v, &field, cells, two_d, &Value::from(-1), |c, cf| {
            let id = cx.int(c, cf)?;
            if !(-1..=i32::MAX as i64).contains(&id) {
                return Err(cx.bad(
                    cf,
                    format!("tile id {id} is not -1 (empty) or a tile index"),
                ));
            }
            Ok(id as i32)
        })?
    };
    Ok(LayerContent::Tiles { tileset, key, ids })
}

/// A grid layer's values (numbers and booleans as text).
fn grid_content(
    cx: &Cx<'_>,
    f: &str,
    o: &Obj,
    cells: (u32, u32),
) -> Result<LayerContent, LevelError> {
    let mode = export_mode(cx, f, o, "arrayMode")?;
    let (key, two_d) = pick_cells_key(cx, f, o, ["grid", "grid2D"], mode)?;
    let empty = Value::from("0");
    let values = cx.cells(&o[key], &join(f, key), cells, two_d, &empty, |c, cf| {
        Ok(match c {
            Value::String(s) => s.clone(),
            Value::Number(n) => n.to_string(),
            Value::Bool(b) => (*b as u8).to_string(),
            other => return Err(cx.expected(cf, "a string", other)),
        })
    })?;
    Ok(LayerContent::Grid { key, values })
}

/// An entity layer's entities, placed in `layer`.
fn entity_content(
    cx: &Cx<'_>,
    f: &str,
    o: &Obj,
    layer: &OgmoLayer,
    project: Option<&Project>,
) -> Result<LayerContent, LevelError> {
    let list = match o.get("entities") {
        Some(v) => cx.arr(v, &join(f, "entities"))?,
        None => &[],
    };
    let mut es = Vec::with_capacity(list.len());
    for (k, e) in list.iter().enumerate() {
        es.push(parse_entity(
            cx,
            &format!("{f}.entities[{k}]"),
            e,
            layer,
            project,
        )?);
    }
    Ok(LayerContent::Entities(es))
}

fn coord_id(
    cx: &Cx<'_>,
    c: &Value,
    cf: &str,
    columns: Option<u32>,
    tileset: &str,
) -> Result<i32, LevelError> {
    let a = cx.arr(c, cf)?;
    match a {
        [v] if cx.int(v, cf)? == -1 => Ok(-1),
        [x, y] => {
            let (x, y) = (
                cx.int(x, &format!("{cf}[0]"))?,
                cx.int(y, &format!("{cf}[1]"))?,
            );
            let Some(cols) = columns else {
                return Err(cx.bad(
                    cf,
                    format!("tile coordinates need the column count of tileset {tileset:?}, which needs the project and its embedded PNG"),
                ));
            };
            if !(0..cols as i64).contains(&x)
                || !(0..=(i32::MAX as i64 / cols as i64 - 1)).contains(&y)
            {
                return Err(cx.bad(
                    cf,
                    format!("[{x}, {y}] is outside tileset {tileset:?} ({cols} columns)"),
                ));
            }
            Ok((y * cols as i64 + x) as i32)
        }
        _ => Err(cx.bad(
            cf,
            format!("expected [-1] or [x, y], got {} entries", a.len()),
        )),
    }
}

fn parse_entity(
    cx: &Cx<'_>,
    f: &str,
    e: &Value,
    layer: &OgmoLayer,
    project: Option<&Project>,
) -> Result<PlacedEntity, LevelError> {
    let o = cx.obj(e, f)?;
    let name = cx
        .string(cx.req(o, "name", f)?, &join(f, "name"))?
        .to_owned();
    let eid = cx.opt_str(o, "_eid", f)?.unwrap_or_default();
    let def = project.and_then(|p| {
        p.entities
            .iter()
            .find(|d| !eid.is_empty() && d.export_id == eid)
            .or_else(|| p.entities.iter().find(|d| d.name == name))
    });
    let x = cx.num(cx.req(o, "x", f)?, &join(f, "x"))?;
    let y = cx.num(cx.req(o, "y", f)?, &join(f, "y"))?;
    let values = parse_values(cx, o, f)?;
    if is_polygon_name(&name) {
        return parse_polygon(cx, f, o, layer, name, (x, y), values);
    }
    let dim = |key: &str, default: Option<f64>| -> Result<f64, LevelError> {
        match (cx.opt_num(o, key, f)?, default) {
            (Some(v), _) => Ok(v),
            (None, Some(d)) if d > 0.0 => Ok(d),
            _ => Err(LevelError::Missing {
                file: cx.file.into(),
                field: join(f, key),
                hint: format!(" (and no project entity {name:?} gives a default size)"),
            }),
        }
    };
    let w = dim("width", def.map(|d| d.size.0))?;
    let h = dim("height", def.map(|d| d.size.1))?;
    let origin_x = cx
        .opt_num(o, "originX", f)?
        .or(def.map(|d| d.origin.0))
        .unwrap_or(0.0);
    let origin_y = cx
        .opt_num(o, "originY", f)?
        .or(def.map(|d| d.origin.1))
        .unwrap_or(0.0);
    // Top-left corner in units, from a position of the origin.
    let corner = |px: f64, py: f64, field: &str| -> Result<(i64, i64), LevelError> {
        let ux = px_to_units(cx.file, &join(field, "x"), px - origin_x)?;
        let uy = px_to_units(cx.file, &join(field, "y"), py - origin_y)?;
        let (ax, ay) = (layer.origin.x as i64 + ux, layer.origin.y as i64 + uy);
        check_coord_field(cx.file, &join(field, "x"), ax)?;
        check_coord_field(cx.file, &join(field, "y"), ay)?;
        Ok((ax, ay))
    };
    let (left, top) = corner(x, y, f)?;
    let (centre, size) = place_box(cx.file, f, left, top, w, h)?;
    // OGMO turns an entity about its origin (see `Turn`).
    let rotation = cx.opt_num(o, "rotation", f)?.unwrap_or(0.0);
    let pivot = (
        layer.origin.x as f64 + x * UNITS_PER_PX as f64,
        layer.origin.y as f64 + y * UNITS_PER_PX as f64,
    );
    let turn = Turn::new(rotation, pivot, join(f, "rotation"));
    let mut nodes = Vec::new();
    if let Some(v) = o.get("nodes") {
        let nf = join(f, "nodes");
        for (i, n) in cx.arr(v, &nf)?.iter().enumerate() {
            let fi = format!("{nf}[{i}]");
            let (nx, ny) = cx.xy(n, &fi)?;
            let (l, t) = corner(nx, ny, &fi)?;
            nodes.push(place_box(cx.file, &fi, l, t, w, h)?.0);
        }
    }
    Ok(PlacedEntity {
        name,
        layer: layer.name.clone(),
        field: f.into(),
        values_key: "values",
        centre,
        size,
        nodes,
        values,
        polygon: None,
        turn,
        sized: o.contains_key("width") && o.contains_key("height"),
    })
}

/// An entity's `values`, in file order (nulls skipped).
fn parse_values(cx: &Cx<'_>, o: &Obj, f: &str) -> Result<Vec<(String, PropValue)>, LevelError> {
    let mut values = Vec::new();
    if let Some(v) = o.get("values") {
        for (k, val) in cx.obj(v, &join(f, "values"))? {
            let pv = match val {
                Value::Null => continue,
                Value::Bool(b) => PropValue::Bool(*b),
                Value::Number(n) => PropValue::Number(n.as_f64().unwrap_or(f64::NAN)),
                Value::String(s) => PropValue::Text(s.clone()),
                other => PropValue::Text(other.to_string()),
            };
            values.push((k.clone(), pv));
        }
    }
    Ok(values)
}

/// A polygon entity: its vertices are its own position (`x`, `y`: where
/// the editor draws its origin) followed by its `nodes`, raw (no size or
/// origin applied), shifted by the layer's offsets. Size and origin are not
/// needed. More than [`super::MAX_PATH_NODES`] nodes are refused unread.
fn parse_polygon(
    cx: &Cx<'_>,
    f: &str,
    o: &Obj,
    layer: &OgmoLayer,
    name: String,
    (x, y): (f64, f64),
    values: Vec<(String, PropValue)>,
) -> Result<PlacedEntity, LevelError> {
    let point = |px: f64, py: f64, field: &str| -> Result<IVec2, LevelError> {
        let (fx, fy) = (join(field, "x"), join(field, "y"));
        let ax = layer.origin.x as i64 + px_to_units(cx.file, &fx, px)?;
        let ay = layer.origin.y as i64 + px_to_units(cx.file, &fy, py)?;
        check_coord_field(cx.file, &fx, ax)?;
        check_coord_field(cx.file, &fy, ay)?;
        Ok(IVec2::new(ax as i32, ay as i32))
    };
    let nf = join(f, "nodes");
    let mut points = vec![point(x, y, f)?];
    let mut point_fields = vec![f.to_owned()];
    if let Some(v) = o.get("nodes") {
        let list = cx.arr(v, &nf)?;
        // A very long list is refused before converting it; a shorter one
        // with too many vertices by the entity table, with the others.
        if list.len() > super::MAX_PATH_NODES {
            return Err(LevelError::BadPolygon {
                file: cx.file.into(),
                field: nf,
                message: format!(
                    "polygon has {} vertices; it needs 3 to {}",
                    list.len() + 1,
                    ledge_shared::shape::MAX_POLYGON_VERTICES
                ),
            });
        }
        for (i, n) in list.iter().enumerate() {
            let fi = format!("{nf}[{i}]");
            let (nx, ny) = cx.xy(n, &fi)?;
            points.push(point(nx, ny, &fi)?);
            point_fields.push(fi);
        }
    }
    Ok(PlacedEntity {
        name,
        layer: layer.name.clone(),
        field: f.into(),
        values_key: "values",
        centre: points[0],
        size: IVec2::splat(2),
        nodes: Vec::new(),
        values,
        polygon: Some(PlacedPolygon {
            field: nf,
            points,
            point_fields,
        }),
        turn: None,
        sized: false,
    })
}

/// Loads an OGMO level from text: `file` names the level in errors and
/// `project` is the project's `(file, text)`, when there is one.
pub fn load_str(
    file: &str,
    text: &str,
    project: Option<(&str, &str)>,
    options: &LoadOptions,
) -> Result<LoadedLevel, LevelError> {
    let project_file = project.map(|(pf, _)| pf);
    let project = project.map(|(pf, pt)| parse_project(pf, pt)).transpose()?;
    let level = parse_level(file, text, project.as_ref())?;
    let art = match (project_file, &project) {
        (Some(pf), Some(p)) => crate::art::ogmo::from_ogmo(file, pf, p, &level)?,
        _ => crate::art::LevelArt::default(),
    };
    let mut warnings = level.warnings;
    let layers = crate::collision::names::without_decoration(
        file,
        level.layers,
        options,
        &mut warnings,
        |l| match l.content {
            LayerContent::Tiles { .. } | LayerContent::Grid { .. } => Some((&l.name, &l.field)),
            _ => None,
        },
    );
    let mut grids = Vec::new();
    let mut painted = Vec::new();
    let mut entities = Vec::new();
    // OGMO tile layers say nothing about collision. A level with no
    // collision data at all (no grid layer, no tile table or settings for
    // its tilesets, no collision_layers) collides its collision-named tile
    // layers, else all of them, as a Tiled map without data does, and says
    // so.
    let mapped = |t: &str| options.mapping.has_table(t) || options.has_tile_kinds(t);
    let has_data = options.collision_layers.is_some()
        || layers.iter().any(|l| match &l.content {
            LayerContent::Grid { .. } => true,
            LayerContent::Tiles { tileset, .. } => mapped(tileset),
            _ => false,
        });
    let tile_layer = |l: &OgmoLayer| matches!(l.content, LayerContent::Tiles { .. });
    let named = layers
        .iter()
        .any(|l| tile_layer(l) && crate::collision::is_collision_layer_name(&l.name));
    let fallback =
        |l: &OgmoLayer| !has_data && (!named || crate::collision::is_collision_layer_name(&l.name));
    if !has_data && layers.iter().any(tile_layer) {
        warnings.push(format!(
            "{file}: the level has no collision data (no grid layer, no tile table for its tilesets), so every tile of {} is solid; use a grid layer for collision, or map the tiles in the level's settings file (see docs/LEVELS.md, \"What collides\")",
            if named {
                "the tile layers named like collision layers (collision, solid, walls, ground, ...)"
            } else {
                "every tile layer"
            }
        ));
    }
    for l in layers {
        let listed = options.layer_collides(&l.name);
        let wanted = listed != Some(false);
        let falls_back = fallback(&l);
        let fallback_ids = match &l.content {
            LayerContent::Tiles { tileset, ids, .. }
                if wanted && listed.is_none() && falls_back && !mapped(tileset) =>
            {
                let cells: Vec<_> = ids.iter().map(|&i| u32::try_from(i).ok()).collect();
                Some((tileset.clone(), cells))
            }
            _ => None,
        };
        let tiles = match l.content {
            LayerContent::Tiles { tileset, .. }
                if wanted && listed.is_none() && !mapped(&tileset) && !falls_back =>
            {
                // OGMO files say nothing about which tiles collide: only a
                // tileset with a table (ledge's own, or one the settings
                // map) does.
                warnings.push(format!(
                    "{file}: {}: tile layer {:?} does not collide: its tileset {tileset:?} is not ledge's own and no tile table maps it (use a grid layer for collision, map its tiles under [tiles.\"{tileset}\"] in the level's settings, or list the layer in collision_layers)",
                    l.field, l.name
                ));
                continue;
            }
            LayerContent::Tiles { tileset, key, ids } if wanted => ids
                .iter()
                .enumerate()
                .map(|(i, &id)| {
                    if id < 0 {
                        return Ok(Tile::Empty);
                    }
                    let kinds = options.has_tile_kinds(&tileset);
                    if kinds || !options.mapping.has_table(&tileset) {
                        // Settings (missing ids are empty), or a layer the
                        // settings list as colliding (every tile solid).
                        return Ok(
                            match options.tile_kinds.get(&(tileset.to_lowercase(), id as u32)) {
                                Some(&k) => k,
                                None if kinds => Tile::Empty,
                                None => Tile::Solid,
                            },
                        );
                    }
                    options.mapping.tile(&tileset, id as u32).ok_or_else(|| {
                        LevelError::UnknownTile {
                            file: file.into(),
                            field: cell_field(&l.field, key, i, l.cells.0),
                            tile: format!("tile id {id}"),
                            tileset: tileset.clone(),
                        }
                    })
                })
                .collect::<Result<Vec<_>, _>>()?,
            LayerContent::Grid { key, values } if wanted => grid_tiles(
                file,
                (&l.field, &l.name, l.cells.0),
                key,
                &values,
                options,
                &mut warnings,
            ),
            LayerContent::Entities(es) => {
                entities.extend(es);
                continue;
            }
            _ => continue,
        };
        grids.push(GridLayer {
            field: l.field,
            name: l.name,
            origin: l.origin,
            cell: l.cell,
            cells: l.cells,
            tiles,
        });
        if let Some(f) = fallback_ids {
            painted.push((grids.len() - 1, f));
        }
    }
    let name = std::path::Path::new(file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    crate::collision::names::rename_by_layer(file, &mut entities, options, &mut warnings);
    painted_layers(file, &mut grids, painted, &entities, options, &mut warnings);
    crate::collision::resample::onto_one_grid(file, &mut grids, options, &mut warnings)?;
    let mut loaded = assemble(file, name, grids, entities, options)?;
    loaded.warnings.splice(0..0, warnings);
    loaded.art = art;
    Ok(loaded)
}

/// A grid layer's tiles: values the mapping does not know are solid
/// (OGMO's own grids use "0" for empty and "1" for solid), said once per
/// value.
/// `layer`: its field, name and width in cells.
fn grid_tiles(
    file: &str,
    (field, name, width): (&str, &str, u32),
    key: &str,
    values: &[String],
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Vec<Tile> {
    let mut unknown: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
    let tiles = values
        .iter()
        .enumerate()
        .map(|(i, v)| {
            options.mapping.grid_tile(v).unwrap_or_else(|| {
                unknown.entry(v).or_insert((i, 0)).1 += 1;
                Tile::Solid
            })
        })
        .collect();
    for (v, (first, n)) in unknown {
        warnings.push(format!(
            "{file}: {}: grid value {v:?} ({n} cells) of layer {:?} is read as solid (ledge reads \"0\" as empty, \"1\" solid, \"2\" one-way, \"3\" hazard, \"4\"-\"9\" slopes, or tile kind names)",
            cell_field(field, key, first, width),
            name
        ));
    }
    tiles
}

/// A tile layer made solid by the fallback: its grid index, tileset and
/// tile ids (`None` empty).
type FallbackLayer = (usize, (String, Vec<Option<u32>>));

/// Makes the background tiles of the tile layers painted edge to edge
/// that collide only by the fallback empty (`crate::collision::infer`):
/// `painted` holds each one's grid index, tileset and tile ids.
fn painted_layers(
    file: &str,
    grids: &mut [GridLayer],
    painted: Vec<FallbackLayer>,
    entities: &[PlacedEntity],
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) {
    use crate::collision::infer::{apply_painted, painted_warning, solid_elsewhere};
    for (k, (tileset, cells)) in painted {
        let others = solid_elsewhere(grids, k, entities);
        let g = &mut grids[k];
        if let Some(p) = apply_painted(g, &cells, entities, options, others) {
            let line = painted_warning(&p, |id| (tileset.clone(), id));
            warnings.push(format!("{file}: {} (layer {:?}): {line}", g.field, g.name));
        }
    }
}

fn cell_field(layer: &str, key: &str, i: usize, w: u32) -> String {
    if key.ends_with("2D") && w > 0 {
        format!("{layer}.{key}[{}][{}]", i / w as usize, i % w as usize)
    } else {
        format!("{layer}.{key}[{i}]")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_width_reads_ihdr() {
        // 208 x 32 (the echo-slopes tileset's header).
        let uri = "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAANAAAAAgCAMAAABU6AZf";
        assert_eq!(png_width(uri), Some(208));
        assert_eq!(png_width("data:image/png;base64,AAAA"), None);
        assert_eq!(png_width("img/tiles.png"), None);
    }
}
