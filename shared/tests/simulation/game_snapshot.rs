//! The `Game` API contract: snapshot -> restore reproduces the state hash and
//! every future tick; long multi-player runs are deterministic; players join
//! and leave; bad snapshots are refused without changing anything.

use crate::platformer_kit;

use glam::IVec2;
use ledge_shared::game::{kind, Game, GameError, GameEvent, ENTITY_ID_BASE};
use ledge_shared::input::Buttons;
use ledge_shared::level::{EntityKind, Level};
use ledge_shared::protocol::{EntityState, PlayerId, StateSnapshot};
use ledge_shared::scene::scripted_inputs;
use platformer_kit::*;

/// A level with a bit of everything, 60 x 20 tiles.
fn full_level() -> Level {
    let rows = [
        "############################################################",
        "#..........................................................#",
        "#..........................................................#",
        "#..........................................................#",
        "#..........................................................#",
        "#..........................................................#",
        "#..........................................................#",
        "#.........====.............................................#",
        "#..........................................................#",
        "#..................................######..................#",
        "#..........................................................#",
        "#......=====...............................................#",
        "#..........................................====............#",
        "#..........................................................#",
        "#.......................................ab##cd.............#",
        "#......../##\\..................^^.....ab######cd...........#",
        "#......./####\\.........................................#...#",
        "#...............####...................................#...#",
        "#..............######..................................#...#",
        "############################################################",
    ];
    let plat = IVec2::new(4 * T, T / 2);
    let c = tile_centre;
    let entities = vec![
        ent(EntityKind::PlayerSpawn, 3, 18),
        ent(EntityKind::PlayerSpawn, 5, 18),
        platform(&[c(25, 17), c(25, 8)], plat, 128, false),
        platform(&[c(28, 12), c(36, 12)], plat, 200, true),
        platform(&[c(48, 16), c(54, 10), c(48, 6)], plat, 150, false),
        ent(EntityKind::Walker { speed: 96 }, 10, 18),
        ent(EntityKind::Walker { speed: 128 }, 30, 18),
        ent(EntityKind::Walker { speed: 64 }, 38, 8),
        ent_at(
            EntityKind::Springboard { strength: 2560 },
            IVec2::new(33 * T + T / 2, 19 * T - T / 8),
            IVec2::new(T, T / 4),
        ),
        ent_at(
            EntityKind::Springboard { strength: 1800 },
            IVec2::new(52 * T + T / 2, 19 * T - T / 8),
            IVec2::new(T, T / 4),
        ),
        ent(EntityKind::Coin, 8, 18),
        ent(EntityKind::Coin, 12, 14),
        ent(EntityKind::Coin, 20, 16),
        ent(EntityKind::Coin, 27, 7),
        ent(EntityKind::Coin, 41, 11),
        ent(EntityKind::Coin, 50, 18),
        ent(EntityKind::Checkpoint, 22, 18),
        ent(EntityKind::Checkpoint, 45, 13),
        ent(EntityKind::Goal, 57, 18),
        ent(EntityKind::Hazard, 15, 18),
        ent(EntityKind::Block, 40, 17),
    ];
    level(&rows, entities)
}

/// Player `id`'s buttons at `tick`: the scripted inputs, shifted per player,
/// and now and then a restart.
fn input(id: u32, tick: u64) -> Buttons {
    if (tick + id as u64 * 977) % 2500 == 0 {
        return Buttons(Buttons::RESTART);
    }
    let b = scripted_inputs(tick + id as u64 * 40 * 17);
    // Run right more often than left, so players get around the level.
    if (tick / 40 + id as u64) % 3 == 0 {
        Buttons(b.0 & !Buttons::LEFT | Buttons::RIGHT)
    } else {
        b
    }
}

fn inputs(game: &Game) -> Vec<(PlayerId, Buttons)> {
    let t = game.tick();
    // Deliberately not in id order.
    let mut v: Vec<_> = game.players().map(|(id, _)| (id, input(id.0, t))).collect();
    v.reverse();
    v
}

fn step(game: &mut Game) -> Vec<GameEvent> {
    let i = inputs(game);
    game.step(&i).to_vec()
}

#[test]
fn restore_of_a_snapshot_reproduces_the_hash_and_the_next_600_ticks() {
    let lv = full_level();
    let mut a = Game::from_level(&lv).unwrap();
    for id in [3, 1, 2] {
        a.add_player(PlayerId(id)).unwrap();
    }
    for _ in 0..300 {
        step(&mut a);
    }
    let snap = a.snapshot();
    assert_eq!(snap.tick, 300);
    snap.validate().unwrap();
    // Platforms are client-simulated: in the entity states, not in the
    // snapshot.
    assert!(snap
        .entities
        .iter()
        .all(|e| e.flags & EntityState::CLIENT_SIMULATED == 0));
    let all = a.entity_states();
    let platforms: Vec<_> = all.iter().filter(|e| e.kind == kind::PLATFORM).collect();
    assert_eq!(platforms.len(), 3);
    assert!(platforms
        .iter()
        .all(|e| e.flags & EntityState::CLIENT_SIMULATED != 0));
    assert_eq!(snap.entities.len(), all.len() - 3);

    // A fresh game of the same level, with a different player set.
    let mut b = Game::from_level(&lv).unwrap();
    b.add_player(PlayerId(9)).unwrap();
    b.add_player(PlayerId(2)).unwrap();
    assert_ne!(b.state_hash(), a.state_hash());
    b.restore(&snap).unwrap();
    assert_eq!(b.state_hash(), a.state_hash());
    assert_eq!(b.snapshot(), snap);
    assert_eq!(b.entity_states(), all);
    assert_eq!(b.tick(), 300);
    // The players' views (runs included) are the same; only the world's
    // per-tick scratch (touched sides) is not restored.
    let views = |g: &Game| {
        g.player_views()
            .map(|mut v| {
                v.sides = Default::default();
                v
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(views(&b), views(&a));
    assert!(
        a.player_views().any(|v| v.run_started),
        "the runs started: {:?}",
        views(&a)
    );

    // The same game, rolled back after running on.
    let mut c = a.clone();
    for _ in 0..123 {
        step(&mut c);
    }
    assert_ne!(c.state_hash(), a.state_hash());
    c.restore(&snap).unwrap();
    assert_eq!(c.state_hash(), a.state_hash());

    let mut events = 0;
    for t in 0..600 {
        let ea = step(&mut a);
        let eb = step(&mut b);
        let ec = step(&mut c);
        assert_eq!(ea, eb, "tick {t}");
        assert_eq!(ea, ec, "tick {t}");
        assert_eq!(a.state_hash(), b.state_hash(), "tick {t}");
        assert_eq!(a.state_hash(), c.state_hash(), "tick {t}");
        assert_eq!(views(&a), views(&c), "tick {t}");
        events += ea.len();
    }
    assert!(events > 20, "the run did things: {events} events");
}

/// A 10,000-tick run with four players joining, leaving and rejoining;
/// returns the final hash, the event counts by kind, and the snapshot at
/// tick 5,000.
fn long_run(restore_at_5000: Option<&StateSnapshot>) -> (u64, [usize; 9], StateSnapshot) {
    let lv = full_level();
    let mut g = Game::from_level(&lv).unwrap();
    let mut counts = [0usize; 9];
    let mut mid = None;
    for t in 0..10_000u64 {
        match t {
            0 => g.add_player(PlayerId(1)).unwrap(),
            50 => g.add_player(PlayerId(4)).unwrap(),
            120 => g.add_player(PlayerId(2)).unwrap(),
            400 => g.add_player(PlayerId(3)).unwrap(),
            3000 => assert!(g.remove_player(PlayerId(2))),
            6000 => g.add_player(PlayerId(2)).unwrap(),
            _ => {}
        }
        if t == 5000 {
            mid = Some(g.snapshot());
            if let Some(s) = restore_at_5000 {
                let mut fresh = Game::from_level(&lv).unwrap();
                fresh.restore(s).unwrap();
                g = fresh;
            }
        }
        for e in step(&mut g) {
            counts[match e {
                GameEvent::Jumped(_) => 0,
                GameEvent::CoinPicked { .. } => 1,
                GameEvent::Checkpoint { .. } => 2,
                GameEvent::Died { .. } => 3,
                GameEvent::Stomped { .. } | GameEvent::EnemySquished { .. } => 4,
                GameEvent::Launched { .. } => 5,
                GameEvent::Respawned { .. } => 6,
                GameEvent::Restarted(_) => 8,
                _ => 7,
            }] += 1;
        }
    }
    (g.state_hash(), counts, mid.unwrap())
}

#[test]
fn a_10000_tick_multiplayer_run_is_deterministic() {
    let (h1, c1, mid) = long_run(None);
    let (h2, c2, _) = long_run(None);
    assert_eq!(h1, h2);
    assert_eq!(c1, c2);
    // Restored mid-run into a fresh game, it ends the same.
    let (h3, _, _) = long_run(Some(&mid));
    assert_eq!(h3, h1);
    // The run exercised jumping, coins, dying, springs, respawning and
    // restarting.
    assert!(c1[0] > 50, "{c1:?}");
    assert!(c1[1] > 0 && c1[3] > 0 && c1[5] > 0 && c1[6] > 0, "{c1:?}");
    assert!(c1[8] > 5, "{c1:?}");
}

#[test]
fn players_join_and_leave() {
    let lv = full_level();
    let mut g = Game::from_level(&lv).unwrap();
    g.add_player(PlayerId(5)).unwrap();
    g.add_player(PlayerId(2)).unwrap();
    assert_eq!(
        g.add_player(PlayerId(5)),
        Err(GameError::DuplicatePlayer(PlayerId(5)))
    );
    assert_eq!(
        g.add_player(PlayerId(ENTITY_ID_BASE)),
        Err(GameError::PlayerIdOutOfRange(PlayerId(ENTITY_ID_BASE)))
    );
    let ids: Vec<_> = g.players().map(|(id, _)| id).collect();
    assert_eq!(ids, vec![PlayerId(2), PlayerId(5)]);
    // Two spawns: player id modulo the spawn count picks one; players stand
    // on the floor at its bottom, player 2 on spawn 0 itself, player 5 (the
    // third id of spawn 1) on that spawn's third spot, one tile right
    // (`game::spawn`).
    let pos: Vec<_> = g.players().map(|(_, p)| p).collect();
    assert_eq!(pos[0], IVec2::new(3 * T + T / 2, 19 * T - 8 * 256));
    assert_eq!(pos[1], IVec2::new(6 * T + T / 2, 19 * T - 8 * 256));
    let ev = g.step(&[]).to_vec();
    assert_eq!(
        ev,
        vec![
            GameEvent::Joined(PlayerId(5)),
            GameEvent::Joined(PlayerId(2))
        ]
    );
    assert!(g.remove_player(PlayerId(5)));
    assert!(!g.remove_player(PlayerId(5)));
    assert_eq!(g.step(&[]).to_vec(), vec![GameEvent::Left(PlayerId(5))]);
    assert_eq!(g.players().count(), 1);
    // Bodies come and go with players.
    let bodies = g.world().bodies().count();
    g.add_player(PlayerId(5)).unwrap();
    assert_eq!(g.world().bodies().count(), bodies + 1);
    g.remove_player(PlayerId(2));
    assert_eq!(g.world().bodies().count(), bodies);
}

#[test]
fn bad_snapshots_are_refused_and_change_nothing() {
    let lv = full_level();
    let mut g = Game::from_level(&lv).unwrap();
    g.add_player(PlayerId(1)).unwrap();
    for _ in 0..50 {
        step(&mut g);
    }
    let good = g.snapshot();
    let h = g.state_hash();
    let walker = ENTITY_ID_BASE + 5;
    type Corrupt = Box<dyn Fn(&mut StateSnapshot)>;
    let cases: Vec<(&str, Corrupt)> = vec![
        (
            "unknown entity",
            Box::new(|s| s.entities.push(EntityState::zero(ENTITY_ID_BASE + 999))),
        ),
        (
            "wrong kind",
            Box::new(move |s| {
                let i = s.entities.iter().position(|e| e.id == walker).unwrap();
                s.entities[i].kind = kind::COIN;
            }),
        ),
        (
            "missing walker",
            Box::new(move |s| s.entities.retain(|e| e.id != walker)),
        ),
        (
            "unknown player flags",
            Box::new(|s| s.entities[0].flags |= 1 << 12),
        ),
        (
            "bad checkpoint",
            Box::new(|s| s.entities[0].flags |= 3 << 16),
        ),
        (
            "player kind",
            Box::new(|s| s.entities[0].kind = kind::WALKER),
        ),
        (
            "position out of bounds",
            Box::new(|s| s.entities[0].pos.x = i32::MAX),
        ),
        ("unsorted", Box::new(|s| s.entities.swap(0, 1))),
        (
            "stateless entity",
            Box::new(|s| {
                let mut e = EntityState::zero(ENTITY_ID_BASE + 18);
                e.kind = kind::GOAL;
                s.entities.push(e)
            }),
        ),
    ];
    for (what, f) in cases {
        let mut s = good.clone();
        f(&mut s);
        assert!(
            matches!(g.restore(&s), Err(GameError::BadSnapshot(_))),
            "{what} accepted"
        );
        assert_eq!(g.state_hash(), h, "{what} changed the state");
    }
    g.restore(&good).unwrap();
    assert_eq!(g.state_hash(), h);
}

#[test]
fn platforms_follow_the_tick_exactly() {
    let lv = full_level();
    let mut g = Game::from_level(&lv).unwrap();
    let schedules: Vec<_> = lv
        .entities
        .iter()
        .filter_map(|e| match &e.kind {
            EntityKind::MovingPlatform { motion, .. } => {
                Some(ledge_shared::game::PathSchedule::new(motion).unwrap())
            }
            _ => None,
        })
        .collect();
    for _ in 0..1000 {
        g.step(&[]);
        let got: Vec<_> = g
            .entities()
            .filter(|e| e.ty == ledge_shared::game::EntityType::Platform)
            .map(|e| e.pos)
            .collect();
        let want: Vec<_> = schedules.iter().map(|s| s.at(g.tick())).collect();
        assert_eq!(got, want);
    }
}

#[test]
fn the_default_level_runs() {
    let lv = ledge_levels::default_level();
    let mut g = Game::from_level(&lv).unwrap();
    g.add_player(PlayerId(1)).unwrap();
    let mut grounded = false;
    for _ in 0..120 {
        g.step(&[]);
        grounded |= g.player(PlayerId(1)).unwrap().grounded;
    }
    assert!(grounded, "the player lands at the spawn");
    let x0 = g.player(PlayerId(1)).unwrap().pos.x;
    for _ in 0..30 {
        g.step(&[(PlayerId(1), Buttons(Buttons::RIGHT))]);
    }
    assert!(g.player(PlayerId(1)).unwrap().pos.x > x0 + 4 * 256);
    for _ in 0..3000 {
        step(&mut g);
    }
}

#[test]
fn a_game_started_at_a_later_tick_runs_like_one_restored_there() {
    // A room moving to another level keeps counting its ticks: a fresh
    // game set to tick T has its platforms where a game run to T has them,
    // and restores from its own snapshots like any other.
    let level = full_level();
    let mut ran = Game::from_level(&level).unwrap();
    for _ in 0..500 {
        ran.step(&[]);
    }
    let mut late = Game::from_level(&level).unwrap();
    assert!(late.start_at(500));
    assert_eq!(late.tick(), 500);
    let platforms = |g: &Game| {
        g.entities()
            .filter(|e| e.ty == ledge_shared::game::EntityType::Platform)
            .map(|e| e.pos)
            .collect::<Vec<_>>()
    };
    assert!(!platforms(&late).is_empty());
    assert_eq!(platforms(&late), platforms(&ran));
    late.add_player(PlayerId(1)).unwrap();
    assert!(!late.start_at(900), "refused once it has players");
    for _ in 0..60 {
        step(&mut late);
    }
    let mut copy = Game::from_level(&level).unwrap();
    copy.restore(&late.snapshot()).unwrap();
    for _ in 0..120 {
        step(&mut late);
        step(&mut copy);
        assert_eq!(late.state_hash(), copy.state_hash(), "tick {}", late.tick());
    }
}
