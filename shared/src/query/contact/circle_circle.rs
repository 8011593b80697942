//! Contact between a circle and a circle.

use super::circle_convex::circle_convex;
use super::{Contact, Proximity};
use crate::shape::{Circle, Point};
use glam::IVec2;

/// A circle of radius `r1 + r2` against the other centre as a point.
impl Contact<Circle> for Circle {
    #[inline]
    fn contact(&self, pos: IVec2, other: &Circle, other_pos: IVec2) -> Proximity {
        circle_convex(
            self.radius() as i64 + other.radius() as i64,
            pos,
            &Point,
            other_pos,
        )
    }
}

#[cfg(test)]
mod tests {
    use crate::fixed::MAX_COORD;
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::{contact, Proximity::*};
    use crate::shape::Circle;

    fn c(r: i32) -> Circle {
        Circle::new(r).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        // Radii 30 + 20 = 50 = |(30, 40)|.
        check(&c(30), v(0, 0), &c(20), v(30, 40), Touching);
        check(&c(30), v(0, 0), &c(20), v(30, 41), Apart);
        check(&c(1), v(0, 0), &c(1), v(2, 0), Touching);
        check(&c(1), v(0, 0), &c(1), v(2, 1), Apart);
    }

    #[test]
    fn overlapping() {
        // Centres 30 apart along 3-4-5: A moves 20 back, exactly.
        check(&c(30), v(0, 0), &c(20), v(18, 24), Overlapping(v(-12, -16)));
        // 45 degrees, 14.14 apart: (-25.36, -25.36) -> (-26, -26).
        check(&c(30), v(0, 0), &c(20), v(10, 10), Overlapping(v(-26, -26)));
        // Unit circles at (1, 1): 0.41 each way rounds to a whole unit.
        check(&c(1), v(0, 0), &c(1), v(1, 1), Overlapping(v(-1, -1)));
    }

    #[test]
    fn coincident_centres_overlap_and_go_up_both_ways() {
        for t in [v(5, 5), v(-MAX_COORD, MAX_COORD)] {
            assert_eq!(contact(&c(30), t, &c(20), t), Overlapping(v(0, -50)));
            assert_eq!(contact(&c(20), t, &c(30), t), Overlapping(v(0, -50)));
            assert_eq!(contact(&c(1), t, &c(1), t), Overlapping(v(0, -2)));
        }
    }
}
