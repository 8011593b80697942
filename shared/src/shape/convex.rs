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
