//! Bots over real QUIC: a runner reaches the goal of the default level as
//! the server sees it; misbehaving clients are dropped or ignored while a
//! normal bot plays on unaffected.

use std::time::{Duration, Instant};

use ledge_client::bot::{
    misbehave, run_bot, BotOptions, Misbehavior, Outcome, RandomWalker, Runner,
};
use ledge_client::InputClock;
use ledge_shared::game::state::{kind, player_flags};
use ledge_shared::input::Buttons;
use ledge_shared::level::{default_level, default_route};
use ledge_shared::protocol::CloseCode;
use ledge_tests::{metric, starvation, TestServer};

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_runner_bot_reaches_the_goal_as_the_server_sees_it() {
    let server = TestServer::start().await;
    // An observer watches the server's snapshots (its authoritative state)
    // for the runner's player and its goal flag.
    let mut observer = server.join("observer").await;
    let observer_id = observer.welcome().player_id.0;
    let runner_session = server.join("runner").await;
    let runner_id = runner_session.welcome().player_id;
    let bot = tokio::spawn(async move {
        let mut brain = Runner::new(default_route());
        let options = BotOptions {
            stop_when_done: true,
            min_margin: Some(3.0),
            ..BotOptions::new("runner", Duration::from_secs(14))
        };
        let report = run_bot(runner_session, &mut brain, &options).await;
        (report, brain.progress())
    });
    let goal = default_level()
        .entities
        .iter()
        .find(|e| matches!(e.kind, ledge_shared::level::EntityKind::Goal))
        .map(|e| e.pos)
        .unwrap();
    let clock = InputClock::new(observer.welcome(), Instant::now());
    let deadline = Instant::now() + Duration::from_secs(14);
    let mut seen = None;
    let mut furthest = i32::MIN;
    while Instant::now() < deadline && seen.is_none() {
        observer
            .send_input(clock.input_tick(Instant::now()), Buttons::NONE)
            .unwrap();
        let wait = clock.until_next_tick(Instant::now());
        let Ok(event) = tokio::time::timeout(wait, observer.recv()).await else {
            continue;
        };
        if let ledge_client::SessionEvent::Snapshot(update) = event.unwrap() {
            let runner = update
                .state
                .entities
                .iter()
                .find(|e| e.kind == kind::PLAYER && e.id == runner_id.0 && e.id != observer_id);
            if let Some(r) = runner {
                furthest = furthest.max(r.pos.x);
                if r.flags & player_flags::WON != 0 {
                    seen = Some((update.state.tick, r.pos));
                }
            }
        }
    }
    let (report, progress) = bot.await.unwrap();
    eprintln!("{report}");
    eprintln!(
        "runner progress: {progress:?}; furthest x {} px",
        furthest / 256
    );
    let (tick, pos) = seen.unwrap_or_else(|| {
        panic!(
            "the server never saw the runner win; it got to x = {} px ({progress:?})",
            furthest / 256
        )
    });
    eprintln!(
        "won at server tick {tick}, at ({}, {}) px; goal at ({}, {}) px",
        pos.x / 256,
        pos.y / 256,
        goal.x / 256,
        goal.y / 256
    );
    assert!((pos.x - goal.x).abs() < 32 * 256, "at the goal");
    assert!(report.won, "the runner's own snapshots show the win too");
    assert_eq!(progress.respawns, 0, "never hurt on the way");
    observer.close().await;
    server.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn misbehaving_clients_are_dropped_or_ignored_and_a_normal_bot_is_unaffected() {
    let server = TestServer::start().await;
    let normal = server.join("normal").await;
    let normal_bot = tokio::spawn(async move {
        let mut brain = RandomWalker::new(7);
        let options = BotOptions {
            min_margin: Some(3.0),
            ..BotOptions::new("normal", Duration::from_secs(7))
        };
        run_bot(normal, &mut brain, &options).await
    });
    // Let the normal bot settle, then attack.
    tokio::time::sleep(Duration::from_millis(800)).await;
    let starved_before = starvation(&server, "room-1");
    let mut attacks = Vec::new();
    for (i, mode) in Misbehavior::ALL.into_iter().enumerate() {
        let (addr, fp) = (server.addr, server.fingerprint);
        attacks.push(tokio::spawn(async move {
            misbehave(
                addr,
                fp,
                &format!("bad-{i}"),
                mode,
                Duration::from_secs(5),
                i as u64,
            )
            .await
        }));
    }
    let mut reports = Vec::new();
    for a in attacks {
        reports.push(a.await.unwrap());
    }
    let normal = normal_bot.await.unwrap();
    for r in &reports {
        eprintln!("{r}");
    }
    eprintln!("{normal}");
    let metrics = server.metrics();
    for r in &reports {
        match r.mode {
            Misbehavior::ControlGarbage | Misbehavior::OversizedFrame => assert!(
                matches!(
                    r.outcome,
                    Outcome::Closed {
                        code: Some(CloseCode::ProtocolViolation),
                        ..
                    }
                ),
                "{r}"
            ),
            Misbehavior::DatagramFlood | Misbehavior::GarbageDatagrams => assert!(
                matches!(
                    r.outcome,
                    Outcome::Closed {
                        code: Some(CloseCode::Kicked | CloseCode::ProtocolViolation),
                        ..
                    }
                ),
                "{r}"
            ),
            Misbehavior::StaleInputs | Misbehavior::FutureInputs => {
                assert!(
                    matches!(r.outcome, Outcome::Ignored { snapshots } if snapshots > 100),
                    "{r}"
                )
            }
            Misbehavior::WrongVersion => {
                assert!(matches!(r.outcome, Outcome::Rejected(_)), "{r}")
            }
        }
        if matches!(r.outcome, Outcome::Closed { .. }) {
            assert!(r.after < Duration::from_secs(3), "dropped promptly: {r}");
        }
    }
    let late = metric(
        &metrics,
        "ledge_dropped_messages_total{reason=\"InputLate\"}",
    );
    let early = metric(
        &metrics,
        "ledge_dropped_messages_total{reason=\"InputTooEarly\"}",
    );
    assert!(
        late > 0.0 && early > 0.0,
        "stale and future inputs dropped: {late} {early}"
    );
    // The normal bot played on: connected to the end, snapshots at the
    // full rate, and its prediction stayed exact unless its own inputs
    // were late (counted by the server as starvation).
    let starved = starvation(&server, "room-1") - starved_before;
    assert!(normal.ended.is_none(), "{normal}");
    assert!(normal.snapshots >= 180, "{normal}");
    assert!(normal.net.loss < 0.05, "{normal}");
    assert!(
        normal.mispredictions as f64 <= starved,
        "mispredicted {} times with {starved} starved ticks",
        normal.mispredictions
    );
    server.stop().await.unwrap();
}
