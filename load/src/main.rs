//! `ledge-load`: server load benchmark. Starts `ledge-server` and
//! `ledge-bot` (release builds, found next to this binary) for each bot
//! count and prints one table row per count.
//!
//! ```sh
//! cargo build --release -p ledge-server -p ledge-client -p ledge-load
//! target/release/ledge-load --bots 16,64,256 --duration 60
//! target/release/ledge-load --client thin --bots 256 --duration 300 --csv load.csv
//! ```
//!
//! `ledge-load fleet` runs a local Agones fleet instead: servers under
//! fake SDK sidecars, rooms allocated across them by Agones' rule, bots in
//! every room, and checks that nothing crosses between them
//! (`ledge_load::fleet`):
//!
//! ```sh
//! cargo build --release -p ledge-server --features agones -p ledge-client -p ledge-load
//! target/release/ledge-load fleet --servers 3 --rooms-per-server 2 --bots-per-room 4
//! ```

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{bail, Context};
use clap::{Args, Parser, Subcommand, ValueEnum};
use ledge_load::children::Stop;
use ledge_load::fleet::{run_fleet, FleetConfig, SHUTDOWN_MARGIN};
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
    /// ledge-bot --brain thin-idle: thin bots that hold no button (an
    /// idle room: what quiet players cost).
    ThinIdle,
}

/// Server load benchmark: ledge-server plus ledge-bot on this machine.
#[derive(Debug, Parser)]
#[command(version, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Mode>,
    #[command(flatten)]
    load: LoadArgs,
}

/// Modes other than the load benchmark.
#[derive(Debug, Subcommand)]
enum Mode {
    /// A local Agones fleet: servers under fake SDK sidecars, rooms
    /// allocated across them by Agones' rule for ledge's manifests, bots in
    /// every room; checks the packing, no cross-talk and each server's own
    /// shutdown. Needs ledge-server built with `--features agones`.
    Fleet(FleetArgs),
}

/// `ledge-load fleet`.
#[derive(Debug, Args)]
struct FleetArgs {
    /// Server processes, each with its fake sidecar.
    #[arg(long, default_value_t = 3)]
    servers: usize,
    /// Rooms allocated per server; servers x rooms are allocated. Each
    /// server gets --max-rooms one more (its room-1, open from the start,
    /// takes a place), and its GameServer declares those capacities.
    #[arg(long, default_value_t = 2)]
    rooms_per_server: usize,
    /// Bots per room (the servers' --max-players), one ledge-bot process
    /// per room.
    #[arg(long, default_value_t = 4)]
    bots_per_room: usize,
    /// Brain of the bots (runner, walker, idle, thin); runners must also
    /// reach the goal.
    #[arg(long, default_value = "runner")]
    brain: String,
    /// Measured window, seconds, once every bot is in (after --warmup).
    #[arg(long, default_value_t = 30.0)]
    duration: f64,
    /// Time between the last bot joining and the window, seconds (the
    /// bots then play on until every process's planned end: the unused
    /// part of the allocations' time, --room-timeout per room).
    #[arg(long, default_value_t = 2.0)]
    warmup: f64,
    /// Longest wait for an allocated room to show in its server's sidecar,
    /// seconds.
    #[arg(long, default_value_t = 5.0)]
    room_timeout: f64,
    /// The servers' --agones-shutdown-after, seconds: once allocated and
    /// empty this long, a server shuts itself down (checked).
    #[arg(long, default_value_t = 3.0)]
    shutdown_after: f64,
    /// The servers' --agones-health-every, seconds [default: theirs].
    #[arg(long)]
    health_every: Option<f64>,
    /// Server tick rate, Hz.
    #[arg(long, default_value_t = 60)]
    tick_hz: u32,
    /// Server snapshot rate, Hz.
    #[arg(long, default_value_t = 30)]
    snapshot_hz: u32,
    /// Directory holding ledge-server and ledge-bot (default: this
    /// binary's directory, e.g. target/release).
    #[arg(long, value_name = "DIR")]
    bin_dir: Option<PathBuf>,
    /// Keep the servers' and bots' logs here (default: a temporary
    /// directory, removed at the end).
    #[arg(long, value_name = "DIR")]
    log_dir: Option<PathBuf>,
}

/// The load benchmark (no subcommand).
#[derive(Debug, Args)]
struct LoadArgs {
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
    /// The server's runtime threads (ledge-server --threads; default: one
    /// per core).
    #[arg(long, value_name = "N")]
    server_threads: Option<usize>,
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

/// Runs the chosen mode; `Ok(false)` when a run missed the goal or a check
/// failed.
fn main_result() -> anyhow::Result<bool> {
    let cli = Cli::parse();
    match cli.command {
        Some(Mode::Fleet(args)) => fleet(args),
        None => load(cli.load),
    }
}

/// The directory of the binaries: `--bin-dir`, else this binary's.
fn bin_dir(given: Option<&PathBuf>) -> anyhow::Result<PathBuf> {
    match given {
        Some(dir) => Ok(dir.clone()),
        None => Ok(std::env::current_exe()
            .context("locating this binary")?
            .parent()
            .context("this binary has no directory")?
            .to_path_buf()),
    }
}

/// `--log-dir`, created, else `temp`.
fn log_dir(given: Option<&PathBuf>, temp: &tempfile::TempDir) -> anyhow::Result<PathBuf> {
    match given {
        Some(dir) => {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
            Ok(dir.clone())
        }
        None => Ok(temp.path().to_path_buf()),
    }
}

fn print_machine() {
    let load = procstat::load_average().unwrap_or([f64::NAN; 3]);
    println!(
        "machine: {} cores, {}, load average {:.2} {:.2} {:.2}",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        procstat::cpu_model().unwrap_or_else(|| "unknown CPU".into()),
        load[0],
        load[1],
        load[2]
    );
}

/// A positive (or, with `zero_ok`, non-negative) number of seconds.
fn seconds(value: f64, flag: &str, zero_ok: bool) -> anyhow::Result<Duration> {
    let ok = value.is_finite() && value <= 86_400.0 && (value > 0.0 || (zero_ok && value == 0.0));
    if !ok {
        bail!(
            "{flag} must be {} seconds, at most 86400 (got {value})",
            if zero_ok { "0 or more" } else { "more than 0" }
        );
    }
    Ok(Duration::from_secs_f64(value))
}

/// `ledge-load fleet`: `Ok(false)` when a check failed.
fn fleet(args: FleetArgs) -> anyhow::Result<bool> {
    let bin_dir = bin_dir(args.bin_dir.as_ref())?;
    for bin in ["ledge-server", BOT_BINARY] {
        let path = bin_dir.join(bin);
        if !path.is_file() {
            bail!(
                "{} not found: build it first with `cargo build --release -p ledge-server \
                 --features agones -p ledge-client -p ledge-load`, or pass --bin-dir",
                path.display()
            );
        }
    }
    let config = FleetConfig {
        servers: args.servers,
        rooms_per_server: args.rooms_per_server,
        bots_per_room: args.bots_per_room,
        brain: args.brain.clone(),
        duration: seconds(args.duration, "--duration", false)?,
        warmup: seconds(args.warmup, "--warmup", true)?,
        room_timeout: seconds(args.room_timeout, "--room-timeout", false)?,
        shutdown_after: seconds(args.shutdown_after, "--shutdown-after", true)?,
        health_every: args
            .health_every
            .map(|h| seconds(h, "--health-every", false))
            .transpose()?,
        tick_hz: args.tick_hz,
        snapshot_hz: args.snapshot_hz,
        bin_dir: bin_dir.clone(),
        log_dir: PathBuf::new(),
    };
    config.validate()?;
    let temp = tempfile::tempdir().context("creating a log directory")?;
    let config = FleetConfig {
        log_dir: log_dir(args.log_dir.as_ref(), &temp)?,
        ..config
    };
    let stop = Stop::install()?;
    print_machine();
    println!(
        "fleet: {} servers x {} rooms x {} bots (ledge-bot --brain {}), fake Agones sidecars, \
         --agones-shutdown-after {} s; window {} s; {} Hz ticks, {} Hz snapshots; binaries in {}",
        config.servers,
        config.rooms_per_server,
        config.bots_per_room,
        config.brain,
        args.shutdown_after,
        args.duration,
        config.tick_hz,
        config.snapshot_hz,
        bin_dir.display()
    );
    let report = run_fleet(&config, &stop)?;
    println!(
        "\nwindow {:.1} s, load average {:.2} at its start, {:.2} at its end\n",
        report.window_s, report.load.0, report.load.1
    );
    print!("{}", report.markdown());
    println!(
        "\nshutdown allowed: --agones-shutdown-after {} s + {} s margin after the last bot left",
        args.shutdown_after,
        SHUTDOWN_MARGIN.as_secs()
    );
    if report.passed() {
        println!(
            "all checks passed: packed allocation, the fleet full after {} rooms, no cross-talk, \
             every bot in its room{}, every server shut itself down",
            config.rooms(),
            if config.brain == "runner" {
                " and at the goal"
            } else {
                ""
            }
        );
    } else {
        println!("\n{} check(s) failed:", report.problems.len());
        for p in &report.problems {
            println!("  {p}");
        }
    }
    drop(temp);
    Ok(report.passed())
}

/// Runs every count; `Ok(false)` when a run missed the goal.
fn load(cli: LoadArgs) -> anyhow::Result<bool> {
    if cli.bots.is_empty() || cli.bots.contains(&0) {
        bail!("--bots needs counts of at least 1");
    }
    if !(cli.duration > 0.0 && cli.warmup >= 0.0) {
        bail!("--duration must be positive and --warmup not negative");
    }
    let bin_dir = bin_dir(cli.bin_dir.as_ref())?;
    let client = match cli.client {
        Client::Bot => ClientKind::Bot,
        Client::Thin => ClientKind::Thin,
        Client::ThinIdle => ClientKind::ThinIdle,
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
    let log_dir = log_dir(cli.log_dir.as_ref(), &temp)?;
    let stop = Stop::install()?;

    print_machine();
    println!(
        "server: {} Hz ticks, {} Hz snapshots, {} players per room, {}; bots: {}; \
         window {} s after {} s of warm-up; binaries in {}",
        cli.tick_hz,
        cli.snapshot_hz,
        cli.max_players,
        match cli.server_threads {
            Some(1) => "one thread".to_owned(),
            Some(n) => format!("{n} threads"),
            None => "a thread per core".to_owned(),
        },
        match cli.client {
            Client::Bot => format!("ledge-bot --brain {}", cli.brain),
            Client::Thin => "ledge-bot --brain thin".to_owned(),
            Client::ThinIdle => "ledge-bot --brain thin-idle".to_owned(),
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
            server_threads: cli.server_threads,
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
        let per_player = r.cpu_ms_per_player_s();
        println!(
            "{} bots: {:.2} ms of server CPU per player-second: {:.0} players per core \
             (wire per client: {:.0} B/s up, {:.0} B/s down)",
            r.bots,
            per_player,
            1000.0 / per_player.max(1e-9),
            r.wire_up_bytes_per_client_s,
            r.wire_down_bytes_per_client_s,
        );
    }
    if let Some(path) = &cli.csv {
        std::fs::write(path, csv(&results))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    drop(temp);
    Ok(all_met)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(args: &[&str]) -> Result<Cli, clap::Error> {
        Cli::try_parse_from(std::iter::once("ledge-load").chain(args.iter().copied()))
    }

    #[test]
    fn the_load_benchmark_parses_as_before() {
        let cli = parse(&["--client", "thin", "--bots", "16,64", "--duration", "30"]).unwrap();
        assert!(cli.command.is_none());
        assert_eq!(cli.load.bots, [16, 64]);
        assert_eq!(cli.load.client, Client::Thin);
        assert_eq!(cli.load.duration, 30.0);
        let cli = parse(&[]).unwrap();
        assert_eq!(cli.load.bots, [16, 64, 256]);
    }

    #[test]
    fn fleet_is_a_subcommand_with_its_own_flags() {
        let cli = parse(&["fleet"]).unwrap();
        let Some(Mode::Fleet(f)) = cli.command else {
            panic!("not the fleet mode");
        };
        assert_eq!((f.servers, f.rooms_per_server, f.bots_per_room), (3, 2, 4));
        assert_eq!((f.duration, f.shutdown_after), (30.0, 3.0));
        let cli = parse(&["fleet", "--servers", "2", "--brain", "walker"]).unwrap();
        let Some(Mode::Fleet(f)) = cli.command else {
            panic!("not the fleet mode");
        };
        assert_eq!((f.servers, f.brain.as_str()), (2, "walker"));
        // The two modes' flags do not mix.
        assert!(parse(&["--bots", "16", "fleet"]).is_err());
        assert!(parse(&["fleet", "--bots", "16"]).is_err());
        assert!(parse(&["fleet", "--servers", "three"]).is_err());
    }

    #[test]
    fn seconds_must_be_sensible() {
        assert_eq!(
            seconds(1.5, "--duration", false).unwrap(),
            Duration::from_millis(1500)
        );
        assert_eq!(seconds(0.0, "--warmup", true).unwrap(), Duration::ZERO);
        for (v, zero_ok) in [
            (0.0, false),
            (-1.0, true),
            (f64::NAN, true),
            (f64::INFINITY, true),
            (1e9, true),
        ] {
            let e = seconds(v, "--duration", zero_ok).unwrap_err().to_string();
            assert!(e.contains("--duration"), "{e}");
        }
    }
}
