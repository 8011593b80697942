//! Contact between a segment and an axis-aligned box.

use crate::shape::{Aabb, Segment};

super::sat_contact!(Segment, Aabb);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{Aabb, Segment};
    use glam::IVec2;

    fn seg(a: IVec2, b: IVec2) -> Segment {
        Segment::new(a, b).unwrap()
    }

    fn b() -> Aabb {
        Aabb::new(v(50, 50)).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        // Along the bottom side, through one corner only, off the side.
        check(
            &seg(v(-100, 50), v(100, 50)),
            v(0, 0),
            &b(),
            v(0, 0),
            Touching,
        );
        check(&seg(v(30, 70), v(70, 30)), v(0, 0), &b(), v(0, 0), Touching);
        check(&seg(v(31, 70), v(71, 30)), v(0, 0), &b(), v(0, 0), Apart);
        check(&seg(v(51, -100), v(51, 100)), v(0, 0), &b(), v(0, 0), Apart);
    }

    #[test]
    fn overlapping() {
        // 10 above the bottom side: down 10.
        check(
            &seg(v(-100, 40), v(100, 40)),
            v(0, 0),
            &b(),
            v(0, 0),
            Overlapping(v(0, 10)),
        );
        // Cutting the corner along x + y = 90: out to x + y = 100, (5, 5).
        check(
            &seg(v(20, 70), v(70, 20)),
            v(0, 0),
            &b(),
            v(0, 0),
            Overlapping(v(5, 5)),
        );
        // Along x + y = 89: (5.5, 5.5) rounded away.
        check(
            &seg(v(20, 69), v(69, 20)),
            v(0, 0),
            &b(),
            v(0, 0),
            Overlapping(v(6, 6)),
        );
        check(
            &b(),
            v(2000, 0),
            &seg(v(20, 69), v(69, 20)),
            v(2000, 0),
            Overlapping(v(-6, -6)),
        );
    }
}
