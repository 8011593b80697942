//! Prediction in a crowd over real QUIC: runner bots (the `ledge-bot`
//! default brain, which plans jumps by simulating the predicted game)
//! predict the server exactly for a minute beside twelve idle players, six
//! of them joining while the bots run. And players joining one room appear
//! on spots of their own, never on one pixel.
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
use ledge_client::Session;
use ledge_levels::default_route;
use ledge_shared::game::GameConfig;
use ledge_tests::e2e::{bot_options, spawn_bot, task_panics, watch, PlayerState};
use ledge_tests::{snapshot_where, TestServer, WAIT};

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
    let mut snapshots = 0;
    let within = until.saturating_duration_since(Instant::now());
    watch(&mut session, within, |_| {
        snapshots += 1;
        false
    })
    .await;
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
        let expected = PLAY.as_secs_f64() * 60.0;
        assert!(r.covered_ticks as f64 >= expected * 0.9, "{r}");
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

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn players_joining_one_room_appear_apart() {
    let server = TestServer::start().await;
    let mut sessions = Vec::new();
    for i in 0..4 {
        sessions.push(server.join(&format!("player-{i}")).await);
    }
    let ids: Vec<u32> = sessions.iter().map(|s| s.welcome().player_id.0).collect();
    // The first snapshot the last one gets that shows everyone: right after
    // the joins.
    let last = sessions.last_mut().unwrap();
    let state = snapshot_where(last, WAIT, |s| ids.iter().all(|&id| s.get(id).is_some())).await;
    let at: Vec<_> = ids.iter().map(|&id| state.get(id).unwrap().pos).collect();
    eprintln!("players {ids:?} at {at:?} (tick {})", state.tick);
    let half = GameConfig::default().player.half;
    for i in 0..at.len() {
        assert_eq!(at[i].y, at[0].y, "on one floor: {at:?}");
        for j in 0..i {
            assert_ne!(
                at[i], at[j],
                "players {} and {} on one pixel",
                ids[i], ids[j]
            );
        }
    }
    // The first two stand side by side, apart.
    assert!((at[1].x - at[0].x).abs() >= 2 * half.x, "{at:?}");
    for s in sessions {
        s.close().await;
    }
    server.stop().await.unwrap();
}
