//! The GUI-side network thread: connect, send inputs, receive snapshots
//! and chat, leave on drop.

use std::time::{Duration, Instant};

use ledge_client::net::background::{ConnectRequest, NetEvent, NetOptions, NetStatus, NetThread};
use ledge_shared::input::Buttons;
use ledge_tests::TestServer;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_network_thread_joins_sends_inputs_and_reports_snapshots() {
    let server = TestServer::start_with(|c| c.rooms = 2).await;
    let request = ConnectRequest {
        server: server.addr.to_string(),
        cert_fingerprint: server.fingerprint,
        player_name: "gui".into(),
    };
    let options = NetOptions {
        room: Some("room-2".into()),
        ..NetOptions::default()
    };
    let events = tokio::task::spawn_blocking(move || {
        let net = NetThread::spawn_with(request, options).unwrap();
        let mut status = NetStatus::Connecting("server".into());
        let mut welcome = None;
        let mut snapshots = Vec::new();
        let mut chat = None;
        let deadline = Instant::now() + Duration::from_secs(5);
        let mut chatted = false;
        while Instant::now() < deadline && (snapshots.len() < 20 || chat.is_none()) {
            if let Some(w) = &welcome {
                let w: &ledge_shared::protocol::Welcome = w;
                let tick = w.server_tick + 2 + snapshots.len() as u64;
                assert!(net.send_input(tick, Buttons(Buttons::RIGHT)));
                if !chatted {
                    chatted = net.chat("hi from the gui");
                }
            }
            if let Some(event) = net.recv_timeout(Duration::from_millis(16)) {
                match &event {
                    NetEvent::Connected(w) => welcome = Some(w.clone()),
                    NetEvent::Snapshot(u) => snapshots.push(u.clone()),
                    NetEvent::Chat { text, .. } => chat = Some(text.clone()),
                    NetEvent::Failed(e) | NetEvent::Disconnected(e) => panic!("{e}"),
                    _ => {}
                }
                status.apply(event);
            }
        }
        assert_eq!(net.dropped(), 0);
        (status, welcome, snapshots, chat)
    })
    .await
    .unwrap();
    let (status, welcome, snapshots, chat) = events;
    let welcome = welcome.expect("connected");
    assert_eq!(welcome.room, "room-2");
    assert!(status.to_string().contains("room-2"), "{status}");
    assert!(snapshots.len() >= 20, "{} snapshots", snapshots.len());
    assert_eq!(snapshots[0].baseline_tick, None);
    assert!(snapshots.iter().any(|u| u.baseline_tick.is_some()), "acked");
    assert!(
        snapshots
            .windows(2)
            .all(|w| w[0].state.tick < w[1].state.tick),
        "newer and newer"
    );
    assert!(snapshots.iter().any(|u| u.last_input_tick.is_some()));
    assert_eq!(chat.as_deref(), Some("hi from the gui"));
    server.stop().await.unwrap();
}
