//! Bots over real QUIC: misbehaving clients are dropped or ignored while
//! normal bots play on unaffected (same tick rate, exact prediction), and a
//! graceful shutdown reaches every bot. (Runners racing to the goal:
//! `matches.rs`.)

use std::time::{Duration, Instant};

use ledge_client::bot::{misbehave, Misbehavior, Outcome, RandomWalker};
use ledge_shared::protocol::CloseCode;
use ledge_tests::e2e::{assert_steady, bot_options, spawn_bot, task_panics, TickProbe};
use ledge_tests::{metric, TestServer};

/// Normal bots playing through the attack.
const NORMAL: u64 = 3;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn misbehaving_clients_are_dropped_or_ignored_and_normal_bots_are_unaffected() {
    let panics_before = task_panics();
    let server = TestServer::start().await;
    let mut normal_bots = Vec::new();
    for i in 0..NORMAL {
        let name = format!("normal-{i}");
        let session = server.join(&name).await;
        let options = bot_options(&name, Duration::from_secs(10));
        normal_bots.push(spawn_bot(session, RandomWalker::new(7 + i), options));
    }
    // Let the normal bots settle, measure the tick rate, then attack.
    tokio::time::sleep(Duration::from_millis(1500)).await;
    let calm = TickProbe::read(&server, "room-1");
    tokio::time::sleep(Duration::from_millis(2500)).await;
    let attack_start = TickProbe::read(&server, "room-1");
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
    let attack_end = TickProbe::read(&server, "room-1");
    let mut normal = Vec::new();
    for bot in normal_bots {
        normal.push(bot.await.expect("the bot task did not panic").0);
    }
    let (calm_rate, attack_rate) = (
        calm.rate_until(&attack_start),
        attack_start.rate_until(&attack_end),
    );
    for r in &reports {
        eprintln!("{r}");
    }
    for r in &normal {
        eprintln!("{r}");
    }
    eprintln!("server ticks: {calm_rate:.2} Hz before the attack, {attack_rate:.2} Hz during it");
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
    // The room ticked at its rate before and during the attack.
    assert_steady("before the attack", calm_rate, 60.0);
    assert_steady("during the attack", attack_rate, 60.0);
    assert!(
        (attack_rate - calm_rate).abs() <= calm_rate * 0.10,
        "the attack changed the tick rate: {calm_rate:.2} -> {attack_rate:.2} Hz"
    );
    // The normal bots played on: connected to the end, snapshots at the
    // full rate, and their predictions exact before and during the attack.
    for r in &normal {
        assert!(r.ended.is_none(), "{r}");
        assert!(r.covered_ticks as f64 >= 10.0 * 60.0 * 0.9, "{r}");
        assert!(r.net.loss < 0.05, "{r}");
        assert_eq!((r.corrections, r.mispredictions), (0, 0), "{r}");
    }
    server.stop().await.unwrap();
    assert_eq!(
        task_panics(),
        panics_before,
        "a server or bot task panicked"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bots_receive_the_shutdown_notice_and_stop_cleanly() {
    let server = TestServer::start().await;
    let mut bots = Vec::new();
    for i in 0..3 {
        let name = format!("walker-{i}");
        let session = server.join(&name).await;
        let options = bot_options(&name, Duration::from_secs(30));
        bots.push(spawn_bot(session, RandomWalker::new(i), options));
    }
    tokio::time::sleep(Duration::from_secs(2)).await;
    let stopping = Instant::now();
    server.stop().await.expect("clean shutdown");
    for bot in bots {
        let (report, _) = tokio::time::timeout(Duration::from_secs(3), bot)
            .await
            .expect("the bot stops soon after the server")
            .expect("the bot task did not panic");
        eprintln!(
            "{report} (stopped {:?} after the shutdown began)",
            stopping.elapsed()
        );
        // It stopped on the notice, not on the close that follows it.
        assert_eq!(
            report.ended.as_deref(),
            Some("server shut down"),
            "{report}"
        );
        assert!(report.snapshots >= 50, "it played until then: {report}");
        assert!(report.played < Duration::from_secs(6), "{report}");
    }
}
