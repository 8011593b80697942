//! The server under Agones (`--agones`), without a cluster: the real
//! server in-process, its SDK driver talking gRPC to a fake sidecar
//! (`ledge-agones-fake`: the SDK's own protocol definitions served with
//! tonic) that records every call with its time, and real players over
//! QUIC.
//!
//! The sidecar and the driver each run on a thread of their own; the
//! server's rooms run on this test's single worker thread, so blocking it
//! is a stuck tick loop.

use std::time::{Duration, Instant};

use ledge_agones_fake::{Call, FakeSidecar};
use ledge_client::{connect_with, JoinOptions, Session};
use ledge_server::fleet::{FleetConfig, CERT_ANNOTATION, FULL_LABEL, PLAYERS, ROOMS};
use ledge_server::{Server, ServerConfig, ServerError};
use ledge_tests::TestServer;

/// Room places: `--max-rooms` 2 with 4 players each.
const MAX_ROOMS: i64 = 2;
const MAX_PLAYERS: i64 = 4;
/// Time between health pings in these tests.
const HEALTH: Duration = Duration::from_millis(200);

/// A fake sidecar whose GameServer declares what ledge's manifests declare.
fn sidecar() -> FakeSidecar {
    FakeSidecar::start(
        "ledge-test",
        &[(ROOMS, MAX_ROOMS), (PLAYERS, MAX_ROOMS * MAX_PLAYERS)],
        &[(ROOMS, MAX_ROOMS)],
    )
    .expect("the fake sidecar starts")
}

fn fleet(sidecar: &FakeSidecar, shutdown_after: Duration) -> FleetConfig {
    FleetConfig {
        health_every: HEALTH,
        shutdown_after,
        connect_timeout: Duration::from_secs(5),
        sdk_port: Some(sidecar.port()),
    }
}

async fn server_under(fleet: FleetConfig) -> TestServer {
    TestServer::start_with(|c| {
        c.max_rooms = MAX_ROOMS as u32;
        c.max_players = MAX_PLAYERS as usize;
        c.agones = Some(fleet);
    })
    .await
}

/// Waits (at most 5 s) until `check` holds.
async fn until(what: &str, mut check: impl FnMut() -> bool) {
    let deadline = Instant::now() + Duration::from_secs(5);
    while !check() {
        assert!(Instant::now() < deadline, "timed out waiting: {what}");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

async fn join(server: &TestServer, name: &str, room: Option<&str>) -> Session {
    let options = JoinOptions {
        player_name: name.into(),
        room: room.map(str::to_owned),
        resume: None,
    };
    connect_with(server.addr, "localhost", server.fingerprint, &options)
        .await
        .unwrap_or_else(|e| panic!("{name} joins: {e}"))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 1)]
async fn ready_after_listening_then_counters_list_and_label_follow_two_rooms() {
    let sidecar = sidecar();
    let server = server_under(fleet(&sidecar, Duration::from_secs(60))).await;
    until("Ready", || sidecar.state() == "Ready").await;
    // Everything an allocation looks at was published before Ready.
    let calls = sidecar.calls();
    let ready = calls.iter().position(|c| *c == Call::Ready).unwrap();
    let before = &calls[..ready];
    assert!(
        before.contains(&Call::Annotation(
            CERT_ANNOTATION.into(),
            server.fingerprint.to_string()
        )),
        "{calls:?}"
    );
    assert!(before.contains(&Call::AddListValue(ROOMS.into(), "room-1".into())));
    assert!(before.contains(&Call::Label(FULL_LABEL.into(), "false".into())));
    assert_eq!(
        sidecar.annotation(CERT_ANNOTATION),
        Some(server.fingerprint.to_string())
    );
    assert_eq!(sidecar.counter(ROOMS), Some((0, MAX_ROOMS)));
    assert_eq!(sidecar.counter(PLAYERS), Some((0, MAX_ROOMS * MAX_PLAYERS)));
    assert_eq!(sidecar.list(ROOMS), Some(vec!["room-1".to_owned()]));
    // Ready means listening: a player joins at once.
    let ada = join(&server, "ada", None).await;
    until("1 player, 1 room in use", || {
        sidecar.counter(PLAYERS) == Some((1, 8)) && sidecar.counter(ROOMS) == Some((1, 2))
    })
    .await;
    // A second room, opened by name: both rooms in use, the server full.
    let bob = join(&server, "bob", Some("friends")).await;
    until("2 rooms in use and full", || {
        sidecar.counter(ROOMS) == Some((2, 2))
            && sidecar.label(FULL_LABEL).as_deref() == Some("true")
    })
    .await;
    assert_eq!(sidecar.counter(PLAYERS), Some((2, 8)));
    assert_eq!(
        sidecar.list(ROOMS),
        Some(vec!["room-1".to_owned(), "friends".to_owned()])
    );
    // Both leave: room-1 (open from the start) is no longer in use;
    // "friends" stays open (and listed) until it has been empty a minute.
    ada.close().await;
    bob.close().await;
    until("no players, 1 room in use, not full", || {
        sidecar.counter(PLAYERS) == Some((0, 8))
            && sidecar.counter(ROOMS) == Some((1, 2))
            && sidecar.label(FULL_LABEL).as_deref() == Some("false")
    })
    .await;
    assert_eq!(sidecar.list(ROOMS).unwrap().len(), 2);
    // Nothing was sent twice for nothing: each counter value once.
    let players_updates = sidecar
        .calls()
        .iter()
        .filter(
            |c| matches!(c, Call::UpdateCounter { name, count: Some(_), .. } if name == PLAYERS),
        )
        .count();
    assert_eq!(players_updates, 4, "0, 1, 2, 0: {:?}", sidecar.calls());
    server.stop().await.expect("clean stop");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 1)]
async fn health_pings_while_the_rooms_tick_and_none_while_a_tick_loop_is_stuck() {
    let sidecar = sidecar();
    let server = server_under(fleet(&sidecar, Duration::from_secs(60))).await;
    until("Ready", || sidecar.state() == "Ready").await;
    // Two seconds of normal play: a ping every 200 ms.
    let t0 = Instant::now();
    tokio::time::sleep(Duration::from_secs(2)).await;
    let t1 = Instant::now();
    let pings = |from: Instant, to: Instant| {
        sidecar
            .health_pings()
            .into_iter()
            .filter(|&t| t >= from && t < to)
            .count()
    };
    let normal = pings(t0, t1);
    assert!((7..=13).contains(&normal), "{normal} pings in 2 s");
    // The rooms' worker thread blocked for 2.5 s: their tick loops stop.
    let stuck_at = Instant::now();
    let blocker = tokio::spawn(async {
        std::thread::sleep(Duration::from_millis(2500));
    });
    tokio::time::sleep(Duration::from_millis(2500)).await;
    let unstuck_at = Instant::now();
    blocker.await.unwrap();
    // One ping may still go out for ticks made just before the block.
    let during = pings(stuck_at + Duration::from_millis(450), unstuck_at);
    assert_eq!(during, 0, "pings while no room ticks");
    // They come back once the rooms tick again.
    tokio::time::sleep(Duration::from_secs(1)).await;
    let after = pings(unstuck_at, Instant::now());
    assert!(after >= 3, "{after} pings in the second after");
    eprintln!("pings: {normal} in 2 s of play, {during} while stuck, {after} in the second after");
    server.stop().await.expect("clean stop");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 1)]
async fn an_allocated_server_shuts_itself_down_once_empty_for_the_configured_time() {
    let sidecar = sidecar();
    let mut server = server_under(fleet(&sidecar, Duration::from_secs(1))).await;
    until("Ready", || sidecar.state() == "Ready").await;
    // Empty but not allocated: it stays.
    assert!(server.ended(Duration::from_millis(1500)).await.is_none());
    let ada = join(&server, "ada", None).await;
    sidecar.allocate();
    // Allocated with a player: it stays.
    assert!(server.ended(Duration::from_millis(1500)).await.is_none());
    assert!(!sidecar.calls().contains(&Call::Shutdown));
    let left = Instant::now();
    ada.close().await;
    // Empty for a second: Shutdown, then the server drains and stops.
    let ended = server
        .ended(Duration::from_secs(4))
        .await
        .expect("the server stopped by itself");
    ended.expect("a clean stop");
    let shutdown_at = sidecar
        .events()
        .into_iter()
        .find(|e| e.call == Call::Shutdown)
        .expect("Shutdown was called")
        .at;
    let empty_for = shutdown_at.duration_since(left);
    assert!(
        empty_for >= Duration::from_millis(900) && empty_for < Duration::from_secs(3),
        "shut down {empty_for:?} after the last player left"
    );
    assert_eq!(sidecar.state(), "Shutdown");
}

#[tokio::test]
async fn no_sidecar_stops_the_server_at_start_saying_what_to_do() {
    // A port nobody listens on.
    let port = {
        let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        l.local_addr().unwrap().port()
    };
    let certs = tempfile::tempdir().unwrap();
    let config = ServerConfig {
        bind: "127.0.0.1:0".parse().unwrap(),
        cert_dir: certs.path().to_owned(),
        agones: Some(FleetConfig {
            connect_timeout: Duration::from_secs(1),
            sdk_port: Some(port),
            ..FleetConfig::default()
        }),
        ..ServerConfig::default()
    };
    let server = Server::bind(config).expect("binds");
    let started = Instant::now();
    let result = tokio::time::timeout(Duration::from_secs(10), server.run())
        .await
        .expect("gives up within its connect timeout");
    let Err(ServerError::Agones(message)) = result else {
        panic!("not an Agones error: {result:?}");
    };
    assert!(started.elapsed() < Duration::from_secs(5));
    assert!(
        message.contains(&format!("localhost:{port}"))
            && message.contains("within 1 s")
            && message.contains("without --agones"),
        "{message}"
    );
    eprintln!("{message}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 1)]
async fn a_failing_sidecar_is_retried_and_play_goes_on() {
    let sidecar = sidecar();
    let server = server_under(fleet(&sidecar, Duration::from_secs(60))).await;
    until("Ready", || sidecar.state() == "Ready").await;
    sidecar.set_failing(true);
    let failing_from = sidecar.calls().len();
    let mut ada = join(&server, "ada", None).await;
    // The player plays: snapshots keep coming.
    let (first, _) = ledge_tests::next_snapshot(&mut ada, Duration::from_secs(3)).await;
    let (later, _) = ledge_tests::next_snapshot(&mut ada, Duration::from_secs(3)).await;
    assert!(later.state.tick > first.state.tick);
    // The server keeps trying to publish its player.
    until("retries", || {
        sidecar.calls()[failing_from..]
            .iter()
            .filter(|c| matches!(c, Call::UpdateCounter { .. }))
            .count()
            >= 3
    })
    .await;
    assert_eq!(
        sidecar.counter(PLAYERS),
        Some((0, 8)),
        "nothing got through"
    );
    // The sidecar recovers: the count catches up.
    sidecar.set_failing(false);
    until("caught up", || sidecar.counter(PLAYERS) == Some((1, 8))).await;
    ada.close().await;
    server.stop().await.expect("clean stop");
}
