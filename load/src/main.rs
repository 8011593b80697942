//! `ledge-load`: server load benchmark. Starts `ledge-server` and
//! `ledge-bot` (release builds, found next to this binary) for each bot
//! count and prints one table row per count.
//!
//! ```sh
//! cargo build --release -p ledge-server -p ledge-client -p ledge-load
//! target/release/ledge-load --bots 16,64,256 --duration 60
//! target/release/ledge-load --client thin --bots 256 --duration 300 --csv load.csv
//! ```

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{bail, Context};
use clap::{Parser, ValueEnum};
use ledge_load::children::Stop;
use ledge_load::procstat;
use ledge_load::report::{csv, markdown_header, markdown_row, meets_goal};
use ledge_load::run::{run, ClientKind, RunConfig, RunResult, BOT_BINARY};

/// The issue's goal for the 99th percentile tick, seconds.
const P99_GOAL: f64 = 0.002;

/// Which program plays the bots.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Client {
    /// ledge-bot: predicting bots with a brain (--brain).
    Bot,
    /// ledge-bot --brain thin: thin bots (an input per tick, every
    /// snapshot decoded, no prediction): the same server work for far less
    /// CPU.
    Thin,
}

/// Server load benchmark: ledge-server plus ledge-bot on this machine.
#[derive(Debug, Parser)]
#[command(version)]
struct Cli {
    /// Bot counts, one run each.
    #[arg(long, value_delimiter = ',', default_value = "16,64,256")]
    bots: Vec<usize>,
    /// Measured window of each run, seconds.
    #[arg(long, default_value_t = 60.0)]
    duration: f64,
    /// Warm-up after the last bot joined, seconds.
    #[arg(long, default_value_t = 5.0)]
    warmup: f64,
    /// Server tick rate, Hz.
    #[arg(long, default_value_t = 60)]
    tick_hz: u32,
    /// Server snapshot rate, Hz.
    #[arg(long, default_value_t = 30)]
    snapshot_hz: u32,
    /// Players per room; the server gets enough rooms for every bot.
    #[arg(long, default_value_t = 16)]
    max_players: usize,
    /// Most bots per ledge-bot process (more bots: more processes).
    #[arg(long, default_value_t = 256)]
    bots_per_process: usize,
    /// What plays the bots.
    #[arg(long, value_enum, default_value_t = Client::Bot)]
    client: Client,
    /// Brain of ledge-bot's bots (--brain: runner, idle, walker).
    #[arg(long, default_value = "runner")]
    brain: String,
    /// Directory holding ledge-server and ledge-bot (default: this
    /// binary's directory, e.g. target/release).
    #[arg(long, value_name = "DIR")]
    bin_dir: Option<PathBuf>,
    /// Keep the server and bot logs here (default: a temporary directory,
    /// removed at the end).
    #[arg(long, value_name = "DIR")]
    log_dir: Option<PathBuf>,
    /// Also write the results as CSV.
    #[arg(long, value_name = "PATH")]
    csv: Option<PathBuf>,
}

fn main() -> ExitCode {
    match main_result() {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(2),
        Err(e) => {
            eprintln!("ledge-load: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Runs every count; `Ok(false)` when a run missed the goal.
fn main_result() -> anyhow::Result<bool> {
    let cli = Cli::parse();
    if cli.bots.is_empty() || cli.bots.contains(&0) {
        bail!("--bots needs counts of at least 1");
    }
    if !(cli.duration > 0.0 && cli.warmup >= 0.0) {
        bail!("--duration must be positive and --warmup not negative");
    }
    let bin_dir = match &cli.bin_dir {
        Some(dir) => dir.clone(),
        None => std::env::current_exe()
            .context("locating this binary")?
            .parent()
            .context("this binary has no directory")?
            .to_path_buf(),
    };
    let client = match cli.client {
        Client::Bot => ClientKind::Bot,
        Client::Thin => ClientKind::Thin,
    };
    for bin in ["ledge-server", BOT_BINARY] {
        let path = bin_dir.join(bin);
        if !path.is_file() {
            bail!(
                "{} not found: build it first with \
                 `cargo build --release -p ledge-server -p ledge-client -p ledge-load`, \
                 or pass --bin-dir",
                path.display()
            );
        }
    }
    let temp = tempfile::tempdir().context("creating a log directory")?;
    let log_dir = match &cli.log_dir {
        Some(dir) => {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
            dir.clone()
        }
        None => temp.path().to_path_buf(),
    };
    let stop = Stop::install()?;

    let load = procstat::load_average().unwrap_or([f64::NAN; 3]);
    println!(
        "machine: {} cores, {}, load average {:.2} {:.2} {:.2}",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        procstat::cpu_model().unwrap_or_else(|| "unknown CPU".into()),
        load[0],
        load[1],
        load[2]
    );
    println!(
        "server: {} Hz ticks, {} Hz snapshots, {} players per room; bots: {}; \
         window {} s after {} s of warm-up; binaries in {}",
        cli.tick_hz,
        cli.snapshot_hz,
        cli.max_players,
        match cli.client {
            Client::Bot => format!("ledge-bot --brain {}", cli.brain),
            Client::Thin => "ledge-bot --brain thin".to_owned(),
        },
        cli.duration,
        cli.warmup,
        bin_dir.display()
    );

    let mut results: Vec<RunResult> = Vec::new();
    let mut failures: Vec<String> = Vec::new();
    for &bots in &cli.bots {
        let config = RunConfig {
            bots,
            client,
            bot_processes: bots.div_ceil(cli.bots_per_process.max(1)),
            max_players: cli.max_players.max(1),
            tick_hz: cli.tick_hz,
            snapshot_hz: cli.snapshot_hz,
            brain: cli.brain.clone(),
            warmup: Duration::from_secs_f64(cli.warmup),
            duration: Duration::from_secs_f64(cli.duration),
            bin_dir: bin_dir.clone(),
            log_dir: log_dir.clone(),
        };
        eprintln!(
            "run: {bots} bots in {} rooms, {} bot process(es)",
            config.rooms(),
            config.split().len()
        );
        match run(&config, &stop) {
            Ok(result) => {
                eprintln!("  {}", markdown_row(&result));
                results.push(result);
            }
            // Interrupted: stop everything (the children are gone already).
            Err(e) if stop.requested() => return Err(e),
            Err(e) => {
                eprintln!("  the run with {bots} bots failed: {e:#}");
                failures.push(format!("{bots} bots: {e:#}"));
            }
        }
    }

    println!();
    println!("{}", markdown_header());
    for r in &results {
        println!("{}", markdown_row(r));
    }
    let load = procstat::load_average().unwrap_or([f64::NAN; 3]);
    println!(
        "\nload average at the end: {:.2} {:.2} {:.2}",
        load[0], load[1], load[2]
    );
    let mut all_met = failures.is_empty();
    for f in &failures {
        println!("failed: {f}");
    }
    for r in &results {
        let met = meets_goal(r, P99_GOAL);
        all_met &= met;
        println!(
            "{} bots: goal (p99 <= {} ms, no missed tick, no drop) {}",
            r.bots,
            P99_GOAL * 1e3,
            if met { "met" } else { "NOT met" }
        );
    }
    if let Some(path) = &cli.csv {
        std::fs::write(path, csv(&results))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    drop(temp);
    Ok(all_met)
}
