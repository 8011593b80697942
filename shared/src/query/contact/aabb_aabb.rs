//! Contact between an axis-aligned box and an axis-aligned box.

use super::{Contact, Proximity};
use crate::shape::Aabb;
use glam::IVec2;

/// The SAT answer for two unit axes, specialised: no projections, no
/// products. Ties pick the x axis; a centred box is pushed left or up, the
/// same choices the general kernel makes.
impl Contact<Aabb> for Aabb {
    #[inline]
    fn contact(&self, pos: IVec2, other: &Aabb, other_pos: IVec2) -> Proximity {
        let d = other_pos.as_i64vec2() - pos.as_i64vec2();
        let reach = self.half().as_i64vec2() + other.half().as_i64vec2();
        let ox = reach.x - d.x.abs();
        let oy = reach.y - d.y.abs();
        if ox < 0 || oy < 0 {
            return Proximity::Apart;
        }
        if ox == 0 || oy == 0 {
            return Proximity::Touching;
        }
        let mtv = if ox <= oy {
            IVec2::new(if d.x >= 0 { -ox } else { ox } as i32, 0)
        } else {
            IVec2::new(0, if d.y >= 0 { -oy } else { oy } as i32)
        };
        Proximity::Overlapping(mtv)
    }
}
