//! An axis-aligned box centred on its origin.

use super::{Convex, Shape, ShapeError, ShapeKind};
use crate::fixed::check_extent;
use glam::{I64Vec2, IVec2};

/// An axis-aligned box of half extents `half` (units), centred on its
/// collider's origin. Its full size is `2 * half`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct Aabb {
    half: IVec2,
}

impl Aabb {
    /// A box with the given half extents; both must be positive and within the
    /// extent bound.
    pub fn new(half: IVec2) -> Result<Self, ShapeError> {
        for (what, v) in [("box half width", half.x), ("box half height", half.y)] {
            if v <= 0 {
                return Err(ShapeError::NotPositive { what, value: v as i64 });
            }
            check_extent(what, v as i64)?;
        }
        Ok(Self { half })
    }

    /// A box from its full size in units; odd sizes are not representable
    /// centred on an integer origin, so `size` must be even.
    pub fn from_size(size: IVec2) -> Result<Self, ShapeError> {
        Self::new(size / 2)
    }

    /// Half extents in units.
    #[inline]
    pub fn half(&self) -> IVec2 {
        self.half
    }
}

impl Shape for Aabb {
    const KIND: ShapeKind = ShapeKind::Aabb;
    #[inline]
    fn local_bounds(&self) -> (IVec2, IVec2) {
        (-self.half, self.half)
    }
}

impl Convex for Aabb {
    #[inline]
    fn axis_count(&self) -> usize {
        2
    }
    #[inline]
    fn axis(&self, i: usize) -> I64Vec2 {
        if i == 0 {
            I64Vec2::X
        } else {
            I64Vec2::Y
        }
    }
    #[inline]
    fn project(&self, n: I64Vec2) -> (i64, i64) {
        let r = self.half.x as i64 * n.x.abs() + self.half.y as i64 * n.y.abs();
        (-r, r)
    }
    #[inline]
    fn vertex_count(&self) -> usize {
        4
    }
    #[inline]
    fn vertex(&self, i: usize) -> IVec2 {
        let h = self.half;
        match i {
            0 => IVec2::new(-h.x, -h.y),
            1 => IVec2::new(h.x, -h.y),
            2 => IVec2::new(h.x, h.y),
            _ => IVec2::new(-h.x, h.y),
        }
    }
}
