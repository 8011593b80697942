//! [`Bounds`], the integer box every part of the broad phase stores and
//! compares. In a module of its own so that the strips and the sweeps below
//! the broad phase's facade (`mod.rs`) need nothing from it.

use glam::IVec2;

/// An integer axis-aligned box by its corners, in units: the closed set from
/// `min` to `max` (`min <= max` on both axes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Bounds {
    /// Smallest corner (left, top).
    pub min: IVec2,
    /// Largest corner (right, bottom).
    pub max: IVec2,
}

impl Bounds {
    /// The box with corners `min` and `max`.
    #[inline]
    pub const fn new(min: IVec2, max: IVec2) -> Self {
        Self { min, max }
    }

    /// The box of size `size` whose smallest corner is `min`.
    #[inline]
    pub fn from_min_size(min: IVec2, size: IVec2) -> Self {
        Self {
            min,
            max: min + size,
        }
    }

    /// Whether the interiors overlap (positive overlap on both axes).
    #[inline]
    pub fn overlaps(&self, o: &Bounds) -> bool {
        self.min.x < o.max.x && o.min.x < self.max.x && self.min.y < o.max.y && o.min.y < self.max.y
    }
}
