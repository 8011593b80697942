//! Records on PostgreSQL (`--records postgres://...`) over real QUIC, with
//! a throwaway cluster per test ([`ledge_tests::postgres`]): two servers
//! share one store and one top ten; the database going away mid-match
//! fails the runs finished meanwhile, not play, and records resume once it
//! is back; an unreachable database leaves the server playing without
//! records, saying so without the URL's password; a database down at start
//! is found once it is up, with no restart.
//!
//! Without PostgreSQL installed the first two are skipped loudly (they fail
//! under `CI=true`); the third needs none.

use std::net::{Ipv4Addr, SocketAddr, TcpListener};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use ledge_client::bot::{BotOptions, BotReport, Brain, RandomWalker, Runner};
use ledge_levels::default_route;
use ledge_server::records::writer::RETRIES;
use ledge_server::records::RecordsTarget;
use ledge_server::ServerConfig;
use ledge_shared::game::Game;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{PlayerId, MAX_TOP};
use ledge_tests::e2e::{assert_steady, bot_options, spawn_bot, TickProbe};
use ledge_tests::logs;
use ledge_tests::postgres::Postgres;
use ledge_tests::web::http_get_from;
use ledge_tests::{metric, TestServer};
use serde_json::Value;

use crate::records::{millis, race};
use crate::web_transports::{page, web_server};

/// How long a bot may take to finish the level and hear about its run.
const RUN_WITHIN: Duration = Duration::from_secs(30);

/// A server with the web port, storing runs at `url`.
async fn server_on(root: &std::path::Path, url: &str) -> TestServer {
    let url = url.to_owned();
    web_server(root, move |c| c.records = Some(RecordsTarget::Url(url))).await
}

/// `GET path` on the web port: the status and the body as JSON (`Null`
/// when it is not JSON).
async fn get(server: &TestServer, path: &str) -> (u16, Value) {
    let answer = http_get_from(None, server.web_addr.unwrap(), path, &[])
        .await
        .unwrap_or_else(|| panic!("GET {path} answered"));
    let doc = serde_json::from_slice(&answer.body).unwrap_or(Value::Null);
    (answer.status, doc)
}

/// A `/records/LEVEL` list: each entry's player and time.
fn listed(doc: &Value) -> Vec<(String, u64)> {
    doc["top"]
        .as_array()
        .expect("a top list")
        .iter()
        .map(|e| {
            (
                e["player"].as_str().unwrap().to_owned(),
                e["millis"].as_u64().unwrap(),
            )
        })
        .collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn two_servers_share_one_postgres_and_one_fleet_top_ten() {
    let Some(pg) =
        Postgres::start("records_postgres::two_servers_share_one_postgres_and_one_fleet_top_ten")
    else {
        return;
    };
    let root = page();
    // Started together: both migrate the new database at once (under the
    // schema's advisory lock).
    let (a, b) = tokio::join!(
        server_on(root.path(), pg.url()),
        server_on(root.path(), pg.url())
    );
    assert_eq!(a.level_offer, b.level_offer, "one level");
    let hash = a.level_offer.hex();

    // Twelve runs, six on each server, at the same time: more than a top
    // ten.
    let on_a = ["ann", "bob", "cid", "dan", "eli", "fay"];
    let on_b = ["gus", "hal", "ivy", "jon", "kim", "lea"];
    let (reports_a, reports_b) = tokio::join!(race(&a, &on_a), race(&b, &on_b));
    let reports: Vec<BotReport> = reports_a.into_iter().chain(reports_b).collect();
    let runs = reports.len();
    let mut times = Vec::new();
    for r in &reports {
        let ticks = r.finish_ticks.expect("a finish time");
        let standing = match r.standing.clone() {
            Some(Ok(standing)) => standing,
            other => panic!("{}: not told its run was recorded: {other:?}", r.name),
        };
        assert_eq!(standing.millis, millis(ticks), "{}", r.name);
        assert!(
            standing.new_personal_best,
            "{}: a first run is a best",
            r.name
        );
        assert!(
            (1..=runs as u32).contains(&standing.rank),
            "{}: rank {}",
            r.name,
            standing.rank
        );
        assert!(
            standing.top.windows(2).all(|w| w[0].millis <= w[1].millis),
            "{}: its top ten is fastest first: {:?}",
            r.name,
            standing.top
        );
        times.push((r.name.clone(), millis(ticks)));
    }

    // Either server lists the same top ten, from both servers' runs,
    // fastest first.
    let path = format!("/records/{hash}?n={MAX_TOP}");
    let (status_a, doc_a) = get(&a, &path).await;
    let (status_b, doc_b) = get(&b, &path).await;
    assert_eq!((status_a, status_b), (200, 200));
    assert_eq!(doc_a, doc_b, "both servers list the same records");
    assert_eq!(doc_a["level"]["runs"], runs);
    assert_eq!(doc_a["level"]["players"], runs);
    let top = listed(&doc_a);
    assert_eq!(top.len(), MAX_TOP, "a top ten of {runs} runs: {top:?}");
    assert!(
        top.windows(2).all(|w| w[0].1 <= w[1].1),
        "fastest first: {top:?}"
    );
    for entry in &top {
        assert!(times.contains(entry), "{entry:?} is a run of the race");
    }
    let slowest_listed = top.last().unwrap().1;
    for run in times.iter().filter(|t| !top.contains(t)) {
        assert!(
            run.1 >= slowest_listed,
            "{run:?} is faster than the top ten"
        );
    }
    let from = |names: &[&str]| top.iter().filter(|(p, _)| names.contains(&&**p)).count();
    // Ten of twelve: at least four from each server.
    assert!(from(&on_a) >= 4 && from(&on_b) >= 4, "{top:?}");
    let (_, levels) = get(&b, "/records").await;
    assert_eq!(levels["levels"][0]["runs"], runs);

    a.stop().await.unwrap();
    b.stop().await.unwrap();
}

/// A brain that is done once `release` is set (with `stop_when_done`, the
/// bot then leaves), not before: a runner at the goal stays to hear about
/// its run however long the server takes.
struct Until<B> {
    inner: B,
    release: Arc<AtomicBool>,
}

impl<B: Brain> Brain for Until<B> {
    fn name(&self) -> &'static str {
        self.inner.name()
    }

    fn buttons(&mut self, game: &Game, me: PlayerId) -> Buttons {
        self.inner.buttons(game, me)
    }

    fn done(&self) -> bool {
        self.release.load(Ordering::Relaxed)
    }

    fn on_correction(&mut self) {
        self.inner.on_correction();
    }

    fn progress(&self) -> String {
        self.inner.progress()
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn postgres_going_away_mid_match_fails_the_run_not_play_and_records_resume() {
    let logs = logs::capture();
    let Some(mut pg) = Postgres::start(
        "records_postgres::postgres_going_away_mid_match_fails_the_run_not_play_and_records_resume",
    ) else {
        return;
    };
    let root = page();
    let server = server_on(root.path(), pg.url()).await;
    let hash = server.level_offer.hex();
    // The web port's query leaves a connection in the pool, which the
    // outage breaks.
    let (status, doc) = get(&server, "/records").await;
    assert_eq!(
        (status, doc["levels"].as_array().map(Vec::len)),
        (200, Some(0))
    );

    // kai walks about through the outage; ray runs into it. Both leave
    // once the server has given up on ray's run.
    let release = Arc::new(AtomicBool::new(false));
    let long = Duration::from_secs(600);
    let play = |name: &str| BotOptions {
        stop_when_done: true,
        ..bot_options(name, long)
    };
    let kai = spawn_bot(
        server.join("kai").await,
        Until {
            inner: RandomWalker::new(7),
            release: release.clone(),
        },
        play("kai"),
    );
    let ray = spawn_bot(
        server.join("ray").await,
        Until {
            inner: Runner::new(default_route()),
            release: release.clone(),
        },
        play("ray"),
    );
    tokio::task::block_in_place(|| pg.stop());
    let outage = Instant::now();
    let before = TickProbe::read(&server, "room-1");

    // The web port says the database failed, and plays on.
    let (status, _) = get(&server, "/records").await;
    assert_eq!(status, 503, "records pages during the outage");
    // ray finishes; the writer retries, then gives up on its run.
    let ours = format!("@127.0.0.1:{}/", pg.port());
    let given_up = logs
        .wait_for(
            &["records: 1 runs not stored", &ours],
            RUN_WITHIN + Duration::from_secs(120),
        )
        .await
        .unwrap_or_else(|| panic!("the server never gave up on ray's run:\n{}", logs.text()));
    let gave_up_after = outage.elapsed();
    let after = TickProbe::read(&server, "room-1");
    release.store(true, Ordering::Relaxed);
    let (ray, _) = ray.await.expect("ray's task did not panic");
    let (kai, _) = kai.await.expect("kai's task did not panic");
    eprintln!("the server gave up {gave_up_after:?} into the outage: {given_up}");

    assert!(ray.won, "ray reached the goal: {}", ray.progress);
    assert!(ray.ended.is_none(), "ray played on: {:?}", ray.ended);
    let reason = match &ray.standing {
        Some(Err(reason)) => reason.clone(),
        other => panic!("ray was not told its run is not recorded: {other:?}"),
    };
    assert!(reason.contains("records database"), "{reason}");
    assert!(!reason.contains(pg.password()), "no password: {reason}");
    assert_eq!(
        logs.lines_with(&["records: storing 1 runs failed, retrying", &ours])
            .len(),
        RETRIES.len(),
        "the writer tried again and again before giving up:\n{}",
        logs.text()
    );
    assert!(
        !logs.text().contains(pg.password()),
        "the password stays out of the log"
    );
    assert!(
        metric(&server.metrics(), "ledge_records_failed_total") >= 1.0,
        "{}",
        server.metrics()
    );
    // Play went on: the room kept its tick rate and kai its snapshots.
    let tick_rate = f64::from(ServerConfig::default().tick_rate);
    assert_steady("during the outage", before.rate_until(&after), tick_rate);
    assert!(kai.ended.is_none(), "kai played on: {:?}", kai.ended);
    let expected = kai.played.as_secs_f64() * tick_rate;
    assert!(
        kai.covered_ticks as f64 >= expected * 0.8,
        "kai's snapshots covered {} of about {expected:.0} ticks",
        kai.covered_ticks
    );

    // The database is back: the next run is recorded, and listed alone.
    tokio::task::block_in_place(|| pg.restart());
    let again = race(&server, &["roy"]).await;
    match &again[0].standing {
        Some(Ok(standing)) => assert_eq!(standing.rank, 1),
        other => panic!("roy's run was not recorded after the outage: {other:?}"),
    }
    let (status, doc) = get(&server, &format!("/records/{hash}")).await;
    assert_eq!(status, 200);
    let names: Vec<String> = listed(&doc).into_iter().map(|(p, _)| p).collect();
    assert_eq!(names, ["roy"], "ray's run was not stored");
    server.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_server_whose_postgres_is_unreachable_plays_without_records() {
    let logs = logs::capture();
    // A port nothing listens on.
    let port = TcpListener::bind(SocketAddr::from((Ipv4Addr::LOCALHOST, 0)))
        .and_then(|l| l.local_addr())
        .unwrap()
        .port();
    let password = format!("unreachable{port}secret");
    let url = format!("postgres://ledge:{password}@127.0.0.1:{port}/records");
    let shown = format!("postgres://ledge:***@127.0.0.1:{port}/records");
    let root = page();
    let started = Instant::now();
    let server = server_on(root.path(), &url).await;

    let reports = race(&server, &["una"]).await;
    let told = reports[0].standing.clone().expect("told about its run");
    let reason = told.expect_err("not recorded");
    assert!(reason.contains("could not be opened"), "{reason}");
    let (status, _) = get(&server, "/records").await;
    assert_eq!(status, 503);
    let said = logs.lines_with(&["records are off", &shown]);
    assert!(
        !said.is_empty(),
        "the log says records are off, naming {shown}:\n{}",
        logs.text()
    );
    assert!(
        !logs.text().contains(&password),
        "the password stays out of the log"
    );
    eprintln!("played without records {:?} after start", started.elapsed());
    server.stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn records_down_at_start_come_on_once_postgres_is_up() {
    let logs = logs::capture();
    let Some(mut pg) =
        Postgres::start("records_postgres::records_down_at_start_come_on_once_postgres_is_up")
    else {
        return;
    };
    tokio::task::block_in_place(|| pg.stop());
    let root = page();
    let url = pg.url().to_owned();
    let server = web_server(root.path(), move |c| {
        c.records = Some(RecordsTarget::Url(url));
        c.records_retry = Duration::from_secs(1);
    })
    .await;
    // Down: play goes on, the run is not recorded.
    let first = race(&server, &["una"]).await;
    let told = first[0].standing.clone().expect("told about its run");
    assert!(told.is_err(), "not recorded while the database is down");
    // Up: the server finds it by itself and stores the next run.
    tokio::task::block_in_place(|| pg.restart());
    logs.wait_for(&["records are on again"], Duration::from_secs(20))
        .await
        .unwrap_or_else(|| panic!("records never came on:\n{}", logs.text()));
    let second = race(&server, &["una"]).await;
    let standing = second[0].standing.clone().unwrap().expect("recorded");
    assert!(standing.new_personal_best, "her first stored run");
    let (status, doc) = get(&server, &format!("/records/{}", server.level_offer.hex())).await;
    assert_eq!(status, 200);
    assert_eq!(listed(&doc).len(), 1);
    server.stop().await.unwrap();
}
