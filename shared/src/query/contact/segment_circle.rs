//! Contact between a segment and a circle.

use crate::shape::Segment;

// The circle kernel implements circle-against-segment; this pair is its reverse.
super::circle_contact!(Segment);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{Circle, Segment};
    use glam::IVec2;

    fn seg(a: IVec2, b: IVec2) -> Segment {
        Segment::new(a, b).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        let c = Circle::new(50).unwrap();
        check(
            &seg(v(-100, 50), v(100, 50)),
            v(0, 0),
            &c,
            v(0, 0),
            Touching,
        );
        check(&seg(v(-100, 51), v(100, 51)), v(0, 0), &c, v(0, 0), Apart);
        // Nearest feature an end: (30, 40) at distance 50.
        check(&seg(v(30, 40), v(200, 40)), v(0, 0), &c, v(0, 0), Touching);
        check(&seg(v(31, 40), v(200, 40)), v(0, 0), &c, v(0, 0), Apart);
    }

    #[test]
    fn overlapping() {
        let c = Circle::new(50).unwrap();
        // The line 30 below the centre: circle up 20, segment down 20.
        check(
            &seg(v(-100, 30), v(100, 30)),
            v(0, 0),
            &c,
            v(0, 0),
            Overlapping(v(0, 20)),
        );
        // End (20, 20) at 45 degrees, 28.28 away: the circle moves by
        // (-15.36, -15.36) -> (-16, -16).
        check(
            &c,
            v(0, 0),
            &seg(v(20, 20), v(20, 200)),
            v(0, 0),
            Overlapping(v(-16, -16)),
        );
        check(
            &seg(v(20, 20), v(20, 200)),
            v(-5, 7),
            &c,
            v(-5, 7),
            Overlapping(v(16, 16)),
        );
    }

    #[test]
    fn centre_on_the_segment_follows_its_right_hand_normal() {
        let c = Circle::new(50).unwrap();
        check(
            &c,
            v(0, 0),
            &seg(v(-100, 0), v(100, 0)),
            v(0, 0),
            Overlapping(v(0, -50)),
        );
        check(
            &c,
            v(0, 0),
            &seg(v(100, 0), v(-100, 0)),
            v(0, 0),
            Overlapping(v(0, 50)),
        );
    }

    /// Overlaps far below the kernel's 2^-32 square-root precision: the
    /// segment (0,0)-(1,2) has normal w = (2, -1), |w| = sqrt(5), and the
    /// centres below solve 5 r^2 - s^2 = 1 (a Pell equation), so the circle
    /// overlaps the segment by about 1 / (2 s sqrt 5) units. The exact MTV
    /// is a tiny positive multiple of (2, -1): rounded away, (1, -1).
    #[test]
    fn sub_precision_overlap_is_rounded_away_from_zero() {
        let s = seg(v(0, 0), v(1, 2));
        for (r, c) in [
            (98209, v(87841, -43920)),
            (31622993, v(28284465, -14142232)),
        ] {
            let circle = Circle::new(r).unwrap();
            check(&circle, c, &s, v(0, 0), Overlapping(v(1, -1)));
            check(&circle, c + v(1, -1), &s, v(0, 0), Apart);
        }
    }
}
