//! Silent clients cannot hold seats: joined players that send no input are
//! removed after the idle time (half of it while the room is full), told
//! why, and a newcomer then gets a seat; a player who plays is not touched.

use std::time::Duration;

use ledge_client::{ClientError, SessionEvent};
use ledge_shared::protocol::{CloseCode, NoticeKind};
use ledge_tests::e2e::watch;
use ledge_tests::{metric, TestServer};

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn silent_players_lose_their_seats_and_a_newcomer_gets_one() {
    let server = TestServer::start_with(|c| {
        c.max_players = 4;
        c.idle_kick = Duration::from_secs(2);
    })
    .await;
    let mut player = server.join("player").await;
    let mut silent = Vec::new();
    for i in 0..3 {
        silent.push(server.join(&format!("squatter-{i}")).await);
    }
    // The room is full: the squatters go after 1 s of silence; the player,
    // who sends an input every tick, stays.
    let watched = watch(&mut player, Duration::from_secs(3), |_| false).await;
    assert!(!watched);
    let m = server.metrics();
    assert_eq!(metric(&m, r#"ledge_kicks_total{reason="Idle"}"#), 3.0);
    assert_eq!(metric(&m, r#"ledge_players{room="room-1"}"#), 1.0);
    for mut s in silent {
        // Told why, then closed as kicked.
        let mut told = None;
        let end = loop {
            match s.recv().await {
                Ok(SessionEvent::Notice(NoticeKind::Kick { reason })) => told = Some(reason),
                Ok(_) => {}
                Err(e) => break e,
            }
        };
        let reason = told.expect("a kick notice");
        assert!(reason.contains("no input for 2 s"), "{reason}");
        assert!(
            matches!(
                end,
                ClientError::ClosedByServer {
                    code: Some(CloseCode::Kicked),
                    ..
                }
            ),
            "{end}"
        );
    }
    let newcomer = server.join("newcomer").await;
    assert_eq!(newcomer.welcome().room, "room-1");
    assert!(player.players().values().any(|n| n == "player"));
    server.stop().await.unwrap();
}
