//! `ledge-tests`: helpers for end-to-end tests of ledge over real QUIC.
//!
//! [`TestServer::start`] runs the real server in-process on `127.0.0.1:0`
//! with a throw-away certificate directory; tests connect to it with the
//! headless client library exactly as players and bots do. [`UdpRelay`]
//! (a thin wrapper over the `ledge-netsim` link conditioner) sits between
//! clients and the server to impair the traffic, or drop everything to make
//! a client go silent without closing; [`scrape`] reads the metrics
//! endpoint.
//! [`PredictedClient`] drives a predicting client ([`ClientGame`]) in real
//! time with a scripted input, the way a player or bot would.
//! [`browser`] drives headless Chromium over the DevTools protocol, for
//! the browser client's tests. [`postgres`] runs a throwaway PostgreSQL
//! cluster for a test; [`logs`] keeps the in-process server's log.

use std::collections::BTreeSet;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::{Duration, Instant};

use ledge_client::game::predict::Reconciled;
use ledge_client::net::transport::{dial, Dialed};
use ledge_client::netstats::TransportSample;
use ledge_client::{connect, ClientGame, Session, SessionEvent, SnapshotUpdate};
use ledge_netsim::{LinkConfig, Loss, Relay, RelayConfig};
use ledge_server::admission::AdmissionConfig;
use ledge_server::metrics::Registry;
use ledge_server::record::Recorder;
use ledge_server::{Fingerprint, Server, ServerConfig, ServerError, ShutdownHandle};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{FrameDecoder, ServerControl, StateSnapshot, PROTOCOL_VERSION};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::task::JoinHandle;

/// A connection that sent a hand-made hello: its control stream and the
/// server's first answer ([`raw_hello`]).
#[derive(Debug)]
pub struct RawHello {
    /// The client's endpoint (kept open with the connection).
    pub endpoint: quinn::Endpoint,
    /// The connection.
    pub connection: quinn::Connection,
    /// The control stream's sending half.
    pub send: quinn::SendStream,
    /// The control stream's receiving half.
    pub recv: quinn::RecvStream,
    /// The server's first answer (`Welcome`, `Reject`).
    pub answer: ServerControl,
}

/// Connects and sends a hello encoded by hand (variant 0, this build's
/// version, then `name`'s length and bytes), so names the client library
/// refuses to send reach the server; returns the server's first answer
/// with the open stream.
pub async fn raw_hello(server: &TestServer, name: &[u8]) -> RawHello {
    let Dialed {
        endpoint,
        connection,
    } = dial(server.addr, "localhost", server.fingerprint)
        .await
        .expect("dials the test server");
    let (mut send, mut recv) = connection.open_bi().await.expect("control stream");
    let mut payload = vec![0u8, PROTOCOL_VERSION as u8, name.len() as u8];
    payload.extend_from_slice(name);
    let mut frame = (payload.len() as u32).to_le_bytes().to_vec();
    frame.extend_from_slice(&payload);
    send.write_all(&frame).await.expect("hello sent");
    let mut decoder = FrameDecoder::default();
    let mut buf = [0u8; 1024];
    let answer = tokio::time::timeout(WAIT, async {
        loop {
            if let Some(m) = decoder.pop_message::<ServerControl>() {
                return m.expect("a valid answer");
            }
            let n = recv
                .read(&mut buf)
                .await
                .expect("the stream reads")
                .expect("an answer");
            decoder.push(&buf[..n]).expect("a valid frame");
        }
    })
    .await
    .expect("an answer in time");
    RawHello {
        endpoint,
        connection,
        send,
        recv,
        answer,
    }
}

/// How long [`TestServer::stop`] may take before it counts as hung.
pub const STOP_TIMEOUT: Duration = Duration::from_secs(5);

/// How long helpers wait for something that should happen promptly.
pub const WAIT: Duration = Duration::from_secs(3);

/// A server running in-process on loopback, stopped on [`TestServer::stop`]
/// (or aborted when dropped).
#[derive(Debug)]
pub struct TestServer {
    /// Where the server listens (loopback, ephemeral port).
    pub addr: SocketAddr,
    /// SHA-256 of its freshly generated certificate.
    pub fingerprint: Fingerprint,
    /// The metrics endpoint, when configured.
    pub metrics_addr: Option<SocketAddr>,
    /// Room `room-1`'s match record, when recording is configured
    /// ([`ServerConfig::record_ticks`]).
    pub recorder: Option<Recorder>,
    /// The web port, when configured ([`ServerConfig::web`]).
    pub web_addr: Option<SocketAddr>,
    /// WebTransport's UDP address, when on.
    pub webtransport_addr: Option<SocketAddr>,
    /// The level bundle offered (hash and size).
    pub level_offer: ledge_shared::protocol::LevelOffer,
    registry: Arc<Registry>,
    shutdown: ShutdownHandle,
    task: Option<JoinHandle<Result<(), ServerError>>>,
    _cert_dir: tempfile::TempDir,
}

impl TestServer {
    /// Starts a server with the default settings. Call inside a tokio
    /// runtime.
    pub async fn start() -> TestServer {
        Self::start_with(|_| {}).await
    }

    /// Starts a server after letting `adjust` change its configuration
    /// (the address and certificate directory are set for you).
    pub async fn start_with(adjust: impl FnOnce(&mut ServerConfig)) -> TestServer {
        let cert_dir = tempfile::tempdir().expect("temporary certificate directory");
        let mut config = ServerConfig {
            bind: SocketAddr::from(([127, 0, 0, 1], 0)),
            cert_dir: cert_dir.path().to_owned(),
            // Tests stand for many machines on one loopback address; the
            // admission tests (tests/e2e/admission.rs) restore the defaults.
            admission: AdmissionConfig {
                per_address: 4096,
                pending_per_address: 256,
                pending: 256,
                ..AdmissionConfig::default()
            },
            ..ServerConfig::default()
        };
        adjust(&mut config);
        let server = Server::bind(config).expect("server binds to loopback");
        TestServer {
            addr: server.local_addr(),
            fingerprint: server.fingerprint(),
            metrics_addr: server.metrics_addr(),
            recorder: server.recorder("room-1"),
            web_addr: server.web_addr(),
            webtransport_addr: server.webtransport_addr(),
            level_offer: server.level_offer(),
            registry: server.registry(),
            shutdown: server.shutdown_handle(),
            task: Some(tokio::spawn(server.run())),
            _cert_dir: cert_dir,
        }
    }

    /// Joins as `name` (any room).
    pub async fn join(&self, name: &str) -> Session {
        connect(self.addr, "localhost", self.fingerprint, name)
            .await
            .unwrap_or_else(|e| panic!("{name} is welcomed: {e}"))
    }

    /// The metrics in the Prometheus text format, read in-process.
    pub fn metrics(&self) -> String {
        ledge_server::metrics::encode(&self.registry)
    }

    /// Shuts the server down gracefully and returns what `run` returned.
    ///
    /// Panics if shutdown takes longer than [`STOP_TIMEOUT`].
    pub async fn stop(mut self) -> Result<(), ServerError> {
        self.shutdown.shutdown();
        let task = self.task.take().expect("stop is called once");
        tokio::time::timeout(STOP_TIMEOUT, task)
            .await
            .expect("server shut down in time")
            .expect("server task did not panic")
    }

    /// Waits up to `within` for the server to stop on its own (not asked
    /// by the test) and returns what `run` returned; `None` while it runs.
    pub async fn ended(&mut self, within: Duration) -> Option<Result<(), ServerError>> {
        let task = self.task.as_mut()?;
        let done = tokio::time::timeout(within, task).await.ok()?;
        self.task = None;
        Some(done.expect("server task did not panic"))
    }

    /// Asks the server to shut down without waiting.
    pub fn begin_shutdown(&self) {
        self.shutdown.shutdown();
    }
}

impl Drop for TestServer {
    fn drop(&mut self) {
        if let Some(task) = self.task.take() {
            self.shutdown.shutdown();
            task.abort();
        }
    }
}

/// The value of the metric sample `series` (name and labels exactly as
/// printed, e.g. `ledge_malformed_messages_total{channel="Datagram"}`) in a
/// text exposition; 0 when absent.
pub fn metric(text: &str, series: &str) -> f64 {
    text.lines()
        .filter_map(|line| line.strip_prefix(series))
        .filter_map(|rest| rest.strip_prefix(' '))
        .filter_map(|value| value.trim().parse().ok())
        .next()
        .unwrap_or(0.0)
}

/// `GET /metrics` over plain HTTP/1.1; returns the status line and body.
pub async fn scrape(addr: SocketAddr) -> (String, String) {
    let mut stream = tokio::net::TcpStream::connect(addr)
        .await
        .expect("metrics endpoint accepts");
    stream
        .write_all(b"GET /metrics HTTP/1.1\r\nHost: localhost\r\n\r\n")
        .await
        .unwrap();
    let mut response = String::new();
    tokio::time::timeout(WAIT, stream.read_to_string(&mut response))
        .await
        .expect("metrics answer in time")
        .unwrap();
    let (head, body) = response.split_once("\r\n\r\n").expect("an HTTP response");
    let status = head.lines().next().unwrap_or_default().to_owned();
    (status, body.to_owned())
}

/// Receives events until a snapshot arrives (others are returned too).
pub async fn next_snapshot(
    session: &mut Session,
    within: Duration,
) -> (SnapshotUpdate, Vec<SessionEvent>) {
    let mut others = Vec::new();
    let found = tokio::time::timeout(within, async {
        loop {
            match session.recv().await.expect("session stays up") {
                SessionEvent::Snapshot(update) => return update,
                other => others.push(other),
            }
        }
    })
    .await
    .expect("a snapshot in time");
    (found, others)
}

/// Receives snapshots until one satisfies `done`; returns it.
pub async fn snapshot_where(
    session: &mut Session,
    within: Duration,
    mut done: impl FnMut(&StateSnapshot) -> bool,
) -> StateSnapshot {
    let deadline = Instant::now() + within;
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let (update, _) = next_snapshot(session, left).await;
        if done(&update.state) {
            return update.state;
        }
    }
}

/// Every event that arrives within `window`.
pub async fn drain(session: &mut Session, window: Duration) -> Vec<SessionEvent> {
    let mut events = Vec::new();
    let deadline = tokio::time::Instant::now() + window;
    while let Ok(event) = tokio::time::timeout_at(deadline, session.recv()).await {
        events.push(event.expect("session stays up"));
    }
    events
}

/// The entity ids of a snapshot.
pub fn ids(state: &StateSnapshot) -> BTreeSet<u32> {
    state.entities.iter().map(|e| e.id).collect()
}

/// How a [`UdpRelay`] impairs the traffic, simply: random loss each way,
/// and the same delay and jitter both ways. [`UdpRelay::set_links`] takes
/// the full [`LinkConfig`] (burst loss, duplication, reordering).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Impairment {
    /// Fraction of client-to-server datagrams dropped.
    pub loss_up: f64,
    /// Fraction of server-to-client datagrams dropped.
    pub loss_down: f64,
    /// Fixed one-way delay, each way.
    pub delay: Duration,
    /// Extra one-way delay, uniform in `[0, jitter]` per datagram (jitter
    /// never reorders: see [`LinkConfig`]).
    pub jitter: Duration,
}

impl Impairment {
    /// The link each way: `(up, down)`.
    pub fn links(&self) -> (LinkConfig, LinkConfig) {
        let half = self.jitter / 2;
        let base = LinkConfig::delay(self.delay + half).with_jitter(half);
        let lossy = |p: f64| {
            base.with_loss(if p > 0.0 {
                Loss::Bernoulli { p }
            } else {
                Loss::None
            })
        };
        (lossy(self.loss_up), lossy(self.loss_down))
    }
}

/// A link conditioner ([`ledge_netsim::Relay`]) on loopback between
/// clients and a server, perfect until told otherwise. While
/// [`UdpRelay::blackhole`] is on, it drops every datagram both ways, as a
/// dead network or a frozen client would; [`UdpRelay::impair`] and
/// [`UdpRelay::set_links`] impair the traffic. Several clients may share
/// one relay.
#[derive(Debug)]
pub struct UdpRelay {
    /// Where clients connect instead of the server.
    pub addr: SocketAddr,
    relay: Relay,
}

impl UdpRelay {
    /// Starts relaying to `server`, unimpaired.
    pub async fn start(server: SocketAddr) -> UdpRelay {
        Self::with_links(server, LinkConfig::PERFECT, LinkConfig::PERFECT).await
    }

    /// Starts relaying to `server` with `up` (client to server) and `down`.
    pub async fn with_links(server: SocketAddr, up: LinkConfig, down: LinkConfig) -> UdpRelay {
        let config = RelayConfig {
            up,
            down,
            ..RelayConfig::default()
        };
        let relay = Relay::start(SocketAddr::from(([127, 0, 0, 1], 0)), server, config)
            .await
            .expect("the relay binds to loopback");
        UdpRelay {
            addr: relay.local_addr(),
            relay,
        }
    }

    /// Drops all traffic from now on (until [`UdpRelay::restore`]).
    pub fn blackhole(&self) {
        self.relay.set_blackout_both(true);
    }

    /// Ends a [`UdpRelay::blackhole`].
    pub fn restore(&self) {
        self.relay.set_blackout_both(false);
    }

    /// Impairs the traffic from now on.
    pub fn impair(&self, impairment: Impairment) {
        let (up, down) = impairment.links();
        self.set_links(up, down);
    }

    /// Replaces both directions' links from now on.
    pub fn set_links(&self, up: LinkConfig, down: LinkConfig) {
        self.relay
            .set_links(up, down)
            .expect("valid link configurations");
    }

    /// The relay itself: per-direction control and counters.
    pub fn relay(&self) -> &Relay {
        &self.relay
    }
}

/// Ticks the server's room `room` starved for inputs (a player's input for a
/// tick missing when it ran), from the metrics.
pub fn starvation(server: &TestServer, room: &str) -> f64 {
    metric(
        &server.metrics(),
        &format!("ledge_input_starvation_total{{room=\"{room}\"}}"),
    )
}

/// A predicting client on a real session, driven by a script.
#[derive(Debug)]
pub struct PredictedClient {
    /// The session.
    pub session: Session,
    /// Its predicted game, clock, interpolation.
    pub game: ClientGame,
    /// Every reconciliation so far.
    pub log: Vec<Reconciled>,
    /// Every snapshot received so far (its tick and our authoritative state).
    pub snapshots: u64,
    /// Local ticks run.
    pub ticks: u64,
    /// Inputs deliberately not sent.
    pub skipped: u64,
}

impl PredictedClient {
    /// Joins `server` as `name` and sets up prediction on the default level,
    /// with an input margin of `margin` ticks.
    pub async fn join(server: &TestServer, name: &str, margin: f64) -> PredictedClient {
        Self::join_via(server, server.addr, name, margin).await
    }

    /// [`PredictedClient::join`] through `addr` (a [`UdpRelay`]).
    pub async fn join_via(
        server: &TestServer,
        addr: SocketAddr,
        name: &str,
        margin: f64,
    ) -> PredictedClient {
        let session = connect(addr, "localhost", server.fingerprint, name)
            .await
            .unwrap_or_else(|e| panic!("{name} is welcomed: {e}"));
        let level = ledge_levels::default_level();
        let mut game = ClientGame::new(
            session.welcome(),
            level,
            session.connection().rtt(),
            Instant::now(),
        )
        .expect("the server plays the default level");
        game.set_base_margin(margin);
        PredictedClient {
            session,
            game,
            log: Vec::new(),
            snapshots: 0,
            ticks: 0,
            skipped: 0,
        }
    }

    /// Plays until `until`. Each due tick, `script(game, tick)` gives the
    /// buttons and whether to send them (not sending simulates a lost burst
    /// the redundancy cannot recover: the next packet fills the gap with
    /// the previous buttons). Each snapshot is reconciled, then handed to
    /// `seen` with the reconciliation.
    pub async fn run(
        &mut self,
        until: Instant,
        mut script: impl FnMut(&ClientGame, u64) -> (Buttons, bool),
        mut seen: impl FnMut(&ClientGame, &SnapshotUpdate, &Reconciled),
    ) {
        let mut next_sample = Instant::now();
        loop {
            let now = Instant::now();
            if now >= until {
                return;
            }
            if now >= next_sample {
                let sample = TransportSample::of(self.session.connection());
                self.game.on_transport(sample, now);
                next_sample = now + Duration::from_millis(250);
            }
            let due = self.game.advance(now);
            for _ in 0..due {
                let (buttons, send) = script(&self.game, self.game.next_tick());
                let tick = self.game.step(buttons);
                self.ticks += 1;
                if send {
                    self.session
                        .send_input(tick, buttons)
                        .expect("input datagram queued");
                } else {
                    self.skipped += 1;
                }
            }
            let wait = self
                .game
                .clock()
                .until_next_tick(Instant::now())
                .min(until.saturating_duration_since(Instant::now()));
            let event = tokio::select! {
                event = self.session.recv() => event.expect("session stays up"),
                () = tokio::time::sleep(wait) => continue,
            };
            if let SessionEvent::Snapshot(update) = event {
                self.snapshots += 1;
                if let Some(r) = self.game.on_snapshot(&update) {
                    self.log.push(r);
                    seen(&self.game, &update, &r);
                }
            }
        }
    }
}
pub mod attack;
pub mod browser;
pub mod e2e;
pub mod logs;
pub mod postgres;
pub mod server_process;
pub mod web;

/// A file of the level corpus (`target/level-corpus`, made by
/// `scripts/fetch-level-corpus`: Tiled's own examples, with their
/// licences), fetched first when missing under `CI=true`; `None` (the test
/// then says so loudly and passes) elsewhere without it.
pub fn corpus_file(relative: &str) -> Option<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let file = root.join("target/level-corpus").join(relative);
    if !file.is_file() && std::env::var("CI").as_deref() == Ok("true") {
        let status = std::process::Command::new("bash")
            .arg(root.join("scripts/fetch-level-corpus"))
            .status()
            .expect("scripts/fetch-level-corpus runs");
        assert!(
            status.success(),
            "scripts/fetch-level-corpus failed: {status}"
        );
    }
    if file.is_file() {
        Some(file)
    } else {
        eprintln!(
            "\n*** SKIPPED: no level corpus ({}): run scripts/fetch-level-corpus ***\n",
            file.display()
        );
        None
    }
}
