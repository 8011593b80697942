//! Contact between an oriented box and a convex polygon.

use crate::shape::{ConvexPolygon, Obb};

super::sat_contact!(Obb, ConvexPolygon);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{ConvexPolygon, Obb};

    /// u = (30, 40), v = (-20, 15): corner u + v = (10, 55) lowest, x extent
    /// 50; n2 = (15, 20) faces at 1250 (50 units).
    fn obb() -> Obb {
        let o = Obb::new(v(50, 25), v(3, 4)).unwrap();
        assert_eq!((o.u(), o.v()), (v(30, 40), v(-20, 15)));
        o
    }

    /// Right triangle with the right angle at its origin.
    fn tri() -> ConvexPolygon {
        ConvexPolygon::new(&[v(0, 0), v(100, 0), v(0, 100)]).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        // The box's lowest corner on the triangle's top leg.
        check(&obb(), v(0, 0), &tri(), v(0, 55), Touching);
        check(&obb(), v(0, 0), &tri(), v(0, 56), Apart);
    }

    #[test]
    fn overlapping() {
        // Lowest corner 5 into the top leg: up 5.
        check(&obb(), v(0, 0), &tri(), v(0, 50), Overlapping(v(0, -5)));
        // The triangle's corner 10 units into the n2 face: (-6, -8) exactly.
        check(&obb(), v(0, 0), &tri(), v(32, 26), Overlapping(v(-6, -8)));
        // 10.8 units: (-6.48, -8.64) -> (-7, -9).
        check(&obb(), v(0, 0), &tri(), v(32, 25), Overlapping(v(-7, -9)));
        check(&tri(), v(32, 25), &obb(), v(0, 0), Overlapping(v(7, 9)));
    }

    #[test]
    fn equal_depths_pick_the_smallest_angle() {
        // The n2 face and the triangle's x = 0 leg are both 10 deep; the x
        // axis has the smaller angle.
        check(&obb(), v(0, 0), &tri(), v(40, 20), Overlapping(v(-10, 0)));
    }
}
