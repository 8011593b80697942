//! Swept collision in the move phase: a swept body moves to the first time
//! of impact of its colliders against the solid static and kinematic
//! colliders it can collide with and the tilemap, instead of jumping by its
//! whole displacement.
//!
//! Which bodies are swept is [`SweepMode`]'s choice (marked ones, or also
//! fast ones); what a hit does is the body's [`SweepResponse`]. The exact
//! sweeps are [`crate::query::sweep`](mod@crate::query::sweep)'s; this
//! module finds the candidates and applies the outcome:
//!
//! * **Candidates.** Static colliders come from an index of their own (a
//!   [`BroadPhase`] static set, built at the first sweep after the statics
//!   change), queried with the box swept by the collider along its path,
//!   cut into up to [`MAX_CHUNKS`] pieces along a diagonal path so that a
//!   long diagonal shot does not query the whole rectangle it spans; the
//!   pieces are visited in order and the search stops once the best hit
//!   lies before the next piece. Kinematic colliders (few) are all tested,
//!   at their positions after this substep's move. Candidates must be
//!   solid, on another enabled body, and agree on layers both ways.
//! * **Tilemap.** A box collider is swept with [`sweep_tiles`] (the box
//!   rules: culled edges, one-way tiles from above, the foot on slopes);
//!   any other collider (circle, segment, point, oriented box, polygon)
//!   exactly with [`sweep_shape_tiles`]: the pair sweep against each tile's
//!   region near the path (a solid tile's box, a slope's polygon, a one-way
//!   tile's top line, only from above while moving down), hits through
//!   culled internal faces ignored, the same rules as the discrete pass's
//!   [`Tilemap::shape_contacts`].
//! * **One-way colliders** stop a body only when the hit normal has a
//!   positive component along the collider's normal (the body came from
//!   its solid side) and the body is not dropping through.
//! * **Choice.** The hit with the smallest time of impact wins; ties go to
//!   the smaller other collider id (tiles last), then to the body's own
//!   collider id. Hits that start inside an obstacle are left to the
//!   discrete pass.
//! * **Response.** The body moves to the hit's stop position (touching, not
//!   overlapping), its touched sides get the normal's, and its velocity is
//!   slid, zeroed or reflected. `Slide` then continues the rest of the
//!   substep's motion along the surface, up to [`MAX_SWEEPS`] sweeps in
//!   all; `Stop` and `Reflect` drop it.
//! * **Events.** Each hit is reported once ([`Event::SweptHit`]): a hit at
//!   time 0 against one of the surfaces the body's last sweep hit (same
//!   collider, same normal), that is a body resting against it and pushing
//!   again, is not reported; a sweep that moves clear forgets them.
//!
//! Dynamic-dynamic pairs are not swept (the discrete pass handles them), nor
//! are kinematic bodies (they are moved by code and push).

use crate::broad::{Bounds, BroadPhase};
use crate::query::ray::Toi;
use crate::query::sweep::{
    reflect, slide, sweep_shape_tiles, sweep_tiles, Sweep, SweepHit, TileHit,
};
use crate::shape::{Aabb, Circle, ConvexPolygon, Obb, Point, Segment, ShapeKind};
use crate::tilemap::{ContactFlags, Tilemap};
use glam::{I64Vec2, IVec2};

use super::body::{Body, BodyKind, Rest, Sides, SweepResponse, MAX_SWEEPS};
use super::collider::{Colliders, Stored};
use super::config::{BroadPhaseKind, SweepMode};
use super::detect::tile_flags;
use super::event::{Event, Logs};
use super::id::{BodyId, ColliderId, TILEMAP_LAYER, TILEMAP_TAG};
use super::layout::{Layout, Slot, GONE};

/// Most pieces a diagonal path is cut into for the static query.
pub(crate) const MAX_CHUNKS: i64 = 64;

/// Shortest side, in units, of a piece of a diagonal path (256 px).
const CHUNK: i64 = 1 << 16;

/// What the sweeps need besides the bodies, kept between ticks.
#[derive(Debug, Clone, Default)]
pub(crate) struct SweepIndex {
    /// The static index and kinematic list must be rebuilt before use.
    dirty: bool,
    /// Solid colliders of enabled static bodies (built lazily).
    statics: Option<BroadPhase>,
    /// Solid collider ids of kinematic bodies, in id order.
    kinematic: Vec<u32>,
    /// Candidate scratch.
    cand: Vec<u32>,
    /// Static index scratch.
    items: Vec<(u32, Bounds)>,
}

impl SweepIndex {
    /// Marks the index stale (colliders, bodies or statics changed).
    pub fn touch(&mut self) {
        self.dirty = true;
    }

    /// Rebuilds the static set and the kinematic list if stale.
    fn fit(&mut self, kind: BroadPhaseKind, slots: &[Slot], bodies: &[Body]) {
        if !self.dirty && self.statics.is_some() {
            return;
        }
        let config = kind.broad_config();
        let broad = self.statics.get_or_insert_with(|| BroadPhase::new(config));
        self.items.clear();
        self.kinematic.clear();
        for (id, s) in slots.iter().enumerate() {
            if s.index == GONE || !s.solid {
                continue;
            }
            let b = &bodies[s.body as usize];
            match b.kind {
                BodyKind::Static if b.enabled => {
                    // One unit wider: degenerate (zero-width) shapes have an
                    // interior for the query.
                    let lo = b.pos + s.lo - IVec2::ONE;
                    let hi = b.pos + s.hi + IVec2::ONE;
                    self.items.push((id as u32, Bounds::new(lo, hi)));
                }
                BodyKind::Kinematic => self.kinematic.push(id as u32),
                _ => {}
            }
        }
        broad.set_static(&self.items);
        self.items.clear();
        self.dirty = false;
    }
}

/// What a sweep of one body reads.
pub(crate) struct Scene<'a> {
    pub slots: &'a [Slot],
    pub cols: &'a Colliders,
    pub layout: &'a Layout,
    pub tiles: Option<&'a Tilemap>,
}

/// The best hit so far of one sweep.
#[derive(Debug, Clone, Copy)]
struct Best {
    hit: SweepHit,
    /// Position offset of the moving collider from its body.
    offset: IVec2,
    collider: u32,
    other_body: u32,
    other_collider: u32,
    other_tag: u16,
    tile: IVec2,
}

impl Best {
    /// Whether `self` beats `o`: earlier, then smaller other collider id,
    /// then smaller own collider id.
    fn beats(&self, o: &Best) -> bool {
        (self.hit.toi, self.other_collider, self.collider)
            < (o.hit.toi, o.other_collider, o.collider)
    }
}

/// Whether body `b` is swept this substep, moving by `d`.
#[inline]
pub(crate) fn is_swept(mode: SweepMode, b: &Body, d: IVec2) -> bool {
    if b.kind != BodyKind::Dynamic || !b.enabled || d == IVec2::ZERO {
        return false;
    }
    match mode {
        SweepMode::Off => false,
        SweepMode::Flagged => b.swept,
        SweepMode::Auto { min_speed } => {
            b.swept || d.x.unsigned_abs().max(d.y.unsigned_abs()) > min_speed
        }
    }
}

/// Moves swept body `bi` by `d` (its substep share), stopping at the first
/// impact; applies its response and logs the hits.
pub(crate) fn move_swept(
    index: &mut SweepIndex,
    kind: BroadPhaseKind,
    scene: &Scene<'_>,
    bodies: &mut [Body],
    bi: u32,
    d: IVec2,
    logs: &mut Logs,
) {
    index.fit(kind, scene.slots, bodies);
    let mut rest: Rest = [None; MAX_SWEEPS];
    let mut d = d;
    for slot in rest.iter_mut() {
        let Some(best) = first_hit(index, scene, bodies, bi, d) else {
            bodies[bi as usize].translate(d);
            break;
        };
        let b = &mut bodies[bi as usize];
        let start = b.pos;
        let stop = best.hit.stop - best.offset;
        b.translate(stop - start);
        let normal = best.hit.normal.as_ivec2();
        b.sides |= Sides::from_push(normal);
        let key = (best.other_collider, normal);
        let resting = best.hit.toi == Toi::ZERO && b.swept_rest.contains(&Some(key));
        *slot = Some(key);
        if !resting {
            logs.swept_hit(
                bi,
                Event::SweptHit {
                    body: BodyId(bi),
                    collider: ColliderId(best.collider),
                    other_body: BodyId(best.other_body),
                    other_collider: ColliderId(best.other_collider),
                    other_tag: best.other_tag,
                    normal,
                    pos: b.pos,
                    tile: best.tile,
                },
            );
        }
        match b.sweep_response {
            SweepResponse::Stop => {
                b.vel = IVec2::ZERO;
                break;
            }
            SweepResponse::Reflect => {
                b.vel = limit_speed(reflect(b.vel, best.hit.normal), best.hit.normal);
                break;
            }
            SweepResponse::Slide => {
                b.vel = limit_speed(slide(b.vel, best.hit.normal), best.hit.normal);
                let left = d - (b.pos - start);
                d = slide(left, best.hit.normal);
                if d == IVec2::ZERO {
                    break;
                }
            }
        }
    }
    bodies[bi as usize].swept_rest = rest;
}

/// A velocity `v` (slid or reflected off a surface of normal `n`) within
/// the speed bound. Turning a velocity on a slanted surface can push one
/// component past [`crate::fixed::MAX_SPEED`]; it is then scaled down as a
/// whole (same direction) so its largest component is the bound, each
/// component rounded towards the sign of `n`'s, so the result never points
/// more into the surface than `v` did (`v . n` does not decrease).
#[inline]
fn limit_speed(v: IVec2, n: I64Vec2) -> IVec2 {
    let bound = crate::fixed::MAX_SPEED as i128;
    let m = v.x.unsigned_abs().max(v.y.unsigned_abs()) as i128;
    if m <= bound {
        return v;
    }
    let c = |vc: i32, nc: i64| -> i32 {
        let num = vc as i128 * bound;
        (match nc.signum() {
            1 => -(-num).div_euclid(m),
            -1 => num.div_euclid(m),
            _ => num / m,
        }) as i32
    };
    IVec2::new(c(v.x, n.x), c(v.y, n.y))
}

/// The first impact of body `bi` moving by `d` (see the module docs).
fn first_hit(
    index: &mut SweepIndex,
    scene: &Scene<'_>,
    bodies: &[Body],
    bi: u32,
    d: IVec2,
) -> Option<Best> {
    let layout = scene.layout;
    if bi as usize + 1 >= layout.by_body_start.len() {
        return None;
    }
    let body = &bodies[bi as usize];
    let d64 = d.as_i64vec2();
    let mut best: Option<Best> = None;
    let keep = |cand: Best, best: &mut Option<Best>| {
        if best.as_ref().is_none_or(|b| cand.beats(b)) {
            *best = Some(cand);
        }
    };
    for &cid in layout.colliders_of(bi) {
        let a = &scene.slots[cid as usize];
        if !a.solid {
            continue;
        }
        let offset = offset_of(scene.cols, a);
        let start = body.pos + offset;
        // Kinematic colliders: all of them.
        for &oid in &index.kinematic {
            if let Some(c) = against(scene, bodies, body, a, cid, offset, start, d64, oid) {
                keep(c, &mut best);
            }
        }
        // Static colliders: the index, piece by piece along the path.
        if let Some(broad) = &index.statics {
            let m = chunks(d64);
            for j in 0..m {
                if let Some(b) = &best {
                    // Hits in later pieces come after `j / m`.
                    if b.hit.toi < Toi::new(j as u64, m as u64).expect("j < m") {
                        break;
                    }
                }
                let q = piece(body.pos, a, d64, j, m);
                index.cand.clear();
                broad.query_static(&q, |id| index.cand.push(id));
                index.cand.sort_unstable();
                for &oid in &index.cand {
                    if let Some(c) = against(scene, bodies, body, a, cid, offset, start, d64, oid) {
                        keep(c, &mut best);
                    }
                }
            }
        }
        // The tilemap.
        if let Some(map) = scene.tiles {
            if a.mask & TILEMAP_LAYER != 0 {
                if let Some(c) = tiles(map, scene.cols, body, a, cid, offset, d64) {
                    keep(c, &mut best);
                }
            }
        }
    }
    best
}

/// How many pieces the static query cuts path `d` into: one for a path
/// close to an axis, more as the shorter side of its box grows.
#[inline]
fn chunks(d: I64Vec2) -> i64 {
    let short = d.x.abs().min(d.y.abs());
    ((short + CHUNK - 1) / CHUNK).clamp(1, MAX_CHUNKS)
}

/// The box swept by collider `a` of a body at `pos` over piece `j` of `m`
/// of path `d`, one unit wider on each side.
fn piece(pos: IVec2, a: &Slot, d: I64Vec2, j: i64, m: i64) -> Bounds {
    let p0 = pos.as_i64vec2() + d * j / m;
    let p1 = pos.as_i64vec2() + d * (j + 1) / m;
    let lo = p0.min(p1) + a.lo.as_i64vec2() - I64Vec2::ONE;
    let hi = p0.max(p1) + a.hi.as_i64vec2() + I64Vec2::ONE;
    let c = |v: i64| v.clamp(i32::MIN as i64, i32::MAX as i64) as i32;
    Bounds::new(IVec2::new(c(lo.x), c(lo.y)), IVec2::new(c(hi.x), c(hi.y)))
}

/// Collider `a`'s offset from its body.
fn offset_of(cols: &Colliders, a: &Slot) -> IVec2 {
    fn off<S: Stored>(cols: &Colliders, i: u32) -> IVec2 {
        S::set(cols).items[i as usize].offset
    }
    match a.kind {
        ShapeKind::Point => off::<Point>(cols, a.index),
        ShapeKind::Segment => off::<Segment>(cols, a.index),
        ShapeKind::Circle => off::<Circle>(cols, a.index),
        ShapeKind::Aabb => off::<Aabb>(cols, a.index),
        ShapeKind::Obb => off::<Obb>(cols, a.index),
        ShapeKind::Polygon => off::<ConvexPolygon>(cols, a.index),
    }
}

/// The hit of collider `a` (id `cid`) of `body`, its origin at `start`,
/// moving by `d` against collider `oid`, if that one can stop it.
#[allow(clippy::too_many_arguments)]
#[inline]
fn against(
    scene: &Scene<'_>,
    bodies: &[Body],
    body: &Body,
    a: &Slot,
    cid: u32,
    offset: IVec2,
    start: IVec2,
    d: I64Vec2,
    oid: u32,
) -> Option<Best> {
    let o = &scene.slots[oid as usize];
    if o.index == GONE || o.body == a.body || !o.solid {
        return None;
    }
    if a.layer & o.mask == 0 || o.layer & a.mask == 0 {
        return None;
    }
    let ob = &bodies[o.body as usize];
    if !ob.enabled {
        return None;
    }
    let hit = sweep_pair(scene.cols, a, start, d, o, ob.pos)?;
    if hit.started_inside() {
        return None;
    }
    if let Some(dir) = o.one_way {
        let n = dir.normal().as_i64vec2();
        if body.drop_through || hit.normal.dot(n) <= 0 {
            return None;
        }
    }
    Some(Best {
        hit,
        offset,
        collider: cid,
        other_body: o.body,
        other_collider: oid,
        other_tag: o.tag,
        tile: IVec2::ZERO,
    })
}

/// The tile hit of collider `a`: a box by the box rules ([`sweep_tiles`]),
/// any other shape exactly against each tile's region
/// ([`sweep_shape_tiles`]).
fn tiles(
    map: &Tilemap,
    cols: &Colliders,
    body: &Body,
    a: &Slot,
    cid: u32,
    offset: IVec2,
    d: I64Vec2,
) -> Option<Best> {
    fn shaped<S>(
        map: &Tilemap,
        cols: &Colliders,
        i: u32,
        start: IVec2,
        d: I64Vec2,
        f: ContactFlags,
    ) -> Option<TileHit>
    where
        S: Stored + Sweep<Aabb> + Sweep<ConvexPolygon> + Sweep<Segment>,
    {
        sweep_shape_tiles(map, &S::set(cols).items[i as usize].shape, start, d, f)
    }
    let start = body.pos + offset;
    let f = tile_flags(body);
    let i = a.index;
    let th = match a.kind {
        ShapeKind::Aabb => sweep_tiles(map, &cols.aabbs.items[i as usize].shape, start, d, f),
        ShapeKind::Point => shaped::<Point>(map, cols, i, start, d, f),
        ShapeKind::Segment => shaped::<Segment>(map, cols, i, start, d, f),
        ShapeKind::Circle => shaped::<Circle>(map, cols, i, start, d, f),
        ShapeKind::Obb => shaped::<Obb>(map, cols, i, start, d, f),
        ShapeKind::Polygon => shaped::<ConvexPolygon>(map, cols, i, start, d, f),
    }?;
    Some(Best {
        hit: th.hit,
        offset,
        collider: cid,
        other_body: BodyId::TILEMAP.0,
        other_collider: ColliderId::TILEMAP.0,
        other_tag: TILEMAP_TAG,
        tile: th.tile,
    })
}

/// The exact sweep of collider `a` (origin at `start`, moving by `d`)
/// against collider `o` of a body at `o_pos`: one monomorphised kernel per
/// pair of kinds.
fn sweep_pair(
    cols: &Colliders,
    a: &Slot,
    start: IVec2,
    d: I64Vec2,
    o: &Slot,
    o_pos: IVec2,
) -> Option<SweepHit> {
    fn with<A: Stored + Movers>(
        cols: &Colliders,
        i: u32,
        start: IVec2,
        d: I64Vec2,
        o: &Slot,
        o_pos: IVec2,
    ) -> Option<SweepHit> {
        A::set(cols).items[i as usize]
            .shape
            .against_any(cols, start, d, o, o_pos)
    }
    match a.kind {
        ShapeKind::Point => with::<Point>(cols, a.index, start, d, o, o_pos),
        ShapeKind::Segment => with::<Segment>(cols, a.index, start, d, o, o_pos),
        ShapeKind::Circle => with::<Circle>(cols, a.index, start, d, o, o_pos),
        ShapeKind::Aabb => with::<Aabb>(cols, a.index, start, d, o, o_pos),
        ShapeKind::Obb => with::<Obb>(cols, a.index, start, d, o, o_pos),
        ShapeKind::Polygon => with::<ConvexPolygon>(cols, a.index, start, d, o, o_pos),
    }
}

/// A shape that sweeps against every kind.
trait Movers:
    Sized
    + Sweep<Point>
    + Sweep<Segment>
    + Sweep<Circle>
    + Sweep<Aabb>
    + Sweep<Obb>
    + Sweep<ConvexPolygon>
{
    /// The sweep of `self` against collider `o` (dispatched on its kind).
    fn against_any(
        &self,
        cols: &Colliders,
        start: IVec2,
        d: I64Vec2,
        o: &Slot,
        o_pos: IVec2,
    ) -> Option<SweepHit> {
        fn one<A: Sweep<B>, B: Stored>(
            a: &A,
            cols: &Colliders,
            start: IVec2,
            d: I64Vec2,
            i: u32,
            o_pos: IVec2,
        ) -> Option<SweepHit> {
            let c = &B::set(cols).items[i as usize];
            a.sweep(start, d, &c.shape, o_pos + c.offset)
        }
        let i = o.index;
        match o.kind {
            ShapeKind::Point => one::<Self, Point>(self, cols, start, d, i, o_pos),
            ShapeKind::Segment => one::<Self, Segment>(self, cols, start, d, i, o_pos),
            ShapeKind::Circle => one::<Self, Circle>(self, cols, start, d, i, o_pos),
            ShapeKind::Aabb => one::<Self, Aabb>(self, cols, start, d, i, o_pos),
            ShapeKind::Obb => one::<Self, Obb>(self, cols, start, d, i, o_pos),
            ShapeKind::Polygon => one::<Self, ConvexPolygon>(self, cols, start, d, i, o_pos),
        }
    }
}

impl<T> Movers for T where
    T: Sweep<Point>
        + Sweep<Segment>
        + Sweep<Circle>
        + Sweep<Aabb>
        + Sweep<Obb>
        + Sweep<ConvexPolygon>
{
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::MAX_SPEED;

    #[test]
    fn limited_speeds_keep_their_side_of_the_surface() {
        let n = I64Vec2::new(-40, 1);
        let v = IVec2::new(1_713_665, 68_597_698);
        let l = limit_speed(v, n);
        assert_eq!(l.y, MAX_SPEED);
        assert!(l.x > 0 && l.x < v.x);
        assert!(l.as_i64vec2().dot(n) >= 0);
        // Within the bound: unchanged.
        assert_eq!(
            limit_speed(IVec2::new(5, -MAX_SPEED), n),
            IVec2::new(5, -MAX_SPEED)
        );
        for (x, y) in [
            (3, 90_000_001),
            (-90_000_000, 7),
            (-70_000_000, -69_999_999),
        ] {
            let v = IVec2::new(x, y);
            for n in [I64Vec2::new(1, -3), I64Vec2::new(-2, 5), I64Vec2::new(0, 1)] {
                let l = limit_speed(v, n);
                assert!(l.x.abs().max(l.y.abs()) == MAX_SPEED, "{v} {n}: {l}");
                assert!(
                    l.as_i64vec2().dot(n) as f64 / MAX_SPEED as f64
                        >= v.as_i64vec2().dot(n) as f64 / v.x.abs().max(v.y.abs()) as f64 - 1e-9
                );
            }
        }
    }
}
