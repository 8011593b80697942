//! Contact between a segment and a segment.

use super::{sat::sat, Contact, Proximity};
use crate::shape::Segment;
use glam::IVec2;

impl Contact<Segment> for Segment {
    #[inline]
    fn contact(&self, pos: IVec2, other: &Segment, other_pos: IVec2) -> Proximity {
        sat(self, pos, other, other_pos)
    }
}
