//! Contact between a circle and an axis-aligned box.

use crate::shape::Aabb;

super::circle_contact!(Aabb);

#[cfg(test)]
mod tests {
    use crate::query::contact::testing::{check, v};
    use crate::query::contact::Proximity::*;
    use crate::shape::{Aabb, Circle};

    fn b() -> Aabb {
        Aabb::new(v(100, 50)).unwrap()
    }

    fn c(r: i32) -> Circle {
        Circle::new(r).unwrap()
    }

    #[test]
    fn touching_and_apart() {
        check(&c(50), v(0, -100), &b(), v(0, 0), Touching);
        check(&c(50), v(0, -101), &b(), v(0, 0), Apart);
        // Corner (100, 50) at distance |(30, 40)| = 50.
        check(&c(50), v(130, 90), &b(), v(0, 0), Touching);
        check(&c(50), v(131, 90), &b(), v(0, 0), Apart);
    }

    #[test]
    fn overlapping() {
        // 40 above the top side: up 10.
        check(&c(50), v(0, -90), &b(), v(0, 0), Overlapping(v(0, -10)));
        // Corner at 45 degrees, 42.43 away: (5.36, 5.36) -> (6, 6).
        check(&c(50), v(130, 80), &b(), v(0, 0), Overlapping(v(6, 6)));
        check(&b(), v(-9, 4), &c(50), v(121, 84), Overlapping(v(-6, -6)));
        // Centre inside, 10 from the right side: out to 50 beyond it.
        check(&c(50), v(90, 0), &b(), v(0, 0), Overlapping(v(60, 0)));
    }

    #[test]
    fn centred_circle_leaves_through_the_first_nearest_side() {
        // Top and bottom sides tie (50 each): the first edge (top) wins.
        check(&c(50), v(0, 0), &b(), v(0, 0), Overlapping(v(0, -100)));
    }
}
