//! Moving platforms: riders are carried exactly whichever way the platform
//! moves (solid and one-way), platforms crush what they push into solids,
//! and leaving a platform keeps its velocity per `CarryMode`.

use crate::platformer_kit;

use glam::IVec2;
use ledge_shared::game::{CarryMode, GameConfig, GameEvent, HurtCause, PlayerConfig};
use ledge_shared::level::{EntityKind, Level};
use ledge_shared::protocol::PlayerId;
use platformer_kit::*;

/// An empty room 60 x 40 tiles, walls all round.
fn room() -> Vec<String> {
    let mut rows = vec!["#".repeat(60)];
    for _ in 0..38 {
        rows.push(format!("#{}#", ".".repeat(58)));
    }
    rows.push("#".repeat(60));
    rows
}

/// Platform size: 4 x 1/2 tiles.
const PLAT: IVec2 = IVec2::new(4 * T, T / 2);

/// A level with one platform on `path` and the player's spawn standing on
/// its top, `dx` units right of its centre.
fn riding_level(path: &[IVec2], speed: i32, one_way: bool, dx: i32) -> Level {
    let rows = room();
    let rows: Vec<&str> = rows.iter().map(|s| s.as_str()).collect();
    let top = path[0].y - PLAT.y / 2;
    let spawn = ent_at(
        EntityKind::PlayerSpawn,
        IVec2::new(path[0].x + dx, top - T / 2),
        IVec2::splat(T),
    );
    level(&rows, vec![platform(path, PLAT, speed, one_way), spawn])
}

/// Rides for 600 ticks standing still: the offset to the platform never
/// changes and the player's bottom is exactly on the platform's top.
fn ride(path: &[IVec2], speed: i32, one_way: bool) {
    for dx in [0, -PLAT.x / 2 + T / 2, PLAT.x / 2 - T / 2 + 7] {
        let mut s = Sim::new(&riding_level(path, speed, one_way, dx));
        let plat = |s: &Sim| s.game.entities().next().unwrap().pos;
        let offset = s.pos() - plat(&s);
        let mut moved = [false; 4];
        let mut last = plat(&s);
        for t in 0..600 {
            s.step(NONE);
            let p = plat(&s);
            let d = p - last;
            last = p;
            moved[0] |= d.y < 0;
            moved[1] |= d.y > 0;
            moved[2] |= d.x < 0;
            moved[3] |= d.x > 0;
            let v = s.view();
            let ctx = format!("path {path:?} speed {speed} one-way {one_way} dx {dx} tick {t}");
            assert_eq!(v.pos - p, offset, "{ctx}: slipped");
            assert_eq!(
                v.pos.y + v.half.y,
                p.y - PLAT.y / 2,
                "{ctx}: not on the top"
            );
            assert!(v.grounded, "{ctx}");
            if t > 0 {
                assert!(s.events.is_empty(), "{ctx}: {:?}", s.events);
            }
        }
        // The platform went both ways along its path.
        let d = path[1] - path[0];
        assert_eq!(moved[0] && moved[1], d.y != 0, "{moved:?}");
        assert_eq!(moved[2] && moved[3], d.x != 0, "{moved:?}");
    }
}

const START: IVec2 = IVec2::new(30 * T, 20 * T);

/// A path from [`START`] towards `dir` (tiles), shortened so that one leg
/// lasts at most 250 ticks at `speed`.
fn path_towards(dir: IVec2, speed: i32) -> [IVec2; 2] {
    let len = (dir.x.abs().max(dir.y.abs()) * T).min(speed * 250);
    let scale = len / (dir.x.abs().max(dir.y.abs()));
    [START, START + dir * scale]
}

#[test]
fn riding_up_and_down() {
    for speed in [64, 256, 700] {
        ride(&path_towards(IVec2::new(0, -12), speed), speed, false);
        ride(&path_towards(IVec2::new(0, 12), speed), speed, false);
    }
}

#[test]
fn riding_sideways() {
    for speed in [64, 300, 1000] {
        ride(&path_towards(IVec2::new(12, 0), speed), speed, false);
        ride(&path_towards(IVec2::new(-12, 0), speed), speed, false);
    }
}

#[test]
fn riding_diagonally() {
    for speed in [90, 500] {
        ride(&path_towards(IVec2::new(10, -7), speed), speed, false);
        ride(&path_towards(IVec2::new(-9, 11), speed), speed, false);
        ride(&path_towards(IVec2::new(5, 5), speed), speed, false);
    }
}

#[test]
fn riding_one_way_platforms_up_down_and_diagonally() {
    for speed in [64, 500] {
        ride(&path_towards(IVec2::new(0, -12), speed), speed, true);
        ride(&path_towards(IVec2::new(8, 8), speed), speed, true);
        ride(&path_towards(IVec2::new(-8, -3), speed), speed, true);
    }
}

#[test]
fn a_one_way_platform_lets_a_player_jump_up_through_it() {
    // A one-way platform at rest, two tiles above the floor.
    let rows = room();
    let rows: Vec<&str> = rows.iter().map(|s| s.as_str()).collect();
    let floor = 39 * T;
    let p = IVec2::new(10 * T, floor - 3 * T);
    let lv = level(
        &rows,
        vec![
            platform(&[p], PLAT, 64, true),
            ent(EntityKind::PlayerSpawn, 10, 38),
        ],
    );
    let mut s = Sim::new(&lv);
    s.land(10);
    assert_eq!(s.bottom(), floor);
    for _ in 0..40 {
        s.step(JUMP);
    }
    s.land(100);
    assert_eq!(
        s.bottom(),
        p.y - PLAT.y / 2,
        "landed on the platform from below"
    );
    // And down + jump drops back through it.
    s.step(NONE);
    s.step(DOWN_JUMP);
    assert!(s.saw(|e| matches!(e, GameEvent::DroppedThrough(_))));
    s.land(100);
    assert_eq!(s.bottom(), floor);
}

/// Walks the player right until its centre is at `x` or past.
fn walk_to(s: &mut Sim, x: i32) {
    while s.pos().x < x {
        s.step(RIGHT);
    }
    for _ in 0..30 {
        s.step(NONE);
    }
}

#[test]
fn a_descending_platform_squishes_a_player_on_the_floor() {
    let rows = room();
    let rows: Vec<&str> = rows.iter().map(|s| s.as_str()).collect();
    let floor = 39 * T;
    let x = 20 * T;
    let path = [
        IVec2::new(x, floor - 6 * T),
        IVec2::new(x, floor - PLAT.y / 2),
    ];
    let lv = level(
        &rows,
        vec![
            platform(&path, PLAT, 100, false),
            ent(EntityKind::PlayerSpawn, 3, 38),
        ],
    );
    let mut s = Sim::new(&lv);
    s.land(10);
    let spawn = s.pos();
    walk_to(&mut s, x);
    let mut squished = None;
    for t in 0..400 {
        s.step(NONE);
        if s.saw(|e| matches!(e, GameEvent::Died { .. })) {
            squished = Some(t);
            assert_eq!(
                s.events,
                vec![GameEvent::Died {
                    player: PlayerId(1),
                    cause: HurtCause::Squished
                }]
            );
            // Suspended: the platform passes through it while it is dead.
            s.sit_out_death(NONE, spawn);
            assert_eq!(s.pos(), spawn);
            break;
        }
        // Until then it stands on the floor under the platform.
        assert_eq!(s.bottom(), floor, "tick {t}");
    }
    assert!(squished.is_some(), "never squished");
}

#[test]
fn a_platform_pushes_a_player_and_squishes_it_against_a_wall() {
    let rows = room();
    let rows: Vec<&str> = rows.iter().map(|s| s.as_str()).collect();
    let floor = 39 * T;
    // A platform sliding along the floor from the middle to the left wall.
    let y = floor - PLAT.y / 2;
    let path = [IVec2::new(20 * T, y), IVec2::new(T + PLAT.x / 2, y)];
    let lv = level(
        &rows,
        vec![
            platform(&path, PLAT, 200, false),
            ent(EntityKind::PlayerSpawn, 10, 38),
        ],
    );
    let mut s = Sim::new(&lv);
    let mut pushed = false;
    for _ in 0..800 {
        let before = s.pos().x;
        s.step(NONE);
        if s.saw(|e| matches!(e, GameEvent::Died { .. })) {
            assert!(pushed, "squished without being pushed first");
            return;
        }
        pushed |= s.pos().x < before - 100;
    }
    panic!("never squished");
}

/// The player's x and highest point over 40 ticks after jumping off a
/// platform moving by `step` per tick, with `mode`.
fn jump_off(step: IVec2, mode: CarryMode) -> (i32, i32) {
    let path = [START, START + step * 100];
    let speed = step.x.abs().max(step.y.abs());
    let lv = riding_level(&path, speed, false, 0);
    let cfg = GameConfig {
        player: PlayerConfig {
            carry_mode: mode,
            air_brake: 0,
            ..PlayerConfig::default()
        },
        ..GameConfig::default()
    };
    let mut s = Sim::with(&lv, cfg);
    s.run(NONE, 10);
    let (x0, y0) = (s.pos().x, s.pos().y);
    s.step(JUMP);
    let mut top = y0;
    for _ in 0..40 {
        s.step(JUMP);
        top = top.min(s.pos().y);
    }
    (s.pos().x - x0, y0 - top)
}

#[test]
fn leaving_a_platform_keeps_its_velocity_per_carry_mode() {
    let side = IVec2::new(256, 0);
    let (add, _) = jump_off(side, CarryMode::Add);
    let (up_only, _) = jump_off(side, CarryMode::AddUpOnly);
    let (none, _) = jump_off(side, CarryMode::None);
    // Carried on the jump tick only, then 40 ticks at the platform's speed.
    assert_eq!(none, 256);
    assert_eq!(up_only, 256);
    assert_eq!(add, 256 * 41);

    let up = IVec2::new(0, -200);
    let (_, add) = jump_off(up, CarryMode::Add);
    let (_, up_only) = jump_off(up, CarryMode::AddUpOnly);
    let (_, none) = jump_off(up, CarryMode::None);
    assert!(add > none, "{add} {none}");
    assert_eq!(add, up_only);
    let down = IVec2::new(0, 200);
    let (_, add) = jump_off(down, CarryMode::Add);
    let (_, up_only) = jump_off(down, CarryMode::AddUpOnly);
    assert!(add < up_only, "{add} {up_only}");
}
