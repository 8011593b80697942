//! Ray casts against a point.

use super::{relative, Ray, RayCast, RayHit};
use crate::fixed::{cross128, dot128, len2};
use crate::shape::Point;
use glam::{I64Vec2, IVec2};

/// A ray hits a point only by passing exactly through it (the point is on
/// the ray's line, between its ends); the toi is exact and the normal is
/// `-dir`. A zero-length ray hits the point it starts on.
impl RayCast for Point {
    #[inline]
    fn cast_ray(&self, pos: IVec2, ray: &Ray) -> Option<RayHit> {
        let (o, d) = relative(pos, ray);
        // The point is at the local origin: w from the ray origin to it.
        let w = -o;
        if d == I64Vec2::ZERO {
            return (w == I64Vec2::ZERO).then(|| RayHit::new(ray, 0, 1, I64Vec2::ZERO));
        }
        if cross128(w, d) != 0 {
            return None;
        }
        let t = dot128(w, d);
        let dd = len2(d);
        if t < 0 || t as u128 > dd {
            return None;
        }
        Some(RayHit::new(ray, t as u128, dd, -d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::ray::tests::ray;
    use crate::query::ray::Toi;

    const P: IVec2 = IVec2::new(-300, 700);

    fn hit(ox: i32, oy: i32, dx: i32, dy: i32) -> Option<RayHit> {
        Point.cast_ray(P, &ray(P.x + ox, P.y + oy, dx, dy))
    }

    #[test]
    fn hits_from_every_direction() {
        for (o, d, toi) in [
            ((-10, 0), (40, 0), (1, 4)),
            ((10, 0), (-20, 0), (1, 2)),
            ((0, -3), (0, 3), (1, 1)),
            ((0, 6), (0, -8), (3, 4)),
            ((-2, -2), (5, 5), (2, 5)),
            ((6, -9), (-8, 12), (3, 4)),
        ] {
            let h = hit(o.0, o.1, d.0, d.1);
            let Some(h) = h else {
                panic!("{o:?} {d:?} missed")
            };
            assert_eq!(h.toi, Toi::new(toi.0, toi.1).unwrap(), "{o:?} {d:?}");
            assert_eq!(h.normal, -I64Vec2::new(d.0 as i64, d.1 as i64));
            assert_eq!(h.point(), P);
        }
    }

    #[test]
    fn misses_near_and_far() {
        assert_eq!(hit(-10, 1, 40, 0), None); // passes one unit below
        assert_eq!(hit(-10, 0, 9, 0), None); // stops short
        assert_eq!(hit(-10, 0, -9, 0), None); // points away
        assert_eq!(hit(-3, -2, 7, 5), None); // (4, 3) passes near (0, 0)
        assert_eq!(hit(1, 0, 0, 0), None);
    }

    #[test]
    fn starting_on_the_point() {
        let h = hit(0, 0, 5, -1).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (Toi::ZERO, I64Vec2::new(-5, 1), P)
        );
        let h = hit(0, 0, 0, 0).unwrap();
        assert_eq!((h.toi, h.normal, h.point()), (Toi::ZERO, I64Vec2::ZERO, P));
    }
}
