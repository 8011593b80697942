//! Join and leave churn during a match: fifty players come and go (leaving
//! politely, dropping the connection, or vanishing off the network) while
//! bots play. The bots are unaffected, and the server's per-player state
//! returns to its baseline.

use std::collections::BTreeSet;
use std::net::SocketAddr;
use std::time::{Duration, Instant};

use ledge_client::bot::RandomWalker;
use ledge_client::{connect, Fingerprint, InputClock, SessionEvent};
use ledge_shared::game::state::kind;
use ledge_shared::input::Buttons;
use ledge_tests::e2e::{
    assert_steady, bot_options, spawn_bot, task_panics, watch, PlayerState, TickProbe,
};
use ledge_tests::{TestServer, UdpRelay};

/// Players that come and go.
const CHURNERS: u64 = 50;
/// Of those, how many are in the room at once.
const WAVE: u64 = 5;
/// Bots playing throughout.
const BOTS: u64 = 3;

/// How a churning player leaves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Departure {
    /// Sends `Leave` and closes.
    Leave,
    /// Drops the session: the connection closes without a `Leave`.
    Drop,
    /// Goes silent (all its traffic lost) until the idle timeout.
    Vanish,
}

/// Joins as player `i`, plays for a moment (inputs each tick, snapshots
/// read) and departs; returns the snapshots it got.
async fn come_and_go(addr: SocketAddr, fingerprint: Fingerprint, i: u64) -> u64 {
    let departure = match i % 5 {
        0 | 1 => Departure::Leave,
        2 | 3 => Departure::Drop,
        _ => Departure::Vanish,
    };
    let relay = match departure {
        Departure::Vanish => Some(UdpRelay::start(addr).await),
        _ => None,
    };
    let via = relay.as_ref().map_or(addr, |r| r.addr);
    let name = format!("churn-{i}");
    let mut session = connect(via, "localhost", fingerprint, &name)
        .await
        .unwrap_or_else(|e| panic!("{name} is welcomed: {e}"));
    let mut clock = InputClock::new(session.welcome(), Instant::now());
    let buttons = Buttons(if i % 2 == 0 {
        Buttons::RIGHT
    } else {
        Buttons::LEFT | Buttons::JUMP
    });
    let until = Instant::now() + Duration::from_millis(150 + i * 37 % 350);
    let mut snapshots = 0;
    while Instant::now() < until {
        session
            .send_input(clock.input_tick(Instant::now()), buttons)
            .expect("input queued");
        let wait = clock.until_next_tick(Instant::now());
        if let Ok(event) = tokio::time::timeout(wait, session.recv()).await {
            if let SessionEvent::Snapshot(update) = event.expect("the churner stays connected") {
                clock.observe(update.input_timing);
                snapshots += 1;
            }
        }
    }
    match departure {
        Departure::Leave => session.close().await,
        Departure::Drop => drop(session),
        Departure::Vanish => {
            relay.as_ref().expect("a relay").blackhole();
            drop(session);
        }
    }
    snapshots
}

/// Tasks alive on this test's runtime (server, bots, QUIC drivers).
fn alive_tasks() -> usize {
    tokio::runtime::Handle::current()
        .metrics()
        .num_alive_tasks()
}

/// Polls `check` every 100 ms until it holds or `within` passes.
async fn eventually(within: Duration, mut check: impl FnMut() -> bool) -> bool {
    let deadline = Instant::now() + within;
    loop {
        if check() {
            return true;
        }
        if Instant::now() >= deadline {
            return false;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn fifty_players_come_and_go_and_the_server_returns_to_its_baseline() {
    let panics_before = task_panics();
    // A short idle timeout and reconnect grace so the players that vanish
    // are dropped soon (until then they are kept for a resume and hold a
    // seat: room for them).
    let server = TestServer::start_with(|c| {
        c.idle_timeout = Duration::from_secs(2);
        c.reconnect_grace = Duration::from_millis(500);
        c.max_players = 32;
    })
    .await;
    let mut observer = server.join("observer").await;
    let mut ids = BTreeSet::from([observer.welcome().player_id.0]);
    let mut bots = Vec::new();
    for i in 0..BOTS {
        let name = format!("walker-{i}");
        let session = server.join(&name).await;
        ids.insert(session.welcome().player_id.0);
        // They play until the server shuts down at the end.
        let options = bot_options(&name, Duration::from_secs(60));
        bots.push(spawn_bot(session, RandomWalker::new(11 + i), options));
    }
    // Baseline, once the bots play.
    tokio::time::sleep(Duration::from_millis(1000)).await;
    let calm = TickProbe::read(&server, "room-1");
    tokio::time::sleep(Duration::from_millis(1000)).await;
    let baseline = PlayerState::read(&server);
    let baseline_tasks = alive_tasks();
    eprintln!("baseline: {baseline:?}, {baseline_tasks} tasks");
    assert_eq!(baseline.room_players, BOTS as i64 + 1);
    assert_eq!(baseline.connections, BOTS as i64 + 1);
    assert_eq!(baseline.client_series, ids);

    let churn_start = TickProbe::read(&server, "room-1");
    let mut snapshots = 0;
    let mut most_players = 0;
    for wave in 0..CHURNERS / WAVE {
        let mut players = Vec::new();
        for i in wave * WAVE..(wave + 1) * WAVE {
            players.push(tokio::spawn(come_and_go(
                server.addr,
                server.fingerprint,
                i,
            )));
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
        most_players = most_players.max(PlayerState::read(&server).room_players);
        for p in players {
            snapshots += p.await.expect("the churner did not panic");
        }
    }
    let churn_end = TickProbe::read(&server, "room-1");
    eprintln!(
        "{CHURNERS} players came and went in {:?}, {snapshots} snapshots, at most {most_players} \
         players at once",
        churn_end.at.duration_since(churn_start.at)
    );
    assert!(
        most_players > baseline.room_players,
        "the churners were in the room"
    );
    assert!(snapshots >= CHURNERS, "the churners played: {snapshots}");

    // Everything per player returns to the baseline: the room's members,
    // connections, per-client metric series, the players in the game (the
    // server's snapshots) and the tasks (connection tasks, QUIC drivers).
    let mut state = PlayerState::read(&server);
    let settled = eventually(Duration::from_secs(8), || {
        state = PlayerState::read(&server);
        state == baseline
    })
    .await;
    assert!(settled, "per-player state {state:?}, baseline {baseline:?}");
    let mut seen = BTreeSet::new();
    let game_players_back = watch(&mut observer, Duration::from_secs(3), |snapshot| {
        seen = snapshot
            .entities
            .iter()
            .filter(|e| e.kind == kind::PLAYER)
            .map(|e| e.id)
            .collect();
        seen == ids
    })
    .await;
    assert!(
        game_players_back,
        "players in the game {seen:?}, expected {ids:?}"
    );
    let mut tasks = alive_tasks();
    let tasks_back = eventually(Duration::from_secs(5), || {
        tasks = alive_tasks();
        tasks <= baseline_tasks
    })
    .await;
    assert!(tasks_back, "{tasks} tasks alive, {baseline_tasks} before");

    // The bots played on unaffected until the server shut down.
    observer.close().await;
    server.stop().await.unwrap();
    let mut reports = Vec::new();
    for bot in bots {
        reports.push(bot.await.expect("the bot task did not panic").0);
    }
    for r in &reports {
        eprintln!("{r}");
    }
    let (calm_rate, churn_rate) = (
        calm.rate_until(&churn_start),
        churn_start.rate_until(&churn_end),
    );
    eprintln!("server ticks: {calm_rate:.2} Hz before the churn, {churn_rate:.2} Hz during it");
    assert_steady("before the churn", calm_rate, 60.0);
    assert_steady("during the churn", churn_rate, 60.0);
    assert!(
        (churn_rate - calm_rate).abs() <= calm_rate * 0.10,
        "the churn changed the tick rate: {calm_rate:.2} -> {churn_rate:.2} Hz"
    );
    for r in &reports {
        assert_eq!(r.ended.as_deref(), Some("server shut down"), "{r}");
        let expected = r.played.as_secs_f64() * 60.0;
        assert!(r.covered_ticks as f64 >= expected * 0.9, "{r}");
        assert_eq!((r.corrections, r.mispredictions), (0, 0), "{r}");
    }
    assert_eq!(
        task_panics(),
        panics_before,
        "a server or bot task panicked"
    );
}
