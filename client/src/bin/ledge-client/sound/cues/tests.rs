//! Tests of the sound cues ([`super::Cues`]): each from synthetic frames,
//! then from real games: a run into spikes, a coin, and the same runs with
//! the game rolled back and replayed every frame (as the predictor does),
//! which must cue exactly the same.

use glam::IVec2;
use ledge_shared::game::{EntityType, EntityView, Game, GameConfig, GameEvent, PlayerView};
use ledge_shared::input::Buttons;
use ledge_shared::level::{EntityDef, EntityKind, Level};
use ledge_shared::protocol::PlayerId;
use ledge_shared::tilemap::{Tile, Tilemap};
use ledge_shared::world::Sides;

use super::{Cues, REPEAT_TICKS};
use crate::sound::audio::Effect;

const P1: PlayerId = PlayerId(1);
/// One tile, units.
const T: i32 = 16 * 256;
const JUMP_SPEED: i32 = 1280;

fn standing() -> PlayerView {
    PlayerView {
        id: P1,
        pos: IVec2::new(100 * 256, 200 * 256),
        vel: IVec2::ZERO,
        half: IVec2::new(6 * 256, 8 * 256),
        grounded: true,
        facing_left: false,
        coins: 0,
        won: false,
        checkpoint: None,
        deaths: 0,
        run_started: true,
        run_ticks: 100,
        place: None,
        dead: None,
        sides: Sides::default(),
    }
}

fn walker(id: u32, pos: IVec2, active: bool) -> EntityView {
    EntityView {
        id,
        ty: EntityType::Walker,
        pos,
        half: IVec2::new(7 * 256, 7 * 256),
        active,
        one_way: false,
        facing_left: false,
    }
}

/// Cues that saw `before`, then what they say for `after` one tick later.
fn cue(before: PlayerView, after: PlayerView) -> Vec<Effect> {
    cue_with(before, &[], after, &[])
}

fn cue_with(
    before: PlayerView,
    before_entities: &[EntityView],
    after: PlayerView,
    after_entities: &[EntityView],
) -> Vec<Effect> {
    let mut cues = Cues::default();
    assert_eq!(cues.update(1000, Some(&before), before_entities), []);
    cues.update(1001, Some(&after), after_entities)
}

#[test]
fn each_cue_from_a_difference() {
    let s = standing();
    assert_eq!(cue(s, s), [], "nothing changed");
    assert_eq!(cue(s, PlayerView { coins: 1, ..s }), [Effect::Coin]);
    // Dying: the death counter ticks up and the body is suspended.
    let dead = PlayerView {
        deaths: 1,
        dead: Some(24),
        ..s
    };
    assert_eq!(cue(s, dead), [Effect::Hurt]);
    assert_eq!(
        cue(
            dead,
            PlayerView {
                dead: Some(23),
                ..dead
            }
        ),
        []
    );
    // Back at the checkpoint, far away, grounded: a respawn, no landing.
    let back = PlayerView {
        pos: s.pos - IVec2::new(300 * 256, 0),
        dead: None,
        ..dead
    };
    let falling_dead = PlayerView {
        grounded: false,
        vel: IVec2::new(0, 500),
        dead: Some(1),
        ..dead
    };
    assert_eq!(cue(falling_dead, back), [Effect::Respawn]);
    // No respawn delay: died and put back in the same tick.
    assert_eq!(
        cue(s, PlayerView { deaths: 1, ..back }),
        [Effect::Hurt, Effect::Respawn]
    );
    // A death after finishing is not counted, but still heard.
    let won = PlayerView {
        won: true,
        place: Some(1),
        ..s
    };
    assert_eq!(
        cue(
            won,
            PlayerView {
                dead: Some(24),
                ..won
            }
        ),
        [Effect::Hurt]
    );

    // Landing after a fall.
    let falling = PlayerView {
        grounded: false,
        vel: IVec2::new(0, 900),
        ..s
    };
    assert_eq!(cue(falling, s), [Effect::Land]);
    // Stepping down a bump (barely falling) is not a landing.
    let stepping = PlayerView {
        grounded: false,
        vel: IVec2::new(300, 100),
        ..s
    };
    assert_eq!(cue(stepping, s), []);

    // A jump off the ground (gravity already applied to the take-off).
    let jumped = PlayerView {
        grounded: false,
        vel: IVec2::new(0, -JUMP_SPEED + 40),
        pos: s.pos - IVec2::new(0, 5 * 256),
        ..s
    };
    assert_eq!(cue(s, jumped), [Effect::Jump]);
    // Rising on: no second jump; releasing jump early (slower) neither.
    let higher = PlayerView {
        vel: IVec2::new(0, -JUMP_SPEED + 80),
        ..jumped
    };
    assert_eq!(cue(jumped, higher), []);
    assert_eq!(
        cue(
            jumped,
            PlayerView {
                vel: IVec2::new(0, -300),
                ..jumped
            }
        ),
        []
    );
    // A coyote jump: from falling to going up.
    assert_eq!(
        cue(
            PlayerView {
                grounded: false,
                vel: IVec2::new(0, 200),
                ..s
            },
            jumped
        ),
        [Effect::Jump]
    );
    // A springboard's launch: stronger than any jump.
    let launched = PlayerView {
        grounded: false,
        vel: IVec2::new(0, -2400),
        ..s
    };
    assert_eq!(cue(s, launched), [Effect::Spring]);
    // A weak springboard right under us is still a springboard.
    let spring = EntityView {
        id: 7,
        ty: EntityType::Springboard,
        pos: s.pos + IVec2::new(0, 16 * 256),
        half: IVec2::new(8 * 256, 8 * 256),
        active: true,
        one_way: false,
        facing_left: false,
    };
    assert_eq!(cue_with(s, &[spring], jumped, &[spring]), [Effect::Spring]);

    // A stomp: falling onto a walker next to us, which is then defeated,
    // and we bounce.
    let onto = PlayerView {
        grounded: false,
        vel: IVec2::new(0, 700),
        ..s
    };
    let bounced = PlayerView {
        vel: IVec2::new(0, -1024 + 40),
        ..onto
    };
    let under = s.pos + IVec2::new(0, 15 * 256);
    assert_eq!(
        cue_with(
            onto,
            &[walker(9, under, true)],
            bounced,
            &[walker(9, under, false)]
        ),
        [Effect::Stomp]
    );
    // A walker defeated far away (someone else's stomp): our bounce off
    // something else is a jump.
    let far = s.pos + IVec2::new(400 * 256, 0);
    assert_eq!(
        cue_with(
            onto,
            &[walker(9, far, true)],
            bounced,
            &[walker(9, far, false)]
        ),
        [Effect::Jump]
    );
    // An already defeated walker next to us is not a new stomp.
    assert_eq!(
        cue_with(
            onto,
            &[walker(9, under, false)],
            bounced,
            &[walker(9, under, false)]
        ),
        [Effect::Jump]
    );

    // Checkpoints: a new one is cued; back to the spawn (None) is not.
    let at_cp = PlayerView {
        checkpoint: Some(5),
        ..s
    };
    assert_eq!(cue(s, at_cp), [Effect::Checkpoint]);
    assert_eq!(
        cue(
            at_cp,
            PlayerView {
                checkpoint: Some(6),
                ..s
            }
        ),
        [Effect::Checkpoint]
    );
    // The goal: place becomes Some, once; moving up a place is quiet.
    let finished = PlayerView {
        won: true,
        place: Some(2),
        ..s
    };
    assert_eq!(cue(s, finished), [Effect::Goal]);
    assert_eq!(
        cue(
            finished,
            PlayerView {
                place: Some(1),
                ..finished
            }
        ),
        []
    );
}

#[test]
fn a_restart_plays_a_respawn_and_nothing_else() {
    let s = standing();
    // Mid-air, 3 deaths, 4 coins, a checkpoint, finished.
    let before = PlayerView {
        pos: s.pos + IVec2::new(500 * 256, -40 * 256),
        vel: IVec2::new(300, 600),
        grounded: false,
        coins: 4,
        deaths: 3,
        checkpoint: Some(8),
        run_ticks: 1234,
        place: Some(1),
        won: true,
        ..s
    };
    // Back at the spawn, on the ground, everything cleared.
    let fresh = PlayerView {
        run_started: false,
        run_ticks: 0,
        ..s
    };
    assert_eq!(cue(before, fresh), [Effect::Respawn]);
    // A restart before any death or coin (only the timer resets).
    let running = PlayerView {
        run_ticks: 300,
        pos: s.pos + IVec2::new(100 * 256, 0),
        ..s
    };
    assert_eq!(cue(running, fresh), [Effect::Respawn]);
    // While dead.
    let dead = PlayerView {
        deaths: 1,
        dead: Some(10),
        ..running
    };
    assert_eq!(cue(dead, fresh), [Effect::Respawn]);
    // The new run's first coin and death are heard again.
    let mut cues = Cues::default();
    let coin = PlayerView { coins: 1, ..s };
    cues.update(10, Some(&s), &[]);
    assert_eq!(cues.update(11, Some(&coin), &[]), [Effect::Coin]);
    assert_eq!(cues.update(12, Some(&fresh), &[]), [Effect::Respawn]);
    let coin_again = PlayerView {
        coins: 1,
        run_ticks: 3,
        ..s
    };
    assert_eq!(cues.update(13, Some(&coin_again), &[]), [Effect::Coin]);
}

#[test]
fn a_change_taken_back_and_made_again_is_heard_once() {
    // A predicted coin, un-picked by a snapshot, picked again by the replay.
    let s = standing();
    let coin = PlayerView { coins: 1, ..s };
    let mut cues = Cues::default();
    let mut heard = Vec::new();
    for (tick, v) in [(1, s), (2, coin), (3, s), (4, coin), (5, coin)] {
        heard.extend(cues.update(tick, Some(&v), &[]));
    }
    assert_eq!(heard, [Effect::Coin]);
    // Long after, the same count again is a new coin (another was
    // really lost and a second one taken).
    let later = 5 + REPEAT_TICKS;
    assert_eq!(cues.update(later, Some(&s), &[]), []);
    assert_eq!(cues.update(later + 1, Some(&coin), &[]), [Effect::Coin]);
    // A death predicted, denied, then confirmed.
    let dead = PlayerView {
        deaths: 1,
        dead: Some(24),
        ..s
    };
    let mut cues = Cues::default();
    let mut heard = Vec::new();
    for (tick, v) in [(1, s), (2, dead), (3, s), (4, dead)] {
        heard.extend(cues.update(tick, Some(&v), &[]));
    }
    assert_eq!(heard, [Effect::Hurt]);
}

#[test]
fn nothing_when_first_seen_or_gone() {
    let mut cues = Cues::default();
    let rich = PlayerView {
        coins: 9,
        deaths: 4,
        checkpoint: Some(3),
        place: Some(1),
        ..standing()
    };
    assert_eq!(cues.update(1, Some(&rich), &[]), [], "joined mid-run");
    assert_eq!(cues.update(2, None, &[]), []);
    assert_eq!(
        cues.update(3, Some(&standing()), &[]),
        [],
        "back: first seen"
    );
}

// ---- real games ----

/// A room 40 x 14 tiles, floor top at row 13, with `patches` (row, column,
/// tile) and `entities` (kind, column, row).
fn room(patches: &[(usize, usize, Tile)], entities: &[(EntityKind, i32, i32)]) -> Level {
    let (w, h) = (40usize, 14usize);
    let mut tiles = vec![Tile::Empty; w * h];
    for r in 0..h {
        for c in 0..w {
            if r == 0 || r == h - 1 || c == 0 || c == w - 1 {
                tiles[r * w + c] = Tile::Solid;
            }
        }
    }
    for &(r, c, t) in patches {
        tiles[r * w + c] = t;
    }
    Level {
        name: "cues".into(),
        tilemap: Tilemap::new(IVec2::ZERO, T, w as u32, h as u32, tiles).unwrap(),
        entities: entities
            .iter()
            .map(|(kind, c, r)| EntityDef {
                kind: kind.clone(),
                pos: IVec2::new(c * T + T / 2, r * T + T / 2),
                size: IVec2::splat(T),
            })
            .collect(),
        player: Default::default(),
    }
}

/// Effects with the game tick they were cued at.
type Heard = Vec<(u64, Effect)>;

/// Runs `buttons(tick)` for `ticks` ticks, observing after each; with
/// `rollback`, every tick also restores the game to 6 ticks ago and
/// replays them (what a correction-free reconciliation does) before
/// observing. Returns the cues with their ticks, and the game's events.
fn run(
    level: &Level,
    ticks: u64,
    buttons: impl Fn(u64) -> Buttons,
    rollback: bool,
) -> (Heard, Vec<(u64, GameEvent)>) {
    let mut game = Game::with_config(level, GameConfig::default()).unwrap();
    game.add_player(P1).unwrap();
    let mut cues = Cues::new(&game.config().player);
    let mut history = std::collections::VecDeque::new();
    let (mut heard, mut events) = (Vec::new(), Vec::new());
    for t in 0..ticks {
        history.push_back((game.snapshot(), t));
        if history.len() > 6 {
            history.pop_front();
        }
        let stepped = game.step(&[(P1, buttons(t))]).to_vec();
        events.extend(stepped.into_iter().map(|e| (t + 1, e)));
        if rollback {
            let (snap, from) = history.front().unwrap().clone();
            let want = game.state_hash();
            game.restore(&snap).unwrap();
            for r in from..=t {
                game.step(&[(P1, buttons(r))]);
            }
            assert_eq!(game.state_hash(), want, "the replay is exact");
        }
        heard.extend(
            cues.observe(&game, P1)
                .into_iter()
                .map(|e| (game.tick(), e)),
        );
    }
    (heard, events)
}

fn count(heard: &[(u64, Effect)], effect: Effect) -> usize {
    heard.iter().filter(|(_, e)| *e == effect).count()
}

#[test]
fn a_run_into_spikes_is_one_hurt_then_one_respawn_after_the_delay() {
    // Spikes at column 20, a checkpoint at 10, the spawn at 3.
    let level = room(
        &[(12, 20, Tile::Hazard)],
        &[
            (EntityKind::PlayerSpawn, 3, 12),
            (EntityKind::Checkpoint, 10, 12),
        ],
    );
    let delay = u64::from(GameConfig::default().player.respawn_delay_ticks);
    // Right until the death, then nothing (a respawned player stands).
    let (_, events) = run(&level, 400, |_| Buttons(Buttons::RIGHT), false);
    let died = events
        .iter()
        .find(|(_, e)| matches!(e, GameEvent::Died { .. }))
        .expect("ran into the spikes")
        .0;
    let buttons = move |t: u64| {
        if t < died {
            Buttons(Buttons::RIGHT)
        } else {
            Buttons::NONE
        }
    };
    for rollback in [false, true] {
        let (heard, events) = run(&level, died + delay + 60, buttons, rollback);
        let respawned = events
            .iter()
            .find(|(_, e)| matches!(e, GameEvent::Respawned { .. }))
            .expect("respawned")
            .0;
        assert_eq!(respawned, died + delay, "after the delay");
        assert_eq!(count(&heard, Effect::Hurt), 1, "{heard:?}");
        assert_eq!(count(&heard, Effect::Respawn), 1, "{heard:?}");
        assert_eq!(count(&heard, Effect::Checkpoint), 1, "{heard:?}");
        assert_eq!(count(&heard, Effect::Coin), 0, "{heard:?}");
        assert_eq!(count(&heard, Effect::Jump), 0, "{heard:?}");
        let at = |effect| heard.iter().find(|(_, e)| *e == effect).unwrap().0;
        assert_eq!(at(Effect::Hurt), died, "rollback {rollback}");
        assert_eq!(at(Effect::Respawn), died + delay, "rollback {rollback}");
        // Nothing but an optional first landing besides.
        assert!(
            heard.iter().all(|(_, e)| matches!(
                e,
                Effect::Hurt | Effect::Respawn | Effect::Checkpoint | Effect::Land
            )),
            "{heard:?}"
        );
        assert!(count(&heard, Effect::Land) <= 1, "{heard:?}");
    }
}

#[test]
fn a_coin_is_one_coin_and_a_jump_is_one_jump() {
    let level = room(
        &[],
        &[(EntityKind::PlayerSpawn, 3, 12), (EntityKind::Coin, 8, 12)],
    );
    // Run right over the coin, then jump once (at tick 100) and land.
    let buttons = |t: u64| match t {
        0..=79 => Buttons(Buttons::RIGHT),
        100..=110 => Buttons(Buttons::JUMP),
        _ => Buttons::NONE,
    };
    for rollback in [false, true] {
        let (heard, events) = run(&level, 220, buttons, rollback);
        let picked = events
            .iter()
            .filter(|(_, e)| matches!(e, GameEvent::CoinPicked { .. }))
            .count();
        assert_eq!(picked, 1);
        assert_eq!(count(&heard, Effect::Coin), 1, "{heard:?}");
        let jumped = events
            .iter()
            .find(|(_, e)| matches!(e, GameEvent::Jumped(_)))
            .expect("jumped")
            .0;
        assert_eq!(
            heard
                .iter()
                .filter(|(_, e)| *e == Effect::Jump)
                .map(|(t, _)| *t)
                .collect::<Vec<_>>(),
            [jumped]
        );
        // Landed once after the jump.
        let lands: Vec<u64> = heard
            .iter()
            .filter(|(t, e)| *e == Effect::Land && *t > jumped)
            .map(|(t, _)| *t)
            .collect();
        assert_eq!(lands.len(), 1, "{heard:?}");
        assert_eq!(count(&heard, Effect::Hurt), 0);
        assert_eq!(count(&heard, Effect::Spring), 0);
    }
}
