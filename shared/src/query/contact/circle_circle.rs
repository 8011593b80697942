//! Contact between a circle and a circle.

use super::circle_convex::circle_convex;
use super::{Contact, Proximity};
use crate::shape::{Circle, Point};
use glam::IVec2;

/// A circle of radius `r1 + r2` against the other centre as a point.
impl Contact<Circle> for Circle {
    #[inline]
    fn contact(&self, pos: IVec2, other: &Circle, other_pos: IVec2) -> Proximity {
        circle_convex(self.radius() as i64 + other.radius() as i64, pos, &Point, other_pos)
    }
}
