//! The numeric model: fixed-point subpixel integers and the exact helpers the
//! collision code needs.
//!
//! Every position, size and velocity is an `i32` count of *units*;
//! [`UNITS_PER_PX`] units make one pixel. The bounds below are chosen so that
//! every derived quantity fits its integer type with no overflow check at run
//! time:
//!
//! * a body position lies in `[-MAX_COORD, MAX_COORD]` (about ±6.29 million px);
//! * every point of a shape lies within [`MAX_EXTENT`] of its collider origin,
//!   and a collider's offset from its body is at most [`MAX_EXTENT`] per axis;
//! * a velocity component is at most [`MAX_SPEED`] units per tick.
//!
//! So a world-space AABB edge is at most `MAX_COORD + 2 * MAX_EXTENT` and a
//! position after one move at most `MAX_COORD + MAX_SPEED`, both below
//! `i32::MAX`. Narrow-phase code works in `i64` coordinates relative to one
//! shape: relative coordinates stay below 2^32, products of two below 2^64
//! (computed in `i64`/`i128`), and the few comparisons of products of four
//! use [`cmp_mul_u128`], which is exact for any `u128` inputs.
//!
//! Scenes and levels are checked against these bounds when they are built
//! ([`check_coord`], [`check_extent`], [`check_speed`]).

use core::cmp::Ordering;
use glam::{I64Vec2, IVec2};
use thiserror::Error;

/// Units in one pixel: positions have 1/256 px precision everywhere.
pub const UNITS_PER_PX: i32 = 256;
/// Largest absolute body coordinate, in units (6,291,456 px).
pub const MAX_COORD: i32 = 3 << 29;
/// Largest distance of a shape point from its collider origin, and largest
/// collider offset, per axis, in units (524,288 px).
pub const MAX_EXTENT: i32 = 1 << 27;
/// Largest absolute velocity component, in units per tick (262,144 px/tick).
pub const MAX_SPEED: i32 = 1 << 26;

// The headroom argument in the module docs, checked by the compiler.
const _: () =
    assert!((MAX_COORD as i64) + 2 * (MAX_EXTENT as i64) + (MAX_SPEED as i64) < i32::MAX as i64);

/// Whole pixels to units.
#[inline]
pub const fn px(p: i32) -> i32 {
    p * UNITS_PER_PX
}

/// A value outside the documented numeric bounds.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum BoundsError {
    /// A coordinate beyond [`MAX_COORD`].
    #[error("{what} = {value} units is outside the world bound of ±{MAX_COORD} units")]
    Coord {
        /// Which value (for example "body position x").
        what: &'static str,
        /// The offending value.
        value: i64,
    },
    /// A shape extent or offset beyond [`MAX_EXTENT`].
    #[error("{what} = {value} units exceeds the largest shape extent of {MAX_EXTENT} units")]
    Extent {
        /// Which value.
        what: &'static str,
        /// The offending value.
        value: i64,
    },
    /// A velocity component beyond [`MAX_SPEED`].
    #[error("{what} = {value} units/tick exceeds the largest speed of {MAX_SPEED} units/tick")]
    Speed {
        /// Which value.
        what: &'static str,
        /// The offending value.
        value: i64,
    },
}

/// Checks a body coordinate against [`MAX_COORD`].
pub fn check_coord(what: &'static str, value: i64) -> Result<(), BoundsError> {
    if value.abs() <= MAX_COORD as i64 {
        Ok(())
    } else {
        Err(BoundsError::Coord { what, value })
    }
}

/// Checks a shape extent or collider offset against [`MAX_EXTENT`].
pub fn check_extent(what: &'static str, value: i64) -> Result<(), BoundsError> {
    if value.abs() <= MAX_EXTENT as i64 {
        Ok(())
    } else {
        Err(BoundsError::Extent { what, value })
    }
}

/// Checks a velocity component against [`MAX_SPEED`].
pub fn check_speed(what: &'static str, value: i64) -> Result<(), BoundsError> {
    if value.abs() <= MAX_SPEED as i64 {
        Ok(())
    } else {
        Err(BoundsError::Speed { what, value })
    }
}

/// Widens a vector for relative-coordinate arithmetic.
#[inline]
pub fn wide(v: IVec2) -> I64Vec2 {
    I64Vec2::new(v.x as i64, v.y as i64)
}

/// Right-hand perpendicular `(y, -x)`: for an edge of a positively wound
/// polygon (see [`crate::shape::ConvexPolygon`]) it points outwards.
#[inline]
pub fn perp(v: I64Vec2) -> I64Vec2 {
    I64Vec2::new(v.y, -v.x)
}

/// Dot product in `i64` (callers keep inputs below 2^31 per component).
#[inline]
pub fn dot(a: I64Vec2, b: I64Vec2) -> i64 {
    a.x * b.x + a.y * b.y
}

/// Dot product in `i128`, for inputs up to 2^62 per component.
#[inline]
pub fn dot128(a: I64Vec2, b: I64Vec2) -> i128 {
    a.x as i128 * b.x as i128 + a.y as i128 * b.y as i128
}

/// 2D cross product `a.x * b.y - a.y * b.x` in `i128`.
#[inline]
pub fn cross128(a: I64Vec2, b: I64Vec2) -> i128 {
    a.x as i128 * b.y as i128 - a.y as i128 * b.x as i128
}

/// Squared length in `u128`.
#[inline]
pub fn len2(v: I64Vec2) -> u128 {
    (v.x as i128 * v.x as i128 + v.y as i128 * v.y as i128) as u128
}

/// `num / den` rounded away from zero; `den > 0`.
///
/// This is the rounding rule of every MTV component: the exact value rounded
/// away from zero, so applying the MTV always moves at least as far as the
/// exact answer (never leaves an overlap) and at most one unit further per
/// axis.
#[inline]
pub fn div_away(num: i128, den: i128) -> i128 {
    debug_assert!(den > 0);
    let q = num / den;
    if num % den != 0 {
        q + num.signum()
    } else {
        q
    }
}

/// Floor of the square root of `v`.
#[inline]
pub fn isqrt(v: u128) -> u128 {
    v.isqrt()
}

/// Full 256-bit product of two `u128` as `(high, low)`.
#[inline]
fn mul_wide(a: u128, b: u128) -> (u128, u128) {
    const MASK: u128 = u64::MAX as u128;
    let (a_hi, a_lo) = (a >> 64, a & MASK);
    let (b_hi, b_lo) = (b >> 64, b & MASK);
    let ll = a_lo * b_lo;
    let lh = a_lo * b_hi;
    let hl = a_hi * b_lo;
    let hh = a_hi * b_hi;
    let mid = (ll >> 64) + (lh & MASK) + (hl & MASK);
    let lo = (ll & MASK) | (mid << 64);
    let hi = hh + (lh >> 64) + (hl >> 64) + (mid >> 64);
    (hi, lo)
}

/// Compares `a * b` with `c * d` exactly, whatever their size.
///
/// SAT compares depths `o / |n|` along axes of different lengths by comparing
/// `o_1^2 * |n_2|^2` with `o_2^2 * |n_1|^2`; those products need up to ~190
/// bits.
#[inline]
pub fn cmp_mul_u128(a: u128, b: u128, c: u128, d: u128) -> Ordering {
    // Most products fit 128 bits (small shapes, shallow overlaps).
    if let (Some(x), Some(y)) = (a.checked_mul(b), c.checked_mul(d)) {
        return x.cmp(&y);
    }
    mul_wide(a, b).cmp(&mul_wide(c, d))
}

/// Orders undirected lines through the origin by angle in `[0, pi)`, exactly.
///
/// Used to break ties between SAT axes of equal depth the same way whichever
/// shape comes first in a query, so that `mtv(a, b) == -mtv(b, a)`.
pub fn line_order(a: I64Vec2, b: I64Vec2) -> Ordering {
    fn canon(v: I64Vec2) -> I64Vec2 {
        if v.y < 0 || (v.y == 0 && v.x < 0) {
            -v
        } else {
            v
        }
    }
    let (a, b) = (canon(a), canon(b));
    // Both in the upper half plane (angle in [0, pi)): a comes first when b is
    // counter-clockwise of a, i.e. cross(a, b) > 0.
    0.cmp(&cross128(a, b))
}

/// Orders directions by clockwise (on screen, y down) angle from up
/// (`-y`), exactly: up first, then right, down, left.
///
/// Breaks ties between equally good push directions where only one argument
/// order exists (a circle centred inside a polygon), preferring the push
/// closest to up, as the degenerate cases do.
pub fn dir_order(a: I64Vec2, b: I64Vec2) -> Ordering {
    // Half 0: angles [0, pi) from up, i.e. x > 0, or straight up.
    fn half(v: I64Vec2) -> u8 {
        if v.x > 0 || (v.x == 0 && v.y < 0) {
            0
        } else {
            1
        }
    }
    half(a).cmp(&half(b)).then_with(|| 0.cmp(&cross128(a, b)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn div_away_rounds_away_from_zero() {
        assert_eq!(div_away(7, 2), 4);
        assert_eq!(div_away(-7, 2), -4);
        assert_eq!(div_away(6, 2), 3);
        assert_eq!(div_away(-6, 3), -2);
        assert_eq!(div_away(0, 5), 0);
        assert_eq!(div_away(1, 1000), 1);
    }

    #[test]
    fn line_order_sorts_by_angle() {
        let x = I64Vec2::new(1, 0);
        let diag = I64Vec2::new(1, 1);
        let y = I64Vec2::new(0, 1);
        assert_eq!(line_order(x, diag), Ordering::Less);
        assert_eq!(line_order(diag, y), Ordering::Less);
        assert_eq!(line_order(-diag, diag), Ordering::Equal);
        assert_eq!(line_order(y, -x), Ordering::Greater);
    }

    #[test]
    fn dir_order_starts_up_and_turns_clockwise() {
        let up = I64Vec2::new(0, -1);
        let up_right = I64Vec2::new(1, -1);
        let right = I64Vec2::new(1, 0);
        let down = I64Vec2::new(0, 1);
        let left = I64Vec2::new(-1, 0);
        let up_left = I64Vec2::new(-1, -1);
        let seq = [up, up_right, right, down, left, up_left];
        for i in 0..seq.len() {
            for j in 0..seq.len() {
                assert_eq!(dir_order(seq[i], seq[j]), i.cmp(&j), "{i} vs {j}");
            }
        }
        assert_eq!(dir_order(up * 5, up), Ordering::Equal);
    }

    proptest! {
        #[test]
        fn mul_wide_matches_u128_when_it_fits(a in any::<u64>(), b in any::<u64>()) {
            let (hi, lo) = mul_wide(a as u128, b as u128);
            prop_assert_eq!(hi, 0);
            prop_assert_eq!(lo, a as u128 * b as u128);
        }

        #[test]
        fn cmp_mul_is_exact(a in any::<u128>(), b in any::<u128>(), k in 1u128..1000) {
            // (a*k) * b == a * (b*k) exactly, and adding one to a factor
            // makes it strictly larger when the other factor is non-zero.
            let a = a >> 12; let b = b >> 12;
            prop_assert_eq!(cmp_mul_u128(a * k, b, a, b * k), Ordering::Equal);
            // The fast and the wide path agree.
            prop_assert_eq!(cmp_mul_u128(a, b, b, a), mul_wide(a, b).cmp(&mul_wide(b, a)));
            prop_assert_eq!(cmp_mul_u128(a, b, a >> 1, b), mul_wide(a, b).cmp(&mul_wide(a >> 1, b)));
            if b > 0 {
                prop_assert_eq!(cmp_mul_u128(a, b, a + 1, b), Ordering::Less);
            }
        }

        #[test]
        fn isqrt_is_floor(v in any::<u64>()) {
            let r = isqrt(v as u128);
            prop_assert!(r * r <= v as u128);
            prop_assert!((r + 1) * (r + 1) > v as u128);
        }
    }
}
