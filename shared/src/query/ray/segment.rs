//! Ray casts against a segment.

use super::{relative, Ray, RayCast, RayHit};
use crate::fixed::{cross128, dot128, len2, perp, wide};
use crate::shape::Segment;
use glam::{I64Vec2, IVec2};

/// Solves `o + t d = a + s e` by cross products (exact fractions over
/// `cross(d, e)`); the normal is `perp(b - a)` or its opposite, whichever
/// faces the ray origin (against `dir` when the origin lies on the segment).
///
/// A ray along the segment's line (collinear) hits its nearer end, or its
/// origin when that lies on the segment, with normal `-dir`; a parallel ray
/// off the line misses.
impl RayCast for Segment {
    #[inline]
    fn cast_ray(&self, pos: IVec2, ray: &Ray) -> Option<RayHit> {
        let (o, d) = relative(pos, ray);
        let a = wide(self.a());
        let e = wide(self.b()) - a;
        let w = a - o;
        let den = cross128(d, e);
        if den != 0 {
            // t = cross(w, e) / cross(d, e), s = cross(w, d) / cross(d, e).
            let (mut tn, mut sn, mut den) = (cross128(w, e), cross128(w, d), den);
            if den < 0 {
                (tn, sn, den) = (-tn, -sn, -den);
            }
            if tn < 0 || tn > den || sn < 0 || sn > den {
                return None;
            }
            let n = perp(e);
            let side = -dot128(w, n);
            let normal = if side > 0 || (side == 0 && dot128(d, n) < 0) {
                n
            } else {
                -n
            };
            return Some(RayHit::new(ray, tn as u128, den as u128, normal));
        }
        if d == I64Vec2::ZERO {
            // A zero-length ray: is the origin on the segment?
            let t = -dot128(w, e);
            let on = cross128(w, e) == 0 && t >= 0 && t as u128 <= len2(e);
            return on.then(|| RayHit::new(ray, 0, 1, I64Vec2::ZERO));
        }
        if cross128(w, d) != 0 {
            // Parallel, off the line.
            return None;
        }
        // Collinear: the ends at fractions ta / dd and tb / dd.
        let dd = len2(d) as i128;
        let ta = dot128(w, d);
        let tb = dot128(w + e, d);
        let (lo, hi) = (ta.min(tb), ta.max(tb));
        if hi < 0 || lo > dd {
            return None;
        }
        Some(RayHit::new(ray, lo.max(0) as u128, dd as u128, -d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::ray::tests::ray;
    use crate::query::ray::Toi;

    /// From (-10, 0) to (10, 0) placed at (5000, -20): normal perp(e) = (0, -20).
    const POS: IVec2 = IVec2::new(5000, -20);

    fn seg() -> Segment {
        Segment::new(IVec2::new(-10, 0), IVec2::new(10, 0)).unwrap()
    }

    fn hit(ox: i32, oy: i32, dx: i32, dy: i32) -> Option<RayHit> {
        seg().cast_ray(POS, &ray(POS.x + ox, POS.y + oy, dx, dy))
    }

    fn t(num: u64, den: u64) -> Toi {
        Toi::new(num, den).unwrap()
    }

    fn n(x: i64, y: i64) -> I64Vec2 {
        I64Vec2::new(x, y)
    }

    #[test]
    fn crossing_hits_face_the_origin() {
        let h = hit(0, -10, 0, 20).unwrap(); // down from above
        assert_eq!(
            (h.toi, h.normal, h.point() - POS),
            (t(1, 2), n(0, -20), IVec2::new(0, 0))
        );
        let h = hit(3, 8, 0, -16).unwrap(); // up from below
        assert_eq!(
            (h.toi, h.normal, h.point() - POS),
            (t(1, 2), n(0, 20), IVec2::new(3, 0))
        );
        let h = hit(-5, -5, 10, 10).unwrap(); // diagonal
        assert_eq!(
            (h.toi, h.normal, h.point() - POS),
            (t(1, 2), n(0, -20), IVec2::new(0, 0))
        );
        // A fractional hit: y = 0 at t = 3/7, x = 1 + 6/7, rounded towards the origin.
        let h = hit(1, -3, 2, 7).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point() - POS),
            (t(3, 7), n(0, -20), IVec2::new(1, 0))
        );
    }

    #[test]
    fn collinear_rays_hit_the_nearer_end() {
        let h = hit(-20, 0, 40, 0).unwrap(); // moving +x
        assert_eq!(
            (h.toi, h.normal, h.point() - POS),
            (t(1, 4), n(-40, 0), IVec2::new(-10, 0))
        );
        let h = hit(30, 0, -40, 0).unwrap(); // moving -x
        assert_eq!(
            (h.toi, h.normal, h.point() - POS),
            (t(1, 2), n(40, 0), IVec2::new(10, 0))
        );
        let h = hit(0, 0, 5, 0).unwrap(); // starting on it
        assert_eq!(
            (h.toi, h.normal, h.point() - POS),
            (Toi::ZERO, n(-5, 0), IVec2::new(0, 0))
        );
        assert_eq!(hit(-20, 0, 9, 0), None); // stops short
        assert_eq!(hit(-20, 0, -9, 0), None); // points away
        assert_eq!(hit(-20, 1, 40, 0), None); // parallel, one unit below
    }

    #[test]
    fn slanted_segment() {
        // From (0, 0) to (6, 3): e = (6, 3), perp = (3, -6). The ray from
        // (0, 5) along (4, -10) meets it at t = 30/72 = 5/12, (5/3, 5/6),
        // from the +y side: normal (-3, 6); x rounds down, y up.
        let s = Segment::new(IVec2::ZERO, IVec2::new(6, 3)).unwrap();
        let h = s.cast_ray(IVec2::ZERO, &ray(0, 5, 4, -10)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(5, 12), n(-3, 6), IVec2::new(1, 1))
        );
        // The same from the other side, reversed ray: enters from the -y side.
        let h = s.cast_ray(IVec2::ZERO, &ray(4, -5, -4, 10)).unwrap();
        assert_eq!((h.toi, h.normal), (t(7, 12), n(3, -6)));
    }

    #[test]
    fn grazes_misses_and_starts() {
        let h = hit(10, -5, 0, 10).unwrap(); // through the end b
        assert_eq!((h.toi, h.point() - POS), (t(1, 2), IVec2::new(10, 0)));
        let h = hit(-10, 5, 0, -5).unwrap(); // ends exactly on a
        assert_eq!(
            (h.toi, h.normal, h.point() - POS),
            (Toi::ONE, n(0, 20), IVec2::new(-10, 0))
        );
        assert_eq!(hit(11, -5, 0, 10), None); // beyond the end
        assert_eq!(hit(0, -10, 0, 9), None); // stops short
        assert_eq!(hit(0, -10, 0, -9), None); // points away
                                              // Starting on the segment: the normal opposes dir.
        let h = hit(4, 0, 0, 5).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point() - POS),
            (Toi::ZERO, n(0, -20), IVec2::new(4, 0))
        );
        let h = hit(4, 0, 1, -5).unwrap();
        assert_eq!((h.toi, h.normal), (Toi::ZERO, n(0, 20)));
        // Zero-length rays.
        assert_eq!(
            hit(3, 0, 0, 0).map(|h| (h.toi, h.normal)),
            Some((Toi::ZERO, I64Vec2::ZERO))
        );
        assert_eq!(hit(3, 1, 0, 0), None);
        assert_eq!(hit(11, 0, 0, 0), None);
    }
}
