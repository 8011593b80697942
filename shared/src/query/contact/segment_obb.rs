//! Contact between a segment and an oriented box.

use crate::shape::{Obb, Segment};

super::sat_contact!(Segment, Obb);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{Obb, Segment};
    use glam::IVec2;

    fn seg(a: IVec2, b: IVec2) -> Segment {
        Segment::new(a, b).unwrap()
    }

    /// u = (30, 40), v = (-20, 15): n1 = (40, -30) faces at +-1250 (25 units).
    fn obb() -> Obb {
        let o = Obb::new(v(50, 25), v(3, 4)).unwrap();
        assert_eq!((o.u(), o.v()), (v(30, 40), v(-20, 15)));
        o
    }

    #[test]
    fn touching_and_apart() {
        // Along the edge from u - v to -u - v, then one unit off it.
        check(
            &seg(v(50, 25), v(-10, -55)),
            v(0, 0),
            &obb(),
            v(0, 0),
            Touching,
        );
        check(&seg(v(51, 25), v(-9, -55)), v(0, 0), &obb(), v(0, 0), Apart);
    }

    #[test]
    fn overlapping() {
        // Parallel to u, 20 units out along n1 (face at 25): out by 5, (4, -3).
        check(
            &seg(v(1, -32), v(31, 8)),
            v(0, 0),
            &obb(),
            v(0, 0),
            Overlapping(v(4, -3)),
        );
        // One unit lower: 280 / 50 = 5.6 units -> (4.48, -3.36) -> (5, -4).
        check(
            &seg(v(1, -31), v(31, 9)),
            v(0, 0),
            &obb(),
            v(0, 0),
            Overlapping(v(5, -4)),
        );
        check(
            &obb(),
            v(7, 7),
            &seg(v(1, -31), v(31, 9)),
            v(7, 7),
            Overlapping(v(-5, 4)),
        );
    }
}
