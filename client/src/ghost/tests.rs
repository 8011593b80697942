//! The builder on a recorded run of the default level (the runner bot,
//! with another player drilling beside it): exactly the ghost of playing
//! it in one go, in any budget; errors reported where they are found.

use std::sync::OnceLock;

use super::*;
use crate::bot::brain::{drill, Brain};
use crate::bot::runner::Runner;
use ledge_levels::{default_level, default_route};
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::protocol::LevelOffer;
use ledge_shared::replay::{Event, Replay, ReplayError, ReplayHeader, ReplayRecorder};

const ME: PlayerId = PlayerId(1);

/// The runner's finished run, and the same run cut 200 ticks before its
/// finish.
struct Recorded {
    run: Replay,
    unfinished: Replay,
}

fn recorded() -> &'static Recorded {
    static RECORDED: OnceLock<Recorded> = OnceLock::new();
    RECORDED.get_or_init(|| {
        let level = default_level();
        let mut game = Game::from_level(&level).unwrap();
        let header = ReplayHeader::for_match(
            "room",
            ("default", "Default", LevelOffer::default()),
            GameConfig::default(),
            60,
        );
        let mut recorder = ReplayRecorder::new(header, &game);
        game.add_player(ME).unwrap();
        recorder.join(ME, "ann");
        game.add_player(PlayerId(2)).unwrap();
        recorder.join(PlayerId(2), "bob");
        let mut runner = Runner::new(default_route());
        let mut cut = Vec::new();
        for _ in 0..60 * 60 {
            let b = runner.buttons(&game, ME);
            let inputs = [(ME, b), (PlayerId(2), drill(game.tick()))];
            game.step(&inputs);
            recorder.step(&game, &inputs);
            let p = game.player(ME).unwrap();
            cut.push((game.tick(), p.run_ticks));
            if p.won {
                let ticks = u64::from(p.run_ticks);
                let start = game.tick() - ticks;
                let run = recorder.run(&game, ME, start, ticks, 1).unwrap();
                let (at, _) = cut[cut.len() - 200];
                // Cut again at an earlier game: replay the run up to there.
                let unfinished = unfinished(&level, &run, at);
                return Recorded { run, unfinished };
            }
        }
        panic!("the runner never finished");
    })
}

/// `run` cut at game tick `at` (its events up to there, then the hash).
fn unfinished(level: &Level, run: &Replay, at: u64) -> Replay {
    let mut playing = Playback::new(level, run.clone()).unwrap();
    playing.seek(at).unwrap();
    let mut cut = run.clone();
    let mut ticks = run.start_tick();
    let mut events = Vec::new();
    for &e in &run.events {
        if let Event::Step(n) = e {
            let left = at - ticks;
            if left == 0 {
                break;
            }
            let n = u64::from(n).min(left);
            events.push(Event::Step(n as u32));
            ticks += n;
        } else {
            events.push(e);
        }
    }
    events.push(Event::Hash(playing.game().state_hash()));
    cut.events = events;
    cut
}

/// The recorded run as the server sends it: the record, or (`record:
/// false`) our own best.
pub(crate) fn recorded_run(record: bool) -> GhostRun {
    GhostRun {
        record,
        ..ghost_run(&recorded().run)
    }
}

/// [`recorded_run`] with one of its hashes changed half way.
pub(crate) fn diverging_run() -> GhostRun {
    let mut replay = recorded().run.clone();
    let hashes: Vec<usize> = (0..replay.events.len())
        .filter(|&i| matches!(replay.events[i], Event::Hash(_)))
        .collect();
    let Event::Hash(h) = &mut replay.events[hashes[hashes.len() / 2]] else {
        unreachable!()
    };
    *h ^= 1;
    ghost_run(&replay)
}

fn ghost_run(replay: &Replay) -> GhostRun {
    GhostRun {
        record: true,
        player: "ann".into(),
        millis: 12_345,
        replay: replay::encode(replay).unwrap(),
    }
}

/// The ghost as `from_run` played it before the builder (in one loop).
fn in_one_go(level: &Level, run: &GhostRun) -> Result<Ghost, GhostError> {
    let replay = replay::decode(&run.replay)?;
    let ReplayKind::Run { player, .. } = replay.header.kind else {
        return Err(GhostError::NotARun("a match's, not a run's"));
    };
    let mut playing = Playback::new(level, replay)?;
    let mut ghost = Ghost {
        record: run.record,
        player: run.player.clone(),
        millis: run.millis,
        track: Vec::new(),
        half: IVec2::ZERO,
        splits: Vec::new(),
    };
    let mut finished = false;
    while !finished && playing.step()? {
        let Some(view) = playing.game().player(player) else {
            continue;
        };
        if !view.run_started {
            continue;
        }
        let at = view.run_ticks as usize;
        if at + 1 < ghost.track.len() {
            ghost.track.clear();
            ghost.splits.clear();
        }
        ghost.track.resize(at + 1, view.pos);
        ghost.track[at] = view.pos;
        ghost.half = view.half;
        if let Some(c) = view.checkpoint {
            if !ghost.splits.iter().any(|&(id, _)| id == c) {
                ghost.splits.push((c, view.run_ticks));
            }
        }
        finished = view.won;
    }
    if !finished {
        return Err(GhostError::NotARun("one whose runner never finishes"));
    }
    Ok(ghost)
}

/// Builds `run` `budget` ticks per call, checking each call keeps to it;
/// the ghost (or the error) and the calls made.
fn build(run: &GhostRun, budget: u64) -> (Result<Ghost, GhostError>, u64) {
    let mut builder = GhostBuilder::new(&default_level(), run).unwrap();
    let mut calls = 0;
    while !builder.is_done() {
        calls += 1;
        let before = builder.stepped();
        match builder.build(budget) {
            Ok(n) => {
                assert!(n <= budget, "{n} ticks in a call of budget {budget}");
                assert_eq!(builder.stepped(), before + n);
            }
            Err(e) => return (Err(e), calls),
        }
    }
    (Ok(builder.finish().unwrap()), calls)
}

#[test]
fn the_builder_makes_the_ghost_of_one_go_in_any_budget() {
    let run = ghost_run(&recorded().run);
    let level = default_level();
    let expected = in_one_go(&level, &run).unwrap();
    assert!(expected.ticks() > 300, "{}", expected.ticks());
    assert!(!expected.splits.is_empty(), "the runner passes checkpoints");
    assert_eq!(Ghost::from_run(&level, &run).unwrap(), expected);
    let total = recorded().run.ticks();
    for budget in [1, 7, 300, GHOST_TICKS_PER_FRAME, u64::MAX] {
        let (ghost, calls) = build(&run, budget);
        assert_eq!(ghost.unwrap(), expected, "budget {budget}");
        assert!(calls >= total.min(u64::MAX / budget) / budget, "{calls}");
    }
    // Nothing more is stepped once done; not done, no ghost.
    let mut builder = GhostBuilder::new(&level, &run).unwrap();
    builder.build(10).unwrap();
    assert!(!builder.is_done());
    assert_eq!(builder.stepped(), 10);
    while !builder.is_done() {
        builder.build(100).unwrap();
    }
    assert_eq!(builder.build(100).unwrap(), 0);
    assert!(GhostBuilder::new(&level, &run).unwrap().finish().is_none());
}

#[test]
fn a_replay_that_diverges_midway_is_reported_by_the_call_that_finds_it() {
    let run = diverging_run();
    let expected = in_one_go(&default_level(), &run).unwrap_err();
    assert!(
        matches!(expected, GhostError::Replay(ReplayError::Diverged { .. })),
        "{expected}"
    );
    for budget in [1, 50, u64::MAX] {
        let (got, calls) = build(&run, budget);
        assert_eq!(got.unwrap_err(), expected, "budget {budget}");
        if budget == 1 {
            assert!(calls > 100, "found midway: {calls}");
        }
    }
    assert_eq!(
        Ghost::from_run(&default_level(), &run).unwrap_err(),
        expected
    );
}

#[test]
fn a_run_cut_short_or_damaged_is_refused() {
    let level = default_level();
    // The runner never finishes in it: found at its end.
    let run = ghost_run(&recorded().unfinished);
    let (got, calls) = build(&run, 64);
    assert_eq!(
        got.unwrap_err(),
        GhostError::NotARun("one whose runner never finishes")
    );
    assert!(calls > 2, "{calls}");
    assert_eq!(
        in_one_go(&level, &run).unwrap_err(),
        build(&run, 1).0.unwrap_err()
    );
    // A damaged file, or a match's: at once.
    let mut damaged = ghost_run(&recorded().run);
    let last = damaged.replay.len() - 1;
    damaged.replay[last] ^= 0x40;
    let e = GhostBuilder::new(&level, &damaged).unwrap_err();
    assert!(matches!(e, GhostError::Replay(_)), "{e}");
    assert_eq!(Ghost::from_run(&level, &damaged).unwrap_err(), e);
    let mut a_match = recorded().run.clone();
    a_match.header.kind = ReplayKind::Match;
    let e = GhostBuilder::new(&level, &ghost_run(&a_match)).unwrap_err();
    assert_eq!(e, GhostError::NotARun("a match's, not a run's"));
}
