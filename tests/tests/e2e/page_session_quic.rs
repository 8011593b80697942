//! The browser page's session
//! ([`ledge_client::net::page_session::PageSession`], sans IO) against a
//! real server, carried over native QUIC: a small driver gives
//! it the control stream's bytes, the datagrams and the level stream, the
//! way the page's glue gives it WebTransport's. It downloads a real Tiled
//! map's level (Sticker Knight, with its images) byte for byte, is
//! welcomed in its room, sees a native player there, and its inputs move
//! its player on the server.

use std::time::Duration;

use ledge_client::net::page_session::{Incoming, PageSession, Transmit};
use ledge_client::net::transport::{dial, Dialed};
use ledge_client::net::{NetEvent, Network};
use ledge_client::JoinOptions;
use ledge_levels::bundle::sha256;
use ledge_shared::input::Buttons;
use ledge_tests::{corpus_file, TestServer};
use quinn::{RecvStream, SendStream};
use tokio::time::Instant;

/// Tiled's platformer example map (images beside it).
const STICKER_KNIGHT: &str = "tiled-examples/sticker-knight/map/sandbox2.tmx";

/// Runs `session` over `dialed` until `done` says so (or 20 s pass): writes
/// its transmits, feeds it what arrives, polls it every 16 ms, giving it
/// `buttons` for each tick (`next_tick`, set from the first snapshot
/// on).
async fn drive(
    session: &mut PageSession,
    dialed: &Dialed,
    send: &mut SendStream,
    recv: &mut RecvStream,
    mut on_event: impl FnMut(&NetEvent) -> bool,
    buttons: Buttons,
    next_tick: &mut Option<u64>,
) -> Vec<NetEvent> {
    let connection = &dialed.connection;
    let (level_tx, mut level_rx) = tokio::sync::mpsc::channel::<Option<Vec<u8>>>(64);
    let mut buf = vec![0u8; 8192];
    let mut events = Vec::new();
    let mut ticker = tokio::time::interval(Duration::from_millis(16));
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        while let Some(t) = session.poll_transmit() {
            match t {
                Transmit::Stream(b) => send.write_all(&b).await.expect("stream write"),
                Transmit::Datagram(d) => {
                    let _ = connection.send_datagram(d.into());
                }
            }
        }
        while let Some(event) = session.try_recv() {
            let stop = on_event(&event);
            // Inputs a little ahead of the server's newest tick (the
            // level's download took a while since the welcome).
            if let (NetEvent::Snapshot(update), None) = (&event, &next_tick) {
                *next_tick = Some(update.state.tick + 6);
            }
            events.push(event);
            if stop {
                return events;
            }
        }
        if Instant::now() >= deadline {
            let kinds: Vec<String> = events
                .iter()
                .map(|e| match e {
                    NetEvent::Snapshot(u) => format!("Snapshot({})", u.state.tick),
                    NetEvent::Level(b, _) => format!("Level({})", b.level.name),
                    other => format!("{other:?}").chars().take(80).collect(),
                })
                .collect();
            panic!("gave up waiting; events: {kinds:?}");
        }
        let now = ledge_client::time::Instant::now;
        tokio::select! {
            read = recv.read(&mut buf) => match read.expect("control stream") {
                Some(n) => session.on_message(Incoming::Stream(&buf[..n]), now()),
                None => session.on_closed(None, "stream finished"),
            },
            datagram = connection.read_datagram() => {
                let d = datagram.expect("connection open");
                session.on_message(Incoming::Datagram(&d), now());
            }
            uni = connection.accept_uni() => {
                let mut stream = uni.expect("level stream");
                let tx = level_tx.clone();
                tokio::spawn(async move {
                    let mut chunk = vec![0u8; 16 * 1024];
                    while let Ok(Some(n)) = stream.read(&mut chunk).await {
                        let _ = tx.send(Some(chunk[..n].to_vec())).await;
                    }
                    let _ = tx.send(None).await;
                });
            }
            Some(piece) = level_rx.recv() => match piece {
                Some(bytes) => session.on_message(Incoming::Level(&bytes), now()),
                None => session.on_message(Incoming::LevelEnd, now()),
            },
            _ = ticker.tick() => {
                session.poll(now());
                if let Some(tick) = next_tick.as_mut() {
                    session.send_input(*tick, buttons);
                    *tick += 1;
                }
            }
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_browser_protocol_downloads_a_real_level_joins_and_moves() {
    let Some(map) = corpus_file(STICKER_KNIGHT) else {
        return;
    };
    let server = TestServer::start_with(move |c| c.levels = vec![map]).await;
    // A native player in the room first.
    let native = ledge_client::connect_with(
        server.addr,
        "localhost",
        server.fingerprint,
        &JoinOptions {
            room: Some("friends".into()),
            ..JoinOptions::new("bob")
        },
    )
    .await
    .expect("bob joins");
    let server_offer = native.welcome().level;

    let dialed = dial(server.addr, "localhost", server.fingerprint)
        .await
        .expect("dial");
    let (mut send, mut recv) = dialed.connection.open_bi().await.expect("bi stream");
    let mut session = PageSession::new(JoinOptions {
        room: Some("friends".into()),
        ..JoinOptions::new("ada")
    });
    assert!(session.poll_transmit().is_none(), "nothing before the open");
    session.on_open(ledge_client::time::Instant::now());

    let mut next_tick = None;
    // Joined: the level first (downloaded, checked), then the welcome,
    // then bob in the roster.
    let events = drive(
        &mut session,
        &dialed,
        &mut send,
        &mut recv,
        |e| matches!(e, NetEvent::PlayerJoined { name, .. } if name == "bob"),
        Buttons::NONE,
        &mut next_tick,
    )
    .await;
    let level_at = events
        .iter()
        .position(|e| matches!(e, NetEvent::Level(..)))
        .expect("the level arrived");
    let NetEvent::Level(bundle, fetched) = &events[level_at] else {
        unreachable!()
    };
    assert_eq!(
        sha256(&bundle.encode()),
        server_offer.sha256,
        "the downloaded level is the server's, byte for byte"
    );
    assert_eq!(fetched.downloaded, server_offer.size);
    assert!(
        !bundle.art.images.is_empty(),
        "Sticker Knight's images came too"
    );
    assert!(
        events[..level_at]
            .iter()
            .any(|e| matches!(e, NetEvent::LevelProgress { got, total } if got == total)),
        "progress up to the whole level"
    );
    let NetEvent::Connected(welcome) = &events[level_at + 1] else {
        panic!("the welcome follows the level: {events:?}")
    };
    assert_eq!(welcome.room, "friends");
    let me = welcome.player_id;

    // Holding right for a second moves us on the server.
    let first_x = std::cell::Cell::new(None::<i32>);
    let moved = std::cell::Cell::new(0i32);
    drive(
        &mut session,
        &dialed,
        &mut send,
        &mut recv,
        |e| {
            if let NetEvent::Snapshot(update) = e {
                if let Some(p) = update.state.get(me.0) {
                    let x0 = first_x.get().unwrap_or(p.pos.x);
                    first_x.set(Some(x0));
                    moved.set(p.pos.x - x0);
                }
            }
            // 16 px to the right, as the server says.
            moved.get() > 16 * ledge_shared::fixed::UNITS_PER_PX
        },
        Buttons(Buttons::RIGHT),
        &mut next_tick,
    )
    .await;
    assert!(session.transport().unwrap().bytes_in > server_offer.size);
    assert!(session.players().values().any(|n| n == "ada"));
    assert!(!session.is_ended());
    drop(native);
}
