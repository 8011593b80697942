//! The world's platformer machinery on its own: tilemap contacts through the
//! restitution path, riders carried by kinematic boxes, drop-through, body
//! removal and suspension.

use crate::platformer_kit;

use glam::IVec2;
use ledge_shared::shape::Aabb;
use ledge_shared::world::{
    BodyDesc, BodyId, ColliderDesc, ColliderId, Event, OneWay, Sides, World, TILEMAP_TAG,
};
use platformer_kit::*;

const H: IVec2 = IVec2::new(6 * 256, 8 * 256);

fn box_body(w: &mut World, desc: BodyDesc, half: IVec2) -> (BodyId, ColliderId) {
    let b = w.add_body(desc).unwrap();
    let c = w
        .add_collider(b, ColliderDesc::solid(Aabb::new(half).unwrap()))
        .unwrap();
    (b, c)
}

fn tiled(rows: &[&str]) -> World {
    let mut w = World::default();
    w.set_tilemap(map(rows));
    w
}

const BOX_ROOM: [&str; 6] = [
    "##########",
    "#........#",
    "#........#",
    "#..^.....#",
    "#===.....#",
    "##########",
];

#[test]
fn a_falling_box_rests_on_tiles_through_restitution() {
    let mut w = tiled(&BOX_ROOM);
    let (b, c) = box_body(&mut w, BodyDesc::dynamic(IVec2::new(6 * T, 2 * T)), H);
    let mut landed = false;
    for _ in 0..60 {
        let v = w.body(b).unwrap().vel();
        w.set_velocity(b, v + IVec2::new(0, 96)).unwrap();
        let ev = w.step(&[]).to_vec();
        let body = w.body(b).unwrap();
        if body.sides().contains(Sides::BOTTOM) {
            landed = true;
            assert_eq!(body.pos().y + H.y, 5 * T, "rests exactly on the floor");
            assert_eq!(body.vel().y, 0, "velocity against the push removed");
            assert_eq!(
                ev,
                vec![Event::Contact {
                    body: b,
                    collider: c,
                    other_body: BodyId::TILEMAP,
                    other_collider: ColliderId::TILEMAP,
                    other_tag: TILEMAP_TAG,
                    sides: Sides::BOTTOM
                }]
            );
        }
    }
    assert!(landed);
    // The contact records name the tiles.
    w.set_velocity(b, IVec2::new(0, 50)).unwrap();
    w.step(&[]);
    assert_eq!(w.body(b).unwrap().pos().y + H.y, 5 * T);
}

#[test]
fn hazard_tiles_are_triggers_and_one_way_tiles_honour_drop_through() {
    let mut w = tiled(&BOX_ROOM);
    // Resting on the one-way tiles of row 4, inside the hazard tile of row 3.
    let (b, c) = box_body(
        &mut w,
        BodyDesc::dynamic(IVec2::new(3 * T + T / 2, 4 * T - H.y)),
        H,
    );
    w.set_velocity(b, IVec2::new(0, 96)).unwrap();
    let ev = w.step(&[]).to_vec();
    assert_eq!(
        w.body(b).unwrap().pos().y + H.y,
        4 * T,
        "held by the one-way tile"
    );
    assert!(ev.contains(&Event::Trigger {
        body: b,
        collider: c,
        trigger_body: BodyId::TILEMAP,
        trigger: ColliderId::TILEMAP,
        tag: TILEMAP_TAG,
        other_tag: 0
    }));
    // Dropping through: falls past the line.
    w.set_drop_through(b, true).unwrap();
    w.set_velocity(b, IVec2::new(0, 96)).unwrap();
    w.step(&[]);
    assert_eq!(w.body(b).unwrap().pos().y + H.y, 4 * T + 96);
    // Below the line, the flag no longer matters: the tile is passed.
    w.set_drop_through(b, false).unwrap();
    for _ in 0..60 {
        w.step(&[]);
    }
    assert_eq!(w.body(b).unwrap().pos().y + H.y, 5 * T, "on the floor");
}

#[test]
fn a_box_pressed_into_a_thin_corner_at_the_grid_edge_stays_inside() {
    // One-tile-thick floor and wall with nothing beyond: the corner tile's
    // far faces are exposed, its near ones culled.
    let mut w = tiled(&["...#", "...#", "####"]);
    let (b, _) = box_body(&mut w, BodyDesc::dynamic(IVec2::new(T, 2 * T - H.y)), H);
    for _ in 0..100 {
        w.set_velocity(b, IVec2::new(700, 96)).unwrap();
        w.step(&[]);
        let p = w.body(b).unwrap().pos();
        assert!(p.x + H.x <= 3 * T, "went through the wall: {p}");
        assert_eq!(p.y + H.y, 2 * T, "went through the floor: {p}");
    }
    assert_eq!(w.body(b).unwrap().pos().x + H.x, 3 * T);
}

#[test]
fn riders_are_carried_exactly_and_others_are_not() {
    for one_way in [false, true] {
        let mut w = World::default();
        let half = IVec2::new(2 * T, T / 4);
        let plat = w.add_body(BodyDesc::kinematic(IVec2::ZERO)).unwrap();
        let mut c = ColliderDesc::solid(Aabb::new(half).unwrap());
        if one_way {
            c = c.one_way(OneWay::Up);
        }
        w.add_collider(plat, c).unwrap();
        let top = -half.y;
        let (rider, _) = box_body(&mut w, BodyDesc::dynamic(IVec2::new(100, top - H.y)), H);
        let (other, _) = box_body(&mut w, BodyDesc::dynamic(IVec2::new(-5000, top - H.y)), H);
        w.set_rider(rider, true).unwrap();
        for t in 0..300i32 {
            // A wobbly diagonal path.
            let v = IVec2::new(37 + t % 5, if (t / 60) % 2 == 0 { -53 } else { 61 });
            w.set_velocity(plat, v).unwrap();
            for b in [rider, other] {
                let bv = w.body(b).unwrap().vel();
                w.set_velocity(b, bv + IVec2::new(0, 96)).unwrap();
            }
            w.step(&[]);
            let p = w.body(plat).unwrap().pos();
            let r = w.body(rider).unwrap();
            assert_eq!(
                r.pos() - p,
                IVec2::new(100, top - H.y),
                "one-way {one_way} tick {t}"
            );
            assert_eq!(r.carrier(), Some(plat));
            assert!(!w.body(other).unwrap().is_rider());
        }
        // The non-rider was left behind (it fell off).
        assert!(w.body(other).unwrap().pos().y > 0);
    }
}

#[test]
fn a_kinematic_box_squishes_a_body_against_tiles() {
    let mut w = tiled(&["#......", "#......", "#######"]);
    let (b, _) = box_body(&mut w, BodyDesc::dynamic(IVec2::new(3 * T, 2 * T - H.y)), H);
    let k = w
        .add_body(BodyDesc::kinematic(IVec2::new(6 * T, 2 * T - H.y)).with_vel(IVec2::new(-300, 0)))
        .unwrap();
    w.add_collider(k, ColliderDesc::solid(Aabb::new(H).unwrap()))
        .unwrap();
    let mut squished = false;
    for _ in 0..100 {
        let v = w.body(b).unwrap().vel();
        w.set_velocity(b, IVec2::new(v.x, v.y + 96)).unwrap();
        if w.step(&[]).contains(&Event::Squished { body: b }) {
            squished = true;
            break;
        }
    }
    assert!(squished);
}

#[test]
fn removed_bodies_free_their_slot_and_colliders_and_disabled_ones_sleep() {
    let mut w = tiled(&["......", "......", "######"]);
    let (a, ca) = box_body(&mut w, BodyDesc::dynamic(IVec2::new(T, T)), H);
    let (b, cb) = box_body(&mut w, BodyDesc::dynamic(IVec2::new(3 * T, T)), H);
    w.remove_body(a).unwrap();
    assert!(w.body(a).is_none());
    assert!(w.collider(ca).is_none());
    assert_eq!(w.colliders().count(), 1);
    assert!(w.remove_body(a).is_err());
    assert!(w.set_velocity(a, IVec2::ONE).is_err());
    // The next body takes the free slot; collider ids are never reused.
    let (c, cc) = box_body(&mut w, BodyDesc::dynamic(IVec2::new(5 * T, T)), H);
    assert_eq!(c, a);
    assert!(cc > cb);
    assert_eq!(w.collider(cc).unwrap().body, c);
    // A disabled body neither moves nor collides.
    w.set_enabled(b, false).unwrap();
    w.set_velocity(b, IVec2::new(0, 5000)).unwrap();
    w.set_velocity(c, IVec2::new(0, 500)).unwrap();
    for _ in 0..20 {
        w.step(&[]);
    }
    assert_eq!(w.body(b).unwrap().pos(), IVec2::new(3 * T, T));
    assert_eq!(w.body(c).unwrap().pos().y + H.y, 2 * T);
    w.set_enabled(b, true).unwrap();
    w.step(&[]);
    assert_eq!(
        w.body(b).unwrap().pos().y + H.y,
        2 * T,
        "resumed and landed"
    );
}
