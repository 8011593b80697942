//! Helpers shared by the unit tests of the shape-pair files.

use super::{contact, Contact, Proximity};
use crate::fixed::MAX_COORD;
use glam::IVec2;

/// Shorthand for a vector.
pub(super) fn v(x: i32, y: i32) -> IVec2 {
    IVec2::new(x, y)
}

/// Far from the origin, near the world bounds.
pub(super) const FAR: IVec2 = IVec2::new(MAX_COORD - (1 << 20), -(MAX_COORD - (1 << 21)));

/// `a` against `b` is `want`, the reverse order is `want` reversed, and
/// both hold anywhere in the world.
pub(super) fn check<A: Contact<B>, B: Contact<A>>(
    a: &A,
    pa: IVec2,
    b: &B,
    pb: IVec2,
    want: Proximity,
) {
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
