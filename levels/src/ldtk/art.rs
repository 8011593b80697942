//! The art of an LDtk level: its tile layers, auto-layers and IntGrid
//! layers' auto-tiles drawn with their tilesets, its background colour and
//! (when drawn at its own size) its background image, as [`LevelArt`].
//!
//! LDtk may stack several tiles in one cell (rules placing tiles over
//! others) and offset a rule's tiles off the grid, and gives each tile an
//! opacity; [`LevelArt`]'s tile layers hold one tile per cell. So each LDtk
//! layer becomes as many art layers as it needs: one per (offset within the
//! cell, opacity) and stacking depth, lowest first, drawn in LDtk's order.
//! Images are read relative to the project's folder, within the art bounds
//! (`MAX_ART_*`); an image that cannot be read or is not a PNG is left out
//! with what uses it and a line in [`LevelArt::warnings`].

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use super::model::{self, LayerInstance, Level, Project, TilesetDef};
use crate::art::{
    check_image_bytes, check_tile_count, ArtCell, ArtContent, ArtLayer, ArtTileset, Budget, Images,
    LevelArt, TileGrid,
};
use crate::error::LevelError;

/// Builds one level's art.
struct Build<'a> {
    /// The level (in errors and warnings).
    file: &'a str,
    /// The project's folder (`None`: text without a folder: no images).
    dir: Option<&'a Path>,
    project: &'a Project,
    images: Images,
    tilesets: Vec<ArtTileset>,
    /// Art tileset of each LDtk tileset uid (`None`: not drawable).
    by_uid: HashMap<i64, Option<u32>>,
    budget: Budget,
    layers: Vec<ArtLayer>,
    warnings: Vec<String>,
}

/// The art of `level` (its `layers`, top-most first), images read from
/// `dir`.
pub(crate) fn level_art(
    file: &str,
    dir: Option<&Path>,
    project: &Project,
    level: &Level,
    layers: &[LayerInstance],
) -> Result<LevelArt, LevelError> {
    let mut b = Build {
        file,
        dir,
        project,
        images: Images::default(),
        tilesets: Vec::new(),
        by_uid: HashMap::new(),
        budget: Budget::default(),
        layers: Vec::new(),
        warnings: Vec::new(),
    };
    b.background(level)?;
    for (i, l) in layers.iter().enumerate().rev() {
        if l.visible && !l.tiles().0.is_empty() {
            b.layer(&format!("layerInstances[{i}]"), l)?;
        }
    }
    let bg = level
        .bg_color
        .as_deref()
        .or(project.bg_color.as_deref())
        .and_then(parse_colour);
    Ok(LevelArt {
        background: bg,
        size: (level.px_wid.max(0) as f32, level.px_hei.max(0) as f32),
        parallax_origin: (0.0, 0.0),
        images: b.images.into_vec(),
        tilesets: b.tilesets,
        layers: b.layers,
        warnings: b.warnings,
    })
}

/// One art layer being filled: its key (offset in the cell, opacity bits,
/// stacking depth) and cells.
struct Sub {
    rem: (i64, i64),
    alpha: f32,
    cells: Vec<Option<ArtCell>>,
}

impl Build<'_> {
    /// The level's background image, when LDtk draws it at its own size
    /// (else a warning: scaled or cropped backgrounds are not drawn).
    fn background(&mut self, level: &Level) -> Result<(), LevelError> {
        let Some(rel) = level.bg_rel_path.as_deref().filter(|s| !s.is_empty()) else {
            return Ok(());
        };
        let Some(image) = self.image("bgRelPath", rel)? else {
            return Ok(());
        };
        let img = self.images.get(image);
        let (w, h) = (img.width as f64, img.height as f64);
        let pos = level.bg_pos.as_ref();
        let plain = pos.is_none_or(|p| p.scale == [1.0, 1.0] && p.crop_rect == [0.0, 0.0, w, h]);
        if !plain {
            self.warnings.push(format!(
                "{}: bgPos: the background image {rel:?} is scaled or cropped (LDtk's \"cover\", \"contain\" or a scale): it is not drawn (set its position to \"unscaled\" in LDtk's level settings)",
                self.file
            ));
            return Ok(());
        }
        let at = pos.map_or([0.0, 0.0], |p| p.top_left_px);
        self.layers.push(ArtLayer {
            name: "background".into(),
            offset: (at[0] as f32, at[1] as f32),
            parallax: (1.0, 1.0),
            opacity: 1.0,
            content: ArtContent::Image {
                image,
                repeat_x: false,
                repeat_y: false,
            },
        });
        Ok(())
    }

    /// One layer's tiles as art layers (none when its tileset cannot be
    /// drawn, with a warning).
    fn layer(&mut self, field: &str, l: &LayerInstance) -> Result<(), LevelError> {
        let uid = l.override_tileset_uid.or(l.tileset_uid);
        let Some(t) = self.tileset(field, uid)? else {
            return Ok(());
        };
        let grid = model::grid_size(self.file, field, l.grid_size)? as i64;
        // Within the world bound (so the art offsets below cannot overflow).
        model::offset_units(self.file, field, l)?;
        let (w, h) = model::cells(self.file, field, l)?;
        let (placed, key) = l.tiles();
        let ts = self.tilesets[t as usize].clone();
        let step = (ts.tile_width + ts.spacing) as i64;
        let mut subs: Vec<Sub> = Vec::new();
        // cell -> how many tiles are stacked there so far (a later tile is
        // drawn over an earlier one, whatever their offsets and opacities)
        let mut depth: HashMap<usize, usize> = HashMap::new();
        // (rem, alpha bits, depth) -> index into subs
        let mut index: BTreeMap<(usize, (i64, i64), u32), usize> = BTreeMap::new();
        let (mut outside, mut off_atlas) = (0usize, 0usize);
        for tile in placed {
            let (cx, cy) = (tile.px[0].div_euclid(grid), tile.px[1].div_euclid(grid));
            if !((0..w as i64).contains(&cx) && (0..h as i64).contains(&cy)) {
                outside += 1;
                continue;
            }
            let Some(id) = atlas_id(&ts, step, tile.src) else {
                off_atlas += 1;
                continue;
            };
            let rem = (tile.px[0] - cx * grid, tile.px[1] - cy * grid);
            let alpha = if tile.a.is_finite() {
                tile.a.clamp(0.0, 1.0) as f32
            } else {
                1.0
            };
            let cell = (cy * w as i64 + cx) as usize;
            let d = depth.entry(cell).or_insert(0);
            let k = (*d, rem, alpha.to_bits());
            *d += 1;
            let s = match index.get(&k) {
                Some(&s) => s,
                None => {
                    self.budget
                        .cells(self.file, &format!("{field}.{key}"), w as u64 * h as u64)?;
                    subs.push(Sub {
                        rem,
                        alpha,
                        cells: vec![None; w as usize * h as usize],
                    });
                    index.insert(k, subs.len() - 1);
                    subs.len() - 1
                }
            };
            subs[s].cells[cell] = Some(ArtCell {
                tileset: t,
                tile: id,
                flip_h: tile.f & 1 != 0,
                flip_v: tile.f & 2 != 0,
                flip_d: false,
            });
        }
        self.skipped(field, key, l, outside, off_atlas);
        self.push_subs(l, grid, ts.tile_height, index, subs);
        Ok(())
    }

    /// Pushes a layer's art layers (`subs`, by `index`: lowest stacking
    /// depth first, then by offset and opacity), shifted so that each tile's
    /// top-left corner is where LDtk puts it.
    fn push_subs(
        &mut self,
        l: &LayerInstance,
        grid: i64,
        tile_height: u32,
        index: BTreeMap<(usize, (i64, i64), u32), usize>,
        mut subs: Vec<Sub>,
    ) {
        let (w, h) = (l.c_wid as u32, l.c_hei as u32);
        let lift = tile_height as f32 - grid as f32;
        for (_, s) in index {
            let sub = std::mem::take(&mut subs[s].cells);
            let Sub { rem, alpha, .. } = subs[s];
            self.layers.push(ArtLayer {
                name: l.identifier.clone(),
                offset: (
                    (l.offset_x + rem.0) as f32,
                    (l.offset_y + rem.1) as f32 + lift,
                ),
                parallax: (1.0, 1.0),
                opacity: (if l.opacity.is_finite() {
                    l.opacity.clamp(0.0, 1.0) as f32
                } else {
                    1.0
                }) * alpha,
                content: ArtContent::Tiles(TileGrid {
                    width: w,
                    height: h,
                    cell_width: grid as u32,
                    cell_height: grid as u32,
                    cells: sub,
                }),
            });
        }
    }

    /// Warns about tiles left out of a layer.
    fn skipped(&mut self, field: &str, key: &str, l: &LayerInstance, outside: usize, off: usize) {
        if outside > 0 {
            self.warnings.push(format!(
                "{}: {field}.{key}: {outside} tiles of layer {:?} lie outside its grid: not drawn",
                self.file, l.identifier
            ));
        }
        if off > 0 {
            self.warnings.push(format!(
                "{}: {field}.{key}: {off} tiles of layer {:?} are not on their tileset's grid or image (src): not drawn (has the image changed size?)",
                self.file, l.identifier
            ));
        }
    }

    /// The art tileset of LDtk tileset `uid`, made on first use; `None`
    /// (with a warning, once) when it cannot be drawn.
    fn tileset(&mut self, field: &str, uid: Option<i64>) -> Result<Option<u32>, LevelError> {
        let Some(uid) = uid else {
            return Ok(None);
        };
        if let Some(&t) = self.by_uid.get(&uid) {
            return Ok(t);
        }
        let project = self.project;
        let found = project
            .defs
            .tilesets
            .iter()
            .enumerate()
            .find(|(_, d)| d.uid == uid);
        let t = match found {
            None => {
                self.warnings.push(format!(
                    "{}: {field}: tileset uid {uid} is not in the project's defs.tilesets: the layer is not drawn",
                    self.file
                ));
                None
            }
            Some((k, def)) => self.make_tileset(k, def)?,
        };
        self.by_uid.insert(uid, t);
        Ok(t)
    }

    /// An art tileset of `def` (`defs.tilesets[k]`), from its image.
    fn make_tileset(&mut self, k: usize, def: &TilesetDef) -> Result<Option<u32>, LevelError> {
        let field = format!("defs.tilesets[{k}]");
        let Some(rel) = def.rel_path.as_deref().filter(|s| !s.is_empty()) else {
            self.warnings.push(format!(
                "{}: {field}: tileset {:?} has no image file (LDtk's embedded icons): what uses it is not drawn",
                self.file, def.identifier
            ));
            return Ok(None);
        };
        let size = model::grid_size(self.file, &field, def.tile_grid_size)?;
        let (spacing, padding) = (def.spacing, def.padding);
        if !(0..=4096).contains(&spacing) || !(0..=4096).contains(&padding) {
            return Err(model::bad(
                self.file,
                &field,
                format!("spacing {spacing} px or padding {padding} px is outside [0, 4096] px"),
            ));
        }
        let Some(image) = self.image(&format!("{field}.relPath"), rel)? else {
            return Ok(None);
        };
        let img = self.images.get(image);
        let fit = |side: u32| {
            ((side as i64 - 2 * padding + spacing).max(0) / (size as i64 + spacing)) as u32
        };
        let (columns, rows) = (fit(img.width), fit(img.height));
        check_tile_count(self.file, &field, columns as u64 * rows as u64)?;
        self.tilesets.push(ArtTileset {
            name: def.identifier.clone(),
            tile_width: size,
            tile_height: size,
            columns,
            margin: padding as u32,
            spacing: spacing as u32,
            offset: (0, 0),
            tile_count: columns * rows,
            image: Some(image),
            tiles: Vec::new(),
        });
        Ok(Some(self.tilesets.len() as u32 - 1))
    }

    /// Image `rel` (relative to the project's folder), read within the
    /// bounds; `None` with a warning when it cannot be read or is not a PNG.
    fn image(&mut self, field: &str, rel: &str) -> Result<Option<u32>, LevelError> {
        let name = rel.replace('\\', "/");
        let Some(dir) = self.dir else {
            self.warnings.push(format!(
                "{}: {field}: image {name:?} is not drawn: the project was given as text, with no folder to read it from",
                self.file
            ));
            return Ok(None);
        };
        let path: PathBuf = dir.join(&name);
        let key = path.display().to_string();
        if let Some(i) = self.images.find(&key) {
            return Ok(Some(i));
        }
        if let Ok(meta) = std::fs::metadata(&path) {
            check_image_bytes(self.file, &format!("{field} (image {name:?})"), meta.len())?;
        }
        let added = crate::read::read_bytes(&path)
            .and_then(|bytes| self.images.add(self.file, field, key, name, None, bytes));
        match added {
            Ok(i) => Ok(Some(i)),
            Err(e @ (LevelError::Io { .. } | LevelError::BadValue { .. })) => {
                self.warnings.push(format!(
                    "{}: {field}: {e} (what uses this image is not drawn)",
                    self.file
                ));
                Ok(None)
            }
            Err(e) => Err(e),
        }
    }
}

/// The id of the tile whose top-left corner is at `src` in the atlas of
/// `ts` (tiles `step` pixels apart): `None` when `src` is not a tile's
/// corner inside the atlas.
fn atlas_id(ts: &ArtTileset, step: i64, src: [i64; 2]) -> Option<u32> {
    let margin = ts.margin as i64;
    let (sx, sy) = (src[0].checked_sub(margin)?, src[1].checked_sub(margin)?);
    if sx < 0 || sy < 0 || sx % step != 0 || sy % step != 0 || ts.columns == 0 {
        return None;
    }
    let (col, row) = (sx / step, sy / step);
    let rows = (ts.tile_count / ts.columns) as i64;
    (col < ts.columns as i64 && row < rows).then(|| (row * ts.columns as i64 + col) as u32)
}

/// `#rrggbb` or `#rrggbbaa`.
fn parse_colour(s: &str) -> Option<[u8; 4]> {
    let hex = s.strip_prefix('#')?;
    if !(hex.len() == 6 || hex.len() == 8) || !hex.is_ascii() {
        return None;
    }
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).ok();
    Some([
        byte(0)?,
        byte(2)?,
        byte(4)?,
        if hex.len() == 8 { byte(6)? } else { 255 },
    ])
}
