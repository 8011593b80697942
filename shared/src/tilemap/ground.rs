//! The floor under a foot: what a controller snaps to when walking down.

use glam::IVec2;

use super::tile::face::BOTTOM;
use super::{Tile, Tilemap};

impl Tilemap {
    /// The y of the first floor surface at or below `foot` (a box's
    /// bottom-centre point) in the foot's tile column, if it is at most
    /// `max_drop` units below the foot.
    ///
    /// Floor surfaces are the tops of [`Tile::Solid`] tiles not covered by a
    /// full bottom face above them, the tops of [`Tile::OneWay`] tiles, and
    /// slope surfaces at the foot's x, exactly as [`Tilemap::box_contacts`]
    /// places a standing box: snapping the box's bottom to the answer leaves
    /// it resting with no contact pushing it. A controller calls this after
    /// restitution when a grounded body walking (not jumping, not dropping
    /// through) found no floor, to follow a downward slope instead of
    /// launching off it.
    pub fn ground_below(&self, foot: IVec2, max_drop: i32) -> Option<i32> {
        let t = self.tile_size() as i64;
        let (fx, fy) = (foot.x as i64, foot.y as i64);
        let limit = fy + max_drop.max(0) as i64;
        let c = self.col_of(fx);
        if c < 0 || c >= self.width() as i64 {
            return None;
        }
        // A surface exactly at the foot can be the bottom line of the tile
        // above the foot's row (a slope of height 0 there): start one row up.
        let mut r = self.row_of(fy - 1).max(0);
        while r < self.height() as i64 {
            let top = self.row_top(r);
            if top > limit {
                return None;
            }
            let surface = match self.at(c, r) {
                Tile::Solid if self.at(c, r - 1).full_faces() & BOTTOM == 0 => Some(top),
                Tile::OneWay => Some(top),
                Tile::Slope(s) => Some(top + t - s.height64(fx - self.col_left(c), t)),
                _ => None,
            };
            if let Some(y) = surface {
                if y >= fy {
                    return (y <= limit).then_some(y as i32);
                }
            }
            r += 1;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tilemap::Slope as K;

    const T: i32 = 256;

    /// Row 1: `. / # - \ .`; row 2: solid under the slopes only.
    fn map() -> Tilemap {
        use Tile::{Empty, OneWay, Solid};
        let s = Tile::Slope;
        #[rustfmt::skip]
        let tiles = vec![
            Empty, Empty,                Empty, Empty,  Empty,               Empty,
            Empty, s(K::Right45),    Solid, OneWay, s(K::Left45),    Empty,
            Empty, Solid,                Solid, Empty,  Solid,               Empty,
        ];
        Tilemap::new(IVec2::new(-3 * T - 5, 1000), T, 6, 3, tiles).unwrap()
    }

    fn col(m: &Tilemap, c: i32) -> i32 {
        m.origin().x + c * T
    }

    #[test]
    fn surfaces_at_and_below_the_foot() {
        let m = map();
        let (top1, top2) = (m.origin().y + T, m.origin().y + 2 * T);
        // '/' at x = 0: surface on its bottom line, exactly at the foot.
        assert_eq!(m.ground_below(IVec2::new(col(&m, 1), top2), 0), Some(top2));
        assert_eq!(
            m.ground_below(IVec2::new(col(&m, 1), top2 - 5), 5),
            Some(top2)
        );
        assert_eq!(m.ground_below(IVec2::new(col(&m, 1), top2 - 5), 4), None);
        // '/' at x = 100: surface 100 above the bottom.
        assert_eq!(
            m.ground_below(IVec2::new(col(&m, 1) + 100, 0), i32::MAX),
            Some(top2 - 100)
        );
        // Solid top (covered below by nothing above it).
        assert_eq!(
            m.ground_below(IVec2::new(col(&m, 2) + 7, top1), 0),
            Some(top1)
        );
        // One-way top.
        assert_eq!(
            m.ground_below(IVec2::new(col(&m, 3), top1 - 30), 30),
            Some(top1)
        );
        // '\' at x = 10: h = T - 10.
        assert_eq!(
            m.ground_below(IVec2::new(col(&m, 4) + 10, top1), 10),
            Some(top1 + 10)
        );
        // Nothing under the empty columns, or outside the grid.
        assert_eq!(m.ground_below(IVec2::new(col(&m, 0), 0), i32::MAX), None);
        assert_eq!(m.ground_below(IVec2::new(col(&m, 6), 0), i32::MAX), None);
        // The solid under a slope is not a floor of its own: below the slope
        // surface (inside the ground) there is nothing further down.
        assert_eq!(
            m.ground_below(IVec2::new(col(&m, 1) + 100, top2 - 50), i32::MAX),
            None
        );
    }

    #[test]
    fn snapping_leaves_no_contact() {
        let m = map();
        let half = IVec2::new(T / 4 + 3, T / 3);
        let mut out = Vec::new();
        for x in col(&m, 1)..col(&m, 5) {
            let Some(y) = m.ground_below(IVec2::new(x, m.origin().y), 3 * T) else {
                continue;
            };
            out.clear();
            let pos = IVec2::new(x, y - half.y);
            m.box_contacts(pos, half, IVec2::new(0, 1), Default::default(), &mut out);
            assert!(out.is_empty(), "x {x}: {out:?}");
            // And one unit lower, something pushes it back up.
            m.box_contacts(
                pos + IVec2::Y,
                half,
                IVec2::new(0, 1),
                Default::default(),
                &mut out,
            );
            assert!(
                out.iter().any(|c| c.mtv == IVec2::new(0, -1)),
                "x {x}: {out:?}"
            );
        }
    }
}
