//! A circle centred on its origin.

use super::{Shape, ShapeError, ShapeKind};
use crate::fixed::check_extent;
use glam::IVec2;

/// A circle of integer radius (units) centred on its collider's origin.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct Circle {
    radius: i32,
}

impl Circle {
    /// A circle of `radius` units; it must be positive and within the extent bound.
    pub fn new(radius: i32) -> Result<Self, ShapeError> {
        if radius <= 0 {
            return Err(ShapeError::NotPositive {
                what: "circle radius",
                value: radius as i64,
            });
        }
        check_extent("circle radius", radius as i64)?;
        Ok(Self { radius })
    }

    /// The radius in units.
    #[inline]
    pub fn radius(&self) -> i32 {
        self.radius
    }
}

impl Shape for Circle {
    const KIND: ShapeKind = ShapeKind::Circle;
    #[inline]
    fn local_bounds(&self) -> (IVec2, IVec2) {
        (IVec2::splat(-self.radius), IVec2::splat(self.radius))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::MAX_EXTENT;

    #[test]
    fn validates_the_radius() {
        let c = Circle::new(5).unwrap();
        assert_eq!(c.radius(), 5);
        assert_eq!(c.local_bounds(), (IVec2::splat(-5), IVec2::splat(5)));
        assert_eq!(Circle::new(1).unwrap().radius(), 1);
        assert_eq!(Circle::new(MAX_EXTENT).unwrap().radius(), MAX_EXTENT);
        for bad in [0, -1, i32::MIN] {
            assert!(
                matches!(Circle::new(bad), Err(ShapeError::NotPositive { .. })),
                "{bad}"
            );
        }
        for big in [MAX_EXTENT + 1, i32::MAX] {
            assert!(
                matches!(Circle::new(big), Err(ShapeError::Bounds(_))),
                "{big}"
            );
        }
    }
}
