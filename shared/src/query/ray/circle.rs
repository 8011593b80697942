//! Ray casts against a circle.

use super::{relative, Ray, RayCast, RayHit};
use crate::fixed::{cmp_mul_u128, cross128, dot128, len2};
use crate::shape::Circle;
use core::cmp::Ordering;
use glam::{I64Vec2, IVec2};

/// Solves `|o + t d|^2 = r^2` (centre at the local origin) for the entry
/// `t = (-b - sqrt(disc)) / a` with `a = |d|^2`, `b = dot(o, d)` and
/// `disc = b^2 - a (|o|^2 - r^2) = r^2 a - cross(o, d)^2` (Lagrange's
/// identity keeps it below 2^117). Whether the ray hits is decided exactly;
/// the square root is rounded up, so the toi is a lower bound short of the
/// exact entry by less than `1 / a` (see the [module documentation](super)).
///
/// The normal is `o + t d` (the lower-bound hit point relative to the
/// centre), exactly, divided by the gcd of its components and scaled down
/// below 2^30 per component, keeping every component's sign.
impl RayCast for Circle {
    #[inline]
    fn cast_ray(&self, pos: IVec2, ray: &Ray) -> Option<RayHit> {
        let (o, d) = relative(pos, ray);
        let r = self.radius() as i64;
        // Bounding boxes first.
        let e = o + d;
        if o.x.max(e.x) < -r || o.x.min(e.x) > r || o.y.max(e.y) < -r || o.y.min(e.y) > r {
            return None;
        }
        let r2 = (r * r) as u128;
        match len2(o).cmp(&r2) {
            Ordering::Less => return Some(RayHit::new(ray, 0, 1, I64Vec2::ZERO)),
            Ordering::Equal => {
                return Some(RayHit::new(ray, 0, 1, reduce(o.x as i128, o.y as i128)))
            }
            Ordering::Greater => {}
        }
        // The origin is outside: the ray must move towards the centre
        // (b < 0, which also rules out d = 0) and either end in the closed
        // disc, or pass its closest point (t* = -b / a <= 1) within r.
        let b = dot128(o, d);
        if b >= 0 {
            return None;
        }
        let a = len2(d);
        let cross = cross128(o, d).unsigned_abs();
        let line_hits = cmp_mul_u128(cross, cross, r2, a) != Ordering::Greater;
        let hits = len2(e) <= r2 || ((-b) as u128 <= a && line_hits);
        if !hits {
            return None;
        }
        let disc = r2 * a - cross * cross;
        let mut s = disc.isqrt();
        if s * s < disc {
            s += 1;
        }
        // Lower bound of the entry, clamped to the ray's start.
        let num = ((-b) as u128).saturating_sub(s);
        debug_assert!(num <= a);
        let (num, den) = if num == 0 { (0, 1) } else { (num, a) };
        // den * (o + t d), the hit point relative to the centre, scaled.
        let (ni, di) = (num as i128, den as i128);
        let n = reduce(
            o.x as i128 * di + d.x as i128 * ni,
            o.y as i128 * di + d.y as i128 * ni,
        );
        Some(RayHit::new(ray, num, den, n))
    }
}

/// `(x, y)` divided by the gcd of its components, then, if still 2^30 or more,
/// divided by a power of two rounding towards zero but never to zero.
#[inline]
fn reduce(x: i128, y: i128) -> I64Vec2 {
    let g = gcd(x.unsigned_abs(), y.unsigned_abs()).max(1) as i128;
    let (x, y) = (x / g, y / g);
    let m = x.unsigned_abs().max(y.unsigned_abs());
    let bits = 128 - m.leading_zeros();
    let shift = bits.saturating_sub(30);
    let down = |c: i128| -> i64 {
        let q = c / (1i128 << shift);
        (if q == 0 { c.signum() } else { q }) as i64
    };
    I64Vec2::new(down(x), down(y))
}

/// Greatest common divisor (binary); `gcd(0, 0) = 0`.
#[inline]
fn gcd(mut a: u128, mut b: u128) -> u128 {
    if a == 0 || b == 0 {
        return a | b;
    }
    let shift = (a | b).trailing_zeros();
    a >>= a.trailing_zeros();
    loop {
        b >>= b.trailing_zeros();
        if a > b {
            core::mem::swap(&mut a, &mut b);
        }
        b -= a;
        if b == 0 {
            return a << shift;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::ray::tests::ray;
    use crate::query::ray::Toi;

    /// Radius 10 centred at (100, 100).
    fn hit(r: Ray) -> Option<RayHit> {
        Circle::new(10).unwrap().cast_ray(IVec2::new(100, 100), &r)
    }

    fn t(num: u64, den: u64) -> Toi {
        Toi::new(num, den).unwrap()
    }

    fn n(x: i64, y: i64) -> I64Vec2 {
        I64Vec2::new(x, y)
    }

    #[test]
    fn axis_rays_are_exact() {
        for (r, p, nn) in [
            (ray(70, 100, 40, 0), (90, 100), n(-1, 0)),
            (ray(130, 100, -40, 0), (110, 100), n(1, 0)),
            (ray(100, 70, 0, 40), (100, 90), n(0, -1)),
            (ray(100, 130, 0, -40), (100, 110), n(0, 1)),
        ] {
            let h = hit(r).unwrap();
            assert_eq!(
                (h.toi, h.normal, h.point(), h.distance()),
                (t(1, 2), nn, IVec2::new(p.0, p.1), 20),
                "{r:?}"
            );
        }
    }

    #[test]
    fn pythagorean_hit_is_exact() {
        // Radius 5 at the origin, down at x = 3: enters at (3, -4), t = 3/10.
        let h = Circle::new(5)
            .unwrap()
            .cast_ray(IVec2::ZERO, &ray(3, -10, 0, 20))
            .unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point(), h.distance()),
            (t(3, 10), n(3, -4), IVec2::new(3, -4), 6)
        );
    }

    #[test]
    fn diagonal_is_a_close_lower_bound() {
        // Exact entry t = 1 - 10 / (20√2) = 0.646447...; a = 800 and
        // ceil(sqrt(80000)) = 283 give 517/800 = 0.64625.
        let h = hit(ray(80, 80, 20, 20)).unwrap();
        assert_eq!((h.toi, h.normal), (t(517, 800), n(-1, -1)));
        // (92.925, 92.925) rounded away from the centre.
        assert_eq!(h.point(), IVec2::new(92, 92));
        assert_eq!(h.distance(), 18); // 0.64625 * 28.28 = 18.28
    }

    #[test]
    fn grazes_and_misses() {
        // Tangent at (90, 100).
        let h = hit(ray(90, 80, 0, 40)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(1, 2), n(-1, 0), IVec2::new(90, 100))
        );
        assert_eq!(hit(ray(89, 80, 0, 40)), None); // one unit outside
        assert!(hit(ray(91, 80, 0, 40)).is_some());
        // Ending exactly on the circle.
        let h = hit(ray(70, 100, 20, 0)).unwrap();
        assert_eq!((h.toi, h.point()), (Toi::ONE, IVec2::new(90, 100)));
        assert_eq!(hit(ray(70, 100, 19, 0)), None); // stops short
        assert_eq!(hit(ray(70, 100, -10, 0)), None); // points away
        assert_eq!(hit(ray(70, 100, 0, 0)), None); // zero length, outside
                                                   // Passes the closest point beyond the disc's corner region.
        assert_eq!(hit(ray(80, 80, 4, 4)), None);
        assert_eq!(hit(ray(93, 80, 20, 14)), None); // (93..113, 80..94): outside near (107, 93)
    }

    #[test]
    fn starting_inside_or_on_the_circle() {
        assert!(hit(ray(105, 95, 100, 0)).unwrap().started_inside());
        assert!(hit(ray(100, 100, 0, 0)).unwrap().started_inside());
        let h = hit(ray(110, 100, 5, 0)).unwrap(); // on the surface, leaving
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (Toi::ZERO, n(1, 0), IVec2::new(110, 100))
        );
        let h = hit(ray(106, 108, -1, -1)).unwrap(); // on the surface, entering
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (Toi::ZERO, n(3, 4), IVec2::new(106, 108))
        );
    }

    #[test]
    fn reduce_keeps_signs() {
        assert_eq!(reduce(0, 0), n(0, 0));
        assert_eq!(reduce(-16000, 0), n(-1, 0));
        assert_eq!(reduce(1200, -1600), n(3, -4));
        assert_eq!(reduce(1 << 100, -1), n(1 << 29, -1));
        assert_eq!(reduce(-(1 << 90) - 1, 7 << 60), n(-(1 << 29), 3));
    }
}
