//! Contacts between any collider shape (circle, segment, oriented box,
//! polygon, point) and the tiles it overlaps: each tile's own shape, tested
//! with the exact pair contact functions, then the internal edge culling.
//!
//! See the [module documentation](super) for the rules.

use glam::{I64Vec2, IVec2};

use super::tile::face::{BOTTOM, LEFT, RIGHT, TOP};
use super::{ContactFlags, Slope, Tile, TileContact, Tilemap};
use crate::query::{Contact, Proximity};
use crate::shape::{Aabb, ConvexPolygon, Segment, Shape};

/// A shape the tilemap can test exactly: it has contact functions against
/// the three tile shapes (a solid tile's box, a slope's polygon, a one-way
/// tile's top segment). Every collider shape kind is one.
pub trait TileShape: Shape + Contact<Aabb> + Contact<ConvexPolygon> + Contact<Segment> {}

impl<T> TileShape for T where T: Shape + Contact<Aabb> + Contact<ConvexPolygon> + Contact<Segment> {}

/// The solid region of a tile, placed: what [`Tilemap::tile_region`] gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TileRegion {
    /// A solid square: the box, centred at `centre`.
    Square {
        /// The tile's box (half extents `T / 2`).
        shape: Aabb,
        /// Its centre in world units.
        centre: IVec2,
    },
    /// A slope: its triangle or trapezoid under the surface line, vertices
    /// relative to `centre` (the tile's centre).
    Slope {
        /// The region under the slope's surface line.
        shape: ConvexPolygon,
        /// The tile's centre in world units.
        centre: IVec2,
    },
    /// A one-way tile: its top line, relative to `origin` (the tile's
    /// top-left corner).
    Top {
        /// The top face, from `(0, 0)` to `(T, 0)`.
        shape: Segment,
        /// The tile's top-left corner in world units.
        origin: IVec2,
    },
}

impl Tilemap {
    /// The solid region of tile `(c, r)` of kind `kind`; `None` for empty
    /// and hazard tiles (a hazard reports a trigger over its whole square).
    ///
    /// Slopes are the polygon under the straight line through their surface
    /// ([`Slope::height`] at the tile's two sides), so a 22.5 degree ramp's
    /// region is up to half a unit above its integer unit-column heights.
    pub fn tile_region(&self, tile: IVec2, kind: Tile) -> Option<TileRegion> {
        let t = self.tile_size();
        let tl = self.col_left(tile.x as i64) as i32;
        let tt = self.row_top(tile.y as i64) as i32;
        let centre = IVec2::new(tl + t / 2, tt + t / 2);
        match kind {
            Tile::Empty | Tile::Hazard => None,
            Tile::Solid => Some(TileRegion::Square {
                shape: Aabb::new(IVec2::splat(t / 2)).ok()?,
                centre,
            }),
            Tile::OneWay => Some(TileRegion::Top {
                shape: Segment::new(IVec2::ZERO, IVec2::new(t, 0)).ok()?,
                origin: IVec2::new(tl, tt),
            }),
            Tile::Slope(s) => Some(TileRegion::Slope {
                shape: slope_polygon(s, t)?,
                centre,
            }),
        }
    }

    /// The box of a hazard tile (the area that reports a trigger).
    fn hazard_box(&self, c: i64, r: i64) -> Option<(Aabb, IVec2)> {
        let t = self.tile_size();
        let centre = IVec2::new(
            (self.col_left(c) + t as i64 / 2) as i32,
            (self.row_top(r) + t as i64 / 2) as i32,
        );
        Some((Aabb::new(IVec2::splat(t / 2)).ok()?, centre))
    }

    /// Appends to `out` one [`TileContact`] for every tile that pushes
    /// `shape` placed at `pos`, and one trigger contact for every hazard tile
    /// it overlaps, in row-major tile order: the exact MTV of the shape out
    /// of the tile's region ([`Tilemap::tile_region`]), kept only when it
    /// leaves through exposed faces (internal edge culling). `moved` is the
    /// body's displacement so far this tick (one-way tiles).
    ///
    /// `out` is not cleared. For axis-aligned boxes use
    /// [`Tilemap::box_contacts`] (the platformer rules: foot on slopes).
    pub fn shape_contacts<S: TileShape>(
        &self,
        shape: &S,
        pos: IVec2,
        moved: IVec2,
        flags: ContactFlags,
        out: &mut Vec<TileContact>,
    ) {
        let (lo, hi) = shape.local_bounds();
        let (lo, hi) = ((pos + lo).as_i64vec2(), (pos + hi).as_i64vec2());
        // Closed ranges: a degenerate shape (a horizontal segment, a point)
        // on a row line still reaches the tile below it; touching tiles are
        // rejected by the exact test.
        let c0 = self.col_of(lo.x).max(0);
        let c1 = self.col_of(hi.x).min(self.width() as i64 - 1);
        let r0 = self.row_of(lo.y).max(0);
        let r1 = self.row_of(hi.y).min(self.height() as i64 - 1);
        for r in r0..=r1 {
            for c in c0..=c1 {
                let kind = self.at(c, r);
                if kind == Tile::Empty {
                    continue;
                }
                let tile = IVec2::new(c as i32, r as i32);
                if let Some(mtv) = self.shape_mtv(tile, kind, shape, pos, moved, flags) {
                    out.push(TileContact { tile, kind, mtv });
                }
            }
        }
    }

    /// The contact [`Tilemap::shape_contacts`] would report for tile `tile`
    /// with the shape at `pos` now (restitution's re-check).
    pub fn shape_tile_contact<S: TileShape>(
        &self,
        tile: IVec2,
        shape: &S,
        pos: IVec2,
        moved: IVec2,
        flags: ContactFlags,
    ) -> Option<TileContact> {
        let kind = self.at(tile.x as i64, tile.y as i64);
        self.shape_mtv(tile, kind, shape, pos, moved, flags)
            .map(|mtv| TileContact { tile, kind, mtv })
    }

    /// The MTV of tile `tile` (of kind `kind`) against the shape, if it
    /// pushes (zero for an overlapped hazard).
    fn shape_mtv<S: TileShape>(
        &self,
        tile: IVec2,
        kind: Tile,
        shape: &S,
        pos: IVec2,
        moved: IVec2,
        flags: ContactFlags,
    ) -> Option<IVec2> {
        let (c, r) = (tile.x as i64, tile.y as i64);
        match kind {
            Tile::Empty => None,
            Tile::Hazard => {
                let (b, centre) = self.hazard_box(c, r)?;
                matches!(shape.contact(pos, &b, centre), Proximity::Overlapping(_))
                    .then_some(IVec2::ZERO)
            }
            Tile::OneWay => {
                if flags.drop_through || moved.y < 0 {
                    return None;
                }
                let t = self.tile_size() as i64;
                let (tl, tt) = (self.col_left(c), self.row_top(r));
                let (slo, shi) = shape.local_bounds();
                let (lo, hi) = ((pos + slo).as_i64vec2(), (pos + shi).as_i64vec2());
                // Solid only for a body that was on or above the line at the
                // start of the tick, now below it, over the tile's columns.
                if hi.y - moved.y as i64 > tt || hi.y <= tt || lo.x >= tl + t || hi.x <= tl {
                    return None;
                }
                let Some(TileRegion::Top { shape: top, origin }) = self.tile_region(tile, kind)
                else {
                    return None;
                };
                match shape.contact(pos, &top, origin).mtv() {
                    Some(m) if m.y < 0 => self.push_ok(tile, kind, m.as_i64vec2()).then_some(m),
                    // Crossed the line this tick (wholly below it now, or a
                    // flat shape), or its centre went below it: the box rule.
                    Some(_) => Some(IVec2::new(0, -((hi.y - tt) as i32))),
                    None if lo.y >= tt => Some(IVec2::new(0, -((hi.y - tt) as i32))),
                    None => None,
                }
            }
            Tile::Solid => {
                let Some(TileRegion::Square { shape: b, centre }) = self.tile_region(tile, kind)
                else {
                    return None;
                };
                let m = shape.contact(pos, &b, centre).mtv()?;
                if self.push_ok(tile, kind, m.as_i64vec2()) {
                    return Some(m);
                }
                // A push with a part through a hidden face: when a slope's
                // full side hides it, the slope holds the shape (the plateau
                // at a ramp's top); else, as for boxes, the shortest push
                // straight out through an exposed face (the shape's bounding
                // box is its exact extent along the axes).
                let hidden_by_slope = |cond: bool, dc: i64, dr: i64| {
                    cond && matches!(self.at(c + dc, r + dr), Tile::Slope(_))
                };
                if hidden_by_slope(m.x < 0, -1, 0)
                    || hidden_by_slope(m.x > 0, 1, 0)
                    || hidden_by_slope(m.y < 0, 0, -1)
                {
                    return None;
                }
                let faces = self.exposed(c, r, kind);
                let t = self.tile_size() as i64;
                let (tl, tt) = (self.col_left(c), self.row_top(r));
                let (slo, shi) = shape.local_bounds();
                let (lo, hi) = ((pos + slo).as_i64vec2(), (pos + shi).as_i64vec2());
                let cands = [
                    (TOP, hi.y - tt, IVec2::NEG_Y),
                    (BOTTOM, tt + t - lo.y, IVec2::Y),
                    (LEFT, hi.x - tl, IVec2::NEG_X),
                    (RIGHT, tl + t - lo.x, IVec2::X),
                ];
                let mut best: Option<(i64, IVec2)> = None;
                for (f, depth, dir) in cands {
                    if faces & f != 0 && depth > 0 && best.is_none_or(|(d, _)| depth < d) {
                        best = Some((depth, dir));
                    }
                }
                best.map(|(d, dir)| dir * d as i32)
            }
            Tile::Slope(_) => {
                let Some(TileRegion::Slope { shape: p, centre }) = self.tile_region(tile, kind)
                else {
                    return None;
                };
                let m = shape.contact(pos, &p, centre).mtv()?;
                self.push_ok(tile, kind, m.as_i64vec2()).then_some(m)
            }
        }
    }

    /// Internal edge culling for a push `m` (or a sweep's hit normal) out of
    /// the region of tile `tile` of kind `kind`: whether it leaves through
    /// faces the neighbours leave exposed.
    ///
    /// * Solid: each non-zero component's face (up: top, ...) must be
    ///   exposed ([`Tile::full_faces`] culling, as for boxes).
    /// * Slope: a downward push needs the bottom exposed; a push towards the
    ///   high side, or level or downward towards the low side, needs that
    ///   side not covered by the neighbour's side (a plateau, the other half
    ///   of a 22.5 degree ramp); a push up towards the low side is the
    ///   surface's, always exposed.
    /// * One-way: a push with a sideways part (over the tile's end) is
    ///   dropped when the tile on that side is one-way or solid: its top
    ///   continues the floor and holds the shape.
    pub(crate) fn push_ok(&self, tile: IVec2, kind: Tile, m: I64Vec2) -> bool {
        let (c, r) = (tile.x as i64, tile.y as i64);
        match kind {
            Tile::Solid => {
                let faces = self.exposed(c, r, kind);
                let through = |cond: bool, f: u8| !cond || faces & f != 0;
                through(m.y < 0, TOP)
                    && through(m.y > 0, BOTTOM)
                    && through(m.x < 0, LEFT)
                    && through(m.x > 0, RIGHT)
            }
            Tile::Slope(s) => {
                if m.y > 0 && self.exposed(c, r, kind) & BOTTOM == 0 {
                    return false;
                }
                let high = if s.rises_right() { m.x > 0 } else { m.x < 0 };
                let low = m.x != 0 && !high;
                !((high || (low && m.y >= 0)) && self.side_hidden(c, r, s, m.x > 0))
            }
            Tile::OneWay => {
                m.x == 0 || !matches!(self.at(c + m.x.signum(), r), Tile::OneWay | Tile::Solid)
            }
            Tile::Empty | Tile::Hazard => true,
        }
    }

    /// Whether the left (`right == false`) or right side of slope tile
    /// `(c, r)` is covered by its neighbour: the neighbour's facing side is
    /// solid at least as high.
    fn side_hidden(&self, c: i64, r: i64, s: Slope, right: bool) -> bool {
        let t = self.tile_size() as i64;
        let own = side_height(Tile::Slope(s), right, t);
        let n = self.at(if right { c + 1 } else { c - 1 }, r);
        own > 0 && side_height(n, !right, t) >= own
    }
}

/// How high from the tile's bottom the left (`right == false`) or right side
/// of a tile is solid, on the surface line.
fn side_height(kind: Tile, right: bool, t: i64) -> i64 {
    match kind {
        Tile::Solid => t,
        Tile::Slope(s) => line_heights(s, t)[right as usize],
        _ => 0,
    }
}

/// The surface line's heights above the tile's bottom at its left and right
/// sides: `Slope::height` at `0` and extended to `T`.
fn line_heights(s: Slope, t: i64) -> [i64; 2] {
    match s {
        Slope::Right45 => [0, t],
        Slope::Left45 => [t, 0],
        Slope::RightLow22 => [0, t / 2],
        Slope::RightHigh22 => [t / 2, t],
        Slope::LeftHigh22 => [t, t / 2],
        Slope::LeftLow22 => [t / 2, 0],
    }
}

/// The region under slope `s`'s surface line, relative to the tile's
/// centre (y down).
fn slope_polygon(s: Slope, t: i32) -> Option<ConvexPolygon> {
    let h = t / 2;
    let [hl, hr] = line_heights(s, t as i64).map(|v| v as i32);
    // Bottom-left, bottom-right, then the surface ends (dropping a zero-height
    // side, which would repeat a bottom corner).
    let mut v = [IVec2::ZERO; 4];
    let mut n = 0;
    v[n] = IVec2::new(-h, h);
    n += 1;
    v[n] = IVec2::new(h, h);
    n += 1;
    if hr > 0 {
        v[n] = IVec2::new(h, h - hr);
        n += 1;
    }
    if hl > 0 {
        v[n] = IVec2::new(-h, h - hl);
        n += 1;
    }
    ConvexPolygon::new(&v[..n]).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::Circle;

    const T: i32 = 4096;

    fn map(rows: &[&str]) -> Tilemap {
        let w = rows[0].len() as u32;
        let tiles = rows
            .iter()
            .flat_map(|r| {
                r.chars().map(|ch| match ch {
                    '#' => Tile::Solid,
                    '=' => Tile::OneWay,
                    '/' => Tile::Slope(Slope::Right45),
                    '\\' => Tile::Slope(Slope::Left45),
                    '^' => Tile::Hazard,
                    _ => Tile::Empty,
                })
            })
            .collect();
        Tilemap::new(IVec2::ZERO, T, w, rows.len() as u32, tiles).unwrap()
    }

    #[test]
    fn slope_polygons_are_valid_and_match_the_heights() {
        for t in [
            2,
            4,
            6,
            4096,
            18 * 256,
            21 * 256,
            24 * 256,
            31 * 256,
            70 * 256,
        ] {
            for s in Slope::ALL {
                let p = slope_polygon(s, t).expect("valid polygon");
                let top = p.vertices().iter().map(|v| v.y).min().unwrap();
                let hmax = line_heights(s, t as i64).into_iter().max().unwrap() as i32;
                assert_eq!(t / 2 - top, hmax, "{s:?} {t}");
            }
        }
    }

    #[test]
    fn a_circle_on_a_floor_seam_is_pushed_up() {
        let m = map(&["...", "###"]);
        let c = Circle::new(1000).unwrap();
        // Centre just right of the seam between tiles 0 and 1, sunk 10 units.
        let pos = IVec2::new(T + 5, T - 1000 + 10);
        let mut out = Vec::new();
        m.shape_contacts(&c, pos, IVec2::ZERO, ContactFlags::default(), &mut out);
        // Both push straight up by the depth: the left tile's corner push
        // has a part through its hidden right face, so it goes through its
        // top instead.
        assert!(!out.is_empty());
        for c in &out {
            assert_eq!(c.mtv, IVec2::new(0, -10), "{out:?}");
        }
    }

    #[test]
    fn one_way_holds_from_above_only() {
        let m = map(&["...", "==="]);
        let c = Circle::new(1000).unwrap();
        let pos = IVec2::new(T + T / 2, T - 1000 + 10);
        let mut out = Vec::new();
        let down = IVec2::new(0, 50);
        m.shape_contacts(&c, pos, down, ContactFlags::default(), &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].mtv, IVec2::new(0, -10));
        out.clear();
        m.shape_contacts(
            &c,
            pos,
            IVec2::new(0, -50),
            ContactFlags::default(),
            &mut out,
        );
        assert!(out.is_empty());
        let drop = ContactFlags { drop_through: true };
        m.shape_contacts(&c, pos, down, drop, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn hazards_are_triggers() {
        let m = map(&["^"]);
        let c = Circle::new(100).unwrap();
        let mut out = Vec::new();
        m.shape_contacts(
            &c,
            IVec2::splat(T / 2),
            IVec2::ZERO,
            ContactFlags::default(),
            &mut out,
        );
        assert_eq!(out.len(), 1);
        assert!(out[0].is_trigger() && out[0].mtv == IVec2::ZERO);
    }

    #[test]
    fn a_circle_on_a_slope_is_pushed_along_its_normal() {
        let m = map(&["/#", "##"]);
        let c = Circle::new(1000).unwrap();
        // On the `/` surface (y = T - x in the tile), sunk a little.
        let x = T / 2;
        let pos = IVec2::new(x - 700, T - x - 700);
        let mut out = Vec::new();
        m.shape_contacts(&c, pos, IVec2::ZERO, ContactFlags::default(), &mut out);
        assert_eq!(out.len(), 1, "{out:?}");
        let mtv = out[0].mtv;
        assert!(
            mtv.x < 0 && mtv.y < 0 && (mtv.x - mtv.y).abs() <= 2,
            "{mtv}"
        );
    }
}
