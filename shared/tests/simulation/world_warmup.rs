//! The warm-up room: sliding along every surface across its seams at every
//! subpixel offset, contact events with the right tag, the mover's
//! acceleration and braking.

use glam::IVec2;
use ledge_shared::fixed::px;
use ledge_shared::input::Buttons;
use ledge_shared::scene::{tag, warmup_room, warmup_room_with, PLAYER_HALF, TILE};
use ledge_shared::world::{BodyId, Controller, Event, MoverConfig, Sides, SimConfig, World};

const H: i32 = PLAYER_HALF;

fn player(w: &World) -> BodyId {
    w.controllers()[0].body()
}

fn mover(w: &World) -> MoverConfig {
    match w.controllers()[0] {
        Controller::Mover(m) => m.config,
    }
}

/// World bounds of every collider with `tag`.
fn boxes(w: &World, t: u16) -> Vec<(IVec2, IVec2)> {
    w.colliders()
        .filter(|c| c.tag == t)
        .map(|c| c.world_bounds())
        .collect()
}

/// The room's inner faces: (left, right, top, bottom), read from the colliders.
fn interior(w: &World) -> (i32, i32, i32, i32) {
    let walls = boxes(w, tag::WALL);
    let mid = walls.iter().map(|b| b.0.x).sum::<i32>() / walls.len() as i32;
    let left = walls
        .iter()
        .filter(|b| b.1.x < mid)
        .map(|b| b.1.x)
        .max()
        .unwrap();
    let right = walls
        .iter()
        .filter(|b| b.0.x > mid)
        .map(|b| b.0.x)
        .min()
        .unwrap();
    let top = boxes(w, tag::CEILING).iter().map(|b| b.1.y).max().unwrap();
    let bottom = boxes(w, tag::FLOOR).iter().map(|b| b.0.y).min().unwrap();
    (left, right, top, bottom)
}

fn axis(v: IVec2, k: usize) -> i32 {
    v.to_array()[k]
}

fn vec(k: usize, along: i32, across: i32) -> IVec2 {
    if k == 0 {
        IVec2::new(along, across)
    } else {
        IVec2::new(across, along)
    }
}

/// One surface to slide along.
struct Surface {
    name: &'static str,
    tag: u16,
    /// Axis the square slides along (0 = x, 1 = y).
    along: usize,
    /// Direction of the surface from the square along the other axis (+1 or -1).
    into: i32,
    /// Key pressing the square into the surface.
    key: u8,
    /// Side of the square that touches the surface.
    side: Sides,
}

fn surfaces() -> [Surface; 4] {
    [
        Surface {
            name: "floor",
            tag: tag::FLOOR,
            along: 0,
            into: 1,
            key: Buttons::DOWN,
            side: Sides::BOTTOM,
        },
        Surface {
            name: "ceiling",
            tag: tag::CEILING,
            along: 0,
            into: -1,
            key: Buttons::UP,
            side: Sides::TOP,
        },
        Surface {
            name: "left wall",
            tag: tag::WALL,
            along: 1,
            into: -1,
            key: Buttons::LEFT,
            side: Sides::LEFT,
        },
        Surface {
            name: "right wall",
            tag: tag::WALL,
            along: 1,
            into: 1,
            key: Buttons::RIGHT,
            side: Sides::RIGHT,
        },
    ]
}

/// Slides along `s` in direction `dir` from subpixel offset `o`; returns the
/// number of ticks spent sliding in contact.
fn slide(config: SimConfig, s: &Surface, dir: i32, o: i32) -> u32 {
    let mut w = warmup_room_with(config).unwrap();
    let p = player(&w);
    let max = mover(&w).max_speed;
    let (left, right, top, bottom) = interior(&w);
    let across = 1 - s.along;
    // Where the square's centre is when it rests against the surface.
    let line = match (across, s.into) {
        (1, 1) => bottom - H,
        (1, _) => top + H,
        (_, 1) => right - H,
        _ => left + H,
    };
    let (lo, hi) = if s.along == 0 {
        (left, right)
    } else {
        (top, bottom)
    };
    let start_along = if dir > 0 {
        lo + H + px(2) + o
    } else {
        hi - H - px(2) - o
    };
    // 1 px plus the offset away from the surface.
    let start_across = line - s.into * (px(1) + o);
    w.set_position(p, vec(s.along, start_along, start_across))
        .unwrap();
    w.set_velocity(p, vec(s.along, dir * max, 0)).unwrap();
    let along_key = match (s.along, dir) {
        (0, 1) => Buttons::RIGHT,
        (0, _) => Buttons::LEFT,
        (_, 1) => Buttons::DOWN,
        _ => Buttons::UP,
    };
    let keys = Buttons(s.key | along_key);
    let ctx = |t: u32| format!("{} dir {dir} offset {o} tick {t} ({config:?})", s.name);
    let mut touching = 0;
    for t in 0.. {
        let before = w.body(p).unwrap().pos();
        let events = w.step(&[keys]).to_vec();
        let b = w.body(p).unwrap();
        // Along the surface: exactly the maximum speed, every tick.
        assert_eq!(
            axis(b.vel(), s.along),
            dir * max,
            "velocity along, {}",
            ctx(t)
        );
        assert_eq!(
            axis(b.pos() - before, s.along),
            dir * max,
            "displacement along, {}",
            ctx(t)
        );
        assert_eq!(b.displacement(), b.pos() - before);
        // Across: never inside the surface, never pushed off its line.
        let c = axis(b.pos(), across);
        assert!(
            s.into * (c - line) <= 0,
            "inside the surface: {c} vs {line}, {}",
            ctx(t)
        );
        assert!(
            !events.iter().any(|e| matches!(e, Event::Squished { .. })),
            "squished, {}",
            ctx(t)
        );
        if touching > 0 {
            assert_eq!(c, line, "pushed off the surface line, {}", ctx(t));
        }
        if c == line {
            touching += 1;
            let hit = events.iter().any(|e| {
                matches!(e, Event::Contact { body, other_tag, sides, .. }
                    if *body == p && *other_tag == s.tag && sides.contains(s.side))
            });
            // The first tick may end exactly on the line without overlapping.
            assert!(
                hit || touching == 1,
                "no {} contact event, {}: {events:?}",
                s.name,
                ctx(t)
            );
            assert!(
                b.sides().contains(s.side) || touching == 1,
                "sides {:?}, {}",
                b.sides(),
                ctx(t)
            );
        }
        let lead = axis(b.pos(), s.along) + dir * H;
        let end = if dir > 0 { hi } else { lo };
        if dir * (end - lead) <= 2 * max {
            break;
        }
    }
    assert!(touching > 100, "{}: slid only {touching} ticks", ctx(0));
    touching
}

#[test]
fn the_room_has_seams_on_every_surface() {
    let w = warmup_room();
    assert!(boxes(&w, tag::FLOOR).len() >= 3);
    assert!(boxes(&w, tag::CEILING).len() >= 3);
    assert!(boxes(&w, tag::WALL).len() >= 6);
    assert_eq!(boxes(&w, tag::BLOCK).len(), 1);
    assert_eq!(boxes(&w, tag::PLATFORM).len(), 1);
    let (l, r, t, b) = interior(&w);
    assert_eq!((l, r, t, b), (TILE, 39 * TILE, TILE, 23 * TILE));
    // The square is 16 x 16 px.
    let sq = w
        .colliders()
        .find(|c| c.body == player(&w))
        .unwrap()
        .world_bounds();
    assert_eq!(sq.1 - sq.0, IVec2::splat(px(16)));
}

#[test]
fn sliding_along_every_surface_never_snags_at_any_subpixel_offset() {
    let configs = [
        SimConfig::default(),
        SimConfig {
            substeps: 3,
            restitution_iterations: 2,
            ..SimConfig::default()
        },
    ];
    for config in configs {
        for s in &surfaces() {
            for dir in [1, -1] {
                for o in 0..256 {
                    slide(config, s, dir, o);
                }
            }
        }
    }
}

/// Drives the square from `start` with `keys` until an event matching `want`
/// (or `limit` ticks); returns the world and the matching event.
fn drive(
    start: IVec2,
    keys: u8,
    limit: u32,
    want: impl Fn(&Event) -> bool,
) -> (World, Option<Event>) {
    let mut w = warmup_room();
    let p = player(&w);
    w.set_position(p, start).unwrap();
    for _ in 0..limit {
        if let Some(e) = w.step(&[Buttons(keys)]).iter().find(|e| want(e)) {
            let e = *e;
            return (w, Some(e));
        }
    }
    (w, None)
}

fn contact_with(t: u16) -> impl Fn(&Event) -> bool {
    move |e| matches!(e, Event::Contact { other_tag, .. } if *other_tag == t)
}

#[test]
fn touching_each_kind_of_surface_reports_its_tag() {
    let cases = [
        (
            "left wall",
            IVec2::new(3 * TILE, 5 * TILE),
            Buttons::LEFT,
            tag::WALL,
            Sides::LEFT,
            IVec2::new(TILE + H, -1),
        ),
        (
            "right wall",
            IVec2::new(35 * TILE, 5 * TILE),
            Buttons::RIGHT,
            tag::WALL,
            Sides::RIGHT,
            IVec2::new(39 * TILE - H, -1),
        ),
        (
            "floor",
            IVec2::new(5 * TILE, 20 * TILE),
            Buttons::DOWN,
            tag::FLOOR,
            Sides::BOTTOM,
            IVec2::new(-1, 23 * TILE - H),
        ),
        (
            "ceiling",
            IVec2::new(5 * TILE, 5 * TILE),
            Buttons::UP,
            tag::CEILING,
            Sides::TOP,
            IVec2::new(-1, TILE + H),
        ),
        (
            "block",
            IVec2::new(15 * TILE, 12 * TILE),
            Buttons::RIGHT,
            tag::BLOCK,
            Sides::RIGHT,
            IVec2::new(18 * TILE - H, -1),
        ),
        (
            "platform",
            IVec2::new(10 * TILE, 14 * TILE),
            Buttons::DOWN,
            tag::PLATFORM,
            Sides::BOTTOM,
            IVec2::new(-1, 17 * TILE - H),
        ),
    ];
    for (name, start, key, t, side, face) in cases {
        let (w, e) = drive(start, key, 400, contact_with(t));
        let Some(Event::Contact { body, sides, .. }) = e else {
            panic!("{name}: no contact event")
        };
        let w_player = player(&w);
        assert_eq!(body, w_player, "{name}");
        assert_eq!(sides, side, "{name}");
        let pos = w.body(w_player).unwrap().pos();
        // Pushed out exactly to the face on the contact axis.
        if face.x >= 0 {
            assert_eq!(pos.x, face.x, "{name}");
        } else {
            assert_eq!(pos.y, face.y, "{name}");
        }
        assert!(w.body(w_player).unwrap().sides().contains(side), "{name}");
    }
}

#[test]
fn the_platform_lets_the_square_through_from_below() {
    // From below the platform moving up: straight through, up to the ceiling.
    let (w, e) = drive(
        IVec2::new(10 * TILE, 20 * TILE),
        Buttons::UP,
        400,
        contact_with(tag::CEILING),
    );
    assert!(e.is_some());
    assert_eq!(w.body(player(&w)).unwrap().pos().y, TILE + H);
    let (_, e) = drive(
        IVec2::new(10 * TILE, 20 * TILE),
        Buttons::UP,
        400,
        contact_with(tag::PLATFORM),
    );
    assert!(
        e.is_none(),
        "the one-way platform blocked a body from below: {e:?}"
    );
}

#[test]
fn the_pad_is_a_trigger() {
    let p = |e: &Event| matches!(e, Event::Trigger { tag: t, .. } if *t == tag::PAD);
    let (w, e) = drive(
        IVec2::new(27 * TILE, 19 * TILE + TILE / 2),
        Buttons::RIGHT,
        400,
        p,
    );
    let Some(Event::Trigger {
        body, other_tag, ..
    }) = e
    else {
        panic!("no trigger event")
    };
    assert_eq!(body, player(&w));
    assert_eq!(other_tag, tag::PLAYER);
    // It never slowed the square.
    assert_eq!(w.body(body).unwrap().vel().x, mover(&w).max_speed);
}

#[test]
fn acceleration_and_braking_follow_the_mover_config() {
    let mut w = warmup_room();
    let p = player(&w);
    let c = mover(&w);
    assert!(c.accel > 0 && c.brake > 0 && c.max_speed > c.accel);
    w.set_position(p, IVec2::new(10 * TILE, 8 * TILE)).unwrap();
    let mut expect = IVec2::ZERO;
    let check = |w: &mut World, keys: u8, expect: IVec2| {
        let before = w.body(p).unwrap().pos();
        w.step(&[Buttons(keys)]);
        let b = w.body(p).unwrap();
        assert_eq!(b.vel(), expect, "keys {keys:#b}");
        assert_eq!(b.pos() - before, expect, "moves by its new velocity");
    };
    // Right and up from rest: +accel per tick up to the maximum.
    for _ in 0..40 {
        expect = IVec2::new(
            (expect.x + c.accel).min(c.max_speed),
            (expect.y - c.accel).max(-c.max_speed),
        );
        check(&mut w, Buttons::RIGHT | Buttons::UP, expect);
    }
    assert_eq!(expect, IVec2::new(c.max_speed, -c.max_speed));
    // Release up only: y brakes towards zero and stops there; x keeps going.
    for _ in 0..10 {
        expect = IVec2::new(c.max_speed, (expect.y + c.brake).min(0));
        check(&mut w, Buttons::RIGHT, expect);
    }
    assert_eq!(expect.y, 0);
    // Reverse: left accelerates against the motion, through zero, to -max.
    for _ in 0..30 {
        expect.x = (expect.x - c.accel).max(-c.max_speed);
        check(&mut w, Buttons::LEFT, expect);
    }
    assert_eq!(expect.x, -c.max_speed);
    // Both horizontal keys cancel: braking.
    while expect.x != 0 {
        expect.x = (expect.x + c.brake).min(0);
        check(&mut w, Buttons::LEFT | Buttons::RIGHT, expect);
    }
    check(&mut w, 0, IVec2::ZERO);
}
