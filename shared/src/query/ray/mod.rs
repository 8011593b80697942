//! Ray casts against every shape kind (first hit, distance, normal), in exact
//! integer arithmetic.
//!
//! A [`Ray`] is the closed segment from `origin` to `origin + dir`. Casting it
//! at a placed shape ([`RayCast::cast_ray`]) answers the first point of that
//! segment that lies in the *closed* shape, as a [`RayHit`]: the exact
//! fraction [`Toi`] of `dir` travelled, the outward normal of the surface
//! hit, and (on demand) the hit point and distance in units.
//!
//! One file per shape kind; the polygon-like kinds (box, oriented box,
//! polygon) share the Cyrus–Beck clipping kernel in `clip.rs`, generic over
//! [`crate::shape::Convex`] and monomorphised per kind. All arithmetic is done
//! in coordinates relative to the shape's origin, so results are translation
//! invariant: moving the shape and the ray by the same offset moves the hit
//! point by that offset and changes nothing else.
//!
//! # Input bounds
//! Any `i32` origin and direction are accepted together with shapes that
//! satisfy [`crate::fixed`]'s bounds (every shape point within
//! [`crate::fixed::MAX_EXTENT`] of a shape origin that is itself an `i32`).
//! Relative coordinates then stay below 2^33, direction components below
//! 2^31 (so `dir` spans at most `i32::MAX` units per axis: a ray between two
//! points at opposite ends of the world, up to `2 * MAX_COORD` apart, must be
//! split), and every product is computed in `i128` or compared with
//! [`crate::fixed::cmp_mul_u128`]; nothing can overflow. Nothing is
//! validated here beyond that.
//!
//! # What counts as a hit
//! The ray and the shape are both closed sets, consistently with
//! [`Proximity::Touching`](crate::query::contact::Proximity::Touching): a ray
//! that only grazes a shape (passes exactly through a corner, slides along an
//! edge, is tangent to a circle, ends exactly on the surface) hits it. For
//! every shape, `cast_ray` hits exactly when a [`Segment`](crate::shape::Segment)
//! from `origin` to `origin + dir` is not
//! [`Proximity::Apart`](crate::query::contact::Proximity::Apart) from it.
//!
//! * A ray starting strictly inside a shape with area hits at toi 0 with a
//!   **zero normal** ([`RayHit::started_inside`]).
//! * A ray starting exactly on the surface hits at toi 0 with the normal of
//!   that surface, whether it then enters, slides along or leaves the shape.
//! * A ray through a corner (two edges enter at the same toi) reports the
//!   first of those edges in the shape's vertex order (for a box: top, right,
//!   bottom, left).
//! * A ray along a segment's line (collinear) hits the segment's nearer end,
//!   with normal `-dir`; a ray through a [`Point`](crate::shape::Point) hits it
//!   with normal `-dir`.
//! * A zero-length ray (`dir == 0`) is the point `origin`: it hits when that
//!   point is in the closed shape, at toi 0, with the normal of the surface
//!   it lies on for a shape with area, and a zero normal on a point or
//!   segment (no direction to face).
//!
//! # Normals
//! Integer, not normalised, pointing out of the shape towards the side the
//! ray came from: box `±x`/`±y` unit axes; oriented box and polygon
//! `perp(edge)` of the edge hit (see [`crate::fixed::perp`]); segment its
//! `perp(b - a)` or the opposite, whichever faces the ray origin (against
//! `dir` when the origin lies on the segment); circle the direction from the
//! centre to the hit point, reduced and scaled below 2^30 per component; point and
//! collinear segment `-dir`.
//!
//! # Rounding rules
//! * [`Toi`] is exact for every shape but the circle, whose exact entry is
//!   irrational: there `toi` is a rational **lower bound** (`toi <= exact`),
//!   short of the exact value by less than `1 / |dir|^2`, that is by less than
//!   `1 / |dir|` units (at most one unit) along the ray; for rays of a pixel
//!   or longer that is within 2^-16 of `dir`. Rounding earlier keeps the hit
//!   conservative: the point at `toi` is never inside the circle.
//! * [`RayHit::point`] rounds each component of `origin + dir * toi` to the
//!   *outer side of the surface hit*: up where the normal's component is
//!   positive, down where it is negative, and towards the origin where it is
//!   zero. On box faces, and for every hit at toi 0, this is rounding towards
//!   the origin. On a slanted face plain rounding towards the origin can land
//!   strictly inside the shape (both components move back, one of them across
//!   the face), so there one component may move up to one unit away from the
//!   origin instead. Either way the reported point is within one unit per
//!   axis of the (exact or lower-bound) hit and never strictly inside the
//!   shape, unless the ray started inside (then it is the origin).
//! * [`RayHit::distance`] is `floor(toi * |dir|)` in units, exact.

mod aabb;
mod circle;
mod clip;
mod obb;
mod point;
mod polygon;
mod segment;

use crate::fixed::cmp_mul_u128;
use core::cmp::Ordering;
use glam::{I64Vec2, IVec2};

/// A ray: the closed segment from `origin` to `origin + dir`, in world units.
///
/// See the [module documentation](self) for the bounds on `origin` and `dir`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Ray {
    /// Start point in world units.
    pub origin: IVec2,
    /// Displacement from the start to the end point, in units.
    pub dir: IVec2,
}

impl Ray {
    /// The ray from `origin` along `dir`.
    #[inline]
    pub const fn new(origin: IVec2, dir: IVec2) -> Self {
        Self { origin, dir }
    }

    /// The ray from `from` to `to` (their difference must fit an `i32`).
    #[inline]
    pub fn between(from: IVec2, to: IVec2) -> Self {
        Self {
            origin: from,
            dir: to - from,
        }
    }
}

/// A time of impact: the exact fraction `num / den` of a ray's `dir`, with
/// `den > 0` and `0 <= num <= den`.
///
/// Not reduced: equality and order compare the values exactly by
/// cross-multiplication, so `1/2 == 2/4`.
#[derive(Debug, Clone, Copy)]
pub struct Toi {
    num: u64,
    den: u64,
}

impl Toi {
    /// The start of the ray.
    pub const ZERO: Toi = Toi { num: 0, den: 1 };
    /// The end of the ray.
    pub const ONE: Toi = Toi { num: 1, den: 1 };

    /// `num / den`; `None` unless `den > 0` and `num <= den`.
    #[inline]
    pub const fn new(num: u64, den: u64) -> Option<Self> {
        if den > 0 && num <= den {
            Some(Self { num, den })
        } else {
            None
        }
    }

    /// `num / den` for callers in this module that have already checked the
    /// invariant; a zero numerator is stored as `0 / 1`.
    #[inline]
    fn from_parts(num: u128, den: u128) -> Self {
        debug_assert!(den > 0 && num <= den && den <= u64::MAX as u128);
        if num == 0 {
            Self::ZERO
        } else {
            Self {
                num: num as u64,
                den: den as u64,
            }
        }
    }

    /// Numerator.
    #[inline]
    pub const fn num(self) -> u64 {
        self.num
    }

    /// Denominator (positive).
    #[inline]
    pub const fn den(self) -> u64 {
        self.den
    }

    /// Whether this is the start of the ray.
    #[inline]
    pub const fn is_zero(self) -> bool {
        self.num == 0
    }
}

impl PartialEq for Toi {
    #[inline]
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Toi {}

impl PartialOrd for Toi {
    #[inline]
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Toi {
    #[inline]
    fn cmp(&self, other: &Self) -> Ordering {
        (self.num as u128 * other.den as u128).cmp(&(other.num as u128 * self.den as u128))
    }
}

/// The first hit of a ray on a shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RayHit {
    /// The ray that was cast.
    pub ray: Ray,
    /// Fraction of `ray.dir` travelled before the hit (a lower bound for
    /// circles; see the [module documentation](self)).
    pub toi: Toi,
    /// Outward normal of the surface hit, not normalised; zero when the ray
    /// started strictly inside a shape with area.
    pub normal: I64Vec2,
}

impl RayHit {
    /// Builds a hit; `num / den` must satisfy [`Toi`]'s invariant.
    #[inline]
    fn new(ray: &Ray, num: u128, den: u128, normal: I64Vec2) -> Self {
        Self {
            ray: *ray,
            toi: Toi::from_parts(num, den),
            normal,
        }
    }

    /// Whether the hit has no surface direction (toi 0, zero normal): the ray
    /// started strictly inside a shape with area, or is a zero-length ray
    /// lying on a point or segment.
    #[inline]
    pub fn started_inside(&self) -> bool {
        self.toi.is_zero() && self.normal == I64Vec2::ZERO
    }

    /// The hit point `origin + dir * toi` in world units, each component
    /// rounded to the outer side of the surface hit (towards the sign of the
    /// normal's component, towards the origin where it is zero): never
    /// strictly inside the shape unless the ray started inside. See the
    /// [module documentation](self).
    #[inline]
    pub fn point(&self) -> IVec2 {
        let (num, den) = (self.toi.num as i128, self.toi.den as i128);
        let comp = |o: i32, d: i32, n: i64| -> i32 {
            let off = d as i128 * num;
            let q = match n.signum() {
                1 => div_ceil(off, den),
                -1 => div_floor(off, den),
                _ => off / den,
            };
            (o as i128 + q) as i32
        };
        let (o, d, n) = (self.ray.origin, self.ray.dir, self.normal);
        IVec2::new(comp(o.x, d.x, n.x), comp(o.y, d.y, n.y))
    }

    /// Distance travelled before the hit, `floor(toi * |dir|)` in units
    /// (exact, by integer square root and an exact check).
    #[inline]
    pub fn distance(&self) -> u64 {
        let d = self.ray.dir;
        let l2 = (d.x as i128 * d.x as i128 + d.y as i128 * d.y as i128) as u128;
        let (num, den) = (self.toi.num as u128, self.toi.den as u128);
        // floor(isqrt(l2) * toi) is at most the answer and short of it by
        // less than two (isqrt is short of |dir| by less than one).
        let mut k = l2.isqrt() * num / den;
        // k + 1 <= toi * |dir|  <=>  ((k + 1) den)^2 <= num * (num |dir|^2).
        while cmp_mul_u128((k + 1) * den, (k + 1) * den, num, num * l2) != Ordering::Greater {
            k += 1;
        }
        k as u64
    }
}

/// Ray casting against a shape placed in the world.
pub trait RayCast {
    /// The first hit of `ray` on `self` placed with its origin at `pos`, or
    /// `None` when the ray misses. See the [module documentation](self) for
    /// what counts as a hit and how it is rounded.
    fn cast_ray(&self, pos: IVec2, ray: &Ray) -> Option<RayHit>;
}

/// Free-function form of [`RayCast::cast_ray`].
#[inline]
pub fn cast_ray<S: RayCast>(shape: &S, pos: IVec2, ray: &Ray) -> Option<RayHit> {
    shape.cast_ray(pos, ray)
}

/// The ray's origin and direction relative to a shape at `pos`.
#[inline]
fn relative(pos: IVec2, ray: &Ray) -> (I64Vec2, I64Vec2) {
    let o = I64Vec2::new(
        ray.origin.x as i64 - pos.x as i64,
        ray.origin.y as i64 - pos.y as i64,
    );
    let d = I64Vec2::new(ray.dir.x as i64, ray.dir.y as i64);
    (o, d)
}

/// `a / b` rounded down; `b > 0`.
#[inline]
fn div_floor(a: i128, b: i128) -> i128 {
    a.div_euclid(b)
}

/// `a / b` rounded up; `b > 0`.
#[inline]
fn div_ceil(a: i128, b: i128) -> i128 {
    -(-a).div_euclid(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn ray(ox: i32, oy: i32, dx: i32, dy: i32) -> Ray {
        Ray::new(IVec2::new(ox, oy), IVec2::new(dx, dy))
    }

    #[test]
    fn toi_orders_exactly() {
        let half = Toi::new(1, 2).unwrap();
        assert_eq!(half, Toi::new(2, 4).unwrap());
        assert!(Toi::new(1, 3).unwrap() < half);
        assert!(Toi::new(u64::MAX - 1, u64::MAX).unwrap() < Toi::ONE);
        assert!(Toi::ZERO < Toi::new(1, u64::MAX).unwrap());
        assert_eq!(Toi::new(3, 2), None);
        assert_eq!(Toi::new(0, 0), None);
    }

    #[test]
    fn point_rounds_to_the_outer_side() {
        let r = ray(0, 0, 10, -7);
        let t = Toi::new(1, 3).unwrap(); // (3.33.., -2.33..)
        let at = |n: I64Vec2| {
            RayHit {
                ray: r,
                toi: t,
                normal: n,
            }
            .point()
        };
        assert_eq!(at(I64Vec2::ZERO), IVec2::new(3, -2));
        assert_eq!(at(I64Vec2::new(1, 1)), IVec2::new(4, -2));
        assert_eq!(at(I64Vec2::new(-1, -1)), IVec2::new(3, -3));
        assert_eq!(at(I64Vec2::new(0, -5)), IVec2::new(3, -3));
    }

    #[test]
    fn distance_is_floor_of_length() {
        let hit = |d: IVec2, num, den| RayHit {
            ray: Ray::new(IVec2::ZERO, d),
            toi: Toi::new(num, den).unwrap(),
            normal: I64Vec2::ZERO,
        };
        assert_eq!(hit(IVec2::new(3, 4), 1, 1).distance(), 5);
        assert_eq!(hit(IVec2::new(3, 4), 1, 2).distance(), 2);
        assert_eq!(hit(IVec2::new(3, 4), 3, 5).distance(), 3);
        assert_eq!(hit(IVec2::new(1, 1), 1, 1).distance(), 1);
        assert_eq!(hit(IVec2::new(100, 100), 1, 1).distance(), 141);
        assert_eq!(
            hit(IVec2::new(i32::MIN, i32::MIN), 1, 1).distance(),
            3_037_000_499
        );
        assert_eq!(
            hit(IVec2::new(i32::MAX, 0), u64::MAX - 1, u64::MAX).distance(),
            i32::MAX as u64 - 1
        );
        assert_eq!(hit(IVec2::new(7, 0), 0, 1).distance(), 0);
    }
}
