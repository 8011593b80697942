//! Contact between a segment and a convex polygon.

use crate::shape::{ConvexPolygon, Segment};

super::sat_contact!(Segment, ConvexPolygon);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{ConvexPolygon, Segment};
    use glam::IVec2;

    fn seg(a: IVec2, b: IVec2) -> Segment {
        Segment::new(a, b).unwrap()
    }

    /// Right triangle (0,0), (100,0), (0,100).
    fn tri() -> ConvexPolygon {
        ConvexPolygon::new(&[v(0, 0), v(100, 0), v(0, 100)]).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        check(
            &seg(v(100, 0), v(0, 100)),
            v(0, 0),
            &tri(),
            v(0, 0),
            Touching,
        );
        check(
            &seg(v(-50, 0), v(150, 0)),
            v(0, 0),
            &tri(),
            v(0, 0),
            Touching,
        );
        check(&seg(v(101, 0), v(0, 101)), v(0, 0), &tri(), v(0, 0), Apart);
        check(&seg(v(-1, -1), v(-1, 100)), v(0, 0), &tri(), v(0, 0), Apart);
    }

    #[test]
    fn overlapping() {
        // Horizontal at y = 10: up to the top leg, (0, -10).
        check(
            &seg(v(-50, 10), v(150, 10)),
            v(0, 0),
            &tri(),
            v(0, 0),
            Overlapping(v(0, -10)),
        );
        // Parallel to the hypotenuse at x + y = 90: out to 100, (5, 5).
        check(
            &seg(v(10, 80), v(80, 10)),
            v(0, 0),
            &tri(),
            v(0, 0),
            Overlapping(v(5, 5)),
        );
        // At x + y = 89: (5.5, 5.5) rounded away.
        check(
            &seg(v(10, 79), v(79, 10)),
            v(0, 0),
            &tri(),
            v(0, 0),
            Overlapping(v(6, 6)),
        );
        check(
            &tri(),
            v(-30, 30),
            &seg(v(10, 79), v(79, 10)),
            v(-30, 30),
            Overlapping(v(-6, -6)),
        );
    }
}
