//! Contact between a point and a point.

use super::{Contact, Proximity};
use crate::shape::Point;
use glam::IVec2;

/// Two points have no area: they touch when equal and are apart otherwise.
impl Contact<Point> for Point {
    #[inline]
    fn contact(&self, pos: IVec2, _other: &Point, other_pos: IVec2) -> Proximity {
        if pos == other_pos {
            Proximity::Touching
        } else {
            Proximity::Apart
        }
    }
}
