//! The viewer on a recorded match of the default level: speeds, pauses,
//! seeks, whom it follows, a run's opening, the end and a failure.

use super::*;
use crate::bot::brain::drill;
use ledge_shared::game::GameConfig;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::LevelOffer;
use ledge_shared::replay::{Event, ReplayHeader, ReplayRecorder};

fn header() -> ReplayHeader {
    ReplayHeader::for_match(
        "room",
        ("default", "Default", LevelOffer::default()),
        GameConfig::default(),
        60,
    )
}

/// A match of `ticks` ticks: players 1 and 2 from the start, 3 from tick
/// 300, 2 leaving at 900; each drilling from its own offset. Returns the
/// game too, and player 1's position entering each tick.
fn record(ticks: u64) -> (Replay, Game, Vec<glam::IVec2>) {
    let level = ledge_levels::default_level();
    let mut game = Game::from_level(&level).unwrap();
    let mut recorder = ReplayRecorder::new(header(), &game);
    let mut p1 = Vec::new();
    for _ in 0..ticks {
        let tick = game.tick();
        for (at, id) in [(0, 1), (0, 2), (300, 3)] {
            if tick == at {
                game.add_player(PlayerId(id)).unwrap();
                recorder.join(PlayerId(id), &format!("p{id}"));
            }
        }
        if tick == 900 && game.remove_player(PlayerId(2)) {
            recorder.leave(PlayerId(2));
        }
        p1.push(game.player(PlayerId(1)).unwrap().pos);
        let inputs: Vec<(PlayerId, Buttons)> = game
            .players()
            .map(|(id, _)| (id, drill(tick + 50 * u64::from(id.0))))
            .collect();
        game.step(&inputs);
        recorder.step(&game, &inputs);
    }
    p1.push(game.player(PlayerId(1)).unwrap().pos);
    (recorder.replay(&game), game, p1)
}

fn viewer(replay: Replay) -> ReplayViewer {
    ReplayViewer::new(&ledge_levels::default_level(), replay).unwrap()
}

fn p1(v: &ReplayViewer) -> glam::IVec2 {
    v.game().player(PlayerId(1)).unwrap().pos
}

#[test]
fn it_plays_as_many_ticks_as_its_speed_makes_due() {
    let (replay, _, _) = record(1200);
    let mut v = viewer(replay);
    assert_eq!((v.tick(), v.speed(), v.paused()), (0, 1.0, false));
    assert_eq!(v.advance(1.0, u64::MAX).unwrap(), 60);
    v.slower();
    v.slower();
    assert_eq!(v.speed(), 0.25);
    v.slower();
    assert_eq!(v.speed(), 0.25, "the slowest stays");
    assert_eq!(v.advance(1.0, u64::MAX).unwrap(), 15);
    // Half a tick due: drawn half way between the last two ticks.
    assert_eq!(v.advance(0.5 / 15.0, u64::MAX).unwrap(), 0);
    assert!((v.alpha() - 0.5).abs() < 1e-4, "{}", v.alpha());
    for _ in 0..10 {
        v.faster();
    }
    assert_eq!(v.speed(), 4.0);
    assert_eq!(v.advance(0.5, u64::MAX).unwrap(), 120);
    // Paused: nothing plays, whatever the time.
    v.toggle_pause().unwrap();
    assert_eq!(v.advance(3.0, u64::MAX).unwrap(), 0);
    v.toggle_pause().unwrap();
    // A long frame steps at most MAX_DUE_TICKS; a cap stops earlier and
    // draws the tick reached.
    assert_eq!(v.advance(60.0, u64::MAX).unwrap(), MAX_DUE_TICKS as u64);
    assert_eq!(v.advance(1.0, 7).unwrap(), 7);
    assert_eq!(v.alpha(), 1.0);
    v.set_speed(0.6);
    assert_eq!(v.speed(), 0.5);
}

#[test]
fn seeking_lands_where_the_game_was() {
    let (replay, game, pos) = record(1200);
    let mut v = viewer(replay);
    for target in [700, 30, 1199, 299, 0, 1200, 650] {
        v.seek(target).unwrap();
        v.finish_seek().unwrap();
        assert_eq!(v.tick(), target);
        assert_eq!(p1(&v), pos[target as usize], "at {target}");
        // Nothing blended across the seek.
        assert_eq!(
            v.view().local.unwrap().pos,
            crate::view::px2(pos[target as usize])
        );
    }
    v.seek(100).unwrap();
    v.finish_seek().unwrap();
    v.skip(5.0).unwrap();
    v.finish_seek().unwrap();
    assert_eq!(v.tick(), 400);
    v.skip(-10.0).unwrap();
    v.finish_seek().unwrap();
    assert_eq!(v.tick(), 0, "clamped to the start");
    v.seek_end().unwrap();
    v.finish_seek().unwrap();
    assert_eq!(v.tick(), 1200);
    assert!(v.at_end());
    assert_eq!(v.game().state_hash(), game.state_hash());
    assert_eq!(
        v.advance(1.0, u64::MAX).unwrap(),
        0,
        "nothing after the end"
    );
    // Space at the end plays it again from the start, paused or not.
    v.toggle_pause().unwrap();
    assert_eq!((v.tick(), v.paused()), (0, false));
    v.toggle_pause().unwrap();
    v.seek_end().unwrap();
    v.finish_seek().unwrap();
    assert!(v.paused());
    v.toggle_pause().unwrap();
    assert_eq!((v.tick(), v.paused()), (0, false));
}

#[test]
fn the_camera_follows_one_player_in_the_game_or_nobody() {
    let (replay, _, _) = record(1200);
    let mut v = viewer(replay);
    assert_eq!(v.followed(), Some(PlayerId(1)), "a match: its first player");
    assert_eq!(v.players(), vec![PlayerId(1), PlayerId(2)]);
    v.follow_next(true);
    assert_eq!(v.followed(), Some(PlayerId(2)));
    v.follow_next(true);
    assert_eq!(v.followed(), Some(PlayerId(1)), "wraps around");
    v.follow_next(false);
    assert_eq!(v.followed(), Some(PlayerId(2)));
    assert_eq!(v.name_of(PlayerId(2)), "p2");
    assert_eq!(v.name_of(PlayerId(9)), "player #9");
    assert_eq!(v.player_named("p3"), Some(PlayerId(3)));
    // Player 2 leaves at tick 900: the first player in the game is shown,
    // and 2 again when seeking back.
    v.seek(1000).unwrap();
    v.finish_seek().unwrap();
    assert_eq!(v.follow(), Follow::Player(PlayerId(2)));
    assert_eq!(v.followed(), Some(PlayerId(1)));
    assert_eq!(v.players(), vec![PlayerId(1), PlayerId(3)]);
    v.seek(500).unwrap();
    v.finish_seek().unwrap();
    assert_eq!(v.followed(), Some(PlayerId(2)));
    let view = v.view();
    assert_eq!(view.local.as_ref().unwrap().id, PlayerId(2));
    assert_eq!(view.remotes.len(), 2);
    // A free camera follows nobody: everyone is drawn as the others are.
    v.set_follow(Follow::Free);
    assert_eq!(v.followed(), None);
    assert!(v.view().local.is_none());
    v.follow_next(true);
    assert_eq!(v.followed(), Some(PlayerId(1)));
}

#[test]
fn a_run_opens_at_its_start_following_the_runner() {
    // Player 3 joins at 300; its "run" from 320 to the end at 1400.
    let level = ledge_levels::default_level();
    let mut game = Game::from_level(&level).unwrap();
    let mut recorder = ReplayRecorder::new(header(), &game);
    for _ in 0..1400 {
        let tick = game.tick();
        if tick == 300 {
            game.add_player(PlayerId(3)).unwrap();
            recorder.join(PlayerId(3), "runner");
        }
        let inputs: Vec<_> = game.players().map(|(id, _)| (id, drill(tick))).collect();
        game.step(&inputs);
        recorder.step(&game, &inputs);
    }
    let run = recorder.run(&game, PlayerId(3), 320, 1080, 2).unwrap();
    assert_eq!(run.start_tick(), 0, "the keyframe before 320");
    let mut v = viewer(run);
    assert_eq!((v.tick(), v.home()), (320, 320));
    assert_eq!(v.followed(), Some(PlayerId(3)));
    assert_eq!(v.elapsed(), 320);
    assert_eq!(v.total(), 1400);
    v.seek(0).unwrap();
    v.finish_seek().unwrap();
    assert!(v.followed().is_none(), "nobody in the game yet");
    v.seek_home().unwrap();
    v.finish_seek().unwrap();
    assert_eq!(v.tick(), 320);
}

#[test]
fn a_replay_that_plays_differently_stops_where_it_fails() {
    let (mut replay, _, pos) = record(1200);
    // The server's 10th hash (tick 600) was another.
    let mut seen = 0;
    for e in &mut replay.events {
        if let Event::Hash(h) = e {
            seen += 1;
            if seen == 10 {
                *h ^= 1;
            }
        }
    }
    let mut v = viewer(replay);
    v.seek(590).unwrap();
    v.finish_seek().unwrap();
    let err = v.advance(1.0, u64::MAX).unwrap_err();
    assert!(
        matches!(err, ReplayError::Diverged { tick: 600, .. }),
        "{err}"
    );
    assert_eq!(v.failed_at(), Some(600));
    assert!(v.failure().is_some());
    assert!(v.at_end());
    // Never stepped past it, whatever is asked.
    assert_eq!(v.advance(1.0, u64::MAX).unwrap(), 0);
    v.seek_end().unwrap();
    v.finish_seek().unwrap();
    assert_eq!(v.tick(), 599, "the last tick before the failure");
    v.seek(100).unwrap();
    v.finish_seek().unwrap();
    assert_eq!(p1(&v), pos[100]);
    v.skip(100.0).unwrap();
    v.finish_seek().unwrap();
    assert_eq!(v.tick(), 599);
    assert_eq!(p1(&v), pos[599]);
}

/// Where a seek in one go lands: the tick and the state's hash.
fn one_go(replay: &Replay, tick: u64) -> (u64, u64) {
    let mut p = Playback::new(&ledge_levels::default_level(), replay.clone()).unwrap();
    p.seek(tick).unwrap();
    (p.tick(), p.game().state_hash())
}

fn landed(v: &ReplayViewer) -> (u64, u64) {
    (v.tick(), v.game().state_hash())
}

/// Frames until the seek under way is done, checking none steps more
/// than its budget and none plays; the frames.
fn frames_to_seek(v: &mut ReplayViewer) -> u32 {
    let mut frames = 0;
    while v.seeking().is_some() {
        let before = v.tick();
        assert_eq!(
            v.advance(1.0 / 60.0, u64::MAX).unwrap(),
            0,
            "nothing played"
        );
        let after = v.tick();
        assert!(
            after <= before + SEEK_TICKS_PER_FRAME,
            "{before} -> {after}"
        );
        if v.seeking().is_some() {
            assert_eq!(v.alpha(), 1.0, "drawn as reached");
        }
        frames += 1;
        assert!(frames < 1000);
    }
    frames
}

#[test]
fn a_long_seek_is_spread_over_frames_and_lands_as_one_in_one_go() {
    let (replay, game, _) = record(3000);
    let mut v = viewer(replay.clone());
    v.seek(2900).unwrap();
    assert_eq!(
        (v.seeking(), v.tick()),
        (Some(2900), 0),
        "nothing played yet"
    );
    let frames = frames_to_seek(&mut v);
    assert_eq!(frames, 5, "2900 ticks, 600 a frame");
    assert_eq!(landed(&v), one_go(&replay, 2900));
    // Played on from there as before.
    assert_eq!(v.advance(1.0, u64::MAX).unwrap(), 60);
    assert_eq!(landed(&v), one_go(&replay, 2960));
    // Back, then forward again: from the checkpoint at 2700, in a frame.
    v.seek(10).unwrap();
    assert_eq!(landed(&v), (0, one_go(&replay, 0).1), "the checkpoint at 0");
    assert_eq!(frames_to_seek(&mut v), 1);
    assert_eq!(landed(&v), one_go(&replay, 10));
    v.seek(2850).unwrap();
    assert_eq!(v.tick(), 2700, "the nearest checkpoint at once");
    assert_eq!(frames_to_seek(&mut v), 1);
    assert_eq!(landed(&v), one_go(&replay, 2850));
    v.seek_end().unwrap();
    frames_to_seek(&mut v);
    assert_eq!(landed(&v), (3000, game.state_hash()));
    assert!(v.at_end());
    // A skip under way counts from where it goes (a fresh viewer: no
    // checkpoints past the start yet).
    let mut v = viewer(replay.clone());
    v.skip(5.0).unwrap();
    v.skip(5.0).unwrap();
    assert_eq!(v.seeking(), Some(600));
    frames_to_seek(&mut v);
    assert_eq!(landed(&v), one_go(&replay, 600));
}

#[test]
fn a_seek_under_way_gives_way_to_a_newer_one() {
    let (replay, _, _) = record(3000);
    let mut v = viewer(replay.clone());
    v.seek(2900).unwrap();
    v.advance(1.0 / 60.0, u64::MAX).unwrap();
    assert_eq!(v.tick(), 600);
    // Further on: on from where it stands.
    v.seek(1000).unwrap();
    assert_eq!((v.seeking(), v.tick()), (Some(1000), 600));
    assert_eq!(frames_to_seek(&mut v), 1);
    assert_eq!(landed(&v), one_go(&replay, 1000));
    // Behind where it stands: from the checkpoint before.
    v.seek(2900).unwrap();
    v.advance(1.0 / 60.0, u64::MAX).unwrap();
    v.advance(1.0 / 60.0, u64::MAX).unwrap();
    assert_eq!(v.tick(), 2200);
    v.seek(1250).unwrap();
    assert_eq!(v.tick(), 1200);
    assert_eq!(frames_to_seek(&mut v), 1);
    assert_eq!(landed(&v), one_go(&replay, 1250));
}

#[test]
fn a_seek_across_a_failure_stops_where_it_fails() {
    let (mut replay, _, _) = record(1200);
    let mut seen = 0;
    for e in &mut replay.events {
        if let Event::Hash(h) = e {
            seen += 1;
            if seen == 15 {
                *h ^= 1;
            }
        }
    }
    let mut v = viewer(replay);
    v.seek(1100).unwrap();
    assert!(v.advance(1.0 / 60.0, u64::MAX).is_ok(), "up to 600");
    let err = v.advance(1.0 / 60.0, u64::MAX).unwrap_err();
    assert!(
        matches!(err, ReplayError::Diverged { tick: 900, .. }),
        "{err}"
    );
    assert_eq!((v.failed_at(), v.seeking()), (Some(900), None));
    v.seek_end().unwrap();
    frames_to_seek(&mut v);
    assert_eq!(v.tick(), 899, "the last tick before the failure");
}
