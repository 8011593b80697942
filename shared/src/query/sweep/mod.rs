//! Swept collision: the exact time of impact of a shape moving in a straight
//! line for one tick against a static shape or the tilemap.
//!
//! A moving shape `A` at `start` moved by the displacement `d` (units, one
//! tick) against a static shape `B` at `pos_b`: [`Sweep::sweep`] answers the
//! first time of impact as an exact fraction [`Toi`] of `d` (the ray module's
//! type), the surface normal there, and the position where `A` stops
//! ([`SweepHit::stop`], also [`advance`]). The tilemap has its own entry point,
//! [`sweep_tiles`], with the tile rules (edge culling, one-way tiles, slopes).
//!
//! # Method
//! Everything is a ray against the *configuration obstacle* `K`, the set of
//! positions of `A` (relative to `B`) at which the two shapes meet:
//!
//! * polygon-like pairs (point, segment, box, oriented box, polygon, in any
//!   combination): `K = B (+) (-A)`, the Minkowski sum, a convex polygon with
//!   integer vertices (`poly.rs`: built by merging edge angles, then a
//!   Cyrus–Beck clip with exact rational fractions);
//! * pairs with a circle: `K` is the other shape inflated by the radius
//!   (offset edges and vertex discs; a circle against a circle is a disc of
//!   the summed radius), and a polygon-like shape moving against a static
//!   circle is that circle moving by `-d` against it (`round.rs`);
//! * the tilemap (moving boxes, the only colliders the world tests against
//!   tiles): an integer DDA along the swept box visits tiles in the order
//!   the box reaches them and stops at the first hit (`tilemap.rs`). Tiles
//!   follow the tilemap's contact rules rather than the overlap rule below:
//!   a tile stops the box where those rules would first push it back
//!   against its motion (see [`sweep_tiles`]).
//!
//! Each pair is its own monomorphised instance of a generic kernel, like the
//! contact module: no trait object or `match` on kinds in the hot path.
//!
//! # What counts as a hit
//! A hit is the first instant at which the motion would make the shapes
//! *overlap* in the sense of the contact query
//! ([`Proximity::Overlapping`](crate::query::contact::Proximity)): the
//! reported time is the last moment before interiors meet (the moment of
//! touching). So, unlike a ray cast:
//!
//! * sliding along a surface, moving away from it, grazing a corner or
//!   ending exactly on a surface are **not** hits: a box resting on a floor
//!   can move sideways;
//! * starting on a surface and moving into it is a hit at toi 0, with that
//!   surface's normal;
//! * starting overlapping is a hit at toi 0 with a **zero normal**
//!   ([`SweepHit::started_inside`]) and `stop == start`: the sweep cannot say
//!   where to go; the discrete contact pass resolves overlaps. (A convex
//!   obstacle that is started inside cannot be hit later in the same move.)
//! * **Thin pairs.** Point against point, point against segment and a
//!   segment against a parallel segment never overlap (their obstacle `K`
//!   has no area), so they use the crossing rule of a ray: a hit is the
//!   first crossing of `K` at a time `0 < toi <= 1` across its line (passing
//!   exactly through it, for a point); motion along the line is not a hit,
//!   and neither is leaving from a start exactly on `K`. The stop position is
//!   then moved strictly to the side the motion came from (one unit along
//!   the normal's larger axis when rounding lands exactly on `K`'s line), so
//!   a stopped shape is never left on a thin obstacle that the next move
//!   could leave in any direction: it cannot tunnel through it over two
//!   ticks.
//!
//! # Normals
//! Integer, reduced to the smallest vector in their direction (gcd 1; circle
//! normals are also scaled below 2^30 per component, keeping signs), pointing
//! out of the obstacle towards the moving shape (the direction that pushes
//! the mover away). Box faces give unit axes; tiles give the direction the
//! contact rules push (a slope pushes straight up). When the motion enters through
//! a corner of `K` (two faces at the same time), the face met most head-on
//! wins (largest `-dot(n, d) / |n|`), then the one facing most upwards, then
//! the first in vertex order.
//!
//! # Rounding rules
//! * **Toi** is exact for every polygon-like pair and every tile hit. With a
//!   circle the exact time is irrational; the reported toi is a rational
//!   **lower bound**, never later than the true one: short by less than
//!   `1 / |d|^2` (less than `1 / |d|` units along the path) on a vertex disc,
//!   the ray module's rule; on an offset edge `r |e|` is computed to
//!   `2^-p` with `p` as large as `i128` allows and rounded up, so the toi is
//!   short by less than 2^-29 units measured along the normal. A toi whose
//!   parts do not fit the [`Toi`] type's `u64` is rounded down.
//! * **Stop position** ([`SweepHit::stop`], [`advance`]): `start + d * toi`
//!   with each component rounded to the outer side of the surface hit, the
//!   ray module's [`RayHit::point`](crate::query::ray::RayHit::point) rule:
//!   towards the sign of the normal's component, towards the start where
//!   that component is zero. On axis-aligned surfaces (boxes, tiles) this is
//!   rounding towards the start. On a slanted face it keeps the point on the
//!   outer side of the face's supporting line, hence out of the convex `K`.
//!   Circle hits are verified with the exact contact query, and in the rare
//!   case the rounded position still overlaps (a lower-bound point near the
//!   join of an offset edge and a vertex disc) another corner of the same
//!   unit cell is taken, the one on the outer side of the true surface: one
//!   always exists. So the stop position is within one unit per axis of
//!   `start + d * toi` (thin pairs: two units along the normal's larger axis),
//!   lies in the bounding box of the path, and **never overlaps** the
//!   obstacle (the contact query reports `Touching` or `Apart`) unless the
//!   shape started inside it.
//!
//! # Input bounds
//! Shapes within [`crate::fixed`]'s bounds, `start` and `pos_b` any `i32`
//! positions, `d` up to [`MAX_DISPLACEMENT`] per component (a move across the
//! whole world, `2 * MAX_COORD`, fits), and `start + d` a valid `i32`
//! position. Relative coordinates then stay below 2^33, every product is
//! done in `i128` or compared with [`crate::fixed::cmp_mul_u128`], and the
//! answer depends only on relative positions (translation invariance).

mod poly;
mod round;
mod tilemap;

pub use tilemap::{sweep_shape_tiles, sweep_tiles, TileHit};

use crate::fixed::div_away;
use crate::query::ray::Toi;
use core::cmp::Ordering;
use glam::{I64Vec2, IVec2};

/// Largest absolute displacement component a sweep accepts, in units: 2^32,
/// more than the width of the world (`2 * MAX_COORD`).
pub const MAX_DISPLACEMENT: i64 = 1 << 32;

/// The first impact of a sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SweepHit {
    /// Fraction of the displacement travelled before impact (exact, or a
    /// lower bound for circles; see the [module documentation](self)).
    pub toi: Toi,
    /// Surface normal at the impact, out of the obstacle towards the mover,
    /// reduced (gcd 1); zero when the shape started inside the obstacle.
    pub normal: I64Vec2,
    /// Where the moving shape stops: `start + d * toi` rounded to the outer
    /// side of the surface; never overlapping the obstacle (unless it
    /// started inside, then `start`).
    pub stop: IVec2,
}

impl SweepHit {
    /// Whether the shape started inside the obstacle (toi 0, zero normal):
    /// the sweep has no surface to report and `stop` is the start.
    #[inline]
    pub fn started_inside(&self) -> bool {
        self.toi.is_zero() && self.normal == I64Vec2::ZERO
    }
}

/// Swept collision of `Self`, moving, against a static shape `B`.
pub trait Sweep<B> {
    /// The first impact of `self` moving from `start` by `d` against `other`
    /// placed at `other_pos`, or `None` when the motion never makes them
    /// overlap. See the [module documentation](self).
    fn sweep(&self, start: IVec2, d: I64Vec2, other: &B, other_pos: IVec2) -> Option<SweepHit>;
}

/// Free-function form of [`Sweep::sweep`].
#[inline]
pub fn sweep<A: Sweep<B>, B>(
    a: &A,
    start: IVec2,
    d: I64Vec2,
    b: &B,
    pos_b: IVec2,
) -> Option<SweepHit> {
    a.sweep(start, d, b, pos_b)
}

/// The position a sweep ends at: the hit's stop position, or `start + d`
/// when nothing was hit.
///
/// With several obstacles, sweep against each, keep the hit with the
/// smallest toi (ties: any, they stop at the same time) and advance to it;
/// a hit that [`SweepHit::started_inside`] is usually skipped there and left
/// to the discrete contact pass.
#[inline]
pub fn advance(start: IVec2, d: I64Vec2, hit: Option<&SweepHit>) -> IVec2 {
    match hit {
        Some(h) => h.stop,
        None => end_of(start, d),
    }
}

/// `vel` reflected off a surface of normal `normal`: `v - 2 (v.n / n.n) n`,
/// exact for axis-aligned normals (the component along the normal flips).
///
/// On a slanted normal each component of the change is rounded away from
/// zero, so a velocity going into the surface comes out going away from it
/// (never back into it), faster by less than one unit per axis. A velocity
/// already going away from the surface (or along it), or a zero normal,
/// is returned unchanged. Components saturate at the `i32` range.
#[inline]
pub fn reflect(vel: IVec2, normal: I64Vec2) -> IVec2 {
    remove_normal(vel, normal, 2)
}

/// `vel` with its component into the surface of normal `normal` removed:
/// `v - (v.n / n.n) n`, the motion that slides along the surface; exact for
/// axis-aligned normals (the component along the normal becomes zero).
///
/// On a slanted normal the change is rounded away from zero per component,
/// so the result never points into the surface. A velocity already going
/// away from the surface (or along it), or a zero normal, is returned
/// unchanged.
#[inline]
pub fn slide(vel: IVec2, normal: I64Vec2) -> IVec2 {
    remove_normal(vel, normal, 1)
}

/// `vel - k (v.n / n.n) n` when `v.n < 0`, the change rounded away from zero.
fn remove_normal(vel: IVec2, normal: I64Vec2, k: i128) -> IVec2 {
    let n = primitive(normal);
    let v = vel.as_i64vec2();
    let vn = v.x as i128 * n.x as i128 + v.y as i128 * n.y as i128;
    if vn >= 0 {
        return vel;
    }
    let nn = n.x as i128 * n.x as i128 + n.y as i128 * n.y as i128;
    let c = |vc: i64, nc: i64| -> i32 {
        let out = vc as i128 + div_away(-k * vn * nc as i128, nn);
        out.clamp(i32::MIN as i128, i32::MAX as i128) as i32
    };
    IVec2::new(c(v.x, n.x), c(v.y, n.y))
}

/// `start + d` as a position (it must fit; see the input bounds).
#[inline]
fn end_of(start: IVec2, d: I64Vec2) -> IVec2 {
    check_end(start, d);
    offset(start, d)
}

/// Checks that `start + d` is an `i32` position (debug builds).
#[inline]
fn check_end(start: IVec2, d: I64Vec2) {
    let e = start.as_i64vec2() + d;
    debug_assert!(
        e.x >= i32::MIN as i64
            && e.x <= i32::MAX as i64
            && e.y >= i32::MIN as i64
            && e.y <= i32::MAX as i64,
        "start + d must be an i32 position"
    );
}

/// `start + off` as a position (`off` keeps it within the path's box).
#[inline]
fn offset(start: IVec2, off: I64Vec2) -> IVec2 {
    let p = start.as_i64vec2() + off;
    IVec2::new(p.x as i32, p.y as i32)
}

/// Checks the displacement bound (debug builds).
#[inline]
fn check_d(d: I64Vec2) {
    debug_assert!(
        d.x.abs() <= MAX_DISPLACEMENT && d.y.abs() <= MAX_DISPLACEMENT,
        "displacement {d} beyond MAX_DISPLACEMENT"
    );
}

/// A raw kernel answer: fraction `num / den` of `d` (`0 <= num <= den`), and
/// the unreduced normal (zero: started inside).
#[derive(Debug, Clone, Copy)]
struct Entry {
    num: u128,
    den: u128,
    normal: I64Vec2,
}

impl Entry {
    /// Started inside: toi 0, no normal.
    const INSIDE: Entry = Entry {
        num: 0,
        den: 1,
        normal: I64Vec2::ZERO,
    };

    /// The toi, rounded down to fit `u64` parts when needed.
    #[inline]
    fn toi(&self) -> Toi {
        toi_floor(self.num, self.den)
    }
}

/// `num / den` as a [`Toi`], rounded down when the parts exceed `u64`
/// (`0 <= num <= den`, `den > 0`).
fn toi_floor(num: u128, den: u128) -> Toi {
    debug_assert!(den > 0 && num <= den);
    if num == 0 {
        return Toi::ZERO;
    }
    if num == den {
        return Toi::ONE;
    }
    let (mut num, mut den) = (num, den);
    if den > u64::MAX as u128 {
        let shift = 128 - den.leading_zeros() - 64;
        // Numerator down, denominator up: a lower bound.
        num >>= shift;
        den = (den >> shift) + u128::from(den & ((1u128 << shift) - 1) != 0);
        if den > u64::MAX as u128 {
            num >>= 1;
            den = (den >> 1) + (den & 1);
        }
    }
    Toi::new(num as u64, den as u64).expect("0 <= toi <= 1")
}

/// `d * toi` with each component rounded towards the sign of the normal's
/// component, towards zero (the start) where it is zero.
fn round_outer(d: I64Vec2, toi: Toi, n: I64Vec2) -> I64Vec2 {
    let (num, den) = (toi.num() as i128, toi.den() as i128);
    let c = |dc: i64, nc: i64| -> i64 {
        let off = dc as i128 * num;
        (match nc.signum() {
            1 => -(-off).div_euclid(den),
            -1 => off.div_euclid(den),
            _ => off / den,
        }) as i64
    };
    I64Vec2::new(c(d.x, n.x), c(d.y, n.y))
}

/// The stop position of a hit whose exactness is not proven (circle pairs):
/// the outer-side rounding by `n` first, then the other corners of the unit
/// cell around `start + d * toi`, the first that `overlaps` rejects not.
/// `start` itself is the last resort (it is outside when the hit is not a
/// started-inside one).
fn verified_stop(
    start: IVec2,
    d: I64Vec2,
    toi: Toi,
    n: I64Vec2,
    overlaps: impl Fn(IVec2) -> bool,
) -> IVec2 {
    let s = start.as_i64vec2();
    let first = s + round_outer(d, toi, n);
    let at = |o: I64Vec2| IVec2::new(o.x as i32, o.y as i32);
    if !overlaps(at(first)) {
        return at(first);
    }
    // Floor and ceiling of each component.
    let lo = s + round_outer(d, toi, I64Vec2::NEG_ONE);
    let hi = s + round_outer(d, toi, I64Vec2::ONE);
    for q in [
        I64Vec2::new(lo.x, lo.y),
        I64Vec2::new(hi.x, lo.y),
        I64Vec2::new(lo.x, hi.y),
        I64Vec2::new(hi.x, hi.y),
    ] {
        if q != first && !overlaps(at(q)) {
            return at(q);
        }
    }
    debug_assert!(false, "no corner of the stop cell is outside");
    start
}

/// `n` divided by the gcd of its components, then scaled down by a power of
/// two below 2^30 per component if still larger, keeping every component's
/// sign (never rounding one to zero).
fn primitive(n: I64Vec2) -> I64Vec2 {
    reduce(n.x as i128, n.y as i128)
}

/// [`primitive`] of an `i128` vector.
fn reduce(x: i128, y: i128) -> I64Vec2 {
    let g = gcd(x.unsigned_abs(), y.unsigned_abs()).max(1) as i128;
    let (x, y) = (x / g, y / g);
    let m = x.unsigned_abs().max(y.unsigned_abs());
    let shift = (128 - m.leading_zeros()).saturating_sub(30);
    let down = |c: i128| -> i64 {
        let q = c / (1i128 << shift);
        (if q == 0 { c.signum() } else { q }) as i64
    };
    I64Vec2::new(down(x), down(y))
}

/// Greatest common divisor; `gcd(0, 0) = 0`.
fn gcd(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// Compares two fractions `a / b` and `c / d` of non-negative parts
/// (`b, d > 0`), exactly.
#[inline]
fn cmp_frac(a: u128, b: u128, c: u128, d: u128) -> Ordering {
    crate::fixed::cmp_mul_u128(a, d, c, b)
}

/// Whether normal `n1` is a better report than `n2` for a motion `d` entering
/// through both at the same time: met more head-on (`-dot(n, d) / |n|`
/// larger; both are positive for entering faces), then facing more upwards
/// (`-n.y / |n|` larger). `false` on a full tie (keep the first).
fn better_normal(n1: I64Vec2, n2: I64Vec2, d: I64Vec2) -> bool {
    use crate::fixed::{cmp_mul_u128, len2};
    let dot = |n: I64Vec2| -(n.x as i128 * d.x as i128 + n.y as i128 * d.y as i128);
    let (k1, k2) = (dot(n1), dot(n2));
    // Both positive: compare k1^2 |n2|^2 with k2^2 |n1|^2.
    let (k1a, k2a) = (k1.unsigned_abs(), k2.unsigned_abs());
    match cmp_mul_u128(k1a * k1a, len2(n2), k2a * k2a, len2(n1)) {
        Ordering::Greater => return true,
        Ordering::Less => return false,
        Ordering::Equal => {}
    }
    // Upwards: compare u1 / |n1| with u2 / |n2|, u = -n.y.
    let (u1, u2) = (-(n1.y as i128), -(n2.y as i128));
    let mag = |u: i128, other: I64Vec2| (u.unsigned_abs() * u.unsigned_abs(), len2(other));
    let (a1, b1) = mag(u1, n2);
    let (a2, b2) = mag(u2, n1);
    let c = cmp_mul_u128(a1, b1, a2, b2);
    match (u1.signum(), u2.signum()) {
        (s1, s2) if s1 > s2 => true,
        (s1, s2) if s1 < s2 => false,
        (1, _) => c == Ordering::Greater,
        (-1, _) => c == Ordering::Less,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: i64, y: i64) -> I64Vec2 {
        I64Vec2::new(x, y)
    }

    #[test]
    fn toi_floor_keeps_a_lower_bound() {
        assert_eq!(toi_floor(3, 6), Toi::new(1, 2).unwrap());
        assert_eq!(toi_floor(0, 1 << 100), Toi::ZERO);
        let big = (1u128 << 65) + 12345;
        let t = toi_floor(big - 7, big);
        assert!(t < Toi::ONE);
        // t <= (big - 7) / big exactly.
        assert_ne!(
            crate::fixed::cmp_mul_u128(t.num() as u128, big, big - 7, t.den() as u128),
            Ordering::Greater
        );
        assert_eq!(toi_floor(big, big), Toi::new(1, 1).unwrap());
        let t = toi_floor(u128::MAX / 3, u128::MAX);
        assert!(t.num() as u128 * 3 <= t.den() as u128);
    }

    #[test]
    fn outer_rounding_follows_the_normal() {
        let d = v(10, -7);
        let t = Toi::new(1, 3).unwrap(); // (3.33, -2.33)
        assert_eq!(round_outer(d, t, v(0, 0)), v(3, -2));
        assert_eq!(round_outer(d, t, v(1, 1)), v(4, -2));
        assert_eq!(round_outer(d, t, v(-1, -1)), v(3, -3));
        assert_eq!(round_outer(d, t, v(0, -5)), v(3, -3));
    }

    #[test]
    fn primitive_normals() {
        assert_eq!(primitive(v(0, -7)), v(0, -1));
        assert_eq!(primitive(v(6, -4)), v(3, -2));
        assert_eq!(primitive(v(0, 0)), v(0, 0));
        assert_eq!(reduce(1 << 100, -1), v(1 << 29, -1));
    }

    #[test]
    fn reflect_and_slide() {
        let up = v(0, -1);
        assert_eq!(reflect(IVec2::new(5, 9), up), IVec2::new(5, -9));
        assert_eq!(reflect(IVec2::new(5, -9), up), IVec2::new(5, -9));
        assert_eq!(slide(IVec2::new(5, 9), up), IVec2::new(5, 0));
        assert_eq!(reflect(IVec2::new(-3, 0), v(7, 0)), IVec2::new(3, 0));
        // 45 degrees: (4, 0) against (-1, -1) reflects to (0, -4).
        assert_eq!(reflect(IVec2::new(4, 0), v(-1, -1)), IVec2::new(0, -4));
        assert_eq!(slide(IVec2::new(4, 0), v(-1, -1)), IVec2::new(2, -2));
        // Rounded away from the surface.
        let s = slide(IVec2::new(5, 0), v(-1, -2));
        assert!(s.as_i64vec2().dot(v(-1, -2)) >= 0, "{s}");
        let r = reflect(IVec2::new(5, 3), v(-1, -2));
        assert!(r.as_i64vec2().dot(v(-1, -2)) > 0, "{r}");
    }

    #[test]
    fn head_on_then_up() {
        let d = v(3, 1);
        assert!(better_normal(v(-1, 0), v(0, -1), d));
        assert!(!better_normal(v(0, -1), v(-1, 0), d));
        let d = v(2, 2);
        assert!(better_normal(v(0, -1), v(-1, 0), d));
        assert!(!better_normal(v(-1, 0), v(0, -1), d));
        let d = v(0, 5);
        assert!(!better_normal(v(-1, -1), v(1, -1), d));
        assert!(!better_normal(v(1, -1), v(-1, -1), d));
    }
}
