//! Walkers (stomp, hurt, turning), springboards, coins, checkpoints, the
//! goal, hazard tiles and volumes.

use crate::platformer_kit;

use glam::IVec2;
use ledge_shared::game::{EntityType, GameEvent, HurtCause, ENTITY_ID_BASE, FALL_MARGIN};
use ledge_shared::level::{EntityDef, EntityKind};
use ledge_shared::protocol::PlayerId;
use platformer_kit::*;

const P1: PlayerId = PlayerId(1);

const FLOOR: i32 = 13 * T;

/// A walker of one tile standing on the floor at column `c`.
fn walker(c: i32, speed: i32) -> EntityDef {
    ent(EntityKind::Walker { speed }, c, 12)
}

fn id_of(index: usize) -> u32 {
    ENTITY_ID_BASE + index as u32
}

fn walker_view(s: &Sim, index: usize) -> ledge_shared::game::EntityView {
    s.game.entities().nth(index).unwrap()
}

#[test]
fn stomping_a_walker_bounces_and_defeats_it() {
    // The player falls from row 6 onto a walker under it.
    let lv = room(
        &[],
        vec![walker(10, 32), ent(EntityKind::PlayerSpawn, 10, 6)],
    );
    let mut s = Sim::new(&lv);
    for t in 0..100 {
        s.step(NONE);
        if s.saw(|e| matches!(e, GameEvent::Stomped { .. })) {
            assert!(s.events.contains(&GameEvent::Stomped {
                player: P1,
                enemy: id_of(0)
            }));
            assert!(s.view().vel.y < 0, "bounced");
            assert!(!walker_view(&s, 0).active);
            // The defeated walker no longer hurts nor moves.
            let w = walker_view(&s, 0).pos;
            for _ in 0..100 {
                s.step(NONE);
                assert!(
                    !s.saw(|e| matches!(e, GameEvent::Died { .. })),
                    "{:?}",
                    s.events
                );
            }
            assert_eq!(walker_view(&s, 0).pos, w);
            assert_eq!(s.bottom(), FLOOR);
            return;
        }
        assert!(
            !s.saw(|e| matches!(e, GameEvent::Died { .. })),
            "tick {t}: {:?}",
            s.events
        );
    }
    panic!("never stomped");
}

/// Walks right (at most `ticks` ticks) until it dies: one death of `cause`
/// (counted), dead for exactly the respawn delay, then respawned at
/// `respawn`.
fn walk_until_hurt(s: &mut Sim, ticks: u32, cause: HurtCause, respawn: IVec2) {
    let deaths = s.view().deaths;
    for _ in 0..ticks {
        s.step(RIGHT);
        if s.saw(|e| matches!(e, GameEvent::Died { .. })) {
            assert_eq!(s.events, vec![GameEvent::Died { player: P1, cause }]);
            assert_eq!(s.view().deaths, deaths + 1);
            s.sit_out_death(RIGHT, respawn);
            assert_eq!(s.view().deaths, deaths + 1);
            return;
        }
    }
    panic!("not hurt in {ticks} ticks, at {}", s.pos());
}

#[test]
fn a_walker_walking_into_the_player_hurts_it() {
    let lv = room(
        &[],
        vec![walker(12, 128), ent(EntityKind::PlayerSpawn, 4, 12)],
    );
    let mut s = Sim::new(&lv);
    s.land(5);
    let spawn = s.pos();
    // Walk towards the walker (which walks left, towards the player).
    walk_until_hurt(&mut s, 300, HurtCause::Enemy(id_of(0)), spawn);
    assert!(walker_view(&s, 0).active, "hurting does not defeat");
}

#[test]
fn walkers_turn_at_walls_and_ledges() {
    // A ledge of tiles, columns 20-27 on row 8; a walker on it; another
    // walker on the floor between the left wall and a wall at column 10.
    let lv = room(
        &[(8, 20, "########"), (12, 10, "#"), (11, 10, "#")],
        vec![
            ent(EntityKind::Walker { speed: 200 }, 23, 7),
            walker(5, 150),
            ent(EntityKind::PlayerSpawn, 35, 12),
        ],
    );
    let mut s = Sim::new(&lv);
    let (mut turns, mut last_dir) = ([0; 2], [true; 2]);
    let (mut lo, mut hi) = ([i32::MAX; 2], [i32::MIN; 2]);
    for t in 0..1500 {
        s.step(NONE);
        for k in 0..2 {
            let w = walker_view(&s, k);
            assert!(w.active);
            if t > 30 {
                let want = if k == 0 { 8 * T } else { FLOOR };
                assert_eq!(w.pos.y + w.half.y, want, "walker {k} fell at tick {t}");
            }
            if w.facing_left != last_dir[k] {
                turns[k] += 1;
                last_dir[k] = w.facing_left;
            }
            lo[k] = lo[k].min(w.pos.x - w.half.x);
            hi[k] = hi[k].max(w.pos.x + w.half.x);
        }
    }
    assert!(turns[0] >= 6 && turns[1] >= 6, "turns {turns:?}");
    // The ledge walker used the ledge and never went over its ends by more
    // than its half width plus one step.
    assert!(lo[0] >= 20 * T - T / 2 - 200 && lo[0] < 21 * T, "{lo:?}");
    assert!(hi[0] <= 28 * T + T / 2 + 200 && hi[0] > 27 * T, "{hi:?}");
    // The floor walker bounced between the walls, touching both.
    assert_eq!(lo[1], T);
    assert_eq!(hi[1], 10 * T);
}

/// A springboard one tile wide and a quarter tile high on the floor at
/// column `c`.
fn spring(c: i32, strength: i32) -> EntityDef {
    ent_at(
        EntityKind::Springboard { strength },
        IVec2::new(c * T + T / 2, FLOOR - T / 8),
        IVec2::new(T, T / 4),
    )
}

fn launches(s: &Sim) -> usize {
    s.events
        .iter()
        .filter(|e| matches!(e, GameEvent::Launched { .. }))
        .count()
}

#[test]
fn a_springboard_launches_once_per_touch() {
    let strength = 2560;
    let lv = room(
        &[],
        vec![spring(10, strength), ent(EntityKind::PlayerSpawn, 10, 8)],
    );
    let mut s = Sim::new(&lv);
    let mut total = 0;
    let mut launched_at = Vec::new();
    for t in 0..400 {
        s.step(NONE);
        let n = launches(&s);
        if n > 0 {
            assert_eq!(n, 1);
            assert!(s.events.contains(&GameEvent::Launched {
                player: P1,
                springboard: id_of(0)
            }));
            assert_eq!(s.view().vel.y, -strength);
            launched_at.push(t);
        }
        total += n;
    }
    // Every landing on it is one launch: several, well apart.
    assert!(total >= 3, "{launched_at:?}");
    assert!(
        launched_at.windows(2).all(|w| w[1] - w[0] > 20),
        "{launched_at:?}"
    );

    // A weak spring keeps the player inside its box: one launch for the
    // whole touch, another after leaving and coming back.
    let lv = room(
        &[],
        vec![spring(10, 40), ent(EntityKind::PlayerSpawn, 10, 11)],
    );
    let mut s = Sim::new(&lv);
    let mut n = 0;
    for _ in 0..200 {
        s.step(NONE);
        n += launches(&s);
    }
    assert_eq!(n, 1, "one launch while touching");
    for _ in 0..40 {
        s.step(RIGHT);
        n += launches(&s);
    }
    assert!(s.pos().x > 12 * T, "walked off");
    for _ in 0..200 {
        s.step(LEFT);
        n += launches(&s);
        if s.pos().x < 10 * T + T / 2 {
            break;
        }
    }
    assert_eq!(n, 2, "launched again when coming back");
}

#[test]
fn a_coin_counts_once() {
    let lv = room(
        &[],
        vec![
            ent(EntityKind::Coin, 10, 12),
            ent(EntityKind::PlayerSpawn, 4, 12),
        ],
    );
    let mut s = Sim::new(&lv);
    let mut picked = Vec::new();
    for t in 0..400 {
        s.step(if t < 150 { RIGHT } else { LEFT });
        for e in &s.events {
            if let GameEvent::CoinPicked { .. } = e {
                picked.push(*e);
            }
        }
    }
    assert!(s.pos().x < 5 * T, "went back over the coin");
    assert_eq!(
        picked,
        vec![GameEvent::CoinPicked {
            player: P1,
            coin: id_of(0),
            total: 1
        }]
    );
    assert_eq!(s.view().coins, 1);
    assert!(!s.game.entities().next().unwrap().active);
    // Another player walking over it gets nothing.
    s.game.add_player(PlayerId(2)).unwrap();
    for _ in 0..150 {
        let ev = s.game.step(&[(PlayerId(2), RIGHT)]);
        assert!(!ev.iter().any(|e| matches!(e, GameEvent::CoinPicked { .. })));
    }
    assert_eq!(s.game.coins_of(PlayerId(2)), 0);
    assert_eq!(s.game.coins_of(P1), 1);
}

#[test]
fn a_checkpoint_changes_the_respawn_point_and_hazards_hurt() {
    // Hazard tiles at columns 8 and 30 on row 12; a checkpoint at column 20.
    let lv = room(
        &[(12, 8, "^"), (12, 30, "^")],
        vec![
            ent(EntityKind::Checkpoint, 20, 12),
            ent(EntityKind::PlayerSpawn, 3, 12),
            ent(EntityKind::Hazard, 36, 12),
        ],
    );
    let mut s = Sim::new(&lv);
    s.land(5);
    let spawn = s.pos();
    // Walk into the first hazard tile: back to the spawn.
    walk_until_hurt(&mut s, 200, HurtCause::HazardTile, spawn);
    // Jump over it and reach the checkpoint.
    let mut reached = false;
    for t in 0..400 {
        let b = if (20..50).contains(&t) {
            RIGHT_JUMP
        } else {
            RIGHT
        };
        s.step(b);
        assert!(!s.saw(|e| matches!(e, GameEvent::Died { .. })), "tick {t}");
        if s.saw(|e| matches!(e, GameEvent::Checkpoint { .. })) {
            assert!(s.events.contains(&GameEvent::Checkpoint {
                player: P1,
                checkpoint: id_of(0)
            }));
            reached = true;
            break;
        }
    }
    assert!(reached, "never reached the checkpoint at {}", s.pos());
    assert_eq!(s.view().checkpoint, Some(id_of(0)));
    let checkpoint = IVec2::new(20 * T + T / 2, FLOOR - s.view().half.y);
    // The next hazard tile sends it to the checkpoint, without a new
    // checkpoint event.
    walk_until_hurt(&mut s, 300, HurtCause::HazardTile, checkpoint);
    // Jump over the hazard tile: the hazard volume hurts too.
    let mut hurt = false;
    let mut jump = None;
    for t in 0..400 {
        if jump.is_none() && s.pos().x > 27 * T + T / 2 {
            jump = Some(t);
        }
        let b = if jump.is_some_and(|j| t < j + 30) {
            RIGHT_JUMP
        } else {
            RIGHT
        };
        s.step(b);
        if let Some(GameEvent::Died { cause, .. }) = s.events.first() {
            assert_eq!(*cause, HurtCause::Hazard(id_of(2)), "tick {t}");
            hurt = true;
            break;
        }
    }
    assert!(hurt);
    s.sit_out_death(RIGHT, checkpoint);
    assert_eq!(s.pos(), checkpoint);
    assert_eq!(s.view().deaths, 3);
}

#[test]
fn reaching_the_goal_raises_the_win_event_once() {
    let lv = room(
        &[],
        vec![
            ent(EntityKind::Goal, 15, 12),
            ent(EntityKind::PlayerSpawn, 4, 12),
        ],
    );
    let mut s = Sim::new(&lv);
    let mut wins = 0;
    for t in 0..300 {
        s.step(if t < 200 { RIGHT } else { LEFT });
        wins += s
            .events
            .iter()
            .filter(|e| matches!(e, GameEvent::Finished { player: P1, .. }))
            .count();
    }
    assert_eq!(wins, 1);
    assert!(s.view().won);
    assert_eq!(s.view().place, Some(1));
    assert_eq!(s.game.entities().next().unwrap().ty, EntityType::Goal);
}

#[test]
fn a_player_who_falls_out_of_the_level_dies_and_respawns() {
    // A ledge with nothing below or beside it: walk off its right end.
    let lv = level(
        &["..........", "..........", "######....", ".........."],
        vec![ent(EntityKind::PlayerSpawn, 1, 1)],
    );
    let (_, hi) = lv.bounds().unwrap();
    assert_eq!(hi, IVec2::new(10 * T, 4 * T));
    let mut s = Sim::new(&lv);
    s.land(5);
    let spawn = s.pos();
    let mut lowest = i32::MIN;
    for t in 0..2000 {
        s.step(RIGHT);
        if s.saw(|e| matches!(e, GameEvent::Died { .. })) {
            assert_eq!(
                s.events,
                vec![GameEvent::Died {
                    player: P1,
                    cause: HurtCause::Fell
                }],
                "tick {t}"
            );
            assert_eq!(s.view().deaths, 1, "falling out is a death");
            s.sit_out_death(RIGHT, spawn);
            // Not before its top passed the margin below the level: the
            // tick before, its top (8 px above its centre) was still above
            // the line, and less than one fall step (32 px) from it.
            let line = hi.y + FALL_MARGIN;
            let top = lowest - 8 * 256;
            assert!(top <= line && top > line - 32 * 256, "{top} vs {line}");
            return;
        }
        lowest = lowest.max(s.pos().y);
    }
    panic!("never fell out, at {}", s.pos());
}
