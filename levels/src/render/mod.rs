//! A loaded level as one picture (`ledge-level render`): the level as the
//! game draws it (its art, or the game's plain colours where it has none)
//! with the collision overlay on top ([`crate::overlay`]: what collides,
//! the entities' boxes, the spawns and a player's box at each), so a host
//! sees in one picture what `ledge-level check` says in words.
//!
//! Drawing only: [`render`] gives pixels, [`Rendered::encode_png`] the PNG
//! file's bytes; reading and writing files is the caller's. The picture
//! covers what the client's camera may show (the level's bounds and its
//! art's extent), [`Rendered::scale`] picture pixels per world pixel; its
//! size is bounded ([`MAX_RENDER_SIDE`], [`MAX_RENDER_PIXELS`]) before
//! anything is allocated.

mod art;
mod canvas;
mod flat;

use tiny_skia::Pixmap;

use crate::art::covered::covered_cells;
use crate::palette::flat as colour;
use crate::LoadedLevel;
use canvas::Canvas;
use ledge_shared::fixed::UNITS_PER_PX;

/// Widest or tallest picture, pixels.
pub const MAX_RENDER_SIDE: u32 = 16384;
/// Most pixels in a picture (32 Mi: 128 MiB of RGBA).
pub const MAX_RENDER_PIXELS: u64 = 1 << 25;
/// Largest scale (picture pixels per world pixel).
pub const MAX_RENDER_SCALE: f32 = 16.0;
pub use art::MAX_DECODED_IMAGE_PIXELS;

/// How to draw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Picture pixels per world pixel; `None`: 1, or less for a level too
    /// large for that (the largest scale that fits, said in the notes).
    pub scale: Option<f32>,
    /// Draw the collision overlay.
    pub overlay: bool,
    /// The part of the world to draw, world pixels `[left, top, width,
    /// height]` (`None`: [`extent`], the whole level).
    pub region: Option<[f32; 4]>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            scale: None,
            overlay: true,
            region: None,
        }
    }
}

/// A level's picture.
pub struct Rendered {
    /// The pixels (premultiplied RGBA).
    pub pixmap: Pixmap,
    /// Picture pixels per world pixel.
    pub scale: f32,
    /// The world point at the picture's top-left corner, world pixels.
    pub origin: [f32; 2],
    /// What was drawn differently (a reduced scale, images left out).
    pub notes: Vec<String>,
}

/// Why a level cannot be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RenderError {
    /// The picture would pass [`MAX_RENDER_SIDE`] or [`MAX_RENDER_PIXELS`].
    #[error(
        "the picture would be {width} x {height} px at scale {scale}, more than the limit of \
         {MAX_RENDER_SIDE} px a side and {MAX_RENDER_PIXELS} px (MAX_RENDER_SIDE, \
         MAX_RENDER_PIXELS); use --scale {fits} or less"
    )]
    TooLarge {
        /// Width it would have, pixels.
        width: u64,
        /// Height it would have.
        height: u64,
        /// The scale asked for.
        scale: f32,
        /// The largest scale that fits.
        fits: f32,
    },
    /// A scale that is not a number in `(0, MAX_RENDER_SCALE]`.
    #[error("scale {0} is not a number above 0 and at most {MAX_RENDER_SCALE}")]
    BadScale(f32),
    /// A region that is not a box of at least one pixel.
    #[error("region {0:?} is not a box of finite numbers at least 1 px wide and high")]
    BadRegion([f32; 4]),
    /// The PNG could not be encoded.
    #[error("cannot encode the picture as PNG: {0}")]
    Png(String),
}

impl Rendered {
    /// Width, pixels.
    pub fn width(&self) -> u32 {
        self.pixmap.width()
    }

    /// Height, pixels.
    pub fn height(&self) -> u32 {
        self.pixmap.height()
    }

    /// The pixel at `x, y` as straight RGBA (transparent outside).
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        self.pixmap.pixel(x, y).map_or([0; 4], |p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue(), c.alpha()]
        })
    }

    /// The picture as a PNG file's bytes.
    pub fn encode_png(&self) -> Result<Vec<u8>, RenderError> {
        self.pixmap
            .encode_png()
            .map_err(|e| RenderError::Png(e.to_string()))
    }
}

/// What the picture covers: the level's bounds and its art's extent (as
/// the client's camera bounds), world pixels `[left, top, right, bottom]`,
/// whole pixels.
pub fn extent(loaded: &LoadedLevel) -> [f32; 4] {
    let u = UNITS_PER_PX as f32;
    let mut b = loaded.level.bounds().map(|(lo, hi)| {
        [
            lo.x as f32 / u,
            lo.y as f32 / u,
            hi.x as f32 / u,
            hi.y as f32 / u,
        ]
    });
    let (w, h) = loaded.art.size;
    if w > 0.0 && h > 0.0 {
        let a = [0.0, 0.0, w, h];
        b = Some(match b {
            Some(b) => [
                b[0].min(a[0]),
                b[1].min(a[1]),
                b[2].max(a[2]),
                b[3].max(a[3]),
            ],
            None => a,
        });
    }
    let [l, t, r, bo] = b.unwrap_or([0.0, 0.0, 1.0, 1.0]);
    [
        l.floor(),
        t.floor(),
        r.ceil().max(l.floor() + 1.0),
        bo.ceil().max(t.floor() + 1.0),
    ]
}

/// The picture's size at `scale` for a world box `w` x `h` pixels, or
/// the error naming the largest scale that fits.
fn picture_size(w: f32, h: f32, scale: f32) -> Result<(u32, u32), RenderError> {
    let (pw, ph) = (
        (w * scale).ceil().max(1.0) as u64,
        (h * scale).ceil().max(1.0) as u64,
    );
    if pw <= MAX_RENDER_SIDE as u64 && ph <= MAX_RENDER_SIDE as u64 && pw * ph <= MAX_RENDER_PIXELS
    {
        return Ok((pw as u32, ph as u32));
    }
    Err(RenderError::TooLarge {
        width: pw,
        height: ph,
        scale,
        fits: fitting_scale(w, h),
    })
}

/// The largest scale (in 1/256 steps, at most 1) at which a world box `w`
/// x `h` pixels fits the bounds.
fn fitting_scale(w: f32, h: f32) -> f32 {
    let side = MAX_RENDER_SIDE as f32;
    let s = (side / w)
        .min(side / h)
        .min((MAX_RENDER_PIXELS as f32 / (w * h)).sqrt())
        .min(1.0);
    ((s * 256.0).floor() / 256.0).max(1.0 / 256.0)
}

/// Draws `loaded`: its art (or plain colours), then the overlay when asked.
pub fn render(loaded: &LoadedLevel, options: &RenderOptions) -> Result<Rendered, RenderError> {
    let [l, t, r, b] = match options.region {
        Some([x, y, w, h])
            if [x, y, w, h].iter().all(|v| v.is_finite()) && w >= 1.0 && h >= 1.0 =>
        {
            [x.floor(), y.floor(), (x + w).ceil(), (y + h).ceil()]
        }
        Some(r) => return Err(RenderError::BadRegion(r)),
        None => extent(loaded),
    };
    let (w, h) = (r - l, b - t);
    let mut notes = Vec::new();
    let scale = match options.scale {
        Some(s) if !(s > 0.0 && s <= MAX_RENDER_SCALE) => return Err(RenderError::BadScale(s)),
        Some(s) => s,
        None => match picture_size(w, h, 1.0) {
            Ok(_) => 1.0,
            Err(_) => {
                let s = fitting_scale(w, h);
                notes.push(format!(
                    "drawn at scale {s} (a {w} x {h} px level is too large for the picture's \
                     bounds at scale 1; --scale chooses)"
                ));
                s
            }
        },
    };
    let (pw, ph) = picture_size(w, h, scale)?;
    let Some(pixmap) = Pixmap::new(pw, ph) else {
        return Err(RenderError::TooLarge {
            width: pw as u64,
            height: ph as u64,
            scale,
            fits: fitting_scale(w, h),
        });
    };
    let mut canvas = Canvas {
        pixmap,
        scale,
        origin: [l, t],
    };
    draw_level(&mut canvas, loaded, &mut notes);
    if options.overlay {
        crate::overlay::level_shapes(&loaded.level, |s| canvas.shape(&s));
    }
    Ok(Rendered {
        pixmap: canvas.pixmap,
        scale,
        origin: [l, t],
        notes,
    })
}

/// The level as the game draws it, back to front: the background, the
/// art, the plain tiles the art does not cover, polygon blocks and blocks
/// (only without art), the entities.
fn draw_level(canvas: &mut Canvas, loaded: &LoadedLevel, notes: &mut Vec<String>) {
    let art = &loaded.art;
    let [r, g, b, a] = art.background.unwrap_or(colour::SKY);
    canvas.pixmap.fill(tiny_skia::Color::from_rgba8(r, g, b, a));
    let images = art::decode(art, notes);
    art::draw(canvas, art, &images);
    let map = &loaded.level.tilemap;
    flat::tiles(canvas, map, &covered_cells(art, map));
    flat::entities(canvas, &loaded.level, art.layers.is_empty());
}

#[cfg(test)]
mod tests;
