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

/// Room places: `--max-rooms` 3 (room-1, open from the start, and two
/// more by name) with 4 players each.
const MAX_ROOMS: i64 = 3;
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
        spectate: false,
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
    assert_eq!(sidecar.counter(ROOMS), Some((1, MAX_ROOMS)));
    assert_eq!(sidecar.counter(PLAYERS), Some((0, MAX_ROOMS * MAX_PLAYERS)));
    assert_eq!(sidecar.list(ROOMS), Some(vec!["room-1".to_owned()]));
    // Ready means listening: a player joins at once.
    let ada = join(&server, "ada", None).await;
    until("1 player in room-1", || {
        sidecar.counter(PLAYERS) == Some((1, 12)) && sidecar.counter(ROOMS) == Some((1, 3))
    })
    .await;
    // A second room, opened by name.
    let bob = join(&server, "bob", Some("friends")).await;
    until("2 rooms open", || {
        sidecar.counter(ROOMS) == Some((2, 3)) && sidecar.counter(PLAYERS) == Some((2, 12))
    })
    .await;
    assert_eq!(sidecar.label(FULL_LABEL).as_deref(), Some("false"));
    // A third: the room cap is reached, the server is full.
    let carol = join(&server, "carol", Some("duel")).await;
    until("3 rooms open and full", || {
        sidecar.counter(ROOMS) == Some((3, 3))
            && sidecar.label(FULL_LABEL).as_deref() == Some("true")
    })
    .await;
    assert_eq!(sidecar.counter(PLAYERS), Some((3, 12)));
    assert_eq!(
        sidecar.list(ROOMS),
        Some(vec!["room-1".into(), "friends".into(), "duel".into()])
    );
    // A fourth room is refused by the server, as its counter said.
    let refused = connect_with(
        server.addr,
        "localhost",
        server.fingerprint,
        &JoinOptions {
            player_name: "dave".into(),
            room: Some("more".into()),
            resume: None,
            spectate: false,
        },
    )
    .await;
    assert!(refused.is_err(), "a fourth room opened");
    // All leave: no players; the rooms opened by name stay open (and
    // counted) until they have been empty a minute.
    for p in [ada, bob, carol] {
        p.close().await;
    }
    until("no players", || sidecar.counter(PLAYERS) == Some((0, 12))).await;
    assert_eq!(sidecar.counter(ROOMS), Some((3, 3)));
    assert_eq!(sidecar.list(ROOMS).unwrap().len(), 3);
    // Nothing was sent twice for nothing: each counter value once, up as
    // they joined and down as they left (two leaving within one update
    // may be one step).
    let players: Vec<i64> = sidecar
        .calls()
        .iter()
        .filter_map(|c| match c {
            Call::UpdateCounter {
                name,
                count: Some(n),
                ..
            } if name == PLAYERS => Some(*n),
            _ => None,
        })
        .collect();
    assert_eq!(players[..4], [0, 1, 2, 3], "{players:?}");
    assert!(
        players[3..].windows(2).all(|w| w[1] < w[0]),
        "each value once, going down: {players:?}"
    );
    assert_eq!(players.last(), Some(&0), "{players:?}");
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
        Some((0, 12)),
        "nothing got through"
    );
    // The sidecar recovers: the count catches up.
    sidecar.set_failing(false);
    until("caught up", || sidecar.counter(PLAYERS) == Some((1, 12))).await;
    ada.close().await;
    server.stop().await.expect("clean stop");
}

/// A local fleet of three servers, each under its own fake sidecar: rooms
/// are allocated one by one with Agones' rule for ledge's manifests (a free
/// room on the fullest Allocated server, else a Ready one), two players
/// join each; every room's players see each other and nobody else, every
/// sidecar lists exactly its rooms, and the fleet is full after 3 × 2.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_fleet_of_three_packs_rooms_by_the_counter_rule_without_cross_talk() {
    use ledge_agones_fake::{allocate, Want};
    use ledge_shared::game::kind;

    const PER_ROOM: usize = 2;
    let sidecars: Vec<FakeSidecar> = (0..3).map(|_| sidecar()).collect();
    let mut servers = Vec::new();
    for s in &sidecars {
        servers.push(server_under(fleet(s, Duration::from_secs(60))).await);
    }
    for s in &sidecars {
        until("Ready", || s.state() == "Ready").await;
    }
    let all: Vec<&FakeSidecar> = sidecars.iter().collect();
    // Room k goes where the rule says; its players join there.
    let mut rooms: Vec<(String, usize, Vec<Session>)> = Vec::new();
    // Each server has room-1 open from the start: two more rooms each.
    let per_server = MAX_ROOMS as usize - 1;
    for k in 0..3 * per_server {
        let name = format!("match-{k}");
        let at = allocate(&all, Want::AnyRoom).expect("a server with a free room");
        // Packed: the first server's rooms fill up before the next is used.
        assert_eq!(at, k / per_server, "room {name}");
        let mut players = Vec::new();
        for p in 0..PER_ROOM {
            players.push(join(&servers[at], &format!("p{k}-{p}"), Some(&name)).await);
        }
        let listed = |s: &FakeSidecar| s.list(ROOMS).is_some_and(|l| l.contains(&name));
        until("the room listed", || listed(&sidecars[at])).await;
        rooms.push((name, at, players));
    }
    assert_eq!(allocate(&all, Want::AnyRoom), None, "the fleet is full");
    for (i, s) in sidecars.iter().enumerate() {
        until("counters", || {
            s.counter(ROOMS) == Some((3, 3))
                && s.counter(PLAYERS) == Some((2 * PER_ROOM as i64, 12))
                && s.label(FULL_LABEL).as_deref() == Some("true")
        })
        .await;
        let mut mine: Vec<String> = rooms
            .iter()
            .filter(|r| r.1 == i)
            .map(|r| r.0.clone())
            .collect();
        mine.push("room-1".into());
        let mut listed = s.list(ROOMS).unwrap();
        mine.sort();
        listed.sort();
        assert_eq!(listed, mine, "server {i} lists its rooms");
    }
    // A named room is found on its server.
    for (name, at, _) in &rooms {
        assert_eq!(allocate(&all, Want::Room(name)), Some(*at));
    }
    // No cross-talk: each player sees exactly its room's players.
    for (name, _, players) in &mut rooms {
        let ids: std::collections::BTreeSet<u32> =
            players.iter().map(|p| p.welcome().player_id.0).collect();
        for p in players.iter_mut() {
            let snapshot = ledge_tests::snapshot_where(p, Duration::from_secs(3), |s| {
                s.entities.iter().filter(|e| e.kind == kind::PLAYER).count() == PER_ROOM
            })
            .await;
            let seen: std::collections::BTreeSet<u32> = snapshot
                .entities
                .iter()
                .filter(|e| e.kind == kind::PLAYER)
                .map(|e| e.id)
                .collect();
            assert_eq!(seen, ids, "in {name}");
            assert_eq!(&p.welcome().room, name);
        }
    }
    for (_, _, players) in rooms {
        for p in players {
            p.close().await;
        }
    }
    for server in servers {
        server.stop().await.expect("clean stop");
    }
}
