//! What a seek costs the replay window's frame (docs/PERFORMANCE.md,
//! "Replays"): a match of the default level, `PLAYERS` players drilling
//! for `MINUTES`, opened in a `ReplayViewer`, then End: in one go (one
//! frame, as before) and spread over frames (`SEEK_TICKS_PER_FRAME` a
//! frame): the worst frame and how many.
//!
//! `cargo run --release -p ledge-client --example replay_seek -- [PLAYERS] [MINUTES]`

use std::time::{Duration, Instant};

use ledge_client::bot::brain::drill;
use ledge_client::replay::viewer::SEEK_TICKS_PER_FRAME;
use ledge_client::replay::ReplayViewer;
use ledge_levels::default_level;
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::protocol::{LevelOffer, PlayerId};
use ledge_shared::replay::{Replay, ReplayHeader, ReplayRecorder};

fn main() {
    let mut args = std::env::args().skip(1);
    let players: u32 = args.next().map_or(8, |a| a.parse().expect("PLAYERS"));
    let minutes: u64 = args.next().map_or(30, |a| a.parse().expect("MINUTES"));
    let level = default_level();
    let replay = record(players, minutes);
    let ticks = replay.ticks();

    let mut v = ReplayViewer::new(&level, replay.clone()).unwrap();
    let t = Instant::now();
    v.seek_end().unwrap();
    v.finish_seek().unwrap();
    let one_go = t.elapsed();
    let landed = (v.tick(), v.game().state_hash());

    let mut v = ReplayViewer::new(&level, replay).unwrap();
    let (mut worst, mut frames) = (Duration::ZERO, 0);
    let mut times = Vec::new();
    let t = Instant::now();
    v.seek_end().unwrap();
    worst = worst.max(t.elapsed());
    while v.seeking().is_some() {
        let t = Instant::now();
        v.advance(1.0 / 60.0, u64::MAX).unwrap();
        worst = worst.max(t.elapsed());
        times.push(t.elapsed());
        frames += 1;
    }
    assert_eq!((v.tick(), v.game().state_hash()), landed);
    times.sort();
    let median = times[times.len() / 2].as_secs_f64() * 1e3;
    println!(
        "{players} players, {ticks} ticks: End in one frame {:.0} ms; \
         {SEEK_TICKS_PER_FRAME} ticks a frame: median frame {median:.2} ms, worst {:.2} ms, {frames} frames",
        one_go.as_secs_f64() * 1e3,
        worst.as_secs_f64() * 1e3,
    );
}

/// `players` drilling from their own offsets for `minutes`.
fn record(players: u32, minutes: u64) -> Replay {
    let mut game = Game::from_level(&default_level()).unwrap();
    let header = ReplayHeader::for_match(
        "room",
        ("default", "Default", LevelOffer::default()),
        GameConfig::default(),
        60,
    );
    let mut recorder = ReplayRecorder::new(header, &game);
    for id in 1..=players {
        game.add_player(PlayerId(id)).unwrap();
        recorder.join(PlayerId(id), &format!("p{id}"));
    }
    for _ in 0..minutes * 3600 {
        let tick = game.tick();
        let inputs: Vec<_> = game
            .players()
            .map(|(id, _)| (id, drill(tick + 50 * u64::from(id.0))))
            .collect();
        game.step(&inputs);
        recorder.step(&game, &inputs);
    }
    recorder.replay(&game)
}
