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
//! [`REQUEST_TIMEOUT`], a request head arriving within [`HEADER_TIMEOUT`];
//! a WebSocket is bounded by its own limits
//! ([`crate::link::websocket`]).

pub mod files;
pub mod webtransport_cert;
pub mod webtransport_endpoint;

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::{Duration, Instant};

use axum::extract::ws::WebSocketUpgrade;
use axum::extract::{ConnectInfo, Request, State};
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
use crate::shared::Shared;
use files::WebRoot;
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
}

/// The routes.
fn router(state: Arc<WebState>) -> Router {
    Router::new()
        .route("/", get(index))
        .route("/web.json", get(web_json_route))
        .route("/level", get(level))
        .route("/ws", get(websocket))
        .fallback(file)
        .with_state(state)
}

/// A response with a body, its type, and no caching (the page changes
/// with the server).
fn answer(status: StatusCode, content_type: &str, body: impl Into<axum::body::Body>) -> Response {
    let mut response = Response::new(body.into());
    *response.status_mut() = status;
    let headers = response.headers_mut();
    if let Ok(value) = content_type.parse() {
        headers.insert(header::CONTENT_TYPE, value);
    }
    headers.insert(
        header::CACHE_CONTROL,
        header::HeaderValue::from_static("no-cache"),
    );
    response
}

fn text(status: StatusCode, body: String) -> Response {
    answer(status, "text/plain; charset=utf-8", body)
}

async fn index(State(state): State<Arc<WebState>>) -> Response {
    if let Some(missing) = state.root.missing() {
        return text(StatusCode::SERVICE_UNAVAILABLE, format!("{missing}\n"));
    }
    file_response(&state, "index.html")
}

async fn file(State(state): State<Arc<WebState>>, request: Request) -> Response {
    let path = request.uri().path();
    let name = path.strip_prefix('/').unwrap_or(path);
    if request.method() != axum::http::Method::GET && request.method() != axum::http::Method::HEAD {
        return text(StatusCode::METHOD_NOT_ALLOWED, "GET only\n".into());
    }
    file_response(&state, name)
}

fn file_response(state: &WebState, name: &str) -> Response {
    match state.root.get(name) {
        Some(f) => answer(StatusCode::OK, f.content_type, f.body.clone()),
        None => text(StatusCode::NOT_FOUND, "not found\n".into()),
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

async fn level(State(state): State<Arc<WebState>>) -> Response {
    answer(
        StatusCode::OK,
        "application/octet-stream",
        state.level.clone(),
    )
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

/// Serves the web port until `stop`.
pub async fn serve(listener: TcpListener, state: Arc<WebState>, mut stop: watch::Receiver<bool>) {
    let router = router(state);
    let slots = Arc::new(Semaphore::new(MAX_HTTP_CONNECTIONS));
    let mut connections = JoinSet::new();
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
        let router = router.clone();
        connections.spawn(async move {
            let _permit = permit;
            let service =
                hyper::service::service_fn(move |mut request: Request<hyper::body::Incoming>| {
                    request.extensions_mut().insert(ConnectInfo(peer));
                    let mut router = router.clone();
                    async move { tower_service::Service::call(&mut router, request).await }
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
        });
    }
    connections.shutdown().await;
}
