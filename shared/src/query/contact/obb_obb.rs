//! Contact between an oriented box and an oriented box.

use super::{sat::sat, Contact, Proximity};
use crate::shape::Obb;
use glam::IVec2;

impl Contact<Obb> for Obb {
    #[inline]
    fn contact(&self, pos: IVec2, other: &Obb, other_pos: IVec2) -> Proximity {
        sat(self, pos, other, other_pos)
    }
}
