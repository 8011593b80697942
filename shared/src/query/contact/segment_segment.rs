//! Contact between a segment and a segment.

use super::{sat::sat, Contact, Proximity};
use crate::shape::Segment;
use glam::IVec2;

impl Contact<Segment> for Segment {
    #[inline]
    fn contact(&self, pos: IVec2, other: &Segment, other_pos: IVec2) -> Proximity {
        sat(self, pos, other, other_pos)
    }
}

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::{contact, Proximity::*};
    use crate::shape::Segment;
    use glam::IVec2;

    fn seg(a: IVec2, b: IVec2) -> Segment {
        Segment::new(a, b).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        let a = seg(v(0, 0), v(100, 0));
        // Collinear overlap, T junction, end to end: zero gap.
        check(&a, v(0, 0), &seg(v(50, 0), v(150, 0)), v(0, 0), Touching);
        check(&a, v(0, 0), &seg(v(50, 0), v(50, 50)), v(0, 0), Touching);
        check(&a, v(0, 0), &seg(v(100, 0), v(200, 50)), v(0, 0), Touching);
        // Collinear with a gap (direction axis), parallel lines (normal).
        check(&a, v(0, 0), &seg(v(101, 0), v(150, 0)), v(0, 0), Apart);
        check(&a, v(0, 0), &seg(v(0, 1), v(100, 1)), v(0, 0), Apart);
    }

    #[test]
    fn crossing_segments_overlap() {
        let a = seg(v(-100, 0), v(100, 0));
        let b = seg(v(0, -50), v(0, 50));
        // B spans y in [-30, 70] at x = 30: A goes up 30 to B's top end.
        check(&a, v(0, 0), &b, v(30, 20), Overlapping(v(0, -30)));
        // Slanted: A along (4, 3), B vertical at x = 40 from y = 10 to 70.
        // A's normal (60, -80): B projects to [-3200, 1600], push 1600 / 100
        // = 16 units -> (9.6, -12.8) -> (10, -13).
        let a = seg(v(0, 0), v(80, 60));
        let b = seg(v(40, 10), v(40, 70));
        check(&a, v(0, 0), &b, v(0, 0), Overlapping(v(10, -13)));
    }

    #[test]
    fn centred_cross_goes_up_both_ways() {
        // Same kind and centred: each shape, when first, is pushed up.
        let a = seg(v(-100, 0), v(100, 0));
        let b = seg(v(0, -50), v(0, 50));
        assert_eq!(contact(&a, v(0, 0), &b, v(0, 0)), Overlapping(v(0, -50)));
        assert_eq!(contact(&b, v(0, 0), &a, v(0, 0)), Overlapping(v(0, -50)));
    }
}
