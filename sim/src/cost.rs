//! Cost: median wall-clock nanoseconds per tick of two busy scenes.
//!
//! * **world**: [`scenes::mixed`] (every shape kind moving, triggers,
//!   one-way colliders, kinematic platforms with riders, a tilemap with
//!   slopes, one-way and hazard tiles), driven by its movers;
//! * **game**: the default level with 8 players on scripted inputs
//!   (`Game::step`: the rules and the world);
//! * **pile**: the landing pile of [`crate::scenes::penetration`] (boxes
//!   falling into a bin and resting on each other: where restitution passes
//!   cost, since overlaps persist).
//!
//! Method: every setting's scenes are built first; a warm-up whose ticks
//! are timed chooses, per scene and setting, how many ticks a run needs to
//! last `target`; then `runs` rounds, each running one timed run of every
//! scene of every setting in turn (interleaved, so a burst of load from
//! elsewhere on a shared machine hits all settings alike rather than one).
//! A run is timed as a whole with [`Instant`]; the result is the median of
//! the runs' times per tick. The simulation goes on from run to run (no
//! reset), so later runs see a settled scene.

use std::time::{Duration, Instant};

use anyhow::Result;
use ledge_levels::default_level;
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use ledge_shared::scene::scripted_inputs;
use ledge_shared::world::{scenes, SimConfig};

use crate::scenes::penetration::Pile;

/// How long and how often to time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Timing {
    /// Ticks run (and timed together) before the runs.
    pub warmup: u32,
    /// Timed runs; the median is reported.
    pub runs: u32,
    /// Least duration of one run.
    pub target: Duration,
}

/// A scene being timed: one tick per call.
type Ticker<'a> = Box<dyn FnMut() + 'a>;

/// The busy world of one setting: [`scenes::mixed`] with `bodies` moving
/// bodies, driven by its movers.
fn world_ticker<'a>(sim: SimConfig, bodies: usize, seed: u64) -> Result<Ticker<'a>> {
    let mut w = scenes::mixed(bodies, seed, sim)?;
    let mut inputs = vec![Buttons::default(); w.controllers().len()];
    Ok(Box::new(move || {
        scenes::inputs(w.tick(), &mut inputs);
        w.step(&inputs);
    }))
}

/// The default level with 8 players on scripted inputs, under `config`.
fn game_ticker<'a>(config: GameConfig) -> Result<Ticker<'a>> {
    let mut g = Game::with_config(&default_level(), config)?;
    for id in 1..=8 {
        g.add_player(PlayerId(id))?;
    }
    let mut inputs: Vec<(PlayerId, Buttons)> = Vec::with_capacity(8);
    Ok(Box::new(move || {
        let t = g.tick();
        inputs.clear();
        inputs.extend(
            (1..=8u32).map(|id| (PlayerId(id), scripted_inputs(t + 555 * (id as u64 - 1)))),
        );
        g.step(&inputs);
    }))
}

/// The landing pile of `bodies` boxes under `sim`.
fn pile_ticker<'a>(sim: SimConfig, bodies: usize, seed: u64) -> Result<Ticker<'a>> {
    let mut pile = Pile::new(sim, bodies, seed)?;
    Ok(Box::new(move || {
        // Gravity on bodies the pile made: cannot fail.
        let _ = pile.tick();
    }))
}

/// Median ns per tick of each scene for one configuration.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Costs {
    /// The busy world.
    pub world: f64,
    /// The default level with 8 players.
    pub game: f64,
    /// The landing pile.
    pub pile: f64,
}

/// Median ns per tick of the busy world (`bodies` moving bodies), the game
/// and the landing pile (`pile_bodies` boxes) for each of `configs`, timed
/// interleaved (module docs).
pub fn measure(
    configs: &[GameConfig],
    bodies: usize,
    pile_bodies: usize,
    seed: u64,
    timing: Timing,
) -> Result<Vec<Costs>> {
    let mut tickers: Vec<Ticker> = Vec::with_capacity(3 * configs.len());
    for c in configs {
        tickers.push(world_ticker(c.sim, bodies, seed)?);
        tickers.push(game_ticker(*c)?);
        tickers.push(pile_ticker(c.sim, pile_bodies, seed)?);
    }
    let ns = interleaved(&mut tickers, timing);
    Ok(ns
        .chunks(3)
        .map(|p| Costs {
            world: p[0],
            game: p[1],
            pile: p[2],
        })
        .collect())
}

/// Times every ticker as the module docs say; median ns per tick of each.
fn interleaved(tickers: &mut [Ticker], timing: Timing) -> Vec<f64> {
    let warmup = timing.warmup.max(1);
    let per_run: Vec<u64> = tickers
        .iter_mut()
        .map(|tick| {
            let start = Instant::now();
            for _ in 0..warmup {
                tick();
            }
            let per_tick = start.elapsed().as_secs_f64() / warmup as f64;
            ((timing.target.as_secs_f64() / per_tick.max(1e-9)).ceil() as u64).clamp(1, 1_000_000)
        })
        .collect();
    let mut samples = vec![Vec::with_capacity(timing.runs as usize); tickers.len()];
    for _ in 0..timing.runs.max(1) {
        for ((tick, &n), out) in tickers.iter_mut().zip(&per_run).zip(&mut samples) {
            let t = Instant::now();
            for _ in 0..n {
                tick();
            }
            out.push(t.elapsed().as_nanos() as f64 / n as f64);
        }
    }
    samples
        .into_iter()
        .map(|mut v| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        })
        .collect()
}
