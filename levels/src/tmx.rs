//! Tiled maps (`.tmx`, with embedded or external `.tsx` tilesets), read
//! with the `tiled` crate after the bounded pre-scan of [`crate::limits`].
//!
//! * The map must be orthogonal, with square tiles of 1 to 4096 px, at most
//!   [`MAX_LEVEL_TILES`] per side; an infinite map's grid spans the chunks
//!   holding tiles.
//! * **Tile layers** (also inside group layers; hidden ones never) collide
//!   by the map's own data (the `collision` module): the settings' tile kinds,
//!   tile properties and classes, tile collision outlines (full squares and
//!   slopes become tiles, anything else static geometry), layer properties
//!   and classes; a map with no collision data at all collides its
//!   collision-named layers (else every visible one), and says so.
//! * **Object layers**: each object's class (Tiled 1.9+; `type` before) or
//!   its name goes through the entity table ([`super::ENTITY_NAMES`]) and
//!   the settings' aliases; custom properties are the parameters.
//!   Rectangles, ellipses and tile objects use their bounds; a point object
//!   is a box of one tile centred on it. A polygon entity is a convex
//!   polygon solid ([`super::EntityKind::PolygonBlock`], rotated by the
//!   object's rotation). Objects that are no entity are solid geometry when
//!   marked solid or unnamed shapes, hazards when marked so, else skipped
//!   with a warning. A moving platform's `path` property (type object) names
//!   a polyline or polygon object whose points are the centres the platform
//!   passes through (a polygon loops unless `loop` says otherwise); those
//!   path objects are not entities. Layer and group offsets shift objects.
//! * Image layers are art only ([`crate::art`]).

pub(crate) mod common;

use std::cell::RefCell;
use std::collections::{BTreeMap, BTreeSet};
use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use ::tiled::{
    ChunkData, DefaultResourceCache, LayerTile, LayerType, Loader, Map, Object, ObjectLayer,
    ObjectShape, Orientation, PropertyValue, ResourceReader, TileLayer,
};
use glam::IVec2;

use self::common::{object_name, props, short_data};
use super::collision::{self, tile_of_props, Outline, TileShape};
use super::entities::is_entity_name;
use super::entities::{
    check_coord_field, place_box, px_to_units, PlacedEntity, PlacedPolygon, PropValue, Turn,
};
use super::mapping::normalize;
use crate::assemble::{assemble, GridLayer};
use crate::collision::infer::{apply_painted, painted_warning, solid_elsewhere};
use crate::collision::names::decoration_word;
use crate::collision::names::{layer_thing, Thing};
use crate::error::LevelError;
use crate::loaded::LoadedLevel;
use crate::options::{LoadOptions, MAX_LEVEL_TILES};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::shape::MAX_POLYGON_VERTICES;
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
                crate::read::read_bytes(path)?
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
        fallback: Fallback::None,
        notes: RefCell::new(Notes::default()),
        grid: (0, 0, map.width, map.height),
        fallback_cells: RefCell::default(),
    }
    .run(path)?;
    loaded.art = crate::art::tiled::from_tiled(&file, &map, options)?;
    Ok(loaded)
}

struct Conv<'a> {
    file: &'a str,
    map: &'a Map,
    options: &'a LoadOptions,
    /// Which tile layers collide when nothing in the map says.
    fallback: Fallback,
    /// Warnings, aggregated.
    notes: RefCell<Notes>,
    /// The collision grid in tiles: left and top column/row, width and
    /// height (the map's size; an infinite map's: the chunks' bounds).
    grid: (i32, i32, u32, u32),
    /// The tile layers made solid by the fallback, by field: each cell's
    /// tile (tileset index, id), for [`painted`].
    fallback_cells: RefCell<Vec<FallbackLayer>>,
}

/// What collides in a map that carries no collision data at all (no tile
/// collision shapes, no collision properties or classes on tiles, tilesets
/// or layers).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Fallback {
    /// The map has collision data: tiles without any are empty.
    None,
    /// Every tile of the visible tile layers with a collision name
    /// ([`collision::is_collision_layer_name`]).
    NamedLayers,
    /// Every tile of every visible tile layer; when `but_decoration`, not
    /// of the layers named for decoration (`collision::names`).
    AllLayers {
        /// Leave out the decoration-named layers (some other is not one).
        but_decoration: bool,
    },
}

/// Warnings counted by what they say, with the first place each happened.
#[derive(Default)]
struct Notes {
    by_key: BTreeMap<String, (usize, String)>,
    order: Vec<String>,
}

impl Notes {
    /// Records `what` (one line, the same for every occurrence) at `place`.
    fn add(&mut self, what: String, place: impl FnOnce() -> String) {
        match self.by_key.get_mut(&what) {
            Some((n, _)) => *n += 1,
            None => {
                self.by_key.insert(what.clone(), (1, place()));
                self.order.push(what);
            }
        }
    }

    fn lines(self, file: &str) -> Vec<String> {
        let mut by_key = self.by_key;
        self.order
            .into_iter()
            .filter_map(|what| {
                let (n, place) = by_key.remove(&what)?;
                Some(if n == 1 {
                    format!("{file}: {place}: {what}")
                } else {
                    format!("{file}: {place} and {} more like it: {what}", n - 1)
                })
            })
            .collect()
    }
}

/// A layer as [`Conv::visit`] hands it over, groups applied.
struct LayerInfo<'l> {
    /// Path of the layer (`layers[1].layers[0]`).
    field: String,
    /// The layer's name.
    name: &'l str,
    /// Visible, with every group above it.
    visible: bool,
    /// What its properties/class (or its groups') say about collision.
    collides: Option<bool>,
    /// Offset in pixels, groups included.
    off: (f64, f64),
}

impl LayerInfo<'_> {
    /// `layer "Ground" (layers[2])`, for messages.
    fn describe(&self) -> String {
        format!("layer {:?} ({})", self.name, self.field)
    }
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

/// What [`Conv::visit`] calls on each layer.
type LayerFn<'m, 'f> = dyn FnMut(&LayerInfo<'_>, LayerType<'m>) -> Result<(), LevelError> + 'f;

/// What a tile's own data says about its collision.
enum TileRule {
    /// A ledge tile (flips still to apply to slopes).
    Kind(Tile),
    /// Collision outlines, tile-local pixels of the tile's own size.
    Outlines(Vec<Outline>),
    /// Nothing.
    Silent,
}

impl Conv<'_> {
    fn bad(&self, field: impl Into<String>, message: String) -> LevelError {
        LevelError::BadValue {
            file: self.file.into(),
            field: field.into(),
            message,
        }
    }

    fn run(mut self, path: &Path) -> Result<LoadedLevel, LevelError> {
        let m = self.map;
        if m.orientation != Orientation::Orthogonal {
            return Err(self.bad(
                "map.orientation",
                format!(
                    "{:?} maps are not supported: ledge levels are orthogonal (side view); make an orthogonal map",
                    m.orientation
                ),
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
        if m.infinite() {
            self.grid = self.chunk_bounds()?;
        }
        for (v, f) in [(self.grid.2, "map.width"), (self.grid.3, "map.height")] {
            if v > MAX_LEVEL_TILES {
                return Err(LevelError::OutOfBounds {
                    file: self.file.into(),
                    field: f.into(),
                    message: format!("{v} tiles is more than {MAX_LEVEL_TILES}"),
                });
            }
        }
        // Every polyline/polygon by id, the ids platforms use as paths, and
        // whether the map says anything about collision.
        let mut paths = Paths::default();
        let mut has_data = m.tilesets().iter().any(|ts| {
            ts.tiles().any(|(_, t)| {
                t.collision.is_some()
                    || !matches!(tile_of_props(props(&t.properties), &t.user_type), Ok(None))
            })
        });
        let mut named_layer = false;
        let mut plain_layer = false;
        let mut drawn_solids = DrawnSolids::default();
        self.visit(m.layers(), "layers", &mut |info, layer| {
            // A layer said to collide is collision data; one said not to
            // is not (the other layers may still collide by the fallback).
            has_data |= info.collides == Some(true);
            match layer {
                LayerType::Tiles(tl) => {
                    named_layer |= info.visible && collision::is_collision_layer_name(info.name);
                    plain_layer |= info.visible && decoration_word(info.name).is_none();
                    drawn_solids.tiles |= info.visible && holds_a_tile(&tl);
                }
                LayerType::Objects(ol) => {
                    self.solid_objects(info, &ol, &mut drawn_solids)?;
                    for o in ol.objects() {
                        let (ox, oy) = (o.x as f64 + info.off.0, o.y as f64 + info.off.1);
                        let (pts, closed) = match &o.shape {
                            ObjectShape::Polyline { points } => (points, false),
                            ObjectShape::Polygon { points } => (points, true),
                            _ => {
                                if let Some(PropertyValue::ObjectValue(id)) =
                                    o.properties.get("path")
                                {
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
                _ => {}
            }
            Ok(())
        })?;
        // Collision drawn as shapes in object layers is collision data:
        // the tile layers are then decoration unless the file says.
        if !has_data && drawn_solids.found(&paths) {
            has_data = true;
            self.objects_collide_note(&drawn_solids);
        }
        self.fallback = match (has_data, named_layer) {
            (true, _) => Fallback::None,
            (false, true) => Fallback::NamedLayers,
            (false, false) => Fallback::AllLayers {
                but_decoration: plain_layer,
            },
        };
        let mut grids = Vec::new();
        let mut entities = Vec::new();
        let mut any_tiles = false;
        self.visit(m.layers(), "layers", &mut |info, layer| {
            match layer {
                LayerType::Tiles(tl) => {
                    if let Some(g) = self.tile_layer(info, &tl, &mut entities)? {
                        any_tiles |= g.tiles.iter().any(|&t| t != Tile::Empty);
                        grids.push(g);
                    }
                }
                LayerType::Objects(ol) => self.object_layer(info, &ol, &paths, &mut entities)?,
                _ => {}
            }
            Ok(())
        })?;
        self.infer_painted(&mut grids, &entities);
        if self.fallback == Fallback::NamedLayers && any_tiles {
            self.notes.get_mut().add(
                "the map has no collision data (no tile collision shapes, no `solid`/`collides`/`one_way`/`hazard` tile properties, no collision layer property or class), so every tile of the visible layers named like collision layers (collision, solid, walls, ground, terrain, platforms, ...) is solid and the other layers are decoration; mark what collides in Tiled (see docs/LEVELS.md, \"What collides\")".into(),
                || "map".into(),
            );
        }
        if let (Fallback::AllLayers { but_decoration }, true) = (self.fallback, any_tiles) {
            let but = if but_decoration {
                " (but those named for decoration: camera, background, bg, decor, parallax, ...; list them in collision_layers to make them collide)"
            } else {
                ""
            };
            self.notes.get_mut().add(
                format!("the map has no collision data (no tile collision shapes, no `solid`/`collides`/`one_way`/`hazard` tile properties, no collision layer property or class, no layer named \"collision\"), so every tile of every visible tile layer is solid{but}; mark what collides in Tiled (see docs/LEVELS.md, \"What collides\")"),
                || "map".into(),
            );
        }
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let mut loaded = assemble(self.file, name, grids, entities, self.options)?;
        let notes = std::mem::take(self.notes.get_mut());
        loaded.warnings.splice(0..0, notes.lines(self.file));
        Ok(loaded)
    }

    /// Calls `f(info, layer)` on every layer, groups flattened: offsets
    /// accumulated (pixels), a hidden group hides its layers, and a group's
    /// collision property or class applies to the layers that have none.
    fn visit<'m>(
        &self,
        layers: impl Iterator<Item = ::tiled::Layer<'m>>,
        parent: &str,
        f: &mut LayerFn<'m, '_>,
    ) -> Result<(), LevelError> {
        let top = LayerInfo {
            field: String::new(),
            name: "",
            visible: true,
            collides: None,
            off: (0.0, 0.0),
        };
        self.visit_in(layers, parent, &top, f, 0)
    }

    fn visit_in<'m>(
        &self,
        layers: impl Iterator<Item = ::tiled::Layer<'m>>,
        parent: &str,
        up: &LayerInfo<'_>,
        f: &mut LayerFn<'m, '_>,
        depth: usize,
    ) -> Result<(), LevelError> {
        for (i, l) in layers.enumerate() {
            let info = LayerInfo {
                field: format!("{parent}[{i}]"),
                name: &l.name,
                visible: up.visible && l.visible,
                collides: self
                    .options
                    .layer_collides(&l.name)
                    .or_else(|| collision::layer_collides(props(&l.properties), &l.user_type))
                    .or(up.collides),
                off: (up.off.0 + l.offset_x as f64, up.off.1 + l.offset_y as f64),
            };
            match l.layer_type() {
                LayerType::Group(g) => {
                    if depth >= MAX_GROUP_DEPTH {
                        return Err(self.bad(
                            info.field,
                            format!("groups nested deeper than {MAX_GROUP_DEPTH}"),
                        ));
                    }
                    let field = format!("{}.layers", info.field);
                    self.visit_in(g.layers(), &field, &info, f, depth + 1)?
                }
                t => f(&info, t)?,
            }
        }
        Ok(())
    }

    /// What a tileset tile says about its collision (its `kind` and
    /// collision properties, its class, its collision outlines), or what
    /// [`LoadOptions::mapping`] says for its tileset.
    fn tile_rule(
        &self,
        ts: &::tiled::Tileset,
        id: u32,
        field: &str,
    ) -> Result<TileRule, LevelError> {
        if let Some(&k) = self.options.tile_kinds.get(&(ts.name.to_lowercase(), id)) {
            return Ok(TileRule::Kind(k));
        }
        let tile = ts.get_tile(id);
        if let Some(t) = &tile {
            let mut named: Vec<_> = t
                .properties
                .iter()
                .filter(|(_, v)| !matches!(v, PropertyValue::BoolValue(false)))
                .filter_map(|(k, _)| self.options.tile_properties.get(&normalize(k)))
                .collect();
            named.sort_by_key(|t| t.code());
            if let Some(&&k) = named.first() {
                return Ok(TileRule::Kind(k));
            }
            let said = tile_of_props(props(&t.properties), &t.user_type).map_err(|m| {
                self.bad(
                    format!("{field} (tileset {:?} tile {id} properties)", ts.name),
                    m,
                )
            })?;
            if let Some(tile) = said {
                return Ok(TileRule::Kind(tile));
            }
        }
        if self.options.mapping.has_table(&ts.name) {
            return match self.options.mapping.tile(&ts.name, id) {
                Some(tile) => Ok(TileRule::Kind(tile)),
                None => Err(LevelError::UnknownTile {
                    file: self.file.into(),
                    field: field.into(),
                    tile: format!("tile id {id}"),
                    tileset: ts.name.clone(),
                }),
            };
        }
        let Some(t) = tile else {
            return Ok(TileRule::Silent);
        };
        let Some(group) = &t.collision else {
            return Ok(TileRule::Silent);
        };
        let mut outlines = Vec::new();
        for o in group.object_data() {
            let (x, y, r) = (o.x as f64, o.y as f64, o.rotation as f64);
            let outline = match &o.shape {
                ObjectShape::Rect { width, height } => {
                    collision::rect_outline(x, y, *width as f64, *height as f64, r)
                }
                ObjectShape::Ellipse { width, height } => {
                    let e = collision::ellipse_outline(0.0, 0.0, *width as f64, *height as f64);
                    collision::rotate_about(&e, (x, y), r)
                }
                ObjectShape::Polygon { points } => {
                    let pts: Vec<_> = points.iter().map(|&(a, b)| (a as f64, b as f64)).collect();
                    collision::rotate_about(&pts, (x, y), r)
                }
                _ => {
                    self.notes.borrow_mut().add(
                        format!(
                            "tileset {:?} tile {id}: collision shapes other than rectangles, ellipses and polygons (polylines, points) are ignored",
                            ts.name
                        ),
                        || field.to_owned(),
                    );
                    continue;
                }
            };
            outlines.push(outline);
        }
        Ok(if outlines.is_empty() {
            TileRule::Silent
        } else {
            TileRule::Outlines(outlines)
        })
    }

    fn tile_layer(
        &self,
        info: &LayerInfo<'_>,
        tl: &TileLayer<'_>,
        geometry: &mut Vec<PlacedEntity>,
    ) -> Result<Option<GridLayer>, LevelError> {
        let field = info.field.as_str();
        let wanted = self
            .options
            .collision_layers
            .as_ref()
            .is_none_or(|names| names.iter().any(|n| n == info.name));
        if !wanted || info.collides == Some(false) {
            return Ok(None);
        }
        if !info.visible {
            self.notes.borrow_mut().add(
                "hidden tile layer: not collided (make it visible in Tiled to collide)".into(),
                || info.describe(),
            );
            return Ok(None);
        }
        if info.off != (0.0, 0.0) {
            return Err(self.bad(
                format!("{field}.offsetx"),
                format!(
                    "tile layers must not be offset, got ({}, {}) px",
                    info.off.0, info.off.1
                ),
            ));
        }
        let (ox, oy, w, h) = self.grid;
        if let TileLayer::Finite(fl) = tl {
            if (fl.width(), fl.height()) != (w, h) {
                return Err(self.bad(
                    format!("{field}.width"),
                    format!(
                        "layer is {} x {} tiles, the map {w} x {h}",
                        fl.width(),
                        fl.height()
                    ),
                ));
            }
            if short_data(fl) {
                return Err(self.bad(
                    format!("{field}.data"),
                    format!(
                        "fewer entries than the layer's {w} x {h} = {} cells",
                        w as u64 * h as u64
                    ),
                ));
            }
        }
        // Grid cell (x, y) is map tile (x + ox, y + oy).
        let cell = |x: i32, y: i32| match tl {
            TileLayer::Finite(fl) => fl.get_tile(x, y),
            TileLayer::Infinite(il) => il.get_tile(x + ox, y + oy),
        };
        let fallback = match self.fallback {
            Fallback::None => false,
            Fallback::NamedLayers => collision::is_collision_layer_name(info.name),
            Fallback::AllLayers { but_decoration } => {
                !but_decoration || decoration_word(info.name).is_none()
            }
        };
        let t = self.map.tile_width as f64;
        let mut rules: BTreeMap<(usize, u32), TileRule> = BTreeMap::new();
        let mut tiles = Vec::with_capacity(w as usize * h as usize);
        for y in 0..h as i32 {
            for x in 0..w as i32 {
                let Some(lt) = cell(x, y) else {
                    tiles.push(Tile::Empty);
                    continue;
                };
                let cf = || format!("{field}.data[{}]", y as i64 * w as i64 + x as i64);
                let ts = lt.get_tileset();
                let key = (lt.tileset_index(), lt.id());
                if let std::collections::btree_map::Entry::Vacant(v) = rules.entry(key) {
                    v.insert(self.tile_rule(ts, lt.id(), &cf())?);
                }
                let (tw, th) = (ts.tile_width as f64, ts.tile_height as f64);
                let flips = (lt.flip_h, lt.flip_v, lt.flip_d);
                let shape = match &rules[&key] {
                    TileRule::Kind(Tile::Slope(s)) if flips != (false, false, false) => {
                        let mut o = collision::region_outline(Tile::Slope(*s), t);
                        collision::flip(&mut o, t, flips.0, flips.1, flips.2);
                        collision::classify_outlines(vec![o], t)
                    }
                    TileRule::Kind(k) => TileShape::Tile(*k),
                    TileRule::Outlines(outlines) => {
                        let mut outlines = outlines.clone();
                        for o in &mut outlines {
                            collision::flip(o, tw, flips.0, flips.1, flips.2);
                        }
                        if (tw, th) == (t, t) {
                            collision::classify_outlines(outlines, t)
                        } else {
                            // A tile of another size stands on the cell's
                            // bottom-left corner.
                            for o in &mut outlines {
                                for p in o.iter_mut() {
                                    p.1 += t - th;
                                }
                            }
                            TileShape::Geometry(outlines)
                        }
                    }
                    TileRule::Silent if info.collides == Some(true) || fallback => {
                        TileShape::Tile(Tile::Solid)
                    }
                    TileRule::Silent => TileShape::Tile(Tile::Empty),
                };
                match shape {
                    TileShape::Tile(tile) => tiles.push(tile),
                    TileShape::Geometry(outlines) => {
                        tiles.push(Tile::Empty);
                        let corner = ((x + ox) as f64 * t, (y + oy) as f64 * t);
                        for (k, o) in outlines.into_iter().enumerate() {
                            let abs: Vec<_> =
                                o.iter().map(|p| (corner.0 + p.0, corner.1 + p.1)).collect();
                            let gf = format!(
                                "{} (tileset {:?} tile {} collision shape {k})",
                                cf(),
                                ts.name,
                                lt.id()
                            );
                            self.push_geometry(info, &gf, (x + ox, y + oy), &abs, geometry)?;
                        }
                    }
                }
            }
        }
        if fallback && info.collides != Some(true) {
            self.keep_fallback_cells(field, (w, h), &cell, &rules);
        }
        let ts = self.map.tile_width;
        let origin = [ox, oy].map(|o| o as i64 * ts as i64 * UNITS_PER_PX as i64);
        for (v, axis) in origin.iter().zip(["x", "y"]) {
            check_coord_field(self.file, &format!("{field} (grid origin {axis})"), *v)?;
        }
        Ok(Some(GridLayer {
            field: field.into(),
            name: info.name.into(),
            origin: IVec2::new(origin[0] as i32, origin[1] as i32),
            cell: (ts, ts),
            cells: (w, h),
            tiles,
        }))
    }

    /// An infinite map's grid: the bounds, in tiles, of every chunk holding
    /// a tile in any tile layer (`(left, top, width, height)`; empty
    /// chunks do not count).
    fn chunk_bounds(&self) -> Result<(i32, i32, u32, u32), LevelError> {
        let (mut lo, mut hi) = ((i64::MAX, i64::MAX), (i64::MIN, i64::MIN));
        self.visit(self.map.layers(), "layers", &mut |_, layer| {
            if let LayerType::Tiles(TileLayer::Infinite(il)) = layer {
                for ((cx, cy), chunk) in il.chunks() {
                    let (cw, ch) = (ChunkData::WIDTH as i32, ChunkData::HEIGHT as i32);
                    let used = (0..ch).any(|y| (0..cw).any(|x| chunk.get_tile(x, y).is_some()));
                    if used {
                        let (x0, y0) = (cx as i64 * cw as i64, cy as i64 * ch as i64);
                        lo = (lo.0.min(x0), lo.1.min(y0));
                        hi = (hi.0.max(x0 + cw as i64), hi.1.max(y0 + ch as i64));
                    }
                }
            }
            Ok(())
        })?;
        if lo.0 > hi.0 {
            return Ok((0, 0, 0, 0));
        }
        let (w, h) = (hi.0 - lo.0, hi.1 - lo.1);
        if w > MAX_LEVEL_TILES as i64 || h > MAX_LEVEL_TILES as i64 {
            return Err(LevelError::OutOfBounds {
                file: self.file.into(),
                field: "map (infinite: the chunks' extent)".into(),
                message: format!(
                    "the tiles span {w} x {h} tiles (from ({}, {})), more than {MAX_LEVEL_TILES} per side",
                    lo.0, lo.1
                ),
            });
        }
        Ok((lo.0 as i32, lo.1 as i32, w as u32, h as u32))
    }

    /// Static solid geometry outside the grid from an outline in absolute
    /// pixels: an axis-aligned box becomes a block, a convex outline of 3
    /// to 8 points a polygon block; anything else is skipped with a
    /// warning. `at` is the place (tiles) for the warning.
    fn push_geometry(
        &self,
        info: &LayerInfo<'_>,
        field: &str,
        at: (i32, i32),
        outline: &[(f64, f64)],
        out: &mut Vec<PlacedEntity>,
    ) -> Result<(), LevelError> {
        let place = || format!("{} at ({}, {}) tiles", info.describe(), at.0, at.1);
        let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
        for p in outline {
            lo = (lo.0.min(p.0), lo.1.min(p.1));
            hi = (hi.0.max(p.0), hi.1.max(p.1));
        }
        let axis_box = outline.len() == 4
            && outline
                .iter()
                .all(|p| [lo.0, hi.0].contains(&p.0) && [lo.1, hi.1].contains(&p.1));
        if axis_box {
            let l = px_to_units(self.file, &format!("{field}.x"), lo.0)?;
            let tp = px_to_units(self.file, &format!("{field}.y"), lo.1)?;
            if hi.0 - lo.0 <= 0.0 || hi.1 - lo.1 <= 0.0 {
                self.notes.borrow_mut().add(
                    "a collision rectangle of zero size is ignored".into(),
                    place,
                );
                return Ok(());
            }
            let (centre, size) = place_box(self.file, field, l, tp, hi.0 - lo.0, hi.1 - lo.1)?;
            out.push(geometry_entity(info, field, centre, size, None));
            return Ok(());
        }
        if !collision::is_convex(outline) || !(3..=MAX_POLYGON_VERTICES).contains(&outline.len()) {
            // Concave, or too many points: convex pieces of the same area.
            let Some(pieces) = collision::convex_pieces(outline, MAX_POLYGON_VERTICES) else {
                self.notes.borrow_mut().add(
                    "a collision outline that crosses itself (or has no area) is ignored: redraw it as a simple polygon".into(),
                    place,
                );
                return Ok(());
            };
            for (k, piece) in pieces.iter().enumerate() {
                self.push_geometry(info, &format!("{field} (convex piece {k})"), at, piece, out)?;
            }
            return Ok(());
        }
        let mut poly = PlacedPolygon {
            field: field.into(),
            points: Vec::with_capacity(outline.len()),
            point_fields: Vec::with_capacity(outline.len()),
        };
        for (i, &(x, y)) in outline.iter().enumerate() {
            let pf = format!("{field}[{i}]");
            let ux = px_to_units(self.file, &format!("{pf}.x"), x)?;
            let uy = px_to_units(self.file, &format!("{pf}.y"), y)?;
            poly.points.push(IVec2::new(ux as i32, uy as i32));
            poly.point_fields.push(pf);
        }
        let first = poly.points[0];
        out.push(geometry_entity(
            info,
            field,
            first,
            IVec2::splat(2),
            Some(poly),
        ));
        Ok(())
    }

    fn object_layer(
        &self,
        info: &LayerInfo<'_>,
        ol: &ObjectLayer<'_>,
        paths: &Paths,
        out: &mut Vec<PlacedEntity>,
    ) -> Result<(), LevelError> {
        let field = info.field.as_str();
        let off = info.off;
        if !info.visible {
            if ol.objects().len() > 0 {
                self.notes.borrow_mut().add(
                    format!(
                        "hidden object layer: its {} objects are ignored (make it visible in Tiled to use them)",
                        ol.objects().len()
                    ),
                    || info.describe(),
                );
            }
            return Ok(());
        }
        for (k, o) in ol.objects().enumerate() {
            if paths.used.contains(&o.id()) && paths.by_id.contains_key(&o.id()) {
                continue;
            }
            let f = format!("{field}.objects[{k}]");
            let known = |n: &str| is_entity_name(self.options.entity_name(n));
            let name = object_name(self.options, &o).to_owned();
            let (x, y) = (o.x as f64 + off.0, o.y as f64 + off.1);
            if !o.visible {
                self.notes.borrow_mut().add(
                    "hidden objects are ignored (make them visible in Tiled to use them)".into(),
                    || object_place(info, &o, &name, (x, y)),
                );
                continue;
            }
            if !known(&name) {
                self.other_object(info, &f, &o, &name, (x, y), out)?;
                continue;
            }
            if let ObjectShape::Polygon { points } = &o.shape {
                let polygon = self.polygon(&f, o.id(), &name, points, (x, y), o.rotation)?;
                out.push(PlacedEntity {
                    name,
                    layer: info.name.into(),
                    field: f,
                    values_key: "properties",
                    centre: polygon.points.first().copied().unwrap_or_default(),
                    size: IVec2::splat(2),
                    nodes: Vec::new(),
                    values: Vec::new(),
                    polygon: Some(polygon),
                    turn: None,
                    sized: false,
                });
                continue;
            }
            let (left, top, w, h) = self.entity_box(&f, &o, (x, y))?;
            let l = px_to_units(self.file, &format!("{f}.x"), left)?;
            let t = px_to_units(self.file, &format!("{f}.y"), top)?;
            let (centre, size) = place_box(self.file, &f, l, t, w, h)?;
            let (values, nodes) = self.entity_values(&f, &o, paths, centre, size, (w, h))?;
            // Tiled turns an object about its position (a tile object's
            // bottom-left corner); a point has nothing to turn, nor a size.
            let sized = !matches!(o.shape, ObjectShape::Point(..));
            let turn = sized
                .then(|| {
                    let u = f64::from(UNITS_PER_PX);
                    Turn::new(o.rotation as f64, (x * u, y * u), format!("{f}.rotation"))
                })
                .flatten();
            out.push(PlacedEntity {
                name,
                layer: info.name.into(),
                field: f,
                values_key: "properties",
                centre,
                size,
                nodes,
                values,
                polygon: None,
                turn,
                sized,
            });
        }
        Ok(())
    }

    /// An object that is no entity: solid geometry if it says so (or is an
    /// unnamed shape), a hazard, or something to skip (with a note, or an
    /// error when unknown entities are refused).
    fn other_object(
        &self,
        info: &LayerInfo<'_>,
        f: &str,
        o: &::tiled::Object<'_>,
        name: &str,
        (x, y): (f64, f64),
        out: &mut Vec<PlacedEntity>,
    ) -> Result<(), LevelError> {
        let at = || object_place(info, o, name, (x, y));
        let tile = o.get_tile();
        match self.object_role(info, f, o, name)? {
            Role::Solid => {}
            Role::Hazard => {
                if let Some((l, t, w, h)) = object_box(&o.shape, x, y, tile.is_some()) {
                    let lu = px_to_units(self.file, &format!("{f}.x"), l)?;
                    let tu = px_to_units(self.file, &format!("{f}.y"), t)?;
                    let (centre, size) = place_box(self.file, f, lu, tu, w, h)?;
                    let mut e = geometry_entity(info, f, centre, size, None);
                    e.name = "hazard".into();
                    out.push(e);
                }
                return Ok(());
            }
            Role::OneWay => {
                self.notes.borrow_mut().add(
                    "one-way objects are not supported (use one-way tiles or a platform object named \"platform\" with `one_way`); ignored".into(),
                    at,
                );
                return Ok(());
            }
            Role::Empty => return Ok(()),
            Role::Entity { name: e, why } => {
                return self.entity_by_name(info, f, o, &e, &why, (x, y), out);
            }
            Role::Skip { why } => {
                self.notes.borrow_mut().add(
                    format!(
                        "objects with no ledge name or class are neither collision nor entities by {why}: skipped (give them a ledge name or class, or alias the layer in the level's settings: [entities] {:?} = \"block\")",
                        info.name
                    ),
                    at,
                );
                return Ok(());
            }
            Role::Marker => {
                // Decoration (tile objects, drawn), markers
                // (points), labels (text): nothing to collide
                // with; said for the ones that are not drawn.
                if tile.is_none() {
                    self.notes.borrow_mut().add(
                        "unnamed points, text and capsules are markers and labels: not used (name a point \"spawn\", \"coin\", ... to make it an entity)".into(),
                        at,
                    );
                }
                return Ok(());
            }
            Role::Unknown => {
                if !self.options.skip_unknown_entities {
                    return Err(LevelError::UnknownEntity {
                        file: self.file.into(),
                        field: format!("{f}.name"),
                        layer: info.name.into(),
                        name: name.to_owned(),
                    });
                }
                self.notes.borrow_mut().add(
                    format!(
                        "skipped objects named {name:?}: not a ledge entity (known: {}); give them a known name or class, or an alias in the level's settings",
                        crate::ENTITY_NAMES.join(", ")
                    ),
                    at,
                );
                return Ok(());
            }
        }
        self.solid_object(info, f, o, (x, y), out)
    }

    /// An entity object's box `(left, top, width, height)` in pixels: a
    /// point is one tile centred on it; polylines, text and capsules are
    /// refused.
    fn entity_box(
        &self,
        f: &str,
        o: &::tiled::Object<'_>,
        (x, y): (f64, f64),
    ) -> Result<(f64, f64, f64, f64), LevelError> {
        let tile_px = self.map.tile_width as f64;
        Ok(match &o.shape {
            ObjectShape::Point(..) => (x - tile_px / 2.0, y - tile_px / 2.0, tile_px, tile_px),
            shape => match object_box(shape, x, y, o.tile_data().is_some()) {
                Some(b) => b,
                None => {
                    let shape = match shape {
                        ObjectShape::Polyline { .. } => "polyline",
                        ObjectShape::Text { .. } => "text",
                        _ => "capsule",
                    };
                    return Err(self.bad(
                        format!("{f}.shape"),
                        format!("a {shape} object is not an entity (polylines are platform paths: name them in a platform's `path` property)"),
                    ));
                }
            },
        })
    }

    /// An entity object's parameters (its custom properties, by name) and
    /// path nodes (the points of the object its `path` property names, as
    /// centres of its `size`; `(w, h)` its box in pixels).
    #[allow(clippy::type_complexity)]
    fn entity_values(
        &self,
        f: &str,
        o: &::tiled::Object<'_>,
        paths: &Paths,
        centre: IVec2,
        size: IVec2,
        (w, h): (f64, f64),
    ) -> Result<(Vec<(String, PropValue)>, Vec<IVec2>), LevelError> {
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
                    if p.closed && !o.properties.keys().any(|k| k.eq_ignore_ascii_case("loop")) {
                        values.push(("loop".into(), PropValue::Bool(true)));
                    }
                    continue;
                }
                other => PropValue::Text(format!("{other:?}")),
            };
            values.push((key.clone(), pv));
        }
        Ok((values, nodes))
    }

    /// A solid object that is not an entity: a rectangle (turned by its
    /// rotation), an ellipse (as an octagon), or a tile object (its tile's
    /// collision outlines fitted to the object, else its box), as static
    /// geometry.
    fn solid_object(
        &self,
        info: &LayerInfo<'_>,
        f: &str,
        o: &::tiled::Object<'_>,
        (x, y): (f64, f64),
        out: &mut Vec<PlacedEntity>,
    ) -> Result<(), LevelError> {
        let r = o.rotation as f64;
        let at = (
            (x / self.map.tile_width as f64).floor() as i32,
            (y / self.map.tile_height as f64).floor() as i32,
        );
        let outlines: Vec<Outline> = match (&o.shape, o.get_tile()) {
            (ObjectShape::Rect { width, height }, Some(tile)) => {
                // Tile objects stand on their bottom-left corner and turn
                // about it; the tile's outlines scale to the object's size.
                let (w, h) = (*width as f64, *height as f64);
                let ts = tile.get_tileset();
                let (tw, th) = match tile.get_tile().and_then(|t| t.image.clone()) {
                    Some(img) => (img.width as f64, img.height as f64),
                    None => (ts.tile_width as f64, ts.tile_height as f64),
                };
                let data = o.tile_data();
                let (fh, fv) = data.map(|d| (d.flip_h, d.flip_v)).unwrap_or_default();
                let own = match self.tile_rule(ts, tile.id(), f)? {
                    TileRule::Outlines(v) => v,
                    _ => vec![collision::rect_outline(0.0, 0.0, tw, th, 0.0)],
                };
                own.into_iter()
                    .map(|mut ol| {
                        for p in ol.iter_mut() {
                            if fh {
                                p.0 = tw - p.0;
                            }
                            if fv {
                                p.1 = th - p.1;
                            }
                            *p = (p.0 * w / tw.max(1e-9), p.1 * h / th.max(1e-9) - h);
                        }
                        collision::rotate_about(&ol, (x, y), r)
                    })
                    .collect()
            }
            (ObjectShape::Rect { width, height }, None) => {
                vec![collision::rect_outline(
                    x,
                    y,
                    *width as f64,
                    *height as f64,
                    r,
                )]
            }
            (ObjectShape::Ellipse { width, height }, _) => {
                let e = collision::ellipse_outline(0.0, 0.0, *width as f64, *height as f64);
                vec![collision::rotate_about(&e, (x, y), r)]
            }
            (ObjectShape::Polyline { points }, _) => {
                // A chain of solid lines: each leg a quad 2 px thick on its
                // right-hand side (below a line drawn left to right, as
                // Box2D chains are drawn over the ground).
                if points.len() > super::MAX_PATH_NODES {
                    return Err(LevelError::BadPolygon {
                        file: self.file.into(),
                        field: format!("{f}.polyline"),
                        message: format!(
                            "polyline has {} points; at most {} are read",
                            points.len(),
                            super::MAX_PATH_NODES
                        ),
                    });
                }
                let pts: Vec<_> = points.iter().map(|&(a, b)| (a as f64, b as f64)).collect();
                let abs = collision::rotate_about(&pts, (x, y), r);
                abs.windows(2)
                    .filter_map(|w| collision::thick_line(w[0], w[1], POLYLINE_THICKNESS))
                    .collect()
            }
            (ObjectShape::Polygon { points }, _) => {
                if points.len() > super::MAX_PATH_NODES {
                    return Err(LevelError::BadPolygon {
                        file: self.file.into(),
                        field: format!("{f}.polygon"),
                        message: format!(
                            "polygon has {} vertices; at most {} are read",
                            points.len(),
                            super::MAX_PATH_NODES
                        ),
                    });
                }
                let pts: Vec<_> = points.iter().map(|&(a, b)| (a as f64, b as f64)).collect();
                vec![collision::rotate_about(&pts, (x, y), r)]
            }
            _ => {
                self.notes.borrow_mut().add(
                    "solid objects must be rectangles, ellipses, polygons or tile objects; this one is ignored".into(),
                    || format!("{} object {}", info.describe(), o.id()),
                );
                return Ok(());
            }
        };
        for (k, ol) in outlines.iter().enumerate() {
            let gf = if outlines.len() == 1 {
                f.to_owned()
            } else {
                format!("{f} (collision shape {k})")
            };
            self.push_geometry(info, &gf, at, ol, out)?;
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
                    MAX_POLYGON_VERTICES
                ),
            });
        }
        let pts: Vec<_> = points.iter().map(|&(a, b)| (a as f64, b as f64)).collect();
        let abs = collision::rotate_about(&pts, (x, y), rotation as f64);
        let mut out = PlacedPolygon {
            field,
            points: Vec::with_capacity(points.len()),
            point_fields: Vec::with_capacity(points.len()),
        };
        for (i, &(ax, ay)) in abs.iter().enumerate() {
            let pf = format!("{f}.polygon[{i}] (object {id} {name:?})");
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

/// How thick a solid polyline's legs are, in pixels.
const POLYLINE_THICKNESS: f64 = 2.0;

/// Deepest nesting of group layers.
const MAX_GROUP_DEPTH: usize = 64;

/// The box `(left, top, width, height)` in pixels of a rectangle, ellipse
/// or tile object (tile objects stand on their bottom-left corner); `None`
/// for other shapes.
fn object_box(shape: &ObjectShape, x: f64, y: f64, is_tile: bool) -> Option<(f64, f64, f64, f64)> {
    match shape {
        ObjectShape::Rect { width, height } | ObjectShape::Ellipse { width, height } => {
            let (w, h) = (*width as f64, *height as f64);
            let top = if is_tile { y - h } else { y };
            Some((x, top, w, h))
        }
        _ => None,
    }
}

/// Where an object is, for notes: its layer, id, name and position.
fn object_place(
    info: &LayerInfo<'_>,
    o: &::tiled::ObjectData,
    name: &str,
    (x, y): (f64, f64),
) -> String {
    format!(
        "{} object {} {:?} at ({:.0}, {:.0}) px",
        info.describe(),
        o.id(),
        name,
        x,
        y
    )
}

/// A static solid from a tile collision shape or a solid object.
fn geometry_entity(
    info: &LayerInfo<'_>,
    field: &str,
    centre: IVec2,
    size: IVec2,
    polygon: Option<PlacedPolygon>,
) -> PlacedEntity {
    PlacedEntity {
        name: if polygon.is_some() {
            "polygon"
        } else {
            "block"
        }
        .into(),
        layer: info.name.into(),
        field: field.into(),
        values_key: "properties",
        centre,
        size,
        nodes: Vec::new(),
        values: Vec::new(),
        polygon,
        turn: None,
        sized: false,
    }
}

// ---- objects: Tiled objects that are not ledge entities by their own name: what their
// properties, their shape and their layer's name make of them ([`Role`]),
// the one rule both the importer's pre-pass (is there collision drawn as
// objects?) and its object pass read.

/// What an object that is no entity by its own name becomes.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Role {
    /// Static solid geometry: marked solid (or a slope), an unnamed shape,
    /// or a shape in a layer named for solid things (`Ground`, `Pipes`).
    Solid,
    /// A hazard box (marked so).
    Hazard,
    /// Marked one-way: not supported.
    OneWay,
    /// Marked not solid.
    Empty,
    /// This entity, by its layer's name (or its own, `Goomba`), or by the
    /// settings' `[entities]` alias for the layer.
    Entity {
        /// The ledge entity name.
        name: String,
        /// What said so: `layer "Coins"` or `the settings' [entities] alias`.
        why: String,
    },
    /// Skipped by its layer's name (`Camera`, `Background`, `Triggers`) or
    /// the settings' `decoration_layers`.
    Skip {
        /// What said so.
        why: String,
    },
    /// An unnamed point, text or capsule (a marker or label), or an unnamed
    /// tile object (drawn only).
    Marker,
    /// A name that is no entity: skipped with a warning (or refused).
    Unknown,
}

/// Whether a shape can be solid geometry by its layer's name (tile objects
/// are pictures: only their own marks make them solid).
fn is_plain_shape(o: &Object<'_>) -> bool {
    o.get_tile().is_none()
        && matches!(
            o.shape,
            ObjectShape::Rect { .. }
                | ObjectShape::Ellipse { .. }
                | ObjectShape::Polygon { .. }
                | ObjectShape::Polyline { .. }
        )
}

impl Conv<'_> {
    /// The role of object `o` (named `name`, which is no entity) in layer
    /// `info`. Its own marks win; then the settings' `decoration_layers`,
    /// an `[entities]` alias for the layer's name, the object's own name and
    /// its layer's name (`collision::names`); then an unnamed shape is
    /// solid.
    fn object_role(
        &self,
        info: &LayerInfo<'_>,
        f: &str,
        o: &Object<'_>,
        name: &str,
    ) -> Result<Role, LevelError> {
        let own = tile_of_props(props(&o.properties), "")
            .map_err(|m| self.bad(format!("{f}.properties"), m))?;
        let from_tile = match (own, o.get_tile()) {
            (None, Some(t)) => match t.get_tile() {
                Some(td) => tile_of_props(props(&td.properties), &td.user_type)
                    .map_err(|m| self.bad(format!("{f}.properties"), m))?,
                None => None,
            },
            _ => None,
        };
        match own.or(from_tile) {
            Some(Tile::Solid) | Some(Tile::Slope(_)) => return Ok(Role::Solid),
            Some(Tile::Hazard) => return Ok(Role::Hazard),
            Some(Tile::OneWay) => return Ok(Role::OneWay),
            Some(Tile::Empty) => return Ok(Role::Empty),
            None => {}
        }
        if self
            .options
            .decoration_layers
            .iter()
            .any(|n| n == info.name)
        {
            return Ok(Role::Skip {
                why: format!("decoration_layers lists layer {:?}", info.name),
            });
        }
        if let Some(alias) = self.options.entity_aliases.get(&normalize(info.name)) {
            if is_entity_name(alias) {
                return Ok(Role::Entity {
                    name: alias.clone(),
                    why: format!("the settings' [entities] alias for layer {:?}", info.name),
                });
            }
        }
        let by_name = (!name.trim().is_empty())
            .then(|| layer_thing(name).map(|t| (t, format!("its name {name:?}"))))
            .flatten();
        let by_layer = || layer_thing(info.name).map(|t| (t, format!("layer {:?}", info.name)));
        match by_name.or_else(by_layer) {
            Some(((Thing::Entity(e), _), why)) => Ok(Role::Entity {
                name: e.into(),
                why,
            }),
            Some(((Thing::Solid, _), _)) if is_plain_shape(o) => Ok(Role::Solid),
            Some(((Thing::Skip, _), why)) => Ok(Role::Skip { why }),
            _ if name.trim().is_empty() && is_plain_shape(o) => Ok(Role::Solid),
            _ if name.trim().is_empty() => Ok(Role::Marker),
            _ => Ok(Role::Unknown),
        }
    }
}

impl Conv<'_> {
    /// Places object `o` as entity `entity` (its [`Role::Entity`]): its
    /// box (a point: one tile centred on it; a polygon or polyline: its
    /// points' bounds), its custom properties as parameters, and a note
    /// saying why and how to choose otherwise. Text and capsules are
    /// skipped, said.
    #[allow(clippy::too_many_arguments)]
    fn entity_by_name(
        &self,
        info: &LayerInfo<'_>,
        f: &str,
        o: &Object<'_>,
        entity: &str,
        why: &str,
        (x, y): (f64, f64),
        out: &mut Vec<crate::entities::PlacedEntity>,
    ) -> Result<(), LevelError> {
        let at = || format!("{} object {}", info.describe(), o.id());
        let bounds = |pts: &[(f32, f32)]| {
            let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
            for &(a, b) in pts {
                lo = (lo.0.min(a as f64), lo.1.min(b as f64));
                hi = (hi.0.max(a as f64), hi.1.max(b as f64));
            }
            (x + lo.0, y + lo.1, hi.0 - lo.0, hi.1 - lo.1)
        };
        let (left, top, w, h) = match &o.shape {
            ObjectShape::Polygon { points } | ObjectShape::Polyline { points }
                if !points.is_empty() =>
            {
                bounds(points)
            }
            ObjectShape::Text { .. }
            | ObjectShape::Polygon { .. }
            | ObjectShape::Polyline { .. } => {
                self.notes
                    .borrow_mut()
                    .add(format!("a text or empty shape is no {entity}: skipped"), at);
                return Ok(());
            }
            _ => match self.entity_box(f, o, (x, y)) {
                Ok(b) => b,
                Err(_) => {
                    self.notes
                        .borrow_mut()
                        .add(format!("a capsule is no {entity}: skipped"), at);
                    return Ok(());
                }
            },
        };
        let l = crate::entities::px_to_units(self.file, &format!("{f}.x"), left)?;
        let t = crate::entities::px_to_units(self.file, &format!("{f}.y"), top)?;
        let (centre, size) =
            crate::entities::place_box(self.file, f, l, t, w.max(1.0), h.max(1.0))?;
        let mut e = geometry_entity(info, f, centre, size, None);
        e.name = entity.into();
        let mut values: Vec<_> = o.properties.iter().collect();
        values.sort_by(|a, b| a.0.cmp(b.0));
        e.values = values
            .into_iter()
            .filter_map(|(k, v)| {
                use crate::entities::PropValue as P;
                use ::tiled::PropertyValue as V;
                let v = match v {
                    V::BoolValue(b) => P::Bool(*b),
                    V::FloatValue(n) => P::Number(*n as f64),
                    V::IntValue(n) => P::Number(*n as f64),
                    V::StringValue(s) => P::Text(s.clone()),
                    _ => return None,
                };
                Some((k.clone(), v))
            })
            .collect();
        out.push(e);
        self.notes.borrow_mut().add(
            format!(
                "objects with no ledge name or class are read as {entity:?} by {why}; give them a ledge name or class, or choose in the level's settings: [entities] {:?} = \"coin\" (any entity name) for the layer, or decoration_layers = [{:?}] to skip them",
                info.name, info.name
            ),
            at,
        );
        Ok(())
    }
}

/// The solid shapes a map draws in its object layers (the pre-pass's
/// count), and whether its tile layers hold any tile.
#[derive(Default)]
struct DrawnSolids {
    /// Object ids of the solid shapes, with their layers' names (the first
    /// few, for the note).
    ids: Vec<u32>,
    /// How many there are.
    count: usize,
    /// The layers they are in (at most a few, for the note).
    layers: Vec<String>,
    /// A visible tile layer holds a tile.
    tiles: bool,
}

/// Most object ids [`DrawnSolids`] keeps (the rest are only counted).
const KEPT_IDS: usize = 4096;

impl DrawnSolids {
    /// Whether any solid shape is not a platform's path.
    fn found(&self, paths: &Paths) -> bool {
        self.count > self.ids.len()
            || self
                .ids
                .iter()
                .any(|id| !(paths.used.contains(id) && paths.by_id.contains_key(id)))
    }
}

impl Conv<'_> {
    /// Counts into `out` the objects of layer `info` that become solid
    /// geometry ([`Role::Solid`]), as the object pass will make them.
    fn solid_objects(
        &self,
        info: &LayerInfo<'_>,
        ol: &::tiled::ObjectLayer<'_>,
        out: &mut DrawnSolids,
    ) -> Result<(), LevelError> {
        if !info.visible {
            return Ok(());
        }
        for (k, o) in ol.objects().enumerate() {
            let name = common::object_name(self.options, &o);
            if !o.visible || is_entity_name(self.options.entity_name(name)) {
                continue;
            }
            let f = format!("{}.objects[{k}]", info.field);
            if self.object_role(info, &f, &o, name)? == Role::Solid {
                out.count += 1;
                if out.ids.len() < KEPT_IDS {
                    out.ids.push(o.id());
                }
                if out.layers.len() < 4 && !out.layers.iter().any(|l| l == info.name) {
                    out.layers.push(info.name.to_owned());
                }
            }
        }
        Ok(())
    }

    /// Says that the map's collision is its object shapes, so its tile
    /// layers (when they hold tiles) are decoration.
    fn objects_collide_note(&self, d: &DrawnSolids) {
        if !d.tiles {
            return;
        }
        self.notes.borrow_mut().add(
            format!(
                "the map has no collision data for its tiles (no tile collision shapes or properties, no collision layer property or class), but its collision is drawn as objects ({} solid shapes in layers {}), so its tile layers are decoration; list the tile layers that collide in collision_layers in the level's settings (see docs/LEVELS.md, \"What collides\")",
                d.count,
                d.layers.iter().map(|l| format!("{l:?}")).collect::<Vec<_>>().join(", ")
            ),
            || "map".into(),
        );
    }
}

/// Whether a tile layer holds at least one tile.
fn holds_a_tile(tl: &::tiled::TileLayer<'_>) -> bool {
    match tl {
        ::tiled::TileLayer::Finite(fl) => {
            let (w, h) = (fl.width() as i32, fl.height() as i32);
            !common::short_data(fl)
                && (0..h).any(|y| (0..w).any(|x| fl.get_tile_data(x, y).is_some()))
        }
        ::tiled::TileLayer::Infinite(il) => il.chunks().any(|(_, c)| {
            let (w, h) = (
                ::tiled::ChunkData::WIDTH as i32,
                ::tiled::ChunkData::HEIGHT as i32,
            );
            (0..h).any(|y| (0..w).any(|x| c.get_tile_data(x, y).is_some()))
        }),
    }
}

// ---- painted: Tiled tile layers painted edge to edge in a map without collision data
// (`crate::collision::infer`): their background tiles are made empty.

/// A tile layer the fallback made solid: its field and each cell's tile
/// (tileset index, id), row-major.
struct FallbackLayer {
    field: String,
    cells: Vec<Option<(usize, u32)>>,
}

impl Conv<'_> {
    /// Keeps the cells of fallback layer `field` (`w` x `h`, read with
    /// `cell`) for [`Conv::infer_painted`], unless a tile of it has a rule
    /// of its own (the settings' tile kinds decide then).
    fn keep_fallback_cells<'t>(
        &self,
        field: &str,
        (w, h): (u32, u32),
        cell: &dyn Fn(i32, i32) -> Option<LayerTile<'t>>,
        rules: &BTreeMap<(usize, u32), TileRule>,
    ) {
        let mut cells = Vec::with_capacity(w as usize * h as usize);
        for y in 0..h as i32 {
            for x in 0..w as i32 {
                let key = cell(x, y).map(|t| (t.tileset_index(), t.id()));
                if key.is_some_and(|k| !matches!(rules.get(&k), Some(TileRule::Silent))) {
                    return;
                }
                cells.push(key);
            }
        }
        self.fallback_cells.borrow_mut().push(FallbackLayer {
            field: field.into(),
            cells,
        });
    }

    /// Makes the background tiles of each painted fallback layer empty
    /// (evidence: `entities`), with a note saying which tiles are which.
    fn infer_painted(&self, grids: &mut [GridLayer], entities: &[PlacedEntity]) {
        let layers = std::mem::take(&mut *self.fallback_cells.borrow_mut());
        for l in layers {
            let Some(k) = grids.iter().position(|g| g.field == l.field) else {
                continue;
            };
            let others = solid_elsewhere(grids, k, entities);
            let g = &mut grids[k];
            let Some(p) = apply_painted(g, &l.cells, entities, self.options, others) else {
                continue;
            };
            let tilesets = self.map.tilesets();
            let name = |(ts, id): (usize, u32)| {
                (
                    tilesets.get(ts).map(|t| t.name.clone()).unwrap_or_default(),
                    id,
                )
            };
            let place = format!("layer {:?} ({})", g.name, g.field);
            let line = painted_warning(&p, name);
            self.notes.borrow_mut().add(line, || place);
        }
    }
}
