//! A level's own art drawn as the client's window draws it (see its
//! `draw/art.rs`): layers back to front, a tile's bottom-left corner on its
//! cell's plus the tileset's offset, Tiled's flips (the diagonal as a
//! quarter turn of the vertically mirrored tile), tile objects stretched to
//! their box and turned about their bottom-left corner, image layers
//! repeated, parallax measured from the picture's centre, opacity;
//! nearest-neighbour sampling.

use tiny_skia::{FilterQuality, Paint, Pattern, Pixmap, Rect, SpreadMode, Transform};

use crate::art::{ArtContent, LevelArt, TileGrid, TileSource};

use super::canvas::Canvas;

/// Most pixels of the level's images decoded for one picture (32 Mi);
/// images past it are not drawn (said in `Rendered::notes`).
pub const MAX_DECODED_IMAGE_PIXELS: u64 = 1 << 25;

/// The art's images decoded (`None`: it did not decode, or was left out
/// past [`MAX_DECODED_IMAGE_PIXELS`]; said in `notes`).
pub(crate) fn decode(art: &LevelArt, notes: &mut Vec<String>) -> Vec<Option<Pixmap>> {
    let mut budget = MAX_DECODED_IMAGE_PIXELS;
    art.images
        .iter()
        .map(|img| {
            let pixels = img.width as u64 * img.height as u64;
            if pixels > budget {
                notes.push(format!(
                    "image {:?} is not drawn: the images' decoded pixels would pass \
                     {MAX_DECODED_IMAGE_PIXELS} (MAX_DECODED_IMAGE_PIXELS)",
                    img.name
                ));
                return None;
            }
            budget -= pixels;
            match Pixmap::decode_png(&img.bytes) {
                Ok(mut p) => {
                    if let Some([r, g, b]) = img.transparent {
                        for px in p.pixels_mut() {
                            if px.alpha() == 255 && [px.red(), px.green(), px.blue()] == [r, g, b] {
                                *px = tiny_skia::PremultipliedColorU8::TRANSPARENT;
                            }
                        }
                    }
                    Some(p)
                }
                Err(e) => {
                    notes.push(format!("image {:?} does not decode: {e}", img.name));
                    None
                }
            }
        })
        .collect()
}

/// How one tile is put down: its destination box (world pixels), mirrors
/// within it, and a clockwise turn (degrees) about `pivot`.
struct Placement {
    dest: [f32; 4],
    flip_x: bool,
    flip_y: bool,
    degrees: f32,
    pivot: [f32; 2],
    opacity: f32,
}

/// Draws the part `src` of `image` as `at` says.
fn blit(canvas: &mut Canvas, image: &Pixmap, src: TileSource, at: &Placement) {
    let [dx, dy, dw, dh] = at.dest;
    let (sw, sh) = (src.w as f32, src.h as f32);
    let numbers = [
        dx,
        dy,
        dw,
        dh,
        at.degrees,
        at.pivot[0],
        at.pivot[1],
        at.opacity,
    ];
    if numbers.iter().any(|v| !v.is_finite()) {
        return;
    }
    let Some(rect) = Rect::from_xywh(dx, dy, dw, dh) else {
        return;
    };
    if sw <= 0.0 || sh <= 0.0 {
        return;
    }
    // Image pixels to world pixels, before the turn.
    let mut t = Transform::from_translate(-(src.x as f32), -(src.y as f32));
    if at.flip_x {
        t = t.post_concat(Transform::from_row(-1.0, 0.0, 0.0, 1.0, sw, 0.0));
    }
    if at.flip_y {
        t = t.post_concat(Transform::from_row(1.0, 0.0, 0.0, -1.0, 0.0, sh));
    }
    t = t.post_scale(dw / sw, dh / sh).post_translate(dx, dy);
    let turn = Transform::from_rotate_at(at.degrees, at.pivot[0], at.pivot[1]);
    let paint = Paint {
        shader: Pattern::new(
            image.as_ref(),
            SpreadMode::Pad,
            FilterQuality::Nearest,
            at.opacity.clamp(0.0, 1.0),
            t,
        ),
        anti_alias: false,
        ..Paint::default()
    };
    let world = canvas.world().pre_concat(turn);
    canvas.pixmap.fill_rect(rect, &paint, world, None);
}

/// Draws every layer of `art`, back to front.
pub(crate) fn draw(canvas: &mut Canvas, art: &LevelArt, images: &[Option<Pixmap>]) {
    let centre = canvas.centre();
    let origin = art.parallax_origin;
    for layer in &art.layers {
        let (px, py) = layer.parallax;
        let off = [
            layer.offset.0 + (1.0 - px) * (centre[0] - origin.0),
            layer.offset.1 + (1.0 - py) * (centre[1] - origin.1),
        ];
        match &layer.content {
            ArtContent::Tiles(grid) => draw_grid(canvas, art, images, grid, off, layer.opacity),
            ArtContent::Objects(objects) => {
                for o in objects {
                    let Some(src) = art.source(o.tileset, o.tile) else {
                        continue;
                    };
                    let Some(Some(image)) = images.get(src.image as usize) else {
                        continue;
                    };
                    let anchor = [off[0] + o.x, off[1] + o.y];
                    let at = Placement {
                        dest: [anchor[0], anchor[1] - o.height, o.width, o.height],
                        flip_x: o.flip_h,
                        flip_y: o.flip_v,
                        degrees: o.rotation,
                        pivot: anchor,
                        opacity: layer.opacity * o.opacity,
                    };
                    blit(canvas, image, src, &at);
                }
            }
            ArtContent::Image {
                image,
                repeat_x,
                repeat_y,
            } => {
                let Some(Some(img)) = images.get(*image as usize) else {
                    continue;
                };
                draw_image(
                    canvas,
                    img,
                    *image,
                    (*repeat_x, *repeat_y),
                    off,
                    layer.opacity,
                );
            }
        }
    }
}

fn draw_grid(
    canvas: &mut Canvas,
    art: &LevelArt,
    images: &[Option<Pixmap>],
    grid: &TileGrid,
    off: [f32; 2],
    opacity: f32,
) {
    let (cw, ch) = (grid.cell_width as f32, grid.cell_height as f32);
    if cw <= 0.0 || ch <= 0.0 {
        return;
    }
    for r in 0..grid.height {
        for c in 0..grid.width {
            let Some(cell) = grid.get(c, r) else {
                continue;
            };
            let Some(src) = art.source(cell.tileset, cell.tile) else {
                continue;
            };
            let Some(Some(image)) = images.get(src.image as usize) else {
                continue;
            };
            let to = art.tilesets[cell.tileset as usize].offset;
            let x = off[0] + c as f32 * cw + to.0 as f32;
            let y = off[1] + (r + 1) as f32 * ch - src.h as f32 + to.1 as f32;
            let (w, h) = (src.w as f32, src.h as f32);
            let (degrees, flip_x, flip_y) = if cell.flip_d {
                (90.0, cell.flip_v, !cell.flip_h)
            } else {
                (0.0, cell.flip_h, cell.flip_v)
            };
            let at = Placement {
                dest: [x, y, w, h],
                flip_x,
                flip_y,
                degrees,
                pivot: [x + w / 2.0, y + h / 2.0],
                opacity,
            };
            blit(canvas, image, src, &at);
        }
    }
}

fn draw_image(
    canvas: &mut Canvas,
    img: &Pixmap,
    index: u32,
    (repeat_x, repeat_y): (bool, bool),
    off: [f32; 2],
    opacity: f32,
) {
    let (w, h) = (img.width() as f32, img.height() as f32);
    let seen = canvas.visible();
    // The first copy and how many, along one axis (at most 16384).
    let span = |repeat: bool, start: f32, lo: f32, hi: f32, step: f32| -> (f32, usize) {
        if repeat {
            let first = start + ((lo - start) / step).floor() * step;
            (first, (((hi - first) / step).ceil() as usize).min(16384))
        } else {
            (start, 1)
        }
    };
    let (x0, nx) = span(repeat_x, off[0], seen[0], seen[2], w);
    let (y0, ny) = span(repeat_y, off[1], seen[1], seen[3], h);
    // At most 2^20 copies in all.
    let ny = ny.min((1 << 20) / nx.max(1));
    let src = TileSource {
        image: index,
        x: 0,
        y: 0,
        w: img.width(),
        h: img.height(),
    };
    for j in 0..ny {
        for i in 0..nx {
            let at = Placement {
                dest: [x0 + i as f32 * w, y0 + j as f32 * h, w, h],
                flip_x: false,
                flip_y: false,
                degrees: 0.0,
                pivot: [0.0, 0.0],
                opacity,
            };
            blit(canvas, img, src, &at);
        }
    }
}
