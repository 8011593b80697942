//! Contact between a point and an axis-aligned box.

use crate::shape::{Aabb, Point};

super::sat_contact!(Point, Aabb);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{Aabb, Point};

    fn b() -> Aabb {
        Aabb::new(v(100, 50)).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        let b = b();
        for p in [v(100, 0), v(100, 50), v(-100, -50), v(0, -50), v(-37, 50)] {
            check(&Point, p, &b, v(0, 0), Touching);
        }
        for p in [v(101, 0), v(0, 51), v(101, 51), v(-100, -51)] {
            check(&Point, p, &b, v(0, 0), Apart);
        }
    }

    #[test]
    fn overlapping_pushes_out_through_the_nearest_side() {
        let b = b();
        // x: 30 to the right side, y: 40 to the bottom.
        check(&Point, v(70, 10), &b, v(0, 0), Overlapping(v(30, 0)));
        // x: 5 to the left side, y: 2 to the bottom.
        check(&Point, v(-95, 48), &b, v(0, 0), Overlapping(v(0, 2)));
        check(
            &Point,
            v(-95, 48) + v(-3000, 77),
            &b,
            v(-3000, 77),
            Overlapping(v(0, 2)),
        );
    }

    #[test]
    fn centred_point_goes_up_or_left() {
        // Centred: the shallower axis is y (50 < 100), pushed up.
        check(&Point, v(0, 0), &b(), v(0, 0), Overlapping(v(0, -50)));
        // A square: x and y tie, the x axis wins (smallest angle), pushed left.
        let sq = Aabb::new(v(50, 50)).unwrap();
        check(&Point, v(9, 9), &sq, v(9, 9), Overlapping(v(-50, 0)));
    }
}
