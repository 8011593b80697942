//! The server: endpoint, rooms, connection tasks, metrics, and their
//! graceful shutdown.

use std::net::SocketAddr;
use std::path::Path;
use std::sync::atomic::AtomicU32;
use std::sync::Arc;
use std::time::{Duration, Instant};

use ledge_shared::game::GameError;
use ledge_shared::level::Level;
use ledge_shared::protocol::{CloseCode, LevelOffer, DEFAULT_INPUT_REDUNDANCY};
use prometheus_client::registry::Registry;
use tokio::sync::{mpsc, watch};
use tokio::task::{JoinHandle, JoinSet};
use tracing::{debug, error, info, warn};
use wtransport::endpoint::IncomingSession;

use crate::admission::{Admission, Refusal, Ticket, Verdict};
use crate::config::{ConfigError, ServerConfig, WebConfig};
use crate::connection::{self, SHUTDOWN_LINGER};
use crate::fingerprint::Fingerprint;
use crate::levels::{self, LevelLoadError, LevelSet};
use crate::link::Incoming;
use crate::metrics::{self, Metrics};
use crate::quic_cert::{CertError, Identity};
use crate::record::Recorder;
use crate::records::writer::WriterMetrics;
use crate::records::{RecordStore, RecordsHandle, RecordsTarget};
use crate::replays::{ReplayDir, ReplaysHandle, ReplaysTarget};
use crate::room_logic::RoomConfig;
use crate::room_registry::Rooms;
use crate::sessions::Sessions;
use crate::shared::Shared;
use crate::shutdown::{stopped, ShutdownHandle};
use crate::snapshots::DEFAULT_HISTORY;
use crate::tls::{self, TlsError};
use crate::web::files::{WebRoot, WebRootError};
use crate::web::webtransport_cert::CertLife;
use crate::web::webtransport_endpoint::{self as wt, WebCerts, WebTransportError};
use crate::web::{self, WebState};

/// How long shutdown waits for connection tasks, then for the endpoint.
const SHUTDOWN_GRACE: Duration = Duration::from_secs(3);

/// How often lost players past the reconnect grace time and idle rooms
/// opened by name are looked for (and removed, closed).
const SWEEP: Duration = Duration::from_secs(1);

/// Shortest time between two warnings that connections are being refused
/// (each refusal is logged at debug level).
const REFUSAL_WARNING_EVERY: Duration = Duration::from_secs(10);

/// Why the server could not start.
#[derive(Debug, thiserror::Error)]
pub enum ServerError {
    /// The configuration is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The level could not be loaded.
    #[error(transparent)]
    Level(#[from] LevelLoadError),
    /// The level cannot be played.
    #[error("cannot start the game: {0}")]
    Game(#[from] GameError),
    /// The certificate could not be loaded or created.
    #[error(transparent)]
    Cert(#[from] CertError),
    /// The TLS/QUIC configuration was refused.
    #[error(transparent)]
    Tls(#[from] TlsError),
    /// The web page's directory cannot be served (`--web-root`).
    #[error("--web-root {0}")]
    WebRoot(#[from] WebRootError),
    /// The WebTransport endpoint could not be set up.
    #[error(transparent)]
    WebTransport(#[from] WebTransportError),
    /// `--agones` was asked of a server built without the `agones` feature,
    /// or the Agones SDK sidecar did not answer.
    #[error("{0}")]
    Agones(String),
    /// A socket could not be bound.
    #[error("cannot bind {addr}: {source}; {}", bind_hint(option, *addr, source))]
    Bind {
        /// The address asked for.
        addr: SocketAddr,
        /// The option that sets it (`--bind`, `--metrics-bind`).
        option: &'static str,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// What to do when `addr` (set by `option`) cannot be bound.
fn bind_hint(option: &str, addr: SocketAddr, error: &std::io::Error) -> String {
    let mut other = addr;
    other.set_port(addr.port().checked_add(1).unwrap_or(4433));
    let change = format!("choose another with {option} (e.g. {option} {other})");
    match error.kind() {
        std::io::ErrorKind::AddrInUse => format!(
            "another program (another ledge-server?) uses port {}: stop it, or {change}",
            addr.port()
        ),
        std::io::ErrorKind::AddrNotAvailable => {
            format!("{} is not an address of this machine: {change}", addr.ip())
        }
        std::io::ErrorKind::PermissionDenied if addr.port() < 1024 => {
            format!("ports below 1024 need privileges: {change}")
        }
        _ => change,
    }
}

/// Decides on a new QUIC or WebTransport connection
/// ([`Admission::consider`]) and acts: a Retry, a refusal (counted), or a
/// task serving it. (WebSockets are admitted by the web port, before
/// their upgrade.)
fn admit(
    incoming: Incoming,
    shared: &Arc<Shared>,
    connections: &mut JoinSet<()>,
    refusals: &mut RefusalLog,
) {
    let remote = incoming.remote_address();
    let (validated, may_retry) = match &incoming {
        Incoming::Quic(i) => (i.remote_address_validated(), i.may_retry()),
        Incoming::WebTransport(i) => {
            let validated = i.remote_address_validated();
            (validated, !validated)
        }
        Incoming::WebSocket(_) => (true, false),
    };
    let verdict = shared
        .admission
        .consider(remote.ip(), validated, may_retry, Instant::now());
    let metrics = &shared.metrics;
    match verdict {
        Verdict::Retry => {
            metrics.retries.inc();
            match incoming {
                Incoming::Quic(incoming) => {
                    if let Err(e) = incoming.retry() {
                        debug!(%remote, "cannot send a Retry: {e}");
                        e.into_incoming().ignore();
                    }
                }
                Incoming::WebTransport(incoming) => incoming.retry(),
                Incoming::WebSocket(_) => {}
            }
        }
        Verdict::Refuse(reason) => {
            metrics.refused_on(incoming.transport(), reason);
            refusals.count(reason);
            debug!(%remote, ?reason, "connection refused");
            match incoming {
                Incoming::Quic(incoming) => incoming.refuse(),
                Incoming::WebTransport(incoming) => incoming.refuse(),
                Incoming::WebSocket(_) => {}
            }
        }
        Verdict::Admit { ticket, evicted } => {
            if evicted {
                metrics.refused(Refusal::Evicted);
                refusals.count(Refusal::Evicted);
            }
            metrics
                .pending_connections
                .set(shared.admission.pending() as i64);
            connections.spawn(connection::serve(incoming, ticket, shared.clone()));
        }
    }
}

/// Refusals since the last warning, so a flood of refused connections
/// gives one log line every [`REFUSAL_WARNING_EVERY`], not one each.
#[derive(Debug, Default)]
struct RefusalLog {
    since: u64,
    reason: Option<Refusal>,
    warned: Option<Instant>,
}

impl RefusalLog {
    fn count(&mut self, reason: Refusal) {
        self.since += 1;
        self.reason = Some(reason);
    }

    /// Warns of the refusals counted, unless it did so recently.
    fn warn(&mut self, now: Instant) {
        let recently = self
            .warned
            .is_some_and(|at| now.duration_since(at) < REFUSAL_WARNING_EVERY);
        let Some(reason) = self.reason.filter(|_| self.since > 0 && !recently) else {
            return;
        };
        warn!(
            refused = self.since,
            last_reason = ?reason,
            "new connections refused (per-address caps, pending pool, server full); \
             see ledge_connections_refused_total"
        );
        self.since = 0;
        self.warned = Some(now);
    }
}

/// The web port and WebTransport, bound.
#[derive(Debug)]
struct WebParts {
    listener: tokio::net::TcpListener,
    addr: SocketAddr,
    root: WebRoot,
    webtransport: Option<WebTransportParts>,
    limits: web::guard::WebLimits,
}

struct WebTransportParts {
    endpoint: Arc<wt::Endpoint>,
    certs: Arc<WebCerts>,
    settings: wt::Settings,
    addr: SocketAddr,
}

impl std::fmt::Debug for WebTransportParts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WebTransportParts")
            .field("addr", &self.addr)
            .field("certs", &self.certs)
            .finish_non_exhaustive()
    }
}

/// How to make a [`ServerError::Bind`] of an I/O error for `addr`, set by
/// `option`.
fn bind_error(
    addr: SocketAddr,
    option: &'static str,
) -> impl Fn(std::io::Error) -> ServerError + Copy {
    move |source| ServerError::Bind {
        addr,
        option,
        source,
    }
}

/// Binds the metrics listener (`--metrics-bind`): the listener and its real
/// address.
fn bind_metrics(addr: SocketAddr) -> Result<(tokio::net::TcpListener, SocketAddr), ServerError> {
    let listener = metrics::bind(addr).map_err(bind_error(addr, "--metrics-bind"))?;
    let bound = listener
        .local_addr()
        .map_err(bind_error(addr, "--metrics-bind"))?;
    Ok((listener, bound))
}

/// Binds the web port (`--web-bind`), loads the page's directory and binds
/// WebTransport if on.
fn bind_web(w: &WebConfig, idle_timeout: Duration) -> Result<WebParts, ServerError> {
    let (listener, addr, webtransport) = bind_web_ports(w, idle_timeout)?;
    let root = WebRoot::load(&w.root)?;
    if let Some(missing) = root.missing() {
        warn!("{missing}; / answers 503 until then");
    }
    Ok(WebParts {
        listener,
        addr,
        root,
        webtransport,
        limits: w.limits,
    })
}

/// Tries of an ephemeral web port whose number WebTransport's UDP socket
/// shares, when another program holds that UDP port.
const EPHEMERAL_WEB_TRIES: usize = 16;

/// The web port's TCP listener, its address, and WebTransport's endpoint
/// (UDP, on the same port number by default). With port 0 the system picks
/// the TCP port, and its UDP twin may be taken by another program: then
/// another TCP port is tried, up to [`EPHEMERAL_WEB_TRIES`] times.
fn bind_web_ports(
    w: &WebConfig,
    idle_timeout: Duration,
) -> Result<
    (
        tokio::net::TcpListener,
        SocketAddr,
        Option<WebTransportParts>,
    ),
    ServerError,
> {
    // The same port number as the web port by default.
    let shared_ephemeral = w.bind.port() == 0 && w.webtransport == Some(w.bind);
    let mut tries = 1;
    loop {
        let listener = web::bind(w.bind).map_err(bind_error(w.bind, "--web-bind"))?;
        let addr = listener
            .local_addr()
            .map_err(bind_error(w.bind, "--web-bind"))?;
        let Some(mut bind) = w.webtransport else {
            return Ok((listener, addr, None));
        };
        if shared_ephemeral {
            bind.set_port(addr.port());
        }
        match bind_webtransport(bind, idle_timeout, w.cert_life) {
            Err(ServerError::Bind { source, .. })
                if shared_ephemeral
                    && source.kind() == std::io::ErrorKind::AddrInUse
                    && tries < EPHEMERAL_WEB_TRIES =>
            {
                tries += 1;
            }
            result => return Ok((listener, addr, Some(result?))),
        }
    }
}

/// Binds WebTransport's endpoint at `bind` with its first certificates.
fn bind_webtransport(
    bind: SocketAddr,
    idle_timeout: Duration,
    cert_life: CertLife,
) -> Result<WebTransportParts, ServerError> {
    let settings = wt::Settings {
        bind,
        idle_timeout,
        cert_life,
    };
    let (endpoint, certs) = wt::bind(&settings).map_err(|e| match e {
        wt::BindError::Setup(e) => ServerError::WebTransport(e),
        wt::BindError::Io(source) => ServerError::Bind {
            addr: bind,
            option: "--webtransport-bind",
            source,
        },
    })?;
    let addr = endpoint
        .local_addr()
        .map_err(bind_error(bind, "--webtransport-bind"))?;
    Ok(WebTransportParts {
        endpoint,
        certs,
        settings,
        addr,
    })
}

/// A bound, not yet running server.
///
/// `bind` then `run`; keep a [`ShutdownHandle`] to stop it. Tests bind to
/// `127.0.0.1:0` and read the real ports from [`Server::local_addr`] and
/// [`Server::metrics_addr`].
#[derive(Debug)]
pub struct Server {
    endpoint: quinn::Endpoint,
    local_addr: SocketAddr,
    fingerprint: Fingerprint,
    config: ServerConfig,
    /// The levels played, in rotation order.
    levels: LevelSet,
    metrics: Arc<Metrics>,
    registry: Arc<Registry>,
    metrics_listener: Option<(tokio::net::TcpListener, SocketAddr)>,
    shutdown: watch::Sender<bool>,
    /// One per room when `record_ticks` is set, in room order.
    recorders: Vec<Recorder>,
    /// The web port and WebTransport (`--web-bind`), if on.
    web: Option<WebParts>,
}

impl Server {
    /// Checks the configuration, loads the level, loads or creates the
    /// certificate and binds the QUIC endpoint (and the metrics listener,
    /// the web port and WebTransport, when on).
    ///
    /// Must be called inside a tokio runtime (the sockets register with it).
    pub fn bind(config: ServerConfig) -> Result<Server, ServerError> {
        config.validate()?;
        if config.agones.is_some() && !cfg!(feature = "agones") {
            return Err(ServerError::Agones(
                "--agones: this ledge-server was built without Agones support; build it with \
                 `cargo build --release -p ledge-server --features agones` (deploy/Dockerfile does)"
                    .into(),
            ));
        }
        let levels = LevelSet::load(
            &config.levels,
            config.level_settings.as_deref(),
            config.game_config(),
            config.max_level_mib,
        )?;
        let level = &levels.get(0).level;
        let identity = Identity::load_or_generate(&config.cert_dir)?;
        if identity.generated {
            info!(dir = %config.cert_dir.display(), "generated a new self-signed certificate");
        }
        let quic = tls::server_config(&identity, config.idle_timeout)?;
        let udp = bind_error(config.bind, "--bind");
        let endpoint = ledge_quic::packets::server_endpoint(quic, config.bind).map_err(udp)?;
        let local_addr = endpoint.local_addr().map_err(udp)?;
        let metrics_listener = config.metrics_bind.map(bind_metrics).transpose()?;
        let web = config
            .web
            .as_ref()
            .map(|w| bind_web(w, config.idle_timeout))
            .transpose()?;
        let (metrics, registry) = Metrics::new();
        let recorders = match config.record_ticks {
            Some(limit) => {
                let (id, hash) = (levels::level_id(level), level.content_hash());
                (1..=config.rooms)
                    .map(|i| Recorder::new(&format!("room-{i}"), &id, hash, limit))
                    .collect()
            }
            None => Vec::new(),
        };
        Ok(Server {
            endpoint,
            local_addr,
            fingerprint: identity.fingerprint,
            config,
            levels,
            metrics,
            registry: Arc::new(registry),
            metrics_listener,
            shutdown: watch::Sender::new(false),
            recorders,
            web,
        })
    }

    /// The web port's address (`--web-bind`), if on.
    pub fn web_addr(&self) -> Option<SocketAddr> {
        self.web.as_ref().map(|w| w.addr)
    }

    /// WebTransport's UDP address, if on.
    pub fn webtransport_addr(&self) -> Option<SocketAddr> {
        self.web.as_ref()?.webtransport.as_ref().map(|w| w.addr)
    }

    /// SHA-256 of the WebTransport certificates a page may meet, current
    /// first (as `/web.json` lists them); empty when WebTransport is off.
    pub fn webtransport_hashes(&self) -> Vec<[u8; 32]> {
        self.web
            .as_ref()
            .and_then(|w| w.webtransport.as_ref())
            .map(|w| w.certs.hashes())
            .unwrap_or_default()
    }

    /// The UDP address actually bound (the real port when binding port 0).
    pub fn local_addr(&self) -> SocketAddr {
        self.local_addr
    }

    /// The metrics endpoint's address, if one is configured.
    pub fn metrics_addr(&self) -> Option<SocketAddr> {
        self.metrics_listener.as_ref().map(|(_, addr)| *addr)
    }

    /// The metrics registry (render it with [`metrics::encode`]).
    pub fn registry(&self) -> Arc<Registry> {
        self.registry.clone()
    }

    /// SHA-256 of the certificate: what clients pin.
    pub fn fingerprint(&self) -> Fingerprint {
        self.fingerprint
    }

    /// The configuration in use.
    pub fn config(&self) -> &ServerConfig {
        &self.config
    }

    /// The first level played.
    pub fn level(&self) -> &Level {
        &self.levels.get(0).level
    }

    /// The first level's bundle, as clients download it (hash and size).
    pub fn level_offer(&self) -> LevelOffer {
        self.levels.get(0).offer
    }

    /// Every level played, in rotation order.
    pub fn levels(&self) -> &LevelSet {
        &self.levels
    }

    /// The match record of room `room` (e.g. `room-1`), when recording is
    /// on (`ServerConfig::record_ticks`); it fills while the server runs and
    /// stays readable after it stopped.
    pub fn recorder(&self, room: &str) -> Option<Recorder> {
        self.recorders.iter().find(|r| r.room() == room).cloned()
    }

    /// A handle that stops [`Server::run`].
    pub fn shutdown_handle(&self) -> ShutdownHandle {
        ShutdownHandle(self.shutdown.clone())
    }

    /// Runs the rooms and serves connections until shutdown is requested,
    /// then says goodbye to every client, closes the endpoint and waits
    /// (bounded) for it to go idle.
    pub async fn run(self) -> Result<(), ServerError> {
        let Server {
            endpoint,
            local_addr,
            config,
            levels,
            metrics,
            registry,
            metrics_listener,
            shutdown,
            recorders,
            fingerprint,
            web,
            ..
        } = self;
        let mut stop = shutdown.subscribe();
        let (records, records_task) = open_records(&config, &metrics, stop.clone()).await;
        let (replays, replays_task) = open_replays(&config, &metrics, records.clone());
        let replays_dir = replays.dir().map(Path::to_owned);
        let rooms = open_rooms(
            &config,
            &levels,
            &recorders,
            metrics.clone(),
            (records.clone(), replays),
        )?;
        let metrics_task = metrics_listener.map(|(listener, addr)| {
            info!(%addr, "serving metrics at /metrics");
            tokio::spawn(metrics::serve(listener, registry, stop.clone()))
        });
        let shared = Arc::new(Shared {
            rooms,
            sessions: Sessions::new(config.reconnect_grace),
            levels: levels.clone(),
            metrics,
            limits: config.limits,
            next_player: AtomicU32::new(1),
            admission: Admission::new(config.admission, config.max_connections),
            shutdown: stop.clone(),
            records,
            replays_dir,
        });
        #[cfg(feature = "agones")]
        let agones_task = join_fleet(&config, fingerprint, &shared, &stop, &shutdown).await?;
        #[cfg(not(feature = "agones"))]
        let _ = fingerprint;
        info!(
            %local_addr,
            level = %levels.get(0).id,
            levels = levels.len(),
            level_bundle_bytes = levels.get(0).offer.size,
            rooms = config.rooms,
            tick_rate = config.tick_rate,
            snapshot_interval = config.snapshot_interval(),
            "listening"
        );
        if levels.len() > 1 {
            let names: Vec<&str> = levels.levels().iter().map(|l| l.id.as_str()).collect();
            let r = &config.rotation;
            info!(
                vote = r.vote.name(),
                level_time_s = r.level_time.map_or(0, |t| t.as_secs()),
                results_time_s = r.results_time.as_secs_f32(),
                "levels in rotation: {}",
                names.join(", ")
            );
        }
        // Browsers: the web port's task hands admitted WebSockets to the
        // accept loop; WebTransport sessions are accepted there like QUIC
        // ones.
        let (accepted_tx, accepted) = mpsc::channel::<web::Accepted>(64);
        let browsers = serve_browsers(web, &shared, &config, accepted_tx, &stop);
        let mut serving = Serving {
            endpoint,
            webtransport: browsers.webtransport,
            accepted,
            shared,
            connections: JoinSet::new(),
        };
        serving.accept_until_stopped(&mut stop).await;
        serving.drain().await;
        serving.close_endpoints().await;
        for task in browsers.tasks {
            let _ = task.await;
        }
        #[cfg(feature = "agones")]
        if let Some(thread) = agones_task {
            // It sees `stop` and ends within a poll.
            let _ = tokio::task::spawn_blocking(move || thread.join()).await;
        }
        stop_rooms(serving.shared).await;
        if let Some(task) = replays_task {
            if tokio::time::timeout(RECORDS_GRACE, task).await.is_err() {
                warn!("replays still being saved after {RECORDS_GRACE:?}; stopping anyway");
            }
        }
        if let Some(task) = records_task {
            // Every room is gone, so the writer stores what is queued and
            // ends.
            if tokio::time::timeout(RECORDS_GRACE, task).await.is_err() {
                warn!("records still being written after {RECORDS_GRACE:?}; stopping anyway");
            }
        }
        if let Some(task) = metrics_task {
            let _ = task.await;
        }
        drop(shutdown);
        info!("stopped");
        Ok(())
    }
}

/// A random id of this server's run (hex), unique enough that finished
/// runs of two servers, or of one server before and after a restart, never
/// share a key.
fn instance_id() -> String {
    let mut bytes = [0u8; 12];
    if ring::rand::SecureRandom::fill(&ring::rand::SystemRandom::new(), &mut bytes).is_err() {
        // No system randomness: the time keeps restarts apart.
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        bytes.copy_from_slice(&nanos.to_le_bytes()[..12]);
    }
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// How long shutdown waits for the records writer to store what is queued.
pub const RECORDS_GRACE: Duration = Duration::from_secs(10);

/// Opens the records (`--records`) and starts their writer; if they cannot
/// be opened, says so, plays on without them and tries again every
/// `records_retry` until they open or `stop`. The task to await at
/// shutdown: the writer's, or the one trying again (which ends with the
/// writer it started).
async fn open_records(
    config: &ServerConfig,
    metrics: &Metrics,
    stop: watch::Receiver<bool>,
) -> (RecordsHandle, Option<tokio::task::JoinHandle<()>>) {
    let target = config.records_target();
    let writer = WriterMetrics {
        stored: metrics.records_stored.clone(),
        failed: metrics.records_failed.clone(),
        write_seconds: Some(metrics.records_write_seconds.clone()),
    };
    match RecordStore::open(&target).await {
        Ok(Some(store)) => {
            info!(records = %store.target(), "storing finished runs");
            let (handle, task) = RecordsHandle::spawn(store, writer);
            (handle, Some(task))
        }
        Ok(None) => {
            info!("records are off (--records off): finished runs are not stored");
            (RecordsHandle::off("this server keeps no records"), None)
        }
        Err(e) => {
            let every = config.records_retry;
            error!("records are off: {e}; trying again every {every:?}");
            let handle = RecordsHandle::off("the server's records database could not be opened")
                .with_metrics(writer);
            let task = tokio::spawn(reopen_records(handle.clone(), target, every, stop));
            (handle, Some(task))
        }
    }
}

/// Tries to open the records every `every` until they open (then every
/// clone of `handle` stores, and this waits for the writer to end) or the
/// server stops.
async fn reopen_records(
    handle: RecordsHandle,
    target: RecordsTarget,
    every: Duration,
    mut stop: watch::Receiver<bool>,
) {
    loop {
        tokio::select! {
            () = tokio::time::sleep(every) => {}
            _ = stop.wait_for(|stopped| *stopped) => return,
        }
        match RecordStore::open(&target).await {
            Ok(Some(store)) => {
                info!(records = %store.target(), "records are on again: storing finished runs");
                let writer = handle.go_live(store);
                drop(handle);
                if let Some(writer) = writer {
                    let _ = writer.await;
                }
                return;
            }
            Ok(None) => return,
            Err(e) => warn!("records still off: {e}"),
        }
    }
}

/// Opens the replays folder (`--replays`) and starts its writer; if it
/// cannot be opened, says so and plays on without replays.
fn open_replays(
    config: &ServerConfig,
    metrics: &Metrics,
    records: RecordsHandle,
) -> (ReplaysHandle, Option<tokio::task::JoinHandle<()>>) {
    let ReplaysTarget::Dir(dir) = config.replays_target() else {
        info!("replays are off (--replays off)");
        return (ReplaysHandle::off(), None);
    };
    match ReplayDir::open(&dir, config.replays_cap) {
        Ok(d) => {
            info!(
                replays = %dir.display(),
                kept = d.len(),
                mib = d.total() >> 20,
                cap_mib = config.replays_cap >> 20,
                "saving replays"
            );
            let (handle, task) = ReplaysHandle::spawn(d, records, metrics.replays.clone());
            (handle, Some(task))
        }
        Err(e) => {
            error!(
                "replays are off: cannot open the folder {}: {e}; fix it or pass --replays with \
                 another folder (or --replays off)",
                dir.display()
            );
            (ReplaysHandle::off(), None)
        }
    }
}

/// Makes the rooms from the configuration and level, and opens the
/// permanent ones (`room-1` ..), each with its recorder if recording.
fn open_rooms(
    config: &ServerConfig,
    levels: &LevelSet,
    recorders: &[Recorder],
    metrics: Arc<Metrics>,
    (records, replays): (RecordsHandle, ReplaysHandle),
) -> Result<Rooms, ServerError> {
    let template = RoomConfig {
        name: String::new(),
        tick_rate: config.tick_rate,
        snapshot_interval: config.snapshot_interval(),
        max_players: config.max_players,
        max_spectators: config.max_spectators,
        max_catch_up: config.max_catch_up,
        input_window: config.tick_rate.max(32) as usize,
        input_redundancy: DEFAULT_INPUT_REDUNDANCY,
        history: DEFAULT_HISTORY,
        level_id: levels.get(0).id.clone(),
        level_hash: levels.get(0).hash,
        level: levels.get(0).offer,
        levels: levels.clone(),
        rotation: config.rotation,
        record: None,
        idle_kick: config.idle_kick,
        instance: instance_id(),
        records,
        replays,
    };
    let rooms = Rooms::new(
        levels.get(0).game.clone(),
        template,
        config.max_rooms as usize,
        metrics,
    );
    for i in 1..=config.rooms {
        let record = recorders.get(i as usize - 1).cloned();
        rooms.open_permanent(format!("room-{i}"), record);
    }
    Ok(rooms)
}

/// Under Agones: waits for the SDK sidecar, which must answer before
/// anything else, and starts the driver; the fleet logic then says Ready
/// with the rooms open.
#[cfg(feature = "agones")]
async fn join_fleet(
    config: &ServerConfig,
    fingerprint: Fingerprint,
    shared: &Arc<Shared>,
    stop: &watch::Receiver<bool>,
    shutdown: &watch::Sender<bool>,
) -> Result<Option<std::thread::JoinHandle<()>>, ServerError> {
    let Some(fleet) = config.agones else {
        return Ok(None);
    };
    let thread = crate::agones::start(
        fleet,
        fingerprint.to_string(),
        shared.clone(),
        stop.clone(),
        ShutdownHandle(shutdown.clone()),
    )
    .await
    .map_err(|e| ServerError::Agones(e.to_string()))?;
    Ok(Some(thread))
}

/// The tasks serving browsers, and the WebTransport endpoint whose
/// sessions the accept loop takes.
struct Browsers {
    tasks: Vec<JoinHandle<()>>,
    webtransport: Option<Arc<wt::Endpoint>>,
}

/// Starts serving browsers if the web port is on: WebTransport's
/// certificate rotation and the web port itself, which hands admitted
/// WebSockets to `accepted`.
fn serve_browsers(
    web: Option<WebParts>,
    shared: &Arc<Shared>,
    config: &ServerConfig,
    accepted: mpsc::Sender<web::Accepted>,
    stop: &watch::Receiver<bool>,
) -> Browsers {
    let mut browsers = Browsers {
        tasks: Vec::new(),
        webtransport: None,
    };
    let Some(w) = web else {
        return browsers;
    };
    let wt_port = w
        .webtransport
        .as_ref()
        .map(|t| (t.addr.port(), t.certs.clone()));
    if let Some(t) = &w.webtransport {
        info!(
            addr = %t.addr,
            cert_sha256 = %crate::Fingerprint(t.certs.current().sha256),
            "WebTransport sessions at {}",
            crate::link::webtransport::PATH
        );
        browsers.tasks.push(tokio::spawn(wt::rotate(
            t.endpoint.clone(),
            t.certs.clone(),
            t.settings.clone(),
            stop.clone(),
        )));
        browsers.webtransport = Some(t.endpoint.clone());
    }
    info!(addr = %w.addr, files = w.root.len(), "serving browsers (the page, /web.json, /ws)");
    let state = Arc::new(WebState {
        shared: shared.clone(),
        root: w.root,
        level_hex: shared.levels.get(0).offer.hex(),
        level: shared.levels.get(0).bundle.clone(),
        webtransport: wt_port,
        accepted,
        idle_timeout: config.idle_timeout,
        guard: web::guard::WebGuard::new(w.limits, std::time::Instant::now()),
        warnings: std::sync::Mutex::new(crate::ratelimit::Throttle::new(web::WARN_EVERY)),
    });
    browsers
        .tasks
        .push(tokio::spawn(web::serve(w.listener, state, stop.clone())));
    browsers
}

/// The next WebTransport session, or never when WebTransport is off.
async fn next_webtransport(endpoint: Option<Arc<wt::Endpoint>>) -> IncomingSession {
    match endpoint {
        Some(e) => e.accept().await,
        None => std::future::pending().await,
    }
}

/// What the accept loop, and the shutdown after it, work on.
struct Serving {
    endpoint: quinn::Endpoint,
    /// The WebTransport endpoint, when it is on.
    webtransport: Option<Arc<wt::Endpoint>>,
    /// WebSockets admitted and upgraded by the web port.
    accepted: mpsc::Receiver<web::Accepted>,
    shared: Arc<Shared>,
    /// One task per connection.
    connections: JoinSet<()>,
}

impl Serving {
    /// Admits new connections and sweeps every [`SWEEP`] until shutdown is
    /// requested (or the endpoint closes).
    async fn accept_until_stopped(&mut self, stop: &mut watch::Receiver<bool>) {
        let mut sweep = tokio::time::interval(SWEEP);
        let mut refusals = RefusalLog::default();
        loop {
            tokio::select! {
                // `shutdown` lives until the end of `run`, so this never errs.
                () = stopped(stop) => break,
                _ = sweep.tick() => self.sweep(&mut refusals),
                incoming = self.endpoint.accept() => match incoming {
                    Some(incoming) => admit(
                        Incoming::Quic(incoming),
                        &self.shared,
                        &mut self.connections,
                        &mut refusals,
                    ),
                    None => break,
                },
                incoming = next_webtransport(self.webtransport.clone()) => admit(
                    Incoming::WebTransport(incoming),
                    &self.shared,
                    &mut self.connections,
                    &mut refusals,
                ),
                Some((incoming, ticket)) = self.accepted.recv() => self.serve(incoming, ticket),
                Some(done) = self.connections.join_next(), if !self.connections.is_empty() => {
                    if let Err(e) = done {
                        error!("connection task failed: {e}");
                    }
                }
            }
        }
    }

    /// Removes lost players past the reconnect grace time and closes idle
    /// rooms; refreshes the pending gauge and warns of refusals.
    fn sweep(&self, refusals: &mut RefusalLog) {
        let now = Instant::now();
        let metrics = &self.shared.metrics;
        for lost in self.shared.sessions.expire(now) {
            info!(player = %lost.player_id, room = %lost.room.name(), "reconnect grace over; the player leaves");
            metrics.sessions_expired.inc();
            lost.room.leave(lost.player_id, lost.generation);
        }
        self.shared.rooms.close_idle(now);
        metrics
            .pending_connections
            .set(self.shared.admission.pending() as i64);
        refusals.warn(now);
    }

    /// Serves a WebSocket the web port admitted and upgraded.
    fn serve(&mut self, incoming: Incoming, ticket: Ticket) {
        self.connections
            .spawn(connection::serve(incoming, ticket, self.shared.clone()));
    }

    /// Waits (bounded) for the connection tasks, which see the same signal:
    /// each sends `Notice{Shutdown}` and closes with `ServerShutdown`.
    /// Newcomers are refused meanwhile; tasks still running are aborted.
    async fn drain(&mut self) {
        info!(
            clients = self.connections.len(),
            "shutting down: notifying clients"
        );
        let drained = tokio::time::timeout(SHUTDOWN_GRACE + SHUTDOWN_LINGER, async {
            loop {
                tokio::select! {
                    done = self.connections.join_next() => if done.is_none() { break },
                    // Newcomers are refused at once rather than left waiting.
                    Some(incoming) = self.endpoint.accept() => incoming.refuse(),
                    incoming = next_webtransport(self.webtransport.clone()) => incoming.refuse(),
                    // Upgraded meanwhile: told the server is shutting down.
                    Some((incoming, ticket)) = self.accepted.recv() => self.serve(incoming, ticket),
                }
            }
        })
        .await;
        if drained.is_err() {
            warn!("connection tasks still running after the grace period; aborting them");
            self.connections.shutdown().await;
        }
    }

    /// Closes the QUIC endpoint, then WebTransport's, and waits (bounded)
    /// for each to go idle.
    async fn close_endpoints(&self) {
        self.endpoint.close(
            CloseCode::ServerShutdown.to_u32().into(),
            b"server shutting down",
        );
        if tokio::time::timeout(SHUTDOWN_GRACE, self.endpoint.wait_idle())
            .await
            .is_err()
        {
            warn!("endpoint not idle after {SHUTDOWN_GRACE:?}");
        }
        if let Some(endpoint) = &self.webtransport {
            endpoint.close(
                wtransport::VarInt::from_u32(CloseCode::ServerShutdown.to_u32()),
                b"server shutting down",
            );
            if tokio::time::timeout(SHUTDOWN_GRACE, endpoint.wait_idle())
                .await
                .is_err()
            {
                warn!("WebTransport endpoint not idle after {SHUTDOWN_GRACE:?}");
            }
        }
    }
}

/// Stops the rooms and waits for their tasks. A room stops once its last
/// handle is gone, so the shared state (whose sessions hold handles) goes
/// first.
async fn stop_rooms(shared: Arc<Shared>) {
    let room_tasks = shared.rooms.close_all();
    drop(shared);
    for task in room_tasks {
        if let Err(e) = task.await {
            error!("room task failed: {e}");
        }
    }
}
