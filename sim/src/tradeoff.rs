//! Runs every scene for every setting: one [`Row`] of figures per setting.

use std::time::Duration;

use anyhow::{Context, Result};

use crate::cost::{self, Timing};
use crate::scenes::{drift, penetration, seams, squish, thin_walls};
use crate::settings::Setting;

/// How much work each measurement does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    /// Shots at the thin walls.
    pub shots: u64,
    /// Boxes in the landing pile, and its ticks.
    pub pile_bodies: usize,
    /// Ticks of the landing pile.
    pub pile_ticks: u32,
    /// Ticks of the sliding boxes.
    pub seam_ticks: u32,
    /// Start offsets of the sliding boxes every this many units (1: all 256).
    pub seam_offset_step: i32,
    /// Tallest stack.
    pub stack_height: u32,
    /// Ticks of the stacks.
    pub stack_ticks: u32,
    /// Authority ticks of the drift scene.
    pub drift_ticks: u32,
    /// Moving bodies of the busy world timed for the cost.
    pub cost_bodies: usize,
    /// How the cost is timed.
    pub timing: Timing,
    /// Seed of the random scenes.
    pub seed: u64,
}

impl Scale {
    /// The published run: 1,000,000 shots, every subpixel offset, 3,000
    /// bodies for the cost (above the 2,048 moving colliders from which
    /// detection uses threads).
    pub fn full() -> Self {
        Self {
            shots: 1_000_000,
            pile_bodies: 300,
            pile_ticks: 300,
            seam_ticks: 240,
            seam_offset_step: 1,
            stack_height: 12,
            stack_ticks: 300,
            drift_ticks: 1200,
            cost_bodies: 3000,
            timing: Timing {
                warmup: 20,
                runs: 7,
                target: Duration::from_millis(150),
            },
            seed: 1,
        }
    }

    /// A run of a few seconds for tests and quick looks: same scenes, fewer
    /// shots, bodies, offsets and ticks.
    pub fn quick() -> Self {
        Self {
            shots: 20_000,
            pile_bodies: 60,
            pile_ticks: 60,
            seam_ticks: 60,
            seam_offset_step: 32,
            stack_height: 6,
            stack_ticks: 60,
            drift_ticks: 96,
            cost_bodies: 200,
            timing: Timing {
                warmup: 3,
                runs: 3,
                target: Duration::from_millis(2),
            },
            seed: 1,
        }
    }
}

/// Every figure of one setting (the costs are filled in by [`run`] once
/// every setting's accuracy is measured).
#[derive(Debug, Clone, PartialEq)]
pub struct Metrics {
    /// Median ns per tick of the busy world ([`cost::measure`]).
    pub world_ns: f64,
    /// Median ns per tick of the default level with 8 players.
    pub game_ns: f64,
    /// Median ns per tick of the landing pile.
    pub pile_ns: f64,
    /// Tunnelling.
    pub thin_walls: thin_walls::ThinWalls,
    /// Overlap left after a tick (and the pile's squishes).
    pub penetration: penetration::Penetration,
    /// Motion lost at seams.
    pub seams: seams::Seams,
    /// Squishes of the stacks.
    pub squish: squish::Squish,
    /// Prediction drift against the default configuration.
    pub drift: drift::Drift,
}

impl Metrics {
    /// Squish events of the stacks and the landing pile: all false.
    pub fn false_squishes(&self) -> u64 {
        self.squish.squished + self.penetration.squished
    }
}

/// One setting and its figures.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The setting.
    pub setting: Setting,
    /// What it measured.
    pub metrics: Metrics,
}

/// Measures one setting's accuracy (costs left at zero).
pub fn measure(setting: &Setting, scale: &Scale) -> Result<Metrics> {
    let sim = setting.config.sim;
    let ctx = |what: &str| format!("{}: {what}", setting.name);
    Ok(Metrics {
        thin_walls: thin_walls::run(sim, scale.shots, scale.seed, setting.mark_shots)
            .with_context(|| ctx("thin walls"))?,
        penetration: penetration::run(sim, scale.pile_bodies, scale.pile_ticks, scale.seed)
            .with_context(|| ctx("landing pile"))?,
        seams: seams::run(setting.config, scale.seam_ticks, scale.seam_offset_step)
            .with_context(|| ctx("seams"))?,
        squish: squish::run(sim, scale.stack_height, scale.stack_ticks)
            .with_context(|| ctx("stacks"))?,
        drift: drift::run(setting.config, scale.drift_ticks).with_context(|| ctx("drift"))?,
        world_ns: 0.0,
        game_ns: 0.0,
        pile_ns: 0.0,
    })
}

/// Measures every setting of `settings`: accuracy one setting at a time
/// (calling `progress` after each), then the costs of all of them,
/// interleaved ([`cost::measure`]).
pub fn run(
    settings: &[Setting],
    scale: &Scale,
    mut progress: impl FnMut(&Row),
) -> Result<Vec<Row>> {
    let mut rows = Vec::with_capacity(settings.len());
    for s in settings {
        let row = Row {
            setting: s.clone(),
            metrics: measure(s, scale)?,
        };
        progress(&row);
        rows.push(row);
    }
    let configs: Vec<_> = settings.iter().map(|s| s.config).collect();
    let costs = cost::measure(
        &configs,
        scale.cost_bodies,
        scale.pile_bodies,
        scale.seed,
        scale.timing,
    )
    .context("timing the busy scenes")?;
    for (row, c) in rows.iter_mut().zip(costs) {
        row.metrics.world_ns = c.world;
        row.metrics.game_ns = c.game;
        row.metrics.pile_ns = c.pile;
    }
    Ok(rows)
}
