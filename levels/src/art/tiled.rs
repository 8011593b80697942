//! The art of a Tiled map.

use std::collections::{BTreeMap, HashMap};
use std::path::{Component, Path, PathBuf};

use ::tiled::{
    Image, LayerType, Map, ObjectAlignment, ObjectLayer, ObjectShape, TileLayer, Tileset,
};

use super::{
    check_image_bytes, check_tile_count, ArtContent, ArtLayer, ArtObject, ArtTileset, Budget,
    CollectionTile, Images, LevelArt, TileGrid,
};
use crate::art::ArtCell;
use crate::LevelError;

/// The art of a Tiled map: its visible tile layers, tile objects and image
/// layers, and the images they use (read relative to the file that names
/// them, each at most [`super::MAX_ART_IMAGE_BYTES`]).
///
/// An image that cannot be read or is not a PNG is left out, with what
/// uses it, and a line in [`LevelArt::warnings`]; a bound exceeded is an
/// error.
pub(crate) fn from_tiled(
    file: &str,
    map: &Map,
    options: &crate::LoadOptions,
) -> Result<LevelArt, LevelError> {
    let map_dir = map.source.parent().map(normalize).unwrap_or_default();
    let mut b = Build {
        file,
        map,
        options,
        map_dir,
        images: Images::default(),
        tilesets: Vec::new(),
        collection: Vec::new(),
        ids: HashMap::new(),
        budget: Budget::default(),
        layers: Vec::new(),
        missing: HashMap::new(),
        warnings: Vec::new(),
    };
    let top = Inherited {
        name: String::new(),
        offset: (0.0, 0.0),
        parallax: (1.0, 1.0),
        opacity: 1.0,
    };
    b.visit(map.layers(), "layers", &top)?;
    let Build {
        images,
        mut tilesets,
        collection,
        layers,
        warnings,
        ..
    } = b;
    for (ts, tiles) in tilesets.iter_mut().zip(collection) {
        ts.tiles = tiles.into_values().collect();
    }
    Ok(LevelArt {
        background: map
            .background_color
            .map(|c| [c.red, c.green, c.blue, c.alpha]),
        size: (
            (map.width as u64 * map.tile_width as u64) as f32,
            (map.height as u64 * map.tile_height as u64) as f32,
        ),
        parallax_origin: (map.parallax_origin_x, map.parallax_origin_y),
        images: images.into_vec(),
        tilesets,
        layers,
        warnings,
    })
}

/// What a layer inherits from its groups.
struct Inherited {
    name: String,
    offset: (f32, f32),
    parallax: (f32, f32),
    opacity: f32,
}

struct Build<'m> {
    file: &'m str,
    map: &'m Map,
    /// The load's options (entity names and aliases).
    options: &'m crate::LoadOptions,
    map_dir: PathBuf,
    images: Images,
    tilesets: Vec<ArtTileset>,
    /// A collection tileset's tiles used so far, by id.
    collection: Vec<BTreeMap<u32, CollectionTile>>,
    /// Art tileset index of each tiled tileset used (by address: template
    /// tilesets are not in the map's list).
    ids: HashMap<*const Tileset, u32>,
    budget: Budget,
    layers: Vec<ArtLayer>,
    /// Image paths that could not be used, and why.
    missing: HashMap<String, String>,
    warnings: Vec<String>,
}

fn finite(v: f32, default: f32) -> f32 {
    if v.is_finite() {
        v
    } else {
        default
    }
}

impl<'m> Build<'m> {
    fn bad(&self, field: impl Into<String>, message: String) -> LevelError {
        LevelError::BadValue {
            file: self.file.into(),
            field: field.into(),
            message,
        }
    }

    fn visit(
        &mut self,
        layers: impl Iterator<Item = ::tiled::Layer<'m>>,
        parent: &str,
        up: &Inherited,
    ) -> Result<(), LevelError> {
        for (i, l) in layers.enumerate() {
            if !l.visible {
                continue;
            }
            let field = format!("{parent}[{i}]");
            let here = Inherited {
                name: if up.name.is_empty() {
                    l.name.clone()
                } else {
                    format!("{}/{}", up.name, l.name)
                },
                offset: (
                    up.offset.0 + finite(l.offset_x, 0.0),
                    up.offset.1 + finite(l.offset_y, 0.0),
                ),
                parallax: (
                    up.parallax.0 * finite(l.parallax_x, 1.0),
                    up.parallax.1 * finite(l.parallax_y, 1.0),
                ),
                opacity: up.opacity * finite(l.opacity, 1.0).clamp(0.0, 1.0),
            };
            let content = match l.layer_type() {
                LayerType::Group(g) => {
                    self.visit(g.layers(), &format!("{field}.layers"), &here)?;
                    continue;
                }
                LayerType::Tiles(tl) => self.tiles(&field, &tl)?.map(ArtContent::Tiles),
                LayerType::Objects(ol) => {
                    Some(ArtContent::Objects(self.objects(&field, &l.name, &ol)?))
                }
                LayerType::Image(il) => match &il.image {
                    Some(img) => {
                        self.image(img, &format!("{field}.image"))?
                            .map(|image| ArtContent::Image {
                                image,
                                repeat_x: il.repeat_x,
                                repeat_y: il.repeat_y,
                            })
                    }
                    None => None,
                },
            };
            let Some(content) = content else { continue };
            if matches!(&content, ArtContent::Objects(o) if o.is_empty()) {
                continue;
            }
            self.layers.push(ArtLayer {
                name: here.name,
                offset: here.offset,
                parallax: here.parallax,
                opacity: here.opacity,
                content,
            });
        }
        Ok(())
    }

    /// A tile layer's cells (`None`: an infinite layer, not drawn).
    fn tiles(&mut self, field: &str, tl: &TileLayer<'m>) -> Result<Option<TileGrid>, LevelError> {
        let TileLayer::Finite(fl) = tl else {
            return Ok(None);
        };
        let (w, h) = (fl.width(), fl.height());
        self.budget.cells(self.file, field, w as u64 * h as u64)?;
        if crate::tmx::common::short_data(fl) {
            return Err(self.bad(
                format!("{field}.data"),
                format!("fewer entries than the layer's {w} x {h} cells"),
            ));
        }
        let mut cells = Vec::with_capacity(w as usize * h as usize);
        for y in 0..h as i32 {
            for x in 0..w as i32 {
                let Some(d) = fl.get_tile_data(x, y) else {
                    cells.push(None);
                    continue;
                };
                let Some(ts) = self.map.tilesets().get(d.tileset_index()) else {
                    cells.push(None);
                    continue;
                };
                let cf = format!("{field}.data[{}]", y as i64 * w as i64 + x as i64);
                let Some(tileset) = self.tile(ts, d.id(), &cf)? else {
                    cells.push(None);
                    continue;
                };
                cells.push(Some(ArtCell {
                    tileset,
                    tile: d.id(),
                    flip_h: d.flip_h,
                    flip_v: d.flip_v,
                    flip_d: d.flip_d,
                }));
            }
        }
        Ok(Some(TileGrid {
            width: w,
            height: h,
            cell_width: self.map.tile_width,
            cell_height: self.map.tile_height,
            cells,
        }))
    }

    /// An object layer's visible tile objects (other shapes are not drawn).
    fn objects(
        &mut self,
        field: &str,
        layer: &str,
        ol: &ObjectLayer<'m>,
    ) -> Result<Vec<ArtObject>, LevelError> {
        let mut out = Vec::new();
        for (k, o) in ol.objects().enumerate() {
            if !o.visible {
                continue;
            }
            let Some(t) = o.get_tile() else { continue };
            // The game draws its entities (a coin vanishes when collected).
            if crate::tmx::common::is_drawn_entity(self.options, layer, &o) {
                continue;
            }
            let of = format!("{field}.objects[{k}]");
            self.budget.object(self.file, &of)?;
            let ts = t.get_tileset();
            let Some(tileset) = self.tile(ts, t.id(), &of)? else {
                continue;
            };
            let (mut w, mut h) = match o.shape {
                ObjectShape::Rect { width, height } => (width, height),
                _ => (0.0, 0.0),
            };
            let src = self.source(tileset, t.id());
            if !(w.is_finite() && w > 0.0) {
                w = src.0;
            }
            if !(h.is_finite() && h > 0.0) {
                h = src.1;
            }
            let rotation = finite(o.rotation, 0.0);
            // The anchor (x, y) is the point of the box the tileset's object
            // alignment names (bottom-left when unspecified); find the
            // bottom-left corner, rotated with the box about the anchor.
            let (ax, ay) = match ts.object_alignment {
                ObjectAlignment::TopLeft => (0.0, 0.0),
                ObjectAlignment::Top => (0.5, 0.0),
                ObjectAlignment::TopRight => (1.0, 0.0),
                ObjectAlignment::Left => (0.0, 0.5),
                ObjectAlignment::Center => (0.5, 0.5),
                ObjectAlignment::Right => (1.0, 0.5),
                ObjectAlignment::Bottom => (0.5, 1.0),
                ObjectAlignment::BottomRight => (1.0, 1.0),
                ObjectAlignment::Unspecified | ObjectAlignment::BottomLeft => (0.0, 1.0),
            };
            let (dx, dy) = (-ax * w, (1.0 - ay) * h);
            let (sin, cos) = rotation.to_radians().sin_cos();
            let (x, y) = (
                finite(o.x, 0.0) + dx * cos - dy * sin,
                finite(o.y, 0.0) + dx * sin + dy * cos,
            );
            out.push(ArtObject {
                tileset,
                tile: t.id(),
                x,
                y,
                width: w,
                height: h,
                rotation,
                flip_h: t.flip_h,
                flip_v: t.flip_v,
                opacity: finite(o.opacity, 1.0).clamp(0.0, 1.0),
            });
        }
        Ok(out)
    }

    /// The size of a tile already registered.
    fn source(&self, tileset: u32, id: u32) -> (f32, f32) {
        let ts = &self.tilesets[tileset as usize];
        match self.collection[tileset as usize].get(&id) {
            Some(t) => (t.rect[2] as f32, t.rect[3] as f32),
            None => (ts.tile_width as f32, ts.tile_height as f32),
        }
    }

    /// Registers tile `id` of `ts` (and its tileset and image); returns the
    /// art tileset index (`None`: its image could not be used). Refuses a
    /// tile the tileset does not have.
    fn tile(&mut self, ts: &'m Tileset, id: u32, field: &str) -> Result<Option<u32>, LevelError> {
        let Some(t) = self.tileset(ts, field)? else {
            return Ok(None);
        };
        let art = &self.tilesets[t as usize];
        match art.image {
            Some(image) => {
                if art.source(id, self.images.as_slice()).is_none() {
                    return Err(self.bad(
                        field,
                        format!(
                            "tile id {id} is outside tileset {:?} ({} tiles in {} columns of its {} x {} px image)",
                            ts.name,
                            art.tile_count,
                            art.columns,
                            self.images.get(image).width,
                            self.images.get(image).height
                        ),
                    ));
                }
            }
            None => {
                if self.collection[t as usize].contains_key(&id) {
                    return Ok(Some(t));
                }
                let Some(img) = ts.get_tile(id).and_then(|tile| tile.image.clone()) else {
                    return Err(self.bad(
                        field,
                        format!("tile id {id} has no image in tileset {:?}", ts.name),
                    ));
                };
                let rect = ts.get_tile(id).and_then(|tile| tile.image_rect);
                let Some(image) =
                    self.image(&img, &format!("{field} (tileset {:?} tile {id})", ts.name))?
                else {
                    return Ok(None);
                };
                let (iw, ih) = {
                    let i = self.images.get(image);
                    (i.width, i.height)
                };
                let rect = match rect {
                    Some(r) => {
                        let ok = r.x >= 0
                            && r.y >= 0
                            && r.width > 0
                            && r.height > 0
                            && r.x as u64 + r.width as u64 <= iw as u64
                            && r.y as u64 + r.height as u64 <= ih as u64;
                        if !ok {
                            return Err(self.bad(
                                field,
                                format!(
                                    "tile {id} of tileset {:?}: rectangle {} x {} px at ({}, {}) is not inside its {iw} x {ih} px image",
                                    ts.name, r.width, r.height, r.x, r.y
                                ),
                            ));
                        }
                        [r.x as u32, r.y as u32, r.width as u32, r.height as u32]
                    }
                    None => [0, 0, iw, ih],
                };
                self.collection[t as usize].insert(id, CollectionTile { id, image, rect });
            }
        }
        Ok(Some(t))
    }

    /// Registers a tileset (`None`: its image could not be used).
    fn tileset(&mut self, ts: &'m Tileset, field: &str) -> Result<Option<u32>, LevelError> {
        if let Some(&i) = self.ids.get(&(ts as *const Tileset)) {
            return Ok((i != u32::MAX).then_some(i));
        }
        let tf = format!("{field} (tileset {:?})", ts.name);
        check_tile_count(self.file, &tf, ts.tilecount as u64)?;
        let (image, columns) = match &ts.image {
            Some(img) => {
                let Some(i) = self.image(img, &tf)? else {
                    self.ids.insert(ts as *const Tileset, u32::MAX);
                    return Ok(None);
                };
                let columns = if ts.columns > 0 {
                    ts.columns
                } else {
                    let iw = self.images.get(i).width as u64;
                    let step = ts.tile_width as u64 + ts.spacing as u64;
                    ((iw + ts.spacing as u64).saturating_sub(2 * ts.margin as u64))
                        .checked_div(step)
                        .unwrap_or(0) as u32
                };
                (Some(i), columns)
            }
            None => (None, ts.columns),
        };
        self.tilesets.push(ArtTileset {
            name: ts.name.clone(),
            tile_width: ts.tile_width,
            tile_height: ts.tile_height,
            columns,
            margin: ts.margin,
            spacing: ts.spacing,
            offset: (ts.offset_x, ts.offset_y),
            tile_count: ts.tilecount,
            image,
            tiles: Vec::new(),
        });
        self.collection.push(BTreeMap::new());
        let i = self.tilesets.len() as u32 - 1;
        self.ids.insert(ts as *const Tileset, i);
        Ok(Some(i))
    }

    /// Reads an image file (once per path). `None`: it cannot be read or
    /// is not a PNG (a warning says so, once).
    fn image(&mut self, img: &Image, field: &str) -> Result<Option<u32>, LevelError> {
        let path = normalize(&img.source);
        let key = path.display().to_string();
        if let Some(i) = self.images.find(&key) {
            return Ok(Some(i));
        }
        if self.missing.contains_key(&key) {
            return Ok(None);
        }
        let name = relative(&self.map_dir, &path);
        if let Ok(meta) = std::fs::metadata(&path) {
            check_image_bytes(self.file, &format!("{field} (image {name:?})"), meta.len())?;
        }
        let added = crate::read::read_bytes(&path).and_then(|bytes| {
            let trans = img.transparent_colour.map(|c| [c.red, c.green, c.blue]);
            self.images
                .add(self.file, field, key.clone(), name, trans, bytes)
        });
        match added {
            Ok(i) => Ok(Some(i)),
            Err(e @ (LevelError::Io { .. } | LevelError::BadValue { .. })) => {
                self.warnings.push(format!(
                    "{}: {field}: {e} (what uses this image is not drawn)",
                    self.file
                ));
                self.missing.insert(key, e.to_string());
                Ok(None)
            }
            Err(e) => Err(e),
        }
    }
}

/// `p` with `.` removed and `dir/..` folded (lexically).
fn normalize(p: &Path) -> PathBuf {
    let mut out: Vec<Component<'_>> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out.iter().collect()
}

/// `path` relative to `dir` (both normalized), `/`-separated.
fn relative(dir: &Path, path: &Path) -> String {
    let d: Vec<_> = dir.components().collect();
    let p: Vec<_> = path.components().collect();
    let common = d.iter().zip(&p).take_while(|(a, b)| a == b).count();
    let mut parts: Vec<String> = Vec::new();
    for _ in common..d.len() {
        parts.push("..".into());
    }
    for c in &p[common..] {
        parts.push(c.as_os_str().to_string_lossy().into_owned());
    }
    parts.join("/")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_relative_to_the_map() {
        let dir = normalize(Path::new("a/b/./maps"));
        assert_eq!(
            relative(&dir, &normalize(Path::new("a/b/maps/../tiles/t.png"))),
            "../tiles/t.png"
        );
        assert_eq!(
            relative(&dir, &normalize(Path::new("a/b/maps/t.png"))),
            "t.png"
        );
        assert_eq!(relative(Path::new(""), Path::new("t.png")), "t.png");
    }
}
