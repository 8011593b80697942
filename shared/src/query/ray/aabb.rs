//! Ray casts against an axis-aligned box.

use super::{clip, Ray, RayCast, RayHit};
use crate::shape::Aabb;
use glam::{I64Vec2, IVec2};

/// Cyrus–Beck over the box's four edges; the normal is the unit axis of the
/// face hit (`-y` top, `+x` right, `+y` bottom, `-x` left).
impl RayCast for Aabb {
    #[inline]
    fn cast_ray(&self, pos: IVec2, ray: &Ray) -> Option<RayHit> {
        clip::cast(self, pos, ray, |n| I64Vec2::new(n.x.signum(), n.y.signum()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::ray::tests::ray;
    use crate::query::ray::Toi;

    /// A 20 x 10 box centred at (100, 50): x in [90, 110], y in [45, 55].
    fn hit(r: Ray) -> Option<RayHit> {
        Aabb::new(IVec2::new(10, 5))
            .unwrap()
            .cast_ray(IVec2::new(100, 50), &r)
    }

    fn t(num: u64, den: u64) -> Toi {
        Toi::new(num, den).unwrap()
    }

    #[test]
    fn hits_from_all_four_sides() {
        // From the left, moving +x.
        let h = hit(ray(80, 50, 20, 0)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point(), h.distance()),
            (t(1, 2), I64Vec2::new(-1, 0), IVec2::new(90, 50), 10)
        );
        // From the right, moving -x.
        let h = hit(ray(130, 52, -40, 0)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point(), h.distance()),
            (t(1, 2), I64Vec2::new(1, 0), IVec2::new(110, 52), 20)
        );
        // From above, moving down (+y).
        let h = hit(ray(95, 0, 0, 100)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point(), h.distance()),
            (t(45, 100), I64Vec2::new(0, -1), IVec2::new(95, 45), 45)
        );
        // From below, moving up (-y).
        let h = hit(ray(105, 60, 0, -10)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point(), h.distance()),
            (t(1, 2), I64Vec2::new(0, 1), IVec2::new(105, 55), 5)
        );
    }

    #[test]
    fn diagonal_hit_rounds_towards_the_origin() {
        // From (80, 37) along (3, 2): reaches x = 90 at t = 10/30, y = 43.67 (above
        // the box), then y = 45 at t = 8/20 = 0.4, x = 92: the top face.
        let h = hit(ray(80, 37, 30, 20)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(2, 5), I64Vec2::new(0, -1), IVec2::new(92, 45))
        );
        // A fractional hit point: from (81, 30) along (19, 30) the top face
        // y = 45 is reached at t = 1/2, x = 90.5 (the left face x = 90 is
        // crossed earlier, at y = 44.2, above the box); x rounds to 90.
        let h = hit(ray(81, 30, 19, 30)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(1, 2), I64Vec2::new(0, -1), IVec2::new(90, 45))
        );
        // Up-left from below-right, hitting the bottom face at x = 107.5,
        // rounded towards the origin (x = 115).
        let h = hit(ray(115, 70, -10, -20)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(3, 4), I64Vec2::new(0, 1), IVec2::new(108, 55))
        );
    }

    #[test]
    fn misses() {
        assert_eq!(hit(ray(80, 50, 9, 0)), None); // stops short
        assert_eq!(hit(ray(80, 50, -20, 0)), None); // points away
        assert_eq!(hit(ray(80, 44, 100, 0)), None); // passes above
        assert_eq!(hit(ray(80, 30, 30, 14)), None); // passes above the top-left corner
        assert_eq!(hit(ray(0, 0, 0, 0)), None); // zero length, outside
    }

    #[test]
    fn grazes_count_as_hits() {
        // Sliding exactly along the top face: enters through the left face's end.
        let h = hit(ray(80, 45, 40, 0)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(1, 4), I64Vec2::new(-1, 0), IVec2::new(90, 45))
        );
        // Through the top-left corner diagonally: tie between the top (edge 0)
        // and the left (edge 3) face; the first in vertex order wins.
        let h = hit(ray(85, 40, 10, 10)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(1, 2), I64Vec2::new(0, -1), IVec2::new(90, 45))
        );
        // Touching the top-right corner only, going down-right: enters through
        // the top and leaves through the right face at the same toi.
        let h = hit(ray(105, 40, 10, 10)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (t(1, 2), I64Vec2::new(0, -1), IVec2::new(110, 45))
        );
        // Ending exactly on the left face.
        let h = hit(ray(80, 50, 10, 0)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.point()),
            (Toi::ONE, I64Vec2::new(-1, 0), IVec2::new(90, 50))
        );
    }

    #[test]
    fn starting_inside_or_on_the_surface() {
        let h = hit(ray(100, 50, 50, 7)).unwrap();
        assert!(h.started_inside());
        assert_eq!(
            (h.toi, h.point(), h.distance()),
            (Toi::ZERO, IVec2::new(100, 50), 0)
        );
        assert!(hit(ray(100, 50, 0, 0)).unwrap().started_inside());
        // On the top face, moving in, along, and out: the top face's normal.
        for d in [(0, 5), (3, 0), (-3, 0), (2, -9)] {
            let h = hit(ray(100, 45, d.0, d.1)).unwrap();
            assert_eq!(
                (h.toi, h.normal, h.point()),
                (Toi::ZERO, I64Vec2::new(0, -1), IVec2::new(100, 45)),
                "{d:?}"
            );
        }
        // On the right face moving in.
        let h = hit(ray(110, 50, -1, 0)).unwrap();
        assert_eq!((h.toi, h.normal), (Toi::ZERO, I64Vec2::new(1, 0)));
    }
}
