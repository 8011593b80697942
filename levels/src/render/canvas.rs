//! The picture being drawn: a pixmap and the world-to-picture transform
//! (`picture = (world - origin) * scale`, pixels, y down), with the few
//! primitives the level's drawing needs, in world pixels. No
//! anti-aliasing, as the game's window draws its triangles.

use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Transform};

use crate::overlay::Shape;
use crate::palette::Rgba;

/// A picture of part of the world.
pub(crate) struct Canvas {
    /// The pixels.
    pub pixmap: Pixmap,
    /// Picture pixels per world pixel.
    pub scale: f32,
    /// The world point at the picture's top-left corner, world pixels.
    pub origin: [f32; 2],
}

/// A solid paint of `c`.
pub(crate) fn paint(c: Rgba) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(c[0], c[1], c[2], c[3]);
    p.anti_alias = false;
    p
}

impl Canvas {
    /// World pixels to picture pixels.
    pub fn world(&self) -> Transform {
        Transform::from_row(
            self.scale,
            0.0,
            0.0,
            self.scale,
            -self.origin[0] * self.scale,
            -self.origin[1] * self.scale,
        )
    }

    /// The world point at the picture's centre.
    pub fn centre(&self) -> [f32; 2] {
        [
            self.origin[0] + self.pixmap.width() as f32 / self.scale / 2.0,
            self.origin[1] + self.pixmap.height() as f32 / self.scale / 2.0,
        ]
    }

    /// The world box the picture shows: `[left, top, right, bottom]`.
    pub fn visible(&self) -> [f32; 4] {
        [
            self.origin[0],
            self.origin[1],
            self.origin[0] + self.pixmap.width() as f32 / self.scale,
            self.origin[1] + self.pixmap.height() as f32 / self.scale,
        ]
    }

    /// Fills the convex polygon `points` (world pixels) with `c`.
    pub fn polygon(&mut self, points: &[[f32; 2]], c: Rgba) {
        if points.len() < 3 || c[3] == 0 {
            return;
        }
        let mut pb = PathBuilder::new();
        pb.move_to(points[0][0], points[0][1]);
        for p in &points[1..] {
            pb.line_to(p[0], p[1]);
        }
        pb.close();
        if let Some(path) = pb.finish() {
            let t = self.world();
            self.pixmap
                .fill_path(&path, &paint(c), FillRule::Winding, t, None);
        }
    }

    /// Fills an overlay shape.
    pub fn shape(&mut self, s: &Shape) {
        self.polygon(s.points(), s.color);
    }

    /// Fills the box at `x, y` of size `w, h` (world pixels).
    pub fn rect(&mut self, x: f32, y: f32, w: f32, h: f32, c: Rgba) {
        if w > 0.0 && h > 0.0 {
            self.polygon(&[[x, y], [x + w, y], [x + w, y + h], [x, y + h]], c);
        }
    }

    /// Fills a triangle.
    pub fn tri(&mut self, a: [f32; 2], b: [f32; 2], c: [f32; 2], color: Rgba) {
        self.polygon(&[a, b, c], color);
    }

    /// A line `thickness` world pixels thick, as a quad around it.
    pub fn line(&mut self, a: [f32; 2], b: [f32; 2], thickness: f32, c: Rgba) {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = (dx * dx + dy * dy).sqrt();
        if len <= 0.0 {
            return;
        }
        let k = thickness / 2.0 / len;
        let (nx, ny) = (-dy * k, dx * k);
        self.polygon(
            &[
                [a[0] + nx, a[1] + ny],
                [b[0] + nx, b[1] + ny],
                [b[0] - nx, b[1] - ny],
                [a[0] - nx, a[1] - ny],
            ],
            c,
        );
    }

    /// Fills an ellipse of radii `rx, ry` about `c` (a 24-sided polygon).
    pub fn ellipse(&mut self, c: [f32; 2], rx: f32, ry: f32, color: Rgba) {
        let pts: Vec<[f32; 2]> = (0..24)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / 24.0;
                [c[0] + rx * a.cos(), c[1] + ry * a.sin()]
            })
            .collect();
        self.polygon(&pts, color);
    }
}
