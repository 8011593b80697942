//! Contact between an axis-aligned box and a convex polygon.

use crate::shape::{Aabb, ConvexPolygon};

super::sat_contact!(Aabb, ConvexPolygon);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{Aabb, ConvexPolygon};

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
