//! Where players appear: spots spread around each spawn point, so players
//! joining one room never stand on one pixel (a friend on top of you is
//! invisible until someone moves).
//!
//! Each spawn gets its spots once, from the level, when the game is built:
//! the spawn itself first, then offsets along x from coarse to fine within
//! [`SPREAD_STEPS`] steps of a player's width plus [`GAP`] to each side:
//! `-w, +w, -2w, +2w`, then the odd multiples of `w / 2` (`-w/2, +w/2,
//! -3w/2, +3w/2`), of `w / 4`, and so on down to [`MIN_STEP`], at most
//! [`MAX_SPOTS`] spots. So the first players stand a little apart, side by
//! side, and later ones fill the gaps (overlapping, never on one pixel).
//! An offset is kept only where a player stands as well as on the spawn
//! itself: its box overlaps no solid, slope or hazard tile, no block,
//! polygon block, hazard volume or springboard, and nowhere a moving
//! platform's path passes; and the floor under its foot (tiles and block
//! tops, within [`FLOOR_PROBE`] player heights) is at the same height as
//! the spawn's. Integer arithmetic only: the same level gives the same
//! spots everywhere.
//!
//! Player `id` takes spawn `id % spawns` (as before) and there spot
//! `(id - 1) / spawns % spots` (wrapping `u32` arithmetic): in a level
//! with one spawn, players 1, 2, 3, ... take spots 0, 1, 2, ..., so player
//! 1 stands on the spawn itself. A player's spot depends on its id and the
//! level only, never on who else is in the game, so a client predicts its
//! own respawn exactly.

use glam::IVec2;

use super::entity::{Ent, EntityType};
use super::rect::Rect;
use crate::fixed::UNITS_PER_PX;
use crate::tilemap::{ContactFlags, TileContact, Tilemap};

/// Space left between two players side by side at the first spots, units.
pub const GAP: i32 = 4 * UNITS_PER_PX;
/// Spots reach this many steps (a player's width plus [`GAP`]) to each
/// side of the spawn.
pub const SPREAD_STEPS: i32 = 2;
/// The finest step between spots, units.
pub const MIN_STEP: i32 = 2 * UNITS_PER_PX;
/// Most spots per spawn (the spawn itself included).
pub const MAX_SPOTS: usize = 32;
/// How far below a spot's foot, in player heights, a floor is looked for.
pub const FLOOR_PROBE: i32 = 4;

/// The x offsets tried, in order (0 first), for a player of half width
/// `half_x`.
pub fn offsets(half_x: i32) -> Vec<i32> {
    let step = 2 * half_x + GAP;
    let span = SPREAD_STEPS * step;
    let mut out = vec![0];
    // First the whole steps, then each halving adds the odd multiples.
    let mut unit = step;
    let mut first = true;
    while unit >= MIN_STEP && out.len() < MAX_SPOTS {
        let mut k = 1;
        while k * unit <= span && out.len() < MAX_SPOTS {
            for off in [-k * unit, k * unit] {
                if out.len() < MAX_SPOTS && !out.contains(&off) {
                    out.push(off);
                }
            }
            k += if first { 1 } else { 2 };
        }
        first = false;
        unit /= 2;
    }
    out
}

/// What a spot is checked against.
pub(super) struct Ground<'a> {
    /// The level's tiles.
    pub(super) map: &'a Tilemap,
    /// The level's entities (platforms with their paths).
    pub(super) ents: &'a [Ent],
    /// The player's half extents.
    pub(super) half: IVec2,
}

impl Ground<'_> {
    /// The spots of a spawn whose player centre is `centre`: `centre`
    /// first, then every offset where a player stands as on `centre`.
    pub(super) fn spots(&self, centre: IVec2) -> Vec<IVec2> {
        let floor = self.floor(centre);
        let mut scratch = Vec::new();
        let mut spots = vec![centre];
        for off in offsets(self.half.x).into_iter().skip(1) {
            let Some(x) = centre.x.checked_add(off) else {
                continue;
            };
            let spot = IVec2::new(x, centre.y);
            if self.clear(spot, &mut scratch) && self.floor(spot) == floor {
                spots.push(spot);
            }
        }
        spots
    }

    /// Whether a player's box at `pos` overlaps nothing solid or harmful.
    fn clear(&self, pos: IVec2, scratch: &mut Vec<TileContact>) -> bool {
        scratch.clear();
        self.map.box_contacts(
            pos,
            self.half,
            IVec2::ZERO,
            ContactFlags::default(),
            scratch,
        );
        if !scratch.is_empty() {
            return false;
        }
        let me = Rect::new(pos, self.half);
        self.ents.iter().all(|e| {
            let r = match e.ty {
                EntityType::Block
                | EntityType::PolygonBlock
                | EntityType::Hazard
                | EntityType::Springboard => Rect::new(e.pos, e.half),
                EntityType::Platform => {
                    let (lo, hi) = e.path.as_ref().expect("platform path").bounds();
                    let lo = Rect::new(lo, e.half);
                    let hi = Rect::new(hi, e.half);
                    Rect {
                        l: lo.l,
                        t: lo.t,
                        r: hi.r,
                        b: hi.b,
                    }
                }
                _ => return true,
            };
            !r.overlaps(&me)
        })
    }

    /// The y of the nearest floor under the foot of a player at `pos` (a
    /// tile surface or a block's top, at most [`FLOOR_PROBE`] player
    /// heights down), if any.
    fn floor(&self, pos: IVec2) -> Option<i64> {
        let foot = IVec2::new(pos.x, pos.y.saturating_add(self.half.y));
        let reach = self.half.y.saturating_mul(2 * FLOOR_PROBE);
        let tiles = self.map.ground_below(foot, reach).map(i64::from);
        let (fx, fy) = (i64::from(foot.x), i64::from(foot.y));
        let blocks = self
            .ents
            .iter()
            .filter(|e| e.ty == EntityType::Block)
            .map(|e| Rect::new(e.pos, e.half))
            .filter(|r| r.l <= fx && fx < r.r && r.t >= fy && r.t <= fy + i64::from(reach))
            .map(|r| r.t)
            .min();
        match (tiles, blocks) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_go_from_coarse_to_fine_and_never_repeat() {
        const PX: i32 = UNITS_PER_PX;
        // A 12 px wide player: steps of 16 px, 32 px to each side.
        let o = offsets(6 * PX);
        assert_eq!(
            &o[..9],
            &[
                0,
                -16 * PX,
                16 * PX,
                -32 * PX,
                32 * PX,
                -8 * PX,
                8 * PX,
                -24 * PX,
                24 * PX
            ]
        );
        assert_eq!(&o[9..11], &[-4 * PX, 4 * PX]);
        assert_eq!(o.len(), MAX_SPOTS);
        let mut sorted = o.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), o.len(), "no offset twice");
        assert!(o.iter().all(|x| x.abs() <= 32 * PX && x % MIN_STEP == 0));
        // Tiny players still get distinct spots.
        let tiny = offsets(1);
        assert!(tiny.len() > 1 && tiny.len() <= MAX_SPOTS);
    }
}
