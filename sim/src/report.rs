//! The table (Markdown, for the terminal and `docs/TRADEOFFS.md`) and the
//! CSV (one row per setting, every figure, raw units).

use std::fmt::Write as _;
use std::io::Write;

use ledge_shared::world::{BroadPhaseKind, Pipeline, SimConfig, SweepMode};

use crate::tradeoff::Row;

/// The CSV's columns, in order.
pub const CSV_COLUMNS: [&str; 39] = [
    "setting",
    "knob",
    "substeps",
    "restitution_iterations",
    "broad_phase",
    "pipeline",
    "threads",
    "sweep",
    "marked_shots",
    "player_shape",
    "world_ns_per_tick",
    "game_ns_per_tick",
    "pile_ns_per_tick",
    "shots",
    "tunnels",
    "tunnel_rate",
    "slow_shots",
    "slow_tunnels",
    "tiny_shots",
    "tiny_tunnels",
    "tiny_tunnel_rate",
    "max_penetration_units",
    "mean_max_penetration_units",
    "seam_crossings",
    "seam_loss_tiles_units",
    "seam_loss_boxes_units",
    "game_seam_crossings_tiles",
    "game_seam_loss_tiles_units",
    "game_seam_crossings_blocks",
    "game_seam_loss_blocks_units",
    "game_seam_loss_per_crossing_units",
    "seam_loss_per_crossing_units",
    "stack_boxes",
    "stack_squishes",
    "pile_squishes",
    "false_squishes",
    "drift_samples",
    "drift_mean_units",
    "drift_max_units",
];

/// The broad phase as one word: `brute` or `strips<shift>x<level shift>`.
pub fn broad_phase_name(b: BroadPhaseKind) -> String {
    match b {
        BroadPhaseKind::BruteForce => "brute".to_owned(),
        BroadPhaseKind::Strips {
            strip_shift,
            level_shift,
        } => format!("strips{strip_shift}x{level_shift}"),
    }
}

/// The sweep mode as one word: `off`, `flagged` or `auto<min speed>`.
pub fn sweep_name(s: SweepMode) -> String {
    match s {
        SweepMode::Off => "off".to_owned(),
        SweepMode::Flagged => "flagged".to_owned(),
        SweepMode::Auto { min_speed } => format!("auto{min_speed}"),
    }
}

fn pipeline_name(p: Pipeline) -> &'static str {
    match p {
        Pipeline::Specialised => "specialised",
        Pipeline::General => "general",
    }
}

/// The CSV text: a header line and one line per row.
pub fn csv(rows: &[Row]) -> String {
    let mut out = CSV_COLUMNS.join(",");
    out.push('\n');
    for r in rows {
        let (s, m): (&SimConfig, _) = (&r.setting.config.sim, &r.metrics);
        let fields: Vec<String> = vec![
            r.setting.name.clone(),
            r.setting.knob.to_owned(),
            s.substeps.to_string(),
            s.restitution_iterations.to_string(),
            broad_phase_name(s.broad_phase),
            pipeline_name(s.pipeline).to_owned(),
            s.threads.to_string(),
            sweep_name(s.sweep),
            r.setting.mark_shots.to_string(),
            format!("{:?}", r.setting.config.player.shape),
            format!("{:.0}", m.world_ns),
            format!("{:.0}", m.game_ns),
            format!("{:.0}", m.pile_ns),
            m.thin_walls.shots.to_string(),
            m.thin_walls.tunnels.to_string(),
            format!("{:.6}", m.thin_walls.rate()),
            m.thin_walls.slow_shots.to_string(),
            m.thin_walls.slow_tunnels.to_string(),
            m.thin_walls.tiny_shots.to_string(),
            m.thin_walls.tiny_tunnels.to_string(),
            format!("{:.6}", m.thin_walls.tiny_rate()),
            m.penetration.max.to_string(),
            format!("{:.2}", m.penetration.mean_of_max),
            m.seams.crossings.to_string(),
            m.seams.lost_tiles.to_string(),
            m.seams.lost_boxes.to_string(),
            m.seams.game_crossings_tiles.to_string(),
            m.seams.game_lost_tiles.to_string(),
            m.seams.game_crossings_blocks.to_string(),
            m.seams.game_lost_blocks.to_string(),
            format!("{:.3}", m.seams.per_seam_game()),
            format!("{:.3}", m.seams.per_seam()),
            m.squish.boxes.to_string(),
            m.squish.squished.to_string(),
            m.penetration.squished.to_string(),
            m.false_squishes().to_string(),
            m.drift.samples.to_string(),
            format!("{:.2}", m.drift.mean),
            m.drift.max.to_string(),
        ];
        debug_assert_eq!(fields.len(), CSV_COLUMNS.len());
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// Writes [`csv`] to `w`.
pub fn write_csv(rows: &[Row], mut w: impl Write) -> std::io::Result<()> {
    w.write_all(csv(rows).as_bytes())
}

/// The Markdown table: cost in microseconds per tick, tunnelling rates in
/// percent (game-sized shots, those at game speeds, tiny shots),
/// penetration and drift in pixels, seam loss in units per seam crossed.
pub fn table(rows: &[Row]) -> String {
    let mut out = String::new();
    out.push_str(
        "| setting | world µs/tick | game µs/tick | pile µs/tick | tunnelling | at ≤ 8 px/tick | tiny shots | max penetration | seam loss (units/seam): all (boxes, players) | false squishes | drift mean / max |\n",
    );
    out.push_str("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for r in rows {
        let m = &r.metrics;
        let _ = writeln!(
            out,
            "| {} | {:.1} | {:.2} | {:.1} | {:.3} % | {:.3} % | {:.3} % | {:.2} px | {:.2} ({:.2}, {:.2}) | {} | {:.2} / {:.2} px |",
            r.setting.name,
            m.world_ns / 1000.0,
            m.game_ns / 1000.0,
            m.pile_ns / 1000.0,
            100.0 * m.thin_walls.rate(),
            100.0 * m.thin_walls.slow_rate(),
            100.0 * m.thin_walls.tiny_rate(),
            m.penetration.max as f64 / 256.0,
            m.seams.per_seam(),
            (m.seams.per_seam_tiles() + m.seams.per_seam_boxes()) / 2.0,
            m.seams.per_seam_game(),
            m.false_squishes(),
            m.drift.mean / 256.0,
            m.drift.max as f64 / 256.0,
        );
    }
    out
}
