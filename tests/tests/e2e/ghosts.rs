//! Ghosts (issue 32) over real QUIC: once a run is in the records with its
//! replay, a player joining gets it as a ghost to race (the level's record,
//! and its own best when that is another run), which plays on the client
//! into a track as long as the run.

use std::time::Duration;

use ledge_client::ghost::Ghost;
use ledge_client::net::session::{Session, SessionEvent};
use ledge_levels::default_level;
use ledge_shared::protocol::GhostRun;

use crate::records::{millis, race};
use crate::web_transports::{page, web_server};

/// The ghosts `session` is sent within `within`.
async fn ghosts(session: &mut Session, within: Duration) -> Vec<GhostRun> {
    let mut out = Vec::new();
    let deadline = tokio::time::Instant::now() + within;
    while let Ok(event) = tokio::time::timeout_at(deadline, session.recv()).await {
        if let SessionEvent::Ghost(g) = event.expect("the session lasts") {
            out.push(g);
        }
    }
    out
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_joining_player_races_the_record_and_its_own_best() {
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    // Nothing recorded yet: no ghost.
    let mut early = server.join("eve").await;
    assert!(ghosts(&mut early, Duration::from_millis(500))
        .await
        .is_empty());
    early.close().await;

    let ann = race(&server, &["ann"]).await.remove(0);
    let ann_ticks = ann.finish_ticks.expect("ann finished");

    // bob gets ann's record; it plays into a track as long as her run.
    let mut bob = server.join("bob").await;
    let sent = ghosts(&mut bob, Duration::from_secs(2)).await;
    assert_eq!(sent.len(), 1, "the record only: bob has no best yet");
    let record = &sent[0];
    assert!(record.record);
    assert_eq!(record.player, "ann");
    assert_eq!(record.millis, millis(ann_ticks));
    let ghost = Ghost::from_run(&default_level(), record).unwrap();
    assert_eq!(ghost.ticks(), ann_ticks, "the ghost's run is ann's");
    assert!(
        ghost.at(0).unwrap().x < ghost.at(ann_ticks).unwrap().x,
        "it runs to the goal"
    );
    bob.close().await;

    // bob finishes too; if slower, he races ann's record and his own best.
    let bob_run = race(&server, &["bob"]).await.remove(0);
    let bob_ticks = bob_run.finish_ticks.unwrap();
    let mut again = server.join("bob").await;
    let sent = ghosts(&mut again, Duration::from_secs(2)).await;
    let best: Vec<&GhostRun> = sent.iter().filter(|g| !g.record).collect();
    if bob_ticks > ann_ticks {
        assert_eq!(best.len(), 1, "bob's own best beside the record");
        let mine = Ghost::from_run(&default_level(), best[0]).unwrap();
        assert_eq!(mine.ticks(), bob_ticks);
    } else {
        // bob holds the record: one ghost, his.
        assert!(best.is_empty());
        assert_eq!(sent[0].player, "bob");
    }
    again.close().await;
    server.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_record_set_while_a_player_races_reaches_it_at_once() {
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    // eve is in the room, with no ghost to race yet.
    let mut eve = server.join("eve").await;
    assert!(ghosts(&mut eve, Duration::from_millis(300))
        .await
        .is_empty());
    let ann = race(&server, &["ann"]).await.remove(0);
    // ann's record is stored: eve gets its ghost without joining again.
    let sent = ghosts(&mut eve, Duration::from_secs(3)).await;
    assert_eq!(sent.len(), 1, "{sent:?}");
    assert!(sent[0].record);
    assert_eq!(sent[0].player, "ann");
    assert_eq!(sent[0].millis, millis(ann.finish_ticks.unwrap()));
    eve.close().await;
    server.stop().await.unwrap();
}
