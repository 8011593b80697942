//! Contact between a point and a convex polygon.

use crate::shape::{ConvexPolygon, Point};

super::sat_contact!(Point, ConvexPolygon);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::{contact, Proximity::*};
    use crate::shape::{ConvexPolygon, Point};

    /// Right triangle (0,0), (100,0), (0,100): legs on x = 0 and y = 0,
    /// hypotenuse x + y = 100.
    fn tri() -> ConvexPolygon {
        ConvexPolygon::new(&[v(0, 0), v(100, 0), v(0, 100)]).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        let t = tri();
        for p in [v(0, 0), v(100, 0), v(0, 100), v(50, 50), v(0, 50), v(30, 0)] {
            check(&Point, p, &t, v(0, 0), Touching);
        }
        for p in [v(51, 50), v(-1, 0), v(0, 101), v(20, -1)] {
            check(&Point, p, &t, v(0, 0), Apart);
        }
    }

    #[test]
    fn overlapping() {
        let t = tri();
        // 20 from x = 0, 30 from y = 0, 35.4 from the hypotenuse.
        check(&Point, v(20, 30), &t, v(0, 0), Overlapping(v(-20, 0)));
        // 7.07 from the hypotenuse along (1, 1): exactly (5, 5).
        check(&Point, v(45, 45), &t, v(0, 0), Overlapping(v(5, 5)));
        // (5.5, 5.5) rounded away: the point ends at x + y = 101.
        check(&Point, v(44, 45), &t, v(0, 0), Overlapping(v(6, 6)));
        // Same answers with the vertices given the other way round.
        let r = ConvexPolygon::new(&[v(0, 100), v(100, 0), v(0, 0)]).unwrap();
        check(&Point, v(44, 45), &r, v(0, 0), Overlapping(v(6, 6)));
        check(
            &r,
            v(1000, 1000),
            &Point,
            v(1044, 1045),
            Overlapping(v(-6, -6)),
        );
    }

    #[test]
    fn centred_in_a_diamond() {
        // All four faces 70.7 deep: the (1, 1) line has the smallest angle,
        // and centred it is pushed up: (-50, -50).
        let d = ConvexPolygon::new(&[v(0, -100), v(100, 0), v(0, 100), v(-100, 0)]).unwrap();
        check(&Point, v(0, 0), &d, v(0, 0), Overlapping(v(-50, -50)));
        // Tie of (1, 1) and (1, -1) faces near the bottom corner: the (1, 1)
        // line wins; (0.5, 0.5) rounds to (1, 1).
        check(&Point, v(0, 99), &d, v(0, 0), Overlapping(v(1, 1)));
    }

    /// After the MTV (1, 1) near the diamond's bottom corner, moving back two
    /// units along one axis leaves through the other face: the separation
    /// bound must be stated per component (the MTV shortened by a unit on
    /// each axis overlaps again), not along a single axis.
    #[test]
    fn moving_back_along_one_axis_can_exit_elsewhere() {
        let d = ConvexPolygon::new(&[v(0, -100), v(100, 0), v(0, 100), v(-100, 0)]).unwrap();
        let p = v(0, 99);
        let m = contact(&Point, p, &d, v(0, 0)).mtv().unwrap();
        assert_eq!(m, v(1, 1));
        assert_eq!(contact(&Point, p + m, &d, v(0, 0)), Apart);
        assert_eq!(contact(&Point, p + m - v(2, 0), &d, v(0, 0)), Apart);
        assert!(contact(&Point, p + m - v(1, 1), &d, v(0, 0))
            .mtv()
            .is_some());
    }
}
