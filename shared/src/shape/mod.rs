//! Collision shapes, each in its own local coordinates around its origin.
//!
//! A shape never stores its position: a collider places it at
//! `body.pos + offset`. Queries take each shape's world position and work in
//! coordinates relative to the first shape, so answers are the same anywhere
//! in the world (translation invariance).
//!
//! Axes: x grows to the right, y grows *down* (screen convention), so "up" is
//! `-y`. Polygon-like shapes are wound positively (`cross(e_i, e_{i+1}) > 0`),
//! which makes the right-hand perpendicular `(e.y, -e.x)` of each edge point
//! outwards.

mod aabb;
mod circle;
mod convex;
mod obb;
mod point;
mod polygon;
mod segment;

pub use aabb::Aabb;
pub use circle::Circle;
pub use convex::{Convex, Shape};
pub use obb::Obb;
pub use point::Point;
pub use polygon::{ConvexPolygon, MAX_POLYGON_VERTICES};
pub use segment::Segment;

use crate::fixed::BoundsError;
use thiserror::Error;

/// The kinds of shape, in the canonical order used to pick which pair file
/// implements a query (the lower kind comes first).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum ShapeKind {
    /// [`Point`].
    Point,
    /// [`Segment`].
    Segment,
    /// [`Circle`].
    Circle,
    /// [`Aabb`].
    Aabb,
    /// [`Obb`].
    Obb,
    /// [`ConvexPolygon`].
    Polygon,
}

/// Why a shape could not be built.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ShapeError {
    /// A size or vertex outside the numeric bounds.
    #[error(transparent)]
    Bounds(#[from] BoundsError),
    /// A size that must be positive is not.
    #[error("{what} must be positive, got {value}")]
    NotPositive {
        /// Which value.
        what: &'static str,
        /// The offending value.
        value: i64,
    },
    /// A full size that must be even (a centred box has integer half extents).
    #[error("{what} must be even, got {value}")]
    OddSize {
        /// Which value.
        what: &'static str,
        /// The offending value.
        value: i64,
    },
    /// A segment whose ends coincide.
    #[error("segment has zero length")]
    ZeroLength,
    /// A polygon with fewer than 3 or more than [`MAX_POLYGON_VERTICES`] vertices.
    #[error("polygon has {0} vertices; it needs 3 to {MAX_POLYGON_VERTICES}")]
    VertexCount(usize),
    /// Two consecutive polygon vertices are equal.
    #[error("polygon vertex {0} duplicates the one before it")]
    DuplicateVertex(usize),
    /// Three consecutive polygon vertices are collinear (this includes zero area).
    #[error("polygon vertices around index {0} are collinear")]
    Collinear(usize),
    /// The polygon turns both ways or winds more than once.
    #[error("polygon is not convex at vertex {0}")]
    Concave(usize),
    /// An oriented box whose axes are not perpendicular or are zero.
    #[error("oriented box axes must be non-zero and perpendicular")]
    BadAxes,
}
