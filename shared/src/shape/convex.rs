//! The traits shared by all shapes and by the polygon-like ones.

use super::ShapeKind;
use glam::{I64Vec2, IVec2};

/// What every shape can tell about itself, without knowing where it is.
pub trait Shape {
    /// The kind, for dispatch tables and debugging.
    const KIND: ShapeKind;
    /// Smallest and largest corner of the bounding box, in local units.
    fn local_bounds(&self) -> (IVec2, IVec2);
}

/// A convex shape described by vertices (point, segment, box, oriented box,
/// polygon), so the separating axis test and the circle test can run over it
/// generically. Each pair of kinds instantiates these generics separately:
/// static dispatch, no trait object or per-pair `match` in the hot loop.
///
/// Vertices are wound positively (see [`crate::shape`]); edge `i` runs from
/// vertex `i` to vertex `i + 1` and its outward normal is `perp(edge)`.
/// A segment has two vertices and two opposite edges; a point one vertex and
/// no edge.
pub trait Convex: Shape {
    /// How many SAT axes this shape contributes.
    fn axis_count(&self) -> usize;
    /// SAT axis `i` (not normalised; direction is irrelevant).
    fn axis(&self, i: usize) -> I64Vec2;
    /// `(min, max)` of `dot(v, n)` over the shape's points `v` (local coordinates).
    fn project(&self, n: I64Vec2) -> (i64, i64);
    /// Number of vertices.
    fn vertex_count(&self) -> usize;
    /// Vertex `i` in local coordinates.
    fn vertex(&self, i: usize) -> IVec2;
}

#[cfg(test)]
pub(super) mod tests {
    //! A consistency check every polygon-like shape must pass: what the SAT
    //! and circle kernels read through [`Convex`] describes one convex shape.
    use super::*;
    use crate::fixed::{cross128, perp, wide};

    /// Checks bounds, winding, axes and projections of `s` against its vertices.
    pub(in crate::shape) fn check_convex<S: Convex>(s: &S) {
        let n = s.vertex_count();
        assert!(n >= 1);
        let vs: Vec<I64Vec2> = (0..n).map(|i| wide(s.vertex(i))).collect();
        // Bounds are the vertices' bounds.
        let (lo, hi) = s.local_bounds();
        let min = vs.iter().fold(vs[0], |m, v| m.min(*v));
        let max = vs.iter().fold(vs[0], |m, v| m.max(*v));
        assert_eq!((wide(lo), wide(hi)), (min, max), "local bounds");
        // Positive winding, strictly convex.
        if n >= 3 {
            for i in 0..n {
                let e0 = vs[(i + 1) % n] - vs[i];
                let e1 = vs[(i + 2) % n] - vs[(i + 1) % n];
                assert!(cross128(e0, e1) > 0, "turn at vertex {}", (i + 1) % n);
            }
        }
        // Axes: a point has none; a segment its normal and direction; a
        // polygon-like shape exactly the lines of its edge normals.
        let axes: Vec<I64Vec2> = (0..s.axis_count()).map(|i| s.axis(i)).collect();
        let parallel = |a: I64Vec2, b: I64Vec2| cross128(a, b) == 0;
        match n {
            1 => assert!(axes.is_empty()),
            2 => {
                let e = vs[1] - vs[0];
                assert_eq!(axes.len(), 2);
                assert!(
                    parallel(axes[0], perp(e)) && parallel(axes[1], e),
                    "segment axes {axes:?}"
                );
            }
            _ => {
                let normals: Vec<I64Vec2> = (0..n).map(|i| perp(vs[(i + 1) % n] - vs[i])).collect();
                for a in &axes {
                    assert!(
                        *a != I64Vec2::ZERO && normals.iter().any(|m| parallel(*a, *m)),
                        "axis {a} is no edge normal"
                    );
                }
                for m in &normals {
                    assert!(
                        axes.iter().any(|a| parallel(*a, *m)),
                        "edge normal {m} has no axis"
                    );
                }
            }
        }
        // Projections are the vertices' extremes, along the axes and others.
        let dirs = axes.iter().copied().chain([
            I64Vec2::X,
            I64Vec2::Y,
            I64Vec2::new(3, -4),
            I64Vec2::new(-7, -2),
            I64Vec2::new(1 << 20, 12345),
        ]);
        for d in dirs {
            let p = vs.iter().map(|v| v.dot(d));
            let want = (p.clone().min().unwrap(), p.max().unwrap());
            assert_eq!(s.project(d), want, "projection on {d}");
        }
    }
}
