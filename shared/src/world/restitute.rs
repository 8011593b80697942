//! Restitution: separate overlapping solids, largest overlap first.
//!
//! One pass walks the contact buffer in the order of
//! [`ContactRecord::order_key`] (`|MTV|^2` descending, then overlap area,
//! then ids; the keys are sorted with the records' indices, the buffer
//! itself keeps its canonical detection order) and for each solid contact:
//!
//! 1. **re-check**: if either body moved since the contact was detected, the
//!    stored MTV is stale; the pair's narrow phase runs again at the current
//!    positions (through the monomorphised function pointer the detector
//!    stored) and the contact is dropped if it no longer overlaps;
//! 2. **one-way**: a one-way collider only pushes along its normal, and only
//!    a body that came from that side this tick: the depth along the normal
//!    is at most how far the body moved against the normal this tick,
//!    relative to the one-way collider's body (so a platform moving up into
//!    a body resting on it still carries it), plus [`ONE_WAY_SLOP`];
//! 3. **no push-back**: per axis, a body never receives a push against the
//!    pushes it already received this tick (that MTV component is zeroed for
//!    it); static and kinematic bodies never move;
//! 4. **split**: when both bodies may move along an axis, that component is
//!    split by mass (the lighter body moves more; rounded half away from
//!    zero, and the two shares always sum to the component); when only one
//!    may, it takes the whole component;
//! 5. **velocity**: a moved body loses the velocity component against its
//!    push `d`: `v -= d (v.d) / |d|^2` when `v.d < 0`, each component of the
//!    removed part rounded away from zero (exact for axis pushes);
//! 6. **sides** touched are recorded from the MTV's direction for every
//!    dynamic body of the contact, and every push is logged for events.
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
use crate::tilemap::Tilemap;
use glam::{I64Vec2, IVec2};

use super::body::{Body, Sides};
use super::collider::{Colliders, OneWay};
use super::contact::{ContactKind, ContactRecord};
use super::detect::{tile_flags, tile_push_ok};
use super::event::{Hit, TriggerHit};

/// What re-checks need besides the bodies: the colliders and the tilemap.
#[derive(Clone, Copy)]
pub(crate) struct Scene<'a> {
    pub cols: &'a Colliders,
    pub tiles: Option<&'a Tilemap>,
}

/// Slack, in units, of the one-way "came from that side" test. MTVs are
/// rounded away from zero (SAT: under one unit per axis; circles: at most
/// two), so the depth an MTV reports can exceed the true depth by up to two
/// units.
pub const ONE_WAY_SLOP: i64 = 2;

/// A contact's place in the restitution order ([`ContactRecord::order_key`]).
pub(crate) type OrderKey = (
    core::cmp::Reverse<u64>,
    core::cmp::Reverse<u64>,
    u32,
    u32,
    i32,
    i32,
);

/// Runs one restitution pass over `contacts` in restitution order (`order`
/// is scratch for the sorted keys); returns whether any body moved, and
/// appends every body it moved to `pushed` (possibly more than once).
pub(crate) fn pass(
    contacts: &[ContactRecord],
    order: &mut Vec<(OrderKey, u32)>,
    bodies: &mut [Body],
    scene: Scene<'_>,
    hits: &mut Vec<Hit>,
    pushed: &mut Vec<u32>,
) -> bool {
    order.clear();
    order.extend(
        contacts
            .iter()
            .enumerate()
            .filter(|(_, c)| c.kind == ContactKind::Solid)
            .map(|(i, c)| (c.order_key(), i as u32)),
    );
    // Keys are unique (ids, tile): any sort gives one order.
    order.sort_unstable();
    let mut moved = false;
    for &(_, i) in order.iter() {
        let c = &contacts[i as usize];
        let Some(m) = current_mtv(c, bodies, scene) else {
            continue;
        };
        if !one_way_ok(c, m, bodies) {
            continue;
        }
        moved |= resolve(c, m, bodies, hits, pushed);
    }
    moved
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

/// Logs the dynamic bodies of every solid contact that still overlaps and
/// still applies (one-way) after the last pass.
pub(crate) fn log_squished(
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
        let d = &scene.cols.aabbs.items[c.a.index as usize];
        let map = scene.tiles?;
        let centre = a.pos + d.offset;
        return map
            .tile_contact(
                c.tile,
                centre,
                d.shape.half(),
                a.pos - a.start,
                tile_flags(a),
            )
            .filter(|t| tile_push_ok(map, t.tile, t.kind, centre, t.mtv))
            .map(|t| t.mtv);
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

/// Applies MTV `m` to the contact's bodies; returns whether one moved.
fn resolve(
    c: &ContactRecord,
    m: IVec2,
    bodies: &mut [Body],
    hits: &mut Vec<Hit>,
    pushed: &mut Vec<u32>,
) -> bool {
    let (ia, ib) = (c.a.body as usize, c.b.body as usize);
    let tile = c.is_tile();
    let dyn_a = bodies[ia].is_dynamic();
    let push_a = bodies[ia].push.to_array();
    let mass_a = bodies[ia].mass as i128;
    // The tilemap end is static: never moves, no push, any mass.
    let (dyn_b, push_b, mass_b) = if tile {
        (false, [0; 2], 1)
    } else {
        let b = &bodies[ib];
        (b.is_dynamic(), b.push.to_array(), b.mass as i128)
    };
    let mv = m.to_array();
    let mut da = [0i32; 2];
    let mut db = [0i32; 2];
    for k in 0..2 {
        let mk = mv[k];
        if mk == 0 {
            continue;
        }
        let s = mk.signum();
        // A moves along `s`, B along `-s`; neither against its earlier pushes.
        let can_a = dyn_a && push_a[k].signum() != -s;
        let can_b = dyn_b && push_b[k].signum() != s;
        match (can_a, can_b) {
            (true, true) => {
                let share = div_round(mk as i128 * mass_b, mass_a + mass_b) as i32;
                da[k] = share;
                db[k] = share - mk;
            }
            (true, false) => da[k] = mk,
            (false, true) => db[k] = -mk,
            (false, false) => {}
        }
    }
    let (da, db) = (IVec2::from_array(da), IVec2::from_array(db));
    if dyn_a {
        bodies[ia].sides |= Sides::from_push(m);
    }
    if dyn_b {
        bodies[ib].sides |= Sides::from_push(-m);
    }
    if da != IVec2::ZERO {
        apply(&mut bodies[ia], da);
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
    da != IVec2::ZERO || db != IVec2::ZERO
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
