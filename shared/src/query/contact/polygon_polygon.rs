//! Contact between a convex polygon and a convex polygon.

use super::{sat::sat, Contact, Proximity};
use crate::shape::ConvexPolygon;
use glam::IVec2;

impl Contact<ConvexPolygon> for ConvexPolygon {
    #[inline]
    fn contact(&self, pos: IVec2, other: &ConvexPolygon, other_pos: IVec2) -> Proximity {
        sat(self, pos, other, other_pos)
    }
}

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::{contact, Proximity::*};
    use crate::shape::ConvexPolygon;

    /// Diamond with corners at 100 on each axis.
    fn diamond() -> ConvexPolygon {
        ConvexPolygon::new(&[v(0, -100), v(100, 0), v(0, 100), v(-100, 0)]).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        check(&diamond(), v(0, 0), &diamond(), v(100, -100), Touching);
        check(&diamond(), v(0, 0), &diamond(), v(200, 0), Touching);
        check(&diamond(), v(0, 0), &diamond(), v(101, -100), Apart);
        check(&diamond(), v(0, 0), &diamond(), v(201, 0), Apart);
    }

    #[test]
    fn overlapping() {
        // Faces x - y = 100 and x - y = 80 overlap by 20 / sqrt 2: (-10, 10).
        check(
            &diamond(),
            v(0, 0),
            &diamond(),
            v(90, -90),
            Overlapping(v(-10, 10)),
        );
        // 21 / sqrt 2: (-10.5, 10.5) rounded away.
        check(
            &diamond(),
            v(0, 0),
            &diamond(),
            v(90, -89),
            Overlapping(v(-11, 11)),
        );
        // A triangle (given clockwise) and that diamond: the diamond reaches
        // y = 11 into the triangle's top leg, shallower than the 14.8 units
        // across x - y: the triangle goes down 11.
        let t = ConvexPolygon::new(&[v(0, 100), v(100, 0), v(0, 0)]).unwrap();
        check(&t, v(0, 0), &diamond(), v(90, -89), Overlapping(v(0, 11)));
    }

    #[test]
    fn centred_goes_up_both_ways() {
        // Every face ties; the (1, 1) line has the smallest angle; up.
        assert_eq!(
            contact(&diamond(), v(0, 0), &diamond(), v(0, 0)),
            Overlapping(v(-100, -100))
        );
    }
}
