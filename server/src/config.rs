//! Server settings: command-line flags, an optional TOML file, defaults.
//!
//! Precedence: a flag given on the command line wins over the file
//! (`--config PATH`), which wins over the defaults below. The file uses the
//! flags' names with underscores (`tick_rate = 60`), plus a `[limits]`
//! table for the per-client rate limits; unknown keys are errors, so a typo
//! never silently falls back to a default.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::Duration;

use clap::Parser;
use ledge_shared::protocol::{VoteRule, MAX_LEVEL_BUNDLE, MAX_ROOMS};
use serde::Deserialize;

use ledge_shared::game::{GameConfig, MAX_RESPAWN_DELAY_TICKS};

use crate::admission::AdmissionConfig;
use crate::fleet::FleetConfig;
use crate::records::RecordsTarget;
use crate::replays::ReplaysTarget;
use crate::web::guard::{mbps_to_bytes, WebLimits, DEFAULT_ADDRESS_SHARE};

/// Default UDP address the server listens on.
pub const DEFAULT_BIND: &str = "0.0.0.0:4433";
/// Default directory of the certificate and key.
pub const DEFAULT_CERT_DIR: &str = "certs";
/// Default directory of the web page (`--web-root`), relative to the
/// working directory.
pub const DEFAULT_WEB_ROOT: &str = "web/dist";
/// Default simulation rate in Hz.
pub const DEFAULT_TICK_RATE: u32 = 60;
/// Default snapshot rate in Hz.
pub const DEFAULT_SNAPSHOT_RATE: u32 = 30;
/// Default most players in one room.
pub const DEFAULT_MAX_PLAYERS: usize = 16;
/// Default most spectators per room.
pub const DEFAULT_MAX_SPECTATORS: usize = 16;
/// Default number of rooms.
pub const DEFAULT_ROOMS: u32 = 1;
/// Default most rooms at once, counting those players open by name (the
/// cap is at least `rooms`).
pub const DEFAULT_MAX_ROOMS: u32 = 16;
/// Default time a joined player may send no input before it is removed
/// (half of it while its room is full).
pub const DEFAULT_IDLE_KICK: Duration = Duration::from_secs(30);
/// Default time a player whose connection was lost is kept for a resume.
pub const DEFAULT_RECONNECT_GRACE: Duration = Duration::from_secs(30);
/// Default largest level bundle the server offers, MiB: a level (with its
/// art) that encodes bigger is refused at start.
pub const DEFAULT_MAX_LEVEL_MIB: u64 = 32;
/// Default most joined connections (players, room listings); connections
/// before their hello have a pool of their own ([`AdmissionConfig::pending`]).
pub const DEFAULT_MAX_CONNECTIONS: usize = 256;
/// Default bound on ticks run back to back after a stall (0.25 s at 60 Hz).
pub const DEFAULT_MAX_CATCH_UP: u32 = 15;
/// Most runtime threads (`--threads`).
pub const MAX_THREADS: usize = 1024;
/// Default QUIC idle timeout: a connection with no traffic for this long is
/// dropped (clients send keep-alives every [`DEFAULT_IDLE_TIMEOUT`] / 3).
pub const DEFAULT_IDLE_TIMEOUT: Duration = Duration::from_secs(10);

/// Default time a dead player waits before it respawns.
pub const DEFAULT_RESPAWN_DELAY: Duration = Duration::from_millis(400);
/// Longest respawn delay.
pub const MAX_RESPAWN_DELAY: Duration = Duration::from_secs(10);

/// Per-client rate limits and abuse thresholds (the file's `[limits]`).
///
/// Each limit is a token bucket: `*_per_second` tokens refill it up to
/// `*_burst`; a message that finds it empty is dropped and counted.
/// Dropped or malformed messages also drain a *strike* bucket; a client
/// that empties it is disconnected.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Limits {
    /// Input datagrams per second (a client sends one per tick).
    pub datagrams_per_second: f64,
    /// Input datagrams accepted in a burst.
    pub datagram_burst: f64,
    /// Control-stream messages per second (chat, pings).
    pub control_per_second: f64,
    /// Control-stream messages accepted in a burst.
    pub control_burst: f64,
    /// Malformed messages tolerated in a burst before disconnecting.
    pub malformed_burst: f64,
    /// Malformed messages forgiven per second.
    pub malformed_per_second: f64,
    /// Rate-limited messages tolerated in a burst before disconnecting.
    pub flood_burst: f64,
    /// Rate-limited messages forgiven per second.
    pub flood_per_second: f64,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            // Twice the default tick rate: clock corrections and bursts
            // after a hiccup stay well inside it.
            datagrams_per_second: 120.0,
            datagram_burst: 60.0,
            control_per_second: 10.0,
            control_burst: 20.0,
            malformed_burst: 20.0,
            malformed_per_second: 0.5,
            flood_burst: 300.0,
            flood_per_second: 30.0,
        }
    }
}

/// Everything [`crate::Server::bind`] needs.
#[derive(Debug, Clone, PartialEq)]
pub struct ServerConfig {
    /// UDP address to listen on; port 0 picks a free port (tests).
    pub bind: SocketAddr,
    /// Where the certificate and key are kept (created if missing).
    pub cert_dir: PathBuf,
    /// The levels to play in turn: level files, folders of them,
    /// playlists (`.txt`) or Tiled worlds (`.world`); none: the embedded
    /// default level ([`crate::levels::LevelSet::load`]).
    pub levels: Vec<PathBuf>,
    /// The level's settings file (`None`: `LEVEL.ledge.toml` beside the
    /// level, when there is one); only with a single level.
    pub level_settings: Option<PathBuf>,
    /// When a room moves to the next level, and how players vote.
    pub rotation: RotationConfig,
    /// Simulation ticks per second.
    pub tick_rate: u32,
    /// Snapshots per second (rounded to a whole number of ticks between
    /// snapshots: see [`ServerConfig::snapshot_interval`]).
    pub snapshot_rate: u32,
    /// Most players in one room.
    pub max_players: usize,
    /// Most spectators in one room (`ClientControl::Spectate`; they take
    /// no player's place).
    pub max_spectators: usize,
    /// Number of rooms open from the start and never closed (named
    /// `room-1`, `room-2`, ...).
    pub rooms: u32,
    /// Most rooms at once: a client asking for a room by a new name opens
    /// it while fewer are open (it closes once empty for a while). At least
    /// `rooms`, at most [`MAX_ROOMS`].
    pub max_rooms: u32,
    /// Most joined connections; a newcomer while this many have joined is
    /// refused at its first packet. Connections before their hello are
    /// limited by [`ServerConfig::admission`].
    pub max_connections: usize,
    /// Largest level bundle (level and art, as clients download it), MiB;
    /// a bigger one stops the server at start. At most
    /// [`MAX_LEVEL_BUNDLE`] (96 MiB).
    pub max_level_mib: u64,
    /// TCP address of the Prometheus metrics endpoint; `None`: no endpoint.
    pub metrics_bind: Option<SocketAddr>,
    /// Most ticks run back to back after a stall; older ones are skipped.
    pub max_catch_up: u32,
    /// Threads of the runtime `ledge-server` builds for the rooms and the
    /// connections; `None`: one per core. One thread runs everything on
    /// one (the least CPU per player: no hand-offs between threads; run a
    /// server per core to use more). [`crate::Server::bind`] itself runs
    /// on whatever runtime calls it.
    pub threads: Option<usize>,
    /// QUIC idle timeout: silent connections are dropped after it.
    pub idle_timeout: Duration,
    /// A joined player that sends no input for this long is removed (half
    /// of it while its room is full), so silent clients cannot hold
    /// seats; a connected client sends an input every tick.
    pub idle_kick: Duration,
    /// How long a player whose connection was lost stays in its room (still)
    /// for its client to resume it; then it leaves.
    pub reconnect_grace: Duration,
    /// Per-client rate limits.
    pub limits: Limits,
    /// Limits on new connections: per address, before the hello.
    pub admission: AdmissionConfig,
    /// How long a player who died stays dead before it respawns at its
    /// checkpoint (rounded to whole ticks; clients learn it in `Welcome`).
    pub respawn_delay: Duration,
    /// Record each room's match (inputs, joins and leaves, state hash per
    /// tick) for its first this many ticks; `None` (the default): off. Set
    /// programmatically (tests, tools); read with
    /// [`crate::Server::recorder`]. See [`crate::record`].
    pub record_ticks: Option<usize>,
    /// Run as an Agones GameServer (`--agones`): the fleet logic's
    /// settings; `None`: not under Agones. Needs the `agones` cargo
    /// feature.
    pub agones: Option<FleetConfig>,
    /// Browsers: the web port and WebTransport (`--web-bind`); `None`
    /// (the default): no web port.
    pub web: Option<WebConfig>,
    /// Where finished runs are stored (`--records`); `None` (the
    /// default): [`crate::records::DEFAULT_FILE`] in `cert_dir`.
    pub records: Option<RecordsTarget>,
    /// How often records that could not be opened at start are tried
    /// again (set programmatically; 30 s).
    pub records_retry: Duration,
    /// Where replays are saved (`--replays`); `None` (the default):
    /// [`crate::replays::DEFAULT_DIR`] in `cert_dir`.
    pub replays: Option<ReplaysTarget>,
    /// Most bytes the replays take (`--replays-cap-mib`); the oldest go
    /// first, the records' own last.
    pub replays_cap: u64,
}

/// Where browsers connect (docs/SERVER.md, "Browsers").
#[derive(Debug, Clone, PartialEq)]
pub struct WebConfig {
    /// TCP address of the HTTP/1.1 server: the page, `/web.json`,
    /// `/level`, WebSocket sessions at `/ws`.
    pub bind: SocketAddr,
    /// The web page's directory (read once at start).
    pub root: PathBuf,
    /// UDP address of WebTransport sessions; `None`: WebTransport off.
    pub webtransport: Option<SocketAddr>,
    /// How long WebTransport certificates live (13 days; tests shorten it
    /// to see a rotation).
    pub cert_life: crate::web::webtransport_cert::CertLife,
    /// The web port's per-address limits and uplink budget.
    pub limits: WebLimits,
}

impl WebConfig {
    /// The web port at `bind` with the default page directory and
    /// WebTransport on the same port number.
    pub fn new(bind: SocketAddr) -> WebConfig {
        WebConfig {
            bind,
            root: PathBuf::from(DEFAULT_WEB_ROOT),
            webtransport: Some(bind),
            cert_life: Default::default(),
            limits: WebLimits::default(),
        }
    }
}

impl Default for ServerConfig {
    fn default() -> ServerConfig {
        ServerConfig {
            bind: DEFAULT_BIND.parse().expect("valid default address"),
            cert_dir: PathBuf::from(DEFAULT_CERT_DIR),
            levels: Vec::new(),
            level_settings: None,
            rotation: RotationConfig::default(),
            tick_rate: DEFAULT_TICK_RATE,
            snapshot_rate: DEFAULT_SNAPSHOT_RATE,
            max_players: DEFAULT_MAX_PLAYERS,
            max_spectators: DEFAULT_MAX_SPECTATORS,
            rooms: DEFAULT_ROOMS,
            max_rooms: DEFAULT_MAX_ROOMS,
            max_connections: DEFAULT_MAX_CONNECTIONS,
            max_level_mib: DEFAULT_MAX_LEVEL_MIB,
            metrics_bind: None,
            max_catch_up: DEFAULT_MAX_CATCH_UP,
            threads: None,
            idle_timeout: DEFAULT_IDLE_TIMEOUT,
            reconnect_grace: DEFAULT_RECONNECT_GRACE,
            idle_kick: DEFAULT_IDLE_KICK,
            limits: Limits::default(),
            admission: AdmissionConfig::default(),
            respawn_delay: DEFAULT_RESPAWN_DELAY,
            record_ticks: None,
            agones: None,
            web: None,
            records: None,
            records_retry: Duration::from_secs(30),
            replays: None,
            replays_cap: crate::replays::DEFAULT_CAP_MIB << 20,
        }
    }
}

impl ServerConfig {
    /// Where the records go: `--records`, or the default file in the
    /// certificate directory.
    pub fn records_target(&self) -> RecordsTarget {
        self.records
            .clone()
            .unwrap_or_else(|| RecordsTarget::in_state_dir(&self.cert_dir))
    }

    /// Where the replays go: `--replays`, or the default folder in the
    /// certificate directory.
    pub fn replays_target(&self) -> ReplaysTarget {
        self.replays
            .clone()
            .unwrap_or_else(|| ReplaysTarget::in_state_dir(&self.cert_dir))
    }

    /// The game's configuration: the defaults with this server's respawn
    /// delay in ticks.
    pub fn game_config(&self) -> GameConfig {
        let mut game = GameConfig::default();
        let ticks = (self.respawn_delay.as_secs_f64() * f64::from(self.tick_rate)).round();
        game.player.respawn_delay_ticks = ticks.min(f64::from(u16::MAX)) as u16;
        game
    }

    /// Ticks between two snapshots: `tick_rate / snapshot_rate`, rounded to
    /// the nearest whole tick, at least 1.
    pub fn snapshot_interval(&self) -> u32 {
        let rate = self.snapshot_rate.clamp(1, self.tick_rate.max(1));
        ((self.tick_rate + rate / 2) / rate).max(1)
    }

    /// Checks the values are usable.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let bad = |what: &str| Err(ConfigError::Invalid(what.to_owned()));
        if !(1..=1000).contains(&self.tick_rate) {
            return bad("tick_rate must be 1..=1000 Hz");
        }
        if self.snapshot_rate == 0 || self.snapshot_rate > self.tick_rate {
            return bad("snapshot_rate must be 1..=tick_rate Hz");
        }
        if self.max_players == 0 {
            return bad("max_players must be at least 1");
        }
        if self.rooms == 0 || self.rooms as usize > MAX_ROOMS {
            return Err(ConfigError::Invalid(format!(
                "rooms must be 1..={MAX_ROOMS}"
            )));
        }
        if self.max_rooms < self.rooms || self.max_rooms as usize > MAX_ROOMS {
            return Err(ConfigError::Invalid(format!(
                "max_rooms must be rooms ({})..={MAX_ROOMS}",
                self.rooms
            )));
        }
        if self.max_level_mib == 0 || self.max_level_mib > MAX_LEVEL_BUNDLE >> 20 {
            return Err(ConfigError::Invalid(format!(
                "max_level_mib must be 1..={}",
                MAX_LEVEL_BUNDLE >> 20
            )));
        }
        if self.max_connections == 0 {
            return bad("max_connections must be at least 1");
        }
        if self
            .threads
            .is_some_and(|n| !(1..=MAX_THREADS).contains(&n))
        {
            return Err(ConfigError::Invalid(format!(
                "threads must be 1..={MAX_THREADS}"
            )));
        }
        if self.record_ticks == Some(0) {
            return bad("record_ticks must be at least 1 when set");
        }
        if self.idle_kick < Duration::from_millis(300) {
            return bad("idle_kick must be at least 0.3 s");
        }
        if self.reconnect_grace > Duration::from_secs(3600) {
            return bad("reconnect_grace must be at most 3600 s");
        }
        let delay_ticks = self.game_config().player.respawn_delay_ticks;
        if self.respawn_delay > MAX_RESPAWN_DELAY || delay_ticks > MAX_RESPAWN_DELAY_TICKS {
            return Err(ConfigError::Invalid(format!(
                "respawn_delay must be at most {} s and {MAX_RESPAWN_DELAY_TICKS} ticks",
                MAX_RESPAWN_DELAY.as_secs()
            )));
        }
        if self.idle_timeout < Duration::from_millis(100) {
            return bad("idle_timeout must be at least 0.1 s");
        }
        if let Some(web) = &self.web {
            web.limits.check().map_err(ConfigError::Invalid)?;
        }
        let l = &self.limits;
        let rates = [
            l.datagrams_per_second,
            l.datagram_burst,
            l.control_per_second,
            l.control_burst,
            l.malformed_burst,
            l.malformed_per_second,
            l.flood_burst,
            l.flood_per_second,
        ];
        if rates.iter().any(|r| !r.is_finite() || *r < 0.0) {
            return bad("limits must be finite and not negative");
        }
        if l.datagram_burst < 1.0 || l.control_burst < 1.0 {
            return bad("datagram_burst and control_burst must be at least 1");
        }
        let a = &self.admission;
        if a.per_address == 0 || a.pending_per_address == 0 || a.pending == 0 {
            return bad(
                "admission: per_address, pending_per_address and pending must be at least 1",
            );
        }
        if a.pending_per_address > a.per_address {
            return bad("admission: pending_per_address must be at most per_address");
        }
        if !(Duration::from_millis(100)..=Duration::from_secs(60)).contains(&a.hello_timeout) {
            return bad("admission: hello_timeout must be 0.1..=60 s");
        }
        if let Some(f) = &self.agones {
            if !(Duration::from_millis(100)..=Duration::from_secs(60)).contains(&f.health_every) {
                return bad("agones: health_every must be 0.1..=60 s");
            }
            if f.shutdown_after > Duration::from_secs(24 * 3600) {
                return bad("agones: shutdown_after must be at most 86400 s");
            }
            if !(Duration::from_millis(100)..=Duration::from_secs(600)).contains(&f.connect_timeout)
            {
                return bad("agones: connect_timeout must be 0.1..=600 s");
            }
        }
        Ok(())
    }
}

/// Why the configuration could not be built.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The configuration file could not be read.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The configuration file is not valid TOML of the expected shape.
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What the parser said.
        message: String,
    },
    /// A value is out of range.
    #[error("invalid configuration: {0}")]
    Invalid(String),
}

/// Authoritative ledge server (QUIC over UDP).
///
/// Every option can also be set in the `--config` TOML file (same names,
/// with underscores); flags override the file.
#[derive(Debug, Default, Parser)]
#[command(version)]
pub struct Cli {
    /// TOML configuration file.
    #[arg(long, value_name = "PATH")]
    pub config: Option<PathBuf>,
    /// UDP address to listen on: ADDR:PORT, HOST:PORT (resolved, the
    /// first address) or a bare PORT (all interfaces) [default:
    /// 0.0.0.0:4433].
    #[arg(long, value_name = "ADDR:PORT", value_parser = parse_bind)]
    pub bind: Option<SocketAddr>,
    /// Level to play: a level file (OGMO .json, Tiled .tmx), a folder of
    /// them, a playlist (.txt, a path per line) or a Tiled .world;
    /// repeated, the rooms play them in turn [default: the embedded
    /// default level].
    #[arg(long, value_name = "PATH")]
    pub level: Vec<PathBuf>,
    /// With several levels, a room moves to the next one this many
    /// seconds after the level started, finished or not (0: only when
    /// everyone finished or by vote) [default: 300].
    #[arg(long, value_name = "SECS")]
    pub level_time: Option<f64>,
    /// Seconds between everyone finishing (or a vote's majority) and the
    /// move to the next level, for the results [default: 8].
    #[arg(long, value_name = "SECS")]
    pub results_time: Option<f64>,
    /// How players choose the next level: majority (more than half of a
    /// room's players), host (the room's longest-present player decides)
    /// or off (the levels come in turn) [default: majority].
    #[arg(long, value_name = "RULE", value_parser = parse_vote)]
    pub vote: Option<VoteRule>,
    /// The level's settings file [default: LEVEL.ledge.toml beside the
    /// level, when there is one].
    #[arg(long, value_name = "PATH")]
    pub level_settings: Option<PathBuf>,
    /// Simulation ticks per second [default: 60].
    #[arg(long, value_name = "HZ")]
    pub tick_rate: Option<u32>,
    /// Snapshots per second [default: 30].
    #[arg(long, value_name = "HZ")]
    pub snapshot_rate: Option<u32>,
    /// Most players per room [default: 16].
    #[arg(long, value_name = "N")]
    pub max_players: Option<usize>,
    /// Most spectators per room (they take no player's place) [default:
    /// 16].
    #[arg(long, value_name = "N")]
    pub max_spectators: Option<usize>,
    /// Rooms open from the start (room-1, room-2, ...) [default: 1].
    #[arg(long, value_name = "N")]
    pub rooms: Option<u32>,
    /// Most rooms at once, counting rooms players open by name with
    /// `--room NAME` [default: 16, or --rooms if more].
    #[arg(long, value_name = "N")]
    pub max_rooms: Option<u32>,
    /// Most joined connections (players, room listings) [default: 256].
    #[arg(long, value_name = "N")]
    pub max_connections: Option<usize>,
    /// Threads running the rooms and the connections. 1 runs everything on
    /// one thread: the least CPU per player (no hand-offs between
    /// threads); run one server per core to use more [default: one per
    /// core].
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Most connections from one address (an IPv4 address or an IPv6 /64);
    /// raise it for many players behind one NAT, or bots on one machine
    /// [default: 4].
    #[arg(long, value_name = "N")]
    pub max_per_address: Option<usize>,
    /// Most connections from one address still in their handshake (before
    /// the hello) [default: as --max-per-address].
    #[arg(long, value_name = "N")]
    pub max_pending_per_address: Option<usize>,
    /// Most connections in their handshake in all; when full, the oldest of
    /// the address holding the most is closed for a newcomer [default: 32].
    #[arg(long, value_name = "N")]
    pub max_pending: Option<usize>,
    /// Seconds a player who died stays dead before it respawns at its
    /// checkpoint, at most 10 [default: 0.4].
    #[arg(long, value_name = "SECONDS")]
    pub respawn_delay: Option<f64>,
    /// Seconds a new connection has to finish its QUIC handshake and send
    /// its hello [default: 2].
    #[arg(long, value_name = "SECONDS")]
    pub hello_timeout: Option<f64>,
    /// Seconds a player whose connection was lost is kept for its client to
    /// come back (same player, position, coins) [default: 30].
    #[arg(long, value_name = "SECONDS")]
    pub reconnect_grace: Option<f64>,
    /// Largest level clients download (the level and its images, encoded),
    /// in MiB; a bigger level stops the server at start [default: 32].
    #[arg(long, value_name = "MIB")]
    pub max_level_mib: Option<u64>,
    /// Directory of the certificate and key, created on first start
    /// [default: certs].
    #[arg(long, value_name = "DIR")]
    pub cert_dir: Option<PathBuf>,
    /// TCP address serving Prometheus metrics at /metrics [default: none].
    #[arg(long, value_name = "ADDR:PORT")]
    pub metrics_bind: Option<SocketAddr>,
    /// Run as an Agones GameServer: say Ready through the SDK sidecar
    /// (AGONES_SDK_GRPC_PORT, default 9357), send health pings while the
    /// rooms tick, publish the rooms and players counters, the rooms list,
    /// the full label and the certificate's fingerprint, and shut down
    /// once Allocated and empty (docs/DEPLOY.md). Needs a server built with
    /// the `agones` feature.
    #[arg(long)]
    pub agones: bool,
    /// Under Agones, once Allocated: shut down after no player has been in
    /// any room this long, in seconds [default: 60].
    #[arg(long, value_name = "SECONDS", requires = "agones")]
    pub agones_shutdown_after: Option<f64>,
    /// Under Agones: seconds between health pings [default: 2].
    #[arg(long, value_name = "SECONDS", requires = "agones")]
    pub agones_health_every: Option<f64>,
    /// TCP address of the web port for browsers: the web page, /web.json,
    /// /level and WebSocket sessions at /ws; WebTransport listens on the
    /// same port number over UDP unless told otherwise [default: off].
    #[arg(long, value_name = "ADDR:PORT", value_parser = parse_bind)]
    pub web_bind: Option<SocketAddr>,
    /// Directory of the web page (built by scripts/build-web), read at
    /// start [default: web/dist].
    #[arg(long, value_name = "DIR")]
    pub web_root: Option<PathBuf>,
    /// UDP address of WebTransport sessions [default: the --web-bind
    /// address].
    #[arg(long, value_name = "ADDR:PORT", value_parser = parse_bind)]
    pub webtransport_bind: Option<SocketAddr>,
    /// No WebTransport: browsers use WebSocket only.
    #[arg(long)]
    pub no_webtransport: bool,
    /// Where finished runs are stored: an SQLite file (created if
    /// missing), a postgres:// URL (a fleet sharing one store), or `off`
    /// [default: records.sqlite in --cert-dir].
    #[arg(long, value_name = "PATH|URL|off")]
    pub records: Option<String>,
    /// Folder where each finished run and each match is saved as a replay
    /// (served at /replays/ID on the web port), or `off` [default: replays
    /// in --cert-dir].
    #[arg(long, value_name = "DIR|off")]
    pub replays: Option<String>,
    /// Most MiB the replays take; past it the oldest are deleted, except
    /// those of each level's top ten [default: 1024].
    #[arg(long, value_name = "MIB")]
    pub replays_cap_mib: Option<u64>,
    /// The host's upload budget for the web port's downloads (the page,
    /// the level), Mbit/s, all addresses together [default: 100].
    #[arg(long, value_name = "MBPS")]
    pub web_uplink_mbps: Option<f64>,
    /// Of that, the most one address may take, Mbit/s [default: a quarter
    /// of --web-uplink-mbps].
    #[arg(long, value_name = "MBPS")]
    pub web_address_mbps: Option<f64>,
}

/// When a room moves to its next level and how players vote
/// ([`crate::rotation`]). Only a server with several levels moves on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotationConfig {
    /// A level is played at most this long (`None`: until everyone
    /// finished, or a vote).
    pub level_time: Option<Duration>,
    /// The pause between the decision (everyone finished, a majority)
    /// and the change, for the results card.
    pub results_time: Duration,
    /// How votes count.
    pub vote: VoteRule,
}

impl Default for RotationConfig {
    fn default() -> RotationConfig {
        RotationConfig {
            level_time: Some(Duration::from_secs(300)),
            results_time: Duration::from_secs(8),
            vote: VoteRule::Majority,
        }
    }
}

/// `--vote`'s values.
fn parse_vote(s: &str) -> Result<VoteRule, String> {
    [VoteRule::Majority, VoteRule::Host, VoteRule::Off]
        .into_iter()
        .find(|r| r.name() == s)
        .ok_or_else(|| format!("{s:?} is not a vote rule: majority, host or off"))
}

/// A TOML value that is one path or a list of them (`level`).
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum OneOrMany {
    One(PathBuf),
    Many(Vec<PathBuf>),
}

impl OneOrMany {
    fn into_vec(self) -> Vec<PathBuf> {
        match self {
            OneOrMany::One(p) => vec![p],
            OneOrMany::Many(v) => v,
        }
    }
}

/// The TOML file: every key optional.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileConfig {
    /// As `--bind`: ADDR:PORT, HOST:PORT or PORT.
    bind: Option<String>,
    /// A path, or a list of them.
    level: Option<OneOrMany>,
    /// Seconds.
    level_time: Option<f64>,
    /// Seconds.
    results_time: Option<f64>,
    /// As `--vote`.
    vote: Option<String>,
    level_settings: Option<PathBuf>,
    tick_rate: Option<u32>,
    snapshot_rate: Option<u32>,
    max_players: Option<usize>,
    max_spectators: Option<usize>,
    rooms: Option<u32>,
    max_rooms: Option<u32>,
    max_connections: Option<usize>,
    max_level_mib: Option<u64>,
    cert_dir: Option<PathBuf>,
    metrics_bind: Option<SocketAddr>,
    max_catch_up: Option<u32>,
    threads: Option<usize>,
    /// Seconds.
    idle_timeout: Option<f64>,
    /// Seconds.
    reconnect_grace: Option<f64>,
    /// Seconds.
    idle_kick: Option<f64>,
    /// Seconds.
    respawn_delay: Option<f64>,
    limits: Option<Limits>,
    admission: Option<FileAdmission>,
    agones: Option<FileAgones>,
    /// As `--web-bind`.
    web_bind: Option<String>,
    web_root: Option<PathBuf>,
    /// As `--webtransport-bind`.
    webtransport_bind: Option<String>,
    /// `false`: as `--no-webtransport`.
    webtransport: Option<bool>,
    web_limits: Option<FileWebLimits>,
    /// As `--records`.
    records: Option<String>,
    /// As `--replays`.
    replays: Option<String>,
    /// As `--replays-cap-mib`.
    replays_cap_mib: Option<u64>,
}

/// The file's `[web_limits]`: every key optional (docs/SERVER.md).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileWebLimits {
    connections_per_address: Option<usize>,
    requests_per_second: Option<f64>,
    request_burst: Option<f64>,
    downloads_per_address: Option<usize>,
    downloads_per_minute: Option<u32>,
    uplink_mbps: Option<f64>,
    address_mbps: Option<f64>,
}

impl FileWebLimits {
    /// The limits: defaults, then the file's keys, then the flags' rates.
    fn resolve(&self, uplink_flag: Option<f64>, address_flag: Option<f64>) -> WebLimits {
        let mut l = WebLimits::default();
        set(&mut l.connections_per_address, self.connections_per_address);
        set(&mut l.requests_per_second, self.requests_per_second);
        set(&mut l.request_burst, self.request_burst);
        set(&mut l.downloads_per_address, self.downloads_per_address);
        set(&mut l.downloads_per_minute, self.downloads_per_minute);
        let uplink = uplink_flag.or(self.uplink_mbps);
        if let Some(mbps) = uplink {
            l.uplink_bytes_per_second = mbps_to_bytes(mbps);
            l.address_bytes_per_second = mbps_to_bytes(mbps * DEFAULT_ADDRESS_SHARE);
        }
        if let Some(mbps) = address_flag.or(self.address_mbps) {
            l.address_bytes_per_second = mbps_to_bytes(mbps);
        }
        l
    }
}

/// The file's `[agones]`: present (even empty) means run under Agones.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileAgones {
    /// Seconds.
    shutdown_after: Option<f64>,
    /// Seconds.
    health_every: Option<f64>,
    /// Seconds.
    connect_timeout: Option<f64>,
}

/// The file's `[admission]`: every key optional.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileAdmission {
    per_address: Option<usize>,
    pending_per_address: Option<usize>,
    pending: Option<usize>,
    /// Seconds.
    hello_timeout: Option<f64>,
    retry_above: Option<usize>,
}

/// Seconds from the file or a flag, as a duration; `key` names it.
fn seconds(secs: f64, key: &str) -> Result<Duration, ConfigError> {
    Duration::try_from_secs_f64(secs)
        .map_err(|_| ConfigError::Invalid(format!("{key} must be seconds (not {secs})")))
}

impl Cli {
    /// Where the records and the replays go: the flags, else the file (a
    /// relative path in the file being relative to it).
    fn resolve_stores(
        &self,
        file: &FileConfig,
        c: &mut ServerConfig,
        relative: &dyn Fn(PathBuf) -> PathBuf,
    ) {
        if let Some(r) = self.records.as_deref().or(file.records.as_deref()) {
            c.records = Some(match RecordsTarget::parse(r) {
                RecordsTarget::Sqlite(p) if self.records.is_none() => {
                    RecordsTarget::Sqlite(relative(p))
                }
                target => target,
            });
        }
        if let Some(r) = self.replays.as_deref().or(file.replays.as_deref()) {
            c.replays = Some(match ReplaysTarget::parse(r) {
                ReplaysTarget::Dir(p) if self.replays.is_none() => ReplaysTarget::Dir(relative(p)),
                target => target,
            });
        }
        if let Some(mib) = self.replays_cap_mib.or(file.replays_cap_mib) {
            c.replays_cap = mib.saturating_mul(1 << 20);
        }
    }

    /// The rotation's times and vote rule: the file's, then the flags'.
    fn resolve_rotation(
        &self,
        file: &FileConfig,
        r: &mut RotationConfig,
    ) -> Result<(), ConfigError> {
        if let Some(secs) = self.level_time.or(file.level_time) {
            r.level_time = (secs != 0.0)
                .then(|| seconds(secs, "level_time"))
                .transpose()?;
        }
        if let Some(secs) = self.results_time.or(file.results_time) {
            r.results_time = seconds(secs, "results_time")?;
        }
        if let Some(rule) = self.vote {
            r.vote = rule;
        } else if let Some(rule) = &file.vote {
            r.vote = parse_vote(rule).map_err(|message| ConfigError::Parse {
                path: self.config.clone().unwrap_or_default(),
                message: format!("vote: {message}"),
            })?;
        }
        Ok(())
    }

    /// The configuration: defaults, then the file (if any), then the flags.
    pub fn resolve(&self) -> Result<ServerConfig, ConfigError> {
        let file = match &self.config {
            Some(path) => {
                let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
                    path: path.clone(),
                    source,
                })?;
                parse_file(&text, path)?
            }
            None => FileConfig::default(),
        };
        let mut c = ServerConfig::default();
        // File values, resolving relative paths against the file's folder.
        let base = self.config.as_deref().and_then(Path::parent);
        let relative = |p: PathBuf| match base {
            Some(dir) if p.is_relative() => dir.join(p),
            _ => p,
        };
        self.resolve_stores(&file, &mut c, &relative);
        if let Some(b) = &file.bind {
            c.bind = parse_bind(b).map_err(|message| ConfigError::Parse {
                path: self.config.clone().unwrap_or_default(),
                message: format!("bind: {message}"),
            })?;
        }
        if let Some(levels) = file.level.clone() {
            c.levels = levels.into_vec().into_iter().map(relative).collect();
        }
        self.resolve_rotation(&file, &mut c.rotation)?;
        set(
            &mut c.level_settings,
            file.level_settings.map(|p| Some(relative(p))),
        );
        set(&mut c.tick_rate, file.tick_rate);
        set(&mut c.snapshot_rate, file.snapshot_rate);
        set(&mut c.max_players, file.max_players);
        set(&mut c.max_spectators, file.max_spectators);
        set(&mut c.rooms, file.rooms);
        set(&mut c.max_rooms, file.max_rooms);
        set(&mut c.max_connections, file.max_connections);
        set(&mut c.max_level_mib, file.max_level_mib);
        set(&mut c.cert_dir, file.cert_dir.map(relative));
        set(&mut c.metrics_bind, file.metrics_bind.map(Some));
        set(&mut c.max_catch_up, file.max_catch_up);
        set(&mut c.threads, file.threads.map(Some));
        if let Some(secs) = file.idle_timeout {
            c.idle_timeout = seconds(secs, "idle_timeout")?;
        }
        set(&mut c.limits, file.limits);
        let admission = file.admission.unwrap_or_default();
        let a = &mut c.admission;
        set(&mut a.per_address, admission.per_address);
        set(&mut a.pending_per_address, admission.pending_per_address);
        set(&mut a.pending, admission.pending);
        set(&mut a.retry_above, admission.retry_above);
        if let Some(secs) = self.hello_timeout.or(admission.hello_timeout) {
            a.hello_timeout = seconds(secs, "hello_timeout")?;
        }
        set(&mut a.per_address, self.max_per_address);
        set(&mut a.pending_per_address, self.max_pending_per_address);
        set(&mut a.pending, self.max_pending);
        // Unless set, the pending cap follows the connection cap.
        if admission.pending_per_address.is_none() && self.max_pending_per_address.is_none() {
            a.pending_per_address = a.per_address;
        }
        if let Some(secs) = file.idle_kick {
            c.idle_kick = seconds(secs, "idle_kick")?;
        }
        if let Some(secs) = self.respawn_delay.or(file.respawn_delay) {
            c.respawn_delay = seconds(secs, "respawn_delay")?;
        }
        if let Some(secs) = self.reconnect_grace.or(file.reconnect_grace) {
            c.reconnect_grace = seconds(secs, "reconnect_grace")?;
        }
        // Flags win.
        set(&mut c.bind, self.bind);
        if !self.level.is_empty() {
            c.levels.clone_from(&self.level);
        }
        set(&mut c.level_settings, self.level_settings.clone().map(Some));
        set(&mut c.tick_rate, self.tick_rate);
        set(&mut c.snapshot_rate, self.snapshot_rate);
        set(&mut c.max_players, self.max_players);
        set(&mut c.max_spectators, self.max_spectators);
        set(&mut c.rooms, self.rooms);
        set(&mut c.max_rooms, self.max_rooms);
        // Unless set, the cap follows a larger number of rooms.
        if file.max_rooms.is_none() && self.max_rooms.is_none() {
            c.max_rooms = c.max_rooms.max(c.rooms);
        }
        set(&mut c.max_connections, self.max_connections);
        set(&mut c.threads, self.threads.map(Some));
        set(&mut c.max_level_mib, self.max_level_mib);
        set(&mut c.cert_dir, self.cert_dir.clone());
        set(&mut c.metrics_bind, self.metrics_bind.map(Some));
        if self.agones || file.agones.is_some() {
            let from_file = file.agones.unwrap_or_default();
            let mut fleet = FleetConfig::default();
            if let Some(secs) = self.agones_shutdown_after.or(from_file.shutdown_after) {
                fleet.shutdown_after = seconds(secs, "agones shutdown_after")?;
            }
            if let Some(secs) = self.agones_health_every.or(from_file.health_every) {
                fleet.health_every = seconds(secs, "agones health_every")?;
            }
            if let Some(secs) = from_file.connect_timeout {
                fleet.connect_timeout = seconds(secs, "agones connect_timeout")?;
            }
            c.agones = Some(fleet);
        }
        let file_bind = |key: &str, value: &Option<String>| {
            value
                .as_deref()
                .map(|b| {
                    parse_bind(b).map_err(|message| ConfigError::Parse {
                        path: self.config.clone().unwrap_or_default(),
                        message: format!("{key}: {message}"),
                    })
                })
                .transpose()
        };
        let web_bind = match self.web_bind {
            Some(bind) => Some(bind),
            None => file_bind("web_bind", &file.web_bind)?,
        };
        if let Some(bind) = web_bind {
            let mut web = WebConfig::new(bind);
            set(&mut web.root, file.web_root.map(relative));
            set(&mut web.root, self.web_root.clone());
            let wt_bind = match self.webtransport_bind {
                Some(b) => Some(b),
                None => file_bind("webtransport_bind", &file.webtransport_bind)?,
            };
            web.limits = file
                .web_limits
                .unwrap_or_default()
                .resolve(self.web_uplink_mbps, self.web_address_mbps);
            web.webtransport = match (self.no_webtransport, file.webtransport) {
                (true, _) | (false, Some(false)) => None,
                _ => Some(wt_bind.unwrap_or(bind)),
            };
            c.web = Some(web);
        }
        c.validate()?;
        Ok(c)
    }
}

fn set<T>(slot: &mut T, value: Option<T>) {
    if let Some(v) = value {
        *slot = v;
    }
}

/// A listening address: `ADDR:PORT`, `HOST:PORT` (resolved; the first
/// address) or a bare `PORT` (all interfaces, `0.0.0.0:PORT`).
pub fn parse_bind(s: &str) -> Result<SocketAddr, String> {
    let s = s.trim();
    if let Ok(port) = s.parse::<u16>() {
        return Ok(SocketAddr::from(([0, 0, 0, 0], port)));
    }
    if let Ok(addr) = s.parse::<SocketAddr>() {
        return Ok(addr);
    }
    use std::net::ToSocketAddrs;
    match s.to_socket_addrs() {
        Ok(mut addrs) => addrs
            .next()
            .ok_or_else(|| format!("{s:?} resolves to no address")),
        Err(e) => Err(format!(
            "{s:?} is not ADDR:PORT, HOST:PORT or PORT (e.g. 0.0.0.0:4433, localhost:4433, 4433): {e}"
        )),
    }
}

fn parse_file(text: &str, path: &Path) -> Result<FileConfig, ConfigError> {
    toml::from_str(text).map_err(|e| ConfigError::Parse {
        path: path.to_owned(),
        message: e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bind_takes_addresses_host_names_and_bare_ports() {
        assert_eq!(parse_bind("4433"), Ok("0.0.0.0:4433".parse().unwrap()));
        assert_eq!(
            parse_bind("127.0.0.1:5000"),
            Ok("127.0.0.1:5000".parse().unwrap())
        );
        assert_eq!(parse_bind("[::1]:5000"), Ok("[::1]:5000".parse().unwrap()));
        let local = parse_bind("localhost:5001").unwrap();
        assert!(local.ip().is_loopback() && local.port() == 5001, "{local}");
        let e = parse_bind("no such host").unwrap_err();
        assert!(e.contains("is not ADDR:PORT, HOST:PORT or PORT"), "{e}");
        assert!(parse_bind("70000").is_err());
        assert_eq!(
            cli(&["--bind", "6001"]).resolve().unwrap().bind,
            "0.0.0.0:6001".parse().unwrap()
        );
        assert!(Cli::try_parse_from(["ledge-server", "--bind", "nowhere:x"]).is_err());
    }

    fn cli(args: &[&str]) -> Cli {
        Cli::try_parse_from(std::iter::once("ledge-server").chain(args.iter().copied())).unwrap()
    }

    #[test]
    fn defaults_match_the_documented_ones() {
        let c = cli(&[]).resolve().unwrap();
        assert_eq!(c, ServerConfig::default());
        assert_eq!(c.bind, "0.0.0.0:4433".parse().unwrap());
        assert_eq!((c.tick_rate, c.snapshot_rate), (60, 30));
        assert_eq!(c.snapshot_interval(), 2);
        assert!(c.levels.is_empty());
        assert_eq!(c.metrics_bind, None);
        assert_eq!(c.threads, None, "one thread per core unless told");
    }

    #[test]
    fn replays_go_beside_the_certificate_unless_told() {
        let c = cli(&["--cert-dir", "/srv/ledge"]).resolve().unwrap();
        assert_eq!(
            c.replays_target(),
            ReplaysTarget::Dir("/srv/ledge/replays".into())
        );
        assert_eq!(c.replays_cap, 1024 << 20);
        let c = cli(&["--replays", "off", "--replays-cap-mib", "5"])
            .resolve()
            .unwrap();
        assert_eq!(
            (c.replays_target(), c.replays_cap),
            (ReplaysTarget::Off, 5 << 20)
        );
        // In the file: relative to it; the flag wins.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("server.toml");
        std::fs::write(&path, "replays = \"runs\"\nreplays_cap_mib = 7\n").unwrap();
        let config = path.to_str().unwrap();
        let c = cli(&["--config", config]).resolve().unwrap();
        assert_eq!(
            c.replays_target(),
            ReplaysTarget::Dir(dir.path().join("runs"))
        );
        assert_eq!(c.replays_cap, 7 << 20);
        let c = cli(&["--config", config, "--replays", "here"])
            .resolve()
            .unwrap();
        assert_eq!(c.replays_target(), ReplaysTarget::Dir("here".into()));
    }

    #[test]
    fn file_values_apply_and_flags_override_them() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("server.toml");
        std::fs::write(
            &path,
            r#"
bind = "127.0.0.1:5000"
tick_rate = 120
snapshot_rate = 20
max_players = 4
rooms = 3
cert_dir = "my-certs"
level = "levels/one.json"
metrics_bind = "127.0.0.1:9100"
idle_timeout = 2.5
threads = 1

[limits]
datagrams_per_second = 500.0
"#,
        )
        .unwrap();
        let config = path.to_str().unwrap();
        let c = cli(&["--config", config]).resolve().unwrap();
        assert_eq!(c.bind, "127.0.0.1:5000".parse().unwrap());
        assert_eq!((c.tick_rate, c.snapshot_rate), (120, 20));
        assert_eq!(c.snapshot_interval(), 6);
        assert_eq!((c.max_players, c.rooms), (4, 3));
        assert_eq!(c.cert_dir, dir.path().join("my-certs"));
        assert_eq!(c.levels, vec![dir.path().join("levels/one.json")]);
        assert_eq!(c.metrics_bind, Some("127.0.0.1:9100".parse().unwrap()));
        assert_eq!(c.idle_timeout, Duration::from_millis(2500));
        assert_eq!(c.threads, Some(1));
        assert_eq!(c.limits.datagrams_per_second, 500.0);
        // Keys missing from [limits] keep their defaults.
        assert_eq!(c.limits.control_burst, Limits::default().control_burst);

        let c = cli(&[
            "--config",
            config,
            "--tick-rate",
            "30",
            "--snapshot-rate",
            "30",
            "--bind",
            "127.0.0.1:6000",
            "--max-players",
            "2",
            "--cert-dir",
            "/tmp/c",
            "--threads",
            "3",
        ])
        .resolve()
        .unwrap();
        assert_eq!(c.threads, Some(3));
        assert_eq!(c.bind, "127.0.0.1:6000".parse().unwrap());
        assert_eq!((c.tick_rate, c.snapshot_rate), (30, 30));
        assert_eq!(c.snapshot_interval(), 1);
        assert_eq!(c.max_players, 2);
        assert_eq!(c.cert_dir, PathBuf::from("/tmp/c"));
        // Not overridden: still the file's.
        assert_eq!(c.rooms, 3);
    }

    #[test]
    fn bad_files_and_values_are_reported() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, "tick_rat = 60\n").unwrap();
        let err = cli(&["--config", path.to_str().unwrap()])
            .resolve()
            .unwrap_err();
        assert!(
            matches!(&err, ConfigError::Parse { message, .. } if message.contains("tick_rat")),
            "{err}"
        );
        std::fs::write(&path, "tick_rate = \"fast\"\n").unwrap();
        let err = cli(&["--config", path.to_str().unwrap()])
            .resolve()
            .unwrap_err();
        assert!(matches!(err, ConfigError::Parse { .. }), "{err}");
        let err = cli(&["--config", "/nonexistent/ledge.toml"])
            .resolve()
            .unwrap_err();
        assert!(matches!(err, ConfigError::Read { .. }), "{err}");
        for args in [
            &["--tick-rate", "0"][..],
            &["--snapshot-rate", "61"],
            &["--max-players", "0"],
            &["--rooms", "0"],
            &["--rooms", "257"],
            &["--rooms", "3", "--max-rooms", "2"],
            &["--max-rooms", "257"],
            &["--max-level-mib", "0"],
            &["--max-level-mib", "97"],
            &["--threads", "0"],
            &["--threads", "1025"],
        ] {
            let err = cli(args).resolve().unwrap_err();
            assert!(matches!(err, ConfigError::Invalid(_)), "{args:?}: {err}");
        }
    }

    #[test]
    fn agones_comes_from_the_flag_or_the_file() {
        assert_eq!(cli(&[]).resolve().unwrap().agones, None);
        let f = cli(&["--agones"]).resolve().unwrap().agones.unwrap();
        assert_eq!(f, FleetConfig::default());
        let f = cli(&[
            "--agones",
            "--agones-shutdown-after",
            "5",
            "--agones-health-every",
            "0.5",
        ])
        .resolve()
        .unwrap()
        .agones
        .unwrap();
        assert_eq!(f.shutdown_after, Duration::from_secs(5));
        assert_eq!(f.health_every, Duration::from_millis(500));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("server.toml");
        std::fs::write(&path, "[agones]\nshutdown_after = 30\n").unwrap();
        let config = path.to_str().unwrap();
        let f = cli(&["--config", config])
            .resolve()
            .unwrap()
            .agones
            .unwrap();
        assert_eq!(f.shutdown_after, Duration::from_secs(30));
        // Out of range, or without --agones: refused.
        assert!(cli(&["--agones", "--agones-health-every", "0"])
            .resolve()
            .is_err());
        assert!(Cli::try_parse_from(["ledge-server", "--agones-shutdown-after", "5"]).is_err());
    }

    #[test]
    fn admission_limits_come_from_the_file_and_flags() {
        let c = cli(&[]).resolve().unwrap();
        assert_eq!(c.admission, AdmissionConfig::default());
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("server.toml");
        std::fs::write(
            &path,
            "[admission]\nper_address = 8\npending = 16\nhello_timeout = 1.5\nretry_above = 0\n",
        )
        .unwrap();
        let config = path.to_str().unwrap();
        let a = cli(&["--config", config]).resolve().unwrap().admission;
        assert_eq!(
            (a.per_address, a.pending_per_address),
            (8, 8),
            "pending follows"
        );
        assert_eq!((a.pending, a.retry_above), (16, 0));
        assert_eq!(a.hello_timeout, Duration::from_millis(1500));
        let a = cli(&[
            "--config",
            config,
            "--max-per-address",
            "1",
            "--hello-timeout",
            "3",
        ])
        .resolve()
        .unwrap()
        .admission;
        assert_eq!(
            (a.per_address, a.pending_per_address),
            (1, 1),
            "pending follows"
        );
        assert_eq!(a.hello_timeout, Duration::from_secs(3));
        let a = cli(&[
            "--max-pending-per-address",
            "5",
            "--max-per-address",
            "9",
            "--max-pending",
            "7",
        ])
        .resolve()
        .unwrap()
        .admission;
        assert_eq!((a.per_address, a.pending_per_address, a.pending), (9, 5, 7));
        for args in [
            &["--max-per-address", "0"][..],
            &["--max-pending", "0"],
            &["--max-per-address", "2", "--max-pending-per-address", "3"],
            &["--hello-timeout", "0.01"],
            &["--hello-timeout", "61"],
        ] {
            let err = cli(args).resolve().unwrap_err();
            assert!(matches!(err, ConfigError::Invalid(_)), "{args:?}: {err}");
        }
        std::fs::write(&path, "[admission]\nper_adress = 8\n").unwrap();
        let err = cli(&["--config", path.to_str().unwrap()])
            .resolve()
            .unwrap_err();
        assert!(matches!(err, ConfigError::Parse { .. }), "{err}");
    }

    #[test]
    fn the_web_port_comes_from_the_flags_or_the_file() {
        assert_eq!(cli(&[]).resolve().unwrap().web, None);
        let w = cli(&["--web-bind", "8080"]).resolve().unwrap().web.unwrap();
        let bind: SocketAddr = "0.0.0.0:8080".parse().unwrap();
        assert_eq!(w, WebConfig::new(bind));
        assert_eq!(w.root, PathBuf::from(DEFAULT_WEB_ROOT));
        assert_eq!(w.webtransport, Some(bind), "the same port number");
        let w = cli(&[
            "--web-bind",
            "127.0.0.1:8080",
            "--webtransport-bind",
            "127.0.0.1:9443",
            "--web-root",
            "/srv/page",
        ])
        .resolve()
        .unwrap()
        .web
        .unwrap();
        assert_eq!(w.webtransport, Some("127.0.0.1:9443".parse().unwrap()));
        assert_eq!(w.root, PathBuf::from("/srv/page"));
        let w = cli(&["--web-bind", "8080", "--no-webtransport"])
            .resolve()
            .unwrap()
            .web
            .unwrap();
        assert_eq!(w.webtransport, None);
        assert!(Cli::try_parse_from(["ledge-server", "--web-bind", "nowhere:x"]).is_err());

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("server.toml");
        std::fs::write(
            &path,
            "web_bind = \"127.0.0.1:8000\"\nweb_root = \"page\"\nwebtransport = false\n",
        )
        .unwrap();
        let config = path.to_str().unwrap();
        let w = cli(&["--config", config]).resolve().unwrap().web.unwrap();
        assert_eq!(w.bind, "127.0.0.1:8000".parse().unwrap());
        assert_eq!(w.root, dir.path().join("page"), "relative to the file");
        assert_eq!(w.webtransport, None);
        let w = cli(&["--config", config, "--web-bind", "9000"])
            .resolve()
            .unwrap()
            .web
            .unwrap();
        assert_eq!(w.bind.port(), 9000, "the flag wins");
        std::fs::write(&path, "web_bind = \"not an address\"\n").unwrap();
        let err = cli(&["--config", config]).resolve().unwrap_err();
        assert!(
            matches!(&err, ConfigError::Parse { message, .. } if message.contains("web_bind")),
            "{err}"
        );
    }

    #[test]
    fn the_respawn_delay_is_whole_ticks_of_the_tick_rate() {
        let c = cli(&[]).resolve().unwrap();
        assert_eq!(c.game_config().player.respawn_delay_ticks, 24);
        let c = cli(&[
            "--respawn-delay",
            "1",
            "--tick-rate",
            "120",
            "--snapshot-rate",
            "30",
        ])
        .resolve()
        .unwrap();
        assert_eq!(c.game_config().player.respawn_delay_ticks, 120);
        assert!(c.game_config().player.validate().is_ok());
        let c = cli(&["--respawn-delay", "0"]).resolve().unwrap();
        assert_eq!(c.game_config().player.respawn_delay_ticks, 0);
        let err = cli(&["--respawn-delay", "11"]).resolve().unwrap_err();
        assert!(matches!(err, ConfigError::Invalid(_)), "{err}");
    }

    #[test]
    fn the_room_cap_follows_the_rooms_unless_set() {
        let c = cli(&[]).resolve().unwrap();
        assert_eq!((c.rooms, c.max_rooms), (1, DEFAULT_MAX_ROOMS));
        let c = cli(&["--rooms", "20"]).resolve().unwrap();
        assert_eq!((c.rooms, c.max_rooms), (20, 20));
        let c = cli(&["--rooms", "2", "--max-rooms", "5"])
            .resolve()
            .unwrap();
        assert_eq!((c.rooms, c.max_rooms), (2, 5));
    }

    #[test]
    fn snapshot_interval_rounds_to_whole_ticks() {
        let at = |tick_rate, snapshot_rate| {
            ServerConfig {
                tick_rate,
                snapshot_rate,
                ..ServerConfig::default()
            }
            .snapshot_interval()
        };
        assert_eq!(at(60, 60), 1);
        assert_eq!(at(60, 20), 3);
        assert_eq!(at(60, 25), 2);
        assert_eq!(at(60, 1), 60);
    }

    #[test]
    fn recording_is_off_by_default_and_needs_a_positive_cap() {
        assert_eq!(ServerConfig::default().record_ticks, None);
        let with = |record_ticks| ServerConfig {
            record_ticks,
            ..ServerConfig::default()
        };
        assert!(matches!(
            with(Some(0)).validate(),
            Err(ConfigError::Invalid(_))
        ));
        assert!(with(Some(1)).validate().is_ok());
    }
}
