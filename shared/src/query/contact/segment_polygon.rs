//! Contact between a segment and a convex polygon.

use crate::shape::{ConvexPolygon, Segment};

super::sat_contact!(Segment, ConvexPolygon);

#[cfg(test)]
mod tests {
    use crate::fixed::MAX_COORD;
    use crate::query::contact::{
        contact, Contact,
        Proximity::{self, *},
    };
    use crate::shape::{ConvexPolygon, Segment};
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
