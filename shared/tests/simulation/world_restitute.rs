//! Restitution and detection rules, one small world per rule.

use glam::IVec2;
use ledge_shared::fixed::{px, BoundsError, MAX_COORD, MAX_EXTENT, MAX_SPEED};
use ledge_shared::query::{Contact, Proximity};
use ledge_shared::shape::{Aabb, Circle};
use ledge_shared::world::{
    BodyDesc, BodyId, BuildError, ColliderDesc, ColliderId, Event, OneWay, Sides, SimConfig, World,
};

const H: i32 = px(8);

fn aabb(half: IVec2) -> Aabb {
    Aabb::new(half).unwrap()
}

/// A static box of half size `half` centred at `centre`.
fn fixed(w: &mut World, centre: IVec2, half: IVec2) -> (BodyId, ColliderId) {
    let b = w.add_body(BodyDesc::fixed(centre)).unwrap();
    (
        b,
        w.add_collider(b, ColliderDesc::solid(aabb(half))).unwrap(),
    )
}

/// A dynamic 16 x 16 px box.
fn square(w: &mut World, pos: IVec2, vel: IVec2) -> (BodyId, ColliderId) {
    square_mass(w, pos, vel, 1)
}

fn square_mass(w: &mut World, pos: IVec2, vel: IVec2, mass: u32) -> (BodyId, ColliderId) {
    let b = w
        .add_body(BodyDesc::dynamic(pos).with_vel(vel).with_mass(mass))
        .unwrap();
    (
        b,
        w.add_collider(b, ColliderDesc::solid(aabb(IVec2::splat(H))))
            .unwrap(),
    )
}

fn pos(w: &World, b: BodyId) -> IVec2 {
    w.body(b).unwrap().pos()
}

fn vel(w: &World, b: BodyId) -> IVec2 {
    w.body(b).unwrap().vel()
}

fn contacts(events: &[Event]) -> Vec<(BodyId, ColliderId, Sides)> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Contact {
                body,
                other_collider,
                sides,
                ..
            } => Some((*body, *other_collider, *sides)),
            _ => None,
        })
        .collect()
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

/// A floor seam at x = 0 whose right box (the one being entered) has the
/// lower collider id. The square slides right pressing down and ends the move
/// `ox` units into the right box and `p` units into the floor.
#[test]
fn largest_mtv_first_and_the_area_tie_break_prevent_seam_snags() {
    for (ox, p) in [(10, 40), (39, 40), (40, 40), (1, 1), (40, 41), (200, 40)] {
        let mut w = World::default();
        let half = IVec2::new(px(50), px(8));
        let (_, entered) = fixed(&mut w, IVec2::new(px(50), px(8)), half);
        let (_, left) = fixed(&mut w, IVec2::new(-px(50), px(8)), half);
        assert!(entered < left);
        let vx = 300;
        let start = IVec2::new(-(vx - ox) - H, -H);
        let (b, _) = square(&mut w, start, IVec2::new(vx, p));
        // The box being entered offers a sideways push no deeper than the
        // floor's upward one (equal when ox == p: the kernel then picks x).
        let moved = start + IVec2::new(vx, p);
        let side = aabb(IVec2::splat(H)).contact(moved, &aabb(half), IVec2::new(px(50), px(8)));
        if ox <= p {
            assert_eq!(side, Proximity::Overlapping(IVec2::new(-ox, 0)));
        }
        let events = w.step(&[]).to_vec();
        let ctx = format!("ox {ox} p {p}");
        assert_eq!(pos(&w, b), IVec2::new(start.x + vx, -H), "{ctx}: snagged");
        assert_eq!(vel(&w, b), IVec2::new(vx, 0), "{ctx}");
        // Only the floor box it stands on pushed it.
        assert_eq!(contacts(&events), vec![(b, left, Sides::BOTTOM)], "{ctx}");
    }
}

/// Two floor boxes overlap each other with the same top: both report the
/// same upward MTV, but once the first is applied the second is stale, is
/// re-checked, and no longer overlaps.
#[test]
fn a_stale_mtv_is_rechecked_before_use() {
    let mut w = World::default();
    let (_, a) = fixed(&mut w, IVec2::new(0, px(8)), IVec2::new(px(50), px(8)));
    fixed(&mut w, IVec2::new(0, px(4)), IVec2::new(px(30), px(4)));
    let (b, _) = square(&mut w, IVec2::new(0, -H), IVec2::new(0, 40));
    let events = w.step(&[]).to_vec();
    assert_eq!(pos(&w, b), IVec2::new(0, -H), "pushed out twice");
    assert_eq!(vel(&w, b), IVec2::ZERO);
    // Equal MTVs and equal areas: the lower id goes first.
    assert_eq!(contacts(&events), vec![(b, a, Sides::BOTTOM)]);
}

#[test]
fn two_dynamic_bodies_split_the_mtv_by_mass() {
    for (ma, mb, overlap) in [
        (1, 3, 12),
        (1, 2, 10),
        (1, 1, 7),
        (5, 5, 1),
        (7, 2, 33),
        (1, 1000, 3),
    ] {
        let mut w = World::default();
        let (a, _) = square_mass(&mut w, IVec2::ZERO, IVec2::ZERO, ma);
        let (b, _) = square_mass(&mut w, IVec2::new(2 * H - overlap, 0), IVec2::ZERO, mb);
        let events = w.step(&[]).to_vec();
        let (da, db) = (pos(&w, a).x, pos(&w, b).x - (2 * H - overlap));
        let ctx = format!("masses {ma}:{mb} overlap {overlap}");
        // The two shares sum to the MTV exactly: touching, not overlapping, no gap.
        assert_eq!(db - da, overlap, "{ctx}");
        // The lighter body moves more; shares are rounded to nearest.
        let exact_a = overlap as f64 * mb as f64 / (ma + mb) as f64;
        assert!(
            (-da as f64 - exact_a).abs() <= 0.5,
            "{ctx}: A moved {da}, exact {exact_a}"
        );
        assert_eq!(pos(&w, a).y, 0);
        let mut c = contacts(&events);
        c.retain(|x| x.0 == a || x.0 == b);
        assert_eq!(c.len(), (da != 0) as usize + (db != 0) as usize, "{ctx}");
    }
}

#[test]
fn the_velocity_pushed_against_is_removed() {
    let mut w = World::default();
    let (wall, _) = fixed(&mut w, IVec2::new(px(40), 0), IVec2::new(px(8), px(100)));
    // Right edge 1 px before the wall's face, moving (300, 100).
    let (b, _) = square(
        &mut w,
        IVec2::new(px(32) - H - px(1) + 20, 0),
        IVec2::new(300, 100),
    );
    w.step(&[]);
    assert_eq!(pos(&w, b), IVec2::new(px(32) - H, 100));
    assert_eq!(
        vel(&w, b),
        IVec2::new(0, 100),
        "only the component into the wall is removed"
    );
    assert_eq!(w.body(b).unwrap().sides(), Sides::RIGHT);
    assert_eq!(
        pos(&w, wall),
        IVec2::new(px(40), 0),
        "static bodies never move"
    );
    // Moving away from the wall keeps its velocity.
    w.set_velocity(b, IVec2::new(-50, 0)).unwrap();
    w.step(&[]);
    assert_eq!(vel(&w, b), IVec2::new(-50, 0));
    assert_eq!(
        w.body(b).unwrap().sides(),
        Sides::NONE,
        "sides are reset each tick"
    );
}

#[test]
fn a_slanted_push_removes_only_the_velocity_against_it() {
    // A circle falling onto the corner of a box is pushed diagonally.
    let mut w = World::default();
    fixed(&mut w, IVec2::new(0, px(8)), IVec2::new(px(8), px(8)));
    let b = w
        .add_body(
            BodyDesc::dynamic(IVec2::new(px(8) + px(3), -px(3))).with_vel(IVec2::new(-200, 300)),
        )
        .unwrap();
    w.add_collider(b, ColliderDesc::solid(Circle::new(px(4)).unwrap()))
        .unwrap();
    let events = w.step(&[]).to_vec();
    assert_eq!(contacts(&events).len(), 1);
    let v = vel(&w, b);
    let p = pos(&w, b) - IVec2::new(px(8), 0);
    // Pushed away from the corner: the remaining velocity does not point into it.
    assert!(
        v.as_i64vec2().dot(p.as_i64vec2()) >= 0,
        "v {v} still points into the corner at {p}"
    );
    assert_ne!(v, IVec2::ZERO, "the tangential part is kept");
    assert!(w
        .body(b)
        .unwrap()
        .sides()
        .contains(Sides::BOTTOM | Sides::LEFT));
}

#[test]
fn kinematic_bodies_push_and_are_never_pushed() {
    let mut w = World::default();
    let k = w
        .add_body(BodyDesc::kinematic(IVec2::ZERO).with_vel(IVec2::new(200, 0)))
        .unwrap();
    w.add_collider(k, ColliderDesc::solid(aabb(IVec2::splat(H))))
        .unwrap();
    let (b, _) = square(&mut w, IVec2::new(2 * H + 50, 0), IVec2::ZERO);
    for t in 1..=20 {
        w.step(&[]);
        assert_eq!(pos(&w, k), IVec2::new(200 * t, 0));
        assert_eq!(vel(&w, k), IVec2::new(200, 0));
        assert!(
            pos(&w, b).x >= pos(&w, k).x + 2 * H,
            "overlap left at tick {t}"
        );
    }
    assert_eq!(pos(&w, b).x, pos(&w, k).x + 2 * H);
    assert_eq!(w.body(b).unwrap().sides(), Sides::LEFT);
}

fn platform(w: &mut World) -> (BodyId, ColliderId) {
    // Top face at y = 0, 8 px thick, 100 px wide, solid from above.
    let b = w.add_body(BodyDesc::fixed(IVec2::new(0, px(4)))).unwrap();
    let c = ColliderDesc::solid(aabb(IVec2::new(px(50), px(4))))
        .one_way(OneWay::Up)
        .tagged(5);
    (b, w.add_collider(b, c).unwrap())
}

/// Steps `ticks` times; asserts the body moves freely (by its velocity,
/// never pushed) and no contact is reported.
fn assert_passes(w: &mut World, b: BodyId, ticks: i32, ctx: &str) {
    let (p0, v) = (pos(w, b), vel(w, b));
    for t in 1..=ticks {
        let events = w.step(&[]).to_vec();
        assert_eq!(pos(w, b), p0 + v * t, "{ctx}: blocked at tick {t}");
        assert!(contacts(&events).is_empty(), "{ctx}: {events:?}");
        assert!(squished(&events).is_empty(), "{ctx}");
    }
}

#[test]
fn one_way_platforms_block_from_their_side_only() {
    // From above: lands on top and stays there.
    let mut w = World::default();
    let (_, plat) = platform(&mut w);
    let (b, _) = square(&mut w, IVec2::new(0, -H - px(2)), IVec2::new(0, px(3)));
    let events = w.step(&[]).to_vec();
    assert_eq!(pos(&w, b), IVec2::new(0, -H));
    assert_eq!(contacts(&events), vec![(b, plat, Sides::BOTTOM)]);
    for _ in 0..10 {
        w.set_velocity(b, IVec2::new(0, 300)).unwrap();
        let events = w.step(&[]).to_vec();
        assert_eq!(pos(&w, b), IVec2::new(0, -H), "fell through from above");
        assert_eq!(contacts(&events).len(), 1);
    }

    // From below: straight through.
    let mut w = World::default();
    platform(&mut w);
    let (b, _) = square(
        &mut w,
        IVec2::new(0, px(8) + H + px(1)),
        IVec2::new(0, -px(3)),
    );
    assert_passes(&mut w, b, 12, "from below");

    // From the side (overlapping its height): straight through.
    let mut w = World::default();
    platform(&mut w);
    let (b, _) = square(
        &mut w,
        IVec2::new(-px(50) - H - px(1), px(4)),
        IVec2::new(px(3), 0),
    );
    assert_passes(&mut w, b, 12, "from the side");

    // From inside (it did not come from above this tick): keeps going down.
    let mut w = World::default();
    platform(&mut w);
    let (b, _) = square(&mut w, IVec2::new(0, -H + px(4)), IVec2::new(0, px(1)));
    assert_passes(&mut w, b, 12, "from inside");
}

#[test]
fn a_rising_one_way_platform_carries_a_body_resting_on_it() {
    // The rule uses the displacement relative to the platform's body.
    let mut w = World::default();
    let k = w
        .add_body(BodyDesc::kinematic(IVec2::new(0, px(4))).with_vel(IVec2::new(0, -100)))
        .unwrap();
    w.add_collider(
        k,
        ColliderDesc::solid(aabb(IVec2::new(px(50), px(4)))).one_way(OneWay::Up),
    )
    .unwrap();
    let (b, _) = square(&mut w, IVec2::new(0, -H), IVec2::ZERO);
    for t in 1..=10 {
        w.step(&[]);
        assert_eq!(pos(&w, b), IVec2::new(0, -H - 100 * t));
    }
}

#[test]
fn layers_and_masks_filter_pairs_both_ways() {
    for (wall_layer, wall_mask, body_layer, body_mask, blocks) in [
        (2, 1, 1, 2, true),
        (1, u32::MAX, 1, u32::MAX, true),
        (2, u32::MAX, 1, 1, false),
        (2, 2, 1, u32::MAX, false),
        (4, 0, 4, u32::MAX, false),
    ] {
        let mut w = World::default();
        let wb = w.add_body(BodyDesc::fixed(IVec2::new(px(40), 0))).unwrap();
        let wc =
            ColliderDesc::solid(aabb(IVec2::new(px(8), px(100)))).layers(wall_layer, wall_mask);
        w.add_collider(wb, wc).unwrap();
        let b = w
            .add_body(BodyDesc::dynamic(IVec2::ZERO).with_vel(IVec2::new(px(3), 0)))
            .unwrap();
        let bc = ColliderDesc::solid(aabb(IVec2::splat(H))).layers(body_layer, body_mask);
        w.add_collider(b, bc).unwrap();
        let ctx = format!("wall {wall_layer}/{wall_mask} body {body_layer}/{body_mask}");
        if blocks {
            for _ in 0..20 {
                w.step(&[]);
            }
            assert_eq!(pos(&w, b).x, px(32) - H, "{ctx}");
        } else {
            assert_passes(&mut w, b, 20, &ctx);
        }
    }
}

#[test]
fn triggers_report_and_never_move_anything() {
    let mut w = World::default();
    let zone = w.add_body(BodyDesc::fixed(IVec2::new(px(40), 0))).unwrap();
    let tc = w
        .add_collider(
            zone,
            ColliderDesc::trigger(aabb(IVec2::splat(px(16)))).tagged(77),
        )
        .unwrap();
    let b = w
        .add_body(BodyDesc::dynamic(IVec2::ZERO).with_vel(IVec2::new(200, 0)))
        .unwrap();
    let bc = w
        .add_collider(b, ColliderDesc::solid(aabb(IVec2::splat(H))).tagged(3))
        .unwrap();
    let mut inside = 0;
    for t in 1..=200 {
        let events = w.step(&[]).to_vec();
        let x = 200 * t;
        assert_eq!(pos(&w, b), IVec2::new(x, 0), "a trigger moved the body");
        assert_eq!(vel(&w, b), IVec2::new(200, 0), "a trigger slowed the body");
        assert_eq!(pos(&w, zone), IVec2::new(px(40), 0));
        let overlaps = (x - px(40)).abs() < px(16) + H;
        let expect = if overlaps {
            inside += 1;
            vec![Event::Trigger {
                body: b,
                collider: bc,
                trigger_body: zone,
                trigger: tc,
                tag: 77,
                other_tag: 3,
            }]
        } else {
            vec![]
        };
        assert_eq!(events, expect, "tick {t}");
    }
    assert!(inside > 10);
}

#[test]
fn a_dynamic_bodys_sensor_reports_solids_and_never_pushes() {
    let mut w = World::default();
    let (floor, fc) = fixed(&mut w, IVec2::new(0, px(8)), IVec2::new(px(50), px(8)));
    let b = w.add_body(BodyDesc::dynamic(IVec2::new(0, -H))).unwrap();
    w.add_collider(b, ColliderDesc::solid(aabb(IVec2::splat(H))))
        .unwrap();
    // A foot sensor 2 px tall straddling the body's bottom edge.
    let foot = ColliderDesc::trigger(aabb(IVec2::new(px(4), px(1))))
        .at(IVec2::new(0, H))
        .tagged(9);
    let sensor = w.add_collider(b, foot).unwrap();
    w.add_collider(
        floor,
        ColliderDesc::trigger(aabb(IVec2::splat(px(4)))).at(IVec2::new(px(30), 0)),
    )
    .unwrap();
    let fc_tag = w.collider(fc).unwrap().tag;
    for _ in 0..3 {
        let events = w.step(&[]).to_vec();
        assert_eq!(pos(&w, b), IVec2::new(0, -H));
        assert_eq!(
            events,
            vec![Event::Trigger {
                body: floor,
                collider: fc,
                trigger_body: b,
                trigger: sensor,
                tag: 9,
                other_tag: fc_tag
            }]
        );
    }
}

#[test]
fn trigger_pairs_without_a_dynamic_solid_or_with_two_triggers_are_skipped() {
    let mut w = World::default();
    // Static trigger on a static solid, kinematic trigger on a static solid.
    let (s, _) = fixed(&mut w, IVec2::ZERO, IVec2::splat(px(20)));
    w.add_collider(s, ColliderDesc::trigger(aabb(IVec2::splat(px(4)))))
        .unwrap();
    let k = w.add_body(BodyDesc::kinematic(IVec2::ZERO)).unwrap();
    w.add_collider(k, ColliderDesc::trigger(aabb(IVec2::splat(px(4)))))
        .unwrap();
    // Two dynamic bodies that are only triggers, overlapping each other.
    for x in [px(100), px(102)] {
        let d = w.add_body(BodyDesc::dynamic(IVec2::new(x, 0))).unwrap();
        w.add_collider(d, ColliderDesc::trigger(aabb(IVec2::splat(px(4)))))
            .unwrap();
    }
    assert!(w.step(&[]).is_empty());
}

/// A floor (top at y = 0) and a low ceiling (bottom at y = -14 px) over a
/// 16 px square: the floor's deeper push goes first; the ceiling's push then
/// points back against it and is dropped, so the body is squished rather
/// than shoved back into the floor.
#[test]
fn a_later_contact_never_pushes_a_body_back_against_an_earlier_push() {
    let mut w = World::default();
    let (_, floor) = fixed(&mut w, IVec2::new(0, px(8)), IVec2::new(px(50), px(8)));
    fixed(
        &mut w,
        IVec2::new(0, -px(14) - px(8)),
        IVec2::new(px(50), px(8)),
    );
    // 5 px into the floor, 3 px into the ceiling.
    let (b, _) = square(&mut w, IVec2::new(0, -px(3)), IVec2::ZERO);
    let events = w.step(&[]).to_vec();
    assert_eq!(pos(&w, b), IVec2::new(0, -H), "pushed back down");
    assert_eq!(w.body(b).unwrap().pushed(), IVec2::new(0, -px(5)));
    assert_eq!(contacts(&events), vec![(b, floor, Sides::BOTTOM)]);
    assert_eq!(squished(&events), vec![b]);
    // Sides record both contacts, even the one that could not push.
    assert_eq!(w.body(b).unwrap().sides(), Sides::BOTTOM | Sides::TOP);
}

/// A box resting on the floor (pressed 3 px into it) with a second box
/// falling 5 px into it: the floor goes first (support before dynamic
/// pairs), pins the lower box against moving down, and the upper box then
/// takes the whole push instead of splitting it by mass.
#[test]
fn a_body_pushed_out_of_immovable_support_is_immovable_to_the_bodies_on_it() {
    for (m_low, m_high) in [(1, 1), (1, 9), (9, 1)] {
        let mut w = World::default();
        let (_, floor) = fixed(&mut w, IVec2::new(0, px(8)), IVec2::new(px(50), px(8)));
        let (low, low_c) =
            square_mass(&mut w, IVec2::new(0, -H + px(3)), IVec2::new(0, 100), m_low);
        let (high, _) = square_mass(
            &mut w,
            IVec2::new(0, -3 * H + px(8)),
            IVec2::new(0, 100),
            m_high,
        );
        let events = w.step(&[]).to_vec();
        let ctx = format!("masses {m_low}:{m_high}");
        assert!(squished(&events).is_empty(), "{ctx}");
        assert_eq!(pos(&w, low), IVec2::new(0, -H), "{ctx}");
        assert_eq!(pos(&w, high), IVec2::new(0, -3 * H), "{ctx}");
        assert_eq!((vel(&w, low), vel(&w, high)), (IVec2::ZERO, IVec2::ZERO));
        // The lower box was pushed by the floor only (never down by the
        // upper one); the upper one by the lower one.
        assert_eq!(w.body(low).unwrap().pushed(), IVec2::new(0, -px(3) - 100));
        let c = contacts(&events);
        assert!(c.contains(&(low, floor, Sides::BOTTOM)), "{ctx}: {c:?}");
        assert!(c.contains(&(high, low_c, Sides::BOTTOM)), "{ctx}: {c:?}");
        assert!(
            !c.iter().any(|x| x.0 == low && x.1 != floor),
            "{ctx}: {c:?}"
        );
    }
}

/// Immovable support overrides the no-push-back rule against a push from a
/// dynamic body: a box shoved into a wall by another is pushed back out
/// (flush), and the shover takes the whole push.
#[test]
fn immovable_support_overrides_a_push_back_from_a_dynamic_body() {
    let mut w = World::default();
    let (_, wall) = fixed(&mut w, IVec2::new(px(8), 0), IVec2::new(px(8), px(50)));
    // B flush against the wall; A 6 px into B, moving right.
    let (b, _) = square(&mut w, IVec2::new(-H, 0), IVec2::ZERO);
    let (a, _) = square(
        &mut w,
        IVec2::new(-3 * H + px(6) - 64, 0),
        IVec2::new(64, 0),
    );
    let events = w.step(&[]).to_vec();
    assert!(squished(&events).is_empty());
    assert_eq!(pos(&w, b), IVec2::new(-H, 0));
    assert_eq!(pos(&w, a), IVec2::new(-3 * H, 0));
    assert_eq!(vel(&w, a), IVec2::ZERO);
    assert!(contacts(&events).contains(&(b, wall, Sides::RIGHT)));
}

/// A wall box standing on a floor box: the wall's bottom face is covered.
/// A triangle pressed into the inside corner gets no push out of the wall's
/// bottom corner along its slanted edge (that would point into the floor):
/// it is pushed out of the wall's open side and rests flush in the corner.
#[test]
fn a_static_box_never_pushes_through_a_face_another_static_box_covers() {
    use ledge_shared::shape::ConvexPolygon;
    let tri = |w: &mut World, at: IVec2, vel: IVec2| {
        let v: Vec<IVec2> = [(-6, 5), (6, 5), (0, -6)]
            .iter()
            .map(|&(x, y)| IVec2::new(px(x), px(y)))
            .collect();
        let b = w.add_body(BodyDesc::dynamic(at).with_vel(vel)).unwrap();
        w.add_collider(b, ColliderDesc::solid(ConvexPolygon::new(&v).unwrap()))
            .unwrap();
        b
    };
    let flush = IVec2::new(px(6), -px(5));
    // The corner as two boxes of one static body, and (the same corner) as
    // one box alone: its bottom face is then open, and the slanted push is
    // the right one.
    let mut w = World::default();
    let room = w.add_body(BodyDesc::fixed(IVec2::ZERO)).unwrap();
    for (c, h) in [
        (IVec2::new(0, px(8)), IVec2::new(px(100), px(8))),
        (IVec2::new(-px(8), -px(50)), IVec2::new(px(8), px(50))),
    ] {
        w.add_collider(room, ColliderDesc::solid(aabb(h)).at(c))
            .unwrap();
    }
    let t = tri(&mut w, flush + IVec2::new(-1, 1), IVec2::ZERO);
    let events = w.step(&[]).to_vec();
    assert!(squished(&events).is_empty(), "{events:?}");
    assert_eq!(pos(&w, t), flush);
    // The same triangle against the wall box alone, just below its bottom
    // corner: the slanted push out of the corner applies (down and right).
    let mut w = World::default();
    fixed(
        &mut w,
        IVec2::new(-px(8), -px(50)),
        IVec2::new(px(8), px(50)),
    );
    let t = tri(&mut w, flush + IVec2::new(-1, 1), IVec2::ZERO);
    w.step(&[]);
    let p = pos(&w, t) - flush - IVec2::new(-1, 1);
    assert!(p.x > 0 && p.y > 0, "pushed by {p}");
}

#[test]
fn a_body_pressed_between_walls_closer_than_itself_is_squished() {
    for iterations in [1, 4, 16] {
        let mut w = World::new(SimConfig {
            substeps: 1,
            restitution_iterations: iterations,
            ..SimConfig::default()
        })
        .unwrap();
        // Faces at x = -6 px and +6 px: 12 px of room for a 16 px body.
        fixed(
            &mut w,
            IVec2::new(-px(6) - px(8), 0),
            IVec2::new(px(8), px(50)),
        );
        fixed(
            &mut w,
            IVec2::new(px(6) + px(8), 0),
            IVec2::new(px(8), px(50)),
        );
        let (b, _) = square(&mut w, IVec2::ZERO, IVec2::ZERO);
        for _ in 0..5 {
            let events = w.step(&[]).to_vec();
            assert_eq!(squished(&events), vec![b], "iterations {iterations}");
            let x = pos(&w, b).x;
            assert!(x.abs() <= px(4), "thrown out to {x}");
        }
    }
}

#[test]
fn a_kinematic_wall_closing_in_squishes_without_panicking() {
    let mut w = World::default();
    fixed(&mut w, IVec2::new(-px(8), 0), IVec2::new(px(8), px(50)));
    let k = w
        .add_body(BodyDesc::kinematic(IVec2::new(px(40), 0)).with_vel(IVec2::new(-px(1), 0)))
        .unwrap();
    w.add_collider(k, ColliderDesc::solid(aabb(IVec2::new(px(8), px(50)))))
        .unwrap();
    let (b, _) = square(&mut w, IVec2::new(px(12), 0), IVec2::ZERO);
    let mut first = None;
    for t in 1..=40 {
        let events = w.step(&[]).to_vec();
        assert_eq!(
            pos(&w, k).x,
            px(40) - px(t),
            "the kinematic wall was pushed"
        );
        if !squished(&events).is_empty() && first.is_none() {
            first = Some(t);
        }
    }
    // Free until the gap (32 px - t px) gets narrower than the body (16 px).
    assert_eq!(first, Some(17));
    assert!(pos(&w, b).x.abs() < px(64));
}

#[test]
fn substeps_stop_tunnelling_through_thin_walls() {
    let run = |substeps| {
        let mut w = World::new(SimConfig {
            substeps,
            restitution_iterations: 4,
            ..SimConfig::default()
        })
        .unwrap();
        // A 2 px thin wall, face at x = 0.
        fixed(&mut w, IVec2::new(px(1), 0), IVec2::new(px(1), px(50)));
        let (b, _) = square(&mut w, IVec2::new(-H - px(1), 0), IVec2::new(px(24), 0));
        w.step(&[]);
        pos(&w, b).x
    };
    assert!(run(1) > 0, "expected the single-step body to tunnel");
    assert_eq!(run(4), -H, "four substeps catch the wall");
}

#[test]
fn substeps_move_exactly_by_the_velocity() {
    for substeps in 1..=7 {
        let mut w = World::new(SimConfig {
            substeps,
            restitution_iterations: 1,
            ..SimConfig::default()
        })
        .unwrap();
        let (b, _) = square(&mut w, IVec2::new(5, -3), IVec2::new(1001, -37));
        for t in 1..=5 {
            w.step(&[]);
            assert_eq!(pos(&w, b), IVec2::new(5 + 1001 * t, -3 - 37 * t));
            assert_eq!(w.body(b).unwrap().displacement(), IVec2::new(1001, -37));
        }
    }
}

#[test]
fn building_rejects_values_outside_the_bounds_and_names_them() {
    let mut w = World::default();
    let err = w
        .add_body(BodyDesc::dynamic(IVec2::new(MAX_COORD + 1, 0)))
        .unwrap_err();
    assert_eq!(
        err,
        BuildError::Bounds(BoundsError::Coord {
            what: "body position x",
            value: MAX_COORD as i64 + 1
        })
    );
    assert!(err.to_string().contains("body position x"));
    let err = w
        .add_body(BodyDesc::dynamic(IVec2::new(0, -MAX_COORD - 1)))
        .unwrap_err();
    assert!(err.to_string().contains("body position y"), "{err}");
    let err = w
        .add_body(BodyDesc::dynamic(IVec2::ZERO).with_vel(IVec2::new(0, MAX_SPEED + 1)))
        .unwrap_err();
    assert!(err.to_string().contains("body velocity y"), "{err}");
    assert_eq!(
        w.add_body(BodyDesc::dynamic(IVec2::ZERO).with_mass(0)),
        Err(BuildError::Mass { value: 0 })
    );
    assert_eq!(
        w.add_body(BodyDesc::fixed(IVec2::ZERO).with_vel(IVec2::X)),
        Err(BuildError::StaticVelocity)
    );
    let b = w
        .add_body(BodyDesc::dynamic(IVec2::new(MAX_COORD, -MAX_COORD)))
        .unwrap();
    let err = w
        .add_collider(
            b,
            ColliderDesc::solid(aabb(IVec2::ONE)).at(IVec2::new(MAX_EXTENT + 1, 0)),
        )
        .unwrap_err();
    assert!(err.to_string().contains("collider offset x"), "{err}");
    let err = w
        .add_collider(
            b,
            ColliderDesc::trigger(aabb(IVec2::ONE)).one_way(OneWay::Up),
        )
        .unwrap_err();
    assert_eq!(err, BuildError::OneWayTrigger);
    assert_eq!(
        w.add_collider(BodyId(99), ColliderDesc::solid(aabb(IVec2::ONE))),
        Err(BuildError::NoBody(BodyId(99)))
    );
    assert!(w.set_velocity(b, IVec2::new(-MAX_SPEED - 1, 0)).is_err());
    assert!(w.set_position(b, IVec2::new(0, MAX_COORD + 1)).is_err());
    assert!(World::new(SimConfig {
        substeps: 0,
        restitution_iterations: 1,
        ..SimConfig::default()
    })
    .is_err());
    assert!(World::new(SimConfig {
        substeps: 1,
        restitution_iterations: 0,
        ..SimConfig::default()
    })
    .is_err());
}

#[test]
fn positions_are_clamped_to_the_world_bound_and_lose_that_velocity() {
    let mut w = World::default();
    let (b, _) = square(
        &mut w,
        IVec2::new(MAX_COORD - 10, -MAX_COORD + 5),
        IVec2::new(MAX_SPEED, -MAX_SPEED),
    );
    w.set_velocity(b, IVec2::new(100, -3)).unwrap();
    w.step(&[]);
    assert_eq!(pos(&w, b), IVec2::new(MAX_COORD, -MAX_COORD + 2));
    assert_eq!(vel(&w, b), IVec2::new(0, -3));
    w.set_velocity(b, IVec2::new(MAX_SPEED, -MAX_SPEED))
        .unwrap();
    w.step(&[]);
    assert_eq!(pos(&w, b), IVec2::new(MAX_COORD, -MAX_COORD));
    assert_eq!(vel(&w, b), IVec2::ZERO);
}

#[test]
fn events_are_sorted_unique_and_merge_substeps() {
    let mut w = World::new(SimConfig {
        substeps: 4,
        restitution_iterations: 4,
        ..SimConfig::default()
    })
    .unwrap();
    let (_, floor) = fixed(&mut w, IVec2::new(0, px(8)), IVec2::new(px(200), px(8)));
    let (_, wall) = fixed(
        &mut w,
        IVec2::new(px(50), -px(50)),
        IVec2::new(px(8), px(50)),
    );
    // Two squares resting on the floor, the second also against the wall;
    // both pressed down every substep.
    let (a, _) = square(&mut w, IVec2::new(-px(40), -H), IVec2::new(0, 400));
    let (b, _) = square(&mut w, IVec2::new(px(42) - H, -H), IVec2::new(400, 400));
    let events = w.step(&[]).to_vec();
    assert_eq!(
        contacts(&events),
        vec![
            (a, floor, Sides::BOTTOM),
            (b, floor, Sides::BOTTOM),
            (b, wall, Sides::RIGHT)
        ],
        "{events:?}"
    );
}

#[test]
fn the_state_hash_covers_the_state_and_nothing_else() {
    let build = || {
        let mut w = World::default();
        fixed(&mut w, IVec2::new(0, px(8)), IVec2::new(px(50), px(8)));
        square(&mut w, IVec2::new(0, -H - 100), IVec2::new(3, 40));
        w
    };
    let (mut a, mut b) = (build(), build());
    assert_eq!(a.state_hash(), b.state_hash());
    let h0 = a.state_hash();
    a.step(&[]);
    assert_ne!(a.state_hash(), h0);
    b.step(&[]);
    assert_eq!(a.state_hash(), b.state_hash());
    let c = a.clone();
    assert_eq!(c.state_hash(), a.state_hash());
    b.set_velocity(BodyId(1), IVec2::new(3, 41)).unwrap();
    assert_ne!(a.state_hash(), b.state_hash());
}

#[test]
fn worlds_can_move_between_threads() {
    // The server runs each room's world on its own task.
    fn send_sync<T: Send + Sync + Clone>() {}
    send_sync::<World>();
}
