//! Ray casts against an oriented box.

use super::{clip, Ray, RayCast, RayHit};
use crate::shape::Obb;
use glam::IVec2;

/// Cyrus–Beck over the box's four edges; the normal is `perp(edge)` of the
/// edge hit (`perp(2u)` or `perp(2v)`, up to sign).
impl RayCast for Obb {
    #[inline]
    fn cast_ray(&self, pos: IVec2, ray: &Ray) -> Option<RayHit> {
        clip::cast(self, pos, ray, |n| n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::ray::tests::ray;
    use crate::query::ray::Toi;
    use glam::I64Vec2;

    /// A diamond centred at the origin: corners (±10, 0), (0, ±10).
    /// Half axes u = (5, -5), v = (5, 5); edges 2u, 2v, -2u, -2v.
    fn diamond() -> Obb {
        Obb::from_axes(IVec2::new(5, -5), IVec2::new(5, 5)).unwrap()
    }

    fn hit(r: Ray) -> Option<RayHit> {
        diamond().cast_ray(IVec2::ZERO, &r)
    }

    fn t(num: u64, den: u64) -> Toi {
        Toi::new(num, den).unwrap()
    }

    #[test]
    fn axis_rays_hit_the_corners() {
        // Along each axis the first point is a corner: the two edges meeting
        // there tie and the first in vertex order is reported.
        for (o, d, p) in [
            ((-20, 0), (40, 0), (-10, 0)),
            ((20, 0), (-40, 0), (10, 0)),
            ((0, -20), (0, 40), (0, -10)),
            ((0, 20), (0, -40), (0, 10)),
        ] {
            let h = hit(ray(o.0, o.1, d.0, d.1)).unwrap();
            assert_eq!((h.toi, h.point()), (t(1, 4), IVec2::new(p.0, p.1)), "{o:?}");
            // The normal is one of the two faces meeting at the corner: it
            // faces the ray, and is `perp` of an edge `±2u` or `±2v`.
            let dir = I64Vec2::new(d.0 as i64, d.1 as i64);
            assert!(h.normal.dot(dir) < 0);
            assert_eq!(h.normal.x.abs(), 10);
            assert_eq!(h.normal.y.abs(), 10);
        }
    }

    #[test]
    fn hits_faces_with_perp_edge_normals() {
        // Down from above, slightly right of the top corner: the upper-right
        // face x - y = 10 (outward normal along (1, -1)).
        let h = hit(ray(2, -20, 0, 40)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(12, 40), I64Vec2::new(10, -10), IVec2::new(2, -8))
        );
        // Moving left from the right at y = 3: face x + y = 10, x = 7.
        let h = hit(ray(30, 3, -30, 0)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(23, 30), I64Vec2::new(10, 10), IVec2::new(7, 3))
        );
        // Diagonally up-left at the lower-right face x + y = 10 from (20, 20):
        // at t = 3/4 the point is (5, 5).
        let h = hit(ray(20, 20, -20, -20)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(3, 4), I64Vec2::new(10, 10), IVec2::new(5, 5))
        );
    }

    #[test]
    fn slanted_face_rounds_to_the_outer_side() {
        // From (12, -1) along (-9, -1): x - y = 13 - 8t meets the face
        // x - y = 10 at t = 3/8, point (8.625, -1.375). The normal (10, -10)
        // rounds x up and y down: (9, -2), outside (x - y = 11).
        let h = hit(ray(12, -1, -9, -1)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(3, 8), I64Vec2::new(10, -10), IVec2::new(9, -2))
        );
    }

    #[test]
    fn misses_grazes_and_starts() {
        assert_eq!(hit(ray(-20, -11, 40, 0)), None);
        assert_eq!(hit(ray(6, -6, 10, -10)), None); // leaves away from a face, starting outside
        assert_eq!(hit(ray(-20, 0, 9, 0)), None);
        // Sliding along the upper-right face from beyond the top corner: enters
        // at the corner (0, -10) through the upper-left face's end.
        let h = hit(ray(-5, -15, 10, 10)).unwrap();
        assert_eq!((h.toi, h.point()), (t(1, 2), IVec2::new(0, -10)));
        // Grazing the right corner going straight down.
        let h = hit(ray(10, -5, 0, 10)).unwrap();
        assert_eq!((h.toi, h.point()), (t(1, 2), IVec2::new(10, 0)));
        // Inside.
        assert!(hit(ray(1, 1, 100, 3)).unwrap().started_inside());
        // On the face x + y = 10 at (5, 5), leaving: that face's normal.
        let h = hit(ray(5, 5, 3, 3)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (Toi::ZERO, I64Vec2::new(10, 10), IVec2::new(5, 5))
        );
    }
}
