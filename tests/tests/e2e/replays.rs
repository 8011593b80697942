//! Replays (issue 32) over real QUIC: runner bots finish the default level;
//! each recorded run has a replay, served by the web port, which plays
//! again to the server's state hashes and ends with that player finished in
//! the time the records show; the match is saved when the room empties.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use ledge_levels::default_level;
use ledge_shared::replay::{self, Event, Playback, Replay, ReplayKind};
use ledge_tests::web::http_get_from;
use ledge_tests::TestServer;

use crate::records::race;
use crate::web_transports::{page, web_server};

/// Every replay in `dir`, read.
fn replays_in(dir: &Path) -> Vec<Replay> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "ledgereplay") {
            let bytes = std::fs::read(&path).unwrap();
            out.push(replay::decode(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display())));
        }
    }
    out
}

/// A server with the web port saving replays in a folder of its own
/// (at most `cap` bytes of them, if given): the server, the folder, and
/// the temporary directories to keep while it runs.
async fn server_saving_replays(
    cap: Option<u64>,
) -> (TestServer, PathBuf, (tempfile::TempDir, tempfile::TempDir)) {
    let root = page();
    let dir = tempfile::tempdir().unwrap();
    let replays = dir.path().join("replays");
    let folder = replays.clone();
    let server = web_server(root.path(), move |c| {
        c.replays = Some(ledge_server::replays::ReplaysTarget::Dir(folder));
        if let Some(cap) = cap {
            c.replays_cap = cap;
        }
    })
    .await;
    (server, replays, (root, dir))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn each_finished_run_and_the_match_replay_to_the_servers_hashes() {
    let (server, replays, _keep) = server_saving_replays(None).await;
    let web = server.web_addr.unwrap();
    let hash = server.level_offer.hex();
    let reports = race(&server, &["ann", "bob"]).await;

    let top = http_get_from(None, web, &format!("/records/{hash}"), &[])
        .await
        .unwrap();
    let doc: serde_json::Value = serde_json::from_slice(&top.body).unwrap();
    for entry in doc["top"].as_array().unwrap() {
        let name = entry["player"].as_str().unwrap();
        let id = entry["replay"]
            .as_str()
            .expect("a replay id with the record");
        let file = http_get_from(None, web, &format!("/replays/{id}"), &[])
            .await
            .unwrap();
        assert_eq!(file.status, 200, "{}", file.head);
        assert_eq!(
            file.header("content-type"),
            Some("application/octet-stream")
        );
        let run = replay::decode(&file.body).unwrap();
        assert_eq!(run.header.level, server.level_offer);
        let ReplayKind::Run { player, ticks, .. } = run.header.kind else {
            panic!("{id} is a {:?}", run.header.kind);
        };
        assert_eq!(run.name_of(player), Some(name));
        let report = reports.iter().find(|r| r.name == name).unwrap();
        assert_eq!(Some(ticks as u32), report.finish_ticks, "{name}");
        assert_eq!(entry["ticks"].as_u64(), Some(ticks));
        // Played again, every hash checked: it ends with that player
        // finished, in the time the records show.
        let mut playing = Playback::new(&default_level(), run).unwrap();
        playing
            .play_to_end()
            .unwrap_or_else(|e| panic!("{name}'s replay: {e}"));
        let view = playing.game().player(player).expect("still in the game");
        assert!(view.won, "{name} finished in the replay");
        assert_eq!(u64::from(view.run_ticks), ticks, "{name}'s time");
    }

    // The bots left: the room is empty and its match is saved.
    assert_eq!(
        wait_for_kinds(&replays, (2, 1)).await,
        (2, 1),
        "both runs, one match"
    );
    let matches: Vec<Replay> = replays_in(&replays)
        .into_iter()
        .filter(|r| r.header.kind == ReplayKind::Match)
        .collect();
    assert_eq!(matches.len(), 1, "one match");
    let game = &matches[0];
    let joins = game
        .events
        .iter()
        .filter(|e| matches!(e, Event::Join(_)))
        .count();
    assert_eq!(joins, 2, "both bots joined it");
    let mut playing = Playback::new(&default_level(), game.clone()).unwrap();
    let ticks = playing.play_to_end().unwrap();
    assert!(ticks > 300, "{ticks} ticks");
    assert_eq!(playing.game().players().count(), 0, "both left");

    // The level by its hash; bad names are told why.
    let level = http_get_from(None, web, &format!("/levels/{hash}"), &[])
        .await
        .unwrap();
    let by_default = http_get_from(None, web, "/level", &[]).await.unwrap();
    assert_eq!(level.status, 200);
    assert_eq!(level.body, by_default.body);
    for (path, status) in [
        ("/replays/nothex".to_owned(), 400),
        ("/replays/0000000000000000".to_owned(), 404),
        (format!("/levels/{}", "0".repeat(64)), 404),
    ] {
        let answer = http_get_from(None, web, &path, &[]).await.unwrap();
        assert_eq!(answer.status, status, "{path}: {}", answer.head);
    }
    let html = http_get_from(None, web, "/records", &[("Accept", "text/html")])
        .await
        .unwrap();
    assert!(String::from_utf8_lossy(&html.body).contains("<a href=\"/replays/"));
    server.stop().await.unwrap();
}

/// Replays in `dir` by kind: (runs, matches).
fn kinds(dir: &Path) -> (usize, usize) {
    let all = replays_in(dir);
    let matches = all
        .iter()
        .filter(|r| r.header.kind == ReplayKind::Match)
        .count();
    (all.len() - matches, matches)
}

/// Waits up to 10 s for `dir` to hold `want` (runs, matches).
async fn wait_for_kinds(dir: &Path, want: (usize, usize)) -> (usize, usize) {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let found = kinds(dir);
        if found == want || Instant::now() > deadline {
            return found;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn past_the_cap_the_oldest_replays_go_but_not_the_records_own() {
    // A cap no replay fits: everything that may go, goes.
    let (server, replays, _keep) = server_saving_replays(Some(1)).await;
    race(&server, &["ann"]).await;
    // Her run's replay, then the match's (the newest always stays).
    assert_eq!(wait_for_kinds(&replays, (1, 1)).await, (1, 1));
    race(&server, &["bob"]).await;
    // Bob's run came: the first match went; ann's run is a record's, kept.
    assert_eq!(wait_for_kinds(&replays, (2, 1)).await, (2, 1));
    let pruned = ledge_tests::metric(&server.metrics(), "ledge_replays_pruned_total");
    assert!(pruned >= 1.0, "{pruned} pruned");
    server.stop().await.unwrap();
}
