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
}
