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
            return Err(ShapeError::NotPositive { what: "circle radius", value: radius as i64 });
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
