//! [`Rect`], a box by its edges in `i64` units: what the rules and the spawn
//! spots test overlaps with. In a module of its own so that `spawn` and
//! `rules` share it without naming each other.

use glam::IVec2;

/// A box by its edges, in `i64` units.
#[derive(Debug, Clone, Copy)]
pub(super) struct Rect {
    pub(super) l: i64,
    pub(super) t: i64,
    pub(super) r: i64,
    pub(super) b: i64,
}

impl Rect {
    pub(super) fn new(centre: IVec2, half: IVec2) -> Self {
        let (c, h) = (centre.as_i64vec2(), half.as_i64vec2());
        Rect {
            l: c.x - h.x,
            t: c.y - h.y,
            r: c.x + h.x,
            b: c.y + h.y,
        }
    }

    /// Interiors overlap.
    pub(super) fn overlaps(&self, o: &Rect) -> bool {
        self.l < o.r && o.l < self.r && self.t < o.b && o.t < self.b
    }

    /// The interiors of this box and of the parallelogram of corners `c ±
    /// u ± v` overlap: exact separating-axis test on the box's axes and the
    /// normals of `u` and `v` (in `i128`: no overflow for any `i32`
    /// input).
    pub(super) fn overlaps_obb(&self, c: IVec2, u: IVec2, v: IVec2) -> bool {
        let w = |x: i64| x as i128;
        let (u, v) = (
            (w(u.x as i64), w(u.y as i64)),
            (w(v.x as i64), w(v.y as i64)),
        );
        // Doubled: the box's centre and extents without halving.
        let (cx2, cy2) = (w(self.l + self.r), w(self.t + self.b));
        let (wx, wy) = (w(self.r - self.l), w(self.b - self.t));
        let (ox2, oy2) = (2 * w(c.x as i64), 2 * w(c.y as i64));
        let axes = [(1, 0), (0, 1), (u.1, -u.0), (v.1, -v.0)];
        axes.iter().all(|&(nx, ny)| {
            let d = (cx2 - ox2) * nx + (cy2 - oy2) * ny;
            let box_r = wx * nx.abs() + wy * ny.abs();
            let obb_r = 2 * ((u.0 * nx + u.1 * ny).abs() + (v.0 * nx + v.1 * ny).abs());
            d.abs() < box_r + obb_r
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_upright_parallelogram_overlaps_as_its_box_does() {
        let b = Rect::new(IVec2::new(0, 0), IVec2::new(6, 8));
        for x in -20..=20 {
            for y in -20..=20 {
                let c = IVec2::new(x, y);
                let (u, v) = (IVec2::new(5, 0), IVec2::new(0, 3));
                let upright = Rect::new(c, IVec2::new(5, 3)).overlaps(&b);
                assert_eq!(b.overlaps_obb(c, u, v), upright, "{c}");
                // Either winding.
                assert_eq!(b.overlaps_obb(c, v, -u), upright, "{c}");
            }
        }
    }

    #[test]
    fn a_diamond_misses_the_corners_of_its_bounding_box() {
        // A square turned 45 degrees: corners (±10, 0), (0, ±10).
        let (u, v) = (IVec2::new(5, 5), IVec2::new(-5, 5));
        let at = |x: i32, y: i32, h: i32| Rect::new(IVec2::new(x, y), IVec2::splat(h));
        assert!(at(0, 0, 1).overlaps_obb(IVec2::ZERO, u, v));
        // In the bounding box's corner, clear of the diamond.
        assert!(!at(8, 8, 2).overlaps_obb(IVec2::ZERO, u, v));
        // Touching an edge is not an overlap; one unit more is.
        assert!(!at(6, 6, 1).overlaps_obb(IVec2::ZERO, u, v));
        assert!(at(6, 5, 1).overlaps_obb(IVec2::ZERO, u, v));
        // Extreme coordinates do not overflow.
        let far = Rect::new(IVec2::splat(i32::MAX / 2), IVec2::splat(1 << 27));
        assert!(!far.overlaps_obb(IVec2::splat(-(i32::MAX / 2)), u * (1 << 20), v));
    }
}
