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
    use crate::query::contact::{
        contact, Contact,
        Proximity::{self, *},
    };
    use crate::shape::Circle;
    use glam::IVec2;

    fn v(x: i32, y: i32) -> IVec2 {
        IVec2::new(x, y)
    }

    /// Far from the origin, near the world bounds.
    const FAR: IVec2 = IVec2::new(MAX_COORD - (1 << 20), -(MAX_COORD - (1 << 21)));

    /// `a` against `b` is `want`, the reverse order is `want` reversed, and
    /// both hold anywhere in the world.
    fn check<A: Contact<B>, B: Contact<A>>(a: &A, pa: IVec2, b: &B, pb: IVec2, want: Proximity) {
        for t in [IVec2::ZERO, FAR, -FAR] {
            assert_eq!(
                contact(a, pa + t, b, pb + t),
                want,
                "a at {pa}, b at {pb}, shifted by {t}"
            );
            assert_eq!(
                contact(b, pb + t, a, pa + t),
                want.reversed(),
                "reverse: a at {pa}, b at {pb}, shifted by {t}"
            );
        }
    }

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
