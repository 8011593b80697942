//! Contact between a convex polygon and a convex polygon.

use super::{sat::sat, Contact, Proximity};
use crate::shape::ConvexPolygon;
use glam::IVec2;

impl Contact<ConvexPolygon> for ConvexPolygon {
    #[inline]
    fn contact(&self, pos: IVec2, other: &ConvexPolygon, other_pos: IVec2) -> Proximity {
        sat(self, pos, other, other_pos)
    }
}
