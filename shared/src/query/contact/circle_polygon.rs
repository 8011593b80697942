//! Contact between a circle and a convex polygon.

use crate::shape::ConvexPolygon;

super::circle_contact!(ConvexPolygon);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{Circle, ConvexPolygon};

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
