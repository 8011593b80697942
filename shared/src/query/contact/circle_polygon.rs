//! Contact between a circle and a convex polygon.

use crate::shape::ConvexPolygon;

super::circle_contact!(ConvexPolygon);

#[cfg(test)]
mod tests {
    use crate::fixed::MAX_COORD;
    use crate::query::contact::{
        contact, Contact,
        Proximity::{self, *},
    };
    use crate::shape::{Circle, ConvexPolygon};
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

    /// Diamond with corners at 100 on each axis: faces |x| + |y| = 100.
    fn diamond() -> ConvexPolygon {
        ConvexPolygon::new(&[v(0, -100), v(100, 0), v(0, 100), v(-100, 0)]).unwrap()
    }

    fn c(r: i32) -> Circle {
        Circle::new(r).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        check(&c(20), v(0, -120), &diamond(), v(0, 0), Touching);
        check(&c(20), v(0, -121), &diamond(), v(0, 0), Apart);
        // Face x - y = 100 at distance 30 / sqrt 2 = 21.2 > 20.
        check(&c(20), v(70, -60), &diamond(), v(0, 0), Apart);
    }

    #[test]
    fn overlapping() {
        // 7.07 from the upper-right face: (9.14, -9.14) -> (10, -10).
        check(
            &c(20),
            v(60, -50),
            &diamond(),
            v(0, 0),
            Overlapping(v(10, -10)),
        );
        check(
            &diamond(),
            v(5, 5),
            &c(20),
            v(65, -45),
            Overlapping(v(-10, 10)),
        );
        // Centre 5 left of a triangle's vertical leg: out 5 more, exactly.
        let t = ConvexPolygon::new(&[v(0, 0), v(100, 0), v(0, 100)]).unwrap();
        check(&c(10), v(-5, 50), &t, v(0, 0), Overlapping(v(-5, 0)));
    }

    #[test]
    fn centred_circle_leaves_through_the_nearest_face_closest_to_up() {
        // All faces 70.7 away: the push closest to up (normal (1, -1)) wins:
        // (64.14, -64.14) -> (65, -65).
        check(
            &c(20),
            v(0, 0),
            &diamond(),
            v(0, 0),
            Overlapping(v(65, -65)),
        );
    }

    #[test]
    fn centred_circle_tie_does_not_depend_on_the_first_vertex() {
        let d = diamond();
        let verts = d.vertices().to_vec();
        for k in 0..verts.len() {
            let mut rotated = verts.clone();
            rotated.rotate_left(k);
            let p = ConvexPolygon::new(&rotated).unwrap();
            check(&c(20), v(0, 0), &p, v(0, 0), Overlapping(v(65, -65)));
        }
    }
}
