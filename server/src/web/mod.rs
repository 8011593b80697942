//! Browsers: the web port (`--web-bind`, HTTP/1.1) and WebTransport.
//!
//! The web port serves the page ([`files`]), `/web.json` (what the page
//! needs to connect), `/level` (the level bundle) and WebSocket sessions
//! at `/ws`. WebSocket and WebTransport sessions go through admission like
//! QUIC ones (the browser's real address) and are then served by the same
//! connection code ([`crate::connection`], [`crate::link`]).
//!
//! The HTTP side is bounded: at most [`MAX_HTTP_CONNECTIONS`] connections
//! at once (more wait in the kernel's backlog), each for at most
//! [`REQUEST_TIMEOUT`], a request head arriving within [`HEADER_TIMEOUT`]
//! (an idle keep-alive connection too); a WebSocket is bounded by its own
//! limits ([`crate::link::websocket`]). Per address ([`guard`]): open
//! connections, requests a second, downloads, and the bytes a second of
//! their bodies, refused with 429 and `Retry-After` ([`refusal`]); bodies
//! are paced ([`paced`]). Files and the level carry entity tags, so a
//! reload revalidates them instead of downloading them again.

pub mod files;
pub mod guard;
pub mod paced;
pub mod records_pages;
pub mod refusal;
pub mod respond;
pub mod webtransport_cert;
pub mod webtransport_endpoint;

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::{Duration, Instant};

use axum::extract::ws::WebSocketUpgrade;
use axum::extract::{ConnectInfo, Path, Request, State};
use axum::http::{header, StatusCode};
use axum::response::Response;
use axum::routing::get;
use axum::Router;
use bytes::Bytes;
use hyper_util::rt::{TokioIo, TokioTimer};
use ledge_shared::protocol::web::MAX_CLIENT_MESSAGE;
use ledge_shared::protocol::PROTOCOL_VERSION;
use tokio::net::TcpListener;
use tokio::sync::{mpsc, watch, Semaphore};
use tokio::task::JoinSet;
use tracing::{debug, warn};

use crate::admission::{Refusal, Ticket, Verdict};
use crate::link::websocket::{self, Upgraded};
use crate::link::{Incoming, Transport};
use crate::metrics::{AddressClass, AddressClassLabel, WebRefusalLabel};
use crate::ratelimit::Throttle;
use crate::shared::Shared;
use files::WebRoot;
use guard::{ConnectionPermit, Limited, WebGuard, WebRefusal, PACED_FROM};
use respond::{answer, text};
use webtransport_endpoint::WebCerts;

/// Most HTTP connections served at once.
pub const MAX_HTTP_CONNECTIONS: usize = 128;
/// Time a client has to send its request head.
pub const HEADER_TIMEOUT: Duration = Duration::from_secs(5);
/// Longest life of an HTTP connection (a WebSocket's is not counted: it
/// is handed over at the upgrade).
pub const REQUEST_TIMEOUT: Duration = Duration::from_secs(60);

/// Most bytes of a request buffered (its head: no route reads a body).
pub const MAX_REQUEST_BUFFER: usize = 16 * 1024;
/// Most refused connections being answered at once; past it they are
/// closed unanswered (a flood gets what it sends).
pub const MAX_REFUSALS_AT_ONCE: usize = 64;
/// A warning about refusals at most this often.
pub const WARN_EVERY: Duration = Duration::from_secs(10);

/// A WebSocket admitted and upgraded, for the server's accept loop.
pub type Accepted = (Incoming, Ticket);

/// What the web port's handlers share.
#[derive(Debug)]
pub struct WebState {
    /// The connection tasks' shared state (admission, metrics, level).
    pub shared: Arc<Shared>,
    /// The page.
    pub root: WebRoot,
    /// The level bundle, for `/level`.
    pub level: Bytes,
    /// Its SHA-256, lower-case hex.
    pub level_hex: String,
    /// WebTransport's UDP port and certificates, when it is on.
    pub webtransport: Option<(u16, Arc<WebCerts>)>,
    /// Where upgraded WebSockets go (the server's accept loop).
    pub accepted: mpsc::Sender<Accepted>,
    /// A WebSocket client silent this long is lost.
    pub idle_timeout: Duration,
    /// The per-address limits.
    pub guard: Arc<WebGuard>,
    /// Refusal warnings, at most every [`WARN_EVERY`].
    pub warnings: std::sync::Mutex<Throttle>,
}

impl WebState {
    /// Counts a refusal of `peer` and warns at most every [`WARN_EVERY`].
    fn refused(&self, peer: SocketAddr, limited: Limited) {
        let metrics = &self.shared.metrics;
        metrics
            .web_refused
            .get_or_create(&WebRefusalLabel {
                reason: limited.reason,
            })
            .inc();
        let due = self
            .warnings
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .note(Instant::now());
        if let Some(n) = due {
            warn!(
                %peer,
                reason = ?limited.reason,
                "web port: {n} refused since the last warning (limits: docs/SERVER.md, \
                 \"The web port's limits\"; counts: ledge_web_refused_total)"
            );
        }
    }

    /// The answer to a refused request, counted.
    fn refuse(&self, peer: SocketAddr, limited: Limited) -> Response {
        self.refused(peer, limited);
        refusal::limited_response(limited)
    }
}

/// The routes.
fn router(state: Arc<WebState>) -> Router {
    Router::new()
        .route("/", get(index))
        .route("/web.json", get(web_json_route))
        .route("/level", get(level))
        .route(
            "/levels/:hex",
            get(|s: State<Arc<WebState>>, Path(hex): Path<String>, request: Request| async move {
                let found = s.shared.levels.levels().iter().find(|l| l.offer.hex().eq_ignore_ascii_case(&hex));
                match found {
                    Some(l) => {
                        let etag = format!("\"{}\"", l.offer.hex());
                        download(&s, &request, "application/octet-stream", &etag, l.bundle.clone())
                    }
                    None => text(
                        StatusCode::NOT_FOUND,
                        format!("this server does not play level {hex} (GET /level is its first level)\n"),
                    ),
                }
            }),
        )
        .route(
            "/replays/:id",
            get(|State(s): State<Arc<WebState>>, Path(id): Path<String>, request: Request| async move {
                replay(&s, &id, request).await
            }),
        )
        .route(
            "/records",
            get(|State(s): State<Arc<WebState>>, request: Request| async move {
                let html = records_pages::wants_html(&request);
                drop(request);
                records_pages::levels(s.shared.records.store().as_ref(), html).await
            }),
        )
        .route(
            "/records/:level",
            get(
                |State(s): State<Arc<WebState>>, Path(level): Path<String>, request: Request| async move {
                    let query = request.uri().query().map(str::to_owned);
                    drop(request);
                    records_pages::level(s.shared.records.store().as_ref(), &level, query.as_deref()).await
                },
            ),
        )
        .route("/ws", get(websocket))
        .fallback(file)
        .with_state(state)
}

/// Who is asking: the peer and its connection's permit (put in each
/// request's extensions by [`serve`]).
#[derive(Debug, Clone)]
struct Caller {
    peer: SocketAddr,
    permit: Arc<ConnectionPermit>,
}

async fn index(State(state): State<Arc<WebState>>, request: Request) -> Response {
    if let Some(missing) = state.root.missing() {
        return text(StatusCode::SERVICE_UNAVAILABLE, format!("{missing}\n"));
    }
    file_response(&state, &request, "index.html")
}

async fn file(State(state): State<Arc<WebState>>, request: Request) -> Response {
    let path = request.uri().path();
    let name = path.strip_prefix('/').unwrap_or(path);
    if request.method() != axum::http::Method::GET && request.method() != axum::http::Method::HEAD {
        return text(StatusCode::METHOD_NOT_ALLOWED, "GET only\n".into());
    }
    file_response(&state, &request, name)
}

fn file_response(state: &WebState, request: &Request, name: &str) -> Response {
    match state.root.get(name) {
        Some(f) => download(state, request, f.content_type, &f.etag, f.body.clone()),
        None => text(StatusCode::NOT_FOUND, "not found\n".into()),
    }
}

/// Whether `If-None-Match` names `etag` (or `*`): the client has it.
fn not_modified(headers: &axum::http::HeaderMap, etag: &str) -> bool {
    headers
        .get_all(header::IF_NONE_MATCH)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(','))
        .map(|tag| tag.trim().trim_start_matches("W/"))
        .any(|tag| tag == "*" || tag == etag)
}

/// `body` with its entity tag: 304 when the client has it; a download
/// (counted and paced, [`guard`]) when it is large.
fn download(
    state: &WebState,
    request: &Request,
    content_type: &str,
    etag: &str,
    body: Bytes,
) -> Response {
    let with_tag = |mut response: Response| {
        if let Ok(value) = etag.parse() {
            response.headers_mut().insert(header::ETAG, value);
        }
        response
    };
    if not_modified(request.headers(), etag) {
        return with_tag(answer(
            StatusCode::NOT_MODIFIED,
            content_type,
            axum::body::Body::empty(),
        ));
    }
    let caller = request.extensions().get::<Caller>();
    let (Some(caller), true) = (caller, body.len() >= PACED_FROM) else {
        return with_tag(answer(StatusCode::OK, content_type, body));
    };
    match state.guard.download(&caller.permit, Instant::now()) {
        Err(limited) => state.refuse(caller.peer, limited),
        Ok(permit) => {
            let class = AddressClass::of(caller.peer.ip());
            let sent = state
                .shared
                .metrics
                .web_download_bytes
                .get_or_create(&AddressClassLabel { class })
                .clone();
            let len = body.len();
            let mut response = answer(
                StatusCode::OK,
                content_type,
                paced::paced_body(body, permit, sent),
            );
            response
                .headers_mut()
                .insert(header::CONTENT_LENGTH, len.into());
            with_tag(response)
        }
    }
}

/// The JSON document of `/web.json`.
pub fn web_json(level_hex: &str, webtransport: Option<(u16, &[[u8; 32]])>) -> serde_json::Value {
    let hex = |h: &[u8; 32]| h.iter().map(|b| format!("{b:02x}")).collect::<String>();
    let webtransport = match webtransport {
        Some((port, hashes)) => serde_json::json!({
            "port": port,
            "path": crate::link::webtransport::PATH,
            "cert_sha256": hashes.iter().map(hex).collect::<Vec<_>>(),
        }),
        None => serde_json::Value::Null,
    };
    serde_json::json!({
        "protocol": PROTOCOL_VERSION,
        "websocket": "/ws",
        "webtransport": webtransport,
        "level": level_hex,
    })
}

async fn web_json_route(State(state): State<Arc<WebState>>) -> Response {
    let hashes = state
        .webtransport
        .as_ref()
        .map(|(port, certs)| (*port, certs.hashes()));
    let doc = web_json(
        &state.level_hex,
        hashes.as_ref().map(|(port, h)| (*port, h.as_slice())),
    );
    answer(StatusCode::OK, "application/json", doc.to_string())
}

async fn level(State(state): State<Arc<WebState>>, request: Request) -> Response {
    let etag = format!("\"{}\"", state.level_hex);
    download(
        &state,
        &request,
        "application/octet-stream",
        &etag,
        state.level.clone(),
    )
}

/// `GET /replays/ID`: a replay file, paced and limited like the level.
async fn replay(state: &WebState, id: &str, request: Request) -> Response {
    let Some(dir) = &state.shared.replays_dir else {
        return text(
            StatusCode::NOT_FOUND,
            "this server keeps no replays (--replays off)\n".into(),
        );
    };
    if !crate::replays::is_replay_id(id) {
        return text(
            StatusCode::BAD_REQUEST,
            "a replay is named by 16 lower-case hex digits (the records page links them)\n".into(),
        );
    }
    let path = crate::replays::ReplayDir::path_of(dir, id);
    let max =
        (ledge_shared::replay::MAX_REPLAY_BYTES + ledge_shared::replay::file::HEADER_LEN) as u64;
    let bytes = match tokio::fs::metadata(&path).await {
        Ok(meta) if meta.len() > max => Err(format!("replay {id} is over {max} bytes")),
        Ok(_) => tokio::fs::read(&path).await.map_err(|e| e.to_string()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return text(
                StatusCode::NOT_FOUND,
                format!("no replay {id} here: never saved, or deleted past the server's cap\n"),
            );
        }
        Err(e) => Err(e.to_string()),
    };
    match bytes {
        Ok(bytes) => {
            let etag = format!("\"{id}-{}\"", bytes.len());
            download(
                state,
                &request,
                "application/octet-stream",
                &etag,
                Bytes::from(bytes),
            )
        }
        Err(e) => {
            warn!("cannot serve replay {id}: {e}");
            text(
                StatusCode::INTERNAL_SERVER_ERROR,
                "the replay cannot be read\n".into(),
            )
        }
    }
}

/// What a refused browser is told.
fn refusal_text(reason: Refusal) -> &'static str {
    match reason {
        Refusal::ServerFull => "the server is full: try again later\n",
        Refusal::AddressConnections | Refusal::AddressPending => {
            "too many connections from your address: close some and try again\n"
        }
        Refusal::PendingFull | Refusal::Evicted => {
            "too many connections are waiting to join: try again\n"
        }
        Refusal::HelloTimeout | Refusal::ShuttingDown => "the server is shutting down\n",
    }
}

async fn websocket(
    State(state): State<Arc<WebState>>,
    ConnectInfo(peer): ConnectInfo<SocketAddr>,
    upgrade: WebSocketUpgrade,
) -> Response {
    let shared = &state.shared;
    if *shared.shutdown.borrow() {
        return text(
            StatusCode::SERVICE_UNAVAILABLE,
            refusal_text(Refusal::ShuttingDown).into(),
        );
    }
    let metrics = &shared.metrics;
    let (ticket, evicted) = match shared
        .admission
        .consider(peer.ip(), true, false, Instant::now())
    {
        Verdict::Admit { ticket, evicted } => (ticket, evicted),
        Verdict::Refuse(reason) => {
            metrics.refused_on(Transport::WebSocket, reason);
            debug!(%peer, ?reason, "WebSocket refused");
            let status = match reason {
                Refusal::ServerFull => StatusCode::SERVICE_UNAVAILABLE,
                _ => StatusCode::TOO_MANY_REQUESTS,
            };
            return text(status, refusal_text(reason).into());
        }
        // Not asked for: a TCP peer's address is validated.
        Verdict::Retry => {
            return text(StatusCode::SERVICE_UNAVAILABLE, "try again\n".into());
        }
    };
    if evicted {
        metrics.refused(Refusal::Evicted);
    }
    metrics
        .pending_connections
        .set(shared.admission.pending() as i64);
    let accepted = state.accepted.clone();
    let idle = state.idle_timeout;
    upgrade
        .max_message_size(MAX_CLIENT_MESSAGE)
        .max_frame_size(MAX_CLIENT_MESSAGE)
        .write_buffer_size(websocket::WRITE_BUFFER)
        .max_write_buffer_size(websocket::MAX_WRITE_BUFFER)
        .on_upgrade(move |socket| async move {
            let incoming = Incoming::WebSocket(Upgraded::new(socket, peer, idle));
            // The server stopped: the ticket and socket go.
            let _ = accepted.send((incoming, ticket)).await;
        })
}

/// Binds the web port now (so a bad address fails the start-up and the
/// real port is known).
pub fn bind(addr: SocketAddr) -> std::io::Result<TcpListener> {
    crate::metrics::bind(addr)
}

/// Whether a request has a body (no route takes one).
fn has_body(headers: &axum::http::HeaderMap) -> bool {
    headers.contains_key(header::TRANSFER_ENCODING)
        || headers
            .get(header::CONTENT_LENGTH)
            .is_some_and(|v| v.as_bytes() != b"0")
}

/// The checks every request passes before its route: its address's
/// request rate, and no body.
fn screen<B>(state: &WebState, caller: &Caller, request: &Request<B>) -> Result<(), Limited> {
    state.guard.request(&caller.permit, Instant::now())?;
    if has_body(request.headers()) {
        return Err(Limited {
            reason: WebRefusal::Body,
            retry_after: Duration::ZERO,
        });
    }
    Ok(())
}

/// Open HTTP connections, counted in the gauge until dropped.
struct OpenConnection(prometheus_client::metrics::gauge::Gauge);

impl OpenConnection {
    fn new(gauge: &prometheus_client::metrics::gauge::Gauge) -> OpenConnection {
        gauge.inc();
        OpenConnection(gauge.clone())
    }
}

impl Drop for OpenConnection {
    fn drop(&mut self) {
        self.0.dec();
    }
}

/// Serves one HTTP connection (and hands a WebSocket upgrade over).
async fn serve_connection(
    stream: tokio::net::TcpStream,
    caller: Caller,
    router: Router,
    state: Arc<WebState>,
) {
    let _open = OpenConnection::new(&state.shared.metrics.web_connections);
    let peer = caller.peer;
    let service = hyper::service::service_fn(move |mut request: Request<hyper::body::Incoming>| {
        let (caller, state, mut router) = (caller.clone(), state.clone(), router.clone());
        async move {
            if let Err(limited) = screen(&state, &caller, &request) {
                return Ok(state.refuse(caller.peer, limited));
            }
            request.extensions_mut().insert(ConnectInfo(caller.peer));
            request.extensions_mut().insert(caller);
            tower_service::Service::call(&mut router, request).await
        }
    });
    let connection = hyper::server::conn::http1::Builder::new()
        .timer(TokioTimer::new())
        .header_read_timeout(HEADER_TIMEOUT)
        .max_buf_size(MAX_REQUEST_BUFFER)
        .serve_connection(TokioIo::new(stream), service)
        .with_upgrades();
    match tokio::time::timeout(REQUEST_TIMEOUT, connection).await {
        Ok(Ok(())) => {}
        Ok(Err(e)) => debug!(%peer, "web request: {e}"),
        Err(_) => debug!(%peer, "web request timed out"),
    }
}

/// Every second until `stop`: forgets the addresses that went idle and
/// shows how many are left (`ledge_web_addresses`).
async fn forget_idle_addresses(state: Arc<WebState>, mut stop: watch::Receiver<bool>) {
    let mut every = tokio::time::interval(Duration::from_secs(1));
    loop {
        tokio::select! {
            () = crate::shutdown::stopped(&mut stop) => return,
            _ = every.tick() => {}
        }
        let addresses = state.guard.addresses(Instant::now());
        state.shared.metrics.web_addresses.set(addresses as i64);
    }
}

/// Serves the web port until `stop`.
pub async fn serve(listener: TcpListener, state: Arc<WebState>, mut stop: watch::Receiver<bool>) {
    let router = router(state.clone());
    let slots = Arc::new(Semaphore::new(MAX_HTTP_CONNECTIONS));
    let refusals = Arc::new(Semaphore::new(MAX_REFUSALS_AT_ONCE));
    let mut connections = JoinSet::new();
    connections.spawn(forget_idle_addresses(state.clone(), stop.clone()));
    loop {
        let permit = tokio::select! {
            () = crate::shutdown::stopped(&mut stop) => break,
            permit = slots.clone().acquire_owned() => match permit {
                Ok(permit) => permit,
                Err(_) => break,
            },
            Some(_) = connections.join_next(), if !connections.is_empty() => continue,
        };
        let (stream, peer) = tokio::select! {
            () = crate::shutdown::stopped(&mut stop) => break,
            accepted = listener.accept() => match accepted {
                Ok(accepted) => accepted,
                Err(e) => {
                    warn!("web port: {e}");
                    tokio::time::sleep(Duration::from_millis(100)).await;
                    continue;
                }
            },
        };
        match state.guard.connect(peer.ip(), Instant::now()) {
            Ok(conn) => {
                let caller = Caller {
                    peer,
                    permit: Arc::new(conn),
                };
                let (router, state) = (router.clone(), state.clone());
                connections.spawn(async move {
                    let _permit = permit;
                    serve_connection(stream, caller, router, state).await;
                });
            }
            Err(limited) => {
                drop(permit);
                state.refused(peer, limited);
                // Past the answering cap the connection just closes.
                if let Ok(slot) = refusals.clone().try_acquire_owned() {
                    connections.spawn(async move {
                        let _slot = slot;
                        refusal::refuse_connection(stream, limited).await;
                    });
                }
            }
        }
    }
    connections.shutdown().await;
}
