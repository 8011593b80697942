//! Stability at the extremes (issue 8).
//!
//! These tests run in the dev profile, where overflow checks are on
//! (`overflow_checks_are_on` makes sure of it): every tick stepped here is
//! also a check that no arithmetic overflows at the documented bounds
//! (`fixed::{MAX_COORD, MAX_EXTENT, MAX_SPEED}`).
//!
//! * whole scenes are translation invariant, tick for tick, out to the world
//!   bound on both axes and both signs;
//! * speeds from one unit per tick to `MAX_SPEED` against a thick wall, or a
//!   thin one with enough substeps, end flush; positions clamp at the bound;
//! * shapes from one unit to `MAX_EXTENT` collide correctly at the bound, and
//!   values beyond the bounds or degenerate shapes are refused by name;
//! * a stack of 100 boxes (or of boxes and circles) pressed down every tick
//!   settles exactly and stays put with the default configuration; a box
//!   shoved into a wall by another ends flush; boxes, circles, oriented
//!   boxes, polygons and segments pressed into an inside corner rest there;
//! * a body crushed between kinematic platforms is squished, never a panic;
//! * property tests build worlds at `±MAX_COORD` with `MAX_EXTENT` shapes and
//!   `MAX_SPEED` velocities and step them;
//! * a long run (10^6 ticks) of a busy room is periodic (no drift) and
//!   allocates nothing after warm-up.
//!
//! The test binary's counting allocator (`counting_alloc`) measures the
//! long run's memory.

use std::time::Instant;

use glam::IVec2;
use ledge_shared::fixed::{px, MAX_COORD, MAX_EXTENT, MAX_SPEED};
use ledge_shared::input::Buttons;
use ledge_shared::query::contact::{contact, Proximity};
use ledge_shared::scene::{self, scripted_inputs, warmup_room, PLAYER_HALF, TILE};
use ledge_shared::shape::{Aabb, Circle, ConvexPolygon, Obb, Point, Segment, ShapeError};
use ledge_shared::world::config::MAX_ROUNDS;
use ledge_shared::world::{
    AnyShape, BodyDesc, BodyId, BodyKind, ColliderDesc, ColliderId, ColliderView, Controller,
    Event, Mover, MoverConfig, OneWay, Sides, SimConfig, World,
};
use proptest::prelude::*;

// ------------------------------------------------------------ allocator

use crate::counting_alloc::calls_and_bytes as allocations;

#[test]
fn the_allocation_counter_counts() {
    let ((), calls, net) = allocations(|| {
        let v = std::hint::black_box(vec![1u8; 100]);
        std::mem::forget(v);
    });
    assert_eq!((calls, net), (1, 100));
    let ((), calls, net) = allocations(|| drop(std::hint::black_box(vec![1u8; 64])));
    assert_eq!((calls, net), (1, 0));
}

/// The whole file is about arithmetic at the bounds: it means something only
/// where overflow panics. Debug assertions and overflow checks go together in
/// the dev profile; a profile with one and not the other fails here.
#[test]
fn overflow_checks_are_on() {
    if !cfg!(debug_assertions) {
        return;
    }
    let overflowed =
        std::panic::catch_unwind(|| std::hint::black_box(i32::MAX) + std::hint::black_box(1));
    assert!(
        overflowed.is_err(),
        "overflow checks are off: run these tests in the dev profile"
    );
}

// ------------------------------------------------------------ helpers

fn config(substeps: u32, restitution_iterations: u32) -> SimConfig {
    tuned(SimConfig::default(), substeps, restitution_iterations)
}

fn tuned(mut c: SimConfig, substeps: u32, restitution_iterations: u32) -> SimConfig {
    c.substeps = substeps;
    c.restitution_iterations = restitution_iterations;
    c
}

fn aabb(half: IVec2) -> Aabb {
    Aabb::new(half).unwrap()
}

fn circle(r: i32) -> Circle {
    Circle::new(r).unwrap()
}

fn seg(a: (i32, i32), b: (i32, i32)) -> Segment {
    Segment::new(IVec2::from(a), IVec2::from(b)).unwrap()
}

fn poly(p: &[(i32, i32)]) -> ConvexPolygon {
    let v: Vec<IVec2> = p.iter().map(|&q| IVec2::from(q)).collect();
    ConvexPolygon::new(&v).unwrap()
}

/// A polygon given in pixels.
fn poly_px(p: &[(i32, i32)]) -> ConvexPolygon {
    let v: Vec<(i32, i32)> = p.iter().map(|&(x, y)| (px(x), px(y))).collect();
    poly(&v)
}

fn v2(x: i32, y: i32) -> IVec2 {
    IVec2::new(x, y)
}

fn pos(w: &World, b: BodyId) -> IVec2 {
    w.body(b).unwrap().pos()
}

fn vel(w: &World, b: BodyId) -> IVec2 {
    w.body(b).unwrap().vel()
}

fn squished(events: &[Event]) -> Vec<BodyId> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Squished { body } => Some(*body),
            _ => None,
        })
        .collect()
}

/// Runs `$body` with `$x` bound to the concrete shape inside `$s`.
macro_rules! with_shape {
    ($s:expr, $x:ident => $body:expr) => {
        match $s {
            AnyShape::Point($x) => $body,
            AnyShape::Segment($x) => $body,
            AnyShape::Circle($x) => $body,
            AnyShape::Aabb($x) => $body,
            AnyShape::Obb($x) => $body,
            AnyShape::Polygon($x) => $body,
        }
    };
}

/// The narrow phase for any two shapes (the MTV moves `a`).
fn prox(a: AnyShape, pa: IVec2, b: AnyShape, pb: IVec2) -> Proximity {
    with_shape!(a, x => with_shape!(b, y => contact(&x, pa, &y, pb)))
}

/// The narrow phase between two placed colliders.
fn prox_views(a: &ColliderView, b: &ColliderView) -> Proximity {
    prox(a.shape, a.pos, b.shape, b.pos)
}

/// Largest absolute local coordinate of a shape, per axis.
fn reach(s: &AnyShape) -> IVec2 {
    let (lo, hi) = s.local_bounds();
    lo.abs().max(hi.abs())
}

/// Every pair of solid colliders on different bodies, at least one of them
/// dynamic, whose interiors overlap.
fn overlapping_pairs(w: &World) -> Vec<(ColliderId, ColliderId, IVec2)> {
    let cols: Vec<ColliderView> = w
        .colliders()
        .filter(|c| matches!(c.mode, ledge_shared::world::ColliderMode::Solid))
        .collect();
    let mut out = Vec::new();
    for (i, a) in cols.iter().enumerate() {
        for b in &cols[i + 1..] {
            let (ka, kb) = (
                w.body(a.body).unwrap().kind(),
                w.body(b.body).unwrap().kind(),
            );
            if a.body == b.body
                || (ka != BodyKind::Dynamic && kb != BodyKind::Dynamic)
                || a.layer & b.mask == 0
                || b.layer & a.mask == 0
            {
                continue;
            }
            if let Proximity::Overlapping(m) = prox_views(a, b) {
                out.push((a.id, b.id, m));
            }
        }
    }
    out
}

/// A small, fixed pseudo-random function (an LCG scrambled three times): the
/// scripts here must never change with a dependency.
fn mix(a: u64, b: u64) -> u64 {
    let mut s = a.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ b ^ 0x1ed9_e5ee_d000_0001;
    for _ in 0..3 {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
    }
    s
}

/// A value in `lo..=hi` from bits `shift..` of `s`.
fn pick(s: u64, shift: u32, lo: i32, hi: i32) -> i32 {
    lo + ((s >> shift) % (hi - lo + 1) as u64) as i32
}

/// The state of one body that a tick can change, with its position
/// relative to some origin.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Snap {
    pos: IVec2,
    vel: IVec2,
    sides: Sides,
    disp: IVec2,
    pushed: IVec2,
    carrier: Option<BodyId>,
}

fn snap(w: &World, origin: IVec2) -> Vec<Snap> {
    w.bodies()
        .map(|(_, b)| Snap {
            pos: b.pos().wrapping_sub(origin),
            vel: b.vel(),
            sides: b.sides(),
            disp: b.displacement(),
            pushed: b.pushed(),
            carrier: b.carrier(),
        })
        .collect()
}

// ------------------------------------------------- translation invariance

/// Interior half size of the test room (centred on its static body).
const ROOM: IVec2 = IVec2::new(px(400), px(300));
/// Half thickness of its walls.
const WALL: i32 = px(32);
/// Ticks of every translated run.
const INVARIANCE_TICKS: u64 = 2_000;

/// A box collider covering `[lo, hi)` around the body's origin.
fn span(lo: IVec2, hi: IVec2) -> ColliderDesc {
    ColliderDesc::solid(aabb((hi - lo) / 2)).at((lo + hi) / 2)
}

/// The busy scene of the invariance test, built with its static body at `o`.
struct Rig {
    world: World,
    origin: IVec2,
    driven: Vec<BodyId>,
    kinematic: BodyId,
}

impl Rig {
    fn new(o: IVec2, config: SimConfig) -> Rig {
        let mut w = World::new(config).unwrap();
        let room = w.add_body(BodyDesc::fixed(o)).unwrap();
        let mut add = |d: ColliderDesc| {
            w.add_collider(room, d).unwrap();
        };
        let (r, t) = (ROOM, 2 * WALL);
        // Walls of two boxes each, seams at odd places.
        add(span(v2(-r.x - t, -r.y - t), v2(-r.x, -px(38))).tagged(1));
        add(span(v2(-r.x - t, -px(38)), v2(-r.x, r.y + t)).tagged(1));
        add(span(v2(r.x, -r.y - t), v2(r.x + t, px(54))).tagged(1));
        add(span(v2(r.x, px(54)), v2(r.x + t, r.y + t)).tagged(1));
        add(span(v2(-r.x, -r.y - t), v2(px(58), -r.y)).tagged(2));
        add(span(v2(px(58), -r.y - t), v2(r.x, -r.y)).tagged(2));
        add(span(v2(-r.x, r.y), v2(-px(122), r.y + t)).tagged(3));
        add(span(v2(-px(122), r.y), v2(r.x, r.y + t)).tagged(3));
        // Obstacles of every kind.
        add(ColliderDesc::solid(poly_px(&[
            (0, -40),
            (38, -12),
            (24, 32),
            (-24, 32),
            (-38, -12),
        ]))
        .at(v2(-px(200), -px(100)))
        .tagged(4));
        add(ColliderDesc::solid(circle(px(30)))
            .at(v2(px(200), -px(150)))
            .tagged(5));
        add(
            ColliderDesc::solid(seg((-px(75), -px(45)), (px(75), px(45))))
                .at(v2(-px(110), px(170)))
                .tagged(6),
        );
        add(
            ColliderDesc::solid(Obb::new(v2(px(40), px(12)), v2(3, 4)).unwrap())
                .at(v2(px(150), px(150)))
                .tagged(7),
        );
        add(span(v2(-px(80), px(96)), v2(px(80), px(104)))
            .one_way(OneWay::Up)
            .tagged(8));
        add(ColliderDesc::trigger(aabb(IVec2::splat(px(30))))
            .at(v2(px(300), px(240)))
            .tagged(9));
        add(span(v2(-px(70), -px(40)), v2(-px(30), 0)).tagged(10));

        // A kinematic platform going round a rectangle.
        let kinematic = w
            .add_body(BodyDesc::kinematic(o + v2(0, -px(220))))
            .unwrap();
        w.add_collider(
            kinematic,
            ColliderDesc::solid(aabb(v2(px(48), px(6)))).tagged(11),
        )
        .unwrap();

        // The player, driven by a mover at input slot 0.
        let player = w
            .add_body(BodyDesc::dynamic(o + v2(-px(300), -px(200))))
            .unwrap();
        w.add_collider(
            player,
            ColliderDesc::solid(aabb(IVec2::splat(px(8)))).tagged(12),
        )
        .unwrap();
        w.add_controller(Controller::Mover(Mover {
            body: player,
            config: scene::MOVER,
        }))
        .unwrap();

        // Dynamic bodies of every kind, driven by velocity scripts.
        let shapes: [(AnyShape, (i32, i32), u32); 7] = [
            (aabb(v2(px(10), px(6))).into(), (100, 0), 3),
            (aabb(IVec2::splat(px(6))).into(), (120, 30), 1),
            (circle(px(9)).into(), (-100, 50), 2),
            (
                poly_px(&[(-10, -5), (0, -11), (10, -5), (10, 5), (0, 11), (-10, 5)]).into(),
                (250, -50),
                1,
            ),
            (
                Obb::new(v2(px(10), px(5)), v2(1, 2)).unwrap().into(),
                (-250, 100),
                4,
            ),
            (seg((-px(10), -px(3)), (px(10), px(3))).into(), (0, -100), 1),
            (Point.into(), (50, 200), 1),
        ];
        let mut driven = Vec::new();
        for (i, (shape, (x, y), mass)) in shapes.into_iter().enumerate() {
            let b = w
                .add_body(BodyDesc::dynamic(o + v2(px(x), px(y))).with_mass(mass))
                .unwrap();
            w.add_collider(b, ColliderDesc::solid(shape).tagged(20 + i as u16))
                .unwrap();
            driven.push(b);
        }
        // A compound body: a box with a circle beside it.
        let b = w
            .add_body(BodyDesc::dynamic(o + v2(px(300), px(100))).with_mass(2))
            .unwrap();
        w.add_collider(b, ColliderDesc::solid(aabb(IVec2::splat(px(5)))).tagged(30))
            .unwrap();
        w.add_collider(
            b,
            ColliderDesc::solid(circle(px(5)))
                .at(v2(px(9), 0))
                .tagged(31),
        )
        .unwrap();
        driven.push(b);
        Rig {
            world: w,
            origin: o,
            driven,
            kinematic,
        }
    }

    /// Sets the scripted velocities of tick `t` and returns the player's input.
    fn drive(&mut self, t: u64) -> Buttons {
        let k = match t % 320 {
            0..120 => v2(px(2), 0),
            120..160 => v2(0, px(1)),
            160..280 => v2(-px(2), 0),
            _ => v2(0, -px(1)),
        };
        self.world.set_velocity(self.kinematic, k).unwrap();
        for (i, &b) in self.driven.iter().enumerate() {
            let s = mix(i as u64, t / 25);
            let v = v2(pick(s, 8, -px(3), px(3)), pick(s, 32, -px(3), px(3)));
            self.world.set_velocity(b, v).unwrap();
        }
        scripted_inputs(t)
    }
}

/// One tick of a run: every body's state relative to the origin, the events.
#[derive(Debug, Clone, PartialEq, Eq)]
struct TickTrace {
    bodies: Vec<Snap>,
    events: Vec<Event>,
}

/// Runs the rig at origin `o`; returns the trace and the largest absolute
/// body coordinate reached per axis.
fn run_rig(o: IVec2, config: SimConfig) -> (Vec<TickTrace>, IVec2) {
    let mut rig = Rig::new(o, config);
    let mut trace = Vec::with_capacity(INVARIANCE_TICKS as usize);
    let mut far = IVec2::ZERO;
    for t in 0..INVARIANCE_TICKS {
        let input = rig.drive(t);
        let events = rig.world.step(&[input]).to_vec();
        for (_, b) in rig.world.bodies() {
            far = far.max(b.pos().abs());
        }
        trace.push(TickTrace {
            bodies: snap(&rig.world, rig.origin),
            events,
        });
    }
    (trace, far)
}

/// Smallest and largest coordinate (relative) any body can have reached at
/// any moment of a trace, and the largest motion of a tick.
///
/// Bodies also pass through positions between ticks: a body that moves into
/// a wall and is pushed back out never shows its deepest point. Per axis,
/// the tick's motion `M = displacement - pushes` is monotone (substep shares
/// have one sign) and so are its pushes (a body is never pushed back against
/// an earlier push of the same tick), so every position of the tick lies
/// within `[start, start + M]` widened by the pushes: between
/// `min(start, start + M, end - M)` and `max(start, start + M, end - M)`.
fn extent(trace: &[TickTrace]) -> (IVec2, IVec2, i32) {
    let mut lo = IVec2::MAX;
    let mut hi = IVec2::MIN;
    let mut motion = 0;
    for t in trace {
        for b in &t.bodies {
            let start = b.pos - b.disp;
            let m = b.disp - b.pushed;
            motion = motion.max(m.abs().max_element());
            for p in [start, start + m, b.pos, b.pos - m] {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
    }
    (lo, hi, motion)
}

/// Panics at the first tick where two traces differ.
fn assert_same_trace(want: &[TickTrace], got: &[TickTrace], ctx: &str) {
    assert_eq!(want.len(), got.len(), "{ctx}");
    for (t, (a, b)) in want.iter().zip(got).enumerate() {
        if a == b {
            continue;
        }
        for (i, (x, y)) in a.bodies.iter().zip(&b.bodies).enumerate() {
            assert_eq!(x, y, "{ctx}: body {i} differs at tick {}", t + 1);
        }
        assert_eq!(a.events, b.events, "{ctx}: events differ at tick {}", t + 1);
    }
}

#[test]
fn whole_scenes_are_translation_invariant_out_to_the_world_bound() {
    for cfg in [config(1, 4), config(3, 8)] {
        let (base, _) = run_rig(IVec2::ZERO, cfg);

        // The scene is busy: contacts with walls, obstacles, the platform and
        // other bodies, triggers, one-way landings.
        let mut with_static = 0;
        let mut with_dynamic = 0;
        let mut with_kinematic = 0;
        let mut triggers = 0;
        let mut tags = std::collections::BTreeSet::new();
        for t in &base {
            for e in &t.events {
                match *e {
                    Event::Contact {
                        other_body,
                        other_tag,
                        ..
                    } => {
                        tags.insert(other_tag);
                        match other_body.0 {
                            0 => with_static += 1,
                            1 => with_kinematic += 1,
                            _ => with_dynamic += 1,
                        }
                    }
                    Event::Trigger { .. } => triggers += 1,
                    Event::Squished { .. } | Event::SweptHit { .. } => {}
                }
            }
        }
        let busy = (with_static, with_dynamic, with_kinematic, triggers);
        assert!(
            with_static > 500 && with_dynamic > 20 && with_kinematic > 5 && triggers > 0,
            "{cfg:?}: not busy enough: {busy:?}"
        );
        for tag in [1, 2, 3, 4, 5, 6, 7, 8, 10, 11] {
            assert!(
                tags.contains(&tag),
                "{cfg:?}: nothing touched tag {tag}: {tags:?}"
            );
        }

        // As close to the bound as the scene's extent allows: the most
        // extreme position a body can pass through lands exactly on
        // ±MAX_COORD (any closer and a body would be clamped).
        let (lo, hi, motion) = extent(&base);
        let (x_hi, x_lo) = (MAX_COORD - hi.x, -MAX_COORD - lo.x);
        let (y_hi, y_lo) = (MAX_COORD - hi.y, -MAX_COORD - lo.y);
        eprintln!(
            "{cfg:?}: contacts with static/dynamic/kinematic, triggers: {busy:?}; \
             extent {lo}..{hi}, largest motion {motion}"
        );
        let offsets = [
            (v2(px(10_000), px(10_000)), false),
            (v2(-px(10_000), px(10_000)), false),
            (v2(px(1_000_000), -px(1_000_000)), false),
            (v2(-px(1_000_000), -px(1_000_000)), false),
            (v2(x_hi, 0), true),
            (v2(x_lo, 0), true),
            (v2(0, y_hi), true),
            (v2(0, y_lo), true),
            (v2(x_hi, y_hi), true),
            (v2(x_lo, y_lo), true),
            (v2(x_hi, y_lo), true),
            (v2(x_lo, y_hi), true),
        ];
        for (o, at_bound) in offsets {
            let (trace, far) = run_rig(o, cfg);
            if at_bound {
                // Within one tick's motion of the bound.
                assert!(
                    far.max_element() >= MAX_COORD - motion,
                    "offset {o} never came near the bound: {far}"
                );
            }
            assert_same_trace(&base, &trace, &format!("{cfg:?} at offset {o}"));
        }
    }
}

// ------------------------------------------------------------ speeds

/// Powers of two from 1 to `MAX_SPEED` and a few odd values.
fn speeds() -> Vec<i32> {
    (0..=26)
        .map(|k| 1 << k)
        .chain([3, 7, 255, 257, 65_537, 1_000_003, 12_345_679, MAX_SPEED - 1])
        .collect()
}

/// Maps a scenario written for motion along `+x` onto direction `d`
/// (0: `+x`, 1: `-x`, 2: `+y`, 3: `-y`). The map is linear and keeps the
/// world bound, so a scenario at `x = MAX_COORD` lands on the matching bound.
fn orient(d: usize, v: IVec2) -> IVec2 {
    match d {
        0 => v,
        1 => v2(-v.x, v.y),
        2 => v2(v.y, v.x),
        _ => v2(v.y, -v.x),
    }
}

/// The same for half extents (no signs).
fn orient_half(d: usize, h: IVec2) -> IVec2 {
    if d < 2 {
        h
    } else {
        v2(h.y, h.x)
    }
}

/// Coordinate along the scenario's motion axis / across it.
fn along(d: usize, v: IVec2) -> i32 {
    match d {
        0 => v.x,
        1 => -v.x,
        2 => v.y,
        _ => -v.y,
    }
}

fn across(d: usize, v: IVec2) -> i32 {
    if d < 2 {
        v.y
    } else {
        v.x
    }
}

/// The side of the moving body that meets the wall.
fn front(d: usize) -> Sides {
    [Sides::RIGHT, Sides::LEFT, Sides::BOTTOM, Sides::TOP][d]
}

/// Whether two box colliders' interiors overlap (exact).
fn boxes_overlap(a: &ColliderView, b: &ColliderView) -> bool {
    let (alo, ahi) = a.world_bounds();
    let (blo, bhi) = b.world_bounds();
    alo.x < bhi.x && blo.x < ahi.x && alo.y < bhi.y && blo.y < ahi.y
}

struct WallCase {
    speed: i32,
    /// Direction of motion (see [`orient`]).
    d: usize,
    /// Scenario coordinates of the wall's face and of the body's track.
    face: i32,
    track: i32,
    wall_half: IVec2,
    body_half: i32,
    substeps: u32,
}

/// A body flies at `speed` (and drifts 3 units per tick across) into a wall
/// whose near face is at `face`; every tick it never ends overlapping and
/// never exceeds the speed bound, and once it arrives it rests exactly flush
/// with its velocity into the wall removed.
fn fly_into_wall(c: &WallCase) {
    let ctx = format!(
        "speed {} dir {} face {} substeps {} body half {}",
        c.speed, c.d, c.face, c.substeps, c.body_half
    );
    let d = c.d;
    let mut w = World::new(config(c.substeps, 4)).unwrap();
    let wall = w
        .add_body(BodyDesc::fixed(orient(d, v2(c.face, c.track))))
        .unwrap();
    let wall_c = w
        .add_collider(
            wall,
            ColliderDesc::solid(aabb(orient_half(d, c.wall_half)))
                .at(orient(d, v2(c.wall_half.x, 0))),
        )
        .unwrap();
    let h = c.body_half;
    // After two ticks the body is 0 to speed - 1 units short of the wall:
    // it meets it during tick 3.
    let gap = 2 * c.speed + (c.speed - 1) / 2;
    let drift = if c.track > 0 { -3 } else { 3 };
    let start = v2(c.face - h - gap, c.track);
    let body = w
        .add_body(BodyDesc::dynamic(orient(d, start)).with_vel(orient(d, v2(c.speed, drift))))
        .unwrap();
    let body_c = w
        .add_collider(body, ColliderDesc::solid(aabb(IVec2::splat(h))))
        .unwrap();
    let mut hit = None;
    for t in 1..=6 {
        let events = w.step(&[]).to_vec();
        let b = w.body(body).unwrap();
        let (p, v) = (b.pos(), b.vel());
        assert!(p.abs().max_element() <= MAX_COORD, "{ctx}: tick {t} at {p}");
        assert!(
            v.abs().max_element() <= MAX_SPEED,
            "{ctx}: tick {t} velocity {v}"
        );
        assert!(squished(&events).is_empty(), "{ctx}: squished at tick {t}");
        let (bv, wv) = (w.collider(body_c).unwrap(), w.collider(wall_c).unwrap());
        assert!(
            !boxes_overlap(&bv, &wv),
            "{ctx}: overlapping after tick {t}"
        );
        assert_eq!(
            across(d, p),
            c.track + drift * t,
            "{ctx}: drift at tick {t}"
        );
        assert_eq!(across(d, v), drift, "{ctx}: drift velocity at tick {t}");
        let met = events.iter().any(|e| {
            matches!(*e, Event::Contact { body: b, other_collider, .. }
                if b == body && other_collider == wall_c)
        });
        if hit.is_none() && met {
            hit = Some(t);
        }
        if hit.is_some() {
            assert_eq!(along(d, p), c.face - h, "{ctx}: not flush at tick {t}");
            assert_eq!(
                along(d, v),
                0,
                "{ctx}: velocity into the wall kept at tick {t}"
            );
        } else {
            assert_eq!(
                along(d, p),
                start.x + c.speed * t,
                "{ctx}: tick {t} before the wall"
            );
        }
        if hit == Some(t) {
            assert!(w.body(body).unwrap().sides().contains(front(d)), "{ctx}");
        }
    }
    assert_eq!(
        hit,
        Some(3),
        "{ctx}: the body should meet the wall on tick 3"
    );
}

#[test]
fn every_speed_up_to_the_bound_stops_flush_against_a_thick_wall() {
    let h = px(8);
    for speed in speeds() {
        for d in 0..4 {
            for (face, track) in [(0, 0), (MAX_COORD, MAX_COORD - h)] {
                fly_into_wall(&WallCase {
                    speed,
                    d,
                    face,
                    track,
                    // Thicker than a tick of motion, as tall as allowed.
                    wall_half: IVec2::splat(MAX_EXTENT),
                    body_half: h,
                    substeps: 1,
                });
            }
        }
    }
}

#[test]
fn every_speed_up_to_the_bound_stops_flush_against_a_thin_wall_with_enough_substeps() {
    let wall = px(1);
    for speed in speeds() {
        // A substep must move less than the body's half size plus the wall's
        // half thickness, or the body's centre could pass the wall's; when 64
        // substeps are not enough, the body grows instead.
        let reach = px(8) + wall - 1;
        let substeps = ((speed + reach - 1) / reach).clamp(1, MAX_ROUNDS as i32) as u32;
        let step = (speed + substeps as i32 - 1) / substeps as i32;
        let body_half = px(8).max(step - wall + 1);
        for d in 0..4 {
            for (face, track) in [(0, 0), (MAX_COORD, MAX_COORD - body_half)] {
                fly_into_wall(&WallCase {
                    speed,
                    d,
                    face,
                    track,
                    wall_half: v2(wall, MAX_EXTENT),
                    body_half,
                    substeps,
                });
            }
        }
    }
}

#[test]
fn motion_past_the_world_bound_is_clamped_and_loses_that_velocity() {
    let h = px(8);
    for speed in speeds() {
        for d in 0..4 {
            for dist in [0, 1, speed - 1, speed, speed + 1, 2 * speed] {
                for substeps in [1, 5, MAX_ROUNDS] {
                    let ctx = format!("speed {speed} dir {d} distance {dist} substeps {substeps}");
                    let mut w = World::new(config(substeps, 4)).unwrap();
                    let b = w
                        .add_body(
                            BodyDesc::dynamic(orient(d, v2(MAX_COORD - dist, 0)))
                                .with_vel(orient(d, v2(speed, 5))),
                        )
                        .unwrap();
                    w.add_collider(b, ColliderDesc::solid(aabb(IVec2::splat(h))))
                        .unwrap();
                    w.step(&[]);
                    let (p, v) = (pos(&w, b), vel(&w, b));
                    if speed > dist {
                        assert_eq!(along(d, p), MAX_COORD, "{ctx}");
                        assert_eq!(along(d, v), 0, "{ctx}: a clamped axis loses its velocity");
                    } else {
                        assert_eq!(along(d, p), MAX_COORD - dist + speed, "{ctx}");
                        assert_eq!(along(d, v), speed, "{ctx}");
                    }
                    // The other axis is untouched.
                    assert_eq!((across(d, p), across(d, v)), (5, 5), "{ctx}");
                    w.step(&[]);
                    assert_eq!(
                        along(d, pos(&w, b)),
                        MAX_COORD.min(MAX_COORD - dist + 2 * speed),
                        "{ctx}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_push_past_the_world_bound_is_clamped_and_reported_squished() {
    for d in 0..4 {
        let mut w = World::default();
        // A wall overlapping the body by 100 units from the inside pushes it
        // towards the bound, 10 units away.
        let wall = w
            .add_body(BodyDesc::fixed(orient(
                d,
                v2(MAX_COORD - 10 - 2 * px(8) + 100, 0),
            )))
            .unwrap();
        w.add_collider(
            wall,
            ColliderDesc::solid(aabb(orient_half(d, v2(px(8), px(100))))),
        )
        .unwrap();
        let b = w
            .add_body(
                BodyDesc::dynamic(orient(d, v2(MAX_COORD - 10, 0))).with_vel(orient(d, v2(-7, 3))),
            )
            .unwrap();
        w.add_collider(b, ColliderDesc::solid(aabb(IVec2::splat(px(8)))))
            .unwrap();
        for t in 1..=3 {
            let events = w.step(&[]).to_vec();
            let p = pos(&w, b);
            assert_eq!(along(d, p), MAX_COORD, "dir {d} tick {t}");
            assert_eq!(along(d, vel(&w, b)), 0, "dir {d} tick {t}");
            assert_eq!(squished(&events), vec![b], "dir {d} tick {t}");
            w.set_velocity(b, orient(d, v2(-7, 3))).unwrap();
        }
    }
}

#[test]
fn movers_at_the_speed_bound_never_exceed_it() {
    let mut w = World::new(config(MAX_ROUNDS, 4)).unwrap();
    let b = w
        .add_body(BodyDesc::dynamic(v2(MAX_COORD - 5, -MAX_COORD + 5)))
        .unwrap();
    w.add_collider(b, ColliderDesc::solid(aabb(IVec2::splat(MAX_EXTENT))))
        .unwrap();
    w.add_controller(Controller::Mover(Mover {
        body: b,
        config: MoverConfig {
            accel: MAX_SPEED,
            brake: MAX_SPEED,
            max_speed: MAX_SPEED,
        },
    }))
    .unwrap();
    let inputs = [
        Buttons(Buttons::RIGHT | Buttons::UP),
        Buttons(Buttons::LEFT | Buttons::DOWN),
        Buttons(Buttons::LEFT | Buttons::DOWN),
        Buttons::NONE,
        Buttons(Buttons::RIGHT | Buttons::DOWN),
    ];
    for t in 0..400 {
        let input = inputs[(t / 7) % inputs.len()];
        w.step(&[input]);
        let (p, v) = (pos(&w, b), vel(&w, b));
        assert!(p.abs().max_element() <= MAX_COORD, "tick {t}: {p}");
        assert!(v.abs().max_element() <= MAX_SPEED, "tick {t}: {v}");
    }
    // Held towards the corner, it rests on the bound.
    for _ in 0..60 {
        w.step(&[Buttons(Buttons::RIGHT | Buttons::UP)]);
    }
    assert_eq!(pos(&w, b), v2(MAX_COORD, -MAX_COORD));
}

// ------------------------------------------------------------ shapes

/// Shapes from one unit to `MAX_EXTENT`.
fn extreme_shapes() -> Vec<(&'static str, AnyShape)> {
    let m = MAX_EXTENT;
    let k = m / 7;
    vec![
        ("point", Point.into()),
        ("unit segment", seg((0, 0), (1, 0)).into()),
        ("diagonal segment", seg((-m, -m), (m, m)).into()),
        ("long flat segment", seg((-m, 0), (m, 1)).into()),
        ("unit circle", circle(1).into()),
        ("huge circle", circle(m).into()),
        ("unit box", aabb(IVec2::ONE).into()),
        ("huge box", aabb(IVec2::splat(m)).into()),
        ("sliver box", aabb(v2(m, 1)).into()),
        ("tall sliver box", aabb(v2(1, m)).into()),
        ("unit triangle", poly(&[(0, 0), (1, 0), (0, 1)]).into()),
        ("huge triangle", poly(&[(-m, -m), (m, -m), (0, m)]).into()),
        (
            "huge octagon",
            poly(&[
                (-m / 2, -m),
                (m / 2, -m),
                (m, -m / 2),
                (m, m / 2),
                (m / 2, m),
                (-m / 2, m),
                (-m, m / 2),
                (-m, -m / 2),
            ])
            .into(),
        ),
        (
            "unit oriented box",
            Obb::from_axes(v2(1, 1), v2(-1, 1)).unwrap().into(),
        ),
        (
            "huge 3-4-5 oriented box",
            Obb::from_axes(v2(3 * k, 4 * k), v2(-4 * k, 3 * k))
                .unwrap()
                .into(),
        ),
        (
            "sliver oriented box",
            Obb::from_axes(v2(m - 1, 1), v2(-1, 1)).unwrap().into(),
        ),
    ]
}

/// Relative offsets of the second shape: inside, across and beyond the
/// first, in several directions.
fn deltas(a: &AnyShape, b: &AnyShape) -> Vec<IVec2> {
    let r = reach(a).as_i64vec2() + reach(b).as_i64vec2();
    let mut out = vec![IVec2::ZERO, IVec2::ONE, -IVec2::ONE];
    for dir in [
        (1, 0),
        (0, 1),
        (-1, 0),
        (0, -1),
        (1, 1),
        (-3, 2),
        (2, -5),
        (-1, -1),
    ] {
        for (num, den) in [(1, 4), (1, 2), (3, 4), (99, 100), (1, 1), (101, 100)] {
            let x = dir.0 * r.x * num / den;
            let y = dir.1 * r.y * num / den;
            out.push(v2(x as i32, y as i32));
        }
    }
    out
}

/// Whether `rev` (b against a) is consistent with `here` (a against b): the
/// same contact seen from the other side, or, where geometry gives no side
/// (a shape centred in the other, coincident circles), both pushed by the
/// documented default: up, or left on a horizontal axis.
fn reverse_consistent(here: Proximity, rev: Proximity) -> bool {
    rev == here.reversed()
        || matches!((here, rev), (Proximity::Overlapping(m), Proximity::Overlapping(r))
            if m == r && (m.y < 0 || (m.y == 0 && m.x < 0)))
}

/// Checks `a` at the origin against `b` at `rel`, both ways: the two answers
/// agree, an MTV is no longer than the shapes are wide, and applying it
/// separates them (touching or apart).
fn check_pair(a: AnyShape, b: AnyShape, rel: IVec2) -> Result<Proximity, String> {
    let here = prox(a, IVec2::ZERO, b, rel);
    let rev = prox(b, rel, a, IVec2::ZERO);
    if !reverse_consistent(here, rev) {
        return Err(format!("{here:?} but the reverse is {rev:?}"));
    }
    let bound = 2 * (reach(&a) + reach(&b)) + IVec2::splat(2);
    for (m, after) in [
        (here.mtv(), here.mtv().map(|m| prox(a, m, b, rel))),
        (
            rev.mtv(),
            rev.mtv().map(|m| prox(b, rel + m, a, IVec2::ZERO)),
        ),
    ] {
        let (Some(m), Some(after)) = (m, after) else {
            continue;
        };
        if m == IVec2::ZERO || !m.abs().cmple(bound).all() {
            return Err(format!("MTV {m} (shapes reach {bound})"));
        }
        if after.mtv().is_some() {
            return Err(format!("{after:?} after moving by {m}"));
        }
    }
    Ok(here)
}

#[test]
fn shapes_of_extreme_sizes_collide_correctly_at_extreme_positions() {
    let shapes = extreme_shapes();
    let edge = MAX_COORD + MAX_EXTENT;
    let mut overlaps = 0;
    for (na, a) in &shapes {
        for (nb, b) in &shapes {
            for delta in deltas(a, b) {
                let ctx = format!("{na} vs {nb} at {delta}");
                let here = check_pair(*a, *b, delta).unwrap_or_else(|e| panic!("{ctx}: {e}"));
                overlaps += here.mtv().is_some() as u32;
                // The same anywhere a collider can be: collider origins reach
                // MAX_COORD + MAX_EXTENT (body position plus offset).
                for corner in [v2(1, 1), v2(-1, 1), v2(1, -1), v2(-1, -1)] {
                    let pa = corner * edge;
                    let pb = pa.as_i64vec2() + delta.as_i64vec2();
                    if pb.abs().max_element() > edge as i64 {
                        continue;
                    }
                    let pb = pb.as_ivec2();
                    assert_eq!(prox(*a, pa, *b, pb), here, "{ctx} near {pa}");
                    assert_eq!(
                        prox(*b, pb, *a, pa),
                        prox(*b, delta, *a, IVec2::ZERO),
                        "{ctx} near {pa}"
                    );
                }
            }
        }
    }
    assert!(overlaps > 1000, "only {overlaps} overlapping cases");
}

#[test]
fn the_world_separates_extreme_shapes_at_the_bound() {
    let shapes = extreme_shapes();
    let m = MAX_EXTENT;
    let (mut resolved, mut clamped) = (0, 0);
    for (na, a) in &shapes {
        for (nb, b) in &shapes {
            for delta in deltas(a, b) {
                for corner in [v2(1, 1), v2(-1, -1), v2(1, -1)] {
                    let ctx = format!("static {na} vs dynamic {nb} at {delta} near {corner}");
                    // The static body sits on the bound, its collider offset
                    // inwards; the dynamic body's collider is offset the same,
                    // so the colliders are `delta` apart.
                    let s = corner * MAX_COORD;
                    let off = -corner * m;
                    let d = s.as_i64vec2() + delta.as_i64vec2();
                    if d.abs().max_element() > MAX_COORD as i64 {
                        continue;
                    }
                    let d = d.as_ivec2();
                    // Either order of the pair gives the dynamic body a valid
                    // push (they differ only where geometry gives no side).
                    let pushes = [
                        prox(*b, d + off, *a, s + off).mtv(),
                        prox(*a, s + off, *b, d + off).mtv().map(|m| -m),
                    ];
                    let mut w = World::new(config(1, 4)).unwrap();
                    let sb = w.add_body(BodyDesc::fixed(s)).unwrap();
                    let sc = w.add_collider(sb, ColliderDesc::solid(*a).at(off)).unwrap();
                    let db = w.add_body(BodyDesc::dynamic(d)).unwrap();
                    let dc = w.add_collider(db, ColliderDesc::solid(*b).at(off)).unwrap();
                    let events = w.step(&[]).to_vec();
                    let p = pos(&w, db);
                    assert!(p.abs().max_element() <= MAX_COORD, "{ctx}: {p}");
                    let still = prox_views(&w.collider(dc).unwrap(), &w.collider(sc).unwrap());
                    let [Some(m1), Some(m2)] = pushes else {
                        assert_eq!(pushes, [None, None], "{ctx}");
                        assert_eq!(p, d, "{ctx}: moved without overlapping");
                        assert!(events.is_empty(), "{ctx}: {events:?}");
                        continue;
                    };
                    let free = |m: IVec2| d.as_i64vec2() + m.as_i64vec2();
                    let inside = |m: IVec2| free(m).abs().max_element() <= MAX_COORD as i64;
                    if [m1, m2]
                        .iter()
                        .any(|&m| inside(m) && p == free(m).as_ivec2())
                    {
                        // One static contact: the whole MTV, once.
                        resolved += 1;
                        assert!(still.mtv().is_none(), "{ctx}: {still:?}");
                        assert!(squished(&events).is_empty(), "{ctx}");
                    } else {
                        // The push would pass the bound: clamped on it, and
                        // squished exactly when still overlapping.
                        clamped += 1;
                        assert!(
                            !inside(m1) || !inside(m2),
                            "{ctx}: at {p}, pushes {m1} {m2}"
                        );
                        assert_eq!(p.abs().max_element(), MAX_COORD, "{ctx}: at {p}");
                        assert_eq!(
                            squished(&events).is_empty(),
                            still.mtv().is_none(),
                            "{ctx}: {still:?} {events:?}"
                        );
                    }
                }
            }
        }
    }
    assert!(
        resolved > 1000 && clamped > 10,
        "{resolved} resolved, {clamped} clamped cases"
    );
}

/// `r`'s message names `what` and the offending `value`.
fn names<T: std::fmt::Debug, E: std::fmt::Display + std::fmt::Debug>(
    r: Result<T, E>,
    what: &str,
    value: i64,
) -> E {
    let e = r.expect_err(what);
    let msg = e.to_string();
    assert!(msg.contains(what), "{msg:?} does not name {what:?}");
    assert!(
        msg.contains(&value.to_string()),
        "{msg:?} does not give {value}"
    );
    e
}

#[test]
fn values_beyond_the_bounds_are_refused_with_a_message_naming_them() {
    let (m, c, s) = (MAX_EXTENT, MAX_COORD, MAX_SPEED);
    let over = m as i64 + 1;
    // Exactly at the bounds is fine.
    aabb(IVec2::splat(m));
    circle(m);
    seg((-m, -m), (m, m));
    poly(&[(-m, -m), (m, -m), (m, m)]);
    Obb::from_axes(v2(m / 2, m / 2), v2(-m / 2, m / 2)).unwrap();
    // Shapes.
    names(Aabb::new(v2(m + 1, 1)), "box half width", over);
    names(Aabb::new(v2(1, m + 1)), "box half height", over);
    names(
        Aabb::new(v2(1, i32::MAX)),
        "box half height",
        i32::MAX as i64,
    );
    names(Aabb::from_size(v2(2 * m + 2, 2)), "box half width", over);
    names(Circle::new(m + 1), "circle radius", over);
    names(Circle::new(i32::MAX), "circle radius", i32::MAX as i64);
    names(Segment::new(v2(m + 1, 0), IVec2::ZERO), "segment a.x", over);
    names(
        Segment::new(IVec2::ZERO, v2(0, -m - 1)),
        "segment b.y",
        -over,
    );
    names(
        Segment::new(v2(i32::MIN, 0), IVec2::ZERO),
        "segment a.x",
        i32::MIN as i64,
    );
    names(
        ConvexPolygon::new(&[v2(0, 0), v2(m + 1, 0), v2(0, 5)]),
        "polygon vertex x",
        over,
    );
    names(
        ConvexPolygon::new(&[v2(0, 0), v2(5, 0), v2(0, -m - 1)]),
        "polygon vertex y",
        -over,
    );
    names(
        Obb::from_axes(v2(m, 0), v2(1, 1)),
        "oriented box extent x",
        over,
    );
    names(
        Obb::from_axes(v2(0, -m), v2(1, -1)),
        "oriented box extent y",
        over,
    );
    // A turned box whose rotated extent passes the bound.
    assert!(matches!(
        Obb::new(IVec2::splat(m), v2(1, 1)),
        Err(ShapeError::Bounds(_))
    ));
    // World values.
    let mut w = World::default();
    names(
        w.add_body(BodyDesc::dynamic(v2(c + 1, 0))),
        "body position x",
        c as i64 + 1,
    );
    names(
        w.add_body(BodyDesc::dynamic(v2(0, -c - 1))),
        "body position y",
        -(c as i64) - 1,
    );
    names(
        w.add_body(BodyDesc::dynamic(IVec2::ZERO).with_vel(v2(s + 1, 0))),
        "body velocity x",
        s as i64 + 1,
    );
    names(
        w.add_body(BodyDesc::kinematic(IVec2::ZERO).with_vel(v2(0, -s - 1))),
        "body velocity y",
        -(s as i64) - 1,
    );
    let b = w
        .add_body(BodyDesc::dynamic(v2(c, -c)).with_vel(v2(s, -s)))
        .unwrap();
    w.add_collider(b, ColliderDesc::solid(aabb(IVec2::splat(m))).at(v2(m, -m)))
        .unwrap();
    names(
        w.add_collider(b, ColliderDesc::solid(aabb(IVec2::ONE)).at(v2(0, -m - 1))),
        "collider offset y",
        -over,
    );
    names(
        w.set_position(b, v2(c + 1, 0)),
        "body position x",
        c as i64 + 1,
    );
    names(
        w.set_velocity(b, v2(0, s + 1)),
        "body velocity y",
        s as i64 + 1,
    );
    names(w.shift(b, v2(1, 0)), "body position x", c as i64 + 1);
    names(
        w.add_controller(Controller::Mover(Mover {
            body: b,
            config: MoverConfig {
                accel: 1,
                brake: 1,
                max_speed: s + 1,
            },
        })),
        "mover max_speed",
        s as i64 + 1,
    );
    // Nothing was half-built: the body is where it was.
    assert_eq!((pos(&w, b), vel(&w, b)), (v2(c, -c), v2(s, -s)));
    assert_eq!(w.collider_count(), 1);
}

#[test]
fn degenerate_shapes_are_refused_with_a_clear_error() {
    let p = |pts: &[(i32, i32)]| {
        let v: Vec<IVec2> = pts.iter().map(|&q| IVec2::from(q)).collect();
        ConvexPolygon::new(&v)
    };
    let m = MAX_EXTENT;
    // Collinear vertices, at small and huge sizes.
    for pts in [
        &[(0, 0), (5, 0), (10, 0)][..],
        &[(-m, -m), (0, 0), (m, m)],
        &[(0, 0), (5, 0), (10, 0), (5, 5)],
        &[(0, 0), (1, 1), (2, 2), (3, 3)],
    ] {
        let e = p(pts).unwrap_err();
        assert!(matches!(e, ShapeError::Collinear(_)), "{pts:?}: {e:?}");
        assert!(e.to_string().contains("collinear"), "{e}");
    }
    // Duplicate vertices.
    for pts in [
        &[(0, 0), (0, 0), (1, 1)][..],
        &[(m, m), (m, m), (m, m)],
        &[(0, 0), (10, 0), (10, 10), (0, 0)],
    ] {
        let e = p(pts).unwrap_err();
        assert!(
            matches!(e, ShapeError::DuplicateVertex(_)),
            "{pts:?}: {e:?}"
        );
        assert!(e.to_string().contains("duplicates"), "{e}");
    }
    // Zero area in other guises: too few vertices, a flat sliver, a bow tie.
    assert_eq!(p(&[(0, 0), (m, m)]), Err(ShapeError::VertexCount(2)));
    assert!(p(&[(0, 0), (m, m)])
        .unwrap_err()
        .to_string()
        .contains("2 vertices"));
    assert!(p(&[(0, 0), (10, 10), (10, 0), (0, 10)]).is_err());
    // The smallest valid polygon has area 1/2.
    poly(&[(0, 0), (1, 0), (0, 1)]);
    // Zero-length segments, anywhere in range.
    for a in [IVec2::ZERO, v2(m, -m), v2(-m, m)] {
        let e = Segment::new(a, a).unwrap_err();
        assert_eq!(e, ShapeError::ZeroLength);
        assert_eq!(e.to_string(), "segment has zero length");
    }
    // Zero and negative sizes.
    for r in [0, -1, -m, i32::MIN] {
        let e = names(Circle::new(r), "circle radius", r as i64);
        assert!(matches!(e, ShapeError::NotPositive { .. }), "{e:?}");
        assert!(e.to_string().contains("must be positive"), "{e}");
        names(Aabb::new(v2(r, 5)), "box half width", r as i64);
        names(Aabb::new(v2(5, r)), "box half height", r as i64);
        names(
            Obb::new(v2(r, 5), v2(1, 0)),
            "oriented box half extent",
            r as i64,
        );
    }
    names(Aabb::from_size(v2(2, 3)), "box height", 3);
    // Oriented boxes: zero or parallel axes, zero direction.
    for (u, v) in [
        (v2(2, 1), v2(4, 2)),
        (v2(2, 1), v2(-2, -1)),
        (v2(m, 0), v2(-1, 0)),
        (IVec2::ZERO, v2(0, 1)),
        (v2(1, 0), IVec2::ZERO),
    ] {
        let e = Obb::from_axes(u, v).unwrap_err();
        assert_eq!(e, ShapeError::BadAxes, "{u} {v}");
        assert!(e.to_string().contains("oriented box axes"), "{e}");
    }
    assert_eq!(Obb::new(v2(5, 5), IVec2::ZERO), Err(ShapeError::BadAxes));
}

// ------------------------------------------------------------ stacks

/// Drops `n` boxes onto a floor, pressing every box down by a constant
/// velocity every tick (gravity-like), lets them settle, then checks for
/// `hold` ticks that they rest exactly on each other, none squished, none
/// moving.
fn stack_settles(n: usize, iterations: u32, hold: u32) {
    stack_of_settles(n, iterations, hold, |_| aabb(IVec2::splat(px(4))).into());
}

/// [`stack_settles`] with the `i`-th body from the bottom of shape
/// `shape(i)` (every shape 8 px tall and centred on its origin).
fn stack_of_settles(n: usize, iterations: u32, hold: u32, shape: impl Fn(usize) -> AnyShape) {
    let ctx = format!("{n} bodies, {iterations} restitution passes");
    let mut w = World::new(config(1, iterations)).unwrap();
    let floor = w.add_body(BodyDesc::fixed(IVec2::ZERO)).unwrap();
    w.add_collider(floor, span(v2(-px(200), 0), v2(px(200), px(32))))
        .unwrap();
    let h = px(4);
    let push = px(1) / 2;
    let mut boxes = Vec::new();
    let mut y = 0;
    for i in 0..n as i32 {
        // Uneven gaps (up to 2 px) and sideways jitter (under 1 px).
        y -= 2 * h + (i * 53 + 17) % px(2);
        let x = (i * 97) % 512 - 256;
        let b = w
            .add_body(BodyDesc::dynamic(v2(x, y + h)).with_mass(1 + i as u32 % 3))
            .unwrap();
        w.add_collider(b, ColliderDesc::solid(shape(i as usize)))
            .unwrap();
        boxes.push((b, x));
    }
    let tick = |w: &mut World| {
        for &(b, _) in &boxes {
            w.set_velocity(b, v2(0, push)).unwrap();
        }
        w.step(&[]).to_vec()
    };
    // The highest box falls at most 2 px * n; allow twice that.
    for _ in 0..(4 * n as i32 * px(2) / push) {
        tick(&mut w);
    }
    for t in 0..hold {
        let events = tick(&mut w);
        assert!(
            squished(&events).is_empty(),
            "{ctx}: squished at hold tick {t}: {:?}",
            squished(&events)
        );
        for (i, &(b, x)) in boxes.iter().enumerate() {
            let body = w.body(b).unwrap();
            // Exactly on the box below: heights are exact multiples, no
            // overlap, no drift either way.
            let want = v2(x, -h - 2 * h * i as i32);
            assert_eq!(body.pos(), want, "{ctx}: body {i} at hold tick {t}");
            assert!(
                body.sides().contains(Sides::BOTTOM),
                "{ctx}: body {i} not resting"
            );
        }
    }
    assert!(
        overlapping_pairs(&w).is_empty(),
        "{ctx}: {:?}",
        overlapping_pairs(&w)
    );
}

/// A push propagating up a stack moves bodies not yet moved this substep,
/// and such passes do not use up the pass budget: stacks settle at any
/// depth, whatever the budget.
#[test]
fn stacks_settle_exactly_and_stay_put_whatever_the_pass_budget() {
    stack_settles(MAX_ROUNDS as usize, MAX_ROUNDS, 1_000);
    stack_settles(4, SimConfig::default().restitution_iterations, 1_000);
    stack_settles(8, 1, 200);
}

#[test]
fn a_stack_of_100_boxes_settles_exactly_with_the_default_configuration() {
    stack_settles(100, SimConfig::default().restitution_iterations, 1_000);
}

/// Boxes and circles in turn (a circle on a box and a box on a circle push
/// straight up whatever the sub-pixel jitter).
#[test]
fn a_mixed_stack_of_boxes_and_circles_settles_with_the_default_configuration() {
    stack_of_settles(
        60,
        SimConfig::default().restitution_iterations,
        1_000,
        |i| {
            if i % 2 == 0 {
                aabb(IVec2::splat(px(4))).into()
            } else {
                circle(px(4)).into()
            }
        },
    );
}

/// A box `A` shoved every tick into a box `B` resting against a wall: the
/// wall's push on `B` overrides the push `B` got from `A` (immovable support
/// wins), and `A` then takes the whole push. `B` ends flush against the wall,
/// `A` flush against `B`, nothing is squished, whatever the masses and
/// speeds, from three passes up.
#[test]
fn a_box_pushed_into_a_wall_by_another_box_ends_flush() {
    for (substeps, iterations) in [
        (1, SimConfig::default().restitution_iterations),
        // The least that does: the shove, the wall's push back, the
        // shover's push back.
        (1, 3),
        (4, 16),
    ] {
        for (mass_a, mass_b) in [(1, 1), (1, 5), (5, 1)] {
            for speed in [1, px(1), px(3)] {
                for dir in [1, -1] {
                    let ctx = format!(
                        "substeps {substeps} passes {iterations} masses {mass_a}/{mass_b} \
                         speed {speed} dir {dir}"
                    );
                    let mut w = World::new(config(substeps, iterations)).unwrap();
                    let wall = w.add_body(BodyDesc::fixed(IVec2::ZERO)).unwrap();
                    let (lo, hi) = if dir > 0 {
                        (v2(0, -px(50)), v2(px(16), px(50)))
                    } else {
                        (v2(-px(16), -px(50)), v2(0, px(50)))
                    };
                    w.add_collider(wall, span(lo, hi)).unwrap();
                    let add = |w: &mut World, x: i32, mass: u32| {
                        let b = w
                            .add_body(BodyDesc::dynamic(v2(x * dir, 0)).with_mass(mass))
                            .unwrap();
                        w.add_collider(b, ColliderDesc::solid(aabb(IVec2::splat(px(4)))))
                            .unwrap();
                        b
                    };
                    let b = add(&mut w, -px(4), mass_b);
                    let a = add(&mut w, -px(15), mass_a);
                    let mut reached = false;
                    // 3 px to close, then 30 ticks pressed.
                    for t in 1..=px(3) / speed + 30 {
                        w.set_velocity(a, v2(speed * dir, 0)).unwrap();
                        let events = w.step(&[]).to_vec();
                        assert!(
                            squished(&events).is_empty(),
                            "{ctx}: tick {t}: squished, B at {}, A at {}",
                            pos(&w, b),
                            pos(&w, a)
                        );
                        assert!(overlapping_pairs(&w).is_empty(), "{ctx}: tick {t}");
                        assert_eq!(pos(&w, b), v2(-px(4) * dir, 0), "{ctx}: B, tick {t}");
                        reached |= pos(&w, a).x == -px(12) * dir;
                        if reached {
                            assert_eq!(pos(&w, a), v2(-px(12) * dir, 0), "{ctx}: A, tick {t}");
                        }
                    }
                    assert!(reached, "{ctx}: A never reached B");
                }
            }
        }
    }
}

/// A corner where a wall box ends on a floor box (the room's corners are
/// built so): a body at rest in it is pressed into it every tick for 60
/// ticks; it must never be squished nor end overlapping either box.
fn press_into_corner(shape: AnyShape, vel: IVec2) -> Result<(), String> {
    let right = vel.x > 0;
    let mut w = World::default();
    let room = w.add_body(BodyDesc::fixed(IVec2::ZERO)).unwrap();
    w.add_collider(room, span(v2(-px(100), 0), v2(px(100), px(16))))
        .unwrap();
    let wall = if right {
        span(v2(0, -px(100)), v2(px(16), 0))
    } else {
        span(v2(-px(16), -px(100)), v2(0, 0))
    };
    w.add_collider(room, wall).unwrap();
    let (lo, hi) = shape.local_bounds();
    let flush = v2(if right { -hi.x } else { -lo.x }, -hi.y);
    let b = w.add_body(BodyDesc::dynamic(flush)).unwrap();
    w.add_collider(b, ColliderDesc::solid(shape)).unwrap();
    for t in 1..=60 {
        w.set_velocity(b, vel).unwrap();
        let events = w.step(&[]).to_vec();
        let p = pos(&w, b);
        if !squished(&events).is_empty() || !overlapping_pairs(&w).is_empty() {
            return Err(format!(
                "velocity {vel}: tick {t}: at {} from flush, {:?}, overlaps {:?}",
                p - flush,
                squished(&events),
                overlapping_pairs(&w)
            ));
        }
    }
    Ok(())
}

#[test]
fn boxes_circles_and_oriented_boxes_pressed_into_an_inside_corner_rest_there() {
    let shapes: [AnyShape; 4] = [
        aabb(v2(px(6), px(5))).into(),
        aabb(IVec2::splat(px(4))).into(),
        circle(px(5)).into(),
        Obb::new(v2(px(7), px(4)), v2(2, 1)).unwrap().into(),
    ];
    for shape in shapes {
        for vel in [
            v2(-1, 1),
            v2(-300, 163),
            v2(-163, 300),
            v2(-300, 50),
            v2(-px(3), px(3)),
        ] {
            for vel in [vel, vel * v2(-1, 1)] {
                press_into_corner(shape, vel).unwrap_or_else(|e| panic!("{shape:?}: {e}"));
            }
        }
    }
}

/// Where a wall box stands on a floor box, the wall's bottom face is
/// covered: a slanted SAT push out of its bottom corner (along a triangle's
/// edge or a segment's normal, pointing into the floor) is replaced by the
/// push out of its open side, so polygons and segments rest in the corner
/// like boxes do.
#[test]
fn polygons_and_segments_pressed_into_an_inside_corner_rest_there() {
    let shapes: [AnyShape; 5] = [
        poly_px(&[(-6, 5), (6, 5), (0, -6)]).into(),
        poly_px(&[(-6, -6), (6, -6), (7, 2), (0, 7), (-7, 2)]).into(),
        seg((-px(6), -px(2)), (px(6), px(2))).into(),
        seg((-px(6), px(2)), (px(6), -px(2))).into(),
        seg((-px(5), 0), (px(5), 0)).into(),
    ];
    for shape in shapes {
        for vel in [
            v2(-1, 1),
            v2(-300, 163),
            v2(-163, 300),
            v2(-300, 50),
            v2(-px(3), px(3)),
        ] {
            for vel in [vel, vel * v2(-1, 1)] {
                press_into_corner(shape, vel).unwrap_or_else(|e| panic!("{shape:?}: {e}"));
            }
        }
    }
}

// ------------------------------------------------------------ crushing

struct Crush {
    /// Scenario centre (along, across), see [`orient`].
    centre: IVec2,
    d: usize,
    body_half: i32,
    plate_half: IVec2,
    gap: i32,
    speed: i32,
    substeps: u32,
    iterations: u32,
}

/// Two kinematic plates close in on a body from both sides of axis `d`,
/// pass through each other and stop. Returns the first tick a squish was
/// reported and the world.
fn crush(c: &Crush) -> (u32, World, BodyId, [BodyId; 2]) {
    let ctx = format!("dir {} centre {} speed {}", c.d, c.centre, c.speed);
    let d = c.d;
    let mut w = World::new(config(c.substeps, c.iterations)).unwrap();
    let g = c.gap / 2;
    let t = c.plate_half.x;
    let near = c.centre - v2(g + t, 0);
    let far = c.centre + v2(c.gap - g + t, 0);
    let mut plates = [BodyId(0); 2];
    for (i, (p, v)) in [(near, c.speed), (far, -c.speed)].into_iter().enumerate() {
        let k = w
            .add_body(BodyDesc::kinematic(orient(d, p)).with_vel(orient(d, v2(v, 0))))
            .unwrap();
        w.add_collider(k, ColliderDesc::solid(aabb(orient_half(d, c.plate_half))))
            .unwrap();
        plates[i] = k;
    }
    let body = w.add_body(BodyDesc::dynamic(orient(d, c.centre))).unwrap();
    w.add_collider(body, ColliderDesc::solid(aabb(IVec2::splat(c.body_half))))
        .unwrap();
    // Until the plates have swapped places.
    let ticks = (c.gap + 2 * t) / c.speed;
    let mut first = None;
    for tick in 1..=ticks as u32 {
        let events = w.step(&[]).to_vec();
        for (k, start, v) in [(plates[0], near, c.speed), (plates[1], far, -c.speed)] {
            assert_eq!(
                pos(&w, k),
                orient(d, start + v2(v * tick as i32, 0)),
                "{ctx}: a plate was pushed at tick {tick}"
            );
        }
        let b = w.body(body).unwrap();
        assert!(
            b.pos().abs().max_element() <= MAX_COORD,
            "{ctx}: {}",
            b.pos()
        );
        assert!(
            b.vel().abs().max_element() <= MAX_SPEED,
            "{ctx}: {}",
            b.vel()
        );
        if !squished(&events).is_empty() {
            assert_eq!(squished(&events), vec![body], "{ctx}");
            first.get_or_insert(tick);
        }
    }
    for k in plates {
        w.set_velocity(k, IVec2::ZERO).unwrap();
    }
    (first.expect("never squished"), w, body, plates)
}

#[test]
fn a_body_crushed_between_kinematic_platforms_is_squished_and_the_world_runs_on() {
    for d in 0..4 {
        for (substeps, iterations) in [(1, 4), (4, 16)] {
            for (gap, offset) in [(px(32), 0), (px(33), 0), (px(32), px(5)), (px(40), -px(11))] {
                let (speed, h) = (px(1), px(8));
                let c = Crush {
                    centre: v2(offset, 0),
                    d,
                    body_half: h,
                    plate_half: v2(px(10), px(50)),
                    gap,
                    speed,
                    substeps,
                    iterations,
                };
                let ctx = format!("dir {d} gap {gap} offset {offset} substeps {substeps}");
                let (first, mut w, body, _) = crush(&c);
                // Free while the gap is at least the body's size.
                let want = (gap - 2 * h) / (2 * speed) + 1;
                assert_eq!(first, want as u32, "{ctx}: first squish");
                // The world keeps running: the plates have passed each other
                // and stopped; the body comes to rest clear of both.
                for _ in 0..20 {
                    w.step(&[]);
                }
                for t in 0..20 {
                    let events = w.step(&[]).to_vec();
                    assert!(events.is_empty(), "{ctx}: tick {t} after: {events:?}");
                }
                assert!(overlapping_pairs(&w).is_empty(), "{ctx}");
                assert!(
                    w.body(body).unwrap().pos().abs().max_element() < px(200),
                    "{ctx}"
                );
            }
        }
    }
}

#[test]
fn a_body_crushed_at_the_world_bound_at_top_speed_is_squished_without_panicking() {
    let h = MAX_EXTENT / 2;
    let t = MAX_EXTENT / 2;
    let (speed, gap) = (MAX_SPEED, 2 * h + 7 * MAX_SPEED);
    for d in 0..4 {
        for (substeps, iterations) in [(1, 4), (MAX_ROUNDS, MAX_ROUNDS)] {
            // The far plate starts on the bound; the near one ends on it.
            let centre = v2(MAX_COORD - (gap - gap / 2) - t, MAX_COORD - MAX_EXTENT);
            let c = Crush {
                centre,
                d,
                body_half: h,
                plate_half: v2(t, MAX_EXTENT),
                gap,
                speed,
                substeps,
                iterations,
            };
            let (first, mut w, body, plates) = crush(&c);
            // The gap narrows by 2 * MAX_SPEED a tick: 3.5 ticks of room.
            assert_eq!(first, 4, "dir {d} substeps {substeps}");
            assert_eq!(along(d, pos(&w, plates[0])), MAX_COORD);
            let before = w.tick();
            for _ in 0..50 {
                w.step(&[]);
                let b = w.body(body).unwrap();
                assert!(b.pos().abs().max_element() <= MAX_COORD);
                assert!(b.vel().abs().max_element() <= MAX_SPEED);
            }
            assert_eq!(w.tick(), before + 50);
        }
    }
}

// ------------------------------------------------------------ properties

/// A coordinate at or near the world bound, or anywhere.
fn coord() -> impl Strategy<Value = i32> {
    prop_oneof![
        Just(MAX_COORD),
        Just(-MAX_COORD),
        (MAX_COORD - 4 * MAX_EXTENT)..=MAX_COORD,
        -MAX_COORD..=(-MAX_COORD + 4 * MAX_EXTENT),
        -MAX_COORD..=MAX_COORD,
    ]
}

/// A size from one unit to the extent bound, favouring both ends.
fn size() -> impl Strategy<Value = i32> {
    prop_oneof![
        Just(1),
        Just(MAX_EXTENT),
        (MAX_EXTENT - 1000)..=MAX_EXTENT,
        1..=MAX_EXTENT,
        1..=1000,
    ]
}

fn signed_size() -> impl Strategy<Value = i32> {
    prop_oneof![Just(0), size(), size().prop_map(|s| -s)]
}

fn speed() -> impl Strategy<Value = i32> {
    prop_oneof![
        Just(0),
        Just(MAX_SPEED),
        Just(-MAX_SPEED),
        -MAX_SPEED..=MAX_SPEED,
        -1000..=1000,
    ]
}

/// Any shape, with sizes up to the extent bound.
fn shape() -> impl Strategy<Value = AnyShape> {
    prop_oneof![
        Just(AnyShape::Point(Point)),
        (signed_size(), signed_size(), signed_size(), signed_size()).prop_filter_map(
            "zero length",
            |(a, b, c, d)| Segment::new(v2(a, b), v2(c, d)).ok().map(AnyShape::from)
        ),
        size().prop_map(|r| circle(r).into()),
        (size(), size()).prop_map(|(x, y)| aabb(v2(x, y)).into()),
        (size(), size(), -1000i32..=1000, -1000i32..=1000).prop_filter_map(
            "bad oriented box",
            |(x, y, dx, dy)| Obb::new(v2(x, y), v2(dx, dy)).ok().map(AnyShape::from)
        ),
        (size(), size(), 0usize..3).prop_filter_map("bad polygon", |(x, y, k)| {
            let p: Vec<IVec2> = match k {
                0 => vec![v2(-x, -y), v2(x, -y), v2(0, y)],
                1 => vec![v2(x, 0), v2(0, y), v2(-x, 0), v2(0, -y)],
                _ => vec![
                    v2(-x / 2, -y),
                    v2(x / 2, -y),
                    v2(x, -y / 2),
                    v2(x, y / 2),
                    v2(x / 2, y),
                    v2(-x / 2, y),
                    v2(-x, y / 2),
                    v2(-x, -y / 2),
                ],
            };
            ConvexPolygon::new(&p).ok().map(AnyShape::from)
        }),
    ]
}

#[derive(Debug, Clone)]
struct ColSpec {
    shape: AnyShape,
    offset: IVec2,
    trigger: bool,
    one_way: Option<OneWay>,
}

#[derive(Debug, Clone)]
struct BodySpec {
    kind: BodyKind,
    delta: IVec2,
    vel: IVec2,
    mass: u32,
    cols: Vec<ColSpec>,
}

fn col_spec() -> impl Strategy<Value = ColSpec> {
    let offset = prop_oneof![
        Just(0),
        Just(MAX_EXTENT),
        Just(-MAX_EXTENT),
        -MAX_EXTENT..=MAX_EXTENT
    ];
    (
        shape(),
        offset.clone(),
        offset,
        prop::bool::weighted(0.2),
        prop_oneof![
            6 => Just(None),
            1 => Just(Some(OneWay::Up)),
            1 => Just(Some(OneWay::Left)),
        ],
    )
        .prop_map(|(shape, x, y, trigger, one_way)| ColSpec {
            shape,
            offset: v2(x, y),
            trigger,
            one_way: if trigger { None } else { one_way },
        })
}

fn body_spec() -> impl Strategy<Value = BodySpec> {
    let near = prop_oneof![Just(0), -1000i32..=1000, -2 * MAX_EXTENT..=2 * MAX_EXTENT];
    (
        prop_oneof![
            1 => Just(BodyKind::Static),
            1 => Just(BodyKind::Kinematic),
            3 => Just(BodyKind::Dynamic),
        ],
        near.clone(),
        near,
        speed(),
        speed(),
        prop_oneof![Just(1u32), Just(u32::MAX), 1u32..=1000],
        prop::collection::vec(col_spec(), 1..=2),
    )
        .prop_map(|(kind, dx, dy, vx, vy, mass, cols)| BodySpec {
            kind,
            delta: v2(dx, dy),
            vel: if kind == BodyKind::Static {
                IVec2::ZERO
            } else {
                v2(vx, vy)
            },
            mass,
            cols,
        })
}

/// Builds a world around `anchor` (bodies clamped into the bound).
fn build(anchor: IVec2, bodies: &[BodySpec], cfg: SimConfig, mover: bool) -> World {
    let mut w = World::new(cfg).unwrap();
    for b in bodies {
        let p = (anchor.as_i64vec2() + b.delta.as_i64vec2())
            .clamp(
                glam::I64Vec2::splat(-MAX_COORD as i64),
                glam::I64Vec2::splat(MAX_COORD as i64),
            )
            .as_ivec2();
        let desc = BodyDesc {
            kind: b.kind,
            pos: p,
            vel: b.vel,
            mass: b.mass,
        };
        let id = w.add_body(desc).unwrap();
        for c in &b.cols {
            let mut d = if c.trigger {
                ColliderDesc::trigger(c.shape)
            } else {
                ColliderDesc::solid(c.shape)
            };
            d = d.at(c.offset);
            if let Some(o) = c.one_way {
                d = d.one_way(o);
            }
            w.add_collider(id, d).unwrap();
        }
        if mover && b.kind != BodyKind::Static {
            w.add_controller(Controller::Mover(Mover {
                body: id,
                config: MoverConfig {
                    accel: MAX_SPEED / 3,
                    brake: MAX_SPEED,
                    max_speed: MAX_SPEED,
                },
            }))
            .unwrap();
        }
    }
    w
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    /// Worlds at the bound with the largest shapes and speeds step without
    /// overflow; every body stays in bounds, static bodies stay put,
    /// kinematic bodies move exactly by their velocity (clamped at the
    /// bound), and stepping is deterministic.
    #[test]
    fn worlds_at_the_bounds_step_without_overflow(
        anchor in (coord(), coord()),
        bodies in prop::collection::vec(body_spec(), 1..=4),
        cfg in (prop_oneof![Just(1u32), Just(3), Just(MAX_ROUNDS)], prop_oneof![Just(1u32), Just(4), Just(MAX_ROUNDS)]),
        mover in any::<bool>(),
        inputs in prop::collection::vec(any::<u8>(), 4),
    ) {
        let cfg = config(cfg.0, cfg.1);
        let mut w = build(v2(anchor.0, anchor.1), &bodies, cfg, mover);
        let slots = w.controllers().len();
        for (t, &bits) in inputs.iter().enumerate() {
            let input = vec![Buttons(bits & 0x0f); slots];
            let before: Vec<(BodyKind, IVec2, IVec2)> =
                w.bodies().map(|(_, b)| (b.kind(), b.pos(), b.vel())).collect();
            let mut twin = w.clone();
            let events = w.step(&input).to_vec();
            prop_assert_eq!(twin.step(&input).to_vec(), events.clone());
            prop_assert_eq!(twin.state_hash(), w.state_hash());
            for ((i, b), (kind, p0, v0)) in w.bodies().zip(before) {
                let (p, v) = (b.pos(), b.vel());
                prop_assert!(p.abs().max_element() <= MAX_COORD, "tick {} body {:?}: {}", t, i, p);
                prop_assert!(v.abs().max_element() <= MAX_SPEED, "tick {} body {:?}: {}", t, i, v);
                match kind {
                    BodyKind::Static => prop_assert_eq!(p, p0),
                    BodyKind::Kinematic => {
                        let v = match w.controllers().iter().find(|c| c.body() == i) {
                            Some(Controller::Mover(m)) => m.next_velocity(v0, Buttons(bits & 0x0f)),
                            None => v0,
                        };
                        let want = (p0.as_i64vec2() + v.as_i64vec2())
                            .clamp(glam::I64Vec2::splat(-MAX_COORD as i64), glam::I64Vec2::splat(MAX_COORD as i64))
                            .as_ivec2();
                        prop_assert_eq!(p, want, "kinematic body {:?} tick {}", i, t);
                    }
                    BodyKind::Dynamic => {}
                }
            }
            for e in &events {
                if let Event::Squished { body } = e {
                    prop_assert_eq!(w.body(*body).unwrap().kind(), BodyKind::Dynamic);
                }
            }
        }
    }

}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4096))]

    /// The narrow phase at the bound: any two shapes up to MAX_EXTENT, their
    /// origins anywhere a collider can be (up to MAX_COORD + MAX_EXTENT):
    /// the answer does not depend on where they are, the reverse order is
    /// the reverse answer, and the MTV separates them.
    #[test]
    fn contacts_at_the_bounds_are_exact(
        a in shape(),
        b in shape(),
        anchor in (coord(), coord()),
        delta in (-2 * MAX_EXTENT..=2 * MAX_EXTENT, -2 * MAX_EXTENT..=2 * MAX_EXTENT),
        small in prop::bool::weighted(0.3),
    ) {
        let edge = (MAX_COORD + MAX_EXTENT) as i64;
        let delta = if small { v2(delta.0 % 1000, delta.1 % 1000) } else { v2(delta.0, delta.1) };
        let pa = v2(anchor.0, anchor.1);
        let pa = (pa.as_i64vec2() + pa.as_i64vec2().signum() * MAX_EXTENT as i64).as_ivec2();
        let pb = (pa.as_i64vec2() + delta.as_i64vec2()).clamp(glam::I64Vec2::splat(-edge), glam::I64Vec2::splat(edge)).as_ivec2();
        let rel = pb - pa;
        let here = check_pair(a, b, rel).map_err(TestCaseError::fail)?;
        prop_assert_eq!(prox(a, pa, b, pb), here);
        prop_assert_eq!(prox(b, pb, a, pa), prox(b, rel, a, IVec2::ZERO));
    }

    /// Shape constructors never panic, whatever the input, and accept only
    /// what fits the bounds.
    #[test]
    fn constructors_never_panic(
        a in any::<(i32, i32)>(),
        b in any::<(i32, i32)>(),
        c in any::<(i32, i32)>(),
    ) {
        let (a, b, c) = (IVec2::from(a), IVec2::from(b), IVec2::from(c));
        let fits = |s: AnyShape| {
            let (lo, hi) = s.local_bounds();
            lo.abs().max(hi.abs()).max_element() <= MAX_EXTENT
        };
        if let Ok(s) = Aabb::new(a) { prop_assert!(fits(s.into())); }
        if let Ok(s) = Aabb::from_size(a) { prop_assert!(fits(s.into())); }
        if let Ok(s) = Circle::new(a.x) { prop_assert!(fits(s.into())); }
        if let Ok(s) = Segment::new(a, b) { prop_assert!(fits(s.into())); }
        if let Ok(s) = Obb::new(a, b) { prop_assert!(fits(s.into())); }
        if let Ok(s) = Obb::from_axes(a, b) { prop_assert!(fits(s.into())); }
        if let Ok(s) = ConvexPolygon::new(&[a, b, c]) { prop_assert!(fits(s.into())); }
        let small = |v: IVec2| v / 16;
        if let Ok(s) = Obb::new(small(a), small(b)) { prop_assert!(fits(s.into())); }
        if let Ok(s) = ConvexPolygon::new(&[small(a), small(b), small(c)]) { prop_assert!(fits(s.into())); }
    }
}

// ------------------------------------------------------------ the long run

/// Ticks of the long run.
const LONG_RUN_TICKS: u64 = 1_000_000;
/// Period of its script: wander, gather in the corners, rest.
const WANDER: u64 = 1_600;
/// Ticks for the player to reach its corner, then for each group to reach
/// its own.
const GATHER_PLAYER: u64 = 300;
const GATHER_GROUP: u64 = 300;
const PERIOD: u64 = WANDER + GATHER_PLAYER + 3 * GATHER_GROUP + 100;
/// The corners the crowd gathers in, one group each (the player has the
/// fourth, top left).
const CORNERS: [IVec2; 3] = [IVec2::new(1, -1), IVec2::new(-1, 1), IVec2::new(1, 1)];

/// What the crowd does at phase `p` of the period.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    /// Random walks and scripted inputs; everyone collides with everyone.
    Wander,
    /// The player goes to the top-left corner; everyone else is disabled.
    Player,
    /// One group goes to its corner; everyone else is disabled.
    Group(IVec2),
    /// Everyone enabled, at rest in their corners.
    Rest,
}

fn stage(p: u64) -> Stage {
    if p < WANDER {
        Stage::Wander
    } else if p < WANDER + GATHER_PLAYER {
        Stage::Player
    } else if p < WANDER + GATHER_PLAYER + 3 * GATHER_GROUP {
        Stage::Group(CORNERS[((p - WANDER - GATHER_PLAYER) / GATHER_GROUP) as usize])
    } else {
        Stage::Rest
    }
}

/// The warm-up room with a crowd: the player (slot 0, scripted inputs) and
/// nine more bodies of every kind driven by velocity scripts, and a
/// kinematic platform shuttling along the bottom.
struct Crowd {
    world: World,
    player: BodyId,
    kinematic: BodyId,
    /// Each driven body with the corner it gathers in (`±1, ±1`).
    driven: Vec<(BodyId, IVec2)>,
}

impl Crowd {
    fn new() -> Crowd {
        let mut w = warmup_room();
        let player = w.controllers()[0].body();
        let t = TILE;
        let kinematic = w
            .add_body(BodyDesc::kinematic(v2(12 * t, 20 * t + t / 2)))
            .unwrap();
        w.add_collider(
            kinematic,
            ColliderDesc::solid(aabb(v2(px(24), px(4)))).tagged(40),
        )
        .unwrap();
        let [tr, bl, br] = CORNERS;
        // Each corner is a layer of its own whose bodies ignore each other
        // (so several share a corner without piling up in an order that
        // depends on how they arrive) and meet everything else: the room,
        // the platform, the player (layer 1, mask: all; it alone gathers top
        // left) and the bodies of the other corners.
        let crowd: [(AnyShape, (i32, i32), u32, IVec2); 9] = [
            (aabb(v2(px(7), px(5))).into(), (10, 4), 2, tr),
            (circle(px(6)).into(), (8, 12), 1, bl),
            (
                poly_px(&[(-6, -6), (6, -6), (7, 2), (0, 7), (-7, 2)]).into(),
                (30, 14),
                3,
                br,
            ),
            (aabb(IVec2::splat(px(4))).into(), (25, 5), 1, tr),
            (circle(px(5)).into(), (15, 8), 1, bl),
            (
                Obb::new(v2(px(7), px(4)), v2(2, 1)).unwrap().into(),
                (22, 16),
                2,
                br,
            ),
            (aabb(v2(px(6), px(3))).into(), (34, 9), 1, tr),
            (poly_px(&[(-6, 5), (6, 5), (0, -6)]).into(), (5, 20), 1, bl),
            (
                seg((-px(6), -px(2)), (px(6), px(2))).into(),
                (27, 20),
                1,
                br,
            ),
        ];
        let mut driven = Vec::new();
        for (i, (shape, (x, y), mass, corner)) in crowd.into_iter().enumerate() {
            let layer = match (corner.x, corner.y) {
                (1, -1) => 2,
                (-1, 1) => 4,
                _ => 8,
            };
            let b = w
                .add_body(BodyDesc::dynamic(v2(x * t + t / 2, y * t + t / 2)).with_mass(mass))
                .unwrap();
            w.add_collider(
                b,
                ColliderDesc::solid(shape)
                    .layers(layer, !layer)
                    .tagged(50 + i as u16),
            )
            .unwrap();
            driven.push((b, corner));
        }
        Crowd {
            world: w,
            player,
            kinematic,
            driven,
        }
    }

    /// Sets the velocities (and which bodies take part) of phase `p`;
    /// returns the player's input.
    ///
    /// The corners are gathered one group at a time with the others
    /// disabled: two bodies sliding head-on along the same wall towards
    /// different corners would block each other for good, and where they
    /// stopped would depend on the wander before.
    fn drive(&mut self, p: u64) -> Buttons {
        let w = &mut self.world;
        let stage = stage(p);
        let k = if p < 1_024 {
            if (p / 128) % 2 == 0 {
                v2(px(2), 0)
            } else {
                v2(-px(2), 0)
            }
        } else {
            IVec2::ZERO
        };
        w.set_velocity(self.kinematic, k).unwrap();
        let all = matches!(stage, Stage::Wander | Stage::Rest);
        w.set_enabled(self.player, all || stage == Stage::Player)
            .unwrap();
        for (i, &(b, corner)) in self.driven.iter().enumerate() {
            let mine = stage == Stage::Group(corner);
            w.set_enabled(b, all || mine).unwrap();
            let v = if stage == Stage::Wander {
                // A random walk pulled towards the block in the middle, so
                // that bodies meet.
                let s = mix(i as u64 + 100, p / 30);
                let pull = (v2(20 * TILE, 12 * TILE) - pos(w, b)).signum() * px(1);
                v2(pick(s, 8, -px(2), px(2)), pick(s, 32, -px(2), px(2))) + pull
            } else if mine {
                corner * v2(px(2) + 37, px(2) - 19)
            } else {
                IVec2::ZERO
            };
            w.set_velocity(b, v).unwrap();
        }
        match stage {
            Stage::Wander => scripted_inputs(p),
            Stage::Player => Buttons(Buttons::LEFT | Buttons::UP),
            _ => Buttons::NONE,
        }
    }

    /// A hash of every body's whole state (position, velocity, sides,
    /// displacement, pushes, carrier): everything but the tick count.
    fn body_hash(&self) -> u64 {
        let mut h = 0u64;
        for (_, b) in self.world.bodies() {
            for v in [b.pos(), b.vel(), b.displacement(), b.pushed()] {
                h = mix(h, (v.x as u32 as u64) << 32 | v.y as u32 as u64);
            }
            h = mix(
                h,
                b.sides().0 as u64 | (b.carrier().map_or(0, |c| c.0 as u64 + 1) << 8),
            );
        }
        h
    }
}

/// Per period of the long run: a hash of every tick's body states, and
/// counts of contacts with the room, other contacts, triggers, squishes.
type PeriodLog = (u64, [u32; 4]);

/// Steps the crowd from tick `from` to `to`, logging the body state at the
/// start of every period into `phase0` and every whole period into
/// `periods` (both must have room: nothing here allocates).
fn run_crowd(
    crowd: &mut Crowd,
    from: u64,
    to: u64,
    phase0: &mut Vec<u64>,
    periods: &mut Vec<PeriodLog>,
) {
    let mut h = 0u64;
    let mut counts = [0u32; 4];
    for t in from..to {
        let p = t % PERIOD;
        if p == 0 {
            phase0.push(crowd.body_hash());
            h = 0;
            counts = [0; 4];
        }
        let input = crowd.drive(p);
        for e in crowd.world.step(&[input]) {
            counts[match e {
                Event::Contact { other_body, .. } if *other_body == BodyId(0) => 0,
                Event::Contact { .. } => 1,
                Event::Trigger { .. } => 2,
                // Sweeps are off here: no swept hits.
                Event::Squished { .. } | Event::SweptHit { .. } => 3,
            }] += 1;
        }
        h = mix(h, crowd.body_hash());
        if p == WANDER + GATHER_PLAYER - 1 || p == PERIOD - 1 {
            // Closed form: the player is flush in the top-left corner.
            let corner = IVec2::splat(TILE + PLAYER_HALF);
            assert_eq!(pos(&crowd.world, crowd.player), corner, "tick {t}");
        }
        if p == PERIOD - 1 {
            periods.push((h, counts));
        }
    }
}

#[test]
fn a_long_busy_run_is_periodic_and_allocates_nothing() {
    let started = Instant::now();
    let mut crowd = Crowd::new();
    let warmup = 2 * PERIOD;
    let periods_total = LONG_RUN_TICKS.div_ceil(PERIOD) as usize;
    let mut phase0 = Vec::with_capacity(periods_total);
    let mut periods = Vec::with_capacity(periods_total);
    run_crowd(&mut crowd, 0, warmup, &mut phase0, &mut periods);
    let ((), calls, net) = allocations(|| {
        run_crowd(
            &mut crowd,
            warmup,
            LONG_RUN_TICKS,
            &mut phase0,
            &mut periods,
        )
    });
    let elapsed = started.elapsed();
    assert_eq!(crowd.world.tick(), LONG_RUN_TICKS);
    // From the second period on, every period starts in the same state and
    // repeats tick for tick: nothing drifts.
    assert_eq!(phase0.len(), periods_total);
    for (k, h) in phase0.iter().enumerate().skip(1) {
        assert_eq!(*h, phase0[1], "state at the start of period {k}");
    }
    for (k, h) in periods.iter().enumerate().skip(1) {
        assert_eq!(*h, periods[1], "period {k}");
    }
    // Memory: the world's buffers grew during warm-up and never after.
    assert_eq!(
        (calls, net),
        (0, 0),
        "allocations and live bytes added after warm-up ({} ticks)",
        LONG_RUN_TICKS - warmup
    );
    // And the period is busy.
    let counts = periods[1].1;
    assert!(
        counts[0] > 5_000 && counts[1] > 2_000 && counts[2] > 10,
        "contacts with the room, with other bodies, triggers, squishes: {counts:?}"
    );
    eprintln!(
        "long run: {LONG_RUN_TICKS} ticks in {elapsed:.2?}; per period: {counts:?} \
         (room contacts, other contacts, triggers, squishes)"
    );
}
