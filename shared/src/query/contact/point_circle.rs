//! Contact between a point and a circle.

use crate::shape::Point;

// The circle kernel implements circle-against-point; this pair is its reverse.
super::circle_contact!(Point);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{Circle, Point};

    fn c100() -> Circle {
        Circle::new(100).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        let c = c100();
        for p in [v(100, 0), v(0, -100), v(60, 80), v(-80, 60)] {
            check(&Point, p, &c, v(0, 0), Touching);
        }
        // 61^2 + 80^2 = 10121 > 100^2.
        check(&Point, v(61, 80), &c, v(0, 0), Apart);
        check(&Point, v(0, -101), &c, v(0, 0), Apart);
        check(&Point, v(71, 71), &c, v(0, 0), Apart);
        check(&Point, v(1, 1), &Circle::new(1).unwrap(), v(0, 0), Apart);
        check(&Point, v(1, 0), &Circle::new(1).unwrap(), v(0, 0), Touching);
    }

    #[test]
    fn overlapping_pushes_the_point_out_radially() {
        let c = c100();
        // Distance 50 along 3-4-5: exactly 50 more.
        check(&Point, v(30, 40), &c, v(0, 0), Overlapping(v(30, 40)));
        check(
            &Point,
            v(-30, 40) + v(7, -9),
            &c,
            v(7, -9),
            Overlapping(v(-30, 40)),
        );
        // 45 degrees: the circle moves by (-60.71, -60.71), rounded away to
        // 61; then the point is at distance sqrt(71^2 * 2) > 100.
        check(&Point, v(10, 10), &c, v(0, 0), Overlapping(v(61, 61)));
        check(&c, v(0, 0), &Point, v(10, 10), Overlapping(v(-61, -61)));
    }

    #[test]
    fn point_at_the_centre_overlaps_and_the_circle_goes_up() {
        // Coincident centres give no direction: the circle moves up, so the
        // point moves down.
        let c = c100();
        check(&c, v(3, 4), &Point, v(3, 4), Overlapping(v(0, -100)));
        check(&Point, v(3, 4), &c, v(3, 4), Overlapping(v(0, 100)));
        check(
            &Circle::new(1).unwrap(),
            v(0, 0),
            &Point,
            v(0, 0),
            Overlapping(v(0, -1)),
        );
    }
}
