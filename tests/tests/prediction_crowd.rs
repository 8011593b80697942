//! Prediction in a crowd over real QUIC: runner bots (the `ledge-bot`
//! default brain, which plans jumps by simulating the predicted game)
//! predict the server exactly for a minute beside twelve idle players, six
//! of them joining while the bots run.
//!
//! The idle players are thin: they send no-button inputs each tick and read
//! the snapshots, without predicting, so the test costs little more than
//! the four bots. Before the runners planned on a copy of the game holding
//! their own player only, a plan simulated every idle player too; the
//! stall delayed the bot's inputs past the server's tick and the server
//! applied the previous buttons instead: 14 to 41 mispredictions per run
//! (corrections up to 415 px), none without the idle players
//! (`docs/ARCHITECTURE.md`, "Prediction in a crowd").

use std::time::{Duration, Instant};

use ledge_client::bot::Runner;
use ledge_client::clock::InputClock;
use ledge_client::{Session, SessionEvent};
use ledge_levels::default_route;
use ledge_shared::input::Buttons;
use ledge_tests::e2e::{bot_options, spawn_bot, task_panics, PlayerState};
use ledge_tests::TestServer;

/// Predicting runner bots.
const BOTS: usize = 4;
/// Idle players joining before the bots.
const IDLE_BEFORE: usize = 6;
/// Idle players joining while the bots play.
const IDLE_DURING: usize = 6;
/// How long the bots play.
const PLAY: Duration = Duration::from_secs(60);

/// An idle player on `session` until `until`: a no-button input each tick,
/// every snapshot read (no prediction). Returns the snapshots received.
async fn idle(mut session: Session, until: Instant) -> u64 {
    let mut clock = InputClock::new(session.welcome(), Instant::now());
    let mut snapshots = 0;
    while Instant::now() < until {
        let _ = session.send_input(clock.input_tick(Instant::now()), Buttons::NONE);
        let wait = clock
            .until_next_tick(Instant::now())
            .min(until.saturating_duration_since(Instant::now()));
        let Ok(event) = tokio::time::timeout(wait, session.recv()).await else {
            continue;
        };
        match event.expect("the idle player stays connected") {
            SessionEvent::Snapshot(update) => {
                snapshots += 1;
                clock.observe(update.input_timing);
            }
            _ => continue,
        }
    }
    session.close().await;
    snapshots
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn runner_bots_predict_exactly_beside_twelve_idle_players_for_a_minute() {
    let started = Instant::now();
    let panics_before = task_panics();
    let server = TestServer::start().await;
    // The idle players stay until the bots are done.
    let idle_until = Instant::now() + PLAY + Duration::from_secs(5);
    let mut idlers = Vec::new();
    for i in 0..IDLE_BEFORE {
        let session = server.join(&format!("idle-{i}")).await;
        idlers.push(tokio::spawn(idle(session, idle_until)));
    }
    let mut bots = Vec::new();
    for i in 0..BOTS {
        let name = format!("runner-{i}");
        let session = server.join(&name).await;
        let options = bot_options(&name, PLAY);
        bots.push(spawn_bot(session, Runner::new(default_route()), options));
    }
    // More players arrive while the bots run their route.
    for i in IDLE_BEFORE..IDLE_BEFORE + IDLE_DURING {
        tokio::time::sleep(Duration::from_millis(400)).await;
        let session = server.join(&format!("idle-{i}")).await;
        idlers.push(tokio::spawn(idle(session, idle_until)));
    }
    let crowd = PlayerState::read(&server).room_players;
    assert_eq!(
        crowd,
        (BOTS + IDLE_BEFORE + IDLE_DURING) as i64,
        "everyone in one room"
    );
    let mut reports = Vec::new();
    for bot in bots {
        reports.push(bot.await.expect("the bot task did not panic").0);
    }
    for r in &reports {
        eprintln!("{r}");
    }
    let mut idle_snapshots = Vec::new();
    for i in idlers {
        idle_snapshots.push(i.await.expect("the idle player did not panic"));
    }
    server.stop().await.unwrap();
    eprintln!(
        "{BOTS} runners beside {crowd} players in all for {PLAY:?}: {:?} of wall time",
        started.elapsed()
    );
    for r in &reports {
        assert!(r.ended.is_none(), "{r}");
        let expected = PLAY.as_secs_f64() * 30.0;
        assert!(r.snapshots as f64 >= expected * 0.9, "{r}");
        assert!(r.won, "the runner reached the goal: {r}");
        assert_eq!((r.mispredictions, r.corrections), (0, 0), "{r}");
    }
    assert!(
        idle_snapshots.iter().all(|&n| n > 0),
        "the idle players were there: {idle_snapshots:?}"
    );
    assert_eq!(
        task_panics(),
        panics_before,
        "a server or bot task panicked"
    );
}
