//! Replays: a recorded game plays again to the same state hashes, from its
//! start or from a keyframe (a run cut out of a match), seeking both ways;
//! a damaged, truncated, oversized or newer file is refused with its
//! reason, and a replay that plays differently says from which tick.

use ledge_levels::default_level;
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{LevelOffer, PlayerId};
use ledge_shared::replay::{
    self, Event, Playback, Replay, ReplayError, ReplayHeader, ReplayKind, ReplayRecorder,
    FORMAT_VERSION, MAX_REPLAY_BYTES,
};

fn header() -> ReplayHeader {
    ReplayHeader::for_match(
        "room-1",
        ("default", "Default", LevelOffer::default()),
        GameConfig::default(),
        60,
    )
}

/// Each player's buttons at `tick`: a loop of runs and jumps, shifted per
/// player so their presses differ.
fn buttons(id: PlayerId, tick: u64) -> Buttons {
    let t = tick + 37 * u64::from(id.0);
    Buttons(match t % 200 {
        0..=59 => Buttons::RIGHT,
        60..=80 => Buttons::RIGHT | Buttons::JUMP,
        81..=120 => 0,
        121..=170 => Buttons::LEFT,
        171..=180 => Buttons::LEFT | Buttons::JUMP,
        _ => Buttons::JUMP,
    })
}

/// A game of `ticks` ticks with players joining (ticks 0, 30, 650) and one
/// leaving (900), recorded.
struct Played {
    game: Game,
    recorder: ReplayRecorder,
    /// The state hash entering each tick, and at the end.
    hashes: Vec<u64>,
}

fn play(ticks: u64) -> Played {
    let mut game = Game::from_level(&default_level()).unwrap();
    let mut recorder = ReplayRecorder::new(header(), &game);
    let mut hashes = vec![0; game.tick() as usize];
    let mut inputs = Vec::new();
    for _ in 0..ticks {
        let tick = game.tick();
        for (at, id) in [(0, 1), (30, 2), (650, 3)] {
            if tick == at {
                game.add_player(PlayerId(id)).unwrap();
                recorder.join(PlayerId(id), &format!("p{id}"));
            }
        }
        if tick == 900 && game.remove_player(PlayerId(2)) {
            recorder.leave(PlayerId(2));
        }
        // The state entering the tick (as a playback shows it: joins
        // and leaves between two ticks already applied).
        hashes.push(game.state_hash());
        inputs.clear();
        // Unordered, with a second entry for player 1 that does not count.
        for (id, _) in game.players().collect::<Vec<_>>().into_iter().rev() {
            inputs.push((id, buttons(id, tick)));
        }
        inputs.push((PlayerId(1), Buttons(Buttons::LEFT)));
        game.step(&inputs);
        recorder.step(&game, &inputs);
    }
    hashes.push(game.state_hash());
    Played {
        game,
        recorder,
        hashes,
    }
}

fn playback(replay: Replay) -> Playback {
    Playback::new(&default_level(), replay).unwrap()
}

#[test]
fn a_recorded_match_plays_again_to_every_hash_through_its_file() {
    let p = play(1500);
    let replay = p.recorder.replay(&p.game);
    assert_eq!(replay.ticks(), 1500);
    assert_eq!(replay.name_of(PlayerId(3)), Some("p3"));
    let hashes = replay
        .events
        .iter()
        .filter(|e| matches!(e, Event::Hash(_)))
        .count();
    assert_eq!(
        hashes,
        1500 / 60,
        "a hash every 60 ticks (the last one included)"
    );
    let bytes = replay::encode(&replay).unwrap();
    let read = replay::decode(&bytes).unwrap();
    assert_eq!(read, replay);
    let mut playing = playback(read);
    let mut t = playing.tick();
    while playing.step().unwrap() {
        t += 1;
        assert_eq!(
            playing.game().state_hash(),
            p.hashes[t as usize],
            "tick {t}"
        );
    }
    assert!(playing.at_end());
    assert_eq!(playing.tick(), p.game.tick());
    // Few bytes: a press or two a second per player, a hash a second.
    assert!(bytes.len() < 2_000, "{} bytes for 1500 ticks", bytes.len());
}

#[test]
fn seeking_back_and_forth_lands_on_the_recorded_state() {
    let p = play(1500);
    let mut playing = playback(p.recorder.replay(&p.game));
    for target in [1200, 10, 700, 699, 1500, 0, 333] {
        playing.seek(target).unwrap();
        assert_eq!(playing.tick(), target);
        assert_eq!(
            playing.game().state_hash(),
            p.hashes[target as usize],
            "after seeking to {target}"
        );
    }
    // Past the end: clamped to it.
    playing.seek(99_999).unwrap();
    assert_eq!(playing.tick(), 1500);
    assert!(playing.at_end());
}

#[test]
fn a_run_cut_from_the_match_starts_at_a_keyframe_and_ends_at_its_finish() {
    // Player 3 joins at tick 650; cut its "run" at tick 1400.
    let p = play(1400);
    let run = p
        .recorder
        .run(&p.game, PlayerId(3), 650, 750, 1)
        .expect("a keyframe before tick 650");
    assert_eq!(run.start_tick(), 600, "the keyframe before the start");
    assert_eq!(run.end_tick(), 1400);
    assert!(matches!(
        run.header.kind,
        ReplayKind::Run {
            player: PlayerId(3),
            ..
        }
    ));
    let mut playing = playback(replay::decode(&replay::encode(&run).unwrap()).unwrap());
    assert_eq!(playing.game().state_hash(), p.hashes[600]);
    playing.play_to_end().unwrap();
    assert_eq!(playing.game().state_hash(), p.game.state_hash());
    assert_eq!(
        playing.game().player(PlayerId(3)).unwrap().pos,
        p.game.player(PlayerId(3)).unwrap().pos
    );
    // Before the recording started there is no keyframe.
    let later = ReplayRecorder::new(header(), &p.game);
    assert!(later.run(&p.game, PlayerId(3), 650, 750, 1).is_none());
}

#[test]
fn a_replay_that_plays_differently_says_from_which_tick() {
    let p = play(400);
    let mut replay = p.recorder.replay(&p.game);
    // The server's hash at tick 180 was another.
    let mut seen = 0;
    for e in &mut replay.events {
        if let Event::Hash(h) = e {
            seen += 1;
            if seen == 3 {
                *h ^= 1;
            }
        }
    }
    let mut playing = playback(replay);
    let err = playing.play_to_end().unwrap_err();
    // Stepping on says the same again.
    assert_eq!(playing.step().unwrap_err(), err);
    match err {
        ReplayError::Diverged { tick, ours, theirs } => {
            assert_eq!(tick, 180);
            assert_eq!(ours, p.hashes[180]);
            assert_eq!(theirs, p.hashes[180] ^ 1);
        }
        e => panic!("{e}"),
    }
    // A button changed: the next hash tells.
    let mut replay = p.recorder.replay(&p.game);
    let i = replay
        .events
        .iter()
        .position(|e| matches!(e, Event::Press(..)))
        .unwrap();
    replay.events[i] = Event::Press(PlayerId(1), Buttons(Buttons::LEFT | Buttons::JUMP));
    let err = playback(replay).play_to_end().unwrap_err();
    assert!(
        matches!(err, ReplayError::Diverged { tick: 60, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("from tick 60"), "{err}");
}

#[test]
fn damaged_files_are_refused_with_their_reason() {
    let p = play(300);
    let bytes = replay::encode(&p.recorder.replay(&p.game)).unwrap();
    // Every truncation.
    for len in 0..bytes.len() {
        let err = replay::decode(&bytes[..len]).unwrap_err();
        match err {
            ReplayError::NotAReplay => assert!(len < 8),
            ReplayError::Truncated { have, need } => {
                assert_eq!(have, len as u64);
                assert!(need > have);
            }
            e => panic!("{len} bytes: {e}"),
        }
    }
    // Every single bit flipped in the body is caught by the checksum.
    for i in replay::file::HEADER_LEN..bytes.len() {
        let mut flipped = bytes.clone();
        flipped[i] ^= 1 << (i % 8);
        let err = replay::decode(&flipped).unwrap_err();
        assert!(
            matches!(err, ReplayError::Checksum { .. }),
            "byte {i}: {err}"
        );
        assert!(err.to_string().starts_with("damaged"), "{err}");
    }
    // A newer format.
    let mut newer = bytes.clone();
    newer[8..10].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    let err = replay::decode(&newer).unwrap_err();
    assert!(err.to_string().contains("newer ledge"), "{err}");
    // A length over the bound, checked before anything is read.
    let mut huge = bytes.clone();
    huge[10..14].copy_from_slice(&(MAX_REPLAY_BYTES as u32 + 1).to_le_bytes());
    assert!(matches!(
        replay::decode(&huge).unwrap_err(),
        ReplayError::TooLarge { what: "size", .. }
    ));
    // Bytes after it.
    let mut longer = bytes.clone();
    longer.push(0);
    assert_eq!(
        replay::decode(&longer).unwrap_err(),
        ReplayError::TrailingBytes { extra: 1 }
    );
    // Another file.
    let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR";
    assert_eq!(replay::decode(png).unwrap_err(), ReplayError::NotAReplay);
}

#[test]
fn a_well_formed_file_breaking_the_rules_is_refused() {
    let p = play(120);
    let mut replay = p.recorder.replay(&p.game);
    replay.events.insert(0, Event::Step(0));
    assert!(matches!(
        replay::encode(&replay),
        Err(ReplayError::Invalid(_))
    ));
    let mut replay = p.recorder.replay(&p.game);
    replay.header.names = vec![(PlayerId(2), "b".into()), (PlayerId(1), "a".into())];
    assert!(replay::encode(&replay).is_err());
    let mut replay = p.recorder.replay(&p.game);
    replay.events.push(Event::Step(u32::MAX));
    replay.events.push(Event::Step(u32::MAX));
    let err = replay::encode(&replay).unwrap_err();
    assert!(
        matches!(
            err,
            ReplayError::TooLarge {
                what: "tick count",
                ..
            }
        ),
        "{err}"
    );
}

mod fuzz {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        /// Whatever follows a valid file header, reading never panics.
        #[test]
        fn any_bytes_are_read_or_refused(body in proptest::collection::vec(any::<u8>(), 0..512)) {
            let mut bytes = replay::MAGIC.to_vec();
            bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
            bytes.extend_from_slice(&(body.len() as u32).to_le_bytes());
            bytes.extend_from_slice(&crc32fast::hash(&body).to_le_bytes());
            bytes.extend_from_slice(&body);
            let _ = replay::decode(&bytes);
        }
    }
}
