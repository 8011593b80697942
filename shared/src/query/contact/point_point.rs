//! Contact between a point and a point.

use super::{Contact, Proximity};
use crate::shape::Point;
use glam::IVec2;

/// Two points have no area: they touch when equal and are apart otherwise.
impl Contact<Point> for Point {
    #[inline]
    fn contact(&self, pos: IVec2, _other: &Point, other_pos: IVec2) -> Proximity {
        if pos == other_pos {
            Proximity::Touching
        } else {
            Proximity::Apart
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::fixed::MAX_COORD;
    use crate::query::contact::{
        contact, Contact,
        Proximity::{self, *},
    };
    use crate::shape::Point;
    use glam::IVec2;

    fn v(x: i32, y: i32) -> IVec2 {
        IVec2::new(x, y)
    }

    /// Far from the origin, near the world bounds.
    const FAR: IVec2 = IVec2::new(MAX_COORD - (1 << 20), -(MAX_COORD - (1 << 21)));

    /// `a` against `b` is `want`, the reverse order is `want` reversed, and
    /// both hold anywhere in the world.
    fn check<A: Contact<B>, B: Contact<A>>(a: &A, pa: IVec2, b: &B, pb: IVec2, want: Proximity) {
        for t in [IVec2::ZERO, FAR, -FAR] {
            assert_eq!(
                contact(a, pa + t, b, pb + t),
                want,
                "a at {pa}, b at {pb}, shifted by {t}"
            );
            assert_eq!(
                contact(b, pb + t, a, pa + t),
                want.reversed(),
                "reverse: a at {pa}, b at {pb}, shifted by {t}"
            );
        }
    }

    #[test]
    fn equal_points_touch_and_never_overlap() {
        check(&Point, v(5, 5), &Point, v(5, 5), Touching);
        check(&Point, v(-7, 3), &Point, v(-7, 3), Touching);
        for d in [v(1, 0), v(0, 1), v(-1, -1), v(300, -2)] {
            check(&Point, v(5, 5), &Point, v(5, 5) + d, Apart);
        }
    }
}
