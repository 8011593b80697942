//! Drawing a level's own art ([`LevelArt`]: the editor's tile layers, tile
//! objects and image layers, with the level's tileset images) behind the
//! entities and players.
//!
//! Textures are made once, when the window exists ([`ArtView::new`]),
//! nearest-neighbour filtered. Each frame draws the layers back to front,
//! only the cells the view shows. Collision cells that the art draws over
//! are [`ArtView::covered`]: ledge's flat colours are drawn only where the
//! level has no art.

use ledge_levels::art::{ArtContent, LevelArt, TileGrid, TileSource};
use ledge_shared::tilemap::Tilemap;
use macroquad::prelude::*;

use crate::draw::camera::View;

/// A level's art with its textures.
pub struct ArtView {
    art: LevelArt,
    /// One per [`LevelArt::images`] (`None`: it did not decode).
    textures: Vec<Option<Texture2D>>,
    /// Per collision cell (row-major): the art draws over it.
    covered: Vec<bool>,
}

impl ArtView {
    /// Decodes the images into textures (call with a window open) and
    /// finds the collision cells of `map` the art draws over.
    pub fn new(art: LevelArt, map: &Tilemap) -> ArtView {
        let textures = art
            .images
            .iter()
            .map(|img| {
                match macroquad::texture::Image::from_file_with_format(
                    &img.bytes,
                    Some(ImageFormat::Png),
                ) {
                    Ok(mut image) => {
                        if let Some([r, g, b]) = img.transparent {
                            for px in image.get_image_data_mut() {
                                if px[..3] == [r, g, b] {
                                    px[3] = 0;
                                }
                            }
                        }
                        let t = Texture2D::from_image(&image);
                        t.set_filter(FilterMode::Nearest);
                        Some(t)
                    }
                    Err(e) => {
                        tracing::warn!("level art: image {:?} does not decode: {e}", img.name);
                        None
                    }
                }
            })
            .collect();
        let covered = ledge_levels::art::covered::covered_cells(&art, map);
        ArtView {
            art,
            textures,
            covered,
        }
    }

    /// The level's background colour, if it has one.
    pub fn background(&self) -> Option<Color> {
        self.art
            .background
            .map(|[r, g, b, a]| Color::from_rgba(r, g, b, a))
    }

    /// Whether the level has no art to draw (ledge then draws its static
    /// blocks and polygons itself).
    pub fn is_empty(&self) -> bool {
        self.art.layers.is_empty()
    }

    /// The art's extent (world pixels from the origin), if any.
    pub fn extent(&self) -> Option<Rect> {
        let (w, h) = self.art.size;
        (w > 0.0 && h > 0.0).then(|| Rect::new(0.0, 0.0, w, h))
    }

    /// Per collision cell (row-major): drawn by the art.
    pub fn covered(&self) -> &[bool] {
        &self.covered
    }

    /// Draws every layer, back to front.
    pub fn draw(&self, view: &View) {
        let centre = view.to_world(view.screen * 0.5);
        let origin = vec2(self.art.parallax_origin.0, self.art.parallax_origin.1);
        for layer in &self.art.layers {
            // Tiled's parallax: a factor below 1 follows the camera part of
            // the way (0: fixed on screen).
            let p = vec2(layer.parallax.0, layer.parallax.1);
            let shift = (Vec2::ONE - p) * (centre - origin);
            let off = vec2(layer.offset.0, layer.offset.1) + shift;
            let tint = Color::new(1.0, 1.0, 1.0, layer.opacity);
            match &layer.content {
                ArtContent::Tiles(grid) => self.draw_grid(grid, off, view, tint),
                ArtContent::Objects(objects) => {
                    for o in objects {
                        let Some(src) = self.art.source(o.tileset, o.tile) else {
                            continue;
                        };
                        let Some(tex) = self.texture(src) else {
                            continue;
                        };
                        let anchor = view.to_screen(off + vec2(o.x, o.y));
                        let color = Color::new(1.0, 1.0, 1.0, layer.opacity * o.opacity);
                        draw_texture_ex(
                            tex,
                            anchor.x,
                            anchor.y - o.height * view.zoom,
                            color,
                            DrawTextureParams {
                                dest_size: Some(vec2(o.width, o.height) * view.zoom),
                                source: Some(rect_of(src)),
                                rotation: o.rotation.to_radians(),
                                flip_x: o.flip_h,
                                flip_y: o.flip_v,
                                pivot: Some(anchor),
                            },
                        );
                    }
                }
                ArtContent::Image {
                    image,
                    repeat_x,
                    repeat_y,
                } => self.draw_image(*image, (*repeat_x, *repeat_y), off, view, tint),
            }
        }
    }

    fn texture(&self, src: TileSource) -> Option<&Texture2D> {
        self.textures.get(src.image as usize)?.as_ref()
    }

    fn draw_grid(&self, grid: &TileGrid, off: Vec2, view: &View, tint: Color) {
        let (cw, ch) = (grid.cell_width as f32, grid.cell_height as f32);
        if cw <= 0.0 || ch <= 0.0 {
            return;
        }
        let seen = view.visible();
        // Tiles may be larger than cells (they reach up and right) or
        // shifted by their tileset's offset: look a few cells further.
        let extra = self
            .art
            .tilesets
            .iter()
            .map(|t| {
                let reach = t.tile_width.max(t.tile_height) as f32
                    + t.offset.0.unsigned_abs().max(t.offset.1.unsigned_abs()) as f32;
                (reach / cw.min(ch)).ceil() as i64
            })
            .max()
            .unwrap_or(1)
            .clamp(1, 64);
        let col0 = (((seen.x - off.x) / cw).floor() as i64 - extra).max(0);
        let row0 = (((seen.y - off.y) / ch).floor() as i64 - 1).max(0);
        let col1 = (((seen.right() - off.x) / cw).ceil() as i64 + 1).min(grid.width as i64);
        let row1 = (((seen.bottom() - off.y) / ch).ceil() as i64 + extra).min(grid.height as i64);
        for r in row0..row1 {
            for c in col0..col1 {
                let Some(cell) = grid.get(c as u32, r as u32) else {
                    continue;
                };
                let Some(src) = self.art.source(cell.tileset, cell.tile) else {
                    continue;
                };
                let Some(tex) = self.texture(src) else {
                    continue;
                };
                let to = self.art.tilesets[cell.tileset as usize].offset;
                // Bottom-left of the tile on the bottom-left of the cell.
                let x = off.x + c as f32 * cw + to.0 as f32;
                let y = off.y + (r + 1) as f32 * ch - src.h as f32 + to.1 as f32;
                let p = view.to_screen(vec2(x, y));
                let size = vec2(src.w as f32, src.h as f32) * view.zoom;
                // Tiled flips the diagonal first, then horizontally and
                // vertically: as a quarter turn clockwise of the tile
                // mirrored vertically.
                let (rotation, flip_x, flip_y) = if cell.flip_d {
                    (std::f32::consts::FRAC_PI_2, cell.flip_v, !cell.flip_h)
                } else {
                    (0.0, cell.flip_h, cell.flip_v)
                };
                draw_texture_ex(
                    tex,
                    p.x,
                    p.y,
                    tint,
                    DrawTextureParams {
                        dest_size: Some(size),
                        source: Some(rect_of(src)),
                        rotation,
                        flip_x,
                        flip_y,
                        pivot: None,
                    },
                );
            }
        }
    }

    fn draw_image(
        &self,
        image: u32,
        (repeat_x, repeat_y): (bool, bool),
        off: Vec2,
        view: &View,
        tint: Color,
    ) {
        let Some(Some(tex)) = self.textures.get(image as usize) else {
            return;
        };
        let size = vec2(tex.width(), tex.height());
        if size.x < 1.0 || size.y < 1.0 {
            return;
        }
        let seen = view.visible();
        let span = |repeat: bool, start: f32, lo: f32, hi: f32, step: f32| -> (f32, usize) {
            if repeat {
                let first = start + ((lo - start) / step).floor() * step;
                (first, (((hi - first) / step).ceil() as usize).min(4096))
            } else {
                (start, 1)
            }
        };
        let (x0, nx) = span(repeat_x, off.x, seen.x, seen.right(), size.x);
        let (y0, ny) = span(repeat_y, off.y, seen.y, seen.bottom(), size.y);
        for j in 0..ny {
            for i in 0..nx {
                let p = view.to_screen(vec2(x0 + i as f32 * size.x, y0 + j as f32 * size.y));
                draw_texture_ex(
                    tex,
                    p.x,
                    p.y,
                    tint,
                    DrawTextureParams {
                        dest_size: Some(size * view.zoom),
                        ..Default::default()
                    },
                );
            }
        }
    }
}

fn rect_of(s: TileSource) -> Rect {
    Rect::new(s.x as f32, s.y as f32, s.w as f32, s.h as f32)
}
