//! Pairwise contact tests with minimum translation vectors (MTV).
//!
//! One file per pair of shape kinds, named `<first>_<second>.rs` in the
//! canonical kind order ([`crate::shape::ShapeKind`]); each implements
//! [`Contact`] for that pair and, by negation, for the reverse order, so
//! `mtv(a, b) == -mtv(b, a)` holds by construction for mixed pairs.
//! Polygon-like pairs share the separating-axis kernel in `sat.rs`; pairs
//! with a circle share the closest-feature kernel in `circle_convex.rs`.
//! Both are generic and monomorphised per pair: no trait object or `match`
//! on kinds in the hot loop.
//!
//! # Rounding rule
//! Arithmetic is exact integer arithmetic in coordinates relative to the
//! first shape. The MTV along a slanted axis `n` with overlap `o` (in units of
//! `|n|`) is `n * o / |n|^2` with each component rounded *away from zero*: the
//! moved shape is never left overlapping, and overshoots by less than one unit
//! per axis. Circle MTVs involve a square root; they are computed to 2^-32
//! units and then verified exactly, stepping one more unit outward in the rare
//! case the rounded vector still overlaps, so they overshoot by at most two
//! units per axis.
//!
//! # Degenerate cases
//! Where geometry gives no direction (coincident circle centres, a shape
//! exactly centred in the other along the chosen axis, a circle centred on a
//! segment) the push goes towards `-y` (up) or along the segment's right-hand
//! normal; ties between axes of equal depth pick the axis of smallest angle
//! in `[0, pi)`, so the choice does not depend on argument order. A circle
//! centred inside a shape with several equally near faces leaves through the
//! one whose push is closest to up ([`crate::fixed::dir_order`]), whatever
//! vertex the shape's list starts at.

mod circle_convex;
mod proximity;
mod sat;

mod aabb_aabb;
mod aabb_obb;
mod aabb_polygon;
mod circle_aabb;
mod circle_circle;
mod circle_obb;
mod circle_polygon;
mod obb_obb;
mod obb_polygon;
mod point_aabb;
mod point_circle;
mod point_obb;
mod point_point;
mod point_polygon;
mod point_segment;
mod polygon_polygon;
mod segment_aabb;
mod segment_circle;
mod segment_obb;
mod segment_polygon;
mod segment_segment;
#[cfg(test)]
mod testing;

#[cfg(test)]
pub(crate) use sat::sat;

pub use proximity::Proximity;

use glam::IVec2;

/// Contact test of `Self` against shape `B`.
pub trait Contact<B> {
    /// How `self` placed at `pos` relates to `other` placed at `other_pos`;
    /// the MTV, when overlapping, moves `self`.
    fn contact(&self, pos: IVec2, other: &B, other_pos: IVec2) -> Proximity;
}

/// Free-function form of [`Contact::contact`].
#[inline]
pub fn contact<A: Contact<B>, B>(a: &A, pos_a: IVec2, b: &B, pos_b: IVec2) -> Proximity {
    a.contact(pos_a, b, pos_b)
}

/// Implements `Contact<$a> for $b` by negating `Contact<$b> for $a`.
macro_rules! reverse_contact {
    ($a:ty, $b:ty) => {
        impl $crate::query::contact::Contact<$a> for $b {
            #[inline]
            fn contact(
                &self,
                pos: glam::IVec2,
                other: &$a,
                other_pos: glam::IVec2,
            ) -> $crate::query::contact::Proximity {
                other.contact(other_pos, self, pos).reversed()
            }
        }
    };
}
use reverse_contact;

/// Implements `Contact<$b> for $a` (and the reverse) with the SAT kernel.
macro_rules! sat_contact {
    ($a:ty, $b:ty) => {
        impl $crate::query::contact::Contact<$b> for $a {
            #[inline]
            fn contact(
                &self,
                pos: glam::IVec2,
                other: &$b,
                other_pos: glam::IVec2,
            ) -> $crate::query::contact::Proximity {
                $crate::query::contact::sat::sat(self, pos, other, other_pos)
            }
        }
        $crate::query::contact::reverse_contact!($a, $b);
    };
}
use sat_contact;

/// Implements `Contact<$b> for Circle` (and the reverse) with the circle kernel.
macro_rules! circle_contact {
    ($b:ty) => {
        impl $crate::query::contact::Contact<$b> for $crate::shape::Circle {
            #[inline]
            fn contact(
                &self,
                pos: glam::IVec2,
                other: &$b,
                other_pos: glam::IVec2,
            ) -> $crate::query::contact::Proximity {
                $crate::query::contact::circle_convex::circle_convex(
                    self.radius() as i64,
                    pos,
                    other,
                    other_pos,
                )
            }
        }
        $crate::query::contact::reverse_contact!($crate::shape::Circle, $b);
    };
}
use circle_contact;
