//! Restitution: separate overlapping solids, immovable support first, then
//! largest overlap first.
//!
//! One pass walks the contact buffer in the order of
//! [`ContactRecord::order_key`] (contacts with an immovable end first, then
//! `|MTV|^2` descending, then overlap area, then ids; the keys are sorted with
//! the records' indices, the buffer itself keeps its canonical detection
//! order) and for each solid contact:
//!
//! 1. **re-check**: if either body moved since the contact was detected, the
//!    stored MTV is stale; the pair's narrow phase runs again at the current
//!    positions (through the monomorphised function pointer the detector
//!    stored) and the contact is dropped if it no longer overlaps;
//! 2. **covered faces**: a static box never pushes a body out through one of
//!    its faces that another static box covers (a wall box standing on a
//!    floor box has a covered bottom face): such an MTV (a polygon's or a
//!    segment's slanted SAT axis at the seam corner, say) is replaced by the
//!    shallowest push out through an uncovered face, computed from the two
//!    bounding boxes (exact along a box face normal) — the boxes' version of
//!    the tilemap's internal edge culling;
//! 3. **one-way**: a one-way collider only pushes along its normal, and only
//!    a body that came from that side this tick: the depth along the normal
//!    is at most how far the body moved against the normal this tick,
//!    relative to the one-way collider's body (so a platform moving up into
//!    a body resting on it still carries it), plus [`ONE_WAY_SLOP`];
//! 4. **pins and no push-back**: per axis and direction, a body is *pinned*
//!    when it may not move that way: static and kinematic bodies always, a
//!    dynamic body once a push from a pinned or immovable end moved it away
//!    from that end (for the rest of the substep). A pinned body never moves
//!    the pinned way. Otherwise a body never receives a push against the
//!    pushes it already received this tick, *unless* the other end is pinned
//!    along that axis: immovable support overrides a push from a dynamic
//!    body (a box shoved into a wall by another box is pushed back out, and
//!    the shover then takes the whole push);
//! 5. **split**: when both bodies may move along an axis, that component is
//!    split by mass (the lighter body moves more; rounded half away from
//!    zero, and the two shares always sum to the component); when only one
//!    may, it takes the whole component;
//! 6. **velocity**: a moved body loses the velocity component against its
//!    push `d`: `v -= d (v.d) / |d|^2` when `v.d < 0`, each component of the
//!    removed part rounded away from zero (exact for axis pushes);
//! 7. **sides** touched are recorded from the MTV's direction for every
//!    dynamic body of the contact, and every push is logged for events.
//!
//! A pass in which every body it moved moved for the first time this
//! substep, pushed away from a pinned or immovable end, only propagates
//! support up a pile (the floor pushes the bottom box into the next, which
//! the next pass pushes up, ...): it is *propagating* and the caller does not
//! count it against the pass budget ([`PassResult::propagating`]). There are
//! at most as many such passes as dynamic bodies, so a stack of any height
//! settles in one substep, while passes that split pushes between free
//! bodies or move a body again cost what they did.
//!
//! Tile contacts (B is the tilemap, [`super::BodyId::TILEMAP`]) take the same
//! path: B is static, so A takes the whole push; their re-check is
//! [`Tilemap::tile_contact`] at A's current position and displacement, which
//! also applies the tilemap's own one-way rule (one-way tiles are not
//! `OneWay` colliders here). A body flagged to drop through
//! ([`super::World::set_drop_through`]) is never pushed by a one-way
//! collider nor by a one-way tile.
//!
//! Triggers are skipped: they only produce events.

use crate::fixed::{div_away, MAX_SPEED};
use crate::shape::ShapeKind;
use crate::tilemap::Tilemap;
use glam::{I64Vec2, IVec2};

use super::body::{Body, BodyKind, Sides};
use super::collider::{Colliders, OneWay};
use super::contact::{ContactKind, ContactRecord, End, OrderKey};
use super::event::{Hit, TriggerHit};
use super::layout::{Slot, GONE};

/// What re-checks need besides the bodies: the colliders, their slots (for
/// bounding boxes) and the tilemap.
#[derive(Clone, Copy)]
pub(crate) struct Scene<'a> {
    pub cols: &'a Colliders,
    pub slots: &'a [Slot],
    pub tiles: Option<&'a Tilemap>,
}

/// Slack, in units, of the one-way "came from that side" test. MTVs are
/// rounded away from zero (SAT: under one unit per axis; circles: at most
/// two), so the depth an MTV reports can exceed the true depth by up to two
/// units.
pub const ONE_WAY_SLOP: i64 = 2;

/// Bit of direction `s` (`±1`) along axis `k` (0: x, 1: y), for pins and
/// faces: `+x, -x, +y, -y` are bits 0 to 3.
#[inline(always)]
const fn dir_bit(k: usize, s: i32) -> u8 {
    1 << (2 * k + (s < 0) as usize)
}

/// [`Solver`] body state: the body moved this substep.
const MOVED: u8 = 1 << 4;

/// Restitution's reusable state (nothing here allocates per tick once grown).
#[derive(Debug, Clone, Default)]
pub(crate) struct Solver {
    /// Sorted keys and contact indices of the current pass.
    order: Vec<(OrderKey, u32)>,
    /// Per body, this substep: pinned directions ([`dir_bit`]) and [`MOVED`].
    state: Vec<u8>,
    /// Per collider id: the faces ([`dir_bit`] of the outward normal) of a
    /// static box that another static box covers.
    covered: Vec<u8>,
    /// Scratch for [`Solver::cover`]: static boxes `(lo, hi, id)`.
    boxes: Vec<(IVec2, IVec2, u32)>,
}

/// What one pass did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct PassResult {
    /// Some body moved (the contacts must be detected again).
    pub moved: bool,
    /// Every body it moved moved for the first time this substep, pushed
    /// away from a pinned or immovable end: the pass only propagated support
    /// up a pile and does not count against the budget.
    pub propagating: bool,
}

impl Solver {
    /// Recomputes the covered faces of static boxes (whenever statics
    /// change): a face is covered when one other solid, two-way box of an
    /// enabled static body with the same layer and mask lies flush against
    /// it and spans it entirely. Sort and sweep on x.
    pub fn cover(&mut self, slots: &[Slot], bodies: &[Body]) {
        self.covered.clear();
        self.covered.resize(slots.len(), 0);
        self.boxes.clear();
        for (id, s) in slots.iter().enumerate() {
            if s.index == GONE || s.kind != ShapeKind::Aabb || !s.solid || s.one_way.is_some() {
                continue;
            }
            let b = &bodies[s.body as usize];
            if b.kind == BodyKind::Static && b.enabled {
                self.boxes.push((b.pos + s.lo, b.pos + s.hi, id as u32));
            }
        }
        self.boxes.sort_unstable_by_key(|&(lo, _, id)| (lo.x, id));
        for (i, &(alo, ahi, a)) in self.boxes.iter().enumerate() {
            for &(blo, bhi, b) in &self.boxes[i + 1..] {
                if blo.x > ahi.x {
                    break;
                }
                let (sa, sb) = (&slots[a as usize], &slots[b as usize]);
                if sa.layer != sb.layer || sa.mask != sb.mask {
                    continue;
                }
                self.covered[a as usize] |= covered_faces(alo, ahi, blo, bhi);
                self.covered[b as usize] |= covered_faces(blo, bhi, alo, ahi);
            }
        }
        if self.covered.iter().all(|&f| f == 0) {
            // Nothing covered: restitution skips the look-ups.
            self.covered.clear();
        }
    }

    /// Starts a substep's passes: no body pinned or moved yet.
    pub fn begin(&mut self, bodies: usize) {
        self.state.clear();
        self.state.resize(bodies, 0);
    }

    /// Runs one restitution pass over `contacts` in restitution order;
    /// appends every body it moved to `pushed` (possibly more than once).
    pub fn pass(
        &mut self,
        contacts: &[ContactRecord],
        bodies: &mut [Body],
        scene: Scene<'_>,
        hits: &mut Vec<Hit>,
        pushed: &mut Vec<u32>,
    ) -> PassResult {
        let Solver {
            order,
            state,
            covered,
            ..
        } = self;
        order.clear();
        for (i, c) in contacts.iter().enumerate() {
            if c.kind != ContactKind::Solid {
                continue;
            }
            let m = uncovered(covered, c, c.mtv, bodies, scene);
            let class = !immovable_end(c, bodies) as u8;
            order.push((c.order_key(class, m), i as u32));
        }
        // Keys are unique (ids, tile): any sort gives one order.
        order.sort_unstable();
        let mut res = PassResult {
            moved: false,
            propagating: true,
        };
        for &(_, i) in order.iter() {
            let c = &contacts[i as usize];
            let Some(m) = current_mtv(c, bodies, scene) else {
                continue;
            };
            let m = uncovered(covered, c, m, bodies, scene);
            if !one_way_ok(c, m, bodies) {
                continue;
            }
            resolve(c, m, bodies, state, hits, pushed, &mut res);
        }
        res.propagating &= res.moved;
        res
    }

    /// Logs the dynamic bodies of every solid contact that still overlaps
    /// and still applies (one-way) after the last pass.
    pub fn log_squished(
        &self,
        contacts: &[ContactRecord],
        bodies: &[Body],
        scene: Scene<'_>,
        out: &mut Vec<u32>,
    ) {
        for c in contacts {
            if c.kind != ContactKind::Solid {
                continue;
            }
            let Some(m) = current_mtv(c, bodies, scene) else {
                continue;
            };
            let m = uncovered(&self.covered, c, m, bodies, scene);
            if !one_way_ok(c, m, bodies) {
                continue;
            }
            if bodies[c.a.body as usize].is_dynamic() {
                out.push(c.a.body);
            }
            if !c.is_tile() && bodies[c.b.body as usize].is_dynamic() {
                out.push(c.b.body);
            }
        }
    }
}

/// The faces of box `[alo, ahi]` that box `[blo, bhi]` covers: lies flush
/// against and spans entirely.
fn covered_faces(alo: IVec2, ahi: IVec2, blo: IVec2, bhi: IVec2) -> u8 {
    let spans_y = blo.y <= alo.y && ahi.y <= bhi.y;
    let spans_x = blo.x <= alo.x && ahi.x <= bhi.x;
    let mut f = 0;
    if spans_y && blo.x == ahi.x {
        f |= dir_bit(0, 1);
    }
    if spans_y && bhi.x == alo.x {
        f |= dir_bit(0, -1);
    }
    if spans_x && blo.y == ahi.y {
        f |= dir_bit(1, 1);
    }
    if spans_x && bhi.y == alo.y {
        f |= dir_bit(1, -1);
    }
    f
}

/// Whether one end of the contact never moves (static, kinematic, tilemap).
#[inline]
fn immovable_end(c: &ContactRecord, bodies: &[Body]) -> bool {
    c.is_tile()
        || !bodies[c.a.body as usize].is_dynamic()
        || !bodies[c.b.body as usize].is_dynamic()
}

/// A collider's world bounding box.
#[inline]
fn bbox(e: &End, bodies: &[Body], slots: &[Slot]) -> (I64Vec2, I64Vec2) {
    let p = bodies[e.body as usize].pos;
    let s = &slots[e.collider as usize];
    ((p + s.lo).as_i64vec2(), (p + s.hi).as_i64vec2())
}

/// MTV `m` (moving A out of B), unless one end is a static box with covered
/// faces and `m` leaves through one of them: then the shallowest push out
/// through an uncovered face (see the module docs).
#[inline]
fn uncovered(
    covered: &[u8],
    c: &ContactRecord,
    m: IVec2,
    bodies: &[Body],
    scene: Scene<'_>,
) -> IVec2 {
    if covered.is_empty() || c.is_tile() {
        return m;
    }
    let face = |e: &End| covered.get(e.collider as usize).copied().unwrap_or(0);
    let (fa, fb) = (face(&c.a), face(&c.b));
    if fb != 0 {
        let (a, b) = (
            bbox(&c.a, bodies, scene.slots),
            bbox(&c.b, bodies, scene.slots),
        );
        cull(m, fb, a, b)
    } else if fa != 0 {
        let (a, b) = (
            bbox(&c.a, bodies, scene.slots),
            bbox(&c.b, bodies, scene.slots),
        );
        -cull(-m, fa, b, a)
    } else {
        m
    }
}

/// Push `m` moving box-bounded `a` out of box `k` whose covered faces are
/// `faces`: `m` itself unless it leaves through a covered face, else the
/// shallowest push through an uncovered face (first of top, bottom, left,
/// right on ties), else `m`.
fn cull(m: IVec2, faces: u8, a: (I64Vec2, I64Vec2), k: (I64Vec2, I64Vec2)) -> IVec2 {
    let mut through = 0;
    if m.x != 0 {
        through |= dir_bit(0, m.x.signum());
    }
    if m.y != 0 {
        through |= dir_bit(1, m.y.signum());
    }
    if through & faces == 0 {
        return m;
    }
    let ((alo, ahi), (klo, khi)) = (a, k);
    let options = [
        (dir_bit(1, -1), ahi.y - klo.y, IVec2::new(0, -1)),
        (dir_bit(1, 1), khi.y - alo.y, IVec2::new(0, 1)),
        (dir_bit(0, -1), ahi.x - klo.x, IVec2::new(-1, 0)),
        (dir_bit(0, 1), khi.x - alo.x, IVec2::new(1, 0)),
    ];
    let mut best: Option<(i64, IVec2)> = None;
    for (bit, depth, dir) in options {
        if faces & bit != 0 || depth <= 0 {
            continue;
        }
        if best.is_none_or(|(d, _)| depth < d) {
            best = Some((depth, dir));
        }
    }
    // Overlapping boxes: a depth is at most the sum of two widths, < 2^31.
    best.map_or(m, |(d, dir)| dir * d as i32)
}

/// Whether the buffer holds any solid contact.
pub(crate) fn has_solid(contacts: &[ContactRecord]) -> bool {
    contacts.iter().any(|c| c.kind == ContactKind::Solid)
}

/// Logs every trigger contact of the buffer.
pub(crate) fn log_triggers(contacts: &[ContactRecord], out: &mut Vec<TriggerHit>) {
    for c in contacts {
        if c.kind != ContactKind::Trigger {
            continue;
        }
        let (t, o) = if c.a.solid {
            (&c.b, &c.a)
        } else {
            (&c.a, &c.b)
        };
        out.push(TriggerHit {
            body: o.body,
            collider: o.collider,
            trigger_body: t.body,
            trigger: t.collider,
            tag: t.tag,
            other_tag: o.tag,
        });
    }
}

/// The contact's MTV at the bodies' current positions: the stored one if
/// neither body moved since detection, else a fresh narrow phase (for a tile:
/// [`Tilemap::tile_contact`]).
#[inline]
pub(crate) fn current_mtv(c: &ContactRecord, bodies: &[Body], scene: Scene<'_>) -> Option<IVec2> {
    let a = &bodies[c.a.body as usize];
    if c.is_tile() {
        if a.pos == c.pos_a {
            return Some(c.mtv);
        }
        return super::detect::tile_mtv(scene.tiles?, scene.cols, c, a);
    }
    let pa = a.pos;
    let pb = bodies[c.b.body as usize].pos;
    if pa == c.pos_a && pb == c.pos_b {
        Some(c.mtv)
    } else {
        (c.recheck)(scene.cols, c.a.index, pa, c.b.index, pb).mtv()
    }
}

/// Whether the one-way rules (if any) let MTV `m` (moving A out of B) apply.
#[inline]
pub(crate) fn one_way_ok(c: &ContactRecord, m: IVec2, bodies: &[Body]) -> bool {
    if c.a.one_way.is_none() && c.b.one_way.is_none() {
        return true;
    }
    // Tile ends are never one-way colliders: both bodies are real here.
    let (ba, bb) = (&bodies[c.a.body as usize], &bodies[c.b.body as usize]);
    let (da, db) = (displacement(ba), displacement(bb));
    if let Some(dir) = c.b.one_way {
        if ba.drop_through || !one_way_accepts(m, dir, da - db) {
            return false;
        }
    }
    if let Some(dir) = c.a.one_way {
        if bb.drop_through || !one_way_accepts(-m, dir, db - da) {
            return false;
        }
    }
    true
}

/// A one-way collider with side `dir` accepts pushing a body by `m` when `m`
/// points exactly along its normal and the body, which moved by `rel` this
/// tick relative to the collider, came from that side.
#[inline]
fn one_way_accepts(m: IVec2, dir: OneWay, rel: I64Vec2) -> bool {
    let n = dir.normal().as_i64vec2();
    let m = m.as_i64vec2();
    let along = m.dot(n);
    along > 0 && m.perp_dot(n) == 0 && along <= -rel.dot(n) + ONE_WAY_SLOP
}

/// Displacement this tick, in `i64` (a teleport or a huge push can exceed `i32`).
#[inline]
fn displacement(b: &Body) -> I64Vec2 {
    b.pos.as_i64vec2() - b.start.as_i64vec2()
}

/// Applies MTV `m` to the contact's bodies (pins and push-back as in the
/// module docs; `state` holds the pins), noting in `res` whether one moved
/// and whether one moved again this substep.
fn resolve(
    c: &ContactRecord,
    m: IVec2,
    bodies: &mut [Body],
    state: &mut [u8],
    hits: &mut Vec<Hit>,
    pushed: &mut Vec<u32>,
    res: &mut PassResult,
) {
    let (ia, ib) = (c.a.body as usize, c.b.body as usize);
    let tile = c.is_tile();
    let dyn_a = bodies[ia].is_dynamic();
    let push_a = bodies[ia].push.to_array();
    let mass_a = bodies[ia].mass as i128;
    let pins_a = state[ia];
    // The tilemap end is static: never moves, no push, any mass.
    let (dyn_b, push_b, mass_b, pins_b) = if tile {
        (false, [0; 2], 1, 0)
    } else {
        let b = &bodies[ib];
        (b.is_dynamic(), b.push.to_array(), b.mass as i128, state[ib])
    };
    let mv = m.to_array();
    let mut da = [0i32; 2];
    let mut db = [0i32; 2];
    let (mut pin_a, mut pin_b) = (0u8, 0u8);
    // Every axis A (B) moves along, it moves away from a fixed end.
    let (mut held_a, mut held_b) = (true, true);
    for k in 0..2 {
        let mk = mv[k];
        if mk == 0 {
            continue;
        }
        let s = mk.signum();
        // A moves along `s`, B along `-s`. A pinned end never gives way; an
        // unpinned one not against its earlier pushes either, unless the
        // other end is pinned (immovable support wins).
        let fixed_a = !dyn_a || pins_a & dir_bit(k, s) != 0;
        let fixed_b = !dyn_b || pins_b & dir_bit(k, -s) != 0;
        let can_a = !fixed_a && (push_a[k].signum() != -s || fixed_b);
        let can_b = !fixed_b && (push_b[k].signum() != s || fixed_a);
        match (can_a, can_b) {
            (true, true) => {
                let share = div_round(mk as i128 * mass_b, mass_a + mass_b) as i32;
                da[k] = share;
                db[k] = share - mk;
                held_a &= share == 0;
                held_b &= share == mk;
            }
            (true, false) => {
                da[k] = mk;
                if fixed_b {
                    pin_a |= dir_bit(k, -s);
                } else {
                    held_a = false;
                }
            }
            (false, true) => {
                db[k] = -mk;
                if fixed_a {
                    pin_b |= dir_bit(k, s);
                } else {
                    held_b = false;
                }
            }
            (false, false) => {}
        }
    }
    let (da, db) = (IVec2::from_array(da), IVec2::from_array(db));
    if dyn_a {
        bodies[ia].sides |= Sides::from_push(m);
        state[ia] |= pin_a;
    }
    if dyn_b {
        bodies[ib].sides |= Sides::from_push(-m);
        state[ib] |= pin_b;
    }
    if da != IVec2::ZERO {
        apply(&mut bodies[ia], da);
        note_move(&mut state[ia], held_a, res);
        pushed.push(c.a.body);
        hits.push(Hit {
            body: c.a.body,
            collider: c.a.collider,
            other_body: c.b.body,
            other_collider: c.b.collider,
            other_tag: c.b.tag,
            sides: Sides::from_push(m),
        });
    }
    if db != IVec2::ZERO {
        apply(&mut bodies[ib], db);
        note_move(&mut state[ib], held_b, res);
        pushed.push(c.b.body);
        hits.push(Hit {
            body: c.b.body,
            collider: c.b.collider,
            other_body: c.a.body,
            other_collider: c.a.collider,
            other_tag: c.a.tag,
            sides: Sides::from_push(-m),
        });
    }
}

/// Records that a body moved: a second move this substep, or a move that was
/// not a push away from a fixed end (`held`), makes the pass a counted one.
#[inline]
fn note_move(state: &mut u8, held: bool, res: &mut PassResult) {
    res.moved = true;
    if *state & MOVED != 0 || !held {
        res.propagating = false;
    }
    *state |= MOVED;
}

/// Moves a body by push `d`, records the push and removes the velocity
/// against it.
#[inline]
fn apply(b: &mut Body, d: IVec2) {
    b.translate(d);
    b.push = IVec2::new(b.push.x.saturating_add(d.x), b.push.y.saturating_add(d.y));
    b.vel = remove_against(b.vel, d);
}

/// `v - d (v.d) / |d|^2` when `v.d < 0` (else `v`), the removed part rounded
/// away from zero per component, clamped to the speed bound.
#[inline]
pub(crate) fn remove_against(v: IVec2, d: IVec2) -> IVec2 {
    let (vx, vy) = (v.x as i128, v.y as i128);
    let (dx, dy) = (d.x as i128, d.y as i128);
    let vd = vx * dx + vy * dy;
    if vd >= 0 {
        return v;
    }
    let l2 = dx * dx + dy * dy;
    let s = MAX_SPEED as i128;
    let x = (vx - div_away(dx * vd, l2)).clamp(-s, s);
    let y = (vy - div_away(dy * vd, l2)).clamp(-s, s);
    IVec2::new(x as i32, y as i32)
}

/// `num / den` rounded to nearest, halves away from zero; `den > 0`.
#[inline]
fn div_round(num: i128, den: i128) -> i128 {
    let q = num / den;
    let r = num % den;
    if 2 * r.abs() >= den {
        q + num.signum()
    } else {
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn div_round_halves_away_from_zero() {
        assert_eq!(div_round(5, 2), 3);
        assert_eq!(div_round(-5, 2), -3);
        assert_eq!(div_round(4, 3), 1);
        assert_eq!(div_round(-5, 3), -2);
        assert_eq!(div_round(0, 7), 0);
    }

    #[test]
    fn velocity_against_an_axis_push_is_zeroed_exactly() {
        assert_eq!(
            remove_against(IVec2::new(100, 7), IVec2::new(-5, 0)),
            IVec2::new(0, 7)
        );
        assert_eq!(
            remove_against(IVec2::new(-100, 7), IVec2::new(-5, 0)),
            IVec2::new(-100, 7)
        );
        assert_eq!(
            remove_against(IVec2::new(3, 90), IVec2::new(0, -1)),
            IVec2::new(3, 0)
        );
    }

    #[test]
    fn velocity_against_a_slanted_push_leaves_nothing_against_it() {
        for (v, d) in [
            ((100, 0), (-3, -4)),
            ((77, 31), (-1, -1)),
            ((5, 600), (2, -7)),
        ] {
            let (v, d) = (IVec2::from(v), IVec2::from(d));
            let r = remove_against(v, d);
            assert!(r.as_i64vec2().dot(d.as_i64vec2()) >= 0, "{v} {d} -> {r}");
            // Only the normal part changed: the tangential part is kept
            // (up to one unit of rounding per component).
            let t = d.as_i64vec2().perp();
            assert!((r.as_i64vec2().dot(t) - v.as_i64vec2().dot(t)).abs() <= t.x.abs() + t.y.abs());
        }
    }
}
