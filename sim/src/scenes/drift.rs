//! Prediction drift: how far a client predicting with a setting ends from
//! an authority running the default configuration, with perfect inputs.
//!
//! The authority runs the default level with 8 players on scripted inputs
//! and [`GameConfig::default`] (what a server runs unless configured
//! otherwise). Every `horizon` ticks the client restores the authority's
//! snapshot into its own game (same level, the measured setting) and
//! predicts `horizon` ticks with exactly the authority's inputs for every
//! player; then each player's predicted centre is compared with the
//! authority's. Inputs are perfect, so this isolates the configuration:
//! a setting that does not change results (broad phase, pipeline, threads,
//! or the default itself) drifts by exactly zero, and a client predicting
//! with the server's own configuration always does. Lost and late inputs
//! are the netcode's matter (`docs/CLIENT.md`) and do not depend on the
//! knobs.

use anyhow::{Context, Result};
use glam::IVec2;
use ledge_levels::default_level;
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use ledge_shared::scene::scripted_inputs;

/// Players in the game.
pub const PLAYERS: u32 = 8;
/// Ticks predicted from each snapshot: 8 ticks (133 ms), a typical round
/// trip plus the input delay.
pub const HORIZON: u32 = 8;

/// Position error of the predictions.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Drift {
    /// Player positions compared.
    pub samples: u64,
    /// Mean distance between predicted and authoritative centres, units.
    pub mean: f64,
    /// Largest such distance, units.
    pub max: i64,
}

/// Runs `ticks` authority ticks, predicting with `config` from a snapshot
/// every [`HORIZON`] ticks.
pub fn run(config: GameConfig, ticks: u32) -> Result<Drift> {
    let level = default_level();
    let mut authority = Game::with_config(&level, GameConfig::default())?;
    let mut client = Game::with_config(&level, config)?;
    for id in 1..=PLAYERS {
        authority.add_player(PlayerId(id))?;
    }
    let mut inputs: Vec<(PlayerId, Buttons)> = Vec::with_capacity(PLAYERS as usize);
    let mut out = Drift::default();
    let mut sum = 0f64;
    for _ in 0..ticks / HORIZON {
        client
            .restore(&authority.snapshot())
            .context("restoring the authority's snapshot")?;
        for _ in 0..HORIZON {
            let t = authority.tick();
            inputs.clear();
            inputs.extend(
                (1..=PLAYERS).map(|id| (PlayerId(id), scripted_inputs(t + 555 * (id as u64 - 1)))),
            );
            authority.step(&inputs);
            client.step(&inputs);
        }
        for ((ida, pa), (idc, pc)) in authority.players().zip(client.players()) {
            anyhow::ensure!(ida == idc, "player {ida} predicted as {idc}");
            let e = distance(pa, pc);
            out.max = out.max.max(e.ceil() as i64);
            sum += e;
            out.samples += 1;
        }
    }
    out.mean = sum / out.samples.max(1) as f64;
    Ok(out)
}

/// Distance between two points, units.
fn distance(a: IVec2, b: IVec2) -> f64 {
    let d = (a - b).as_dvec2();
    d.length()
}
