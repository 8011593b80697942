//! Contact between an axis-aligned box and a convex polygon.

use crate::shape::{Aabb, ConvexPolygon};

super::sat_contact!(Aabb, ConvexPolygon);

#[cfg(test)]
mod tests {
    use crate::fixed::MAX_COORD;
    use crate::query::contact::{
        contact, Contact,
        Proximity::{self, *},
    };
    use crate::shape::{Aabb, ConvexPolygon};
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

    fn b(x: i32, y: i32) -> Aabb {
        Aabb::new(v(x, y)).unwrap()
    }

    /// Right triangle with the right angle at the origin.
    fn tri() -> ConvexPolygon {
        ConvexPolygon::new(&[v(0, 0), v(100, 0), v(0, 100)]).unwrap()
    }

    /// Right triangle with the right angle at (100, 100): hypotenuse
    /// x + y = 100 on its upper-left side.
    fn tri2() -> ConvexPolygon {
        ConvexPolygon::new(&[v(100, 100), v(0, 100), v(100, 0)]).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        check(&b(50, 50), v(0, 0), &tri2(), v(0, 0), Touching);
        check(&b(50, 50), v(0, 0), &tri2(), v(1, 0), Apart);
        check(&b(50, 50), v(0, 0), &tri(), v(50, -150), Touching);
        check(&b(50, 50), v(0, 0), &tri(), v(51, -150), Apart);
    }

    #[test]
    fn overlapping() {
        // Four axes tie at 30: the x axis has the smallest angle.
        check(
            &b(50, 50),
            v(0, 0),
            &tri(),
            v(20, 20),
            Overlapping(v(-30, 0)),
        );
        // Corner (55, 50) 5 / sqrt 2 past the hypotenuse: (-2.5, -2.5) ->
        // (-3, -3).
        check(
            &b(55, 50),
            v(0, 0),
            &tri2(),
            v(0, 0),
            Overlapping(v(-3, -3)),
        );
        check(
            &tri2(),
            v(40, 40),
            &b(55, 50),
            v(40, 40),
            Overlapping(v(3, 3)),
        );
    }
}
