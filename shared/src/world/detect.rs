//! Detection: every pair of colliders that may interact, tested exactly.
//!
//! Two ways to find the pairs ([`super::BroadPhaseKind`]):
//!
//! * **Strips** ([`detect_broad`], the default): the world's [`BroadPhase`]
//!   holds the colliders of static bodies (indexed once, whenever statics
//!   change) and, refreshed at each detection, those of kinematic and
//!   dynamic bodies (one reused buffer, collider id order, so the update is
//!   incremental). Every pair whose bounding boxes overlap goes through one
//!   closure that applies the pair filters ([`interacts`]) on the colliders'
//!   [`Slot`]s and calls the monomorphised [`Contact`] of the pair's two
//!   kinds through the static table [`NARROW`] (no `match` on kinds, no trait
//!   object). When every collider is a box, the broad phase's AABB fast path
//!   computes the MTV straight from its sorted arrays instead, and the
//!   filters run on its output. Optionally on a rayon pool.
//! * **Brute force** ([`detect_all`]): one generic loop per pair of shape
//!   kinds (21 monomorphised instances, same-kind pairs with `j > i`), a
//!   bounding-box reject, then the narrow phase. The reference.
//!
//! The specialised pipeline adds two shortcuts with the same output:
//! [`detect_small`] tests moving colliders against all colliders directly
//! when the scene is tiny (the broad phase's fixed costs would dominate),
//! and [`redetect`] redoes detection after a restitution pass only around
//! the bodies the pass moved.
//!
//! All give the same records in the same order: sorted by `(smaller
//! collider id, larger collider id)`, each with A the collider of the lower
//! shape kind (of the lower id for equal kinds), exactly as the brute-force
//! loops orient them, so restitution sees identical input.
//!
//! Then [`detect_tiles`] asks the world's tilemap about every solid
//! collider of an enabled dynamic body: boxes through
//! [`Tilemap::box_contacts`], other kinds through
//! [`Tilemap::shape_contacts`]. Tile contacts are records against one
//! static end, [`BodyId::TILEMAP`] (no per-tile collider exists), appended
//! in collider order; the end's `index` says which query made the record
//! ([`tile_mtv`] re-checks through it).

use crate::broad::{Bounds, BroadPhase};
use crate::query::{Contact, Proximity};
use crate::shape::{Aabb, Circle, ConvexPolygon, Obb, Point, Segment, ShapeKind};
use crate::tilemap::{ContactFlags, Tile, TileContact, TileShape, Tilemap};
use glam::IVec2;

use super::body::{Body, BodyKind};
use super::collider::{ColliderData, Colliders, Stored};
use super::config::BroadPhaseKind;
use super::contact::{ContactKind, ContactRecord, End, RecheckFn};
use super::id::{BodyId, TILEMAP_LAYER, TILEMAP_TAG};
use super::layout::{Layout, Slot, TileShapeRef, GONE};

/// Clears `out` and fills it with every overlapping pair that matters
/// (brute force):
///
/// * not two colliders of the same body;
/// * layers and masks agree both ways;
/// * at least one collider is solid (no trigger-trigger pairs);
/// * at least one body is dynamic (static and kinematic bodies never push
///   each other; a trigger reports a dynamic body's solid, and a dynamic
///   body's trigger reports any solid);
/// * both bodies are enabled.
///
/// The output is sorted by collider ids, like [`detect_broad`]'s.
pub(crate) fn detect_all(cols: &Colliders, bodies: &[Body], out: &mut Vec<ContactRecord>) {
    out.clear();
    detect_pair::<Point, Point>(cols, bodies, out);
    detect_pair::<Point, Segment>(cols, bodies, out);
    detect_pair::<Point, Circle>(cols, bodies, out);
    detect_pair::<Point, Aabb>(cols, bodies, out);
    detect_pair::<Point, Obb>(cols, bodies, out);
    detect_pair::<Point, ConvexPolygon>(cols, bodies, out);
    detect_pair::<Segment, Segment>(cols, bodies, out);
    detect_pair::<Segment, Circle>(cols, bodies, out);
    detect_pair::<Segment, Aabb>(cols, bodies, out);
    detect_pair::<Segment, Obb>(cols, bodies, out);
    detect_pair::<Segment, ConvexPolygon>(cols, bodies, out);
    detect_pair::<Circle, Circle>(cols, bodies, out);
    detect_pair::<Circle, Aabb>(cols, bodies, out);
    detect_pair::<Circle, Obb>(cols, bodies, out);
    detect_pair::<Circle, ConvexPolygon>(cols, bodies, out);
    detect_pair::<Aabb, Aabb>(cols, bodies, out);
    detect_pair::<Aabb, Obb>(cols, bodies, out);
    detect_pair::<Aabb, ConvexPolygon>(cols, bodies, out);
    detect_pair::<Obb, Obb>(cols, bodies, out);
    detect_pair::<Obb, ConvexPolygon>(cols, bodies, out);
    detect_pair::<ConvexPolygon, ConvexPolygon>(cols, bodies, out);
    out.sort_unstable_by_key(|c| {
        let (a, b) = (c.a.collider, c.b.collider);
        (a.min(b), a.max(b))
    });
}

/// All pairs of a kind-`A` collider and a kind-`B` collider.
#[inline(never)]
fn detect_pair<A, B>(cols: &Colliders, bodies: &[Body], out: &mut Vec<ContactRecord>)
where
    A: Stored + Contact<B>,
    B: Stored,
{
    let sa = &A::set(cols).items;
    let sb = &B::set(cols).items;
    if sa.is_empty() || sb.is_empty() {
        return;
    }
    // Same kind: one set, each unordered pair once (`j > i`).
    let same = A::KIND == B::KIND;
    for (i, ca) in sa.iter().enumerate() {
        let body_a = &bodies[ca.body as usize];
        if !body_a.enabled {
            continue;
        }
        let pos_a = body_a.pos;
        let (alo, ahi) = (pos_a + ca.lo, pos_a + ca.hi);
        let first = if same { i + 1 } else { 0 };
        for (j, cb) in sb.iter().enumerate().skip(first) {
            if !(ca.dynamic || cb.dynamic) || !(ca.solid || cb.solid) || ca.body == cb.body {
                continue;
            }
            if ca.layer & cb.mask == 0 || cb.layer & ca.mask == 0 {
                continue;
            }
            let body_b = &bodies[cb.body as usize];
            if !body_b.enabled {
                continue;
            }
            let pos_b = body_b.pos;
            let (blo, bhi) = (pos_b + cb.lo, pos_b + cb.hi);
            // Boxes that only touch cannot have overlapping interiors.
            if bhi.x <= alo.x || blo.x >= ahi.x || bhi.y <= alo.y || blo.y >= ahi.y {
                continue;
            }
            let Proximity::Overlapping(mtv) =
                ca.shape
                    .contact(pos_a + ca.offset, &cb.shape, pos_b + cb.offset)
            else {
                continue;
            };
            let ix = (ahi.x.min(bhi.x) as i64 - alo.x.max(blo.x) as i64) as u64;
            let iy = (ahi.y.min(bhi.y) as i64 - alo.y.max(blo.y) as i64) as u64;
            out.push(ContactRecord {
                a: end_of(i, ca),
                b: end_of(j, cb),
                mtv,
                kind: if ca.solid && cb.solid {
                    ContactKind::Solid
                } else {
                    ContactKind::Trigger
                },
                pos_a,
                pos_b,
                area: ix.saturating_mul(iy),
                recheck: recheck::<A, B>,
                tile: IVec2::ZERO,
            });
        }
    }
}

/// The contact end for collider `c` at `index` in its set.
#[inline(always)]
fn end_of<S>(index: usize, c: &ColliderData<S>) -> End {
    End {
        body: c.body,
        collider: c.id,
        index: index as u32,
        tag: c.tag,
        one_way: c.one_way,
        solid: c.solid,
    }
}

/// The narrow phase for one stored pair at the given body positions.
fn recheck<A, B>(cols: &Colliders, ia: u32, pos_a: IVec2, ib: u32, pos_b: IVec2) -> Proximity
where
    A: Stored + Contact<B>,
    B: Stored,
{
    let a = &A::set(cols).items[ia as usize];
    let b = &B::set(cols).items[ib as usize];
    a.shape
        .contact(pos_a + a.offset, &b.shape, pos_b + b.offset)
}

/// `[kind of A][kind of B]`: the narrow phase of every ordered pair of shape
/// kinds, monomorphised ([`recheck`]). The reverse of a mixed pair is its
/// negation by construction, so any orientation gives the exact MTV.
pub(crate) static NARROW: [[RecheckFn; 6]; 6] = {
    macro_rules! row {
        ($a:ty) => {
            [
                recheck::<$a, Point>,
                recheck::<$a, Segment>,
                recheck::<$a, Circle>,
                recheck::<$a, Aabb>,
                recheck::<$a, Obb>,
                recheck::<$a, ConvexPolygon>,
            ]
        };
    }
    [
        row!(Point),
        row!(Segment),
        row!(Circle),
        row!(Aabb),
        row!(Obb),
        row!(ConvexPolygon),
    ]
};

/// The pair filters of [`detect_all`] that need no body: different bodies,
/// at least one dynamic, at least one solid, layers and masks agree both
/// ways.
#[inline(always)]
pub(crate) fn interacts(a: &Slot, b: &Slot) -> bool {
    a.body != b.body
        && (a.dynamic || b.dynamic)
        && (a.solid || b.solid)
        && a.layer & b.mask != 0
        && b.layer & a.mask != 0
}

/// The broad phase and its reused buffers.
#[derive(Debug, Clone)]
pub(crate) struct Detector {
    broad: BroadPhase,
    /// This detection's boxes of the colliders of kinematic and dynamic
    /// bodies, in collider id order.
    items: Vec<(u32, Bounds)>,
    /// The broad phase's output: `(smaller id, larger id, MTV moving the
    /// first)`, sorted.
    pairs: Vec<(u32, u32, IVec2)>,
    /// Incremental re-detection state.
    stale: Stale,
}

/// What incremental re-detection ([`redetect`]) keeps between detections.
#[derive(Debug, Clone, Default)]
struct Stale {
    /// Per body: moved since the broad phase's dynamic set was last updated.
    flag: Vec<bool>,
    /// Those bodies.
    bodies: Vec<u32>,
    /// Their colliders.
    colliders: usize,
    /// Per body: moved by the last restitution pass.
    moved: Vec<bool>,
    /// Candidate pairs `(smaller id, larger id)`.
    cand: Vec<(u32, u32)>,
    /// Stale colliders by left edge: `(min x, id)`.
    sweep: Vec<(i32, u32)>,
    /// New records.
    fresh: Vec<ContactRecord>,
    /// The merged buffer (swapped with the world's).
    next: Vec<ContactRecord>,
}

impl Detector {
    /// An empty detector for `kind` (brute force keeps an unused, empty
    /// broad phase).
    pub fn new(kind: BroadPhaseKind) -> Self {
        let config = kind.broad_config();
        Self {
            broad: BroadPhase::new(config),
            items: Vec::new(),
            pairs: Vec::new(),
            stale: Stale::default(),
        }
    }

    /// Sizes the per-body flags for `n` bodies.
    pub fn fit(&mut self, n: usize) {
        if self.stale.flag.len() < n {
            self.stale.flag.resize(n, false);
            self.stale.moved.resize(n, false);
        }
    }

    /// Forgets the bodies moved since the last update (after an update).
    fn fresh_update(&mut self) {
        let st = &mut self.stale;
        for &b in &st.bodies {
            st.flag[b as usize] = false;
        }
        st.bodies.clear();
        st.colliders = 0;
    }

    /// Indexes the colliders of enabled static bodies (when statics change).
    pub fn set_static(&mut self, slots: &[Slot], bodies: &[Body]) {
        self.items.clear();
        for (id, s) in slots.iter().enumerate() {
            if s.index == GONE {
                continue;
            }
            let b = &bodies[s.body as usize];
            if b.kind == BodyKind::Static && b.enabled {
                self.items.push((id as u32, bounds(s, b.pos)));
            }
        }
        self.broad.set_static(&self.items);
        self.items.clear();
    }

    /// Statistics of the broad phase (for tests and benchmarks).
    pub fn stats(&self) -> crate::broad::BroadPhaseStats {
        self.broad.stats()
    }
}

/// A collider's world bounding box with its body at `pos`.
#[inline(always)]
fn bounds(s: &Slot, pos: IVec2) -> Bounds {
    Bounds::new(pos + s.lo, pos + s.hi)
}

/// What [`detect_broad`] reads.
#[derive(Clone, Copy)]
pub(crate) struct Input<'a> {
    pub slots: &'a [Slot],
    /// Collider ids of kinematic and dynamic bodies, in id order.
    pub moving: &'a [u32],
    pub cols: &'a Colliders,
    pub bodies: &'a [Body],
}

/// Clears `out` and fills it with the same records as [`detect_all`],
/// through the broad phase: the AABB fast path when `aabb_fast` (every
/// collider is a box), else the general narrow-phase dispatch; on the
/// current rayon pool when `par`.
pub(crate) fn detect_broad(
    det: &mut Detector,
    inp: Input<'_>,
    aabb_fast: bool,
    par: bool,
    out: &mut Vec<ContactRecord>,
) {
    out.clear();
    let Input {
        slots,
        moving,
        cols,
        bodies,
    } = inp;
    det.items.clear();
    for &id in moving {
        let s = &slots[id as usize];
        let b = &bodies[s.body as usize];
        if b.enabled {
            det.items.push((id, bounds(s, b.pos)));
        }
    }
    if par {
        det.broad.update_dynamic_par(&det.items);
    } else {
        det.broad.update_dynamic(&det.items);
    }
    det.fresh_update();
    if aabb_fast {
        if par {
            det.broad.contacts_aabb_par(&mut det.pairs);
        } else {
            det.broad.contacts_aabb(&mut det.pairs);
        }
        for &(x, y, m) in &det.pairs {
            let (sx, sy) = (&slots[x as usize], &slots[y as usize]);
            if !interacts(sx, sy) {
                continue;
            }
            let (bx, by) = (&bodies[sx.body as usize], &bodies[sy.body as usize]);
            if bx.enabled && by.enabled {
                out.push(record(x, sx, bx.pos, y, sy, by.pos, m));
            }
        }
        return;
    }
    let narrow = |x: u32, y: u32| -> Option<IVec2> {
        let (sx, sy) = (&slots[x as usize], &slots[y as usize]);
        if !interacts(sx, sy) {
            return None;
        }
        let (bx, by) = (&bodies[sx.body as usize], &bodies[sy.body as usize]);
        if !(bx.enabled && by.enabled) {
            return None;
        }
        NARROW[sx.kind as usize][sy.kind as usize](cols, sx.index, bx.pos, sy.index, by.pos).mtv()
    };
    if par {
        det.broad.contacts_with_par(&narrow, &mut det.pairs);
    } else {
        det.broad.contacts_with(&narrow, &mut det.pairs);
    }
    for &(x, y, m) in &det.pairs {
        let (sx, sy) = (&slots[x as usize], &slots[y as usize]);
        let (px, py) = (bodies[sx.body as usize].pos, bodies[sy.body as usize].pos);
        out.push(record(x, sx, px, y, sy, py, m));
    }
}

/// Clears `out` and fills it with the same records as [`detect_all`] by
/// testing every moving collider against every other collider (each pair
/// once), through the same filters and [`NARROW`] table as
/// [`detect_broad`]: the specialised path of scenes so small that the broad
/// phase's fixed costs exceed the few pair tests (see
/// [`super::layout::SMALL_PAIRS`]).
pub(crate) fn detect_small(inp: Input<'_>, statics: &[u32], out: &mut Vec<ContactRecord>) {
    out.clear();
    let Input {
        slots,
        moving,
        cols,
        bodies,
    } = inp;
    for (k, &x) in moving.iter().enumerate() {
        let sx = &slots[x as usize];
        let bx = &bodies[sx.body as usize];
        if !bx.enabled {
            continue;
        }
        let (xlo, xhi) = (bx.pos + sx.lo, bx.pos + sx.hi);
        // Later moving colliders (ids ascending: x < y), then static ones.
        for &y in moving[k + 1..].iter().chain(statics) {
            let sy = &slots[y as usize];
            if !interacts(sx, sy) {
                continue;
            }
            let by = &bodies[sy.body as usize];
            let (ylo, yhi) = (by.pos + sy.lo, by.pos + sy.hi);
            if !by.enabled || yhi.x <= xlo.x || ylo.x >= xhi.x || yhi.y <= xlo.y || ylo.y >= xhi.y {
                continue;
            }
            let (a, sa, pa, b, sb, pb) = if x < y {
                (x, sx, bx.pos, y, sy, by.pos)
            } else {
                (y, sy, by.pos, x, sx, bx.pos)
            };
            let p = NARROW[sa.kind as usize][sb.kind as usize](cols, sa.index, pa, sb.index, pb);
            if let Some(m) = p.mtv() {
                out.push(record(a, sa, pa, b, sb, pb, m));
            }
        }
    }
    out.sort_unstable_by_key(|c| {
        let (a, b) = (c.a.collider, c.b.collider);
        (a.min(b), a.max(b))
    });
}

/// Re-detection after a restitution pass that moved the bodies `pushed`
/// (sorted, distinct): the same records as a full [`detect_broad`] (then
/// [`detect_tiles`]), computed only around those bodies. Records between
/// bodies that did not move are kept (same positions, same answer); the
/// moved bodies' colliders query the broad phase's static set and the
/// dynamic boxes that are still where the last update put them, and are
/// swept against the other colliders moved since that update; their tile
/// contacts are asked again. The result is merged back into canonical order.
///
/// Returns `false`, doing nothing, when the bodies moved since the last
/// update have more than an eighth of the moving colliders: a full
/// detection is then cheaper.
#[allow(clippy::too_many_arguments)]
pub(crate) fn redetect(
    det: &mut Detector,
    inp: Input<'_>,
    layout: &Layout,
    pushed: &[u32],
    tiles: Option<&Tilemap>,
    scratch: &mut Vec<TileContact>,
    contacts: &mut Vec<ContactRecord>,
) -> bool {
    let Input {
        slots,
        cols,
        bodies,
        ..
    } = inp;
    let limit = (layout.moving.len() / 8).max(8);
    let st = &mut det.stale;
    let mut colliders = st.colliders;
    for &b in pushed {
        if !st.flag[b as usize] {
            colliders += layout.colliders_of(b).len();
        }
    }
    if colliders > limit {
        return false;
    }
    for &b in pushed {
        if !st.flag[b as usize] {
            st.flag[b as usize] = true;
            st.bodies.push(b);
        }
        st.moved[b as usize] = true;
    }
    st.colliders = colliders;
    let here = |id: u32| {
        let s = &slots[id as usize];
        bounds(s, bodies[s.body as usize].pos)
    };
    // Candidates: each moved collider against the static set and the
    // up-to-date dynamic boxes ...
    st.cand.clear();
    for &b in pushed {
        for &x in layout.colliders_of(b) {
            let bx = here(x);
            let cand = &mut st.cand;
            let pair = |y: u32| if x < y { (x, y) } else { (y, x) };
            det.broad.query_static(&bx, |y| cand.push(pair(y)));
            let flag = &st.flag;
            det.broad.query_dynamic(&bx, |y| {
                if !flag[slots[y as usize].body as usize] {
                    cand.push(pair(y));
                }
            });
        }
    }
    // ... and against every collider moved since the update (sort and
    // sweep on x over their current boxes), keeping pairs with a moved one.
    st.sweep.clear();
    for &b in &st.bodies {
        for &x in layout.colliders_of(b) {
            st.sweep.push((here(x).min.x, x));
        }
    }
    st.sweep.sort_unstable();
    for (i, &(_, x)) in st.sweep.iter().enumerate() {
        let bx = here(x);
        let mx = st.moved[slots[x as usize].body as usize];
        for &(minx, y) in &st.sweep[i + 1..] {
            if minx >= bx.max.x {
                break;
            }
            if (mx || st.moved[slots[y as usize].body as usize]) && bx.overlaps(&here(y)) {
                st.cand.push(if x < y { (x, y) } else { (y, x) });
            }
        }
    }
    st.cand.sort_unstable();
    st.cand.dedup();
    // Their records, in canonical order.
    st.fresh.clear();
    for &(x, y) in &st.cand {
        let (sx, sy) = (&slots[x as usize], &slots[y as usize]);
        if !interacts(sx, sy) {
            continue;
        }
        let (bx, by) = (&bodies[sx.body as usize], &bodies[sy.body as usize]);
        if !(bx.enabled && by.enabled) {
            continue;
        }
        let p =
            NARROW[sx.kind as usize][sy.kind as usize](cols, sx.index, bx.pos, sy.index, by.pos);
        if let Some(m) = p.mtv() {
            st.fresh.push(record(x, sx, bx.pos, y, sy, by.pos, m));
        }
    }
    // Merge with the records of bodies that did not move: pairs first ...
    let moved = &st.moved;
    let keep =
        |c: &ContactRecord| !moved[c.a.body as usize] && (c.is_tile() || !moved[c.b.body as usize]);
    let split = contacts
        .iter()
        .position(|c| c.is_tile())
        .unwrap_or(contacts.len());
    let key = |c: &ContactRecord| {
        let (a, b) = (c.a.collider, c.b.collider);
        (a.min(b), a.max(b))
    };
    st.next.clear();
    merge(
        contacts[..split].iter().filter(|c| keep(c)),
        st.fresh.iter(),
        key,
        &mut st.next,
    );
    // ... then tiles, by collider (each collider's tiles are all kept or
    // all asked again).
    if let Some(map) = tiles {
        st.fresh.clear();
        // Boxes and other shapes, merged by collider id.
        let shapes = &layout.tile_shapes;
        let mut j = 0;
        for &i in layout.tile_boxes.iter().chain(core::iter::once(&u32::MAX)) {
            let c = cols.aabbs.items.get(i as usize);
            let id = c.map_or(u32::MAX, |c| c.id);
            while j < shapes.len() && shapes[j].0 < id {
                let sh = shapes[j];
                if moved[slots[sh.0 as usize].body as usize] {
                    tile_shape_of(map, cols, sh, bodies, scratch, &mut st.fresh);
                }
                j += 1;
            }
            if let Some(c) = c.filter(|c| moved[c.body as usize]) {
                tile_box(map, i as usize, c, bodies, scratch, &mut st.fresh);
            }
        }
        merge(
            contacts[split..].iter().filter(|c| keep(c)),
            st.fresh.iter(),
            |c| c.a.collider,
            &mut st.next,
        );
    }
    core::mem::swap(contacts, &mut st.next);
    for &b in pushed {
        st.moved[b as usize] = false;
    }
    true
}

/// Appends the merge of two sequences sorted by `key` (disjoint keys).
fn merge<'a, K: Ord>(
    a: impl Iterator<Item = &'a ContactRecord>,
    b: impl Iterator<Item = &'a ContactRecord>,
    key: impl Fn(&ContactRecord) -> K,
    out: &mut Vec<ContactRecord>,
) {
    let (mut a, mut b) = (a.peekable(), b.peekable());
    loop {
        let next = match (a.peek(), b.peek()) {
            (Some(x), Some(y)) => {
                if key(x) <= key(y) {
                    a.next()
                } else {
                    b.next()
                }
            }
            (Some(_), None) => a.next(),
            (None, Some(_)) => b.next(),
            (None, None) => return,
        };
        out.extend(next.copied());
    }
}

/// The record of colliders `x < y` overlapping with MTV `m` (moving `x`),
/// oriented like [`detect_all`]'s: A is the collider of the lower shape
/// kind, or `x` for equal kinds.
#[inline(always)]
fn record(x: u32, sx: &Slot, px: IVec2, y: u32, sy: &Slot, py: IVec2, m: IVec2) -> ContactRecord {
    let (ia, a, pa, ib, b, pb, m) = if sx.kind <= sy.kind {
        (x, sx, px, y, sy, py, m)
    } else {
        (y, sy, py, x, sx, px, -m)
    };
    let (alo, ahi) = (pa + a.lo, pa + a.hi);
    let (blo, bhi) = (pb + b.lo, pb + b.hi);
    let ix = (ahi.x.min(bhi.x) as i64 - alo.x.max(blo.x) as i64) as u64;
    let iy = (ahi.y.min(bhi.y) as i64 - alo.y.max(blo.y) as i64) as u64;
    ContactRecord {
        a: slot_end(ia, a),
        b: slot_end(ib, b),
        mtv: m,
        kind: if a.solid && b.solid {
            ContactKind::Solid
        } else {
            ContactKind::Trigger
        },
        pos_a: pa,
        pos_b: pb,
        area: ix.saturating_mul(iy),
        recheck: NARROW[a.kind as usize][b.kind as usize],
        tile: IVec2::ZERO,
    }
}

/// The contact end of collider `id`.
#[inline(always)]
fn slot_end(id: u32, s: &Slot) -> End {
    End {
        body: s.body,
        collider: id,
        index: s.index,
        tag: s.tag,
        one_way: s.one_way,
        solid: s.solid,
    }
}

/// The tile query flags of a body.
#[inline]
pub(crate) fn tile_flags(b: &Body) -> ContactFlags {
    ContactFlags {
        drop_through: b.drop_through,
    }
}

/// Appends to `out` one record per tile contact of every solid collider
/// (mask with [`TILEMAP_LAYER`]) of an enabled dynamic body, in collider
/// order then row-major tile order: a solid record for a tile that pushes, a
/// trigger record (zero MTV) for an overlapped hazard. Boxes ask
/// [`Tilemap::box_contacts`] (the platformer rules), other shapes
/// [`Tilemap::shape_contacts`] (exact contacts with each tile's region).
/// `scratch` is reused.
///
/// With `layout` (the specialised pipeline's lists of those colliders: the
/// boxes' set indices and, separately, the other shapes) only they are
/// visited; without, every collider is checked.
pub(crate) fn detect_tiles(
    map: &Tilemap,
    cols: &Colliders,
    bodies: &[Body],
    layout: Option<&Layout>,
    scratch: &mut Vec<TileContact>,
    out: &mut Vec<ContactRecord>,
) {
    let set = &cols.aabbs.items;
    match layout {
        Some(l) => {
            let shapes = &l.tile_shapes;
            let mut j = 0;
            for &i in &l.tile_boxes {
                let c = &set[i as usize];
                while j < shapes.len() && shapes[j].0 < c.id {
                    tile_shape_of(map, cols, shapes[j], bodies, scratch, out);
                    j += 1;
                }
                tile_box(map, i as usize, c, bodies, scratch, out);
            }
            for &sh in &shapes[j..] {
                tile_shape_of(map, cols, sh, bodies, scratch, out);
            }
        }
        None => {
            let mut cur = ShapeCursor::default();
            let mut next = cur.next(cols);
            for (i, c) in set.iter().enumerate() {
                if !(c.dynamic && c.solid && c.mask & TILEMAP_LAYER != 0) {
                    continue;
                }
                while let Some(sh) = next.filter(|sh| sh.0 < c.id) {
                    tile_shape_of(map, cols, sh, bodies, scratch, out);
                    next = cur.next(cols);
                }
                tile_box(map, i, c, bodies, scratch, out);
            }
            while let Some(sh) = next {
                tile_shape_of(map, cols, sh, bodies, scratch, out);
                next = cur.next(cols);
            }
        }
    }
}

/// Whether a collider is asked about tiles: solid, of a dynamic body, mask
/// with [`TILEMAP_LAYER`].
#[inline]
pub(crate) fn touches_tiles<S>(c: &ColliderData<S>) -> bool {
    c.dynamic && c.solid && c.mask & TILEMAP_LAYER != 0
}

/// Walks the non-box colliders that touch tiles in collider id order (a
/// merge of the five sets, each in id order): the brute-force form of
/// [`Layout::tile_shapes`].
#[derive(Default)]
pub(crate) struct ShapeCursor {
    at: [usize; 5],
}

impl ShapeCursor {
    /// The next such collider, if any.
    pub(crate) fn next(&mut self, cols: &Colliders) -> Option<TileShapeRef> {
        fn head<S: Stored>(cols: &Colliders, at: &mut usize) -> Option<u32> {
            let items = &S::set(cols).items;
            while *at < items.len() && !touches_tiles(&items[*at]) {
                *at += 1;
            }
            items.get(*at).map(|c| c.id)
        }
        let heads = [
            (head::<Point>(cols, &mut self.at[0]), ShapeKind::Point),
            (head::<Segment>(cols, &mut self.at[1]), ShapeKind::Segment),
            (head::<Circle>(cols, &mut self.at[2]), ShapeKind::Circle),
            (head::<Obb>(cols, &mut self.at[3]), ShapeKind::Obb),
            (
                head::<ConvexPolygon>(cols, &mut self.at[4]),
                ShapeKind::Polygon,
            ),
        ];
        let (k, (id, kind)) = heads
            .iter()
            .enumerate()
            .filter_map(|(k, &(id, kind))| id.map(|id| (k, (id, kind))))
            .min_by_key(|&(_, (id, _))| id)?;
        let index = self.at[k] as u32;
        self.at[k] += 1;
        Some((id, kind, index))
    }
}

/// The tile contacts of non-box collider `sh`.
#[inline]
pub(crate) fn tile_shape_of(
    map: &Tilemap,
    cols: &Colliders,
    sh: TileShapeRef,
    bodies: &[Body],
    scratch: &mut Vec<TileContact>,
    out: &mut Vec<ContactRecord>,
) {
    fn one<S: Stored + TileShape>(
        map: &Tilemap,
        cols: &Colliders,
        i: u32,
        bodies: &[Body],
        scratch: &mut Vec<TileContact>,
        out: &mut Vec<ContactRecord>,
    ) {
        let c = &S::set(cols).items[i as usize];
        tile_shape(map, i as usize, c, bodies, scratch, out);
    }
    let (_, kind, i) = sh;
    match kind {
        ShapeKind::Point => one::<Point>(map, cols, i, bodies, scratch, out),
        ShapeKind::Segment => one::<Segment>(map, cols, i, bodies, scratch, out),
        ShapeKind::Circle => one::<Circle>(map, cols, i, bodies, scratch, out),
        ShapeKind::Aabb => tile_box(
            map,
            i as usize,
            &cols.aabbs.items[i as usize],
            bodies,
            scratch,
            out,
        ),
        ShapeKind::Obb => one::<Obb>(map, cols, i, bodies, scratch, out),
        ShapeKind::Polygon => one::<ConvexPolygon>(map, cols, i, bodies, scratch, out),
    }
}

/// [`End::index`] of the tilemap end of a tile record: which tile query
/// made it (0: a box, [`Tilemap::box_contacts`]; `1 + kind`: another shape
/// kind, [`Tilemap::shape_contacts`]), so a re-check asks the same one.
#[inline]
fn tile_query_code(kind: ShapeKind) -> u32 {
    if kind == ShapeKind::Aabb {
        0
    } else {
        1 + kind as u32
    }
}

/// The tile contact buffer's capacity once a non-box shape is asked.
const SHAPE_SCRATCH: usize = 64;

/// The tile contacts of non-box collider `c` (index `i` in its set).
fn tile_shape<S: Stored + TileShape>(
    map: &Tilemap,
    i: usize,
    c: &ColliderData<S>,
    bodies: &[Body],
    scratch: &mut Vec<TileContact>,
    out: &mut Vec<ContactRecord>,
) {
    let b = &bodies[c.body as usize];
    if !b.enabled {
        return;
    }
    scratch.clear();
    // A shape may overlap more tiles than any box so far: grow once to a
    // size that covers shapes a few tiles wide, not tick by tick.
    if scratch.capacity() < SHAPE_SCRATCH {
        scratch.reserve(SHAPE_SCRATCH);
    }
    map.shape_contacts(
        &c.shape,
        b.pos + c.offset,
        b.pos - b.start,
        tile_flags(b),
        scratch,
    );
    let centre = b.pos + (c.lo + c.hi) / 2;
    let (lo, hi) = ((b.pos + c.lo).as_i64vec2(), (b.pos + c.hi).as_i64vec2());
    let own = end_of(i, c);
    push_tile_records(
        map,
        own,
        tile_query_code(S::KIND),
        b.pos,
        centre,
        (lo, hi),
        scratch,
        out,
    );
}

/// The MTV of tile record `c` with its body `a` where it is now: the tile
/// query that made the record, asked again about that tile
/// ([`Tilemap::tile_contact`] or [`Tilemap::shape_tile_contact`]), through
/// [`tile_push_ok`]. Restitution's re-check of a stale tile contact.
#[inline]
pub(crate) fn tile_mtv(
    map: &Tilemap,
    cols: &Colliders,
    c: &ContactRecord,
    a: &Body,
) -> Option<IVec2> {
    fn shape<S: Stored + TileShape>(
        map: &Tilemap,
        cols: &Colliders,
        c: &ContactRecord,
        a: &Body,
    ) -> Option<IVec2> {
        let d = &S::set(cols).items[c.a.index as usize];
        let centre = a.pos + (d.lo + d.hi) / 2;
        map.shape_tile_contact(
            c.tile,
            &d.shape,
            a.pos + d.offset,
            a.pos - a.start,
            tile_flags(a),
        )
        .filter(|t| tile_push_ok(map, t.tile, t.kind, centre, t.mtv))
        .map(|t| t.mtv)
    }
    const POINT: u32 = 1 + ShapeKind::Point as u32;
    const SEGMENT: u32 = 1 + ShapeKind::Segment as u32;
    const CIRCLE: u32 = 1 + ShapeKind::Circle as u32;
    const OBB: u32 = 1 + ShapeKind::Obb as u32;
    const POLYGON: u32 = 1 + ShapeKind::Polygon as u32;
    match c.b.index {
        POINT => shape::<Point>(map, cols, c, a),
        SEGMENT => shape::<Segment>(map, cols, c, a),
        CIRCLE => shape::<Circle>(map, cols, c, a),
        OBB => shape::<Obb>(map, cols, c, a),
        POLYGON => shape::<ConvexPolygon>(map, cols, c, a),
        _ => {
            let d = &cols.aabbs.items[c.a.index as usize];
            let centre = a.pos + d.offset;
            map.tile_contact(
                c.tile,
                centre,
                d.shape.half(),
                a.pos - a.start,
                tile_flags(a),
            )
            .filter(|t| tile_push_ok(map, t.tile, t.kind, centre, t.mtv))
            .map(|t| t.mtv)
        }
    }
}

/// The tile contacts of box collider `c` (index `i` in its set).
#[inline]
fn tile_box(
    map: &Tilemap,
    i: usize,
    c: &ColliderData<Aabb>,
    bodies: &[Body],
    scratch: &mut Vec<TileContact>,
    out: &mut Vec<ContactRecord>,
) {
    let b = &bodies[c.body as usize];
    if !b.enabled {
        return;
    }
    let centre = b.pos + c.offset;
    scratch.clear();
    map.box_contacts(
        centre,
        c.shape.half(),
        b.pos - b.start,
        tile_flags(b),
        scratch,
    );
    let (lo, hi) = ((b.pos + c.lo).as_i64vec2(), (b.pos + c.hi).as_i64vec2());
    let own = end_of(i, c);
    push_tile_records(map, own, 0, b.pos, centre, (lo, hi), scratch, out);
}

/// Appends one record per tile contact in `found` of the collider whose end
/// is `own` (body at `pos`, collider centre `centre`, bounds `lo..hi`),
/// skipping pushes [`tile_push_ok`] refuses; `index` says which tile query
/// made them (0: the box query), for the re-check.
#[allow(clippy::too_many_arguments)]
#[inline]
fn push_tile_records(
    map: &Tilemap,
    own: End,
    index: u32,
    pos: IVec2,
    centre: IVec2,
    (lo, hi): (glam::I64Vec2, glam::I64Vec2),
    found: &[TileContact],
    out: &mut Vec<ContactRecord>,
) {
    let t = map.tile_size() as i64;
    let origin = map.origin().as_i64vec2();
    for tc in found {
        if !tile_push_ok(map, tc.tile, tc.kind, centre, tc.mtv) {
            continue;
        }
        let tlo = origin + tc.tile.as_i64vec2() * t;
        let thi = tlo + t;
        let ix = (hi.x.min(thi.x) - lo.x.max(tlo.x)).max(0) as u64;
        let iy = (hi.y.min(thi.y) - lo.y.max(tlo.y)).max(0) as u64;
        let solid = tc.kind != Tile::Hazard;
        out.push(ContactRecord {
            a: own,
            b: End {
                body: BodyId::TILEMAP.0,
                collider: BodyId::TILEMAP.0,
                index,
                tag: TILEMAP_TAG,
                one_way: None,
                solid,
            },
            mtv: tc.mtv,
            kind: if solid {
                ContactKind::Solid
            } else {
                ContactKind::Trigger
            },
            pos_a: pos,
            pos_b: IVec2::ZERO,
            area: ix.saturating_mul(iy),
            recheck: no_recheck,
            tile: tc.tile,
        });
    }
}

/// Whether a tile's push is one the world applies: a [`Tile::Solid`] tile
/// never pushes a box towards its far side, that is, every non-zero MTV
/// component must point from the tile's centre towards the box's centre (or
/// the centres are level on that axis).
///
/// Edge culling can leave a solid tile whose near faces are hidden by its
/// neighbours but whose far faces are exposed (the corner of a one-tile
/// thick floor and wall, a floor tile under a slope on the grid's last row):
/// a box resting against the neighbours dips a few units into it, and its
/// only "way out" is a push of most of a tile through the far face, which
/// largest-MTV-first would apply before the neighbours' small pushes. The
/// neighbours hold the box; this tile must not push it through them.
#[inline]
pub(crate) fn tile_push_ok(
    map: &Tilemap,
    tile: IVec2,
    kind: Tile,
    centre: IVec2,
    mtv: IVec2,
) -> bool {
    if kind != Tile::Solid {
        return true;
    }
    let t = map.tile_size() as i64;
    // Doubled coordinates: the tile centre is a whole number there.
    let tc = (map.origin().as_i64vec2() + tile.as_i64vec2() * t) * 2 + t;
    let bc = centre.as_i64vec2() * 2;
    let ok = |m: i32, b: i64, c: i64| (m <= 0 || b >= c) && (m >= 0 || b <= c);
    ok(mtv.x, bc.x, tc.x) && ok(mtv.y, bc.y, tc.y)
}

/// The re-check slot of a tile record (restitution re-checks tiles through
/// [`Tilemap::tile_contact`] instead; never called).
fn no_recheck(_: &Colliders, _: u32, _: IVec2, _: u32, _: IVec2) -> Proximity {
    Proximity::Apart
}
