//! Ray casts against a convex polygon.

use super::{clip, Ray, RayCast, RayHit};
use crate::shape::ConvexPolygon;
use glam::IVec2;

/// Cyrus–Beck over the polygon's edges; the normal is `perp(edge)` of the
/// edge hit.
impl RayCast for ConvexPolygon {
    #[inline]
    fn cast_ray(&self, pos: IVec2, ray: &Ray) -> Option<RayHit> {
        clip::cast(self, pos, ray, |n| n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::contact::{contact, Proximity};
    use crate::query::ray::tests::ray;
    use crate::query::ray::Toi;
    use crate::shape::Point;
    use glam::I64Vec2;

    /// Triangle (-2, 4), (2, -4), (4, 4), placed at (1000, -1000).
    /// Edges: 0 along (4, -8) normal (-8, -4); 1 along (2, 8) normal (8, -2);
    /// 2 along (-6, 0) normal (0, 6).
    fn tri() -> ConvexPolygon {
        ConvexPolygon::new(&[IVec2::new(-2, 4), IVec2::new(2, -4), IVec2::new(4, 4)]).unwrap()
    }
    const POS: IVec2 = IVec2::new(1000, -1000);

    fn hit(ox: i32, oy: i32, dx: i32, dy: i32) -> Option<RayHit> {
        tri().cast_ray(POS, &ray(ox + POS.x, oy + POS.y, dx, dy))
    }

    fn t(num: u64, den: u64) -> Toi {
        Toi::new(num, den).unwrap()
    }

    fn local(p: IVec2) -> IVec2 {
        p - POS
    }

    #[test]
    fn axis_and_diagonal_hits() {
        // Up from below: bottom edge y = 4 (edge 2), normal (0, 6).
        let h = hit(1, 10, 0, -12).unwrap();
        assert_eq!(
            (h.toi, h.normal, local(h.point())),
            (t(1, 2), I64Vec2::new(0, 6), IVec2::new(1, 4))
        );
        // Down from above at x = 1: edge 0 (y = -2x) at y = -2.
        let h = hit(1, -10, 0, 16).unwrap();
        assert_eq!(
            (h.toi, h.normal, local(h.point())),
            (t(8, 16), I64Vec2::new(-8, -4), IVec2::new(1, -2))
        );
        // Left from the right at y = 0: edge 1 (x = 3 + (y - 4) / 4) at x = 3.
        let h = hit(10, 0, -14, 0).unwrap();
        assert_eq!(
            (h.toi, h.normal, local(h.point())),
            (t(7, 14), I64Vec2::new(8, -2), IVec2::new(3, 0))
        );
        // Right from the left at y = 2: edge 0 at x = -1.
        let h = hit(-9, 2, 16, 0).unwrap();
        assert_eq!(
            (h.toi, h.normal, local(h.point())),
            (t(8, 16), I64Vec2::new(-8, -4), IVec2::new(-1, 2))
        );
        // Diagonal down-left from (8, -4) along (-8, 8): edge 1 where
        // 8x - 2y = 24 (through (2, -4)): 8(8 - 8t) - 2(-4 + 8t) = 72 - 80t -> t = 3/5,
        // point (3.2, 0.8): x rounds up, y down (normal (8, -2)): (4, 0).
        let h = hit(8, -4, -8, 8).unwrap();
        assert_eq!(
            (h.toi, h.normal, local(h.point())),
            (t(3, 5), I64Vec2::new(8, -2), IVec2::new(4, 0))
        );
        assert_eq!(h.distance(), 6); // 0.6 * 8√2 = 6.79
    }

    #[test]
    fn slanted_face_never_rounds_inside() {
        // From (0, -1) along (-1, 4): edge 0 at t = 1/2, exact point (-0.5, 1).
        // Rounding each component towards the origin gives (0, 1), strictly
        // inside the triangle; the outer-side rule gives (-1, 1), outside.
        let h = hit(0, -1, -1, 4).unwrap();
        assert_eq!((h.toi, h.normal), (t(1, 2), I64Vec2::new(-8, -4)));
        assert_eq!(local(h.point()), IVec2::new(-1, 1));
        assert!(contact(&Point, POS + IVec2::new(0, 1), &tri(), POS)
            .mtv()
            .is_some());
        assert_eq!(contact(&Point, h.point(), &tri(), POS), Proximity::Apart);
    }

    #[test]
    fn misses_grazes_and_starts() {
        assert_eq!(hit(5, -5, 0, 20), None); // right of the triangle
        assert_eq!(hit(1, 10, 0, -5), None); // stops short
        assert_eq!(hit(1, 10, 0, 5), None); // points away
                                            // Grazing the vertex (2, -4) horizontally.
        let h = hit(-3, -4, 10, 0).unwrap();
        assert_eq!((h.toi, local(h.point())), (t(5, 10), IVec2::new(2, -4)));
        // Along the bottom edge's line from the right: enters at (4, 4)
        // through edge 1's end.
        let h = hit(10, 4, -20, 0).unwrap();
        assert_eq!(
            (h.toi, h.normal, local(h.point())),
            (t(6, 20), I64Vec2::new(8, -2), IVec2::new(4, 4))
        );
        // Ending exactly on edge 2.
        let h = hit(1, 10, 0, -6).unwrap();
        assert_eq!((h.toi, local(h.point())), (Toi::ONE, IVec2::new(1, 4)));
        // Inside.
        assert!(hit(1, 1, -50, 3).unwrap().started_inside());
        // On a vertex, moving out: the first edge through it.
        let h = hit(4, 4, 5, 5).unwrap();
        assert_eq!(
            (h.toi, h.normal, local(h.point())),
            (Toi::ZERO, I64Vec2::new(8, -2), IVec2::new(4, 4))
        );
    }
}
