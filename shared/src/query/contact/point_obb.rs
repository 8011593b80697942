//! Contact between a point and an oriented box.

use crate::shape::{Obb, Point};

super::sat_contact!(Point, Obb);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{Obb, Point};

    /// Half extents (50, 25) turned to (3, 4): exact half axes u = (30, 40),
    /// v = (-20, 15); SAT axes n1 = (40, -30) (|n1| = 50, half width 25) and
    /// n2 = (15, 20) (|n2| = 25, half width 50).
    fn obb() -> Obb {
        let o = Obb::new(v(50, 25), v(3, 4)).unwrap();
        assert_eq!((o.u(), o.v()), (v(30, 40), v(-20, 15)));
        o
    }

    #[test]
    fn touching_and_apart() {
        let o = obb();
        // Corners +-u +-v and an edge midpoint.
        for p in [v(50, 25), v(-10, -55), v(10, 55), v(-50, -25), v(30, 40)] {
            check(&Point, p, &o, v(0, 0), Touching);
        }
        // n1 . (51, 25) = 1290 > 1250.
        check(&Point, v(51, 25), &o, v(0, 0), Apart);
        check(&Point, v(0, 56), &o, v(0, 0), Apart);
    }

    #[test]
    fn overlapping_pushes_along_the_slanted_normal() {
        let o = obb();
        // n1 . p = 500: 750 / 50 = 15 units from the n1 face (n2: 30 units):
        // MTV = n1 * 750 / 2500 = (12, -9) exactly.
        check(&Point, v(20, 10), &o, v(0, 0), Overlapping(v(12, -9)));
        // n1 . p = 470: MTV = n1 * 780 / 2500 = (12.48, -9.36) -> (13, -10).
        check(&Point, v(20, 11), &o, v(0, 0), Overlapping(v(13, -10)));
        check(
            &o,
            v(-400, 900),
            &Point,
            v(-380, 911),
            Overlapping(v(-13, 10)),
        );
    }

    #[test]
    fn centred_on_the_slanted_axis_goes_up() {
        // p = 0.4 u: centred along n1 (1250 each way, 25 units), 30 units
        // along n2; n1 = (40, -30) already points up: MTV = (20, -15).
        check(&Point, v(12, 16), &obb(), v(0, 0), Overlapping(v(20, -15)));
    }
}
