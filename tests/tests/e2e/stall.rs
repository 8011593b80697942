//! A joined window knows within a second when the server goes silent: a
//! GUI front end ([`OnlineGame`]) behind a relay that drops everything says
//! the connection is stalled (not "online" for the 10 s QUIC waits before
//! it gives up), and stops saying so when snapshots come back; after a
//! loss long enough to end the connection it reconnects by itself and gets
//! its player back; when the server restarts it rejoins by itself.

use std::time::{Duration, Instant};

use ledge_client::net::background::NetStatus;
use ledge_client::net::online::STALL_AFTER;
use ledge_client::{OnlineGame, OnlineRequest, Trust};
use ledge_netsim::LinkConfig;
use ledge_server::{Server, ServerConfig};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use ledge_tests::{TestServer, UdpRelay};

/// Runs `online` in 10 ms frames until `done` holds; returns when it did,
/// or panics after `within`.
fn play_until(
    online: &mut OnlineGame,
    what: &str,
    within: Duration,
    done: impl Fn(&OnlineGame, Instant) -> bool,
) -> Instant {
    let deadline = Instant::now() + within;
    loop {
        let now = Instant::now();
        online.update(now, Buttons::NONE);
        if done(online, now) {
            return now;
        }
        assert!(now < deadline, "{what}: status {}", online.status());
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Plays until `online` has joined and is in sync.
fn joined(online: &mut OnlineGame) {
    play_until(online, "joined", Duration::from_secs(10), |o, now| {
        o.game().is_some_and(|g| g.synced()) && o.stalled(now).is_none()
    });
}

/// A server, a relay in front of it, and a GUI front end joined through
/// the relay (on a runtime of the test's own: the front end blocks).
fn join_through_relay() -> (tokio::runtime::Runtime, TestServer, UdpRelay, OnlineGame) {
    let runtime = tokio::runtime::Runtime::new().unwrap();
    let server = runtime.block_on(TestServer::start());
    let relay = runtime.block_on(UdpRelay::start(server.addr));
    let request = OnlineRequest::new(
        &relay.addr.to_string(),
        Trust::Pinned(server.fingerprint),
        "ada",
    );
    let mut online = OnlineGame::connect(request).unwrap();
    joined(&mut online);
    (runtime, server, relay, online)
}

#[test]
fn a_silent_server_is_noticed_within_a_second() {
    let (runtime, server, relay, mut online) = join_through_relay();

    relay.blackhole();
    let cut = Instant::now();
    let noticed = play_until(
        &mut online,
        "stall noticed",
        Duration::from_secs(3),
        |o, now| o.stalled(now).is_some(),
    );
    let after = noticed - cut;
    assert!(after >= STALL_AFTER, "noticed after {after:?}");
    // A frame or two past the threshold, not the 10 s idle timeout.
    assert!(
        after < STALL_AFTER + Duration::from_millis(900),
        "{after:?}"
    );

    relay.restore();
    play_until(
        &mut online,
        "recovered",
        Duration::from_secs(5),
        |o, now| o.stalled(now).is_none(),
    );
    assert!(online.game().is_some(), "still in the game");
    drop(online);
    runtime.block_on(async { server.stop().await.unwrap() });
}

/// Cuts the client off (total loss) until it says it is reconnecting (its
/// connection timed out).
fn cut_off_until_reconnecting(relay: &UdpRelay, online: &mut OnlineGame) {
    relay.blackhole();
    play_until(online, "reconnecting", Duration::from_secs(15), |o, _| {
        matches!(o.status(), NetStatus::Reconnecting { .. })
    });
}

/// Checks that the client is back as player `me`, resumed once; returns the
/// server's metrics.
fn assert_resumed_as(online: &OnlineGame, server: &TestServer, me: PlayerId) -> String {
    assert_eq!(online.game().unwrap().me(), me, "the same player");
    let m = server.metrics();
    assert_eq!(ledge_tests::metric(&m, "ledge_sessions_resumed_total"), 1.0);
    m
}

#[test]
fn a_gui_client_reconnects_by_itself_and_keeps_its_player() {
    let (runtime, server, relay, mut online) = join_through_relay();
    let me = online.game().unwrap().me();

    // 20 s of total loss: both ends time out (10 s) and the client keeps
    // trying; the server keeps the player.
    cut_off_until_reconnecting(&relay, &mut online);
    // The rest of the 20 s (the connection died after about 10 s).
    std::thread::sleep(Duration::from_secs(9));
    relay.restore();
    play_until(&mut online, "back", Duration::from_secs(10), |o, now| {
        matches!(o.status(), NetStatus::Connected { .. })
            && o.game().is_some_and(|g| g.synced())
            && o.stalled(now).is_none()
    });
    assert_resumed_as(&online, &server, me);
    drop(online);
    runtime.block_on(async { server.stop().await.unwrap() });
}

/// A reconnect over a slow link (0.9 s each way): the QUIC handshake fits
/// in one attempt's time (3 s), the welcome does not. An attempt whose
/// hello is out must not be given up: the server has handed it our player
/// by then, and a connection dropped without a `Leave` reads as leaving,
/// so the next attempt would be a new player.
#[test]
fn a_slow_reconnect_keeps_the_player() {
    let (runtime, server, relay, mut online) = join_through_relay();
    let me = online.game().unwrap().me();

    cut_off_until_reconnecting(&relay, &mut online);
    let slow = LinkConfig::delay(Duration::from_millis(900));
    relay.set_links(slow, slow);
    relay.restore();
    play_until(&mut online, "back", Duration::from_secs(20), |o, _| {
        matches!(o.status(), NetStatus::Connected { .. })
    });
    let m = assert_resumed_as(&online, &server, me);
    assert_eq!(
        ledge_tests::metric(&m, "ledge_players{room=\"room-1\"}"),
        1.0,
        "one player"
    );
    drop(online);
    runtime.block_on(async { server.stop().await.unwrap() });
}

#[test]
fn a_gui_client_rejoins_a_restarted_server_by_itself() {
    let runtime = tokio::runtime::Runtime::new().unwrap();
    let certs = tempfile::tempdir().unwrap();
    let config = |bind| ServerConfig {
        bind,
        cert_dir: certs.path().to_owned(),
        ..ServerConfig::default()
    };
    let start = |config: ServerConfig| {
        runtime.block_on(async {
            // The old endpoint's driver may hold the port a moment after
            // the old server stopped: retry, as a host's restart script would.
            let deadline = Instant::now() + Duration::from_secs(5);
            let server = loop {
                match Server::bind(config.clone()) {
                    Ok(server) => break server,
                    Err(e) => assert!(Instant::now() < deadline, "cannot bind again: {e}"),
                }
                tokio::time::sleep(Duration::from_millis(100)).await;
            };
            let info = (
                server.local_addr(),
                server.fingerprint(),
                server.shutdown_handle(),
            );
            (info, tokio::spawn(server.run()))
        })
    };
    let ((addr, fingerprint, stop), task) = start(config("127.0.0.1:0".parse().unwrap()));
    let request = OnlineRequest::new(&addr.to_string(), Trust::Pinned(fingerprint), "ada");
    let mut online = OnlineGame::connect(request).unwrap();
    joined(&mut online);

    // The host restarts the server (same port, same certificate).
    stop.shutdown();
    runtime.block_on(task).unwrap().unwrap();
    play_until(
        &mut online,
        "reconnecting",
        Duration::from_secs(5),
        |o, _| matches!(o.status(), NetStatus::Reconnecting { .. }),
    );
    let ((_, again, stop), task) = start(config(addr));
    assert_eq!(again, fingerprint, "the same certificate");
    play_until(&mut online, "back", Duration::from_secs(15), |o, now| {
        matches!(o.status(), NetStatus::Connected { .. })
            && o.game().is_some_and(|g| g.synced())
            && o.stalled(now).is_none()
    });
    // A restarted server has a fresh game and no sessions: a new player.
    assert!(online.game().is_some());
    drop(online);
    stop.shutdown();
    runtime.block_on(task).unwrap().unwrap();
}
