//! What building a ghost costs a frame (docs/PERFORMANCE.md, "Replays"):
//! a run of the default level recorded among `PLAYERS` players drilling
//! (the runner steps off the spawn, which starts its timer, waits
//! `MINUTES`, then runs the route), played
//! into a ghost in one go (`Ghost::from_run`: the frame that did it
//! before) and then `GHOST_TICKS_PER_FRAME` ticks per call, as
//! `OnlineGame` does now: the worst call.
//!
//! `cargo run --release -p ledge-client --example ghost_build -- [PLAYERS] [MINUTES]`

use std::time::{Duration, Instant};

use ledge_client::bot::brain::drill;
use ledge_client::bot::{Brain, Runner};
use ledge_client::ghost::{Ghost, GhostBuilder, GHOST_TICKS_PER_FRAME};
use ledge_levels::{default_level, default_route};
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{GhostRun, LevelOffer, PlayerId};
use ledge_shared::replay::{self, ReplayHeader, ReplayRecorder};

fn main() {
    let mut args = std::env::args().skip(1);
    let players: u32 = args.next().map_or(8, |a| a.parse().expect("PLAYERS"));
    let minutes: u64 = args.next().map_or(10, |a| a.parse().expect("MINUTES"));
    let level = default_level();
    let run = record(&level, players, minutes);
    let ticks = replay::decode(&run.replay).unwrap().ticks();
    let started = Instant::now();
    let ghost = Ghost::from_run(&level, &run).unwrap();
    let one_go = started.elapsed();
    let mut builder = GhostBuilder::new(&level, &run).unwrap();
    let (mut worst, mut calls) = (Duration::ZERO, 0);
    let mut times = Vec::new();
    while !builder.is_done() {
        let t = Instant::now();
        builder.build(GHOST_TICKS_PER_FRAME).unwrap();
        worst = worst.max(t.elapsed());
        times.push(t.elapsed());
        calls += 1;
    }
    assert_eq!(builder.finish().unwrap(), ghost);
    times.sort();
    let median = times[times.len() / 2].as_secs_f64() * 1e3;
    println!(
        "{players} players, {ticks} ticks ({} of run): in one go {:.1} ms \
         ({:.2} us/tick); {GHOST_TICKS_PER_FRAME} ticks per frame: median frame {median:.2} ms, worst {:.2} ms, {calls} frames",
        ghost.ticks(),
        one_go.as_secs_f64() * 1e3,
        one_go.as_secs_f64() * 1e6 / ticks as f64,
        worst.as_secs_f64() * 1e3,
    );
}

/// The runner's run (player 1) among `players - 1` drilling players.
fn record(level: &ledge_shared::level::Level, players: u32, minutes: u64) -> GhostRun {
    let mut game = Game::from_level(level).unwrap();
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
    let me = PlayerId(1);
    let mut runner = Runner::new(default_route());
    let wait = minutes * 3600;
    loop {
        let tick = game.tick();
        // A step right starts its run timer; then it waits.
        let mine = if tick < 4 {
            Buttons(Buttons::RIGHT)
        } else if tick < wait {
            Buttons::NONE
        } else {
            runner.buttons(&game, me)
        };
        let inputs: Vec<_> = game
            .players()
            .map(|(id, _)| {
                let b = if id == me {
                    mine
                } else {
                    drill(tick + 50 * u64::from(id.0))
                };
                (id, b)
            })
            .collect();
        game.step(&inputs);
        recorder.step(&game, &inputs);
        let p = game.player(me).unwrap();
        if p.won {
            let ticks = u64::from(p.run_ticks);
            let replay = recorder
                .run(&game, me, game.tick() - ticks, ticks, 1)
                .unwrap();
            return GhostRun {
                record: true,
                player: "p1".into(),
                millis: ticks * 1000 / 60,
                replay: replay::encode(&replay).unwrap(),
            };
        }
        assert!(tick < wait + 3600, "the runner never finished");
    }
}
