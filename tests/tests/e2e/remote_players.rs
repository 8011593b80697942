//! How to draw remote players: interpolated between snapshots in the past
//! (what the client does) or predicted forward from the newest snapshot with
//! the player's last input. A small offline harness: a random walker plays
//! on a server game; snapshots every 2 ticks reach the client after a delay
//! with jitter and loss; frames are drawn at 60 Hz between ticks. For each
//! method it measures the error against where the player really is *now*
//! and the visible snaps (frames where the drawn motion changes abruptly,
//! by more than 4 px and more than twice any real change nearby plus 2 px:
//! corrections, not delayed jumps or landings). `cargo test -p ledge-tests --test
//! e2e remote_players:: -- --nocapture` prints the table (docs/CLIENT.md).

use std::time::{Duration, Instant};

use ledge_client::bot::{Brain, RandomWalker, SplitMix64};
use ledge_client::game::interp::Interpolator;
use ledge_client::netstats::StatsTracker;
use ledge_client::view::px2;
use ledge_client::view::Vec2;
use ledge_levels::default_level;
use ledge_shared::game::Game;
use ledge_shared::protocol::{PlayerId, StateSnapshot};

const RATE: f64 = 60.0;
const TICKS: u64 = 60 * 30;
/// A change of the drawn motion between two frames larger than this, and
/// than twice any real change nearby plus 2 px, is a visible snap.
const SNAP_PX: f32 = 4.0;
/// Frames around a drawn change where a real one may explain it (covers
/// the interpolation delay).
const WINDOW: usize = 12;

#[derive(Debug, Default, Clone, Copy)]
struct Figures {
    mean_err: f32,
    p95_err: f32,
    snaps: usize,
}

fn figures(drawn: &[Vec2], truth: &[Vec2]) -> Figures {
    let mut errs: Vec<f32> = drawn
        .iter()
        .zip(truth)
        .map(|(d, t)| (*d - *t).length())
        .collect();
    // Frame-to-frame change of the motion (a second difference).
    let accel = |p: &[Vec2]| -> Vec<f32> {
        p.windows(3)
            .map(|w| ((w[2] - w[1]) - (w[1] - w[0])).length())
            .collect()
    };
    let (a_drawn, a_true) = (accel(drawn), accel(truth));
    // A snap: the drawn motion changes abruptly where the real motion did
    // not change as much anywhere nearby (a correction, not a delayed
    // jump or landing).
    let snaps = (0..a_drawn.len())
        .filter(|&f| {
            let lo = f.saturating_sub(WINDOW);
            let hi = (f + WINDOW).min(a_true.len() - 1);
            let real = a_true[lo..=hi].iter().copied().fold(0.0, f32::max);
            a_drawn[f] > SNAP_PX && a_drawn[f] > 2.0 * real + 2.0
        })
        .count();
    let mean_err = errs.iter().sum::<f32>() / errs.len() as f32;
    errs.sort_by(f32::total_cmp);
    Figures {
        mean_err,
        p95_err: errs[errs.len() * 95 / 100],
        snaps,
    }
}

/// Runs one network case; returns (interpolation, prediction) figures.
fn run(delay_ms: f64, jitter_ms: f64, loss: f64, seed: u64) -> (Figures, Figures) {
    let level = default_level();
    let me = PlayerId(1);
    let mut server = Game::from_level(&level).unwrap();
    server.add_player(me).unwrap();
    let mut brain = RandomWalker::new(seed);
    // Play the whole match first: states and inputs by tick.
    let mut truth = vec![px2(server.player(me).unwrap().pos)];
    let mut inputs = Vec::new();
    let mut snapshots: Vec<StateSnapshot> = vec![server.snapshot()];
    for _ in 0..TICKS {
        let b = brain.buttons(&server, me);
        inputs.push(b);
        server.step(&[(me, b)]);
        truth.push(px2(server.player(me).unwrap().pos));
        snapshots.push(server.snapshot());
    }
    // Snapshots every 2 ticks, server tick t at t / RATE seconds.
    let mut rng = SplitMix64(seed ^ 0xabc);
    let mut arrivals: Vec<(f64, u64)> = Vec::new();
    for t in (1..=TICKS / 2).map(|i| 2 * i) {
        let lost = rng.next_f64() < loss;
        let at = t as f64 / RATE + (delay_ms + jitter_ms * rng.next_f64()) / 1000.0;
        if !lost {
            arrivals.push((at, t));
        }
    }
    arrivals.sort_by(|a, b| a.0.total_cmp(&b.0));

    let t0 = Instant::now();
    let at = |secs: f64| t0 + Duration::from_secs_f64(secs);
    let mut interp = Interpolator::new(60, 2);
    let mut stats = StatsTracker::new(60, 2);
    let mut client = Game::from_level(&level).unwrap();
    let mut newest: Option<u64> = None;
    let mut next = 0;
    let (mut drawn_i, mut drawn_p, mut real) = (Vec::new(), Vec::new(), Vec::new());
    // Frames between ticks, after a second of warm-up.
    for f in 60..TICKS - 60 {
        let now = (f as f64 + 0.5) / RATE;
        while next < arrivals.len() && arrivals[next].0 <= now {
            let (when, tick) = arrivals[next];
            stats.snapshot(tick, tick.checked_sub(2), at(when));
            interp.set_jitter(stats.jitter_ticks());
            interp.set_loss(stats.loss());
            interp.push(tick, snapshots[tick as usize].entities.clone(), at(when));
            newest = Some(newest.map_or(tick, |n| n.max(tick)));
            next += 1;
        }
        let Some(s) = newest else { continue };
        interp.advance(at(now));
        let Some(sample) = interp.sample().into_iter().find(|x| x.id == me.0) else {
            continue;
        };
        // Predicted: restore the newest snapshot and run the player's last
        // input (as of that snapshot) up to now.
        client.restore(&snapshots[s as usize]).unwrap();
        let last = inputs[s as usize - 1];
        let now_tick = now * RATE;
        let whole = now_tick.floor() as u64;
        let mut prev = px2(client.player(me).unwrap().pos);
        let mut cur = prev;
        for _ in s..=whole {
            prev = cur;
            client.step(&[(me, last)]);
            cur = px2(client.player(me).unwrap().pos);
        }
        let predicted = if whole >= s {
            prev.lerp(cur, (now_tick - whole as f64) as f32)
        } else {
            cur
        };
        let frac = (now_tick - whole as f64) as f32;
        real.push(truth[whole as usize].lerp(truth[whole as usize + 1], frac));
        drawn_i.push(sample.pos);
        drawn_p.push(predicted);
    }
    (figures(&drawn_i, &real), figures(&drawn_p, &real))
}

#[test]
fn interpolation_never_snaps_where_last_input_prediction_does() {
    println!("| network (one way) | method | mean error px | p95 error px | snaps / 28 s |");
    println!("|---|---|---|---|---|");
    let cases = [
        ("20 ms", 20.0, 0.0, 0.0),
        ("20 ms + 0..30 ms jitter", 20.0, 30.0, 0.0),
        ("50 ms + 0..30 ms jitter, 10% loss", 50.0, 30.0, 0.1),
    ];
    for (name, delay, jitter, loss) in cases {
        let (mut i, mut p) = (Figures::default(), Figures::default());
        for seed in 1..=3 {
            let (a, b) = run(delay, jitter, loss, seed);
            i.mean_err += a.mean_err / 3.0;
            i.p95_err += a.p95_err / 3.0;
            i.snaps += a.snaps;
            p.mean_err += b.mean_err / 3.0;
            p.p95_err += b.p95_err / 3.0;
            p.snaps += b.snaps;
        }
        i.snaps /= 3;
        p.snaps /= 3;
        for (m, f) in [("interpolated", i), ("predicted, last input", p)] {
            println!(
                "| {name} | {m} | {:.1} | {:.1} | {} |",
                f.mean_err, f.p95_err, f.snaps
            );
        }
        assert!(
            i.snaps * 4 < p.snaps.max(4),
            "{name}: interpolation {i:?}, prediction {p:?}"
        );
    }
}
