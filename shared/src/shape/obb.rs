//! An oriented box: a rectangle turned by an integer direction vector.

use super::{Convex, Shape, ShapeError, ShapeKind};
use crate::fixed::{check_extent, perp, wide};
use glam::{I64Vec2, IVec2};

/// An oriented box centred on its origin, given by two integer half-axis
/// vectors `u` and `v`: its corners are `±u ± v`.
///
/// Rotation is an integer direction, never an angle. [`Obb::new`] rounds the
/// ideal rectangle to integer half axes; the stored shape is what collides, so
/// every query on it is exact. Only two SAT axes (`perp(u)`, `perp(v)`) are
/// needed, half as many as a general quadrilateral.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct Obb {
    u: IVec2,
    v: IVec2,
}

impl Obb {
    /// A box of half extents `half` (units) whose local x axis points along
    /// `dir` (any non-zero integer vector). Half axes are rounded to the
    /// nearest unit; when `dir` is axis-aligned or a Pythagorean direction
    /// such as (3, 4) the rectangle is exact.
    pub fn new(half: IVec2, dir: IVec2) -> Result<Self, ShapeError> {
        if half.x <= 0 || half.y <= 0 {
            return Err(ShapeError::NotPositive {
                what: "oriented box half extent",
                value: half.x.min(half.y) as i64,
            });
        }
        if dir == IVec2::ZERO {
            return Err(ShapeError::BadAxes);
        }
        let d = wide(dir);
        // |d| * 2^16, floored: precise enough that rounding to nearest below
        // is off by at most one unit in rare half-way cases.
        let len16 = ((d.x as i128 * d.x as i128 + d.y as i128 * d.y as i128) as u128) << 32;
        let len16 = len16.isqrt() as i128;
        let round = |h: i32, c: i64| -> i32 {
            let twice = 2 * (h as i128 * c as i128 * (1 << 16)) / len16;
            ((twice + twice.signum()) / 2) as i32
        };
        let u = IVec2::new(round(half.x, d.x), round(half.x, d.y));
        let v = IVec2::new(round(half.y, -d.y), round(half.y, d.x));
        Self::from_axes(u, v)
    }

    /// A box from exact half-axis vectors: they must be non-zero and not
    /// parallel. Corners are `±u ± v`; when `u` and `v` are not exactly
    /// perpendicular (rounding of a turned rectangle) the shape is the
    /// parallelogram they span, and every query is exact on it.
    pub fn from_axes(u: IVec2, v: IVec2) -> Result<Self, ShapeError> {
        let (wu, wv) = (wide(u), wide(v));
        if u == IVec2::ZERO || v == IVec2::ZERO || wu.perp_dot(wv) == 0 {
            return Err(ShapeError::BadAxes);
        }
        for (what, c) in [
            (
                "oriented box extent x",
                (u.x as i64).abs() + (v.x as i64).abs(),
            ),
            (
                "oriented box extent y",
                (u.y as i64).abs() + (v.y as i64).abs(),
            ),
        ] {
            check_extent(what, c)?;
        }
        // Positive winding needs cross(u, v) > 0.
        let (u, v) = if wu.perp_dot(wv) > 0 { (u, v) } else { (u, -v) };
        Ok(Self { u, v })
    }

    /// First half axis.
    #[inline]
    pub fn u(&self) -> IVec2 {
        self.u
    }

    /// Second half axis (`cross(u, v) > 0`).
    #[inline]
    pub fn v(&self) -> IVec2 {
        self.v
    }
}

impl Shape for Obb {
    const KIND: ShapeKind = ShapeKind::Obb;
    #[inline]
    fn local_bounds(&self) -> (IVec2, IVec2) {
        let h = self.u.abs() + self.v.abs();
        (-h, h)
    }
}

impl Convex for Obb {
    #[inline]
    fn axis_count(&self) -> usize {
        2
    }
    #[inline]
    fn axis(&self, i: usize) -> I64Vec2 {
        if i == 0 {
            perp(wide(self.u))
        } else {
            perp(wide(self.v))
        }
    }
    #[inline]
    fn project(&self, n: I64Vec2) -> (i64, i64) {
        let r = wide(self.u).dot(n).abs() + wide(self.v).dot(n).abs();
        (-r, r)
    }
    #[inline]
    fn vertex_count(&self) -> usize {
        4
    }
    #[inline]
    fn vertex(&self, i: usize) -> IVec2 {
        let (u, v) = (self.u, self.v);
        match i {
            0 => -u - v,
            1 => u - v,
            2 => u + v,
            _ => -u + v,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::MAX_EXTENT;
    use crate::shape::convex::tests::check_convex;
    use proptest::prelude::*;

    fn v(x: i32, y: i32) -> IVec2 {
        IVec2::new(x, y)
    }

    #[test]
    fn pythagorean_and_axis_directions_are_exact() {
        for dir in [v(3, 4), v(6, 8), v(300, 400)] {
            let o = Obb::new(v(50, 25), dir).unwrap();
            assert_eq!((o.u(), o.v()), (v(30, 40), v(-20, 15)), "{dir}");
            check_convex(&o);
        }
        let o = Obb::new(v(7, 3), v(5, 0)).unwrap();
        assert_eq!((o.u(), o.v()), (v(7, 0), v(0, 3)));
        // Turned half a turn: the same rectangle, still positively wound.
        let o = Obb::new(v(7, 3), v(-1, 0)).unwrap();
        assert_eq!((o.u(), o.v()), (v(-7, 0), v(0, -3)));
        assert_eq!(o.local_bounds(), (v(-7, -3), v(7, 3)));
        check_convex(&o);
    }

    #[test]
    fn slanted_directions_round_to_nearest() {
        // 100 / sqrt 2 = 70.71.
        let o = Obb::new(v(100, 100), v(1, 1)).unwrap();
        assert_eq!((o.u(), o.v()), (v(71, 71), v(-71, 71)));
        // 50 / sqrt 2 = 35.36.
        let o = Obb::new(v(50, 50), v(-2, -2)).unwrap();
        assert_eq!((o.u(), o.v()), (v(-35, -35), v(35, -35)));
        check_convex(&o);
    }

    #[test]
    fn rejects_bad_input() {
        assert!(matches!(
            Obb::new(v(0, 5), v(1, 0)),
            Err(ShapeError::NotPositive { .. })
        ));
        assert!(matches!(
            Obb::new(v(5, -1), v(1, 0)),
            Err(ShapeError::NotPositive { .. })
        ));
        assert_eq!(Obb::new(v(5, 5), IVec2::ZERO), Err(ShapeError::BadAxes));
        assert_eq!(
            Obb::from_axes(IVec2::ZERO, v(1, 0)),
            Err(ShapeError::BadAxes)
        );
        assert_eq!(Obb::from_axes(v(2, 1), v(-4, -2)), Err(ShapeError::BadAxes));
        assert!(matches!(
            Obb::from_axes(v(MAX_EXTENT, 0), v(1, 1)),
            Err(ShapeError::Bounds(_))
        ));
        // Turned 45 degrees, a square's extent per axis is sqrt 2 times its half.
        assert!(matches!(
            Obb::new(IVec2::splat(MAX_EXTENT), v(1, 1)),
            Err(ShapeError::Bounds(_))
        ));
        assert!(Obb::new(IVec2::splat(MAX_EXTENT), v(1, 0)).is_ok());
        assert!(Obb::from_axes(v(MAX_EXTENT - 1, 0), v(1, 1)).is_ok());
        // Extreme components are an error, not an overflow.
        assert!(Obb::from_axes(v(i32::MIN, 0), v(0, 1)).is_err());
        assert!(Obb::from_axes(v(1, 0), v(0, i32::MIN)).is_err());
    }

    #[test]
    fn from_axes_winds_positively() {
        let o = Obb::from_axes(v(4, 0), v(0, -2)).unwrap();
        assert_eq!((o.u(), o.v()), (v(4, 0), v(0, 2)));
        // A parallelogram is allowed and is exactly what collides.
        let o = Obb::from_axes(v(5, 1), v(2, 3)).unwrap();
        assert_eq!((o.u(), o.v()), (v(5, 1), v(2, 3)));
        check_convex(&o);
    }

    proptest! {
        /// Half axes are the ideal turned rectangle's to the nearest unit
        /// (at most one unit off), and the shape is consistent.
        #[test]
        fn rounding_stays_within_a_unit(
            hx in 1i32..=1 << 24, hy in 1i32..=1 << 24,
            dx in -(1i32 << 20)..=1 << 20, dy in -(1i32 << 20)..=1 << 20,
        ) {
            prop_assume!(dx != 0 || dy != 0);
            let o = Obb::new(v(hx, hy), v(dx, dy)).unwrap();
            let l = ((dx as f64).powi(2) + (dy as f64).powi(2)).sqrt();
            let (ux, uy) = (hx as f64 * dx as f64 / l, hx as f64 * dy as f64 / l);
            let (vx, vy) = (-(hy as f64) * dy as f64 / l, hy as f64 * dx as f64 / l);
            for (got, want) in [(o.u().x, ux), (o.u().y, uy), (o.v().x, vx), (o.v().y, vy)] {
                prop_assert!((got as f64 - want).abs() <= 1.0, "{} vs {}", got, want);
            }
            check_convex(&o);
        }
    }
}
