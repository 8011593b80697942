//! Contact between a point and a segment.

use crate::shape::{Point, Segment};

super::sat_contact!(Point, Segment);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::{contact, Proximity::*};
    use crate::shape::{Point, Segment};

    /// A 3-4-5 segment of length 500.
    fn slanted() -> Segment {
        Segment::new(v(0, 0), v(400, 300)).unwrap()
    }

    #[test]
    fn point_on_a_segment_touches() {
        let s = slanted();
        for p in [v(0, 0), v(200, 150), v(400, 300), v(4, 3)] {
            check(&Point, p, &s, v(0, 0), Touching);
            check(&Point, p + v(1000, -500), &s, v(1000, -500), Touching);
        }
        let h = Segment::new(v(-10, 0), v(10, 0)).unwrap();
        check(&Point, v(0, 0), &h, v(0, 0), Touching);
        check(&Point, v(-10, 0), &h, v(0, 0), Touching);
    }

    #[test]
    fn point_off_or_beyond_a_segment_is_apart() {
        let s = slanted();
        // Off the line by a unit.
        check(&Point, v(200, 151), &s, v(0, 0), Apart);
        check(&Point, v(199, 150), &s, v(0, 0), Apart);
        // On the line beyond either end: only the direction axis separates.
        check(&Point, v(404, 303), &s, v(0, 0), Apart);
        check(&Point, v(-4, -3), &s, v(0, 0), Apart);
        let h = Segment::new(v(-10, 0), v(10, 0)).unwrap();
        check(&Point, v(11, 0), &h, v(0, 0), Apart);
        check(&Point, v(0, -1), &h, v(0, 0), Apart);
    }

    #[test]
    fn a_point_never_overlaps_a_segment() {
        let s = Segment::new(v(-3, -2), v(4, 5)).unwrap();
        for x in -6..=6 {
            for y in -6..=6 {
                assert!(contact(&Point, v(x, y), &s, v(0, 0)).mtv().is_none());
            }
        }
    }
}
