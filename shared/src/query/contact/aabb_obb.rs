//! Contact between an axis-aligned box and an oriented box.

use crate::shape::{Aabb, Obb};

super::sat_contact!(Aabb, Obb);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::{contact, Proximity::*};
    use crate::shape::{Aabb, Obb};

    fn b() -> Aabb {
        Aabb::new(v(50, 50)).unwrap()
    }

    /// u = (30, 40), v = (-20, 15): x extent 50, y extent 55; n1 = (40, -30)
    /// faces at +-1250 (25 units).
    fn obb() -> Obb {
        let o = Obb::new(v(50, 25), v(3, 4)).unwrap();
        assert_eq!((o.u(), o.v()), (v(30, 40), v(-20, 15)));
        o
    }

    #[test]
    fn touching_and_apart() {
        // The box's corner (50, -50) on the n1 face.
        check(&b(), v(0, 0), &obb(), v(70, -65), Touching);
        check(&b(), v(0, 0), &obb(), v(71, -65), Apart);
        check(&b(), v(0, 0), &obb(), v(100, 0), Touching);
        check(&b(), v(0, 0), &obb(), v(101, 0), Apart);
    }

    #[test]
    fn overlapping() {
        // The box's leftmost corner 5 inside the box's right side.
        check(&b(), v(0, 0), &obb(), v(95, 0), Overlapping(v(-5, 0)));
        // Box corner 5 units past the n1 face: back along -n1, (-4, 3).
        check(&b(), v(0, 0), &obb(), v(60, -70), Overlapping(v(-4, 3)));
        // 5.6 units: (-4.48, 3.36) -> (-5, 4).
        check(&b(), v(0, 0), &obb(), v(60, -69), Overlapping(v(-5, 4)));
        check(&obb(), v(60, -69), &b(), v(0, 0), Overlapping(v(5, -4)));
    }

    #[test]
    fn axis_aligned_oriented_box_is_a_box() {
        let o = Obb::new(v(20, 30), v(9, 0)).unwrap();
        let a = Aabb::new(v(20, 30)).unwrap();
        for x in -75..=75 {
            for y in (-85..=85).step_by(5) {
                let p = v(x, y);
                assert_eq!(
                    contact(&b(), v(0, 0), &o, p),
                    contact(&b(), v(0, 0), &a, p),
                    "at {p}"
                );
            }
        }
    }
}
