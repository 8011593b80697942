//! Contacts between an axis-aligned box and the tiles it overlaps.
//!
//! See the [module documentation](super) for the rules.

use glam::IVec2;

use super::tile::face::{BOTTOM, LEFT, RIGHT, TOP};
use super::{Tile, Tilemap};

/// Options of one contact query.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct ContactFlags {
    /// The body is dropping through one-way platforms: [`Tile::OneWay`]
    /// tiles never push it.
    pub drop_through: bool,
}

/// One tile that pushes a box (or, for a hazard, that it overlaps).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TileContact {
    /// Tile coordinates.
    pub tile: IVec2,
    /// What the tile is.
    pub kind: Tile,
    /// Moves the box out of the tile; axis-aligned and exact (no rounding
    /// involved). Zero for a trigger ([`TileContact::is_trigger`]).
    pub mtv: IVec2,
}

impl TileContact {
    /// A hazard overlap: report it, never push (its `mtv` is zero).
    #[inline]
    pub fn is_trigger(&self) -> bool {
        self.kind == Tile::Hazard
    }
}

/// The box of one query in `i64` world units, and its foot context.
struct Probe {
    l: i64,
    r: i64,
    t: i64,
    b: i64,
    /// Foot x (the box's centre x).
    fx: i64,
    moved_y: i64,
    drop_through: bool,
    /// The slope tile the foot stands in (see [`Tilemap::ground_slope`]).
    ground: Option<(i64, i64)>,
}

impl Tilemap {
    /// Appends to `out` one [`TileContact`] for every tile that pushes the
    /// box of centre `pos` and half extents `half` (both positive), and one
    /// trigger contact for every hazard tile it overlaps, in row-major tile
    /// order. `moved` is the box's displacement so far this tick (position
    /// now minus position at the start of the tick, pushes included), used by
    /// one-way tiles.
    ///
    /// `out` is not cleared (the caller clears and reuses it: no allocation
    /// once it has grown). Cost: one lookup per overlapped tile plus its four
    /// neighbours; no per-tile collider exists.
    pub fn box_contacts(
        &self,
        pos: IVec2,
        half: IVec2,
        moved: IVec2,
        flags: ContactFlags,
        out: &mut Vec<TileContact>,
    ) {
        let p = self.probe(pos, half, moved, flags);
        let (c0, c1) = (
            self.col_of(p.l).max(0),
            self.col_of(p.r - 1).min(self.width() as i64 - 1),
        );
        let (r0, r1) = (
            self.row_of(p.t).max(0),
            self.row_of(p.b - 1).min(self.height() as i64 - 1),
        );
        // The foot's slope may lie just above a box that has sunk entirely
        // into the solid tile below it (a fast landing): it still pushes.
        if let Some((gc, gr)) = p.ground {
            if gr < r0 {
                self.push_contact(gc, gr, &p, out);
            }
        }
        for r in r0..=r1 {
            for c in c0..=c1 {
                self.push_contact(c, r, &p, out);
            }
        }
    }

    /// The contact [`Tilemap::box_contacts`] would report for tile `tile`
    /// with the box where it is now: the re-check before applying a stale
    /// contact during restitution. `None` when that tile does not touch the
    /// box any more.
    pub fn tile_contact(
        &self,
        tile: IVec2,
        pos: IVec2,
        half: IVec2,
        moved: IVec2,
        flags: ContactFlags,
    ) -> Option<TileContact> {
        let p = self.probe(pos, half, moved, flags);
        let (c, r) = (tile.x as i64, tile.y as i64);
        let kind = self.at(c, r);
        self.mtv(c, r, kind, &p)
            .map(|mtv| TileContact { tile, kind, mtv })
    }

    fn probe(&self, pos: IVec2, half: IVec2, moved: IVec2, flags: ContactFlags) -> Probe {
        debug_assert!(
            half.x > 0 && half.y > 0,
            "box half extents must be positive"
        );
        let (x, y) = (pos.x as i64, pos.y as i64);
        let (hx, hy) = (half.x as i64, half.y as i64);
        let b = y + hy;
        Probe {
            l: x - hx,
            r: x + hx,
            t: y - hy,
            b,
            fx: x,
            moved_y: moved.y as i64,
            drop_through: flags.drop_through,
            ground: self.ground_slope(x, b),
        }
    }

    /// The slope tile a foot at `(fx, b)` stands in: the tile containing the
    /// unit cell just above the foot when it is a slope, or the one above
    /// that when the foot has sunk into the [`Tile::Solid`] tile right under
    /// a slope.
    #[inline]
    fn ground_slope(&self, fx: i64, b: i64) -> Option<(i64, i64)> {
        let (c, r) = (self.col_of(fx), self.row_of(b - 1));
        match self.at(c, r) {
            Tile::Slope(_) => Some((c, r)),
            Tile::Solid if matches!(self.at(c, r - 1), Tile::Slope(_)) => Some((c, r - 1)),
            _ => None,
        }
    }

    #[inline]
    fn push_contact(&self, c: i64, r: i64, p: &Probe, out: &mut Vec<TileContact>) {
        let kind = self.at(c, r);
        if kind == Tile::Empty {
            return;
        }
        if let Some(mtv) = self.mtv(c, r, kind, p) {
            out.push(TileContact {
                tile: IVec2::new(c as i32, r as i32),
                kind,
                mtv,
            });
        }
    }

    /// The collision faces of tile `(c, r)`: its full faces not hidden by
    /// the neighbour's full face on the same side.
    #[inline]
    pub(super) fn exposed(&self, c: i64, r: i64, kind: Tile) -> u8 {
        let mut f = kind.full_faces();
        if f & TOP != 0 && self.at(c, r - 1).full_faces() & BOTTOM != 0 {
            f &= !TOP;
        }
        if f & BOTTOM != 0 && self.at(c, r + 1).full_faces() & TOP != 0 {
            f &= !BOTTOM;
        }
        if f & LEFT != 0 && self.at(c - 1, r).full_faces() & RIGHT != 0 {
            f &= !LEFT;
        }
        if f & RIGHT != 0 && self.at(c + 1, r).full_faces() & LEFT != 0 {
            f &= !RIGHT;
        }
        f
    }

    /// The MTV of tile `(c, r)` of kind `kind` against the probe box, if it
    /// pushes (zero for a hazard it overlaps).
    fn mtv(&self, c: i64, r: i64, kind: Tile, p: &Probe) -> Option<IVec2> {
        let t = self.tile_size() as i64;
        let (tl, tt) = (self.col_left(c), self.row_top(r));
        let (tr, tb) = (tl + t, tt + t);
        let overlaps = p.l < tr && p.r > tl && p.t < tb && p.b > tt;
        let up = |d: i64| IVec2::new(0, -(d as i32));
        match kind {
            Tile::Empty => None,
            Tile::Hazard => overlaps.then_some(IVec2::ZERO),
            Tile::OneWay => {
                // The top line only, from above, when not dropping through
                // and not standing on a slope.
                let crosses = p.l < tr && p.r > tl && p.t < tt && p.b > tt;
                let came_from_above = p.moved_y >= 0 && p.b - p.moved_y <= tt;
                (crosses && came_from_above && !p.drop_through && p.ground.is_none())
                    .then(|| up(p.b - tt))
            }
            Tile::Solid => {
                if !overlaps {
                    return None;
                }
                let faces = self.exposed(c, r, kind);
                // Push distances through each face, in tie-break order.
                let cands = [
                    (TOP, IVec2::new(0, -((p.b - tt) as i32))),
                    (BOTTOM, IVec2::new(0, (tb - p.t) as i32)),
                    (LEFT, IVec2::new(-((p.r - tl) as i32), 0)),
                    (RIGHT, IVec2::new((tr - p.l) as i32, 0)),
                ];
                let best = smallest(&cands, faces)?;
                if best.y < 0 && self.plateau_of_slope(c, r, p.fx) {
                    return None;
                }
                Some(best)
            }
            Tile::Slope(s) => {
                if p.ground == Some((c, r)) {
                    // Foot rule: push straight up onto the surface.
                    let surf = tb - s.height64(p.fx - tl, t);
                    return (p.b > surf).then(|| up(p.b - surf));
                }
                // Otherwise the tile pushes only when the box overlaps its
                // solid part, and only through its exposed full faces.
                let (xa, xb) = (p.l.max(tl) - tl, p.r.min(tr) - tl - 1);
                if !overlaps || xa > xb {
                    return None;
                }
                let hmax = s.height64(if s.rises_right() { xb } else { xa }, t);
                if hmax == 0 || p.b <= tb - hmax {
                    return None;
                }
                let mut faces = self.exposed(c, r, kind);
                // The bottom pushes a box hit from below (reaching past it);
                // the high side only a box whose foot is beyond it. A box
                // whose corner merely dips into the triangle gets nothing.
                if p.b <= tb {
                    faces &= !BOTTOM;
                }
                if p.fx < tr {
                    faces &= !RIGHT;
                }
                if p.fx >= tl {
                    faces &= !LEFT;
                }
                let cands = [
                    (BOTTOM, IVec2::new(0, (tb - p.t) as i32)),
                    (LEFT, IVec2::new(-((p.r - tl) as i32), 0)),
                    (RIGHT, IVec2::new((tr - p.l) as i32, 0)),
                ];
                smallest(&cands, faces)
            }
        }
    }
}

impl Tilemap {
    /// Whether solid tile `(c, r)` is part of a plateau that a slope
    /// between it and the foot (at x `fx`) leads onto: walking along the row
    /// from the tile towards the foot's column crosses only solid tiles
    /// before reaching a slope whose full high side faces them. The slope's
    /// surface then decides the standing height: this top does not hold the
    /// box up (it gives no push at all: its side towards the foot is
    /// hidden).
    fn plateau_of_slope(&self, c: i64, r: i64, fx: i64) -> bool {
        let fc = self.col_of(fx);
        if fc == c {
            return false;
        }
        let (step, facing) = if fc < c { (-1, RIGHT) } else { (1, LEFT) };
        let mut nc = c + step;
        loop {
            match self.at(nc, r) {
                Tile::Slope(s) => return Tile::Slope(s).full_faces() & facing != 0,
                Tile::Solid if nc != fc => nc += step,
                _ => return false,
            }
        }
    }
}

/// The shortest push among the candidates whose face is in `faces`; the
/// first one wins ties (candidates are listed vertical first).
#[inline]
fn smallest(cands: &[(u8, IVec2)], faces: u8) -> Option<IVec2> {
    let mut best: Option<IVec2> = None;
    for &(f, m) in cands {
        if faces & f != 0 && best.is_none_or(|b| len(m) < len(b)) {
            best = Some(m);
        }
    }
    best
}

#[inline]
fn len(m: IVec2) -> i64 {
    (m.x as i64).abs() + (m.y as i64).abs()
}
