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
            return Err(ShapeError::NotPositive { what: "oriented box half extent", value: half.x.min(half.y) as i64 });
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
        for (what, c) in [("oriented box extent x", u.x.abs() as i64 + v.x.abs() as i64), ("oriented box extent y", u.y.abs() as i64 + v.y.abs() as i64)] {
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
