//! The native `ledge-bot`: its command line and the bots' run.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, ValueEnum};
use ledge_client::bot::{
    connect_and_run, misbehave, run_thin, run_thin_with, BotOptions, Brain, Idle, Misbehavior,
    RandomWalker, Runner,
};
use ledge_client::net::bundle::LevelCache;
use ledge_client::net::transport::resolve;
use ledge_client::net::trust::{KnownHosts, Trust};
use ledge_client::Fingerprint;
use ledge_levels::default_route;
use ledge_shared::input::Buttons;

/// Which brain the bots run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum BrainKind {
    /// Follows the default level's route to the goal.
    Runner,
    /// Holds nothing.
    Idle,
    /// Random buttons (seeded).
    Walker,
    /// The walker's buttons without prediction: thin clients for load
    /// generation (one input per tick, every snapshot decoded).
    Thin,
    /// A thin client holding nothing: what an idle player costs.
    ThinIdle,
    /// Abuses the protocol (see --mode).
    Misbehave,
}

/// Headless ledge bots.
#[derive(Debug, Parser)]
#[command(version)]
struct Cli {
    /// Server address, HOST:PORT.
    #[arg(long, value_name = "HOST:PORT")]
    connect: String,
    /// SHA-256 fingerprint of the server certificate (else trust on first
    /// use with --known-hosts).
    #[arg(long, value_name = "HEX")]
    cert_hash: Option<Fingerprint>,
    /// Known-hosts file for trust on first use.
    #[arg(long, value_name = "PATH")]
    known_hosts: Option<PathBuf>,
    /// Number of bots.
    #[arg(long, default_value_t = 1)]
    count: usize,
    /// What they do.
    #[arg(long, value_enum, default_value_t = BrainKind::Runner)]
    brain: BrainKind,
    /// How long they play, seconds.
    #[arg(long, default_value_t = 30.0)]
    seconds: f64,
    /// Misbehaviors, comma separated, cycled over the bots (garbage,
    /// oversized, flood, garbage-datagrams, stale, future, version; default
    /// all).
    #[arg(long, value_delimiter = ',')]
    mode: Vec<String>,
    /// Seed of the random walkers and misbehavers.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Room to join (default: the server picks).
    #[arg(long)]
    room: Option<String>,
    /// A copy of the server's level file. Without it the server's level is
    /// downloaded (or found in the cache, or embedded).
    #[arg(long, value_name = "PATH")]
    level: Option<PathBuf>,
    /// Where downloaded levels are cached [default:
    /// $XDG_CACHE_HOME/ledge/levels or ~/.cache/ledge/levels].
    #[arg(long, value_name = "DIR")]
    level_cache: Option<PathBuf>,
    /// Name prefix (bots are PREFIX-1, PREFIX-2, ...).
    #[arg(long, default_value = "bot")]
    name: String,
    /// Runners leave when they reach the goal (the first: on a server
    /// rotating levels they do not wait for the next).
    #[arg(long)]
    stop_at_goal: bool,
    /// Input margin kept with no jitter, ticks (more tolerates a loaded
    /// machine: many bots planning at once).
    #[arg(long, value_name = "TICKS")]
    margin: Option<f64>,
    /// Vote for the level at index N of the server's level list (0 is the
    /// first) once the list arrives; each bot's line says how it went.
    #[arg(long, value_name = "N")]
    vote: Option<u32>,
}

/// Runs the bots the command line asks for.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let runtime = match tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
    {
        Ok(r) => r,
        Err(e) => {
            eprintln!("ledge-bot: cannot start the runtime: {e}");
            return ExitCode::FAILURE;
        }
    };
    runtime.block_on(run(cli))
}

async fn run(cli: Cli) -> ExitCode {
    let trust = Trust::from_args(cli.cert_hash, cli.known_hosts.clone());
    let duration = Duration::from_secs_f64(cli.seconds.max(0.0));
    if cli.brain == BrainKind::Misbehave {
        return run_misbehavers(&cli, &trust, duration).await;
    }
    let mut tasks = Vec::new();
    for i in 0..cli.count {
        let seed = cli.seed.wrapping_add(i as u64);
        // No brain: a thin bot, walking without prediction.
        let brain: Option<Box<dyn Brain>> = match cli.brain {
            BrainKind::Runner => Some(Box::new(Runner::new(default_route()))),
            BrainKind::Idle => Some(Box::new(Idle)),
            BrainKind::Walker => Some(Box::new(RandomWalker::new(seed))),
            BrainKind::Thin | BrainKind::ThinIdle => None,
            BrainKind::Misbehave => unreachable!("handled above"),
        };
        let options = BotOptions {
            room: cli.room.clone(),
            stop_when_done: cli.stop_at_goal,
            level: cli.level.clone(),
            level_cache: cli.level_cache.clone().or_else(LevelCache::default_dir),
            min_margin: cli.margin,
            vote: cli.vote,
            ..BotOptions::new(&format!("{}-{}", cli.name, i + 1), duration)
        };
        let server = cli.connect.clone();
        let trust = trust.clone();
        let idle = cli.brain == BrainKind::ThinIdle;
        tasks.push(tokio::spawn(async move {
            match brain {
                Some(mut brain) => connect_and_run(&server, &trust, brain.as_mut(), &options).await,
                None if idle => {
                    run_thin_with(&server, &trust, &mut || Buttons::NONE, &options).await
                }
                None => run_thin(&server, &trust, &mut RandomWalker::new(seed), &options).await,
            }
        }));
        // Stagger the joins a little (the first one may store the host key).
        tokio::time::sleep(Duration::from_millis(if i == 0 { 300 } else { 20 })).await;
    }
    let mut failed = 0;
    let mut goals = 0;
    println!("{} bots, brain {:?}:", cli.count, cli.brain);
    for task in tasks {
        match task.await {
            Ok(report) => {
                failed += usize::from(report.ended.is_some() && report.ticks == 0);
                goals += usize::from(report.won);
                println!("{report}");
            }
            Err(e) => {
                failed += 1;
                println!("a bot task failed: {e}");
            }
        }
    }
    if cli.brain == BrainKind::Runner {
        println!(
            "{goals}/{} reached the goal (as the server saw it)",
            cli.count
        );
    }
    if failed > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

async fn run_misbehavers(cli: &Cli, trust: &Trust, duration: Duration) -> ExitCode {
    let modes: Vec<Misbehavior> = if cli.mode.is_empty() {
        Misbehavior::ALL.to_vec()
    } else {
        match cli.mode.iter().map(|m| m.parse()).collect() {
            Ok(m) => m,
            Err(e) => {
                eprintln!("ledge-bot: {e}");
                return ExitCode::FAILURE;
            }
        }
    };
    let (addr, _) = match resolve(&cli.connect).await {
        Ok(a) => a,
        Err(e) => {
            eprintln!("ledge-bot: {e}");
            return ExitCode::FAILURE;
        }
    };
    let fingerprint = match trust {
        Trust::Pinned(pin) => *pin,
        Trust::KnownHosts(path) => match KnownHosts::load(path) {
            Ok(known) => match known.get(&cli.connect) {
                Some(k) => k.fingerprint,
                None => {
                    eprintln!(
                        "ledge-bot: misbehaving bots need --cert-hash (or {} in {})",
                        cli.connect,
                        path.display()
                    );
                    return ExitCode::FAILURE;
                }
            },
            Err(e) => {
                eprintln!("ledge-bot: {e}");
                return ExitCode::FAILURE;
            }
        },
    };
    let mut tasks = Vec::new();
    for i in 0..cli.count {
        let mode = modes[i % modes.len()];
        let name = format!("{}-{}", cli.name, i + 1);
        let seed = cli.seed.wrapping_add(i as u64);
        tasks.push(tokio::spawn(async move {
            misbehave(addr, fingerprint, &name, mode, duration, seed).await
        }));
    }
    println!("{} misbehaving bots:", cli.count);
    for task in tasks {
        match task.await {
            Ok(report) => println!("{report}"),
            Err(e) => println!("a bot task failed: {e}"),
        }
    }
    ExitCode::SUCCESS
}
