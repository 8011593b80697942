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

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::Point;

    #[test]
    fn equal_points_touch_and_never_overlap() {
        check(&Point, v(5, 5), &Point, v(5, 5), Touching);
        check(&Point, v(-7, 3), &Point, v(-7, 3), Touching);
        for d in [v(1, 0), v(0, 1), v(-1, -1), v(300, -2)] {
            check(&Point, v(5, 5), &Point, v(5, 5) + d, Apart);
        }
    }
}
