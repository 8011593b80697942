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
                return Err(ShapeError::NotPositive {
                    what,
                    value: v as i64,
                });
            }
            check_extent(what, v as i64)?;
        }
        Ok(Self { half })
    }

    /// A box from its full size in units; odd sizes are not representable
    /// centred on an integer origin, so `size` must be even.
    pub fn from_size(size: IVec2) -> Result<Self, ShapeError> {
        for (what, v) in [("box width", size.x), ("box height", size.y)] {
            if v % 2 != 0 {
                return Err(ShapeError::OddSize {
                    what,
                    value: v as i64,
                });
            }
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::MAX_EXTENT;
    use crate::shape::convex::tests::check_convex;

    #[test]
    fn validates_half_extents() {
        let b = Aabb::new(IVec2::new(3, 7)).unwrap();
        assert_eq!(b.half(), IVec2::new(3, 7));
        assert_eq!(b.local_bounds(), (IVec2::new(-3, -7), IVec2::new(3, 7)));
        check_convex(&b);
        check_convex(&Aabb::new(IVec2::ONE).unwrap());
        check_convex(&Aabb::new(IVec2::splat(MAX_EXTENT)).unwrap());
        for bad in [
            IVec2::new(0, 1),
            IVec2::new(1, 0),
            IVec2::new(-1, 5),
            IVec2::new(5, i32::MIN),
        ] {
            assert!(
                matches!(Aabb::new(bad), Err(ShapeError::NotPositive { .. })),
                "{bad}"
            );
        }
        for big in [IVec2::new(MAX_EXTENT + 1, 1), IVec2::new(1, i32::MAX)] {
            assert!(
                matches!(Aabb::new(big), Err(ShapeError::Bounds(_))),
                "{big}"
            );
        }
    }

    #[test]
    fn from_size_halves_even_sizes() {
        assert_eq!(
            Aabb::from_size(IVec2::new(20, 10)).unwrap().half(),
            IVec2::new(10, 5)
        );
        assert_eq!(
            Aabb::from_size(IVec2::new(2, 2)).unwrap().half(),
            IVec2::ONE
        );
        assert!(Aabb::from_size(IVec2::new(0, 10)).is_err());
        assert!(Aabb::from_size(IVec2::new(-4, 10)).is_err());
        assert_eq!(
            Aabb::from_size(IVec2::new(3, 10)),
            Err(ShapeError::OddSize {
                what: "box width",
                value: 3
            })
        );
        assert!(Aabb::from_size(IVec2::new(4, 5)).is_err());
    }
}
