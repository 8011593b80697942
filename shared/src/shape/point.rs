//! A point: no area, no axes. Useful as a sensor probe.

use super::{Convex, Shape, ShapeKind};
use glam::{I64Vec2, IVec2};

/// A point at its collider's origin.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
pub struct Point;

impl Shape for Point {
    const KIND: ShapeKind = ShapeKind::Point;
    #[inline]
    fn local_bounds(&self) -> (IVec2, IVec2) {
        (IVec2::ZERO, IVec2::ZERO)
    }
}

impl Convex for Point {
    #[inline]
    fn axis_count(&self) -> usize {
        0
    }
    #[inline]
    fn axis(&self, _i: usize) -> I64Vec2 {
        unreachable!("a point has no axes")
    }
    #[inline]
    fn project(&self, _n: I64Vec2) -> (i64, i64) {
        (0, 0)
    }
    #[inline]
    fn vertex_count(&self) -> usize {
        1
    }
    #[inline]
    fn vertex(&self, _i: usize) -> IVec2 {
        IVec2::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::convex::tests::check_convex;

    #[test]
    fn a_point_is_one_vertex_without_axes() {
        assert_eq!(Point.local_bounds(), (IVec2::ZERO, IVec2::ZERO));
        assert_eq!(Point.axis_count(), 0);
        assert_eq!(Point.project(I64Vec2::new(5, -9)), (0, 0));
        check_convex(&Point);
    }
}
