//! Tiled maps (`.tmx`, with embedded or external `.tsx` tilesets), read
//! with the `tiled` crate.
//!
//! * The map must be orthogonal and finite, with square tiles of a power of
//!   two pixels, at most [`MAX_LEVEL_TILES`] per side.
//! * **Tile layers** (also inside group layers) are collision layers, not
//!   offset. A tile's kind is its tileset tile's `kind` property
//!   ([`parse_tile_kind`]: `solid`, `one_way`, `hazard`, `slope_45_right`,
//!   ...) or else the [`super::TileMapping`] table of its tileset's name. A
//!   horizontally flipped slope is mirrored; a vertically or diagonally
//!   flipped slope is an error.
//! * **Object layers**: each object's class (Tiled 1.9+; `type` before) or,
//!   when empty, its name goes through the entity table
//!   ([`super::ENTITY_NAMES`]); custom properties are the parameters.
//!   Rectangles, ellipses and tile objects use their bounds; a point object
//!   is a box of one tile centred on it. A polygon object (not a path) is a
//!   convex polygon solid ([`super::EntityKind::PolygonBlock`], its points
//!   rotated by the object's rotation): its name must be a block or polygon
//!   name, or empty. A moving platform's `path`
//!   property (type object) names a polyline or polygon object whose points
//!   are the centres the platform passes through (a polygon loops unless
//!   `loop` says otherwise); those path objects are not entities, and a
//!   polyline that is not a path is an error. Layer and group offsets shift
//!   objects.
//! * Image layers are ignored.

use std::collections::{BTreeMap, BTreeSet};
use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use ::tiled::{
    DefaultResourceCache, LayerType, Loader, Map, ObjectLayer, ObjectShape, Orientation,
    PropertyValue, ResourceReader, TileLayer,
};
use glam::IVec2;

use super::entities::{
    check_coord_field, place_box, px_to_units, PlacedEntity, PlacedPolygon, PropValue,
};
use super::mapping::{mirror, parse_tile_kind};
use super::{GridLayer, LevelError, LoadOptions, LoadedLevel, MAX_LEVEL_TILES};
use ledge_shared::tilemap::Tile;

/// Serves the map from memory (when given) and every other file (external
/// tilesets, templates) from the filesystem, with the size limit; every
/// document goes through the pre-scan of [`crate::limits`] first, with one
/// budget for the whole load.
struct Reader {
    main: PathBuf,
    text: Option<Vec<u8>>,
    budget: crate::limits::Budget,
    /// The first refusal, kept whole: the `tiled` crate only passes on its
    /// text (and may name another file).
    error: Option<LevelError>,
}

impl Reader {
    fn read(&mut self, path: &Path) -> Result<Vec<u8>, LevelError> {
        let bytes = match self.text.take() {
            Some(t) if path == self.main => t,
            t => {
                self.text = t;
                super::read_bytes(path)?
            }
        };
        crate::limits::check_tmx_resource(&mut self.budget, path, bytes)
    }
}

impl ResourceReader for Reader {
    type Resource = Cursor<Vec<u8>>;
    type Error = std::io::Error;

    fn read_from(&mut self, path: &Path) -> Result<Self::Resource, Self::Error> {
        if let Some(e) = &self.error {
            return Err(std::io::Error::other(e.to_string()));
        }
        self.read(path).map(Cursor::new).map_err(|e| {
            let io = std::io::Error::other(e.to_string());
            self.error = Some(e);
            io
        })
    }
}

/// Loads a Tiled map file.
pub fn load_path(path: &Path, options: &LoadOptions) -> Result<LoadedLevel, LevelError> {
    load(path, None, options)
}

/// Loads a Tiled map from text; `file` names it in errors and locates its
/// external tilesets (relative paths are relative to its folder).
pub fn load_str(file: &str, text: &str, options: &LoadOptions) -> Result<LoadedLevel, LevelError> {
    load(Path::new(file), Some(text.as_bytes().to_vec()), options)
}

fn load(
    path: &Path,
    text: Option<Vec<u8>>,
    options: &LoadOptions,
) -> Result<LoadedLevel, LevelError> {
    let file = path.display().to_string();
    let mut loader = Loader::<DefaultResourceCache, _>::with_reader(Reader {
        main: path.to_path_buf(),
        text,
        budget: Default::default(),
        error: None,
    });
    let result = catch_unwind(AssertUnwindSafe(|| loader.load_tmx_map(path)));
    // A refusal of the pre-scan wins over whatever the tiled crate made of it
    // (and over a map it loaded anyway).
    if let Some(e) = loader.reader_mut().error.take() {
        return Err(e);
    }
    let map = match result {
        Ok(Ok(map)) => map,
        Ok(Err(::tiled::Error::ResourceLoadingError { path: p, err })) if p == path => {
            return Err(LevelError::Io {
                file,
                message: err.to_string(),
            });
        }
        Ok(Err(e)) => {
            return Err(LevelError::Syntax {
                file,
                field: "map".into(),
                format: "TMX",
                message: e.to_string(),
            });
        }
        Err(_) => {
            return Err(LevelError::Syntax {
                file,
                field: "map".into(),
                format: "TMX",
                message: "the Tiled reader failed on this input".into(),
            });
        }
    };
    let mut loaded = Conv {
        file: &file,
        map: &map,
        options,
    }
    .run(path)?;
    loaded.art = crate::art::from_tiled(&file, &map)?;
    Ok(loaded)
}

struct Conv<'a> {
    file: &'a str,
    map: &'a Map,
    options: &'a LoadOptions,
}

/// A path object: absolute points (pixels) and whether it is closed.
struct PathObj {
    points: Vec<(f64, f64)>,
    closed: bool,
}

/// Every polyline/polygon by id, and the ids platforms name as paths.
#[derive(Default)]
struct Paths {
    by_id: BTreeMap<u32, PathObj>,
    used: BTreeSet<u32>,
}

/// What [`Conv::visit`] calls on each layer: `(field, name, layer, offset)`.
type LayerFn<'m, 'f> =
    dyn FnMut(&str, &str, LayerType<'m>, (f64, f64)) -> Result<(), LevelError> + 'f;

impl Conv<'_> {
    fn bad(&self, field: impl Into<String>, message: String) -> LevelError {
        LevelError::BadValue {
            file: self.file.into(),
            field: field.into(),
            message,
        }
    }

    fn run(&self, path: &Path) -> Result<LoadedLevel, LevelError> {
        let m = self.map;
        if m.orientation != Orientation::Orthogonal {
            return Err(self.bad(
                "map.orientation",
                format!(
                    "{:?} maps are not supported (use orthogonal)",
                    m.orientation
                ),
            ));
        }
        if m.infinite() {
            return Err(self.bad(
                "map.infinite",
                "infinite maps are not supported (make the map finite)".into(),
            ));
        }
        if m.tile_width != m.tile_height || !(1..=4096).contains(&m.tile_width) {
            return Err(self.bad(
                "map.tilewidth",
                format!(
                    "tiles must be square and at most 4096 px, got {} x {} px",
                    m.tile_width, m.tile_height
                ),
            ));
        }
        for (v, f) in [(m.width, "map.width"), (m.height, "map.height")] {
            if v > MAX_LEVEL_TILES {
                return Err(LevelError::OutOfBounds {
                    file: self.file.into(),
                    field: f.into(),
                    message: format!("{v} tiles is more than {MAX_LEVEL_TILES}"),
                });
            }
        }
        // Every polyline/polygon by id, and the ids platforms use as paths.
        let mut paths = Paths::default();
        self.visit(m.layers(), "layers", (0.0, 0.0), &mut |_, _, layer, off| {
            if let LayerType::Objects(ol) = layer {
                for o in ol.objects() {
                    let (ox, oy) = (o.x as f64 + off.0, o.y as f64 + off.1);
                    let (pts, closed) = match &o.shape {
                        ObjectShape::Polyline { points } => (points, false),
                        ObjectShape::Polygon { points } => (points, true),
                        _ => {
                            if let Some(PropertyValue::ObjectValue(id)) = o.properties.get("path") {
                                paths.used.insert(*id);
                            }
                            continue;
                        }
                    };
                    let points = pts
                        .iter()
                        .map(|&(x, y)| (ox + x as f64, oy + y as f64))
                        .collect();
                    paths.by_id.insert(o.id(), PathObj { points, closed });
                }
            }
            Ok(())
        })?;
        let mut grids = Vec::new();
        let mut entities = Vec::new();
        self.visit(
            m.layers(),
            "layers",
            (0.0, 0.0),
            &mut |field, name, layer, off| {
                match layer {
                    LayerType::Tiles(tl) => {
                        if let Some(g) = self.tile_layer(field, name, &tl, off)? {
                            grids.push(g);
                        }
                    }
                    LayerType::Objects(ol) => {
                        self.object_layer(field, name, &ol, off, &paths, &mut entities)?
                    }
                    _ => {}
                }
                Ok(())
            },
        )?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        super::assemble(self.file, name, grids, entities, self.options)
    }

    /// Calls `f(field, name, layer, offset)` on every layer, groups flattened,
    /// offsets accumulated (pixels).
    fn visit<'m>(
        &self,
        layers: impl Iterator<Item = ::tiled::Layer<'m>>,
        parent: &str,
        off: (f64, f64),
        f: &mut LayerFn<'m, '_>,
    ) -> Result<(), LevelError> {
        for (i, l) in layers.enumerate() {
            let field = format!("{parent}[{i}]");
            let off = (off.0 + l.offset_x as f64, off.1 + l.offset_y as f64);
            match l.layer_type() {
                LayerType::Group(g) => {
                    self.visit(g.layers(), &format!("{field}.layers"), off, f)?
                }
                t => f(&field, &l.name, t, off)?,
            }
        }
        Ok(())
    }

    fn tile_layer(
        &self,
        field: &str,
        name: &str,
        tl: &TileLayer<'_>,
        off: (f64, f64),
    ) -> Result<Option<GridLayer>, LevelError> {
        let wanted = self
            .options
            .collision_layers
            .as_ref()
            .is_none_or(|names| names.iter().any(|n| n == name));
        if !wanted {
            return Ok(None);
        }
        let TileLayer::Finite(fl) = tl else {
            return Err(LevelError::UnknownLayer {
                file: self.file.into(),
                field: field.into(),
                kind: "infinite tile layer".into(),
            });
        };
        if off != (0.0, 0.0) {
            return Err(self.bad(
                format!("{field}.offsetx"),
                format!(
                    "tile layers must not be offset, got ({}, {}) px",
                    off.0, off.1
                ),
            ));
        }
        let (w, h) = (fl.width(), fl.height());
        if (w, h) != (self.map.width, self.map.height) {
            return Err(self.bad(
                format!("{field}.width"),
                format!(
                    "layer is {w} x {h} tiles, the map {} x {}",
                    self.map.width, self.map.height
                ),
            ));
        }
        // The tiled crate does not check the data length against the size,
        // and indexing past short data panics: probe the last cell first.
        if w > 0
            && h > 0
            && catch_unwind(AssertUnwindSafe(|| {
                fl.get_tile_data(w as i32 - 1, h as i32 - 1).is_some()
            }))
            .is_err()
        {
            return Err(self.bad(
                format!("{field}.data"),
                format!(
                    "fewer entries than the layer's {w} x {h} = {} cells",
                    w as u64 * h as u64
                ),
            ));
        }
        let mut tiles = Vec::with_capacity(w as usize * h as usize);
        for y in 0..h as i32 {
            for x in 0..w as i32 {
                let Some(lt) = fl.get_tile(x, y) else {
                    tiles.push(Tile::Empty);
                    continue;
                };
                let cf = format!("{field}.data[{}]", y as i64 * w as i64 + x as i64);
                let ts = lt.get_tileset();
                let kind_prop = lt
                    .get_tile()
                    .and_then(|t| t.properties.get("kind").cloned());
                let tile = match kind_prop {
                    Some(PropertyValue::StringValue(s)) => {
                        parse_tile_kind(&s).ok_or_else(|| LevelError::UnknownTile {
                            file: self.file.into(),
                            field: format!(
                                "{cf} (tileset {:?} tile {} properties.kind)",
                                ts.name,
                                lt.id()
                            ),
                            tile: format!("kind {s:?}"),
                            tileset: ts.name.clone(),
                        })?
                    }
                    Some(other) => {
                        return Err(self.bad(
                            format!(
                                "{cf} (tileset {:?} tile {} properties.kind)",
                                ts.name,
                                lt.id()
                            ),
                            format!("expected a string, got {other:?}"),
                        ));
                    }
                    None => self
                        .options
                        .mapping
                        .tile(&ts.name, lt.id())
                        .ok_or_else(|| LevelError::UnknownTile {
                            file: self.file.into(),
                            field: cf.clone(),
                            tile: format!("tile id {}", lt.id()),
                            tileset: ts.name.clone(),
                        })?,
                };
                let tile = match tile {
                    Tile::Slope(_) if lt.flip_v || lt.flip_d => {
                        return Err(self.bad(
                            cf,
                            "a slope flipped vertically or diagonally has no tile kind (ceilings are not supported)".into(),
                        ));
                    }
                    t if lt.flip_h => mirror(t),
                    t => t,
                };
                tiles.push(tile);
            }
        }
        let ts = self.map.tile_width;
        Ok(Some(GridLayer {
            field: field.into(),
            origin: IVec2::ZERO,
            cell: (ts, ts),
            cells: (w, h),
            tiles,
        }))
    }

    fn object_layer(
        &self,
        field: &str,
        layer_name: &str,
        ol: &ObjectLayer<'_>,
        off: (f64, f64),
        paths: &Paths,
        out: &mut Vec<PlacedEntity>,
    ) -> Result<(), LevelError> {
        let tile_px = self.map.tile_width as f64;
        for (k, o) in ol.objects().enumerate() {
            if paths.used.contains(&o.id()) && paths.by_id.contains_key(&o.id()) {
                continue;
            }
            let f = format!("{field}.objects[{k}]");
            let name = if o.user_type.trim().is_empty() {
                o.name.clone()
            } else {
                o.user_type.clone()
            };
            let (x, y) = (o.x as f64 + off.0, o.y as f64 + off.1);
            if let ObjectShape::Polygon { points } = &o.shape {
                let name = if name.trim().is_empty() {
                    "polygon".to_owned()
                } else {
                    name
                };
                let polygon = self.polygon(&f, o.id(), &name, points, (x, y), o.rotation)?;
                out.push(PlacedEntity {
                    name,
                    layer: layer_name.into(),
                    field: f,
                    values_key: "properties",
                    centre: polygon.points.first().copied().unwrap_or_default(),
                    size: IVec2::splat(2),
                    nodes: Vec::new(),
                    values: Vec::new(),
                    polygon: Some(polygon),
                });
                continue;
            }
            let (left, top, w, h) = match &o.shape {
                ObjectShape::Rect { width, height } | ObjectShape::Ellipse { width, height } => {
                    let (w, h) = (*width as f64, *height as f64);
                    // Tile objects are anchored at their bottom-left corner.
                    let top = if o.tile_data().is_some() { y - h } else { y };
                    (x, top, w, h)
                }
                ObjectShape::Point(..) => (x - tile_px / 2.0, y - tile_px / 2.0, tile_px, tile_px),
                other => {
                    let shape = match other {
                        ObjectShape::Polyline { .. } => "polyline",
                        ObjectShape::Text { .. } => "text",
                        _ => "capsule",
                    };
                    return Err(self.bad(
                        format!("{f}.shape"),
                        format!("a {shape} object is not an entity (polylines are platform paths: name them in a platform's `path` property)"),
                    ));
                }
            };
            let l = px_to_units(self.file, &format!("{f}.x"), left)?;
            let t = px_to_units(self.file, &format!("{f}.y"), top)?;
            let (centre, size) = place_box(self.file, &f, l, t, w, h)?;
            let mut values = Vec::new();
            let mut nodes = Vec::new();
            let mut props: Vec<_> = o.properties.iter().collect();
            props.sort_by(|a, b| a.0.cmp(b.0));
            for (key, v) in props {
                let pv = match v {
                    PropertyValue::BoolValue(b) => PropValue::Bool(*b),
                    PropertyValue::FloatValue(x) => PropValue::Number(*x as f64),
                    PropertyValue::IntValue(i) => PropValue::Number(*i as f64),
                    PropertyValue::StringValue(s) | PropertyValue::FileValue(s) => {
                        PropValue::Text(s.clone())
                    }
                    PropertyValue::ObjectValue(id) if key == "path" => {
                        let pf = format!("{f}.properties.path");
                        let Some(p) = paths.by_id.get(id) else {
                            return Err(
                                self.bad(pf, format!("object {id} is not a polyline or polygon"))
                            );
                        };
                        for (i, &(px, py)) in p.points.iter().enumerate() {
                            let nf = format!("{pf} (object {id} point {i})");
                            let nx = px_to_units(self.file, &format!("{nf}.x"), px)?;
                            let ny = px_to_units(self.file, &format!("{nf}.y"), py)?;
                            let (c, _) = place_box(
                                self.file,
                                &nf,
                                nx - size.x as i64 / 2,
                                ny - size.y as i64 / 2,
                                w,
                                h,
                            )?;
                            if !(i == 0 && c == centre) {
                                nodes.push(c);
                            }
                        }
                        if p.closed && !o.properties.keys().any(|k| k.eq_ignore_ascii_case("loop"))
                        {
                            values.push(("loop".into(), PropValue::Bool(true)));
                        }
                        continue;
                    }
                    other => PropValue::Text(format!("{other:?}")),
                };
                values.push((key.clone(), pv));
            }
            out.push(PlacedEntity {
                name,
                layer: layer_name.into(),
                field: f,
                values_key: "properties",
                centre,
                size,
                nodes,
                values,
                polygon: None,
            });
        }
        Ok(())
    }

    /// A polygon object's outline: its points (relative to the object's
    /// position, rotated clockwise by `rotation` degrees about it) as
    /// absolute units. At most [`super::MAX_PATH_NODES`] points are
    /// converted (more is refused).
    fn polygon(
        &self,
        f: &str,
        id: u32,
        name: &str,
        points: &[(f32, f32)],
        (x, y): (f64, f64),
        rotation: f32,
    ) -> Result<PlacedPolygon, LevelError> {
        let field = format!("{f}.polygon (object {id} {name:?})");
        if points.len() > super::MAX_PATH_NODES {
            return Err(LevelError::BadPolygon {
                file: self.file.into(),
                field,
                message: format!(
                    "polygon has {} vertices; it needs 3 to {}",
                    points.len(),
                    ledge_shared::shape::MAX_POLYGON_VERTICES
                ),
            });
        }
        let (sin, cos) = if rotation == 0.0 {
            (0.0, 1.0)
        } else {
            (rotation as f64).to_radians().sin_cos()
        };
        let mut out = PlacedPolygon {
            field,
            points: Vec::with_capacity(points.len()),
            point_fields: Vec::with_capacity(points.len()),
        };
        for (i, &(px, py)) in points.iter().enumerate() {
            let pf = format!("{f}.polygon[{i}] (object {id} {name:?})");
            let (px, py) = (px as f64, py as f64);
            let (ax, ay) = (x + px * cos - py * sin, y + px * sin + py * cos);
            let ux = px_to_units(self.file, &format!("{pf}.x"), ax)?;
            let uy = px_to_units(self.file, &format!("{pf}.y"), ay)?;
            check_coord_field(self.file, &format!("{pf}.x"), ux)?;
            check_coord_field(self.file, &format!("{pf}.y"), uy)?;
            out.points.push(IVec2::new(ux as i32, uy as i32));
            out.point_fields.push(pf);
        }
        Ok(out)
    }
}
