//! `ledge-sim`: simulation tools. `ledge-sim tradeoff` measures every
//! speed/accuracy knob setting on the standard scenes and prints a table
//! (optionally a CSV and an SVG plot); see `docs/TRADEOFFS.md`.

use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use ledge_sim::tradeoff::{self, Scale};
use ledge_sim::{plot, report, settings};

/// ledge's simulation tools.
#[derive(Debug, Parser)]
#[command(name = "ledge-sim", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Runs the standard scenes for every knob setting and prints cost
    /// against accuracy.
    Tradeoff(TradeoffArgs),
}

#[derive(Debug, Args)]
struct TradeoffArgs {
    /// A fast run (fewer shots, bodies, offsets and ticks; for tests).
    #[arg(long)]
    quick: bool,
    /// Shots at the thin walls (default 1,000,000; 20,000 with --quick).
    #[arg(long)]
    shots: Option<u64>,
    /// Seed of the random scenes.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Only the settings whose name contains this.
    #[arg(long)]
    only: Option<String>,
    /// Writes every figure to this CSV file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Draws cost against each accuracy metric to this SVG file.
    #[arg(long)]
    plot: Option<PathBuf>,
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Tradeoff(a) => run_tradeoff(a),
    }
}

fn run_tradeoff(a: TradeoffArgs) -> Result<()> {
    let mut scale = if a.quick {
        Scale::quick()
    } else {
        Scale::full()
    };
    if let Some(s) = a.shots {
        scale.shots = s;
    }
    scale.seed = a.seed;
    let all = settings::all();
    let chosen: Vec<_> = all
        .into_iter()
        .filter(|s| a.only.as_ref().is_none_or(|o| s.name.contains(o.as_str())))
        .collect();
    anyhow::ensure!(!chosen.is_empty(), "no setting matches --only");
    let n = chosen.len();
    let mut done = 0;
    eprintln!("accuracy, one setting at a time; then the costs, all settings interleaved");
    let rows = tradeoff::run(&chosen, &scale, |r| {
        done += 1;
        eprintln!(
            "[{done}/{n}] {}: {} tunnels in {} shots, {} false squishes",
            r.setting.name,
            r.metrics.thin_walls.tunnels,
            r.metrics.thin_walls.shots,
            r.metrics.false_squishes(),
        );
    })?;
    print!("{}", report::table(&rows));
    if let Some(p) = &a.csv {
        let f = File::create(p).with_context(|| format!("creating {}", p.display()))?;
        report::write_csv(&rows, BufWriter::new(f))
            .with_context(|| format!("writing {}", p.display()))?;
    }
    if let Some(p) = &a.plot {
        plot::write_svg(&rows, p).with_context(|| format!("drawing {}", p.display()))?;
    }
    Ok(())
}
