//! A box swept through the tilemap: an integer DDA over the tiles the box
//! reaches, in time order, each tested exactly; the first hit wins.
//!
//! # Traversal
//! The tiles a moving box touches change only when its leading x edge
//! reaches a column line or its leading y edge a row line. Those events are
//! visited in time order (two exact arithmetic sequences of fractions merged,
//! Amanatides–Woo style); at an event the newly reached column (or row) is
//! tested over the rows (or columns) the closed box spans at that instant.
//! Every tile is tested once, no earlier than the box first touches it, and
//! the walk stops at the first event later than the best hit so far, at the
//! end of the move, or when the box leaves the grid's rectangle: the cost is
//! the number of tiles crossed (clipped to the grid), never the map's size.
//!
//! # Rules: where the contact rules would push the box back
//! The tilemap's contact rules ([`Tilemap::box_contacts`]) decide, for a box
//! at a position, which tiles push it and which way; they do not look at
//! where the box came from. The sweep stops the box at the first instant a
//! tile starts to apply a push **against the motion** (`dot(push, d) < 0`):
//! a tile that would push the box along or across its motion (a ramp
//! lifting a box walking into it, a box sunk into a floor sliding over a
//! seam) is left to the contact pass, as it is at low speed. Per tile kind,
//! from the instant the box starts overlapping it (a tile the box starts
//! overlapping is skipped: overlaps are the contact pass's job):
//!
//! * **solid**: the rules push through the exposed face of least depth
//!   (internal edge culling: a face the neighbour covers with a full face is
//!   not exposed); when the box enters through an exposed face, that face.
//!   So a floor, wall or ceiling of many tiles stops a box only at its outer
//!   surface. The plateau rule (a top face beside a ramp's full high side,
//!   seen from a foot on the ramp's side, does not push) applies;
//! * **slope**: the foot (the box's bottom-centre point) entering the region
//!   below the slope's surface in its column (down to the bottom of the
//!   solid tile under it): the rules push it straight up, so a box moving
//!   down is stopped, with the normal `(0, -1)`, and a box walking into a
//!   ramp is not (it is lifted). Beside the foot, the slope's full high side
//!   (when exposed and the foot is beyond it) and exposed bottom push like a
//!   solid's faces over the rectangle under its highest unit column. A
//!   corner dipping into the triangle is no push. The surface is the line
//!   through the integer heights of [`crate::tilemap::Slope::height`] (for
//!   the 22.5 degree ramps rising to the right, half a unit lower), so that
//!   at every integer foot position "below the line" is exactly "below the
//!   surface"; between integer columns the line may run up to half a unit
//!   above the unit-column steps (a stop up to half a unit early);
//! * **one-way**: moving down, having started the move with the bottom on or
//!   above the top line, not dropping through
//!   ([`ContactFlags::drop_through`]): from when the box straddles the line
//!   and overlaps the tile's columns, unless the foot stands in a slope;
//! * **hazard** and **empty**: never.
//!
//! The normal is the direction of the rules' push. Ties at the same time:
//! the push met most head-on, then the most upward, then the first found.
//! Every face is an integer line and a slope line has integer coefficients:
//! the toi is exact (`den` below 2^36), and the stop position, rounded to the
//! outer side of the surface met, is one the rules do not push back. (A foot
//! entering a column from the left is in it from the column's line on, so
//! there the stop is taken on the path one unit before the line.)
//!
//! Known differences from the contact rules, all on the safe side or left to
//! the contact pass: a push that starts while the box already overlaps a
//! tile (the foot reaching a plateau's column, say) is not a hit; the
//! surface line and the tile regions are continuous, so a diagonal move may
//! be stopped by a corner it clips between two integer positions, or up to
//! half a unit early on a 22.5 degree ramp; under a *floating* slope (empty
//! below), the rules push a box whose body crosses the slope's triangle down
//! through the exposed bottom whatever its motion, which no sweep rule
//! mirrors.

use super::{
    better_normal, check_d, check_end, offset, primitive, round_outer, toi_floor, Sweep, SweepHit,
};
use crate::query::ray::Toi;
use crate::shape::{Aabb, ConvexPolygon, Segment, Shape};
use crate::tilemap::{ContactFlags, Slope, Tile, TileRegion, Tilemap};
use core::cmp::Ordering;
use glam::{I64Vec2, IVec2};

/// Face bits, as [`Tile::full_faces`] reports them (checked by a unit test).
const TOP: u8 = 1;
const BOTTOM: u8 = 2;
const LEFT: u8 = 4;
const RIGHT: u8 = 8;

/// The first tile a box sweep hits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileHit {
    /// The impact (never [`SweepHit::started_inside`]: tiles the box starts
    /// in do not stop it).
    pub hit: SweepHit,
    /// Tile coordinates of the tile hit.
    pub tile: IVec2,
    /// What that tile is.
    pub kind: Tile,
}

/// The first tile that stops the box `shape` (centre at `start`) moving by
/// `d`: the first instant a tile would push it back against its motion under
/// the tilemap's contact rules ([`Tilemap::box_contacts`]): solid tiles
/// through exposed faces, slopes under the foot, one-way tiles from above,
/// hazards never. `flags.drop_through` makes one-way tiles let the box
/// through. See the notes of the [`sweep`](super) module.
///
/// `None` when the whole move is clear; then the box ends at `start + d`.
pub fn sweep_tiles(
    map: &Tilemap,
    shape: &Aabb,
    start: IVec2,
    d: I64Vec2,
    flags: ContactFlags,
) -> Option<TileHit> {
    check_d(d);
    check_end(start, d);
    let s = Sweeper::new(map, shape, start, d, flags);
    let best = s.run()?;
    let toi = toi_floor(best.cand.time.n as u128, best.cand.time.d as u128);
    // A foot entering a column from the left is in it from the column's
    // line on: stop where the centre is at `max_x`, one unit before (on the
    // path, earlier: every point of the path before the hit is clean).
    let at = match best.cand.max_x {
        Some(mx) => {
            debug_assert!(d.x > 0 && mx >= start.x as i64);
            toi_floor((mx - start.x as i64) as u128, d.x as u128)
        }
        None => toi,
    };
    let stop = offset(start, round_outer(d, at, best.cand.round));
    Some(TileHit {
        hit: SweepHit {
            toi,
            normal: best.cand.normal,
            stop,
        },
        tile: IVec2::new(best.tile.0 as i32, best.tile.1 as i32),
        kind: best.kind,
    })
}

/// Largest side, in tiles, of one piece of the path [`sweep_shape_tiles`]
/// tests at a time.
const PIECE_TILES: i64 = 1;

/// The first tile that stops `shape` (any kind; its origin at `start`)
/// moving by `d`: the exact sweep ([`Sweep`]) against the region of each
/// tile near the path ([`Tilemap::tile_region`]: a solid tile's box, a
/// slope's polygon, a one-way tile's top line), keeping a hit only when its
/// normal leaves through exposed faces (the same internal edge culling as
/// [`Tilemap::shape_contacts`]). One-way tiles stop only a shape moving
/// down that started with its bottom on or above their line, and not
/// dropping through; hazards never. Tiles the shape starts inside are left
/// to the contact pass.
///
/// The path is cut into pieces about a tile long along its longer axis,
/// visited in order; each piece tests the tiles its swept bounding box
/// covers (row-major), and the walk stops once the best hit lies before the
/// next piece: the cost follows the tiles crossed, not the map's size. The
/// earliest hit wins; ties go to the smaller `(row, column)`.
///
/// For boxes [`sweep_tiles`] applies the box rules (the foot on slopes).
pub fn sweep_shape_tiles<S>(
    map: &Tilemap,
    shape: &S,
    start: IVec2,
    d: I64Vec2,
    flags: ContactFlags,
) -> Option<TileHit>
where
    S: Shape + Sweep<Aabb> + Sweep<ConvexPolygon> + Sweep<Segment>,
{
    check_d(d);
    check_end(start, d);
    let t = map.tile_size() as i64;
    let (lo, hi) = shape.local_bounds();
    let (lo, hi) = (lo.as_i64vec2(), hi.as_i64vec2());
    let s0 = start.as_i64vec2();
    let long = d.x.abs().max(d.y.abs());
    let m = (long / (t * PIECE_TILES) + 1).max(1);
    let bottom0 = s0.y + hi.y;
    let mut best: Option<TileHit> = None;
    let (w, h) = (map.width() as i64, map.height() as i64);
    for j in 0..m {
        if let Some(b) = &best {
            // Hits in later pieces come after `j / m`.
            if b.hit.toi < Toi::new(j as u64, m as u64).expect("j < m") {
                break;
            }
        }
        let p0 = s0 + d * j / m;
        let p1 = s0 + d * (j + 1) / m;
        let (qlo, qhi) = (p0.min(p1) + lo, p0.max(p1) + hi);
        let c0 = map.col_of(qlo.x - 1).max(0);
        let c1 = map.col_of(qhi.x + 1).min(w - 1);
        let r0 = map.row_of(qlo.y - 1).max(0);
        let r1 = map.row_of(qhi.y + 1).min(h - 1);
        for r in r0..=r1 {
            for c in c0..=c1 {
                let tile = IVec2::new(c as i32, r as i32);
                let kind = map.tile(tile);
                let hit = match (kind, map.tile_region(tile, kind)) {
                    (Tile::Solid, Some(TileRegion::Square { shape: b, centre })) => {
                        shape.sweep(start, d, &b, centre)
                    }
                    (Tile::Slope(_), Some(TileRegion::Slope { shape: p, centre })) => {
                        shape.sweep(start, d, &p, centre)
                    }
                    (Tile::OneWay, Some(TileRegion::Top { shape: top, origin })) => {
                        let tt = origin.y as i64;
                        if flags.drop_through || d.y <= 0 || bottom0 > tt {
                            continue;
                        }
                        shape
                            .sweep(start, d, &top, origin)
                            .filter(|h| h.normal.y < 0)
                    }
                    _ => continue,
                };
                let Some(hit) = hit else { continue };
                if hit.started_inside() || !map.push_ok(tile, kind, hit.normal) {
                    continue;
                }
                let earlier = best.as_ref().is_none_or(|b| {
                    (hit.toi, r, c) < (b.hit.toi, b.tile.y as i64, b.tile.x as i64)
                });
                if earlier {
                    best = Some(TileHit { hit, tile, kind });
                }
            }
        }
    }
    best
}

/// A box against the tilemap with default flags (see [`sweep_tiles`]); the
/// map is placed by its own origin, so `other_pos` is ignored.
impl Sweep<Tilemap> for Aabb {
    #[inline]
    fn sweep(
        &self,
        start: IVec2,
        d: I64Vec2,
        other: &Tilemap,
        _other_pos: IVec2,
    ) -> Option<SweepHit> {
        sweep_tiles(other, self, start, d, ContactFlags::default()).map(|h| h.hit)
    }
}

/// A fraction `n / d`, `d > 0`, ordered exactly.
#[derive(Debug, Clone, Copy)]
struct Frac {
    n: i128,
    d: i128,
}

impl Frac {
    const ZERO: Frac = Frac { n: 0, d: 1 };
    const ONE: Frac = Frac { n: 1, d: 1 };

    #[inline]
    fn new(n: i128, d: i128) -> Frac {
        debug_assert!(d != 0);
        if d < 0 {
            Frac { n: -n, d: -d }
        } else {
            Frac { n, d }
        }
    }

    /// `floor(a + b * self)` for integers `a`, `b`.
    #[inline]
    fn floor_affine(self, a: i64, b: i64) -> i64 {
        (a as i128 * self.d + b as i128 * self.n).div_euclid(self.d) as i64
    }
}

impl PartialEq for Frac {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Frac {}
impl PartialOrd for Frac {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Frac {
    fn cmp(&self, o: &Self) -> Ordering {
        (self.n * o.d).cmp(&(o.n * self.d))
    }
}

/// One tile's hit: when, the normal (the rules' push), the normal of the
/// surface met (for rounding the stop to its outer side), and (for a foot
/// entering a column from the left, where the column starts at the entry
/// point) the centre x to stop at, one unit before.
#[derive(Debug, Clone, Copy)]
struct Cand {
    time: Frac,
    normal: I64Vec2,
    round: I64Vec2,
    max_x: Option<i64>,
}

/// The best hit so far.
#[derive(Debug, Clone, Copy)]
struct Best {
    cand: Cand,
    tile: (i64, i64),
    kind: Tile,
}

/// One sweep's state, in `i64` world units.
struct Sweeper<'a> {
    map: &'a Tilemap,
    t: i64,
    ox: i64,
    oy: i64,
    cols: i64,
    rows: i64,
    /// Box edges and centre at the start.
    l0: i64,
    r0: i64,
    t0: i64,
    b0: i64,
    x0: i64,
    d: I64Vec2,
    drop_through: bool,
    best: Option<Best>,
}

impl<'a> Sweeper<'a> {
    fn new(map: &'a Tilemap, shape: &Aabb, start: IVec2, d: I64Vec2, flags: ContactFlags) -> Self {
        let h = shape.half().as_i64vec2();
        let p = start.as_i64vec2();
        Sweeper {
            map,
            t: map.tile_size() as i64,
            ox: map.origin().x as i64,
            oy: map.origin().y as i64,
            cols: map.width() as i64,
            rows: map.height() as i64,
            l0: p.x - h.x,
            r0: p.x + h.x,
            t0: p.y - h.y,
            b0: p.y + h.y,
            x0: p.x,
            d,
            drop_through: flags.drop_through,
            best: None,
        }
    }

    /// The walk; the best hit.
    fn run(mut self) -> Option<Best> {
        let (dx, dy) = (self.d.x, self.d.y);
        let (mx1, my1) = (self.ox + self.cols * self.t, self.oy + self.rows * self.t);
        // When the closed box touches the grid's rectangle.
        let (ax0, ax1) = touch(self.l0, self.r0, dx, self.ox, mx1)?;
        let (ay0, ay1) = touch(self.t0, self.b0, dy, self.oy, my1)?;
        let (t_in, t_out) = (ax0.max(ay0), ax1.min(ay1));
        if t_in > t_out {
            return None;
        }
        let (c0, c1) = self.col_span(t_in);
        let (r0, r1) = self.row_span(t_in);
        for r in r0.max(0)..=r1.min(self.rows - 1) {
            for c in c0.max(0)..=c1.min(self.cols - 1) {
                self.test(c, r);
            }
        }
        // The next column / row the leading edges reach.
        let mut nc = if dx > 0 { c1 + 1 } else { c0 - 1 };
        let mut nr = if dy > 0 { r1 + 1 } else { r0 - 1 };
        loop {
            let ex = (dx != 0 && (0..self.cols).contains(&nc)).then(|| self.col_time(nc));
            let ey = (dy != 0 && (0..self.rows).contains(&nr)).then(|| self.row_time(nr));
            let (is_x, tau) = match (ex, ey) {
                (Some(a), Some(b)) if a <= b => (true, a),
                (_, Some(b)) => (false, b),
                (Some(a), None) => (true, a),
                (None, None) => break,
            };
            if tau > t_out || self.best.is_some_and(|b| tau > b.cand.time) {
                break;
            }
            if is_x {
                let (ra, rb) = self.row_span(tau);
                for r in ra.max(0)..=rb.min(self.rows - 1) {
                    self.test(nc, r);
                }
                nc += dx.signum();
            } else {
                let (ca, cb) = self.col_span(tau);
                for c in ca.max(0)..=cb.min(self.cols - 1) {
                    self.test(c, nr);
                }
                nr += dy.signum();
            }
        }
        self.best
    }

    /// Columns the closed box spans at `tau` (unclamped).
    fn col_span(&self, tau: Frac) -> (i64, i64) {
        self.span(self.l0, self.r0, self.d.x, self.ox, tau)
    }

    /// Rows the closed box spans at `tau` (unclamped).
    fn row_span(&self, tau: Frac) -> (i64, i64) {
        self.span(self.t0, self.b0, self.d.y, self.oy, tau)
    }

    /// Cells along one axis that the closed interval `lo0..=hi0`, moved by
    /// `d * tau`, spans on a grid of cells `t` wide starting at `origin`:
    /// the cells `k` with `origin + k t + t >= lo` and `origin + k t <= hi`.
    fn span(&self, lo0: i64, hi0: i64, d: i64, origin: i64, tau: Frac) -> (i64, i64) {
        let (t, d) = (self.t as i128, d as i128);
        let lnum = lo0 as i128 * tau.d + d * tau.n - origin as i128 * tau.d;
        let hnum = hi0 as i128 * tau.d + d * tau.n - origin as i128 * tau.d;
        let den = t * tau.d;
        let lo = -(-lnum).div_euclid(den) - 1;
        let hi = hnum.div_euclid(den);
        (lo as i64, hi as i64)
    }

    /// When the leading x edge reaches column `c`'s near line.
    fn col_time(&self, c: i64) -> Frac {
        let left = self.ox + c * self.t;
        if self.d.x > 0 {
            Frac::new((left - self.r0) as i128, self.d.x as i128)
        } else {
            Frac::new((self.l0 - (left + self.t)) as i128, -self.d.x as i128)
        }
    }

    /// When the leading y edge reaches row `r`'s near line.
    fn row_time(&self, r: i64) -> Frac {
        let top = self.oy + r * self.t;
        if self.d.y > 0 {
            Frac::new((top - self.b0) as i128, self.d.y as i128)
        } else {
            Frac::new((self.t0 - (top + self.t)) as i128, -self.d.y as i128)
        }
    }

    /// Tests tile `(c, r)` and keeps its hit if it is the best so far.
    fn test(&mut self, c: i64, r: i64) {
        let kind = self.map.at(c, r);
        let cand = match kind {
            Tile::Empty | Tile::Hazard => None,
            Tile::Solid => {
                let f = self.solid(c, r);
                // A foot sunk into a solid tile right under a slope stands in
                // that slope: the slope's foot rule reaches this tile, which
                // the box may touch without touching the slope's.
                let g = match self.map.at(c, r - 1) {
                    Tile::Slope(s) => self.surface(c, r - 1, s),
                    _ => None,
                };
                match (f, g) {
                    (Some(a), Some(b)) => Some(self.merge(a, b)),
                    (a, b) => a.or(b),
                }
            }
            Tile::OneWay => self.one_way(c, r),
            Tile::Slope(s) => {
                let f = self.slope_faces(c, r, s);
                let g = self.surface(c, r, s);
                match (f, g) {
                    (Some(a), Some(b)) => Some(self.merge(a, b)),
                    (a, b) => a.or(b),
                }
            }
        };
        let Some(mut cand) = cand else {
            return;
        };
        if let Some(b) = self.best {
            if cand.time == b.cand.time {
                // Simultaneous hits: the stop must respect both.
                cand.max_x = min_opt(cand.max_x, b.cand.max_x);
                if !self.earlier(cand, b.cand) {
                    self.best = Some(Best {
                        cand: Cand {
                            max_x: cand.max_x,
                            ..b.cand
                        },
                        ..b
                    });
                    return;
                }
            } else if cand.time > b.cand.time {
                return;
            }
        }
        self.best = Some(Best {
            cand,
            tile: (c, r),
            kind,
        });
    }

    /// The earlier of two candidates (at the same time: the better normal,
    /// with both stop limits).
    fn merge(&self, a: Cand, b: Cand) -> Cand {
        match a.time.cmp(&b.time) {
            Ordering::Less => a,
            Ordering::Greater => b,
            Ordering::Equal => Cand {
                max_x: min_opt(a.max_x, b.max_x),
                ..if self.earlier(b, a) { b } else { a }
            },
        }
    }

    /// Whether `a` comes before `b`: earlier, or at the same time with a
    /// better normal.
    fn earlier(&self, a: Cand, b: Cand) -> bool {
        match a.time.cmp(&b.time) {
            Ordering::Less => true,
            Ordering::Equal => better_normal(a.normal, b.normal, self.d),
            Ordering::Greater => false,
        }
    }

    /// The faces of tile `(c, r)` that push: its full faces not covered by
    /// the neighbour's full face on the same side.
    fn exposed(&self, c: i64, r: i64, kind: Tile) -> u8 {
        let at = |c: i64, r: i64| self.map.at(c, r).full_faces();
        let mut f = kind.full_faces();
        if f & TOP != 0 && at(c, r - 1) & BOTTOM != 0 {
            f &= !TOP;
        }
        if f & BOTTOM != 0 && at(c, r + 1) & TOP != 0 {
            f &= !BOTTOM;
        }
        if f & LEFT != 0 && at(c - 1, r) & RIGHT != 0 {
            f &= !LEFT;
        }
        if f & RIGHT != 0 && at(c + 1, r) & LEFT != 0 {
            f &= !RIGHT;
        }
        f
    }

    /// When the box starts overlapping the open rectangle `rect` (left, top,
    /// right, bottom) within the move, and the faces it enters through;
    /// `None` when it never does or already overlaps it at the start.
    fn entry(&self, rect: (i64, i64, i64, i64)) -> Option<(Frac, u8)> {
        let (xl, yt, xr, yb) = rect;
        let (xin, xout) = slab(self.l0, self.r0, self.d.x, xl, xr)?;
        let (yin, yout) = slab(self.t0, self.b0, self.d.y, yt, yb)?;
        let e = match (xin, yin) {
            (Some(a), Some(b)) => a.max(b),
            (Some(a), None) | (None, Some(a)) => a,
            (None, None) => return None,
        };
        let x = match (xout, yout) {
            (Some(a), Some(b)) => a.min(b),
            (Some(a), None) | (None, Some(a)) => a,
            (None, None) => Frac::ONE,
        };
        if e < Frac::ZERO || e >= x || e >= Frac::ONE {
            return None;
        }
        let mut faces = 0;
        if xin == Some(e) {
            faces |= if self.d.x > 0 { LEFT } else { RIGHT };
        }
        if yin == Some(e) {
            faces |= if self.d.y > 0 { TOP } else { BOTTOM };
        }
        Some((e, faces))
    }

    /// The face the rules push through just after the box enters `rect`
    /// at `e` through `entered`, among `allowed`: an entered one if allowed
    /// (its depth grows from zero; the slower axis is shallower just after
    /// a corner), else the one of least depth at `e`; ties in the rules'
    /// order (up, down, left, right).
    fn push_face(
        &self,
        e: Frac,
        entered: u8,
        allowed: u8,
        rect: (i64, i64, i64, i64),
    ) -> Option<u8> {
        const ORDER: [u8; 4] = [TOP, BOTTOM, LEFT, RIGHT];
        let ent = entered & allowed;
        if ent != 0 {
            let rate = |f: u8| {
                if f & (TOP | BOTTOM) != 0 {
                    self.d.y.abs()
                } else {
                    self.d.x.abs()
                }
            };
            return ORDER
                .into_iter()
                .filter(|f| ent & f != 0)
                .min_by_key(|&f| rate(f));
        }
        // Depths at e, all over e.d.
        let (xl, yt, xr, yb) = rect;
        let at = |v0: i64, v: i64| v0 as i128 * e.d + v as i128 * e.n;
        let (l, r, t, b) = (
            at(self.l0, self.d.x),
            at(self.r0, self.d.x),
            at(self.t0, self.d.y),
            at(self.b0, self.d.y),
        );
        let depth = |f: u8| match f {
            TOP => b - yt as i128 * e.d,
            BOTTOM => yb as i128 * e.d - t,
            LEFT => r - xl as i128 * e.d,
            _ => xr as i128 * e.d - l,
        };
        ORDER
            .into_iter()
            .filter(|f| allowed & f != 0)
            .min_by_key(|&f| depth(f))
    }

    /// A hit pushing through `face` at `e`, if that push is against the
    /// motion.
    fn against(&self, face: u8, e: Frac) -> Option<Cand> {
        let n = match face {
            TOP => I64Vec2::new(0, -1),
            BOTTOM => I64Vec2::new(0, 1),
            LEFT => I64Vec2::new(-1, 0),
            _ => I64Vec2::new(1, 0),
        };
        (n.dot(self.d) < 0).then_some(Cand {
            time: e,
            normal: n,
            round: n,
            max_x: None,
        })
    }

    /// A solid tile: from when the box overlaps it, the push through its
    /// exposed face of least depth (the plateau rule may cancel an upward
    /// one).
    fn solid(&self, c: i64, r: i64) -> Option<Cand> {
        let (tl, tt) = (self.map.col_left(c), self.map.row_top(r));
        let rect = (tl, tt, tl + self.t, tt + self.t);
        let (e, entered) = self.entry(rect)?;
        let face = self.push_face(e, entered, self.exposed(c, r, Tile::Solid), rect)?;
        if face == TOP && self.plateau_of_slope(c, r, self.foot_after(e)) {
            return None;
        }
        self.against(face, e)
    }

    /// A slope's faces, for a box whose foot is not standing in it: its
    /// exposed bottom pushes a box reaching below the tile, its exposed full
    /// high side a box whose foot is beyond that side; both over the
    /// rectangle under its highest unit column (the rules' "solid part" for
    /// such a box).
    fn slope_faces(&self, c: i64, r: i64, s: Slope) -> Option<Cand> {
        let (tl, tt) = (self.map.col_left(c), self.map.row_top(r));
        let (tr, tb) = (tl + self.t, tt + self.t);
        let t = self.t as i32;
        let (hmax, high) = if s.rises_right() {
            (s.height(t - 1, t) as i64, RIGHT)
        } else {
            (s.height(0, t) as i64, LEFT)
        };
        let rect = (tl, tb - hmax, tr, tb);
        let (e, entered) = self.entry(rect)?;
        let exposed = self.exposed(c, r, Tile::Slope(s));
        let fx = self.foot_after(e);
        let beyond = if high == RIGHT { fx >= tr } else { fx < tl };
        let bn = self.b0 as i128 * e.d + self.d.y as i128 * e.n;
        let below = bn > tb as i128 * e.d || (bn == tb as i128 * e.d && self.d.y > 0);
        let mut allowed = 0;
        if beyond {
            allowed |= exposed & high;
        }
        if below || entered & BOTTOM != 0 {
            allowed |= exposed & BOTTOM;
        }
        let face = self.push_face(e, entered, allowed, rect)?;
        self.against(face, e)
    }

    /// The plateau rule: solid tile `(c, r)` is a plateau a slope leads onto,
    /// seen from a foot at x `fx` (only solid tiles between it and a slope
    /// whose full high side faces it, walking towards the foot's column).
    fn plateau_of_slope(&self, c: i64, r: i64, fx: i64) -> bool {
        let fc = self.map.col_of(fx);
        if fc == c {
            return false;
        }
        let (step, facing) = if fc < c { (-1, RIGHT) } else { (1, LEFT) };
        let mut nc = c + step;
        loop {
            match self.map.at(nc, r) {
                s @ Tile::Slope(_) => return s.full_faces() & facing != 0,
                Tile::Solid if nc != fc => nc += step,
                _ => return false,
            }
        }
    }

    /// A one-way tile's top line, from above, moving down.
    fn one_way(&self, c: i64, r: i64) -> Option<Cand> {
        let dy = self.d.y;
        let tt = self.map.row_top(r);
        if self.drop_through || dy <= 0 || self.b0 > tt || tt - self.b0 >= dy {
            return None;
        }
        // The rules push a box that straddles the top line (bottom below
        // it, top above it), overlaps the tile's columns, and started the
        // tick on or above the line: the bottom is below from `below` on,
        // the top above until `top_above`, the columns overlap on (xin, xout).
        let below = Frac::new((tt - self.b0) as i128, dy as i128);
        let top_above = Frac::new((tt - self.t0) as i128, dy as i128);
        let tl = self.map.col_left(c);
        let (xin, xout) = slab(self.l0, self.r0, self.d.x, tl, tl + self.t)?;
        let e = xin.map_or(below, |a| a.max(below));
        // The region ends (open) at x; the move at 1.
        let x = xout.map_or(top_above, |a| a.min(top_above));
        if e >= x || e >= Frac::ONE {
            return None;
        }
        // Not while the foot stands in a slope: from e on, find the first
        // time it does not, stepping over the foot's column changes and the
        // row changes of the cell above it (at most a few: the box overlaps
        // this tile meanwhile).
        let dx = self.d.x;
        let mut t = e;
        let mut max_x = None;
        // Moving right, the foot is in its next column from the line on: a
        // column change exactly at the end of the move still counts.
        while t < x && (t < Frac::ONE || (t == Frac::ONE && max_x.is_some())) {
            let fx = self.foot_after(t);
            let b_after = t.floor_affine(self.b0, dy) + 1;
            if !self.ground_slope(fx, b_after) {
                // Down onto the line; or, having passed beside the tile's
                // end with the bottom already below the line, into its end
                // (the stop is beside it); or the foot leaving a slope over
                // the line. The rules push up.
                let up = I64Vec2::new(0, -1);
                let round = if t == below || t != e {
                    up
                } else {
                    I64Vec2::new(-dx.signum(), 0)
                };
                return Some(Cand {
                    time: t,
                    normal: up,
                    round,
                    max_x,
                });
            }
            // The next column of the foot (moving right, it is in the next
            // column from the line on: the stop stays before it).
            let col = self.map.col_of(fx);
            let tc = match dx.cmp(&0) {
                Ordering::Greater => {
                    let line = self.map.col_left(col + 1);
                    Some((
                        Frac::new((line - self.x0) as i128, dx as i128),
                        Some(line - 1),
                    ))
                }
                Ordering::Less => {
                    let line = self.map.col_left(col);
                    Some((Frac::new((line - self.x0) as i128, dx as i128), None))
                }
                Ordering::Equal => None,
            };
            // The next row of the cell above the foot: the bottom reaching
            // the next row's top.
            let rt = self.map.row_top(self.map.row_of(b_after - 1) + 1);
            let tr = Frac::new((rt - self.b0) as i128, dy as i128);
            match tc {
                Some((tc, mx)) if tc <= tr => {
                    t = tc;
                    max_x = mx;
                }
                _ => {
                    t = tr;
                    max_x = None;
                }
            }
        }
        None
    }

    /// The unit column of the foot just after `tau`.
    fn foot_after(&self, tau: Frac) -> i64 {
        if self.d.x < 0 {
            // ceil(x) - 1
            -tau.floor_affine(-self.x0, -self.d.x) - 1
        } else {
            tau.floor_affine(self.x0, self.d.x)
        }
    }

    /// Whether a foot at `(fx, b)` stands in a slope (the contact rules'
    /// test: the unit cell above the foot is in a slope, or in a solid tile
    /// right under one).
    fn ground_slope(&self, fx: i64, b: i64) -> bool {
        let (c, r) = (self.map.col_of(fx), self.map.row_of(b - 1));
        match self.map.at(c, r) {
            Tile::Slope(_) => true,
            Tile::Solid => matches!(self.map.at(c, r - 1), Tile::Slope(_)),
            _ => false,
        }
    }

    /// The foot rule of slope `(c, r)`: the first instant the foot is in the
    /// slope's column, below its surface line and above the bottom of the
    /// solid tile under it (if any): crossing the line from above, or
    /// entering the column through a side below the line. The rules then
    /// push it straight up, against a motion going down only.
    ///
    /// The line is `g(x, y) = 2 (y - tb) + a (x - tl) + k = 0`, air where
    /// `g < 0`, with `2 h(X) = a X + k` the doubled height over the column
    /// offset `X` (lowered by a half unit for the 22.5 degree ramps rising to
    /// the right).
    fn surface(&self, c: i64, r: i64, s: Slope) -> Option<Cand> {
        let t = self.t;
        let (a, k) = slope_line(s, t);
        let tl = self.map.col_left(c);
        let tr = tl + t;
        let tb = self.map.row_top(r) + t;
        // The foot rule holds while the unit cell above the foot is in the
        // slope tile, or in a solid tile right under it: at integer
        // positions, y <= ylim. The foot moves down (below), so it is in
        // just after an instant only if y < ylim then.
        let ylim = tb
            + if self.map.at(c, r + 1) == Tile::Solid {
                t
            } else {
                0
            };
        let (a, k) = (a as i128, k as i128);
        let (dx, dy) = (self.d.x as i128, self.d.y as i128);
        let g0 = 2 * (self.b0 - tb) as i128 + a * (self.x0 - tl) as i128 + k;
        let kk = 2 * dy + a * dx;
        // The rules push the foot straight up: against a motion going down.
        if dy <= 0 {
            return None;
        }
        let up = I64Vec2::new(0, -1);
        let mut best: Option<Cand> = None;
        // (a) Crossing the line from above. Reaching it only at the end
        // (t = 1) is a touch, not a hit.
        if g0 <= 0 && kk > 0 && -g0 < kk {
            // The foot's x at the crossing (times kk: x0 kk - g0 dx) must be
            // in the column [tl, tr) just after it: a foot meeting the line
            // exactly on the column's edge and moving into the column is
            // below the surface there.
            let fx = self.x0 as i128 * kk - g0 * dx;
            let (l, r) = (tl as i128 * kk, tr as i128 * kk);
            let in_l = fx > l || (fx == l && dx >= 0);
            let in_r = fx < r || (fx == r && dx < 0);
            let fy = self.b0 as i128 * kk - g0 * dy;
            if in_l && in_r && fy < ylim as i128 * kk {
                best = Some(Cand {
                    time: Frac::new(-g0, kk),
                    normal: up,
                    round: primitive(I64Vec2::new(-a as i64, -2)),
                    max_x: None,
                });
            }
        }
        // (b, c) Entering the column through its side while below the line
        // (a step: a ramp's half-height side with no ramp beyond it).
        // The column is [tl, tr): from the left the foot is in it at x = tl
        // (so not at the start, possibly at the end); from the right just
        // after x = tr (possibly at the start, not at the end).
        let side = |edge: i64| -> Option<Frac> {
            let n = (edge - self.x0) as i128;
            let ok = if dx > 0 {
                n > 0 && n <= dx
            } else {
                dx < 0 && n <= 0 && n > dx
            };
            if !ok {
                return None;
            }
            let tau = Frac::new(n, dx);
            // 2 y(tau) tau.d against the line at the edge, and the limit.
            let y2 = 2 * (self.b0 as i128 * tau.d + dy * tau.n);
            let g = y2 - 2 * tb as i128 * tau.d + (a * (edge - tl) as i128 + k) * tau.d;
            // From the left the foot is in the column at the instant itself
            // (y <= ylim will do); from the right only just after (y < ylim).
            let lim = 2 * ylim as i128 * tau.d;
            (g > 0 && (y2 < lim || (y2 == lim && dx > 0))).then_some(tau)
        };
        let sides = if dx > 0 {
            side(tl).map(|tau| Cand {
                time: tau,
                normal: up,
                round: I64Vec2::new(-1, 0),
                // The foot is in the column from x = tl on: stop before.
                max_x: Some(tl - 1),
            })
        } else {
            side(tr).map(|tau| Cand {
                time: tau,
                normal: up,
                round: I64Vec2::new(1, 0),
                max_x: None,
            })
        };
        match (best, sides) {
            (Some(b), Some(s)) => Some(self.merge(b, s)),
            (b, s) => b.or(s),
        }
    }
}

/// The smaller of two optional limits.
#[inline]
fn min_opt(a: Option<i64>, b: Option<i64>) -> Option<i64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// The times in `[0, 1]` when the closed interval `[lo0, hi0] + t v` touches
/// `[a, b]`.
fn touch(lo0: i64, hi0: i64, v: i64, a: i64, b: i64) -> Option<(Frac, Frac)> {
    let (lo, hi) = match v.cmp(&0) {
        Ordering::Equal => {
            return (hi0 >= a && lo0 <= b).then_some((Frac::ZERO, Frac::ONE));
        }
        // hi(t) >= a from (a - hi0) / v on; lo(t) <= b until (b - lo0) / v.
        Ordering::Greater => (
            Frac::new((a - hi0) as i128, v as i128),
            Frac::new((b - lo0) as i128, v as i128),
        ),
        Ordering::Less => (
            Frac::new((lo0 - b) as i128, -v as i128),
            Frac::new((hi0 - a) as i128, -v as i128),
        ),
    };
    let (lo, hi) = (lo.max(Frac::ZERO), hi.min(Frac::ONE));
    (lo <= hi).then_some((lo, hi))
}

/// The open overlap of `(lo0, hi0) + t v` with `(a, b)` along one axis:
/// `(entry, exit)` times (`None`: unbounded, for a motionless axis that
/// overlaps), or `None` when a motionless axis never overlaps. Times may be
/// negative or beyond 1.
#[allow(clippy::type_complexity)]
fn slab(lo0: i64, hi0: i64, v: i64, a: i64, b: i64) -> Option<(Option<Frac>, Option<Frac>)> {
    match v.cmp(&0) {
        Ordering::Equal => (lo0 < b && hi0 > a).then_some((None, None)),
        Ordering::Greater => Some((
            Some(Frac::new((a - hi0) as i128, v as i128)),
            Some(Frac::new((b - lo0) as i128, v as i128)),
        )),
        Ordering::Less => Some((
            Some(Frac::new((lo0 - b) as i128, -v as i128)),
            Some(Frac::new((hi0 - a) as i128, -v as i128)),
        )),
    }
}

/// The surface line of slope `s` on tiles `t` wide: `(a, k)` with
/// `2 h(X) = a X + k` the doubled height over the column offset `X`
/// (lowered by a half unit for the 22.5 degree ramps rising to the right),
/// so that below the line is below the surface at integer points.
fn slope_line(s: Slope, t: i64) -> (i64, i64) {
    match s {
        Slope::Right45 => (2, 0),
        Slope::Left45 => (-2, 2 * t),
        Slope::RightLow22 => (1, -1),
        Slope::RightHigh22 => (1, t - 1),
        Slope::LeftHigh22 => (-1, 2 * t),
        Slope::LeftLow22 => (-1, t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_bits_match_the_tilemap() {
        assert_eq!(Tile::Solid.full_faces(), TOP | BOTTOM | LEFT | RIGHT);
        assert_eq!(Tile::Slope(Slope::Right45).full_faces(), BOTTOM | RIGHT);
        assert_eq!(Tile::Slope(Slope::Left45).full_faces(), BOTTOM | LEFT);
        assert_eq!(Tile::Slope(Slope::RightLow22).full_faces(), BOTTOM);
        assert_eq!(Tile::OneWay.full_faces(), 0);
    }

    #[test]
    fn slope_lines_match_the_heights() {
        // At every integer column offset, 2 h(X) >= a X + k (the line is at
        // or below the surface) and the difference is at most one (half a
        // unit): "below the line" is "below the surface" at integer points.
        // Any even tile size, power of two or not.
        for t in [2i64, 6, 64, 70, 18 * 256, 21 * 256] {
            for s in Slope::ALL {
                let (a, k) = slope_line(s, t);
                for x in 0..t {
                    let h2 = 2 * s.height(x as i32, t as i32) as i64;
                    let line = a * x + k;
                    assert!(
                        h2 >= line && h2 - line <= 1,
                        "{s:?} at {x}, T {t}: {h2} vs {line}"
                    );
                }
            }
        }
    }
}
