//! `ledge-load fleet`: a local Agones fleet (issue 17). S release
//! `ledge-server --agones` processes, each beside a fake SDK sidecar of its
//! own (`ledge-agones-fake`, in this process), get rooms allocated one by
//! one with Agones' allocation rule for ledge's manifests
//! ([`ledge_agones_fake::allocate`]); each allocated room gets a
//! `ledge-bot` process of K bots joining it by name on the chosen server.
//!
//! The run:
//!
//! 1. starts the sidecars (declaring Counter `rooms` = R + 1, Counter
//!    `players` = (R + 1)×K and List `rooms` = R + 1, as the GameServer
//!    spec does: `room-1`, open from the start, takes a place) and the
//!    servers (`--max-rooms R+1 --max-players K`, `AGONES_SDK_GRPC_PORT` =
//!    their sidecar's port); waits for each to say `Ready` and reads its
//!    fingerprint from the `ledge-cert-sha256` annotation, as a matchmaker
//!    would;
//! 2. allocates S×R rooms with `Want::AnyRoom`, one at a time: a fresh room
//!    name ([`room_name`]), a bot process joining it, and a wait until the
//!    chosen server's sidecar lists the room and its `rooms` count went up;
//!    then checks the allocations were packed ([`expected_packing`]) and
//!    that one more finds no server;
//! 3. once every bot is in and after a warm-up, measures a window of
//!    play (CPU, peak memory, tick histogram, snapshots, bytes, health
//!    pings) and checks for cross-talk at its end ([`metrics_problems`],
//!    [`list_problems`], counters, `Want::Room`); every bot process plays
//!    until the same planned end (the allocations are given
//!    [`FleetConfig::room_timeout`] each, what they leave unused is spent
//!    after the window), then its reports are checked;
//! 4. once the bots have left, checks that every server, Allocated and
//!    empty, calls `Shutdown` and exits by itself in time.
//!
//! Checks that fail are collected in [`FleetReport::problems`]; what makes
//! the rest meaningless (a server that does not start, a room that never
//! appears) is an error.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use ledge_agones_fake::{allocate, Call, FakeSidecar, Want};

use crate::children::{log_file, tail, Guarded, Lines, Stop};
use crate::procstat;
use crate::prom::{scrape, Scrape};
use crate::run::BOT_BINARY;

/// The Counter of rooms in use, and the List of room names (as the
/// server's `fleet::ROOMS`).
pub const ROOMS: &str = "rooms";
/// The Counter of players (as the server's `fleet::PLAYERS`).
pub const PLAYERS: &str = "players";
/// The annotation holding the certificate's fingerprint (as the server's
/// `fleet::CERT_ANNOTATION`; the sidecar stores it with its prefix).
pub const CERT_ANNOTATION: &str = "ledge-cert-sha256";
/// The server's per-room players gauge (`server/src/metrics.rs`).
pub const PLAYERS_GAUGE: &str = "ledge_players";
/// The room every server opens at start (`--rooms 1`) and never closes.
pub const START_ROOM: &str = "room-1";

/// The `ledge-bot --brain`s that play a room (not `misbehave`).
pub const BRAINS: [&str; 4] = ["runner", "walker", "idle", "thin"];

/// How long a server has to print its address and fingerprint.
const SERVER_START_TIMEOUT: Duration = Duration::from_secs(30);
/// How long a server has to say `Ready` once it printed them.
const READY_TIMEOUT: Duration = Duration::from_secs(30);
/// How often waits poll the sidecars and the children.
const POLL: Duration = Duration::from_millis(50);
/// How often the window checks that every child still runs.
const CHECK_EVERY: Duration = Duration::from_secs(1);
/// Bots play this long after the window, so that none leaves before the
/// last readings and checks.
const BOT_TAIL: Duration = Duration::from_secs(4);
/// How long bot processes have to print their reports after their time.
const BOT_EXIT_GRACE: Duration = Duration::from_secs(30);
/// Allowed beyond `--agones-shutdown-after` between a server's last
/// player leaving and the process exiting: the SDK driver's poll (250 ms),
/// the sidecar's view of the players count (one poll late) and the drain.
pub const SHUTDOWN_MARGIN: Duration = Duration::from_secs(5);
/// How much sooner than `--agones-shutdown-after` a `Shutdown` may come
/// after the sidecar saw the players count reach 0: that count arrives a
/// few SDK calls into the driver's poll, the `Shutdown` first in its poll.
pub const SHUTDOWN_EARLY_TOLERANCE: Duration = Duration::from_millis(500);

/// What a fleet run does.
#[derive(Debug, Clone)]
pub struct FleetConfig {
    /// Server processes (S).
    pub servers: usize,
    /// Rooms allocated per server (R). Its `--max-rooms` (and the
    /// capacities declared) is R + 1: `room-1`, open from the start, takes
    /// a place, and the server's `rooms` counter counts it.
    pub rooms_per_server: usize,
    /// Bots per room (K): `--max-players`, one `ledge-bot` process each
    /// room.
    pub bots_per_room: usize,
    /// Brain of the bots (`ledge-bot --brain`); `runner` bots must also
    /// reach the goal.
    pub brain: String,
    /// The measured window.
    pub duration: Duration,
    /// Time between the last bot joining and the window.
    pub warmup: Duration,
    /// Longest wait for an allocated room to show in its server's sidecar.
    pub room_timeout: Duration,
    /// `--agones-shutdown-after` of the servers.
    pub shutdown_after: Duration,
    /// `--agones-health-every` of the servers (`None`: their default).
    pub health_every: Option<Duration>,
    /// Server tick rate, Hz.
    pub tick_hz: u32,
    /// Server snapshot rate, Hz.
    pub snapshot_hz: u32,
    /// Where `ledge-server` and `ledge-bot` are.
    pub bin_dir: PathBuf,
    /// Where the logs go.
    pub log_dir: PathBuf,
}

impl FleetConfig {
    /// Rooms allocated in all (S×R).
    pub fn rooms(&self) -> usize {
        self.servers * self.rooms_per_server
    }

    /// Checks the numbers, with what to change.
    pub fn validate(&self) -> anyhow::Result<()> {
        if !(1..=16).contains(&self.servers) {
            bail!("--servers must be 1..=16");
        }
        if !(1..=64).contains(&self.rooms_per_server) {
            bail!("--rooms-per-server must be 1..=64");
        }
        if !(1..=64).contains(&self.bots_per_room) {
            bail!("--bots-per-room must be 1..=64");
        }
        if !BRAINS.contains(&self.brain.as_str()) {
            bail!(
                "--brain {:?}: the bots' brain must be one of {}",
                self.brain,
                BRAINS.join(", ")
            );
        }
        if self.duration.is_zero() {
            bail!("--duration must be positive");
        }
        if self.room_timeout.is_zero() {
            bail!("--room-timeout must be positive");
        }
        if self.shutdown_after > Duration::from_secs(600) {
            bail!("--shutdown-after must be at most 600 s (the run waits for it)");
        }
        Ok(())
    }

    fn runner(&self) -> bool {
        self.brain == "runner"
    }
}

/// The fresh name of the `index`-th allocated room (0-based): `fleet-01`,
/// `fleet-02`, ...
pub fn room_name(index: usize) -> String {
    format!("fleet-{:02}", index + 1)
}

/// The bots' name prefix for the `index`-th allocation: `b01` (bots
/// `b01-1`, `b01-2`, ...), unique across the fleet even when rooms share a
/// name (`room-1` on each server).
pub fn bot_prefix(index: usize) -> String {
    format!("b{:02}", index + 1)
}

/// Where the allocation rule must put S×R rooms, one after the other, on
/// servers of R rooms each: packed, server 0 first (the fullest Allocated
/// server with a free room, else the first Ready one).
pub fn expected_packing(servers: usize, rooms_per_server: usize) -> Vec<usize> {
    (0..servers * rooms_per_server)
        .map(|i| i / rooms_per_server.max(1))
        .collect()
}

/// Players per room in a scrape of a server's metrics
/// ([`PLAYERS_GAUGE`]).
pub fn room_players(scrape: &Scrape) -> BTreeMap<String, u64> {
    scrape
        .samples
        .iter()
        .filter(|s| s.name == PLAYERS_GAUGE)
        .filter_map(|s| Some((s.label("room")?.to_owned(), s.value.max(0.0) as u64)))
        .collect()
}

/// Whether `room` is a start-up room (`room-1`, `room-2`, ...), open on
/// every server whether or not it was allocated.
pub fn is_start_room(room: &str) -> bool {
    room.strip_prefix("room-")
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
}

/// Cross-talk in one server's per-room players: each room allocated to it
/// (`expected`) must hold exactly `per_room` players, and no other room
/// may hold any or exist at all (a start-up room, empty, excepted).
/// Returns what is wrong, naming `server`.
pub fn metrics_problems(
    server: &str,
    expected: &[String],
    per_room: u64,
    actual: &BTreeMap<String, u64>,
) -> Vec<String> {
    let mut problems = Vec::new();
    for room in expected {
        match actual.get(room) {
            Some(&n) if n == per_room => {}
            Some(&n) => problems.push(format!(
                "{server}: room {room} has {n} players in its metrics, not {per_room}"
            )),
            None => problems.push(format!("{server}: room {room} is not in its metrics")),
        }
    }
    for (room, &n) in actual {
        if expected.contains(room) {
            continue;
        }
        if n > 0 {
            problems.push(format!(
                "{server}: room {room}, not allocated to it, has {n} players (cross-talk)"
            ));
        } else if !is_start_room(room) {
            problems.push(format!(
                "{server}: room {room}, not allocated to it, is open (cross-talk)"
            ));
        }
    }
    problems
}

/// Cross-talk in one server's `rooms` List: exactly the rooms allocated to
/// it, plus its start-up rooms. Returns what is wrong, naming `server`.
pub fn list_problems(server: &str, expected: &[String], list: &[String]) -> Vec<String> {
    let mut problems = Vec::new();
    let listed: BTreeSet<&String> = list.iter().collect();
    for room in expected {
        if !listed.contains(room) {
            problems.push(format!("{server}: room {room} is not in its rooms list"));
        }
    }
    for room in &listed {
        if !expected.contains(room) && !is_start_room(room) {
            problems.push(format!(
                "{server}: its rooms list holds {room}, not allocated to it (cross-talk)"
            ));
        }
    }
    if listed.len() != list.len() {
        problems.push(format!("{server}: its rooms list repeats a name: {list:?}"));
    }
    problems
}

/// One bot's closing line (`ledge-bot`'s report).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct BotLine {
    /// Its name (`b01-3`).
    pub name: String,
    /// Its player id, if it joined.
    pub player: Option<u32>,
    /// Local ticks run.
    pub ticks: u64,
    /// Snapshots received.
    pub snapshots: u64,
    /// Snapshots that differed from its prediction.
    pub mispredictions: u64,
    /// The server saw it at the goal.
    pub goal: bool,
    /// Why it stopped early, if it did.
    pub ended: Option<String>,
}

/// The token after the first `key` among `tokens`.
fn after<'a>(tokens: &[&'a str], key: &str) -> Option<&'a str> {
    let i = tokens.iter().position(|t| *t == key)?;
    tokens.get(i + 1).copied()
}

/// The report lines of the bots named `PREFIX-N` in a `ledge-bot`
/// process's output, in order. Other lines are skipped; a report line
/// whose fields cannot be read has them at their defaults.
pub fn parse_bot_lines(output: &str, prefix: &str) -> Vec<BotLine> {
    let mut bots = Vec::new();
    for line in output.lines() {
        let Some(name) = line.split_whitespace().next() else {
            continue;
        };
        let ours = name
            .strip_prefix(prefix)
            .and_then(|rest| rest.strip_prefix('-'))
            .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
        if !ours {
            continue;
        }
        let (fields, ended) = match line.split_once("  ended: ") {
            Some((fields, why)) => (fields, Some(why.trim().to_owned())),
            None => (line, None),
        };
        // The progress note (`[...]`) is free text: not read.
        let fields = fields.split("  [").next().unwrap_or(fields);
        let tokens: Vec<&str> = fields.split_whitespace().collect();
        let number = |key: &str| -> u64 {
            after(&tokens, key)
                .and_then(|t| t.trim_end_matches(')').parse().ok())
                .unwrap_or(0)
        };
        bots.push(BotLine {
            name: name.to_owned(),
            // `#7`, or `-` for a bot that never joined.
            player: after(&tokens, "player").and_then(|t| t.trim_start_matches('#').parse().ok()),
            ticks: number("ticks"),
            snapshots: number("snapshots"),
            mispredictions: number("mispredicted"),
            goal: after(&tokens, "goal") == Some("reached"),
            ended,
        });
    }
    bots
}

/// What is wrong with one bot process's reports: `count` bots expected,
/// each joined, none ended early, and (`need_goal`) each at the goal.
pub fn bot_problems(what: &str, lines: &[BotLine], count: usize, need_goal: bool) -> Vec<String> {
    let mut problems = Vec::new();
    if lines.len() != count {
        problems.push(format!("{what}: {} bot reports, not {count}", lines.len()));
    }
    for b in lines {
        if b.player.is_none() {
            problems.push(format!(
                "{what}: {} did not join ({})",
                b.name,
                b.ended.as_deref().unwrap_or("no reason given")
            ));
        } else if let Some(why) = &b.ended {
            problems.push(format!("{what}: {} ended early: {why}", b.name));
        } else if need_goal && !b.goal {
            problems.push(format!(
                "{what}: {} did not reach the goal (as the server saw it)",
                b.name
            ));
        }
    }
    problems
}

/// One allocation, in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Allocation {
    /// The room.
    pub room: String,
    /// The server the rule chose (0-based).
    pub server: usize,
    /// The server the packing says (0-based).
    pub expected: usize,
    /// From the allocation to the room in the sidecar (listed, counted).
    pub shown_after: Duration,
}

/// One server's figures over the window.
#[derive(Debug, Clone, PartialEq)]
pub struct ServerFigures {
    /// `gs-1`, `gs-2`...
    pub name: String,
    /// Its QUIC address.
    pub addr: SocketAddr,
    /// Rooms allocated to it.
    pub rooms: Vec<String>,
    /// Players in its metrics at the window's end.
    pub players: u64,
    /// CPU, percent of one core.
    pub cpu_pct: f64,
    /// Peak resident memory, MiB.
    pub peak_rss_mib: f64,
    /// Ticks in the window, all rooms.
    pub ticks: u64,
    /// Median tick, seconds.
    pub tick_p50: Option<f64>,
    /// 99th percentile tick, seconds.
    pub tick_p99: Option<f64>,
    /// Ticks skipped.
    pub missed_ticks: u64,
    /// Snapshots sent per second, all clients.
    pub snapshots_per_s: f64,
    /// Bytes sent per second, all clients (payload).
    pub down_bytes_per_s: f64,
    /// Health pings the sidecar received per second.
    pub health_per_s: f64,
}

/// One bot process's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct BotFigures {
    /// Its room.
    pub room: String,
    /// Its server (0-based).
    pub server: usize,
    /// Bots asked for.
    pub bots: usize,
    /// Bots that joined.
    pub joined: usize,
    /// Bots the server saw at the goal.
    pub goals: usize,
    /// Mispredicted snapshots, all its bots.
    pub mispredictions: u64,
    /// CPU over the window, percent of one core.
    pub cpu_pct: f64,
}

/// How one server ended.
#[derive(Debug, Clone, PartialEq)]
pub struct ShutdownFigures {
    /// `gs-1`...
    pub name: String,
    /// From its players count reaching 0 (as the sidecar saw it) to its
    /// `Shutdown` call.
    pub empty_to_shutdown: Option<Duration>,
    /// From its last bot process exiting to the process exiting.
    pub left_to_exit: Option<Duration>,
    /// Its exit status, or why there is none.
    pub exit: String,
}

/// What a fleet run saw.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetReport {
    /// Servers (S).
    pub servers: usize,
    /// Rooms per server (R).
    pub rooms_per_server: usize,
    /// Bots per room (K).
    pub bots_per_room: usize,
    /// The bots' brain (thin bots do not predict: no mispredictions).
    pub brain: String,
    /// The window, seconds (measured).
    pub window_s: f64,
    /// The allocations, in order.
    pub allocations: Vec<Allocation>,
    /// What one more allocation found (`None`: no server, as it must).
    pub one_more: Option<usize>,
    /// Per server.
    pub server_figures: Vec<ServerFigures>,
    /// Per bot process, in allocation order.
    pub bot_figures: Vec<BotFigures>,
    /// Per server, at the end.
    pub shutdowns: Vec<ShutdownFigures>,
    /// Checks that failed.
    pub problems: Vec<String>,
    /// 1-minute load average at the window's start and end.
    pub load: (f64, f64),
}

fn ms(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_owned(), |s| format!("{:.3}", s * 1e3))
}

fn secs(d: Option<Duration>) -> String {
    d.map_or_else(|| "-".to_owned(), |d| format!("{:.2}", d.as_secs_f64()))
}

impl FleetReport {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.problems.is_empty()
    }

    /// The figures as Markdown: the servers, the allocation order, the bot
    /// processes and the shutdowns.
    pub fn markdown(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "| server | rooms | players | CPU % | peak RSS MiB | tick p50 ms | tick p99 ms | \
             missed ticks | snapshots/s | down KB/s | health pings/s |"
        );
        let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
        for f in &self.server_figures {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.0} | {:.1} | {} | {} | {} | {:.0} | {:.1} | {:.2} |",
                f.name,
                f.rooms.join(", "),
                f.players,
                f.cpu_pct,
                f.peak_rss_mib,
                ms(f.tick_p50),
                ms(f.tick_p99),
                f.missed_ticks,
                f.snapshots_per_s,
                f.down_bytes_per_s / 1000.0,
                f.health_per_s
            );
        }
        let _ = writeln!(s);
        let _ = writeln!(
            s,
            "| allocation | room | server (rule) | server (packed) | shown in sidecar after s |"
        );
        let _ = writeln!(s, "|---:|---|---|---|---:|");
        for (i, a) in self.allocations.iter().enumerate() {
            let _ = writeln!(
                s,
                "| {} | {} | gs-{} | gs-{} | {:.2} |",
                i + 1,
                a.room,
                a.server + 1,
                a.expected + 1,
                a.shown_after.as_secs_f64()
            );
        }
        let _ = writeln!(
            s,
            "| {} | (one more) | {} | none (full) | - |",
            self.allocations.len() + 1,
            self.one_more
                .map_or_else(|| "none".to_owned(), |i| format!("gs-{}", i + 1))
        );
        let _ = writeln!(s);
        let _ = writeln!(
            s,
            "| bot process | server | bots | joined | at the goal | mispredictions | CPU % |"
        );
        let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|");
        for b in &self.bot_figures {
            let _ = writeln!(
                s,
                "| {} | gs-{} | {} | {} | {} | {} | {:.0} |",
                b.room,
                b.server + 1,
                b.bots,
                b.joined,
                b.goals,
                if self.brain == "thin" {
                    "-".to_owned()
                } else {
                    b.mispredictions.to_string()
                },
                b.cpu_pct
            );
        }
        let _ = writeln!(s);
        let _ = writeln!(
            s,
            "| server | empty → Shutdown s | last bot gone → exit s | exit |"
        );
        let _ = writeln!(s, "|---|---:|---:|---|");
        for d in &self.shutdowns {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} |",
                d.name,
                secs(d.empty_to_shutdown),
                secs(d.left_to_exit),
                d.exit
            );
        }
        s
    }
}

/// A server with its sidecar.
struct Member {
    name: String,
    sidecar: FakeSidecar,
    child: Guarded,
    addr: SocketAddr,
    metrics: SocketAddr,
    fingerprint: String,
    log: PathBuf,
    _lines: Lines,
    _cert_dir: tempfile::TempDir,
}

/// A `ledge-bot` process playing one allocated room.
struct BotProcess {
    room: String,
    prefix: String,
    server: usize,
    child: Guarded,
    out: PathBuf,
    err: PathBuf,
    exited_at: Option<Instant>,
}

/// What a server's log (stderr) says about why it stopped: its own
/// message (`ledge-server: ...`, e.g. that it lacks the `agones` feature
/// and how to build it), or that it does not know `--agones` at all;
/// `None` when it says neither.
pub fn failure_in_log(text: &str) -> Option<String> {
    if text.contains("unexpected argument '--agones'") {
        return Some(
            "this ledge-server does not know --agones (a build older than Agones support): \
             build it with `cargo build --release -p ledge-server --features agones`"
                .to_owned(),
        );
    }
    let own: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("ledge-server: "))
        .collect();
    (!own.is_empty()).then(|| own.join("\n"))
}

/// [`failure_in_log`] of the log file, else its tail.
fn server_failure(log: &Path) -> String {
    let text = std::fs::read_to_string(log).unwrap_or_default();
    failure_in_log(&text).unwrap_or_else(|| format!("its log:\n{}", tail(log, 20)))
}

fn start_member(config: &FleetConfig, index: usize, stop: &Stop) -> anyhow::Result<Member> {
    let name = format!("gs-{}", index + 1);
    // room-1, open from the start, takes one of the --max-rooms places.
    let places = config.rooms_per_server as i64 + 1;
    let k = config.bots_per_room as i64;
    let sidecar = FakeSidecar::start(
        &format!("ledge-fleet-{}", index + 1),
        &[(ROOMS, places), (PLAYERS, places * k)],
        &[(ROOMS, places)],
    )
    .with_context(|| format!("starting the fake Agones sidecar of {name}"))?;
    let cert_dir = tempfile::tempdir().context("creating a certificate directory")?;
    let log = config.log_dir.join(format!("fleet-{name}.log"));
    let out = config.log_dir.join(format!("fleet-{name}.out"));
    let clients = (config.rooms_per_server * config.bots_per_room + 16).to_string();
    let mut command = Command::new(config.bin_dir.join("ledge-server"));
    command
        .arg("--agones")
        .args([
            "--agones-shutdown-after",
            &format!("{}", config.shutdown_after.as_secs_f64()),
        ])
        .args(["--bind", "127.0.0.1:0", "--metrics-bind", "127.0.0.1:0"])
        .arg("--cert-dir")
        .arg(cert_dir.path())
        .args(["--tick-rate", &config.tick_hz.to_string()])
        .args(["--snapshot-rate", &config.snapshot_hz.to_string()])
        .args(["--max-rooms", &places.to_string()])
        .args(["--max-players", &config.bots_per_room.to_string()])
        .args(["--max-connections", &clients])
        // Every bot connects from this machine's one address.
        .args(["--max-per-address", &clients])
        .args([
            "--max-pending-per-address",
            &clients,
            "--max-pending",
            &clients,
        ])
        .env("AGONES_SDK_GRPC_PORT", sidecar.port().to_string())
        .env("RUST_LOG", "info")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(log_file(&log)?);
    if let Some(every) = config.health_every {
        command.args(["--agones-health-every", &format!("{}", every.as_secs_f64())]);
    }
    let mut child = Guarded::spawn(&format!("ledge-server {name}"), &mut command)?;
    let lines = Lines::spawn(child.take_stdout().context("server stdout")?, &out)?;
    let mut wait = |prefix: &str| -> anyhow::Result<String> {
        match lines.wait_for(SERVER_START_TIMEOUT, stop, |l| l.starts_with(prefix)) {
            Ok(line) => Ok(line[prefix.len()..].trim().to_owned()),
            Err(e) => {
                stop.check()?;
                // Gone: say why, in its own words.
                if child.wait_timeout(Duration::from_secs(2), stop)?.is_some() {
                    bail!("{name} could not start: {}", server_failure(&log));
                }
                Err(e).with_context(|| {
                    format!(
                        "waiting for {name}'s {prefix:?} line; its log:\n{}",
                        tail(&log, 20)
                    )
                })
            }
        }
    };
    let addr = wait("ledge server listening on")?;
    let metrics = wait("metrics at")?;
    let printed = wait("certificate SHA-256 fingerprint:")?;
    let metrics = metrics
        .strip_prefix("http://")
        .and_then(|m| m.strip_suffix("/metrics"))
        .with_context(|| format!("{name}'s metrics address {metrics:?}"))?
        .to_owned();
    // Ready, as Agones would see it (the server says it once listening
    // with its rooms open and everything published).
    let until = Instant::now() + READY_TIMEOUT;
    while sidecar.state() != "Ready" {
        if let Some(status) = child.exited()? {
            bail!(
                "{name} exited ({status}) before saying Ready: {}",
                server_failure(&log)
            );
        }
        if Instant::now() >= until {
            bail!(
                "{name} did not say Ready to its sidecar within {READY_TIMEOUT:?} \
                 (state {:?}, calls {:?}); its log:\n{}",
                sidecar.state(),
                sidecar.calls(),
                tail(&log, 20)
            );
        }
        stop.sleep(POLL)?;
    }
    // The fingerprint, as a matchmaker reads it from the GameServer.
    let fingerprint = sidecar
        .annotation(CERT_ANNOTATION)
        .with_context(|| format!("{name} said Ready without the {CERT_ANNOTATION} annotation"))?;
    if fingerprint != printed {
        bail!(
            "{name}'s {CERT_ANNOTATION} annotation {fingerprint:?} is not the fingerprint \
             it printed ({printed:?})"
        );
    }
    Ok(Member {
        name,
        sidecar,
        child,
        addr: addr
            .parse()
            .with_context(|| format!("{}'s address {addr:?}", index + 1))?,
        metrics: metrics
            .parse()
            .with_context(|| format!("metrics address {metrics:?}"))?,
        fingerprint,
        log,
        _lines: lines,
        _cert_dir: cert_dir,
    })
}

fn start_bot_process(
    config: &FleetConfig,
    member: &Member,
    server: usize,
    room: &str,
    index: usize,
    seconds: f64,
) -> anyhow::Result<BotProcess> {
    let prefix = bot_prefix(index);
    let out = config.log_dir.join(format!("fleet-bots-{prefix}.out"));
    let err = config.log_dir.join(format!("fleet-bots-{prefix}.log"));
    let mut command = Command::new(config.bin_dir.join(BOT_BINARY));
    command
        .args(["--connect", &member.addr.to_string()])
        .args(["--cert-hash", &member.fingerprint])
        .args(["--room", room])
        .args(["--count", &config.bots_per_room.to_string()])
        .args(["--seconds", &format!("{seconds:.1}")])
        .args(["--name", &prefix])
        .args(["--brain", &config.brain])
        .args(["--seed", &(index * 1000 + 1).to_string()])
        .env("RUST_LOG", "warn")
        .stdin(Stdio::null())
        .stdout(log_file(&out)?)
        .stderr(log_file(&err)?);
    let child = Guarded::spawn(
        &format!("{BOT_BINARY} {prefix} (room {room})"),
        &mut command,
    )?;
    Ok(BotProcess {
        room: room.to_owned(),
        prefix,
        server,
        child,
        out,
        err,
        exited_at: None,
    })
}

/// Why a server stopped early, from its sidecar and its log.
fn stopped_early(member: &Member, status: ExitStatus, when: &str) -> anyhow::Error {
    let shut_down = member.sidecar.calls().contains(&Call::Shutdown);
    let why = if shut_down {
        "it called Agones Shutdown: allocated and empty for --agones-shutdown-after \
         (raise --shutdown-after if its bots were slow to join)"
            .to_owned()
    } else {
        server_failure(&member.log)
    };
    anyhow::anyhow!("{} exited ({status}) {when}: {why}", member.name)
}

fn check_servers(members: &mut [Member], when: &str) -> anyhow::Result<()> {
    for m in members.iter_mut() {
        if let Some(status) = m.child.exited()? {
            return Err(stopped_early(m, status, when));
        }
    }
    Ok(())
}

/// One server's readings at one end of the window.
struct Reading {
    at: Instant,
    scrape: Scrape,
    cpu: u64,
}

fn read(member: &Member) -> anyhow::Result<Reading> {
    Ok(Reading {
        scrape: scrape(member.metrics)?,
        cpu: procstat::cpu_ticks(member.child.pid())?,
        at: Instant::now(),
    })
}

fn figures(
    member: &Member,
    rooms: Vec<String>,
    first: &Reading,
    last: &Reading,
) -> anyhow::Result<ServerFigures> {
    let (a, b) = (&first.scrape, &last.scrape);
    let window = last.at.duration_since(first.at).as_secs_f64().max(1e-3);
    let delta = |name: &str| (b.sum(name) - a.sum(name)).max(0.0);
    let ticks = b
        .histogram("ledge_tick_duration_fine_seconds")?
        .since(&a.histogram("ledge_tick_duration_fine_seconds")?)?;
    let hz = procstat::clock_ticks_per_second() as f64;
    let pings = member
        .sidecar
        .health_pings()
        .into_iter()
        .filter(|&t| t >= first.at && t < last.at)
        .count();
    Ok(ServerFigures {
        name: member.name.clone(),
        addr: member.addr,
        rooms,
        players: b.sum(PLAYERS_GAUGE).max(0.0) as u64,
        cpu_pct: last.cpu.saturating_sub(first.cpu) as f64 / hz / window * 100.0,
        peak_rss_mib: procstat::vm_hwm_kib(member.child.pid())? as f64 / 1024.0,
        ticks: ticks.total(),
        tick_p50: ticks.quantile(0.5),
        tick_p99: ticks.quantile(0.99),
        missed_ticks: delta("ledge_missed_ticks_total") as u64,
        snapshots_per_s: delta("ledge_snapshot_bytes_count") / window,
        down_bytes_per_s: delta("ledge_bytes_out_total") / window,
        health_per_s: pings as f64 / window,
    })
}

/// Waits until `member`'s sidecar lists `room` with its `rooms` count above
/// `before`, or fails saying why (the bots' output, the server's exit).
fn wait_for_room(
    member: &mut Member,
    bots: &mut BotProcess,
    room: &str,
    before: i64,
    timeout: Duration,
    stop: &Stop,
) -> anyhow::Result<()> {
    let until = Instant::now() + timeout;
    loop {
        let listed = member
            .sidecar
            .list(ROOMS)
            .is_some_and(|l| l.iter().any(|r| r == room));
        let counted = member
            .sidecar
            .counter(ROOMS)
            .is_some_and(|(n, _)| n > before);
        if listed && counted {
            return Ok(());
        }
        if let Some(status) = member.child.exited()? {
            return Err(stopped_early(
                member,
                status,
                &format!("while room {room} was being joined"),
            ));
        }
        let gone = bots.child.exited()?;
        if gone.is_some() || Instant::now() >= until {
            let output = std::fs::read_to_string(&bots.out).unwrap_or_default();
            let refused = parse_bot_lines(&output, &bots.prefix)
                .into_iter()
                .find_map(|b| b.ended.filter(|why| why.contains("no room named")));
            let hint = match refused {
                Some(why) => format!("\nthe server refused the room: {why}"),
                None => String::new(),
            };
            bail!(
                "room {room} did not show in {}'s sidecar (list {:?}, rooms counter {:?}, \
                 before {before}) {}{hint}\nbot output:\n{}\n{}",
                member.name,
                member.sidecar.list(ROOMS).unwrap_or_default(),
                member.sidecar.counter(ROOMS),
                match gone {
                    Some(status) => format!("and its bot process exited ({status})"),
                    None => format!("within {timeout:?}"),
                },
                tail(&bots.out, 10),
                tail(&bots.err, 10)
            );
        }
        stop.sleep(POLL)?;
    }
}

/// When a fleet run's phases end: every bot process plays until the same
/// end, after the allocations' budget, the warm-up and the window.
struct Timing {
    /// When the allocations start (once every server is Ready).
    start: Instant,
    /// The allocations' budget: [`FleetConfig::room_timeout`] each.
    budget: Duration,
    /// When every bot process stops playing.
    end: Instant,
}

impl Timing {
    /// The timing of a run whose allocations start now.
    fn new(config: &FleetConfig) -> Self {
        let start = Instant::now();
        let budget = config.room_timeout * u32::try_from(config.rooms()).unwrap_or(u32::MAX);
        let end = start + budget + config.warmup + config.duration + BOT_TAIL;
        Timing { start, budget, end }
    }
}

/// What the allocations (phase 2) made.
struct Allocated {
    /// The allocations, in order.
    allocations: Vec<Allocation>,
    /// A bot process per allocated room, in allocation order.
    bots: Vec<BotProcess>,
    /// The rooms allocated to each server.
    rooms_of: Vec<Vec<String>>,
    /// What one more allocation found.
    one_more: Option<usize>,
}

/// What the window of play (phase 3) measured.
struct Window {
    /// The servers' figures, in order.
    server_figures: Vec<ServerFigures>,
    /// Each bot process's CPU over the window, percent of one core.
    bot_cpu_pct: Vec<f64>,
    /// The window, seconds (measured).
    window_s: f64,
    /// 1-minute load average at the window's start and end.
    load: (f64, f64),
}

/// Runs the fleet: every child is killed and every sidecar stopped before
/// this returns, whatever happens.
pub fn run_fleet(config: &FleetConfig, stop: &Stop) -> anyhow::Result<FleetReport> {
    config.validate()?;
    let mut problems = Vec::new();
    let mut members = start_servers(config, stop)?;
    let timing = Timing::new(config);
    let Allocated {
        allocations,
        mut bots,
        rooms_of,
        one_more,
    } = allocate_rooms(config, &timing, &mut members, &mut problems, stop)?;
    let window = play_window(
        config,
        &timing,
        &mut members,
        &mut bots,
        &rooms_of,
        &allocations,
        &mut problems,
        stop,
    )?;
    let bot_figures = finish_bots(
        config,
        &timing,
        &mut bots,
        &window.bot_cpu_pct,
        &mut problems,
        stop,
    )?;
    let shutdowns = check_shutdowns(config, &mut members, &bots, &mut problems, stop)?;
    Ok(FleetReport {
        servers: config.servers,
        rooms_per_server: config.rooms_per_server,
        bots_per_room: config.bots_per_room,
        brain: config.brain.clone(),
        window_s: window.window_s,
        allocations,
        one_more,
        server_figures: window.server_figures,
        bot_figures,
        shutdowns,
        problems,
        load: window.load,
    })
}

/// Phase 1: the servers, each with its sidecar, Ready.
fn start_servers(config: &FleetConfig, stop: &Stop) -> anyhow::Result<Vec<Member>> {
    let mut members = Vec::new();
    for i in 0..config.servers {
        let m = start_member(config, i, stop)?;
        eprintln!(
            "  {} Ready at {} (sidecar port {}, fingerprint {}...)",
            m.name,
            m.addr,
            m.sidecar.port(),
            m.fingerprint.chars().take(12).collect::<String>()
        );
        members.push(m);
    }
    Ok(members)
}

/// Phase 2: the allocations, one at a time, each with its bot process and a
/// wait until its room shows; then the packing, and one more allocation,
/// which must find no server.
fn allocate_rooms(
    config: &FleetConfig,
    timing: &Timing,
    members: &mut [Member],
    problems: &mut Vec<String>,
    stop: &Stop,
) -> anyhow::Result<Allocated> {
    let total = config.rooms();
    let Timing { start, budget, end } = *timing;
    let packing = expected_packing(config.servers, config.rooms_per_server);
    let mut allocations = Vec::new();
    let mut bots: Vec<BotProcess> = Vec::new();
    let mut rooms_of: Vec<Vec<String>> = vec![Vec::new(); config.servers];
    for (i, &expected) in packing.iter().enumerate() {
        check_servers(members, "during the allocations")?;
        let fleet: Vec<&FakeSidecar> = members.iter().map(|m| &m.sidecar).collect();
        let allocated_at = Instant::now();
        let Some(server) = allocate(&fleet, Want::AnyRoom) else {
            bail!(
                "allocation {} of {total}: no server has a free room (rooms counters {:?})",
                i + 1,
                members
                    .iter()
                    .map(|m| m.sidecar.counter(ROOMS))
                    .collect::<Vec<_>>()
            );
        };
        let room = room_name(i);
        let before = members[server].sidecar.counter(ROOMS).map_or(0, |(n, _)| n);
        let seconds = end.saturating_duration_since(Instant::now()).as_secs_f64();
        let mut process = start_bot_process(config, &members[server], server, &room, i, seconds)?;
        let left = (start + budget).saturating_duration_since(Instant::now());
        wait_for_room(
            &mut members[server],
            &mut process,
            &room,
            before,
            config.room_timeout.min(left).max(POLL),
            stop,
        )?;
        let shown_after = allocated_at.elapsed();
        eprintln!(
            "  allocation {}: room {room} on {} (shown after {:.2} s)",
            i + 1,
            members[server].name,
            shown_after.as_secs_f64()
        );
        if server != expected {
            problems.push(format!(
                "allocation {}: room {room} went to gs-{}, the packing says gs-{}",
                i + 1,
                server + 1,
                expected + 1
            ));
        }
        rooms_of[server].push(room.clone());
        allocations.push(Allocation {
            room,
            server,
            expected,
            shown_after,
        });
        bots.push(process);
    }
    let one_more = one_more_allocation(members, problems);
    Ok(Allocated {
        allocations,
        bots,
        rooms_of,
        one_more,
    })
}

/// One more allocation on the full fleet: a server it finds is a problem.
fn one_more_allocation(members: &[Member], problems: &mut Vec<String>) -> Option<usize> {
    let one_more = {
        let fleet: Vec<&FakeSidecar> = members.iter().map(|m| &m.sidecar).collect();
        allocate(&fleet, Want::AnyRoom)
    };
    if let Some(i) = one_more {
        problems.push(format!(
            "one more allocation found gs-{} (rooms counter {:?}): the fleet should be full",
            i + 1,
            members[i].sidecar.counter(ROOMS)
        ));
    }
    one_more
}

/// Phase 3: every bot in and the warm-up, the window measured, then the
/// checks for cross-talk at its end.
#[allow(clippy::too_many_arguments)]
fn play_window(
    config: &FleetConfig,
    timing: &Timing,
    members: &mut [Member],
    bots: &mut [BotProcess],
    rooms_of: &[Vec<String>],
    allocations: &[Allocation],
    problems: &mut Vec<String>,
    stop: &Stop,
) -> anyhow::Result<Window> {
    wait_for_players(config, timing, members, problems, stop)?;
    let load_start = procstat::load_average().map(|l| l[0]).unwrap_or(f64::NAN);
    let firsts = members
        .iter()
        .map(read)
        .collect::<anyhow::Result<Vec<_>>>()?;
    let bot_cpu_first = bots
        .iter()
        .map(|b| procstat::cpu_ticks(b.child.pid()).unwrap_or(0))
        .collect::<Vec<_>>();
    let window_end = firsts[0].at + config.duration;
    while Instant::now() < window_end {
        stop.sleep(CHECK_EVERY.min(window_end.saturating_duration_since(Instant::now())))?;
        check_servers(members, "during the window")?;
        for b in bots.iter_mut() {
            if let Some(status) = b.child.exited()? {
                if b.exited_at.is_none() {
                    b.exited_at = Some(Instant::now());
                    problems.push(format!(
                        "{} exited during the window ({status})",
                        b.child.name()
                    ));
                }
            }
        }
    }
    let lasts = members
        .iter()
        .map(read)
        .collect::<anyhow::Result<Vec<_>>>()?;
    let hz = procstat::clock_ticks_per_second() as f64;
    let bot_cpu_pct = bots
        .iter()
        .zip(&bot_cpu_first)
        .map(|(b, &first)| {
            let last = procstat::cpu_ticks(b.child.pid()).unwrap_or(first);
            let window = lasts[0].at.duration_since(firsts[0].at).as_secs_f64();
            last.saturating_sub(first) as f64 / hz / window.max(1e-3) * 100.0
        })
        .collect::<Vec<_>>();
    let load_end = procstat::load_average().map(|l| l[0]).unwrap_or(f64::NAN);
    let window_s = lasts[0].at.duration_since(firsts[0].at).as_secs_f64();
    let server_figures = check_cross_talk(config, members, rooms_of, &firsts, &lasts, problems)?;
    check_rooms_by_name(members, allocations, problems);
    Ok(Window {
        server_figures,
        bot_cpu_pct,
        window_s,
        load: (load_start, load_end),
    })
}

/// Every bot in (by the end of the allocations' budget at the latest),
/// then the warm-up; the bots play on until their end.
fn wait_for_players(
    config: &FleetConfig,
    timing: &Timing,
    members: &mut [Member],
    problems: &mut Vec<String>,
    stop: &Stop,
) -> anyhow::Result<()> {
    let (s, r, k) = (
        config.servers,
        config.rooms_per_server,
        config.bots_per_room,
    );
    let latest = timing.end - BOT_TAIL - config.duration - config.warmup;
    let want_players = (r * k) as i64;
    let all_in = |members: &[Member]| {
        members.iter().all(|m| {
            m.sidecar
                .counter(PLAYERS)
                .is_some_and(|(n, _)| n == want_players)
        })
    };
    while !all_in(members) && Instant::now() < latest {
        check_servers(members, "before the window")?;
        stop.sleep(POLL)?;
    }
    let joined_after = timing.start.elapsed();
    let window_start = Instant::now() + config.warmup;
    if all_in(members) {
        eprintln!(
            "  all {} bots in after {:.1} s; window of {:?} after {:?} of warm-up",
            s * r * k,
            joined_after.as_secs_f64(),
            config.duration,
            config.warmup
        );
    } else {
        let counts: Vec<Option<(i64, i64)>> =
            members.iter().map(|m| m.sidecar.counter(PLAYERS)).collect();
        problems.push(format!(
            "not every bot joined before the window: players counters {counts:?}, \
             {want_players} each expected"
        ));
    }
    stop.sleep(window_start.saturating_duration_since(Instant::now()))
}

/// No cross-talk at the window's end: each server's metrics, list and
/// counters hold its own rooms and players; returns its figures.
fn check_cross_talk(
    config: &FleetConfig,
    members: &[Member],
    rooms_of: &[Vec<String>],
    firsts: &[Reading],
    lasts: &[Reading],
    problems: &mut Vec<String>,
) -> anyhow::Result<Vec<ServerFigures>> {
    let (r, k) = (config.rooms_per_server, config.bots_per_room);
    let want_players = (r * k) as i64;
    let mut server_figures = Vec::new();
    for (i, m) in members.iter().enumerate() {
        let expected = &rooms_of[i];
        problems.extend(metrics_problems(
            &m.name,
            expected,
            k as u64,
            &room_players(&lasts[i].scrape),
        ));
        problems.extend(list_problems(
            &m.name,
            expected,
            &m.sidecar.list(ROOMS).unwrap_or_default(),
        ));
        // Its allocated rooms and room-1, open from the start: full.
        let want_rooms = Some((r as i64 + 1, r as i64 + 1));
        if m.sidecar.counter(ROOMS) != want_rooms {
            problems.push(format!(
                "{}: rooms counter {:?}, not {want_rooms:?}",
                m.name,
                m.sidecar.counter(ROOMS)
            ));
        }
        if m.sidecar.counter(PLAYERS).map(|(n, _)| n) != Some(want_players) {
            problems.push(format!(
                "{}: players counter {:?}, not {want_players}",
                m.name,
                m.sidecar.counter(PLAYERS)
            ));
        }
        server_figures.push(figures(m, expected.clone(), &firsts[i], &lasts[i])?);
    }
    Ok(server_figures)
}

/// The rule's answer for each allocated room by name (`Want::Room`): the
/// server it was allocated on.
fn check_rooms_by_name(members: &[Member], allocations: &[Allocation], problems: &mut Vec<String>) {
    let fleet: Vec<&FakeSidecar> = members.iter().map(|m| &m.sidecar).collect();
    for a in allocations {
        if is_start_room(&a.room) {
            // Every server lists its start-up room: not a unique name.
            continue;
        }
        let found = allocate(&fleet, Want::Room(&a.room));
        if found != Some(a.server) {
            problems.push(format!(
                "Want::Room({}) found {}, not gs-{}",
                a.room,
                found.map_or_else(|| "no server".to_owned(), |i| format!("gs-{}", i + 1)),
                a.server + 1
            ));
        }
    }
}

/// The end of phase 3: the bots finish (killed when they overstay) and
/// their reports are checked.
fn finish_bots(
    config: &FleetConfig,
    timing: &Timing,
    bots: &mut [BotProcess],
    bot_cpu_pct: &[f64],
    problems: &mut Vec<String>,
    stop: &Stop,
) -> anyhow::Result<Vec<BotFigures>> {
    let k = config.bots_per_room;
    let until = timing.end + BOT_EXIT_GRACE;
    loop {
        let mut running = 0;
        for b in bots.iter_mut() {
            if b.exited_at.is_none() {
                if b.child.exited()?.is_some() {
                    b.exited_at = Some(Instant::now());
                } else {
                    running += 1;
                }
            }
        }
        if running == 0 {
            break;
        }
        if Instant::now() >= until {
            for b in bots.iter_mut().filter(|b| b.exited_at.is_none()) {
                problems.push(format!(
                    "{} did not finish {BOT_EXIT_GRACE:?} after its time: killed",
                    b.child.name()
                ));
                b.child.kill();
                b.exited_at = Some(Instant::now());
            }
            break;
        }
        stop.sleep(POLL)?;
    }
    let mut bot_figures = Vec::new();
    for (b, &cpu_pct) in bots.iter().zip(bot_cpu_pct) {
        let output = std::fs::read_to_string(&b.out).unwrap_or_default();
        let lines = parse_bot_lines(&output, &b.prefix);
        let what = format!("{} on gs-{}", b.child.name(), b.server + 1);
        problems.extend(bot_problems(&what, &lines, k, config.runner()));
        bot_figures.push(BotFigures {
            room: b.room.clone(),
            server: b.server,
            bots: k,
            joined: lines.iter().filter(|l| l.player.is_some()).count(),
            goals: lines.iter().filter(|l| l.goal).count(),
            mispredictions: lines.iter().map(|l| l.mispredictions).sum(),
            cpu_pct,
        });
    }
    Ok(bot_figures)
}

/// Phase 4: each server, Allocated and empty, shuts itself down in time
/// once its bots have left.
fn check_shutdowns(
    config: &FleetConfig,
    members: &mut [Member],
    bots: &[BotProcess],
    problems: &mut Vec<String>,
    stop: &Stop,
) -> anyhow::Result<Vec<ShutdownFigures>> {
    let left_at: Vec<Option<Instant>> = (0..config.servers)
        .map(|i| {
            bots.iter()
                .filter(|b| b.server == i)
                .filter_map(|b| b.exited_at)
                .max()
        })
        .collect();
    let last_left = left_at
        .iter()
        .flatten()
        .max()
        .copied()
        .unwrap_or_else(Instant::now);
    let until = last_left + config.shutdown_after + SHUTDOWN_MARGIN;
    let mut exited_at: Vec<Option<(Instant, ExitStatus)>> = vec![None; config.servers];
    loop {
        for (i, m) in members.iter_mut().enumerate() {
            if exited_at[i].is_none() {
                if let Some(status) = m.child.exited()? {
                    exited_at[i] = Some((Instant::now(), status));
                }
            }
        }
        if exited_at.iter().all(Option::is_some) || Instant::now() >= until {
            break;
        }
        stop.sleep(POLL)?;
    }
    Ok(members
        .iter_mut()
        .enumerate()
        .map(|(i, m)| shutdown_figures(config, m, left_at[i], exited_at[i], problems))
        .collect())
}

/// How server `m` ended: when it called `Shutdown` after it was empty, when
/// it exited after its last bot left (`left_at`; `exited_at`: when and how
/// it exited, if it did), each checked against `--agones-shutdown-after`;
/// one still running is terminated.
fn shutdown_figures(
    config: &FleetConfig,
    m: &mut Member,
    left_at: Option<Instant>,
    exited_at: Option<(Instant, ExitStatus)>,
    problems: &mut Vec<String>,
) -> ShutdownFigures {
    let events = m.sidecar.events();
    let shutdown_at = events
        .iter()
        .find(|e| e.call == Call::Shutdown)
        .map(|e| e.at);
    // When the sidecar last saw the players count go to 0.
    let empty_at = events
        .iter()
        .filter(|e| {
            matches!(&e.call, Call::UpdateCounter { name, count: Some(0), .. }
                if name == PLAYERS)
        })
        .map(|e| e.at)
        .filter(|&t| shutdown_at.is_none_or(|s| t <= s))
        .max();
    let empty_to_shutdown = match (empty_at, shutdown_at) {
        (Some(e), Some(s)) => Some(s.duration_since(e)),
        _ => None,
    };
    let left_to_exit = match (left_at, exited_at) {
        (Some(l), Some((x, _))) => Some(x.saturating_duration_since(l)),
        _ => None,
    };
    let exit = match exited_at {
        Some((_, status)) => {
            if !status.success() {
                problems.push(format!(
                    "{} exited with {status} after its shutdown: {}",
                    m.name,
                    server_failure(&m.log)
                ));
            }
            status.to_string()
        }
        None => {
            problems.push(format!(
                "{} still ran {:.1} s after its last bot left (--agones-shutdown-after \
                 {:.1} s + {:.0} s margin); sidecar state {:?}, Shutdown called: {}",
                m.name,
                left_at.map_or(0.0, |l| l.elapsed().as_secs_f64()),
                config.shutdown_after.as_secs_f64(),
                SHUTDOWN_MARGIN.as_secs_f64(),
                m.sidecar.state(),
                shutdown_at.is_some()
            ));
            m.child.terminate(Duration::from_secs(5));
            "still running: terminated".to_owned()
        }
    };
    if shutdown_at.is_none() {
        problems.push(format!("{} never called Agones Shutdown", m.name));
    } else if m.sidecar.state() != "Shutdown" {
        problems.push(format!(
            "{}: sidecar state {:?} after Shutdown",
            m.name,
            m.sidecar.state()
        ));
    }
    if let Some(d) = left_to_exit {
        if d > config.shutdown_after + SHUTDOWN_MARGIN {
            problems.push(format!(
                "{} exited {:.1} s after its last bot left: more than \
                 --agones-shutdown-after {:.1} s + {:.0} s",
                m.name,
                d.as_secs_f64(),
                config.shutdown_after.as_secs_f64(),
                SHUTDOWN_MARGIN.as_secs_f64()
            ));
        }
    }
    if let Some(d) = empty_to_shutdown {
        if d + SHUTDOWN_EARLY_TOLERANCE < config.shutdown_after {
            problems.push(format!(
                "{} called Shutdown {:.2} s after it was empty, before \
                 --agones-shutdown-after {:.1} s",
                m.name,
                d.as_secs_f64(),
                config.shutdown_after.as_secs_f64()
            ));
        }
    }
    ShutdownFigures {
        name: m.name.clone(),
        empty_to_shutdown,
        left_to_exit,
        exit,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn room_names_are_fresh_and_bot_names_unique() {
        let names: BTreeSet<String> = (0..100).map(room_name).collect();
        assert_eq!(names.len(), 100);
        assert_eq!(room_name(0), "fleet-01");
        assert_eq!(room_name(11), "fleet-12");
        assert_eq!(room_name(99), "fleet-100");
        assert!(!is_start_room(&room_name(0)));
        assert_eq!(bot_prefix(0), "b01");
        assert!(is_start_room("room-1") && is_start_room("room-12"));
        assert!(!is_start_room("room-") && !is_start_room("room-1a") && !is_start_room("rooms"));
    }

    #[test]
    fn packing_fills_each_server_before_the_next() {
        assert_eq!(expected_packing(3, 2), [0, 0, 1, 1, 2, 2]);
        assert_eq!(expected_packing(2, 3), [0, 0, 0, 1, 1, 1]);
        assert_eq!(expected_packing(1, 1), [0]);
        assert!(expected_packing(0, 4).is_empty());
    }

    /// The rule of `ledge_agones_fake::allocate` gives the packing when
    /// each server's `rooms` count follows its allocations (as the real
    /// servers' counters do).
    #[test]
    fn the_allocation_rule_packs_as_expected() {
        let (s, r) = (3usize, 2i64);
        let sidecars: Vec<FakeSidecar> = (0..s)
            .map(|i| FakeSidecar::start(&format!("gs-{i}"), &[(ROOMS, r)], &[(ROOMS, r)]).unwrap())
            .collect();
        let fleet: Vec<&FakeSidecar> = sidecars.iter().collect();
        // Not Ready: nothing to allocate.
        assert_eq!(allocate(&fleet, Want::AnyRoom), None);
        drop(fleet);
        // The servers say Ready and count their rooms through the SDK;
        // here, through the fake's own protocol, as a server would.
        let runtime = tokio_runtime();
        for sc in &sidecars {
            runtime.block_on(ready(sc.port()));
        }
        let fleet: Vec<&FakeSidecar> = sidecars.iter().collect();
        let mut got = Vec::new();
        for _ in 0..s * r as usize {
            let i = allocate(&fleet, Want::AnyRoom).expect("a free room");
            let count = sidecars[i].counter(ROOMS).unwrap().0 + 1;
            runtime.block_on(set_rooms(sidecars[i].port(), count));
            got.push(i);
        }
        assert_eq!(got, expected_packing(s, r as usize));
        assert_eq!(allocate(&fleet, Want::AnyRoom), None);
    }

    fn tokio_runtime() -> tokio::runtime::Runtime {
        tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap()
    }

    async fn sdk(port: u16) -> agones::Sdk {
        agones::Sdk::new(Some(port), None)
            .await
            .expect("the SDK connects to the fake")
    }

    async fn ready(port: u16) {
        sdk(port).await.ready().await.unwrap();
    }

    async fn set_rooms(port: u16, count: i64) {
        let sdk = sdk(port).await;
        let mut beta = sdk.beta().clone();
        beta.set_counter_count(ROOMS, count).await.unwrap();
    }

    fn players(text: &str) -> BTreeMap<String, u64> {
        room_players(&Scrape::parse(text).unwrap())
    }

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn per_room_players_are_read_from_the_gauge() {
        let p = players(
            "# TYPE ledge_players gauge\nledge_players{room=\"fleet-01\"} 4\n\
             ledge_players{room=\"room-1\"} 0\nledge_rooms 2\nledge_players_other{room=\"x\"} 9\n",
        );
        assert_eq!(
            p.into_iter().collect::<Vec<_>>(),
            [("fleet-01".to_owned(), 4), ("room-1".to_owned(), 0)]
        );
    }

    #[test]
    fn metrics_with_exactly_the_allocated_rooms_pass() {
        let expected = names(&["fleet-01", "fleet-02"]);
        let actual = players(
            "ledge_players{room=\"fleet-01\"} 4\nledge_players{room=\"fleet-02\"} 4\n\
             ledge_players{room=\"room-1\"} 0\n",
        );
        assert_eq!(
            metrics_problems("gs-1", &expected, 4, &actual),
            Vec::<String>::new()
        );
    }

    #[test]
    fn cross_talk_in_the_metrics_is_named() {
        let expected = names(&["fleet-01", "fleet-02"]);
        // A bot of another server's room here, a room short of a player,
        // one missing, a start-up room with players.
        let actual = players(
            "ledge_players{room=\"fleet-01\"} 3\nledge_players{room=\"fleet-03\"} 1\n\
             ledge_players{room=\"room-1\"} 1\nledge_players{room=\"fleet-04\"} 0\n",
        );
        let problems = metrics_problems("gs-1", &expected, 4, &actual);
        assert_eq!(problems.len(), 5, "{problems:#?}");
        assert!(problems[0].contains("fleet-01 has 3 players"));
        assert!(problems[1].contains("fleet-02 is not in its metrics"));
        assert!(problems[2].contains("fleet-03") && problems[2].contains("cross-talk"));
        assert!(problems[3].contains("fleet-04") && problems[3].contains("is open"));
        assert!(problems[4].contains("room-1") && problems[4].contains("1 players"));
        // A start-up room allocated by name counts like any.
        let expected = names(&["room-1", "fleet-02"]);
        let actual =
            players("ledge_players{room=\"room-1\"} 4\nledge_players{room=\"fleet-02\"} 4\n");
        assert!(metrics_problems("gs-1", &expected, 4, &actual).is_empty());
    }

    #[test]
    fn lists_must_hold_exactly_the_allocated_rooms() {
        let expected = names(&["fleet-03", "fleet-04"]);
        assert!(list_problems(
            "gs-2",
            &expected,
            &names(&["room-1", "fleet-03", "fleet-04"])
        )
        .is_empty());
        let problems = list_problems(
            "gs-2",
            &expected,
            &names(&["room-1", "fleet-03", "fleet-01"]),
        );
        assert_eq!(problems.len(), 2, "{problems:#?}");
        assert!(problems[0].contains("fleet-04 is not in its rooms list"));
        assert!(problems[1].contains("fleet-01") && problems[1].contains("cross-talk"));
        let problems = list_problems(
            "gs-2",
            &expected,
            &names(&["fleet-03", "fleet-04", "fleet-03"]),
        );
        assert_eq!(problems.len(), 1);
        assert!(problems[0].contains("repeats"));
    }

    const BOTS: &str = "4 bots, brain Runner:\n\
        b01-1      runner  player   #1  ticks  2400  snapshots 1200  corrections   2 (max   3.0 px, mispredicted   5)  rtt   0.40 ms  jitter  0.10 ms  loss  0.0%  goal reached at tick 1500  [at the goal]\n\
        b01-2      runner  player   #2  ticks  2400  snapshots 1200  corrections   0 (max   0.0 px, mispredicted   0)  rtt   0.40 ms  jitter  0.10 ms  loss  0.0%  goal no  [step 3 of 9: goal is near]\n\
        b01-3      runner  player   #3  ticks   100  snapshots   50  corrections   0 (max   0.0 px, mispredicted  12)  rtt   0.40 ms  jitter  0.10 ms  loss  0.0%  goal no  ended: closed by the server\n\
        b01-4      runner  player    -  ticks     0  snapshots    0  corrections   0 (max   0.0 px, mispredicted   0)  rtt   0.00 ms  jitter  0.00 ms  loss  0.0%  goal no  ended: cannot connect: rejected: there is no room named \"fleet-02\"\n\
        b011-1     runner  player   #9  ticks     1  snapshots    1  corrections   0 (max   0.0 px, mispredicted   0)  rtt   0.00 ms  jitter  0.00 ms  loss  0.0%  goal no\n\
        1/4 reached the goal (as the server saw it)\n";

    #[test]
    fn bot_reports_are_parsed_by_prefix() {
        let lines = parse_bot_lines(BOTS, "b01");
        assert_eq!(lines.len(), 4);
        assert_eq!(
            lines[0],
            BotLine {
                name: "b01-1".into(),
                player: Some(1),
                ticks: 2400,
                snapshots: 1200,
                mispredictions: 5,
                goal: true,
                ended: None,
            }
        );
        // "goal is near" in the progress note is not the goal.
        assert!(!lines[1].goal);
        assert_eq!(lines[2].mispredictions, 12);
        assert_eq!(lines[2].ended.as_deref(), Some("closed by the server"));
        assert_eq!(lines[3].player, None);
        assert!(lines[3].ended.as_deref().unwrap().contains("no room named"));
        assert_eq!(parse_bot_lines(BOTS, "b011").len(), 1);
        assert!(parse_bot_lines("", "b01").is_empty());
    }

    #[test]
    fn bot_problems_name_each_bot() {
        let lines = parse_bot_lines(BOTS, "b01");
        let problems = bot_problems("bots b01", &lines, 4, true);
        assert_eq!(problems.len(), 3, "{problems:#?}");
        assert!(problems[0].contains("b01-2 did not reach the goal"));
        assert!(problems[1].contains("b01-3 ended early: closed by the server"));
        assert!(problems[2].contains("b01-4 did not join"));
        // Walkers need not reach the goal; a missing report is a problem.
        assert_eq!(
            bot_problems("bots b01", &lines[..2], 2, false),
            Vec::<String>::new()
        );
        let problems = bot_problems("bots b01", &lines[..1], 2, true);
        assert_eq!(problems, ["bots b01: 1 bot reports, not 2"]);
    }

    #[test]
    fn the_report_renders_every_table() {
        let report = FleetReport {
            servers: 1,
            rooms_per_server: 1,
            bots_per_room: 2,
            brain: "runner".into(),
            window_s: 30.0,
            allocations: vec![Allocation {
                room: "fleet-01".into(),
                server: 0,
                expected: 0,
                shown_after: Duration::from_millis(640),
            }],
            one_more: None,
            server_figures: vec![ServerFigures {
                name: "gs-1".into(),
                addr: "127.0.0.1:5000".parse().unwrap(),
                rooms: names(&["fleet-01"]),
                players: 2,
                cpu_pct: 12.4,
                peak_rss_mib: 10.25,
                ticks: 1800,
                tick_p50: Some(0.00005),
                tick_p99: Some(0.0004),
                missed_ticks: 0,
                snapshots_per_s: 60.0,
                down_bytes_per_s: 6000.0,
                health_per_s: 0.5,
            }],
            bot_figures: vec![BotFigures {
                room: "fleet-01".into(),
                server: 0,
                bots: 2,
                joined: 2,
                goals: 2,
                mispredictions: 3,
                cpu_pct: 20.0,
            }],
            shutdowns: vec![ShutdownFigures {
                name: "gs-1".into(),
                empty_to_shutdown: Some(Duration::from_millis(3100)),
                left_to_exit: Some(Duration::from_millis(3500)),
                exit: "exit status: 0".into(),
            }],
            problems: Vec::new(),
            load: (1.0, 1.0),
        };
        assert!(report.passed());
        let md = report.markdown();
        assert!(
            md.contains(
                "| gs-1 | fleet-01 | 2 | 12 | 10.2 | 0.050 | 0.400 | 0 | 60 | 6.0 | 0.50 |"
            ),
            "{md}"
        );
        assert!(md.contains("| 1 | fleet-01 | gs-1 | gs-1 | 0.64 |"), "{md}");
        assert!(
            md.contains("| 2 | (one more) | none | none (full) | - |"),
            "{md}"
        );
        assert!(
            md.contains("| fleet-01 | gs-1 | 2 | 2 | 2 | 3 | 20 |"),
            "{md}"
        );
        assert!(
            md.contains("| gs-1 | 3.10 | 3.50 | exit status: 0 |"),
            "{md}"
        );
        // Thin bots do not predict.
        let thin = FleetReport {
            brain: "thin".into(),
            ..report
        };
        assert!(thin
            .markdown()
            .contains("| fleet-01 | gs-1 | 2 | 2 | 2 | - | 20 |"));
    }

    #[test]
    fn a_server_failure_is_told_in_its_own_words() {
        let log = "2026-11-26T05:00:00Z  INFO ledge_server: something\n\
            ledge-server: starting the server on 127.0.0.1:0 with certificates in /tmp/x: \
            --agones: this ledge-server was built without Agones support; build it with \
            `cargo build --release -p ledge-server --features agones` (deploy/Dockerfile does)\n";
        let told = failure_in_log(log).unwrap();
        assert!(
            told.starts_with("ledge-server: starting the server"),
            "{told}"
        );
        assert!(told.contains("--features agones"), "{told}");
        let old = "error: unexpected argument '--agones' found\n\nUsage: ledge-server [OPTIONS]\n";
        assert!(failure_in_log(old).unwrap().contains("--features agones"));
        assert_eq!(failure_in_log("INFO all is well\n"), None);
    }

    #[test]
    fn bad_numbers_are_refused_with_the_flag_to_change() {
        let config = FleetConfig {
            servers: 3,
            rooms_per_server: 2,
            bots_per_room: 4,
            brain: "runner".into(),
            duration: Duration::from_secs(30),
            warmup: Duration::from_secs(5),
            room_timeout: Duration::from_secs(5),
            shutdown_after: Duration::from_secs(3),
            health_every: None,
            tick_hz: 60,
            snapshot_hz: 30,
            bin_dir: PathBuf::new(),
            log_dir: PathBuf::new(),
        };
        config.validate().unwrap();
        assert_eq!(config.rooms(), 6);
        for (bad, flag) in [
            (
                FleetConfig {
                    servers: 0,
                    ..config.clone()
                },
                "--servers",
            ),
            (
                FleetConfig {
                    rooms_per_server: 0,
                    ..config.clone()
                },
                "--rooms-per-server",
            ),
            (
                FleetConfig {
                    bots_per_room: 0,
                    ..config.clone()
                },
                "--bots-per-room",
            ),
            (
                FleetConfig {
                    duration: Duration::ZERO,
                    ..config.clone()
                },
                "--duration",
            ),
            (
                FleetConfig {
                    brain: "misbehave".into(),
                    ..config.clone()
                },
                "--brain",
            ),
        ] {
            let e = bad.validate().unwrap_err().to_string();
            assert!(e.contains(flag), "{e}");
        }
    }
}
