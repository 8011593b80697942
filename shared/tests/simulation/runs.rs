//! Runs: deaths and the respawn delay, the run timer, finishing places,
//! restarts; all of it in the state hash, the snapshot (full and delta) and
//! a restored game.

use crate::platformer_kit;

use glam::IVec2;
use ledge_shared::game::state::{player_flags, run_flags};
use ledge_shared::game::{
    kind, Game, GameConfig, GameEvent, HurtCause, PlayerConfig, PlayerView, ENTITY_ID_BASE,
    MAX_RESPAWN_DELAY_TICKS, RUN_ID_BASE,
};
use ledge_shared::input::Buttons;
use ledge_shared::level::{EntityKind, Level};
use ledge_shared::protocol::{decode_delta, encode_delta, EntityState, PlayerId, StateSnapshot};
use platformer_kit::*;

const P1: PlayerId = PlayerId(1);
const P2: PlayerId = PlayerId(2);
const RESTART: Buttons = Buttons(Buttons::RESTART);
const UP: Buttons = Buttons(Buttons::UP);

/// The floor's top: row 13.
const FLOOR: i32 = 13 * T;

/// The centre of a player standing on the floor in the tile of column `c`
/// (where a checkpoint or spawn of one tile at row 12 puts it).
fn standing(c: i32) -> IVec2 {
    IVec2::new(c * T + T / 2, FLOOR - 8 * 256)
}

fn with_delay(delay: u16) -> GameConfig {
    GameConfig {
        player: PlayerConfig {
            respawn_delay_ticks: delay,
            ..PlayerConfig::default()
        },
        ..GameConfig::default()
    }
}

fn finished(events: &[GameEvent], who: PlayerId) -> Option<(u32, u32)> {
    events.iter().find_map(|e| match *e {
        GameEvent::Finished {
            player,
            ticks,
            place,
        } if player == who => Some((ticks, place)),
        _ => None,
    })
}

#[test]
fn the_default_respawn_delay_is_about_0_4_s_and_the_bound_is_checked() {
    let d = PlayerConfig::default().respawn_delay_ticks;
    assert_eq!(d, 24, "0.4 s at 60 ticks a second");
    let lv = room(&[], vec![ent(EntityKind::PlayerSpawn, 3, 12)]);
    assert!(Game::with_config(&lv, with_delay(MAX_RESPAWN_DELAY_TICKS)).is_ok());
    assert!(Game::with_config(&lv, with_delay(0)).is_ok());
    let err = Game::with_config(&lv, with_delay(MAX_RESPAWN_DELAY_TICKS + 1)).unwrap_err();
    assert!(err.to_string().contains("respawn_delay_ticks"), "{err}");
}

/// Spikes (hazard tiles) at column 20, a checkpoint at column 10, the spawn
/// at column 3.
fn spikes_level() -> Level {
    room(
        &[(12, 20, "^")],
        vec![
            ent(EntityKind::PlayerSpawn, 3, 12),
            ent(EntityKind::Checkpoint, 10, 12),
        ],
    )
}

#[test]
fn a_run_into_spikes_counts_one_death_and_respawns_at_the_checkpoint_after_the_delay() {
    for delay in [0, 1, 24, 90] {
        let mut s = Sim::with(&spikes_level(), with_delay(delay));
        s.land(5);
        let mut died = None;
        for _ in 0..400 {
            s.step(RIGHT);
            if s.saw(|e| matches!(e, GameEvent::Died { .. })) {
                died = Some(s.game.tick());
                break;
            }
            assert_eq!(s.view().deaths, 0);
        }
        let died = died.expect("ran into the spikes");
        assert_eq!(s.view().checkpoint, Some(ENTITY_ID_BASE + 1), "passed it");
        assert_eq!(
            s.events[0],
            GameEvent::Died {
                player: P1,
                cause: HurtCause::HazardTile
            }
        );
        assert_eq!(s.view().deaths, 1, "delay {delay}");
        let at = s.pos();
        if delay == 0 {
            // Back at once, as before there was a delay.
            assert_eq!(
                s.events[1..],
                [GameEvent::Respawned {
                    player: P1,
                    pos: standing(10)
                }]
            );
            assert_eq!(s.view().dead, None);
            continue;
        }
        assert!(at.x > 19 * T, "died in the spikes, at {at}");
        // Dead for exactly `delay` ticks: no movement, no event (sitting in
        // the spikes does not kill it again), holding buttons or not.
        for k in 1..=delay {
            assert_eq!(s.view().dead, Some(delay - k + 1), "delay {delay}");
            assert_eq!(s.pos(), at);
            s.step(if k % 2 == 0 { RIGHT } else { RIGHT_JUMP });
            if k < delay {
                assert_eq!(s.events, vec![], "delay {delay}, tick {k}");
            }
        }
        assert_eq!(s.game.tick(), died + delay as u64);
        assert_eq!(
            s.events,
            vec![GameEvent::Respawned {
                player: P1,
                pos: standing(10)
            }]
        );
        let v = s.view();
        assert_eq!(
            (v.dead, v.pos, v.vel, v.deaths),
            (None, standing(10), IVec2::ZERO, 1)
        );
        // Alive again: it runs (and dies in the spikes a second time).
        for _ in 0..200 {
            s.step(RIGHT);
            if s.saw(|e| matches!(e, GameEvent::Died { .. })) {
                break;
            }
        }
        assert_eq!(s.view().deaths, 2, "delay {delay}");
    }
}

#[test]
fn a_dead_player_neither_collects_nor_is_hurt_and_its_body_is_suspended() {
    // A coin in the spikes' tile: the player dies there, its body sits in
    // the spikes and the coin while dead, and takes neither.
    let lv = room(
        &[(12, 20, "^")],
        vec![
            ent(EntityKind::PlayerSpawn, 3, 12),
            ent(EntityKind::Coin, 20, 12),
        ],
    );
    let mut s = Sim::new(&lv);
    s.land(5);
    let spawn = s.pos();
    for _ in 0..400 {
        s.step(RIGHT);
        if s.saw(|e| matches!(e, GameEvent::Died { .. })) {
            break;
        }
    }
    assert_eq!(
        s.events,
        vec![GameEvent::Died {
            player: P1,
            cause: HurtCause::HazardTile
        }]
    );
    let coin_active = |s: &Sim| s.game.entities().nth(1).unwrap().active;
    assert!(coin_active(&s));
    let at = s.pos();
    let (_, body) = s
        .game
        .world()
        .bodies()
        .find(|(_, b)| b.pos() == at && b.kind() == ledge_shared::world::BodyKind::Dynamic)
        .expect("the player's body");
    assert!(!body.is_enabled(), "a dead player's body is suspended");
    // No second death, no coin, no motion while dead (sit_out_death checks
    // that no event comes), then back at the spawn.
    s.sit_out_death(RIGHT, spawn);
    assert!(coin_active(&s));
    assert_eq!((s.view().deaths, s.view().coins), (1, 0));
}

#[test]
fn a_finished_runs_time_is_the_ticks_from_the_first_input_to_the_goal() {
    let lv = room(
        &[],
        vec![
            ent(EntityKind::PlayerSpawn, 3, 12),
            ent(EntityKind::Goal, 14, 12),
        ],
    );
    let mut s = Sim::new(&lv);
    // Idle: the timer has not started.
    s.run(NONE, 40);
    let v = s.view();
    assert_eq!((v.run_started, v.run_ticks), (false, 0));
    // Unused bits do not start it either.
    s.run(Buttons(1 << 6 | 1 << 7), 5);
    assert!(!s.view().run_started);
    // The first press of anything (here: up, which moves nothing) starts
    // it; it runs while the player stands still.
    let first = s.game.tick();
    s.step(UP);
    assert_eq!((s.view().run_started, s.view().run_ticks), (true, 1));
    s.run(NONE, 30);
    assert_eq!(s.view().run_ticks, 31);
    let mut time = None;
    for _ in 0..400 {
        s.step(RIGHT);
        if let Some(t) = finished(&s.events, P1) {
            time = Some(t);
            break;
        }
        assert_eq!(s.view().run_ticks as u64, s.game.tick() - first);
    }
    let (ticks, place) = time.expect("reached the goal");
    assert_eq!(ticks as u64, s.game.tick() - first);
    assert_eq!(place, 1);
    let v = s.view();
    assert_eq!((v.won, v.place, v.run_ticks), (true, Some(1), ticks));
    // Stopped: it keeps playing, the time stays, no second finish.
    for t in 0..120 {
        s.step(if t < 60 { LEFT } else { RIGHT });
        assert_eq!(finished(&s.events, P1), None);
    }
    assert_eq!(s.view().run_ticks, ticks);
    assert!(s.view().won);
}

/// Two lanes, one above the other, each with a spawn at column 3 and a goal
/// at column 14: players 1 and 2 each stand on their own spawn (spawn `id %
/// 2`), at the same distance from their own goal.
fn two_lanes() -> Level {
    let mut rows = vec!["#".repeat(40)];
    for r in 1..13 {
        rows.push(if r == 7 {
            "#".repeat(40)
        } else {
            format!("#{}#", ".".repeat(38))
        });
    }
    rows.push("#".repeat(40));
    let rows: Vec<&str> = rows.iter().map(|s| s.as_str()).collect();
    level(
        &rows,
        vec![
            ent(EntityKind::PlayerSpawn, 3, 12),
            ent(EntityKind::PlayerSpawn, 3, 6),
            ent(EntityKind::Goal, 14, 12),
            ent(EntityKind::Goal, 14, 6),
        ],
    )
}

fn two_players() -> Game {
    let mut g = Game::from_level(&two_lanes()).unwrap();
    g.add_player(P2).unwrap();
    g.add_player(P1).unwrap();
    for _ in 0..20 {
        g.step(&[]);
    }
    g
}

fn place(g: &Game, id: PlayerId) -> Option<u32> {
    g.player(id).unwrap().place
}

#[test]
fn two_players_finishing_get_places_1_and_2_deterministically() {
    // The same tick: the lower id is first.
    let mut g = two_players();
    let mut both = None;
    for _ in 0..400 {
        let ev = g.step(&[(P2, RIGHT), (P1, RIGHT)]).to_vec();
        let (a, b) = (finished(&ev, P1), finished(&ev, P2));
        if a.is_some() || b.is_some() {
            both = Some((a, b, ev));
            break;
        }
    }
    let (a, b, ev) = both.expect("they reached their goals");
    let (a, b) = (a.expect("player 1 finished"), b.expect("player 2 too"));
    assert_eq!(a.0, b.0, "the same time");
    assert_eq!((a.1, b.1), (1, 2), "{ev:?}");
    // In id order in the events too.
    let order: Vec<_> = ev
        .iter()
        .filter_map(|e| match e {
            GameEvent::Finished { player, .. } => Some(*player),
            _ => None,
        })
        .collect();
    assert_eq!(order, vec![P1, P2]);
    assert_eq!((place(&g, P1), place(&g, P2)), (Some(1), Some(2)));
    let table: Vec<_> = g.results().iter().map(|p| (p.id, p.place)).collect();
    assert_eq!(table, vec![(P1, Some(1)), (P2, Some(2))]);

    // Player 2 starts 5 ticks earlier: it reaches the goal first, so it is
    // first, with the same run time (the timer starts at the first press).
    let mut g = two_players();
    let mut got = (None, None);
    for t in 0..400 {
        let i = if t < 5 {
            vec![(P2, RIGHT)]
        } else {
            vec![(P1, RIGHT), (P2, RIGHT)]
        };
        let ev = g.step(&i).to_vec();
        got.0 = got.0.or(finished(&ev, P1));
        got.1 = got.1.or(finished(&ev, P2));
        if got.0.is_some() {
            break;
        }
    }
    let (a, b) = (got.0.unwrap(), got.1.unwrap());
    assert_eq!((a.1, b.1), (2, 1));
    assert_eq!(a.0, b.0);
    let table: Vec<_> = g.results().iter().map(|p| p.id).collect();
    assert_eq!(table, vec![P2, P1]);

    // Places are among the players present: when the winner restarts,
    // player 1 moves up; finishing again, player 2 is second.
    g.step(&[(P2, RESTART)]);
    assert_eq!((place(&g, P1), place(&g, P2)), (Some(1), None));
    assert_eq!(g.results().len(), 1);
    let mut again = None;
    for _ in 0..400 {
        let ev = g.step(&[(P2, RIGHT)]).to_vec();
        if let Some(f) = finished(&ev, P2) {
            again = Some(f);
            break;
        }
    }
    assert_eq!(again.map(|f| f.1), Some(2));
    // And when the first leaves, the second is first.
    assert!(g.remove_player(P1));
    assert_eq!(place(&g, P2), Some(1));
}

/// Spawn at column 8, a coin at 10, a checkpoint at 12, spikes at 16, the
/// goal at column 2 (behind the spawn).
fn restart_level() -> Level {
    room(
        &[(12, 16, "^")],
        vec![
            ent(EntityKind::PlayerSpawn, 8, 12),
            ent(EntityKind::Coin, 10, 12),
            ent(EntityKind::Checkpoint, 12, 12),
            ent(EntityKind::Goal, 2, 12),
        ],
    )
}

#[test]
fn restart_resets_position_timer_deaths_checkpoint_finish_and_coins() {
    let mut s = Sim::new(&restart_level());
    s.land(5);
    let spawn = s.pos();
    assert_eq!(spawn, standing(8));
    // Right: the coin, the checkpoint, the spikes (one death).
    for _ in 0..300 {
        s.step(RIGHT);
        if s.saw(|e| matches!(e, GameEvent::Died { .. })) {
            break;
        }
    }
    s.sit_out_death(NONE, standing(12));
    // Left to the goal.
    for _ in 0..400 {
        s.step(LEFT);
        if finished(&s.events, P1).is_some() {
            break;
        }
    }
    let v = s.view();
    assert!(v.won && v.place == Some(1), "{v:?}");
    assert_eq!(
        (v.coins, v.deaths, v.checkpoint),
        (1, 1, Some(ENTITY_ID_BASE + 2))
    );
    let coin_active = |s: &Sim| s.game.entities().nth(1).unwrap().active;
    assert!(!coin_active(&s));
    // Restart (with left held: the restart tick's movement is discarded).
    let tick = s.game.tick();
    s.step(Buttons(Buttons::RESTART | Buttons::LEFT));
    assert_eq!(
        s.events,
        vec![
            GameEvent::Restarted(P1),
            GameEvent::Respawned {
                player: P1,
                pos: spawn
            }
        ]
    );
    assert_eq!(s.game.tick(), tick + 1);
    let v = s.view();
    assert_eq!(v.pos, spawn);
    assert_eq!(v.vel, IVec2::ZERO);
    assert_eq!((v.run_started, v.run_ticks, v.deaths), (false, 0, 0));
    assert_eq!((v.won, v.place, v.checkpoint), (false, None, None));
    assert_eq!(v.coins, 0, "its coins went back to the level");
    assert!(coin_active(&s), "for anyone to take");
    for _ in 0..10 {
        s.step(RESTART);
        assert_eq!(s.events, vec![], "held: no second restart");
    }
    assert!(!s.view().run_started, "restart is not a button that plays");
    // The new run: its timer starts with the next press, the coin counts
    // for it again.
    s.step(RIGHT);
    assert_eq!((s.view().run_started, s.view().run_ticks), (true, 1));
    for _ in 0..60 {
        s.step(RIGHT);
        if s.view().coins == 1 {
            break;
        }
    }
    assert_eq!(s.view().coins, 1);
}

#[test]
fn restart_while_dead_goes_to_the_spawn_at_once() {
    let mut s = Sim::with(&restart_level(), with_delay(60));
    s.land(5);
    let spawn = s.pos();
    for _ in 0..300 {
        s.step(RIGHT);
        if s.saw(|e| matches!(e, GameEvent::Died { .. })) {
            break;
        }
    }
    assert_eq!(s.view().dead, Some(60));
    s.run(NONE, 10);
    s.step(RESTART);
    assert_eq!(
        s.events,
        vec![
            GameEvent::Restarted(P1),
            GameEvent::Respawned {
                player: P1,
                pos: spawn
            }
        ]
    );
    let v = s.view();
    assert_eq!((v.dead, v.deaths, v.checkpoint), (None, 0, None));
    // Alive: it moves, and no late respawn comes.
    for _ in 0..80 {
        s.step(LEFT);
        assert!(!s.saw(|e| matches!(e, GameEvent::Respawned { .. })));
    }
    assert!(s.pos().x < spawn.x);
}

#[test]
fn deaths_after_finishing_do_not_count() {
    // Goal at 10, spikes at 14: finish, then die.
    let lv = room(
        &[(12, 14, "^")],
        vec![
            ent(EntityKind::PlayerSpawn, 3, 12),
            ent(EntityKind::Goal, 10, 12),
        ],
    );
    let mut s = Sim::new(&lv);
    let mut died = false;
    for _ in 0..400 {
        s.step(RIGHT);
        if s.saw(|e| matches!(e, GameEvent::Died { .. })) {
            died = true;
            break;
        }
    }
    assert!(died);
    let v = s.view();
    assert!(v.won);
    assert_eq!(v.deaths, 0);
    s.sit_out_death(NONE, standing(3));
    assert!(s.view().won, "still finished");
}

/// A game with a bit of everything about runs, one spawn at column 3:
/// players 1 and 2 ran right past a coin (column 6, one of them took it), a
/// checkpoint (10) and the goal (16: finished) into spikes (20: dead, a
/// death not counted after finishing); player 3 pressed up each tick (its
/// timer runs, it stands); player 4 is idle. A second coin at column 30.
fn busy_game() -> Game {
    let lv = room(
        &[(12, 20, "^")],
        vec![
            ent(EntityKind::PlayerSpawn, 3, 12),
            ent(EntityKind::Coin, 6, 12),
            ent(EntityKind::Checkpoint, 10, 12),
            ent(EntityKind::Goal, 16, 12),
            ent(EntityKind::Coin, 30, 12),
        ],
    );
    let mut g = Game::from_level(&lv).unwrap();
    for id in 1..=4 {
        g.add_player(PlayerId(id)).unwrap();
    }
    g.step(&[]);
    let p2_died = |ev: &[GameEvent]| {
        ev.iter()
            .any(|e| matches!(e, GameEvent::Died { player, .. } if *player == P2))
    };
    for _ in 0..400 {
        let ev = g.step(&[(P1, RIGHT), (P2, RIGHT), (PlayerId(3), UP)]);
        if p2_died(ev) {
            break;
        }
    }
    g.step(&[(PlayerId(3), UP)]);
    g
}

#[test]
fn busy_game_is_what_the_tests_want() {
    let g = busy_game();
    let v: Vec<PlayerView> = g.player_views().collect();
    for p in &v[..2] {
        assert!(p.won && p.dead.is_some() && p.deaths == 0, "{p:?}");
    }
    assert_eq!(v[1].dead, Some(23));
    assert_eq!(v[0].coins + v[1].coins, 1, "one coin taken");
    assert!(
        v[2].run_started && !v[2].won && v[2].run_ticks > 50,
        "{:?}",
        v[2]
    );
    assert!(!v[3].run_started);
}

/// `snap` with player `id`'s run record changed by `f`.
fn with_run(snap: &StateSnapshot, id: u32, f: impl Fn(&mut EntityState)) -> StateSnapshot {
    let mut s = snap.clone();
    let e = s
        .entities
        .iter_mut()
        .find(|e| e.id == RUN_ID_BASE + id)
        .expect("a run record");
    f(e);
    s
}

#[test]
fn deaths_coins_timer_finish_and_death_are_in_the_state_hash() {
    let g = busy_game();
    let snap = g.snapshot();
    let h = g.state_hash();
    let coin = ENTITY_ID_BASE + 4;
    let mut changes: Vec<(&str, StateSnapshot)> = vec![
        ("deaths", with_run(&snap, 3, |e| e.pos.y += 1)),
        ("timer", with_run(&snap, 3, |e| e.pos.x += 1)),
        (
            "timer started",
            with_run(&snap, 4, |e| {
                e.flags |= run_flags::STARTED;
                e.vel.x = 1;
            }),
        ),
        ("finishing order", with_run(&snap, 1, |e| e.aux += 5)),
    ];
    // Finished: the player's won flag with its run's order.
    let mut fin = with_run(&snap, 3, |e| {
        e.aux = 9;
        e.vel.x = 0;
    });
    fin.entities.iter_mut().find(|e| e.id == 3).unwrap().flags |= player_flags::WON;
    changes.push(("finished", fin));
    // A coin taken by someone.
    let mut coins = snap.clone();
    let c = coins.entities.iter_mut().find(|e| e.id == coin).unwrap();
    assert_eq!(c.kind, kind::COIN);
    c.flags = 1;
    c.aux = 4;
    changes.push(("coins", coins));
    // Dead for one tick more.
    let mut dead = snap.clone();
    let p = dead.entities.iter_mut().find(|e| e.id == 2).unwrap();
    assert_ne!(p.flags & player_flags::DEAD, 0);
    p.aux -= 1;
    changes.push(("respawn countdown", dead));
    for (what, s) in changes {
        let mut other = g.clone();
        other.restore(&s).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_ne!(other.state_hash(), h, "{what} is not in the hash");
        other.restore(&snap).unwrap();
        assert_eq!(other.state_hash(), h);
    }
}

#[test]
fn snapshots_carry_the_run_full_and_delta_and_a_restore_reproduces_it() {
    let g = busy_game();
    let snap = g.snapshot();
    // One run record per player, after every other entity.
    let runs: Vec<_> = snap
        .entities
        .iter()
        .filter(|e| e.kind == kind::RUN)
        .map(|e| e.id - RUN_ID_BASE)
        .collect();
    assert_eq!(runs, vec![1, 2, 3, 4]);
    assert!(snap
        .entities
        .iter()
        .rev()
        .take(4)
        .all(|e| e.kind == kind::RUN));

    // Full.
    let mut bytes = Vec::new();
    encode_delta(None, &snap, &mut bytes).unwrap();
    let full = decode_delta(None, &bytes).unwrap();
    assert_eq!(full, snap);
    // Delta, 7 ticks on: player 3's running timer is extrapolated (free);
    // player 2's countdown and player 1's respawn are written.
    let mut later = g.clone();
    for _ in 0..7 {
        later.step(&[(PlayerId(3), UP)]);
    }
    let cur = later.snapshot();
    bytes.clear();
    encode_delta(Some(&snap), &cur, &mut bytes).unwrap();
    let got = decode_delta(Some(&snap), &bytes).unwrap();
    assert_eq!(got, cur);

    // Restored into a fresh game of the same level (other players), the
    // views and the future are the same.
    let lv_game = |s: &StateSnapshot| {
        let mut fresh = busy_game();
        fresh.remove_player(PlayerId(4));
        fresh.add_player(PlayerId(9)).unwrap();
        fresh.restore(s).unwrap();
        fresh
    };
    let mut r = lv_game(&got);
    assert_eq!(r.state_hash(), later.state_hash());
    let views = |g: &Game| g.player_views().map(strip).collect::<Vec<_>>();
    assert_eq!(views(&r), views(&later));
    let mut l = later.clone();
    for t in 0..120 {
        let i = [
            (P1, if t < 60 { LEFT } else { RESTART }),
            (PlayerId(3), RIGHT),
        ];
        assert_eq!(r.step(&i), l.step(&i), "tick {t}");
        assert_eq!(r.state_hash(), l.state_hash(), "tick {t}");
        assert_eq!(views(&r), views(&l), "tick {t}");
    }
    assert_eq!(r.results(), l.results());

    // A running timer costs nothing in a delta: 30 ticks on everyone is
    // back on its feet and at rest; two snapshots 5 ticks apart differ
    // only in player 3's running timer, which the delta extrapolates.
    let mut idle = g.clone();
    for _ in 0..30 {
        idle.step(&[]);
    }
    let a = idle.snapshot();
    for _ in 0..5 {
        idle.step(&[]);
    }
    let b = idle.snapshot();
    let v3 = idle.player(PlayerId(3)).unwrap();
    assert!(v3.run_started && !v3.won);
    assert_ne!(a.get(RUN_ID_BASE + 3), b.get(RUN_ID_BASE + 3));
    bytes.clear();
    encode_delta(Some(&a), &b, &mut bytes).unwrap();
    let leb = |v: u64| (64 - v.max(1).leading_zeros() as usize).div_ceil(7);
    assert_eq!(
        bytes.len(),
        1 + leb(b.tick) + leb(5) + 1,
        "header, tick, back and a zero count: {bytes:?}"
    );
    assert_eq!(bytes.last(), Some(&0));
    assert_eq!(decode_delta(Some(&a), &bytes).unwrap(), b);
}

/// A view without the world's per-tick scratch (`sides`, empty after a
/// restore).
fn strip(mut v: PlayerView) -> PlayerView {
    v.sides = Default::default();
    v
}

#[test]
fn bad_run_records_are_refused_and_change_nothing() {
    let mut g = busy_game();
    let good = g.snapshot();
    let h = g.state_hash();
    type Corrupt = Box<dyn Fn(&mut StateSnapshot)>;
    let run = |id: u32| {
        move |s: &StateSnapshot| {
            s.entities
                .iter()
                .position(|e| e.id == RUN_ID_BASE + id)
                .unwrap()
        }
    };
    let cases: Vec<(&str, Corrupt)> = vec![
        (
            "missing run record",
            Box::new(move |s| {
                let i = run(3)(s);
                s.entities.remove(i);
            }),
        ),
        (
            "run record of no player",
            Box::new(|s| {
                let mut e = s.entities.last().copied().unwrap();
                e.id = RUN_ID_BASE + 77;
                s.entities.push(e);
            }),
        ),
        (
            "run record kind",
            Box::new(move |s| {
                let i = run(3)(s);
                s.entities[i].kind = kind::PLAYER;
            }),
        ),
        (
            "negative ticks",
            Box::new(move |s| {
                let i = run(3)(s);
                s.entities[i].pos.x = -5;
            }),
        ),
        (
            "timer velocity",
            Box::new(move |s| {
                let i = run(3)(s);
                s.entities[i].vel.x = 2;
            }),
        ),
        (
            "finished without the won flag",
            Box::new(move |s| {
                let i = run(3)(s);
                s.entities[i].aux = 3;
                s.entities[i].vel.x = 0;
            }),
        ),
        (
            "won flag without a finish",
            Box::new(|s| {
                let p = s.entities.iter_mut().find(|e| e.id == 3).unwrap();
                p.flags |= player_flags::WON;
            }),
        ),
        (
            "dead longer than the delay",
            Box::new(|s| {
                let p = s.entities.iter_mut().find(|e| e.id == 2).unwrap();
                p.aux = 25;
            }),
        ),
        (
            "dead with no countdown",
            Box::new(|s| {
                let p = s.entities.iter_mut().find(|e| e.id == 2).unwrap();
                p.aux = 0;
            }),
        ),
    ];
    for (what, f) in cases {
        let mut s = good.clone();
        f(&mut s);
        assert!(g.restore(&s).is_err(), "{what} accepted");
        assert_eq!(g.state_hash(), h, "{what} changed the state");
    }
    g.restore(&good).unwrap();
    assert_eq!(g.state_hash(), h);
}

/// Inputs for a small race on the default level: three players running
/// right, jumping on a schedule, one of them restarting once.
fn race_inputs(tick: u64) -> Vec<(PlayerId, Buttons)> {
    (1..=3u32)
        .map(|id| {
            let t = tick + id as u64 * 7;
            let jump = if t % 50 < 20 { Buttons::JUMP } else { 0 };
            let restart = if id == 2 && tick == 300 {
                Buttons::RESTART
            } else {
                0
            };
            (PlayerId(id), Buttons(Buttons::RIGHT | jump | restart))
        })
        .collect()
}

#[test]
fn a_recorded_match_replays_to_the_same_results() {
    let lv = ledge_levels::default_level();
    let play = |record: &mut Vec<Vec<(PlayerId, Buttons)>>,
                replay: Option<&[Vec<(PlayerId, Buttons)>]>| {
        let mut g = Game::from_level(&lv).unwrap();
        for id in 1..=3 {
            g.add_player(PlayerId(id)).unwrap();
        }
        let mut hashes = Vec::new();
        let mut deaths = 0;
        for t in 0..3000u64 {
            let i = match replay {
                Some(r) => r[t as usize].clone(),
                None => race_inputs(t),
            };
            deaths += g
                .step(&i)
                .iter()
                .filter(|e| matches!(e, GameEvent::Died { .. }))
                .count();
            record.push(i);
            hashes.push(g.state_hash());
        }
        let table: Vec<_> = g
            .player_views()
            .map(|p| (p.id, p.place, p.run_ticks, p.deaths, p.coins))
            .collect();
        (hashes, table, deaths)
    };
    let mut rec = Vec::new();
    let (h1, t1, d1) = play(&mut rec, None);
    let mut again = Vec::new();
    let (h2, t2, d2) = play(&mut again, Some(&rec));
    assert_eq!(h1, h2);
    assert_eq!(t1, t2);
    assert_eq!(d1, d2);
    assert!(d1 > 0, "the run had deaths: {t1:?}");
}
