//! Records (issue 32) over real QUIC with a real SQLite file: runner bots
//! finish the default level, each is told where its run stands once it is
//! stored, and the web port lists the runs, fastest first.

use std::time::Duration;

use ledge_client::bot::{BotOptions, BotReport, Runner};
use ledge_levels::default_route;
use ledge_tests::e2e::{bot_options, spawn_bot};
use ledge_tests::web::http_get_from;
use ledge_tests::TestServer;

use crate::web_transports::{page, web_server};

/// Runs `names` as runner bots at once, until each is done.
pub(crate) async fn race(server: &TestServer, names: &[&str]) -> Vec<BotReport> {
    let mut bots = Vec::new();
    for name in names {
        let session = server.join(name).await;
        let options = BotOptions {
            stop_when_done: true,
            ..bot_options(name, Duration::from_secs(30))
        };
        bots.push(spawn_bot(session, Runner::new(default_route()), options));
    }
    let mut reports = Vec::new();
    for bot in bots {
        let (report, _) = bot.await.expect("the bot task did not panic");
        assert!(
            report.won,
            "{} reached the goal: {}",
            report.name, report.progress
        );
        reports.push(report);
    }
    reports
}

/// A run's time as the records keep it: milliseconds at 60 ticks a second.
pub(crate) fn millis(ticks: u32) -> u64 {
    u64::from(ticks) * 1000 / 60
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn finished_runs_are_recorded_ranked_and_shown_on_the_web_port() {
    let root = page();
    let server = web_server(root.path(), |_| {}).await;
    let web = server.web_addr.unwrap();
    let hash = server.level_offer.hex();

    let reports = race(&server, &["ann", "bob", "cid"]).await;
    let mut times = Vec::new();
    for r in &reports {
        let ticks = r.finish_ticks.expect("a finish time");
        let standing = r
            .standing
            .clone()
            .expect("told where the run stands")
            .expect("recorded");
        assert_eq!(standing.millis, millis(ticks), "{}", r.name);
        assert!(standing.new_personal_best, "a first run is a best");
        assert!((1..=3).contains(&standing.rank));
        times.push((millis(ticks), r.name.clone()));
    }
    times.sort();

    // The web port: the level, then its top players, fastest first.
    let levels = http_get_from(None, web, "/records", &[]).await.unwrap();
    assert_eq!(levels.status, 200, "{}", levels.head);
    let doc: serde_json::Value = serde_json::from_slice(&levels.body).unwrap();
    let level = &doc["levels"][0];
    assert_eq!(level["hash"], hash.as_str());
    assert_eq!(level["name"], "default");
    assert_eq!(level["runs"], 3);
    assert_eq!(level["best_millis"], times[0].0);
    let top = http_get_from(None, web, &format!("/records/{hash}"), &[])
        .await
        .unwrap();
    assert_eq!(top.status, 200, "{}", top.head);
    let doc: serde_json::Value = serde_json::from_slice(&top.body).unwrap();
    let listed: Vec<(u64, String)> = doc["top"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["millis"].as_u64().unwrap(),
                e["player"].as_str().unwrap().into(),
            )
        })
        .collect();
    assert_eq!(listed, times, "ordered by time");

    // ann runs again: two runs, her best kept.
    let again = race(&server, &["ann"]).await;
    let standing = again[0].standing.clone().unwrap().unwrap();
    let first = times.iter().find(|(_, n)| n == "ann").unwrap().0;
    assert_eq!(standing.personal_best, first.min(standing.millis));
    assert_eq!(standing.new_personal_best, standing.millis < first);
    let top = http_get_from(None, web, &format!("/records/{hash}?n=1"), &[])
        .await
        .unwrap();
    let doc: serde_json::Value = serde_json::from_slice(&top.body).unwrap();
    assert_eq!(doc["top"].as_array().unwrap().len(), 1);
    assert_eq!(doc["level"]["runs"], 4);

    // A browser gets the page; bad requests are told why.
    let html = http_get_from(None, web, "/records", &[("Accept", "text/html")])
        .await
        .unwrap();
    let text = String::from_utf8_lossy(&html.body);
    assert!(html
        .header("content-type")
        .unwrap()
        .starts_with("text/html"));
    assert!(text.contains("<h2>default</h2>") && text.contains("ann") && text.contains("cid"));
    for (path, status) in [
        ("/records/nothex", 400),
        (&format!("/records/{}", "0".repeat(64)) as &str, 404),
        (&format!("/records/{hash}?n=1000"), 400),
    ] {
        let answer = http_get_from(None, web, path, &[]).await.unwrap();
        assert_eq!(answer.status, status, "{path}: {}", answer.head);
    }
    server.stop().await.unwrap();
}

#[tokio::test]
async fn a_server_without_records_says_so_to_the_player_and_on_the_web_port() {
    let root = page();
    let server = web_server(root.path(), |c| {
        c.records = Some(ledge_server::records::RecordsTarget::Off);
    })
    .await;
    let answer = http_get_from(None, server.web_addr.unwrap(), "/records", &[])
        .await
        .unwrap();
    assert_eq!(answer.status, 503);
    assert!(String::from_utf8_lossy(&answer.body).contains("no records"));
    let reports = race(&server, &["dee"]).await;
    let told = reports[0].standing.clone().expect("told");
    assert!(told.unwrap_err().contains("no records"));
    server.stop().await.unwrap();
}
