//! A convex polygon of up to eight vertices, stored inline (no heap).

use super::{Convex, Shape, ShapeError, ShapeKind};
use crate::fixed::{check_extent, cross128, perp, wide};
use glam::{I64Vec2, IVec2};

/// Most vertices a [`ConvexPolygon`] can have.
pub const MAX_POLYGON_VERTICES: usize = 8;

/// A strictly convex polygon in local units, positively wound (the
/// constructor reverses a negatively wound input). Degenerate input
/// (duplicate or collinear vertices, zero area, a reflex angle) is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct ConvexPolygon {
    verts: [IVec2; MAX_POLYGON_VERTICES],
    len: u8,
}

impl ConvexPolygon {
    /// Validates and stores `points` (3 to 8 vertices, either winding).
    pub fn new(points: &[IVec2]) -> Result<Self, ShapeError> {
        let n = points.len();
        if !(3..=MAX_POLYGON_VERTICES).contains(&n) {
            return Err(ShapeError::VertexCount(n));
        }
        for p in points {
            check_extent("polygon vertex x", p.x as i64)?;
            check_extent("polygon vertex y", p.y as i64)?;
        }
        for i in 0..n {
            if points[i] == points[(i + n - 1) % n] {
                return Err(ShapeError::DuplicateVertex(i));
            }
        }
        // Every turn must have the same non-zero sign, and the edge directions
        // must go round exactly once (a star polygon turns one way too).
        let edge = |i: usize| wide(points[(i + 1) % n] - points[i]);
        let mut sign = 0i128;
        for i in 0..n {
            let c = cross128(edge(i), edge((i + 1) % n)).signum();
            if c == 0 {
                return Err(ShapeError::Collinear((i + 1) % n));
            }
            if sign == 0 {
                sign = c;
            } else if c != sign {
                return Err(ShapeError::Concave((i + 1) % n));
            }
        }
        // Twice the signed area must have the turning sign, and the edge
        // directions must pass the +x direction exactly once (a star polygon
        // turns one way at every vertex but winds twice).
        let area2: i128 = (0..n)
            .map(|i| cross128(wide(points[i]), wide(points[(i + 1) % n])))
            .sum();
        if area2.signum() != sign {
            return Err(ShapeError::Concave(0));
        }
        let mut crossings = 0;
        for i in 0..n {
            let (a, b) = (edge(i), edge((i + 1) % n));
            // Each turn is under half a circle, so turning positively from a
            // to b passes +x exactly when a.y < 0 <= b.y.
            let (a, b) = if sign > 0 { (a, b) } else { (b, a) };
            if a.y < 0 && b.y >= 0 {
                crossings += 1;
            }
        }
        if crossings != 1 {
            return Err(ShapeError::Concave(0));
        }
        let mut verts = [IVec2::ZERO; MAX_POLYGON_VERTICES];
        for (i, p) in points.iter().enumerate() {
            verts[if sign > 0 { i } else { n - 1 - i }] = *p;
        }
        Ok(Self {
            verts,
            len: n as u8,
        })
    }

    /// The vertices, positively wound.
    #[inline]
    pub fn vertices(&self) -> &[IVec2] {
        &self.verts[..self.len as usize]
    }
}

impl Shape for ConvexPolygon {
    const KIND: ShapeKind = ShapeKind::Polygon;
    #[inline]
    fn local_bounds(&self) -> (IVec2, IVec2) {
        let v = self.vertices();
        v.iter()
            .fold((v[0], v[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
    }
}

impl Convex for ConvexPolygon {
    #[inline]
    fn axis_count(&self) -> usize {
        self.len as usize
    }
    #[inline]
    fn axis(&self, i: usize) -> I64Vec2 {
        let n = self.len as usize;
        // A branch, not `% n`: this runs once per SAT axis in the hot loop.
        let j = if i + 1 == n { 0 } else { i + 1 };
        perp(wide(self.verts[j] - self.verts[i]))
    }
    #[inline]
    fn project(&self, n: I64Vec2) -> (i64, i64) {
        let mut lo = i64::MAX;
        let mut hi = i64::MIN;
        for v in self.vertices() {
            let p = wide(*v).dot(n);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo, hi)
    }
    #[inline]
    fn vertex_count(&self) -> usize {
        self.len as usize
    }
    #[inline]
    fn vertex(&self, i: usize) -> IVec2 {
        self.verts[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::convex::tests::check_convex;
    use proptest::prelude::*;

    fn v(p: &[(i32, i32)]) -> Vec<IVec2> {
        p.iter().map(|&(x, y)| IVec2::new(x, y)).collect()
    }

    #[test]
    fn accepts_both_windings_and_stores_positive() {
        let sq = v(&[(0, 0), (10, 0), (10, 10), (0, 10)]);
        let a = ConvexPolygon::new(&sq).unwrap();
        let mut rev = sq.clone();
        rev.reverse();
        let b = ConvexPolygon::new(&rev).unwrap();
        for p in [a, b] {
            let vs = p.vertices();
            let e0 = wide(vs[1] - vs[0]);
            let e1 = wide(vs[2] - vs[1]);
            assert!(cross128(e0, e1) > 0);
        }
    }

    #[test]
    fn rejects_degenerate_polygons() {
        assert_eq!(
            ConvexPolygon::new(&v(&[(0, 0), (1, 0)])),
            Err(ShapeError::VertexCount(2))
        );
        assert_eq!(
            ConvexPolygon::new(&v(&[(0, 0), (0, 0), (1, 1)])),
            Err(ShapeError::DuplicateVertex(1))
        );
        assert!(matches!(
            ConvexPolygon::new(&v(&[(0, 0), (5, 0), (10, 0)])),
            Err(ShapeError::Collinear(_))
        ));
        assert!(matches!(
            ConvexPolygon::new(&v(&[(0, 0), (5, 0), (10, 0), (5, 5)])),
            Err(ShapeError::Collinear(_))
        ));
        // Concave (an arrow head).
        assert!(matches!(
            ConvexPolygon::new(&v(&[(0, 0), (10, 5), (0, 10), (3, 5)])),
            Err(ShapeError::Concave(_))
        ));
        // A pentagram turns one way at every vertex but winds twice.
        let star = v(&[(0, -10), (6, 8), (-10, -3), (10, -3), (-6, 8)]);
        assert!(matches!(
            ConvexPolygon::new(&star),
            Err(ShapeError::Concave(_))
        ));
        assert!(ConvexPolygon::new(&v(&[(0, 0), (1 << 28, 0), (0, 1)])).is_err());
    }

    #[test]
    fn vertex_count_and_bounds() {
        let oct = v(&[
            (2, 0),
            (5, 0),
            (7, 2),
            (7, 5),
            (5, 7),
            (2, 7),
            (0, 5),
            (0, 2),
        ]);
        let p = ConvexPolygon::new(&oct).unwrap();
        assert_eq!(p.vertices(), &oct[..]);
        assert_eq!(p.local_bounds(), (IVec2::new(0, 0), IVec2::new(7, 7)));
        check_convex(&p);
        let mut nine = oct.clone();
        nine.insert(1, IVec2::new(3, -1));
        assert!(matches!(
            ConvexPolygon::new(&nine),
            Err(ShapeError::VertexCount(9))
        ));
        assert!(matches!(
            ConvexPolygon::new(&[]),
            Err(ShapeError::VertexCount(0))
        ));
        let m = crate::fixed::MAX_EXTENT;
        assert!(ConvexPolygon::new(&v(&[(-m, -m), (m, -m), (0, m)])).is_ok());
        assert!(matches!(
            ConvexPolygon::new(&v(&[(-m, -m), (m + 1, -m), (0, m)])),
            Err(ShapeError::Bounds(_))
        ));
    }

    #[test]
    fn negative_winding_is_reversed() {
        let cw = v(&[(0, 0), (0, 10), (10, 10), (10, 0)]);
        let p = ConvexPolygon::new(&cw).unwrap();
        let mut want = cw.clone();
        want.reverse();
        assert_eq!(p.vertices(), &want[..]);
        check_convex(&p);
    }

    #[test]
    fn rejects_self_intersecting_quads() {
        // A bow tie: the vertices of a square in the wrong order.
        let bow = v(&[(0, 0), (10, 10), (10, 0), (0, 10)]);
        assert!(matches!(
            ConvexPolygon::new(&bow),
            Err(ShapeError::Concave(_))
        ));
        // A last vertex back at the start.
        assert!(matches!(
            ConvexPolygon::new(&v(&[(0, 0), (10, 0), (0, 10), (0, 0)])),
            Err(ShapeError::DuplicateVertex(_))
        ));
    }

    proptest! {
        /// The convex hull of random points is accepted, in either winding
        /// and from any starting vertex; swapping two vertices of a convex
        /// polygon with at least four (a self-intersecting order) is refused.
        #[test]
        fn hulls_are_accepted_and_shuffles_refused(
            pts in proptest::collection::vec((-1000i32..=1000, -1000i32..=1000), 3..40),
            rot in 0usize..8, rev in any::<bool>(), swap in 0usize..8,
        ) {
            let mut h = hull(&pts);
            prop_assume!(h.len() >= 3);
            h.truncate(MAX_POLYGON_VERTICES);
            if rev {
                h.reverse();
            }
            let k = rot % h.len();
            h.rotate_left(k);
            let p = ConvexPolygon::new(&h).unwrap();
            check_convex(&p);
            if h.len() >= 4 {
                let n = h.len();
                h.swap(swap % n, (swap + 1) % n);
                prop_assert!(ConvexPolygon::new(&h).is_err(), "{:?}", h);
            }
        }
    }

    /// Strict convex hull by the monotone chain.
    fn hull(pts: &[(i32, i32)]) -> Vec<IVec2> {
        let mut p: Vec<IVec2> = pts.iter().map(|&(x, y)| IVec2::new(x, y)).collect();
        p.sort_by_key(|q| (q.x, q.y));
        p.dedup();
        let turn = |a: IVec2, b: IVec2, c: IVec2| cross128(wide(b - a), wide(c - b));
        let mut out: Vec<IVec2> = Vec::new();
        for pass in [p.clone(), p.into_iter().rev().collect()] {
            let start = out.len();
            for q in pass {
                while out.len() >= start + 2 && turn(out[out.len() - 2], out[out.len() - 1], q) <= 0
                {
                    out.pop();
                }
                out.push(q);
            }
            out.pop();
        }
        out
    }
}
