//! A line segment between two local points.

use super::{Convex, Shape, ShapeError, ShapeKind};
use crate::fixed::{check_extent, perp, wide};
use glam::{I64Vec2, IVec2};

/// A segment from `a` to `b` (local units). Its SAT axes are its normal and
/// its direction: the direction axis is what separates collinear segments
/// and points beyond an end, which the normal alone cannot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct Segment {
    a: IVec2,
    b: IVec2,
}

impl Segment {
    /// A segment with distinct ends inside the extent bound.
    pub fn new(a: IVec2, b: IVec2) -> Result<Self, ShapeError> {
        for (what, v) in [
            ("segment a.x", a.x),
            ("segment a.y", a.y),
            ("segment b.x", b.x),
            ("segment b.y", b.y),
        ] {
            check_extent(what, v as i64)?;
        }
        if a == b {
            return Err(ShapeError::ZeroLength);
        }
        Ok(Self { a, b })
    }

    /// First end.
    #[inline]
    pub fn a(&self) -> IVec2 {
        self.a
    }

    /// Second end.
    #[inline]
    pub fn b(&self) -> IVec2 {
        self.b
    }
}

impl Shape for Segment {
    const KIND: ShapeKind = ShapeKind::Segment;
    #[inline]
    fn local_bounds(&self) -> (IVec2, IVec2) {
        (self.a.min(self.b), self.a.max(self.b))
    }
}

impl Convex for Segment {
    #[inline]
    fn axis_count(&self) -> usize {
        2
    }
    #[inline]
    fn axis(&self, i: usize) -> I64Vec2 {
        let e = wide(self.b - self.a);
        if i == 0 {
            perp(e)
        } else {
            e
        }
    }
    #[inline]
    fn project(&self, n: I64Vec2) -> (i64, i64) {
        let pa = wide(self.a).dot(n);
        let pb = wide(self.b).dot(n);
        (pa.min(pb), pa.max(pb))
    }
    #[inline]
    fn vertex_count(&self) -> usize {
        2
    }
    #[inline]
    fn vertex(&self, i: usize) -> IVec2 {
        if i == 0 {
            self.a
        } else {
            self.b
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::MAX_EXTENT;
    use crate::shape::convex::tests::check_convex;

    #[test]
    fn validates_ends() {
        let s = Segment::new(IVec2::new(4, -2), IVec2::new(-3, 8)).unwrap();
        assert_eq!((s.a(), s.b()), (IVec2::new(4, -2), IVec2::new(-3, 8)));
        assert_eq!(s.local_bounds(), (IVec2::new(-3, -2), IVec2::new(4, 8)));
        check_convex(&s);
        check_convex(&Segment::new(IVec2::ZERO, IVec2::X).unwrap());
        check_convex(&Segment::new(IVec2::splat(-MAX_EXTENT), IVec2::splat(MAX_EXTENT)).unwrap());
        assert_eq!(
            Segment::new(IVec2::new(1, 1), IVec2::new(1, 1)),
            Err(ShapeError::ZeroLength)
        );
        for (a, b) in [
            (IVec2::new(MAX_EXTENT + 1, 0), IVec2::ZERO),
            (IVec2::ZERO, IVec2::new(0, -MAX_EXTENT - 1)),
            (IVec2::splat(i32::MIN), IVec2::ZERO),
        ] {
            assert!(
                matches!(Segment::new(a, b), Err(ShapeError::Bounds(_))),
                "{a} {b}"
            );
        }
    }
}
