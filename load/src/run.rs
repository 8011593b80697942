//! One load run: a `ledge-server` child on loopback with a throw-away
//! certificate directory and its metrics endpoint, one or more `ledge-bot`
//! children driving N bots, a warm-up once every bot has joined, then a
//! measured window between two scrapes of the metrics and two readings of
//! `/proc`.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{bail, Context};

use crate::children::{log_file, tail, Guarded, Lines, Stop};
use crate::procstat;
use crate::prom::{scrape, Scrape};
use crate::quantile::Buckets;

/// How long the server has to print its address and fingerprint.
const SERVER_START_TIMEOUT: Duration = Duration::from_secs(30);
/// How often the window checks the children and the player count.
const CHECK_EVERY: Duration = Duration::from_secs(1);
/// Time allowed per bot of one process to connect and join (`ledge-bot`
/// staggers its joins by 20 ms), on top of [`JOIN_BASE`].
const JOIN_PER_BOT: Duration = Duration::from_millis(60);
/// Fixed part of the join allowance.
const JOIN_BASE: Duration = Duration::from_secs(10);
/// Extra seconds the bots play after the window, so that none leaves
/// before the second scrape.
const BOT_TAIL: Duration = Duration::from_secs(3);

/// Which program plays the bots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClientKind {
    /// `ledge-bot`: predicting bots with a brain (`RunConfig::brain`).
    Bot,
    /// `ledge-bot --brain thin`: thin bots (inputs and snapshots, no
    /// prediction).
    Thin,
    /// `ledge-bot --brain thin-idle`: thin bots holding no button.
    ThinIdle,
}

/// The program that plays the bots, of either kind.
pub const BOT_BINARY: &str = "ledge-bot";

impl ClientKind {
    /// The `ledge-bot --brain` of the bots, given `RunConfig::brain`.
    pub fn brain(self, brain: &str) -> &str {
        match self {
            ClientKind::Bot => brain,
            ClientKind::Thin => "thin",
            ClientKind::ThinIdle => "thin-idle",
        }
    }
}

/// What one run does.
#[derive(Debug, Clone)]
pub struct RunConfig {
    /// Bots to run.
    pub bots: usize,
    /// Which program plays them.
    pub client: ClientKind,
    /// `ledge-bot` processes sharing them.
    pub bot_processes: usize,
    /// Players per room (rooms: enough for every bot).
    pub max_players: usize,
    /// Server tick rate, Hz.
    pub tick_hz: u32,
    /// Server snapshot rate, Hz.
    pub snapshot_hz: u32,
    /// The server's runtime threads (`--threads`); `None`: its default.
    pub server_threads: Option<usize>,
    /// Brain of the bots (`ledge-bot --brain`).
    pub brain: String,
    /// Time between the last join and the start of the window.
    pub warmup: Duration,
    /// The measured window.
    pub duration: Duration,
    /// Where `ledge-server` and `ledge-bot` are.
    pub bin_dir: PathBuf,
    /// Where the logs go.
    pub log_dir: PathBuf,
}

impl RunConfig {
    /// What plays the bots, for the table: `ledge-bot BRAIN` or `thin`.
    pub fn client_label(&self) -> String {
        match self.client {
            ClientKind::Bot => format!("ledge-bot {}", self.brain),
            ClientKind::Thin => "thin".to_owned(),
            ClientKind::ThinIdle => "thin-idle".to_owned(),
        }
    }

    /// Rooms the server is started with.
    pub fn rooms(&self) -> usize {
        self.bots.div_ceil(self.max_players.max(1)).max(1)
    }

    /// Bots of each `ledge-bot` process (as even as possible).
    pub fn split(&self) -> Vec<usize> {
        let procs = self.bot_processes.clamp(1, self.bots.max(1));
        (0..procs)
            .map(|i| self.bots / procs + usize::from(i < self.bots % procs))
            .collect()
    }

    /// How long the bots have to join.
    pub fn join_allowance(&self) -> Duration {
        let most = self.split().into_iter().max().unwrap_or(0);
        JOIN_BASE + JOIN_PER_BOT * u32::try_from(most).unwrap_or(u32::MAX)
    }
}

/// What one run measured (over the window only).
#[derive(Debug, Clone, PartialEq)]
pub struct RunResult {
    /// Bots asked for.
    pub bots: usize,
    /// What played them ([`RunConfig::client_label`]).
    pub client: String,
    /// Rooms of the server.
    pub rooms: usize,
    /// `ledge-bot` processes.
    pub bot_processes: usize,
    /// Length of the window, seconds (measured).
    pub window_s: f64,
    /// Ticks run in the window, all rooms.
    pub ticks: u64,
    /// Median tick duration, seconds.
    pub tick_p50: Option<f64>,
    /// 99th percentile tick duration, seconds.
    pub tick_p99: Option<f64>,
    /// Upper bound of the longest tick, seconds.
    pub tick_max: Option<f64>,
    /// Mean tick duration, seconds.
    pub tick_mean: Option<f64>,
    /// Ticks skipped by the server (stalls beyond its catch-up).
    pub missed_ticks: u64,
    /// Wake-ups of a room's loop more than one tick period late.
    pub late_wakeups: u64,
    /// 99th percentile of the wake-up lateness, seconds.
    pub lateness_p99: Option<f64>,
    /// Bytes per second per client received by the server (payload).
    pub up_bytes_per_client_s: f64,
    /// Bytes per second per client sent by the server (payload).
    pub down_bytes_per_client_s: f64,
    /// Bytes per second per client the server received on the wire: UDP
    /// payload plus 28 bytes of IPv4 and UDP header per datagram, every
    /// packet (inputs, ACKs, control), native QUIC clients.
    pub wire_up_bytes_per_client_s: f64,
    /// The same, sent by the server.
    pub wire_down_bytes_per_client_s: f64,
    /// UDP datagrams per second per client received by the server.
    pub packets_up_per_client_s: f64,
    /// UDP datagrams per second per client sent by the server.
    pub packets_down_per_client_s: f64,
    /// Server CPU, percent of one core.
    pub server_cpu_pct: f64,
    /// Time the server's threads waited for a CPU while runnable, in
    /// milliseconds per second of the window (other processes' load).
    pub server_run_queue_wait_ms_s: f64,
    /// Server peak resident memory, MiB.
    pub server_peak_rss_mib: f64,
    /// CPU of all bot processes, percent of one core.
    pub bot_cpu_pct: f64,
    /// Players in the server, mean of the window's two ends.
    pub mean_players: f64,
    /// Players in the server when the window started.
    pub connected: u64,
    /// Fewest players seen during the window.
    pub min_players: u64,
    /// Bots that ended early (their reports, or missing players).
    pub dropped: u64,
    /// Inputs missing at their tick, percent of player-ticks.
    pub starved_pct: f64,
    /// 1-minute load average at the start and end of the window.
    pub load: (f64, f64),
}

impl RunResult {
    /// Server CPU per player and second of play, milliseconds: one core
    /// holds `1000 / this` players.
    pub fn cpu_ms_per_player_s(&self) -> f64 {
        self.server_cpu_pct / 100.0 * 1000.0 / self.mean_players.max(1.0)
    }
}

/// A running server and how to reach it.
struct ServerChild {
    child: Guarded,
    addr: SocketAddr,
    metrics: SocketAddr,
    fingerprint: String,
    log: PathBuf,
    _lines: Lines,
}

fn start_server(config: &RunConfig, cert_dir: &Path, stop: &Stop) -> anyhow::Result<ServerChild> {
    let bin = config.bin_dir.join("ledge-server");
    let log = config.log_dir.join(format!("server-{}.log", config.bots));
    let out = config.log_dir.join(format!("server-{}.out", config.bots));
    let mut command = Command::new(&bin);
    command
        .args(["--bind", "127.0.0.1:0", "--metrics-bind", "127.0.0.1:0"])
        .arg("--cert-dir")
        .arg(cert_dir)
        .args(["--tick-rate", &config.tick_hz.to_string()])
        .args(["--snapshot-rate", &config.snapshot_hz.to_string()])
        .args(["--rooms", &config.rooms().to_string()])
        .args(["--max-players", &config.max_players.to_string()])
        .args(["--max-connections", &(config.bots + 16).to_string()])
        // Every bot connects from this machine's one address.
        .args(["--max-per-address", &(config.bots + 16).to_string()])
        .args(["--max-pending-per-address", "64", "--max-pending", "64"])
        .env("RUST_LOG", "info")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(log_file(&log)?);
    if let Some(n) = config.server_threads {
        command.args(["--threads", &n.to_string()]);
    }
    let mut child = Guarded::spawn("ledge-server", &mut command)?;
    let lines = Lines::spawn(child.take_stdout().context("server stdout")?, &out)?;
    let wait = |prefix: &str| -> anyhow::Result<String> {
        let line = lines
            .wait_for(SERVER_START_TIMEOUT, stop, |l| l.starts_with(prefix))
            .with_context(|| {
                format!(
                    "waiting for the server's {prefix:?} line; its log:\n{}",
                    tail(&log, 20)
                )
            })?;
        Ok(line[prefix.len()..].trim().to_owned())
    };
    let addr = wait("ledge server listening on")?;
    let metrics = wait("metrics at")?;
    let fingerprint = wait("certificate SHA-256 fingerprint:")?;
    let metrics = metrics
        .strip_prefix("http://")
        .and_then(|m| m.strip_suffix("/metrics"))
        .with_context(|| format!("metrics address {metrics:?}"))?;
    Ok(ServerChild {
        child,
        addr: addr
            .parse()
            .with_context(|| format!("server address {addr:?}"))?,
        metrics: metrics
            .parse()
            .with_context(|| format!("metrics address {metrics:?}"))?,
        fingerprint,
        log,
        _lines: lines,
    })
}

/// A `ledge-bot` process.
struct BotChild {
    child: Guarded,
    out: PathBuf,
    err: PathBuf,
}

fn start_bots(
    config: &RunConfig,
    server: &ServerChild,
    seconds: f64,
) -> anyhow::Result<Vec<BotChild>> {
    let bin = config.bin_dir.join(BOT_BINARY);
    let mut bots = Vec::new();
    for (i, count) in config.split().into_iter().enumerate() {
        let out = config
            .log_dir
            .join(format!("bots-{}-{}.out", config.bots, i + 1));
        let err = config
            .log_dir
            .join(format!("bots-{}-{}.log", config.bots, i + 1));
        let mut command = Command::new(&bin);
        command
            .args(["--connect", &server.addr.to_string()])
            .args(["--cert-hash", &server.fingerprint])
            .args(["--count", &count.to_string()])
            .args(["--seconds", &format!("{seconds:.1}")])
            .args(["--name", &format!("p{}", i + 1)])
            .args(["--brain", config.client.brain(&config.brain)])
            // Distinct walks in each process.
            .args(["--seed", &(i * 1000 + 1).to_string()])
            .env("RUST_LOG", "warn")
            .stdin(Stdio::null())
            .stdout(log_file(&out)?)
            .stderr(log_file(&err)?);
        let name = format!("{BOT_BINARY} #{}", i + 1);
        let child = Guarded::spawn(&name, &mut command)?;
        bots.push(BotChild { child, out, err });
    }
    Ok(bots)
}

/// Bot reports (`ledge-bot`'s closing lines) of one process's output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BotReports {
    /// Report lines.
    pub reports: u64,
    /// Reports of bots that ended early (refused, closed, kicked).
    pub ended: u64,
}

impl BotReports {
    /// Reads the report lines of bots named `p<i>-<n>`.
    pub fn parse(output: &str) -> BotReports {
        let mut r = BotReports::default();
        for line in output.lines() {
            let is_report = line.starts_with('p')
                && line
                    .split_whitespace()
                    .next()
                    .and_then(|name| name[1..].split_once('-'))
                    .is_some_and(|(a, b)| a.parse::<u32>().is_ok() && b.parse::<u32>().is_ok());
            if is_report {
                r.reports += 1;
                r.ended += u64::from(line.contains("  ended: "));
            } else if line.starts_with("a bot task failed") {
                r.reports += 1;
                r.ended += 1;
            }
        }
        r
    }
}

/// What is read at each end of the window.
struct Reading {
    at: Instant,
    scrape: Scrape,
    server_cpu: u64,
    server_wait_ns: u64,
    bot_cpu: u64,
    load: f64,
}

fn read(server: &ServerChild, bots: &[BotChild]) -> anyhow::Result<Reading> {
    let scrape = scrape(server.metrics)?;
    let server_cpu = procstat::cpu_ticks(server.child.pid())?;
    let server_wait_ns = procstat::run_queue_wait_ns(server.child.pid())?;
    let mut bot_cpu = 0;
    for b in bots {
        bot_cpu += procstat::cpu_ticks(b.child.pid())
            .with_context(|| format!("{} is gone", b.child.name()))?;
    }
    Ok(Reading {
        at: Instant::now(),
        scrape,
        server_cpu,
        server_wait_ns,
        bot_cpu,
        load: procstat::load_average().map(|l| l[0]).unwrap_or(f64::NAN),
    })
}

fn players(scrape: &Scrape) -> u64 {
    scrape.sum("ledge_players").max(0.0) as u64
}

/// Fails if the server or a bot process has exited.
fn check_alive(server: &mut ServerChild, bots: &mut [BotChild]) -> anyhow::Result<()> {
    if let Some(status) = server.child.exited()? {
        bail!(
            "the server exited ({status}); its log:\n{}",
            tail(&server.log, 20)
        );
    }
    for b in bots {
        if let Some(status) = b.child.exited()? {
            bail!(
                "{} exited early ({status}); its output:\n{}\n{}",
                b.child.name(),
                tail(&b.out, 10),
                tail(&b.err, 10)
            );
        }
    }
    Ok(())
}

/// Runs one configuration and returns its figures. Every child is killed
/// before this returns, whatever happens.
pub fn run(config: &RunConfig, stop: &Stop) -> anyhow::Result<RunResult> {
    let cert_dir = tempfile::tempdir().context("creating a certificate directory")?;
    let mut server = start_server(config, cert_dir.path(), stop)?;
    let join = config.join_allowance();
    let bot_seconds = (join + config.warmup + config.duration + BOT_TAIL).as_secs_f64();
    let mut bots = start_bots(config, &server, bot_seconds)?;
    let started = Instant::now();

    // Every bot joined?
    let wanted = config.bots as u64;
    loop {
        check_alive(&mut server, &mut bots)?;
        let now = players(&scrape(server.metrics)?);
        if now >= wanted {
            break;
        }
        if started.elapsed() > join {
            if now == 0 {
                bail!(
                    "no bot joined in {join:?}; bot output:\n{}",
                    tail(&bots[0].err, 10)
                );
            }
            eprintln!("  only {now} of {wanted} bots joined in {join:?}: measuring them");
            break;
        }
        stop.sleep(Duration::from_millis(250))?;
    }
    eprintln!(
        "  bots joined after {:.1} s; warm-up {:?}, window {:?}",
        started.elapsed().as_secs_f64(),
        config.warmup,
        config.duration
    );
    stop.sleep(config.warmup)?;

    let first = read(&server, &bots)?;
    let connected = players(&first.scrape);
    let mut min_players = connected;
    let end = first.at + config.duration;
    while Instant::now() < end {
        stop.sleep(CHECK_EVERY.min(end.saturating_duration_since(Instant::now())))?;
        check_alive(&mut server, &mut bots)?;
        min_players = min_players.min(players(&scrape(server.metrics)?));
    }
    let last = read(&server, &bots)?;
    let peak_rss_kib = procstat::vm_hwm_kib(server.child.pid())?;
    min_players = min_players.min(players(&last.scrape));
    let players_end = players(&last.scrape);

    // Let the bots finish and print their reports.
    let mut reports = BotReports::default();
    let left = (started + Duration::from_secs_f64(bot_seconds))
        .saturating_duration_since(Instant::now())
        + Duration::from_secs(30);
    for b in &mut bots {
        if b.child.wait_timeout(left, stop)?.is_none() {
            eprintln!("  {} did not finish in time: killed", b.child.name());
            b.child.kill();
        }
        let r = BotReports::parse(&std::fs::read_to_string(&b.out).unwrap_or_default());
        reports.reports += r.reports;
        reports.ended += r.ended;
    }
    server.child.terminate(Duration::from_secs(5));

    let result = summarise(config, &first, &last, peak_rss_kib)?;
    let missing_reports = wanted.saturating_sub(reports.reports);
    Ok(RunResult {
        connected,
        min_players,
        dropped: (reports.ended + missing_reports).max(wanted.saturating_sub(players_end)),
        ..result
    })
}

/// Bytes of IPv4 (20) and UDP (8) header on every datagram: the wire
/// figures add them to the UDP payload the server counts (link-layer
/// framing is not counted).
const IP_UDP_HEADER: f64 = 28.0;

fn summarise(
    config: &RunConfig,
    first: &Reading,
    last: &Reading,
    peak_rss_kib: u64,
) -> anyhow::Result<RunResult> {
    let (a, b) = (&first.scrape, &last.scrape);
    let window = last.at.duration_since(first.at).as_secs_f64().max(1e-3);
    let delta = |name: &str| (b.sum(name) - a.sum(name)).max(0.0);
    let ticks_hist = b
        .histogram("ledge_tick_duration_fine_seconds")?
        .since(&a.histogram("ledge_tick_duration_fine_seconds")?)?;
    if ticks_hist.is_empty() {
        bail!("the server does not serve ledge_tick_duration_fine_seconds (an older build?)");
    }
    let lateness: Buckets = b
        .histogram("ledge_tick_lateness_seconds")?
        .since(&a.histogram("ledge_tick_lateness_seconds")?)?;
    let ticks = ticks_hist.total();
    let tick_sum = delta("ledge_tick_duration_fine_seconds_sum");
    let clients = ((players(a) + players(b)) as f64 / 2.0).max(1.0);
    let hz = procstat::clock_ticks_per_second() as f64;
    let cpu_pct = |ticks: u64| ticks as f64 / hz / window * 100.0;
    let player_ticks = clients * window * f64::from(config.tick_hz);
    let per_client = |name: &str| delta(name) / window / clients;
    let packets_up = per_client("ledge_wire_datagrams_in_total");
    let packets_down = per_client("ledge_wire_datagrams_out_total");
    Ok(RunResult {
        bots: config.bots,
        client: config.client_label(),
        rooms: config.rooms(),
        bot_processes: config.split().len(),
        window_s: window,
        ticks,
        tick_p50: ticks_hist.quantile(0.5),
        tick_p99: ticks_hist.quantile(0.99),
        tick_max: ticks_hist.max_bound(),
        tick_mean: (ticks > 0).then(|| tick_sum / ticks as f64),
        missed_ticks: delta("ledge_missed_ticks_total") as u64,
        late_wakeups: lateness.count_above(1.0 / f64::from(config.tick_hz.max(1))),
        lateness_p99: lateness.quantile(0.99),
        up_bytes_per_client_s: per_client("ledge_bytes_in_total"),
        down_bytes_per_client_s: per_client("ledge_bytes_out_total"),
        wire_up_bytes_per_client_s: per_client("ledge_wire_bytes_in_total")
            + IP_UDP_HEADER * packets_up,
        wire_down_bytes_per_client_s: per_client("ledge_wire_bytes_out_total")
            + IP_UDP_HEADER * packets_down,
        packets_up_per_client_s: packets_up,
        packets_down_per_client_s: packets_down,
        server_cpu_pct: cpu_pct(last.server_cpu.saturating_sub(first.server_cpu)),
        server_run_queue_wait_ms_s: last.server_wait_ns.saturating_sub(first.server_wait_ns) as f64
            / 1e6
            / window,
        server_peak_rss_mib: peak_rss_kib as f64 / 1024.0,
        bot_cpu_pct: cpu_pct(last.bot_cpu.saturating_sub(first.bot_cpu)),
        mean_players: clients,
        connected: 0,
        min_players: 0,
        dropped: 0,
        starved_pct: delta("ledge_input_starvation_total") / player_ticks * 100.0,
        load: (first.load, last.load),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(bots: usize, procs: usize) -> RunConfig {
        RunConfig {
            bots,
            client: ClientKind::Bot,
            bot_processes: procs,
            max_players: 16,
            tick_hz: 60,
            snapshot_hz: 30,
            server_threads: None,
            brain: "runner".into(),
            warmup: Duration::from_secs(1),
            duration: Duration::from_secs(1),
            bin_dir: PathBuf::new(),
            log_dir: PathBuf::new(),
        }
    }

    #[test]
    fn bots_are_split_evenly_and_rooms_hold_them_all() {
        assert_eq!(config(256, 3).split(), vec![86, 85, 85]);
        assert_eq!(config(16, 1).split(), vec![16]);
        assert_eq!(config(2, 8).split(), vec![1, 1]);
        assert_eq!(config(256, 3).rooms(), 16);
        assert_eq!(config(17, 1).rooms(), 2);
        assert_eq!(config(1, 1).rooms(), 1);
        assert!(config(256, 1).join_allowance() > config(256, 4).join_allowance());
    }

    #[test]
    fn bot_reports_count_early_ends() {
        let out = "3 bots, brain Runner:\n\
            p1-1       runner  player    1  ticks  1800  snapshots  900  goal no\n\
            p1-2       runner  player    2  ticks   100  snapshots   50  goal no  ended: closed by the server\n\
            p1-3       runner  player    -  ticks     0  snapshots    0  goal no  ended: cannot connect: refused\n\
            a bot task failed: panicked\n\
            0/3 reached the goal (as the server saw it)\n";
        assert_eq!(
            BotReports::parse(out),
            BotReports {
                reports: 4,
                ended: 3
            }
        );
    }
}
