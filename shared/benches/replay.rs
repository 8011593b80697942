//! Replays: what recording costs a room's tick, what a replay weighs per
//! player-minute, and how fast one plays back, on the default level.
//!
//! ```sh
//! cargo bench -p ledge-shared --bench replay
//! ```
//!
//! Players press like the replay tests' players (a run, a jump, a pause,
//! back: a change every 10 to 60 ticks, each player shifted). One game is
//! stepped without a recorder and one with (same inputs, checked to end in
//! the same state), alternating, round after round; figures are medians
//! per tick. The recorded minute is then encoded (bytes per player-minute)
//! and played back to its end with every hash checked (ticks per second).
//! Printed as a markdown table (`docs/PERFORMANCE.md`, "Replays").

use std::time::{Duration, Instant};

use ledge_levels::default_level;
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{LevelOffer, PlayerId};
use ledge_shared::replay::{self, Playback, ReplayHeader, ReplayRecorder};

/// Ticks per round (one minute at 60 Hz).
const TICKS: u64 = 3600;
/// Rounds.
const ROUNDS: usize = 5;

fn header() -> ReplayHeader {
    ReplayHeader::for_match(
        "bench",
        ("default", "Default", LevelOffer::default()),
        GameConfig::default(),
        60,
    )
}

fn buttons(id: u32, tick: u64) -> Buttons {
    let t = tick + 37 * u64::from(id);
    Buttons(match t % 200 {
        0..=59 => Buttons::RIGHT,
        60..=80 => Buttons::RIGHT | Buttons::JUMP,
        81..=120 => 0,
        121..=170 => Buttons::LEFT,
        171..=180 => Buttons::LEFT | Buttons::JUMP,
        _ => Buttons::JUMP,
    })
}

/// A game with `players` joined (recorded when `recorder` is given).
fn game(players: u32, recorder: &mut Option<ReplayRecorder>) -> Game {
    let mut g = Game::from_level(&default_level()).unwrap();
    if recorder.is_some() {
        *recorder = Some(ReplayRecorder::new(header(), &g));
    }
    for id in 1..=players {
        g.add_player(PlayerId(id)).unwrap();
        if let Some(r) = recorder {
            r.join(PlayerId(id), &format!("p{id}"));
        }
    }
    g
}

/// Steps `g` `TICKS` times; the time per tick.
fn run(g: &mut Game, players: u32, recorder: &mut Option<ReplayRecorder>) -> Duration {
    let mut inputs = Vec::with_capacity(players as usize);
    let start = Instant::now();
    for _ in 0..TICKS {
        let tick = g.tick();
        inputs.clear();
        inputs.extend((1..=players).map(|id| (PlayerId(id), buttons(id, tick))));
        g.step(&inputs);
        if let Some(r) = recorder {
            r.step(g, &inputs);
        }
    }
    start.elapsed() / TICKS as u32
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn main() {
    println!("| players | tick | tick + recording | recording's cost | bytes / player-minute | playback, ticks/s |");
    println!("|---|---|---|---|---|---|");
    for players in [8u32, 64] {
        let (mut plain, mut recorded) = (Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..ROUNDS {
            let mut none = None;
            let mut a = game(players, &mut none);
            plain.push(run(&mut a, players, &mut none));
            let mut rec = Some(ReplayRecorder::new(header(), &a));
            let mut b = game(players, &mut rec);
            recorded.push(run(&mut b, players, &mut rec));
            assert_eq!(a.state_hash(), b.state_hash(), "recording changes nothing");
            last = Some((b, rec.unwrap()));
        }
        let (g, rec) = last.unwrap();
        let replay = rec.replay(&g);
        let bytes = replay::encode(&replay).unwrap().len();
        let started = Instant::now();
        let mut playing = Playback::new(&default_level(), replay).unwrap();
        let ticks = playing.play_to_end().unwrap();
        let playback = ticks as f64 / started.elapsed().as_secs_f64();
        let (p, r) = (median(plain), median(recorded));
        let cost = (r.as_secs_f64() / p.as_secs_f64() - 1.0) * 100.0;
        println!(
            "| {players} | {:.1} µs | {:.1} µs | {cost:+.1} % | {} | {:.0} |",
            p.as_secs_f64() * 1e6,
            r.as_secs_f64() * 1e6,
            bytes / players as usize,
            playback
        );
    }
}
