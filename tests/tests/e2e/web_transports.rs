//! Browsers' transports against the real server on loopback, with native
//! clients of each (`ledge_tests::web`): WebSocket on the web port and
//! WebTransport on UDP join rooms beside native QUIC bots, play, download
//! the level, misbehave, are refused and are shut down like native
//! clients; the web port serves the page, `/web.json` and `/level`.

use std::collections::BTreeSet;
use std::net::SocketAddr;
use std::time::{Duration, Instant};

use ledge_client::{connect_with, InputClock, JoinOptions, Session};
use ledge_server::admission::AdmissionConfig;
use ledge_server::config::WebConfig;
use ledge_server::fingerprint;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{
    ClientControl, CloseCode, InputPacket, Message, NoticeKind, ServerControl, Snapshot,
    StateSnapshot, Welcome, PROTOCOL_VERSION,
};
use ledge_tests::web::{http_get, WebEvent, WsClient, WtClient};
use ledge_tests::{drain, ids, metric, next_snapshot, snapshot_where, TestServer, WAIT};
use tokio_tungstenite::tungstenite::Message as WsMessage;

/// A page directory with an `index.html` and a script.
pub(crate) fn page() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("index.html"), "<h1>ledge</h1>").unwrap();
    std::fs::write(dir.path().join("app.js"), "console.log(1)").unwrap();
    dir
}

/// A server with the web port (and WebTransport) on loopback, serving
/// `root`.
pub(crate) async fn web_server(
    root: &std::path::Path,
    adjust: impl FnOnce(&mut ledge_server::ServerConfig),
) -> TestServer {
    let root = root.to_owned();
    TestServer::start_with(move |c| {
        let mut web = WebConfig::new(SocketAddr::from(([127, 0, 0, 1], 0)));
        web.root = root;
        c.web = Some(web);
        adjust(c);
    })
    .await
}

fn hex(h: &[u8; 32]) -> String {
    h.iter().map(|b| format!("{b:02x}")).collect()
}

/// `/web.json`, parsed.
async fn web_json(server: &TestServer) -> serde_json::Value {
    let answer = http_get(server.web_addr.unwrap(), "/web.json").await;
    assert_eq!(answer.status, 200, "{}", answer.head);
    assert_eq!(answer.header("content-type"), Some("application/json"));
    serde_json::from_slice(&answer.body).expect("valid JSON")
}

/// The certificate hashes `/web.json` lists.
async fn cert_hashes(server: &TestServer) -> Vec<[u8; 32]> {
    let doc = web_json(server).await;
    doc["webtransport"]["cert_sha256"]
        .as_array()
        .expect("a list of hashes")
        .iter()
        .map(|h| {
            let h = h.as_str().unwrap();
            assert_eq!(h.len(), 64);
            assert!(h
                .chars()
                .all(|c| c.is_ascii_digit() || ('a'..='f').contains(&c)));
            let mut out = [0u8; 32];
            for (i, byte) in out.iter_mut().enumerate() {
                *byte = u8::from_str_radix(&h[2 * i..2 * i + 2], 16).unwrap();
            }
            out
        })
        .collect()
}

/// Either web client.
enum Web {
    Ws(WsClient),
    Wt(WtClient),
}

impl Web {
    async fn send_control(&mut self, m: &ClientControl) {
        match self {
            Web::Ws(c) => c.send_control(m).await,
            Web::Wt(c) => c.send_control(m).await,
        }
    }

    async fn send_datagram(&mut self, d: &[u8]) -> bool {
        match self {
            Web::Ws(c) => c.send_datagram(d).await,
            Web::Wt(c) => c.send_datagram(d),
        }
    }

    async fn next(&mut self, within: Duration) -> Option<WebEvent> {
        match self {
            Web::Ws(c) => c.next(within).await,
            Web::Wt(c) => c.next(within).await,
        }
    }

    /// Sends a hello for `room` and returns the `Welcome`.
    async fn join(&mut self, name: &str, room: &str) -> Welcome {
        self.send_control(&ClientControl::HelloRoom {
            version: PROTOCOL_VERSION,
            name: name.into(),
            room: room.into(),
        })
        .await;
        match self.next(WAIT).await {
            Some(WebEvent::Control(ServerControl::Welcome(w))) => w,
            other => panic!("{name} expected a Welcome, got {other:?}"),
        }
    }

    /// Events until `within` passes or the session closes.
    async fn drain(&mut self, within: Duration) -> Vec<WebEvent> {
        let deadline = Instant::now() + within;
        let mut events = Vec::new();
        while let Some(e) = self
            .next(deadline.saturating_duration_since(Instant::now()))
            .await
        {
            let closed = matches!(e, WebEvent::Closed(..));
            events.push(e);
            if closed {
                break;
            }
        }
        events
    }
}

async fn bot(server: &TestServer, name: &str, room: &str) -> Session {
    let options = JoinOptions {
        player_name: name.into(),
        room: Some(room.into()),
        resume: None,
        spectate: false,
    };
    connect_with(server.addr, "localhost", server.fingerprint, &options)
        .await
        .expect("the bot joins")
}

/// The body ids that appear in `bot`'s snapshots after `tick`.
async fn new_body(bot: &mut Session, known: &BTreeSet<u32>, tick: u64) -> BTreeSet<u32> {
    let with = snapshot_where(bot, WAIT, |s| s.tick > tick + 2).await;
    let body: BTreeSet<u32> = ids(&with).difference(known).copied().collect();
    assert!(!body.is_empty(), "a new body appeared");
    body
}

fn x_of(body: &BTreeSet<u32>, s: &StateSnapshot) -> i64 {
    body.iter()
        .filter_map(|&id| s.get(id))
        .map(|e| i64::from(e.pos.x))
        .sum()
}

#[tokio::test]
async fn browsers_play_beside_a_native_bot_over_websocket_and_webtransport() {
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    let mut native = bot(&server, "native", "friends").await;
    let (first, _) = next_snapshot(&mut native, WAIT).await;
    let mut known = ids(&first.state);

    let mut ws = Web::Ws(WsClient::connect(server.web_addr.unwrap()).await.unwrap());
    let ws_welcome = ws.join("webby", "friends").await;
    let ws_clock = InputClock::new(&ws_welcome, Instant::now());
    assert_eq!(ws_welcome.room, "friends");
    let ws_body = new_body(&mut native, &known, ws_welcome.server_tick).await;
    known.extend(&ws_body);

    let hashes = cert_hashes(&server).await;
    let wt_addr = server.webtransport_addr.unwrap();
    assert_eq!(wt_addr.port(), server.web_addr.unwrap().port(), "same port");
    let mut wt = Web::Wt(WtClient::connect(wt_addr, "/ledge", &hashes).await.unwrap());
    let wt_welcome = wt.join("transporty", "friends").await;
    let wt_clock = InputClock::new(&wt_welcome, Instant::now());
    assert_eq!(wt_welcome.room, "friends");
    let wt_body = new_body(&mut native, &known, wt_welcome.server_tick).await;

    let start = snapshot_where(&mut native, WAIT, |_| true).await;
    let (ws_start, wt_start) = (x_of(&ws_body, &start), x_of(&wt_body, &start));

    // Both hold right for about a second, one input per tick.
    let right = [Buttons(Buttons::RIGHT); 4];
    let mut applied = [None, None];
    let until = Instant::now() + Duration::from_millis(1000);
    while Instant::now() < until {
        let now = Instant::now();
        for (client, clock) in [(&mut ws, &ws_clock), (&mut wt, &wt_clock)] {
            let packet = InputPacket::new(clock.input_tick(now), &right, None);
            assert!(client.send_datagram(&packet.encode().unwrap()).await);
        }
        for (i, client) in [&mut ws, &mut wt].into_iter().enumerate() {
            for event in client.drain(Duration::from_millis(4)).await {
                if let WebEvent::Datagram(d) = event {
                    // No acknowledgement sent: every snapshot is full.
                    let snapshot = Snapshot::decode(&d).expect("a snapshot datagram");
                    snapshot.decode_state(None).expect("decodes");
                    applied[i] = snapshot.last_input_tick.or(applied[i]);
                }
            }
        }
        drain(&mut native, Duration::ZERO).await;
    }
    let last = snapshot_where(&mut native, WAIT, |s| s.tick > start.tick + 30).await;
    let ws_moved = x_of(&ws_body, &last) - ws_start;
    let wt_moved = x_of(&wt_body, &last) - wt_start;
    assert!(
        ws_moved >= 4 * 256,
        "the WebSocket player moved {ws_moved} units"
    );
    assert!(
        wt_moved >= 4 * 256,
        "the WebTransport player moved {wt_moved} units"
    );
    assert!(applied[0].is_some() && applied[1].is_some(), "{applied:?}");
    // The native client's roster lists both browsers.
    let listed: BTreeSet<String> = native.players().values().cloned().collect();
    assert!(
        listed.contains("webby") && listed.contains("transporty"),
        "{listed:?}"
    );
    let m = server.metrics();
    for transport in ["quic", "webtransport", "websocket"] {
        let series = format!("ledge_transport_connections{{transport=\"{transport}\"}}");
        assert_eq!(metric(&m, &series), 1.0, "{series} in\n{m}");
    }
    server.stop().await.unwrap();
}

#[tokio::test]
async fn the_level_downloads_over_both_web_transports_and_http() {
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    let offer = server.level_offer;
    let check = |bytes: &[u8], how: &str| {
        assert_eq!(bytes.len() as u64, offer.size, "{how}");
        assert_eq!(fingerprint::of_der(bytes).0, offer.sha256, "{how}");
    };
    let mut ws = Web::Ws(WsClient::connect(server.web_addr.unwrap()).await.unwrap());
    let welcome = ws.join("ws-level", "room-1").await;
    assert_eq!(welcome.level, offer);
    ws.send_control(&ClientControl::GetLevel {
        offset: 0,
        sha256: offer.sha256,
    })
    .await;
    let level = loop {
        match ws.next(WAIT).await.expect("the level in time") {
            WebEvent::Level(bytes) => break bytes,
            WebEvent::Closed(..) => panic!("closed"),
            _ => {}
        }
    };
    check(&level, "WebSocket");
    // Resumed from an offset: the rest.
    ws.send_control(&ClientControl::GetLevel {
        offset: 10,
        sha256: offer.sha256,
    })
    .await;
    let rest = loop {
        match ws.next(WAIT).await.expect("the rest in time") {
            WebEvent::Level(bytes) => break bytes,
            WebEvent::Closed(..) => panic!("closed"),
            _ => {}
        }
    };
    assert_eq!(rest, level[10..]);

    let hashes = cert_hashes(&server).await;
    let mut wt = Web::Wt(
        WtClient::connect(server.webtransport_addr.unwrap(), "/ledge", &hashes)
            .await
            .unwrap(),
    );
    wt.join("wt-level", "room-1").await;
    wt.send_control(&ClientControl::GetLevel {
        offset: 0,
        sha256: offer.sha256,
    })
    .await;
    let level = loop {
        match wt.next(WAIT).await.expect("the level in time") {
            WebEvent::Level(bytes) => break bytes,
            WebEvent::Closed(..) => panic!("closed"),
            _ => {}
        }
    };
    check(&level, "WebTransport");

    let answer = http_get(server.web_addr.unwrap(), "/level").await;
    assert_eq!(answer.status, 200);
    assert_eq!(
        answer.header("content-type"),
        Some("application/octet-stream")
    );
    check(&answer.body, "GET /level");
    let m = server.metrics();
    assert_eq!(metric(&m, "ledge_level_downloads_completed_total"), 3.0);
    server.stop().await.unwrap();
}

#[tokio::test]
async fn malformed_websocket_messages_are_counted_and_a_client_that_keeps_sending_them_is_kicked() {
    let root = page();
    let server = web_server(root.path(), |c| {
        c.limits.malformed_burst = 6.0;
        c.limits.malformed_per_second = 0.0;
    })
    .await;
    let addr = server.web_addr.unwrap();
    // Before the hello, a malformed message closes at once.
    let mut early = WsClient::connect(addr).await.unwrap();
    assert!(early.send_raw(WsMessage::Text("not a hello".into())).await);
    match early.next(WAIT).await {
        Some(WebEvent::Closed(code, raw, _)) => {
            assert_eq!((code, raw), (Some(CloseCode::ProtocolViolation), 4001));
        }
        other => panic!("closed, not {other:?}"),
    }
    let mut client = Web::Ws(WsClient::connect(addr).await.unwrap());
    client.join("sloppy", "room-1").await;
    let Web::Ws(sloppy) = &mut client else {
        unreachable!()
    };
    let bad = [
        WsMessage::Text("hello".into()),
        WsMessage::Binary(Vec::new()),
        WsMessage::Binary(vec![0x09, 1, 2]),
        WsMessage::Binary(vec![0x02, 1, 2]),
        WsMessage::Binary(vec![0x03]),
    ];
    for m in bad {
        assert!(sloppy.send_raw(m).await);
    }
    // Still served: a ping is answered.
    sloppy.send_control(&ClientControl::Ping { nonce: 7 }).await;
    let events = client.drain(Duration::from_millis(500)).await;
    assert!(
        events
            .iter()
            .any(|e| matches!(e, WebEvent::Control(ServerControl::Pong { nonce: 7 }))),
        "{events:?}"
    );
    let m = server.metrics();
    assert_eq!(
        metric(&m, "ledge_malformed_messages_total{channel=\"WebSocket\"}"),
        6.0,
        "{m}"
    );
    // Two more strikes empty the bucket: a kick notice, then the close.
    let Web::Ws(sloppy) = &mut client else {
        unreachable!()
    };
    for _ in 0..2 {
        sloppy.send_raw(WsMessage::Binary(vec![0xff])).await;
    }
    let events = client.drain(WAIT).await;
    assert!(
        events.iter().any(|e| matches!(
            e,
            WebEvent::Control(ServerControl::Notice {
                kind: NoticeKind::Kick { .. }
            })
        )),
        "{events:?}"
    );
    match events.last() {
        Some(WebEvent::Closed(code, raw, _)) => {
            assert_eq!(*code, Some(CloseCode::ProtocolViolation));
            assert_eq!(*raw, 4001);
        }
        other => panic!("closed, not {other:?}"),
    }
    let m = server.metrics();
    assert_eq!(metric(&m, "ledge_kicks_total{reason=\"Malformed\"}"), 1.0);

    // A message over the 4 KiB limit: counted, closed at once.
    let mut big = Web::Ws(WsClient::connect(addr).await.unwrap());
    big.join("big", "room-1").await;
    let Web::Ws(c) = &mut big else { unreachable!() };
    c.send_raw(WsMessage::Binary(vec![0; 5000])).await;
    let events = big.drain(WAIT).await;
    assert!(
        matches!(
            events.last(),
            Some(WebEvent::Closed(
                Some(CloseCode::ProtocolViolation),
                4001,
                _
            ))
        ),
        "{events:?}"
    );
    let m = server.metrics();
    assert_eq!(
        metric(&m, "ledge_malformed_messages_total{channel=\"WebSocket\"}"),
        9.0,
        "{m}"
    );
    server.stop().await.unwrap();
}

#[tokio::test]
async fn the_fifth_connection_from_one_address_is_refused_over_websocket_and_webtransport() {
    let root = page();
    let server = web_server(root.path(), |c| {
        c.admission = AdmissionConfig::default();
    })
    .await;
    let addr = server.web_addr.unwrap();
    let mut open = Vec::new();
    for i in 0..4 {
        let mut c = Web::Ws(WsClient::connect(addr).await.expect("admitted"));
        c.join(&format!("p{i}"), "room-1").await;
        open.push(c);
    }
    let refused = WsClient::connect(addr).await.err().expect("refused");
    assert_eq!(refused.status, Some(429), "{}", refused.error);
    let m = server.metrics();
    assert_eq!(
        metric(
            &m,
            "ledge_connections_refused_total{reason=\"AddressConnections\"}"
        ),
        1.0
    );
    assert_eq!(
        metric(
            &m,
            "ledge_transport_connections_refused_total{transport=\"websocket\",reason=\"AddressConnections\"}"
        ),
        1.0,
        "{m}"
    );
    // WebTransport counts against the same address.
    let hashes = cert_hashes(&server).await;
    let wt = WtClient::connect(server.webtransport_addr.unwrap(), "/ledge", &hashes).await;
    assert!(wt.is_err(), "refused at its first packet");
    let m = server.metrics();
    assert_eq!(
        metric(
            &m,
            "ledge_transport_connections_refused_total{transport=\"webtransport\",reason=\"AddressConnections\"}"
        ),
        1.0,
        "{m}"
    );
    assert_eq!(
        metric(
            &m,
            "ledge_connections_refused_total{reason=\"AddressConnections\"}"
        ),
        2.0
    );
    // One leaves: a place again.
    drop(open.pop());
    let deadline = Instant::now() + WAIT;
    loop {
        match WsClient::connect(addr).await {
            Ok(_) => break,
            Err(e) if Instant::now() < deadline => {
                assert_eq!(e.status, Some(429));
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
            Err(e) => panic!("no place after one left: {}", e.error),
        }
    }
    server.stop().await.unwrap();
}

#[tokio::test]
async fn the_web_port_serves_the_page_web_json_and_the_level() {
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    let addr = server.web_addr.unwrap();
    let index = http_get(addr, "/").await;
    assert_eq!(index.status, 200);
    assert_eq!(index.body, b"<h1>ledge</h1>");
    assert_eq!(
        index.header("content-type"),
        Some("text/html; charset=utf-8")
    );
    assert_eq!(index.header("cache-control"), Some("no-cache"));
    let js = http_get(addr, "/app.js").await;
    assert_eq!(js.status, 200);
    assert!(js
        .header("content-type")
        .unwrap()
        .starts_with("text/javascript"));
    for path in ["/nope.js", "/../Cargo.toml", "/index.html/x", "/ws/x"] {
        assert_eq!(http_get(addr, path).await.status, 404, "{path}");
    }
    // A plain GET of /ws is not an upgrade.
    assert_ne!(http_get(addr, "/ws").await.status, 200);
    // A request head over the server's buffer is refused, not buffered.
    let huge = format!("/{}", "a".repeat(32 * 1024));
    let refused = huge_request(addr, &huge).await;
    assert!(
        refused.as_deref().is_none_or(|head| head.contains(" 431 ")),
        "{refused:?}"
    );
    assert_eq!(http_get(addr, "/").await.status, 200, "still serving");

    let doc = web_json(&server).await;
    assert_eq!(doc["protocol"], PROTOCOL_VERSION);
    assert_eq!(doc["websocket"], "/ws");
    assert_eq!(doc["level"], server.level_offer.hex());
    let wt = &doc["webtransport"];
    assert_eq!(wt["port"], server.webtransport_addr.unwrap().port());
    assert_eq!(wt["path"], "/ledge");
    let hashes = cert_hashes(&server).await;
    let client = WtClient::connect(server.webtransport_addr.unwrap(), "/ledge", &hashes)
        .await
        .expect("the certificate is one /web.json lists");
    assert_eq!(hex(&client.server_cert_sha256()), wt["cert_sha256"][0]);
    // The certificate is what browsers take: the client checks it as they
    // do (ECDSA P-256, at most two weeks). Another path is refused.
    assert!(
        WtClient::connect(server.webtransport_addr.unwrap(), "/other", &hashes)
            .await
            .is_err()
    );
    // A wrong hash is refused.
    assert!(
        WtClient::connect(server.webtransport_addr.unwrap(), "/ledge", &[[0; 32]])
            .await
            .is_err()
    );
    server.stop().await.unwrap();
}

/// Sends `GET path` and returns the answer's head, if any came.
async fn huge_request(addr: SocketAddr, path: &str) -> Option<String> {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let mut stream = tokio::net::TcpStream::connect(addr).await.unwrap();
    let request = format!("GET {path} HTTP/1.1\r\nHost: localhost\r\n\r\n");
    let _ = stream.write_all(request.as_bytes()).await;
    let mut answer = Vec::new();
    let read = tokio::time::timeout(WAIT, stream.read_to_end(&mut answer)).await;
    assert!(read.is_ok(), "answered or closed in time");
    let text = String::from_utf8_lossy(&answer).into_owned();
    (!text.is_empty()).then_some(text)
}

#[tokio::test]
async fn a_server_without_its_page_says_what_to_build_and_still_plays() {
    let dir = tempfile::tempdir().unwrap();
    let server = web_server(&dir.path().join("dist"), |c| {
        c.web.as_mut().unwrap().webtransport = None;
    })
    .await;
    let addr = server.web_addr.unwrap();
    let index = http_get(addr, "/").await;
    assert_eq!(index.status, 503);
    let text = String::from_utf8(index.body.clone()).unwrap();
    assert!(text.contains("scripts/build-web"), "{text}");
    assert!(index
        .header("content-type")
        .unwrap()
        .starts_with("text/plain"));
    let doc = web_json(&server).await;
    assert!(doc["webtransport"].is_null(), "{doc}");
    assert_eq!(server.webtransport_addr, None);
    let mut ws = Web::Ws(WsClient::connect(addr).await.unwrap());
    ws.join("no-page", "room-1").await;
    server.stop().await.unwrap();
}

#[tokio::test]
async fn shutdown_closes_web_sessions_like_native_ones() {
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    let mut ws = Web::Ws(WsClient::connect(server.web_addr.unwrap()).await.unwrap());
    ws.join("ws-stays", "room-1").await;
    let hashes = cert_hashes(&server).await;
    let mut wt = Web::Wt(
        WtClient::connect(server.webtransport_addr.unwrap(), "/ledge", &hashes)
            .await
            .unwrap(),
    );
    wt.join("wt-stays", "room-1").await;
    // Keep them from being idle: one input each.
    let packet = InputPacket::new(1, &[Buttons::NONE], None)
        .encode()
        .unwrap();
    ws.send_datagram(&packet).await;
    wt.send_datagram(&packet).await;
    server.begin_shutdown();
    // Both read at once, as two browsers would: a QUIC client that reads
    // only after the close has lost what it had not read.
    let (ws_events, wt_events) = tokio::join!(
        ws.drain(Duration::from_secs(5)),
        wt.drain(Duration::from_secs(5))
    );
    for (name, events) in [("WebSocket", ws_events), ("WebTransport", wt_events)] {
        assert!(
            events.iter().any(|e| matches!(
                e,
                WebEvent::Control(ServerControl::Notice {
                    kind: NoticeKind::Shutdown
                })
            )),
            "{name}: {events:?}"
        );
        match events.last() {
            Some(WebEvent::Closed(code, raw, _)) => {
                assert_eq!(*code, Some(CloseCode::ServerShutdown), "{name}");
                let expected = if name == "WebSocket" { 4004 } else { 4 };
                assert_eq!(*raw, expected, "{name}");
            }
            other => panic!("{name}: closed, not {other:?}"),
        }
    }
    let web = server.web_addr.unwrap();
    server.stop().await.unwrap();
    // The web port is closed too.
    assert!(tokio::net::TcpStream::connect(web).await.is_err());
}

#[tokio::test]
async fn a_silent_websocket_gets_the_hello_timeout() {
    let root = page();
    let server = web_server(root.path(), |c| {
        c.admission.hello_timeout = Duration::from_millis(300);
    })
    .await;
    let mut silent = WsClient::connect(server.web_addr.unwrap()).await.unwrap();
    match silent.next(WAIT).await {
        Some(WebEvent::Closed(code, raw, _)) => {
            assert_eq!((code, raw), (Some(CloseCode::Timeout), 4003));
        }
        other => panic!("closed, not {other:?}"),
    }
    let m = server.metrics();
    assert_eq!(
        metric(
            &m,
            "ledge_transport_connections_refused_total{transport=\"websocket\",reason=\"HelloTimeout\"}"
        ),
        1.0,
        "{m}"
    );
    server.stop().await.unwrap();
}

#[tokio::test]
async fn a_lost_websocket_session_is_resumed_with_its_token() {
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    let addr = server.web_addr.unwrap();
    let mut first = Web::Ws(WsClient::connect(addr).await.unwrap());
    let welcome = first.join("wanderer", "room-1").await;
    // Gone without a close frame (a dropped network, not a left page).
    drop(first);
    let mut again = Web::Ws(WsClient::connect(addr).await.unwrap());
    again
        .send_control(&ClientControl::Resume {
            version: PROTOCOL_VERSION,
            name: "wanderer".into(),
            room: Some("room-1".into()),
            token: welcome.session_token,
        })
        .await;
    let resumed = match again.next(WAIT).await {
        Some(WebEvent::Control(ServerControl::Welcome(w))) => w,
        other => panic!("a Welcome, not {other:?}"),
    };
    assert_eq!(resumed.player_id, welcome.player_id, "the same player");
    let m = server.metrics();
    assert_eq!(metric(&m, "ledge_sessions_resumed_total"), 1.0, "{m}");
    server.stop().await.unwrap();
}

/// The WebTransport certificate's rotation on the live endpoint, with its
/// life shortened to 8 s (made at 40 % = 3.2 s and listed in /web.json,
/// served to new sessions from 50 % = 4 s): a session from before the
/// switch goes on with the old certificate, a page that fetched /web.json
/// before the switch already knows the new one, and a new session gets it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_webtransport_certificate_is_replaced_before_it_expires_and_sessions_go_on() {
    let root = page();
    let server = TestServer::start_with({
        let root = root.path().to_owned();
        move |c| {
            let mut web = WebConfig::new(SocketAddr::from(([127, 0, 0, 1], 0)));
            web.root = root;
            web.cert_life = ledge_server::web::webtransport_cert::CertLife {
                validity: Duration::from_secs(8),
                backdate: Duration::ZERO,
            };
            c.web = Some(web);
        }
    })
    .await;
    let wt_addr = server.webtransport_addr.unwrap();
    let first = cert_hashes(&server).await;
    assert_eq!(first.len(), 1, "one certificate at first");
    let mut old = Web::Wt(WtClient::connect(wt_addr, "/ledge", &first).await.unwrap());
    let Web::Wt(c) = &old else { unreachable!() };
    assert_eq!(c.server_cert_sha256(), first[0]);
    old.join("early", "room-1").await;

    // Between 40 % and 50 %: the next one is listed, after the current.
    let started = Instant::now();
    let listed = loop {
        let hashes = cert_hashes(&server).await;
        if hashes.len() == 2 {
            break hashes;
        }
        assert!(
            started.elapsed() < Duration::from_secs(6),
            "the next certificate was listed by 40 % of the life: {hashes:02x?}"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    assert_eq!(listed[0], first[0], "the current one first");
    let next = listed[1];
    assert_ne!(next, first[0]);

    // After 50 %: new sessions get the next one, which a page holding the
    // earlier /web.json list already trusts.
    let started = Instant::now();
    loop {
        let hashes = cert_hashes(&server).await;
        if hashes[0] == next {
            break;
        }
        assert!(
            started.elapsed() < Duration::from_secs(6),
            "the next certificate was served by 50 % of the life"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    let mut late = Web::Wt(WtClient::connect(wt_addr, "/ledge", &listed).await.unwrap());
    let Web::Wt(c) = &late else { unreachable!() };
    assert_eq!(
        c.server_cert_sha256(),
        next,
        "a new session gets the next one"
    );
    late.join("late", "room-1").await;
    let refused = WtClient::connect(wt_addr, "/ledge", &first).await;
    assert!(
        refused.is_err(),
        "only the old hash: the new certificate is refused, as a browser would"
    );

    // The session from before the switch is still served.
    let snapshots = old
        .drain(Duration::from_millis(500))
        .await
        .into_iter()
        .filter(|e| matches!(e, WebEvent::Datagram(_)))
        .count();
    assert!(
        snapshots > 5,
        "the early session still gets snapshots: {snapshots}"
    );
    server.stop().await.unwrap();
}
