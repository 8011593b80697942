//! Players on polygon slopes: a walkable face holds them like a tile slope
//! (standing still does not slide, running down stays on the ground,
//! running up works), a steeper face is a wall they slide off. Every test
//! runs on a ramp rising right and on its mirror image.

use crate::platformer_kit;

use glam::IVec2;
use ledge_shared::game::{GameConfig, PlayerConfig, PlayerShape, PlayerView, FOOT_INSET};
use ledge_shared::input::Buttons;
use ledge_shared::level::{EntityKind, Level};
use platformer_kit::*;

const PX: i32 = 256;
/// Width of the room, px.
const W: i32 = 384;
/// Top of the floor and of the plateau, px.
const FLOOR: i32 = 128;
const PLATEAU: i32 = 96;
/// Where the ramp meets the plateau (rising right), px.
const TOP_X: i32 = 192;

/// A 24 x 10 tile room: floor top at 128 px; a plateau two tiles high
/// (top 96 px) from x = 192 px to the right wall; `tall` makes it one tile
/// higher (top 80 px).
fn rows(tall: bool) -> Vec<String> {
    (0..10)
        .map(|r| {
            (0..24)
                .map(|c| {
                    let plateau = c >= 12 && (r >= 6 || (tall && r == 5));
                    if r == 0 || r >= 8 || c == 0 || c == 23 || plateau {
                        '#'
                    } else {
                        '.'
                    }
                })
                .collect()
        })
        .collect()
}

/// A ramp (or wedge) on the floor rising right to (192, 128 - rise) px
/// over `run` px, against the plateau; `mirror`: the whole level mirrored
/// in x (rising left).
struct Ramp {
    run: i32,
    rise: i32,
    mirror: bool,
}

impl Ramp {
    fn walkable(run: i32, mirror: bool) -> Self {
        Ramp {
            run,
            rise: FLOOR - PLATEAU,
            mirror,
        }
    }

    /// x (units) in the level from x in the unmirrored level.
    fn x(&self, x: i32) -> i32 {
        if self.mirror {
            W * PX - x
        } else {
            x
        }
    }

    /// The level's buttons for buttons `b` of the unmirrored level.
    fn dir(&self, b: Buttons) -> Buttons {
        if !self.mirror {
            return b;
        }
        let mut out = b.0 & !(Buttons::LEFT | Buttons::RIGHT);
        if b.0 & Buttons::LEFT != 0 {
            out |= Buttons::RIGHT;
        }
        if b.0 & Buttons::RIGHT != 0 {
            out |= Buttons::LEFT;
        }
        Buttons(out)
    }

    /// The level, with the spawn high above `spawn_x` px (unmirrored).
    fn level(&self, spawn_x: i32) -> Level {
        let x0 = TOP_X - self.run;
        let pts = [(x0, FLOOR), (TOP_X, FLOOR - self.rise), (TOP_X, FLOOR)];
        let world: Vec<IVec2> = pts
            .iter()
            .map(|&(x, y)| IVec2::new(self.x(x * PX), y * PX))
            .collect();
        let (lo, hi) = world
            .iter()
            .fold((world[0], world[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let centre = (lo + hi) / 2;
        let vertices = world.iter().map(|p| *p - centre).collect();
        let mut spawn = ent(EntityKind::PlayerSpawn, 0, 0);
        spawn.pos = IVec2::new(self.x(spawn_x * PX), 40 * PX);
        let mut rows = rows(self.rise > FLOOR - PLATEAU);
        if self.mirror {
            rows = rows.iter().map(|r| r.chars().rev().collect()).collect();
        }
        let rows: Vec<&str> = rows.iter().map(|r| r.as_str()).collect();
        level(
            &rows,
            vec![
                spawn,
                ent_at(EntityKind::PolygonBlock { vertices }, centre, hi - lo),
            ],
        )
    }

    /// The player's box as `(left, right, bottom)` in the unmirrored level.
    fn unmirror(&self, p: &PlayerView) -> (i32, i32, i32) {
        let (l, r) = (p.pos.x - p.half.x, p.pos.x + p.half.x);
        let (l, r) = if self.mirror {
            (W * PX - r, W * PX - l)
        } else {
            (l, r)
        };
        (l, r, p.pos.y + p.half.y)
    }

    /// Where a box spanning `[l, r]` (unmirrored) stands: the highest of the
    /// floor, the plateau and the ramp's surface under it.
    fn ground(&self, l: i32, r: i32) -> i32 {
        let x0 = (TOP_X - self.run) * PX;
        let mut y = FLOOR * PX;
        if r > TOP_X * PX {
            y = (FLOOR - self.rise) * PX;
        }
        let x = r.min(TOP_X * PX);
        if x > x0 && l < TOP_X * PX {
            let h = (x - x0) as i64 * self.rise as i64 / self.run as i64;
            y = y.min(FLOOR * PX - h as i32);
        }
        y
    }
}

/// Both walkable ramps (1:4 and 1:2), both ways round.
fn walkable_ramps() -> Vec<Ramp> {
    let mut v = Vec::new();
    for run in [128, 64] {
        for mirror in [false, true] {
            v.push(Ramp::walkable(run, mirror));
        }
    }
    v
}

/// Lands the player on the ramp at `x` px (its box's centre) and lets it
/// settle.
fn stand_on(ramp: &Ramp, x: i32, config: GameConfig) -> Sim {
    let mut s = Sim::with(&ramp.level(x), config);
    s.land(60);
    s.run(NONE, 10);
    s
}

#[test]
fn a_player_stands_still_on_a_walkable_slope() {
    for shape in [PlayerShape::Box, PlayerShape::BoxFeetHead] {
        let config = GameConfig {
            player: PlayerConfig {
                shape,
                ..PlayerConfig::default()
            },
            ..GameConfig::default()
        };
        for ramp in walkable_ramps() {
            let what = format!("run {} mirror {} {shape:?}", ramp.run, ramp.mirror);
            let mut s = stand_on(&ramp, TOP_X - ramp.run / 2, config);
            let start = s.view();
            let (l, r, b) = ramp.unmirror(&start);
            assert!(start.grounded, "{what}: {start:?}");
            assert!(b < FLOOR * PX, "{what}: on the ramp, not the floor");
            // The feet box of `BoxFeetHead` is the one on the surface.
            let inset = if shape == PlayerShape::Box {
                0
            } else {
                FOOT_INSET
            };
            let gap = b - ramp.ground(l + inset, r - inset);
            assert!(gap.abs() <= 4, "{what}: {gap}: {start:?}");
            for t in 0..600 {
                s.step(NONE);
                let p = s.view();
                assert!(p.grounded, "{what}: tick {t}: {p:?}");
                let d = (p.pos - start.pos).abs();
                assert!(d.x <= 1 && d.y <= 1, "{what}: tick {t}: moved {d}: {p:?}");
            }
            // And it jumps from there.
            s.step(JUMP);
            assert!(s.saw(jumped), "{what}");
        }
    }
}

#[test]
fn landing_on_a_walkable_slope_stops_dead() {
    for ramp in walkable_ramps() {
        let mut s = Sim::new(&ramp.level(TOP_X - ramp.run / 2));
        s.land(60);
        let p = s.view();
        assert_eq!(p.vel, IVec2::ZERO, "run {}: {p:?}", ramp.run);
        assert_eq!(p.pos.x, ramp.x((TOP_X - ramp.run / 2) * PX), "{p:?}");
    }
}

#[test]
fn running_down_a_walkable_slope_at_full_speed_stays_grounded() {
    let max = PlayerConfig::default().max_run_speed;
    for ramp in walkable_ramps() {
        let what = format!("run {} mirror {}", ramp.run, ramp.mirror);
        // Start on the plateau, run towards the ramp and down it.
        let mut s = stand_on(&ramp, TOP_X + 60, GameConfig::default());
        let mut on_ramp = 0;
        let mut last = s.view();
        for t in 0..300 {
            s.step(ramp.dir(LEFT));
            let p = s.view();
            let (l, r, b) = ramp.unmirror(&p);
            assert!(p.grounded, "{what}: tick {t}: {p:?}");
            let gap = b - ramp.ground(l, r);
            assert!(
                gap.abs() <= 4,
                "{what}: tick {t}: {gap} off the ground: {p:?}"
            );
            if b > PLATEAU * PX && b < FLOOR * PX {
                on_ramp += 1;
                // Down the surface, at full speed once reached.
                assert!(p.pos.y > last.pos.y, "{what}: tick {t}: {p:?}");
                if last.vel.x.abs() == max {
                    assert_eq!(p.vel.x.abs(), max, "{what}: tick {t}: {p:?}");
                }
            }
            last = p;
            if r < (TOP_X - ramp.run - 16) * PX {
                break;
            }
        }
        let (_, r, b) = ramp.unmirror(&last);
        assert!(
            r < (TOP_X - ramp.run - 16) * PX,
            "{what}: reached the floor"
        );
        assert_eq!(b, FLOOR * PX, "{what}");
        // A 1:4 ramp of 128 px at 2.5 px a tick takes about 50 ticks.
        assert!(
            on_ramp >= ramp.run / 3,
            "{what}: {on_ramp} ticks on the ramp"
        );
    }
}

#[test]
fn running_up_a_walkable_slope_reaches_the_top() {
    let max = PlayerConfig::default().max_run_speed;
    for ramp in walkable_ramps() {
        let what = format!("run {} mirror {}", ramp.run, ramp.mirror);
        let mut s = stand_on(&ramp, TOP_X - ramp.run - 40, GameConfig::default());
        let mut last = s.view();
        let mut on_ramp = 0;
        for t in 0..200 {
            s.step(ramp.dir(RIGHT));
            let p = s.view();
            let (l, r, b) = ramp.unmirror(&p);
            assert!(p.grounded, "{what}: tick {t}: {p:?}");
            let gap = b - ramp.ground(l, r);
            assert!(
                gap.abs() <= 4,
                "{what}: tick {t}: {gap} off the ground: {p:?}"
            );
            if b > PLATEAU * PX && b < FLOOR * PX {
                on_ramp += 1;
                // Up the surface, not slowed down by it.
                assert!(p.pos.y < last.pos.y, "{what}: tick {t}: {p:?}");
                assert!(
                    p.vel.x.abs() >= last.vel.x.abs().min(max - 40),
                    "{what}: tick {t}: {p:?} after {last:?}"
                );
            }
            last = p;
        }
        let (l, _, b) = ramp.unmirror(&last);
        assert!(on_ramp > 5, "{what}: {on_ramp} ticks on the ramp");
        assert!(l > TOP_X * PX, "{what}: on the plateau: {last:?}");
        assert_eq!(b, PLATEAU * PX, "{what}");
    }
}

#[test]
fn a_face_steeper_than_walkable_is_a_wall_the_player_slides_off() {
    // A 3:2 wedge (56 degrees): the world's push off it is mostly upward
    // (it marks the bottom side), but it is steeper than 45 degrees.
    for mirror in [false, true] {
        let ramp = Ramp {
            run: 32,
            rise: 48,
            mirror,
        };
        for (slope, holds) in [(256, false), (2 * 256, true)] {
            let config = GameConfig {
                player: PlayerConfig {
                    max_walkable_slope: slope,
                    ..PlayerConfig::default()
                },
                ..GameConfig::default()
            };
            let what = format!("mirror {mirror} slope {slope}");
            // Dropped onto the face, its right bottom corner first.
            let mut s = Sim::with(&ramp.level(TOP_X - 12), config);
            let mut touched = 0;
            for _ in 0..240 {
                s.step(NONE);
                let p = s.view();
                let (_, _, b) = ramp.unmirror(&p);
                if !p.sides.is_empty() && b < FLOOR * PX {
                    touched += 1;
                    assert_eq!(p.grounded, holds, "{what}: {p:?}");
                }
            }
            assert!(touched > 0, "{what}: never touched the face");
            let p = s.view();
            let (_, r, b) = ramp.unmirror(&p);
            if holds {
                // Walkable by this configuration: it stands on the face.
                assert!(p.grounded && b < FLOOR * PX, "{what}: {p:?}");
            } else {
                // Slid off, onto the floor beside the wedge.
                assert!(p.grounded, "{what}: {p:?}");
                assert_eq!(b, FLOOR * PX, "{what}: {p:?}");
                assert!(r <= (TOP_X - ramp.run) * PX + 4, "{what}: {p:?}");
            }
        }
    }
}

#[test]
fn slopes_replay_exactly_from_a_snapshot() {
    let ramp = Ramp::walkable(64, false);
    let level = ramp.level(TOP_X + 40);
    let script = |t: usize| match t % 97 {
        0..=40 => LEFT,
        41..=60 => NONE,
        61..=62 => RIGHT_JUMP,
        _ => RIGHT,
    };
    let mut a = Sim::new(&level);
    for t in 0..150 {
        a.step(script(t));
    }
    let mut b = Sim::new(&level);
    b.game.restore(&a.game.snapshot()).unwrap();
    for t in 150..600 {
        a.step(script(t));
        b.step(script(t));
        assert_eq!(a.game.state_hash(), b.game.state_hash(), "tick {t}");
    }
}

#[test]
fn running_into_a_face_steeper_than_walkable_stops_at_its_foot() {
    for mirror in [false, true] {
        let ramp = Ramp {
            run: 32,
            rise: 48,
            mirror,
        };
        let mut s = stand_on(&ramp, TOP_X - 80, GameConfig::default());
        for t in 0..120 {
            s.step(ramp.dir(RIGHT));
            let p = s.view();
            let (_, r, b) = ramp.unmirror(&p);
            // The push off the face lifts the box a little (its corner is
            // on the face), never up it.
            assert!(b >= (FLOOR - 2) * PX, "mirror {mirror}: tick {t}: {p:?}");
            assert!(
                r <= (TOP_X - ramp.run + 1) * PX,
                "mirror {mirror}: tick {t}: {p:?}"
            );
        }
    }
}
