//! Contact between a circle and an oriented box.

use crate::shape::Obb;

super::circle_contact!(Obb);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{Circle, Obb};

    /// u = (30, 40), v = (-20, 15): the edge from -u - v to u - v has outward
    /// normal (80, -60) and lies 25 units from the centre.
    fn obb() -> Obb {
        let o = Obb::new(v(50, 25), v(3, 4)).unwrap();
        assert_eq!((o.u(), o.v()), (v(30, 40), v(-20, 15)));
        o
    }

    fn c10() -> Circle {
        Circle::new(10).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        // 35 units out along the face normal (0.8, -0.6).
        check(&c10(), v(28, -21), &obb(), v(0, 0), Touching);
        // Corner u - v = (50, 25) plus (6, 8).
        check(&c10(), v(56, 33), &obb(), v(0, 0), Touching);
        check(&c10(), v(58, 33), &obb(), v(0, 0), Apart);
        check(&c10(), v(29, -21), &obb(), v(0, 0), Apart);
    }

    #[test]
    fn overlapping() {
        // 30 units out: 5 deep along (0.8, -0.6), exactly (4, -3).
        check(&c10(), v(24, -18), &obb(), v(0, 0), Overlapping(v(4, -3)));
        // 29.4 units out: (4.48, -3.36) -> (5, -4).
        check(&c10(), v(24, -17), &obb(), v(0, 0), Overlapping(v(5, -4)));
        // Corner (50, 25) plus (7, 7): 0.1 deep at 45 degrees -> (1, 1).
        check(&c10(), v(57, 32), &obb(), v(0, 0), Overlapping(v(1, 1)));
        check(
            &obb(),
            v(-1000, 0),
            &c10(),
            v(-943, 32),
            Overlapping(v(-1, -1)),
        );
    }
}
