//! The browser page plays a replay (`/?replay=ID`) end to end: a runner
//! bot finishes a level (a copy of the default level under another name:
//! not the page's embedded one, so the page downloads it) on a real server
//! that keeps replays and serves the real page (`scripts/build-web`) on
//! its web port; the records page links the run's replay as "watch";
//! headless Chromium opens that link with `&follow=bob`, the replay plays
//! (its tick advances), and paused with the Space key, the followed player
//! stands exactly where a headless `Playback` of the same file and level
//! (both fetched over HTTP) has him at that tick.
//!
//! What does not play says why on the page (`window.ledgeState.replay.
//! error`): a replay the server does not have (404: the server's words),
//! a damaged file (the replay's own error), a level the server does not
//! have, a replay that plays differently from the server's hashes (from
//! which tick).
//!
//! Without `chromium` these tests print a loud SKIPPED notice and pass,
//! except with `CI=true`, where they fail.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use ledge_levels::{default_level, LevelBundle};
use ledge_server::config::WebConfig;
use ledge_server::replays::ReplaysTarget;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::replay::{self, Event, Playback, ReplayError, ReplayKind};
use ledge_tests::browser::{build_web, skip_without_chromium, Browser, Key, Page};
use ledge_tests::web::http_get_from;
use ledge_tests::TestServer;
use serde_json::Value;

use crate::records::race;

/// A server on its own runtime serving the freshly built page on a web
/// port (loopback, WebSocket only: the replay needs no game connection),
/// playing `levels` (empty: the default level) and keeping its replays in
/// `replays`.
fn replay_server(replays: &Path, levels: Vec<PathBuf>) -> (tokio::runtime::Runtime, TestServer) {
    let dist = build_web();
    let folder = replays.to_owned();
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    let server = runtime.block_on(TestServer::start_with(move |c| {
        let mut web = WebConfig::new(SocketAddr::from(([127, 0, 0, 1], 0)));
        web.root = dist;
        web.webtransport = None;
        c.web = Some(web);
        c.replays = Some(ReplaysTarget::Dir(folder));
        if !levels.is_empty() {
            c.levels = levels;
        }
    }));
    (runtime, server)
}

/// The page's state (`window.ledgeState`).
fn state(page: &mut Page) -> Value {
    page.eval("window.ledgeState || null")
        .expect("read the page's state")
}

/// The body of `GET path` on the web port (status 200 asserted).
fn get(runtime: &tokio::runtime::Runtime, web: SocketAddr, path: &str, html: bool) -> Vec<u8> {
    let headers: &[(&str, &str)] = if html {
        &[("Accept", "text/html")]
    } else {
        &[]
    };
    let answer = runtime
        .block_on(http_get_from(None, web, path, headers))
        .unwrap_or_else(|| panic!("GET {path} answered"));
    assert_eq!(answer.status, 200, "GET {path}: {}", answer.head);
    answer.body
}

/// The replay id the records give `name`'s run (stored once its replay
/// file is written: up to 10 s after the finish).
fn replay_id_of(runtime: &tokio::runtime::Runtime, server: &TestServer, name: &str) -> String {
    let web = server.web_addr.expect("the web port");
    let path = format!("/records/{}", server.level_offer.hex());
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        let doc: Value =
            serde_json::from_slice(&get(runtime, web, &path, false)).expect("the records are JSON");
        let id = doc["top"].as_array().and_then(|top| {
            top.iter()
                .find(|e| e["player"] == name)
                .and_then(|e| e["replay"].as_str().map(str::to_owned))
        });
        if let Some(id) = id {
            return id;
        }
        assert!(
            Instant::now() < deadline,
            "{name}'s run has a replay in the records: {doc}"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// Opens `url` in a new tab of `browser` and waits until the page says
/// something about its replay satisfying `condition` (JS, on `r`, the
/// state's `replay`).
fn open_replay(browser: &Browser, url: &str, condition: &str) -> Page {
    let mut page = browser.new_page().expect("a tab");
    page.open(url).expect("the page loads");
    let js = format!(
        "(() => {{ const r = window.ledgeState && ledgeState.replay; return !!(r && ({condition})); }})()"
    );
    if let Err(e) = page.wait_until(&js, Duration::from_secs(60)) {
        panic!(
            "{url}: not {condition}: {e}\nstate: {}\nconsole:\n{}",
            state(&mut page),
            page.console_text()
        );
    }
    page
}

#[test]
fn the_page_plays_a_runs_replay_exactly_as_the_headless_playback() {
    if skip_without_chromium("browser_replay") {
        return;
    }
    let folder = tempfile::tempdir().unwrap();
    let levels = tempfile::tempdir().unwrap();
    let second = crate::rotation::two_levels(levels.path()).pop().unwrap();
    let (runtime, server) = replay_server(folder.path(), vec![second]);
    let web = server.web_addr.expect("the web port");
    let offer = server.level_offer;
    assert_ne!(
        offer,
        ledge_client::net::download::embedded().1,
        "not the page's own level"
    );
    runtime.block_on(race(&server, &["bob"]));
    let id = replay_id_of(&runtime, &server, "bob");

    // The records page links it as "watch", to the page.
    let html = String::from_utf8(get(&runtime, web, "/records", true)).unwrap();
    let watch = format!("<a href=\"/?replay={id}\">watch</a>");
    assert!(html.contains(&watch), "{watch} in the records page: {html}");

    // The same file and level, as the page fetches them, played headless.
    let bytes = get(&runtime, web, &format!("/replays/{id}"), false);
    let run = replay::decode(&bytes).expect("the served replay decodes");
    assert_eq!(run.header.level, offer);
    let ReplayKind::Run { player: bob, .. } = run.header.kind else {
        panic!("{id} is a {:?}", run.header.kind);
    };
    let level_path = format!("/levels/{}", offer.hex());
    let level = LevelBundle::decode(&get(&runtime, web, &level_path, false))
        .expect("the served level decodes")
        .level;
    let mut playback = Playback::new(&level, run.clone()).expect("it plays");

    let browser = Browser::launch().expect("launch chromium");
    let url = format!("http://{web}/?replay={id}&follow=bob");
    let mut page = open_replay(&browser, &url, "r.tick !== undefined");
    let first = state(&mut page);
    let r = &first["replay"];
    assert_eq!(r["id"], id.as_str(), "{first}");
    assert_eq!(r["following"], "bob", "{first}");
    assert_eq!(r["error"], Value::Null, "{first}");
    assert_eq!(r["ticks"], run.ticks(), "{first}");
    // Its level downloaded from the server, not the embedded one.
    assert_eq!(r["level"]["name"], "second", "{first}");
    assert_eq!(
        r["level"]["from"],
        format!("http://{web}{level_path}"),
        "{first}"
    );
    let tick0 = r["tick"].as_u64().expect("a tick");
    let started = Instant::now();
    page.wait_until(
        &format!("ledgeState.replay.tick >= {}", tick0 + 60),
        Duration::from_secs(30),
    )
    .unwrap_or_else(|e| panic!("the replay plays on: {e}: {}", state(&mut page)));
    let rate = (state(&mut page)["replay"]["tick"].as_u64().unwrap() - tick0) as f64
        / started.elapsed().as_secs_f64();
    eprintln!("browser_replay: the page plays {rate:.1} ticks/s at 1x");

    // Space pauses; the state then holds still.
    page.press(Key::Space).expect("presses Space");
    page.wait_until("ledgeState.replay.paused === true", Duration::from_secs(10))
        .unwrap_or_else(|e| panic!("Space pauses: {e}: {}", state(&mut page)));
    std::thread::sleep(Duration::from_millis(300));
    let paused = state(&mut page);
    std::thread::sleep(Duration::from_millis(300));
    let later = state(&mut page);
    let r = &paused["replay"];
    assert_eq!(r["tick"], later["replay"]["tick"], "paused: {later}");
    let tick = r["tick"].as_u64().unwrap();
    assert!(tick >= tick0 + 60, "{paused}");

    // Exactly where the headless playback has bob at that tick.
    playback.seek(tick).expect("the playback seeks");
    let pos = playback.game().player(bob).expect("bob plays").pos;
    let px = |u: i32| f64::from(u) / f64::from(UNITS_PER_PX);
    let expected = [px(pos.x), px(pos.y)];
    let reported = [0, 1].map(|i| r["follow_pos"][i].as_f64().expect("follow_pos"));
    assert_eq!(reported, expected, "bob at tick {tick}: {paused}");
    assert_eq!(paused["me"]["x"].as_f64(), Some(expected[0]), "{paused}");
    // Drawn as ours (the followed player), where he is (blended between
    // the last two ticks: within a tick's move).
    let players = paused["players"].as_array().expect("players drawn");
    let drawn = players
        .iter()
        .find(|p| p["name"] == "bob")
        .unwrap_or_else(|| panic!("bob is drawn: {paused}"));
    assert_eq!(drawn["local"], true, "{paused}");
    for i in 0..2 {
        let at = drawn["world"][i].as_f64().unwrap();
        assert!(
            (at - expected[i]).abs() < 16.0,
            "bob drawn at {at}, {} in the playback: {paused}",
            expected[i]
        );
    }

    // `speed` and `seek` (seconds into the replay, as the HUD counts).
    let url = format!("http://{web}/?replay={id}&follow=bob&speed=4&seek=3");
    let mut page = open_replay(&browser, &url, "r.tick !== undefined");
    let s = state(&mut page);
    let r = &s["replay"];
    assert_eq!(r["speed"], 4.0, "{s}");
    let start = r["start_tick"].as_u64().unwrap();
    assert!(
        r["tick"].as_u64().unwrap() >= start + 180,
        "opened 3 s in: {s}"
    );
    assert!(
        r["clock"].as_str().unwrap().contains("4x"),
        "the HUD says the speed: {s}"
    );
    drop(browser);
    runtime.block_on(server.stop()).unwrap();
}

#[test]
fn the_page_says_why_a_replay_does_not_play() {
    if skip_without_chromium("browser_replay errors") {
        return;
    }
    let folder = tempfile::tempdir().unwrap();
    let (runtime, server) = replay_server(folder.path(), Vec::new());
    let web = server.web_addr.expect("the web port");
    runtime.block_on(race(&server, &["ann"]));
    let id = replay_id_of(&runtime, &server, "ann");
    let bytes = get(&runtime, web, &format!("/replays/{id}"), false);
    let browser = Browser::launch().expect("launch chromium");

    // No such replay: the server's 404, in its words.
    let none = "0000000000000000";
    let mut page = open_replay(&browser, &format!("http://{web}/?replay={none}"), "r.error");
    let s = state(&mut page);
    let error = s["replay"]["error"].as_str().unwrap();
    assert!(
        error.contains("404") && error.contains(&format!("no replay {none} here")),
        "{s}"
    );
    assert_eq!(s["failure"], error, "{s}");

    // A damaged file (one byte of its body changed): the replay's own
    // error.
    let mut damaged = bytes.clone();
    let last = damaged.len() - 1;
    damaged[last] ^= 0x55;
    let why = replay::decode(&damaged).expect_err("damaged").to_string();
    let bad = "00000000000000da";
    std::fs::write(folder.path().join(format!("{bad}.ledgereplay")), &damaged).unwrap();
    let mut page = open_replay(&browser, &format!("http://{web}/?replay={bad}"), "r.error");
    let s = state(&mut page);
    let error = s["replay"]["error"].as_str().unwrap();
    assert!(
        error.contains(&why) && error.contains("download it again"),
        "{why}: {s}"
    );

    // A replay of a level the server does not have: which level, and what
    // the server says.
    let mut elsewhere = replay::decode(&bytes).unwrap();
    elsewhere.header.level.sha256 = [0xab; 32];
    let other = "00000000000001e7";
    let file = folder.path().join(format!("{other}.ledgereplay"));
    std::fs::write(file, replay::encode(&elsewhere).unwrap()).unwrap();
    let mut page = open_replay(
        &browser,
        &format!("http://{web}/?replay={other}"),
        "r.error",
    );
    let s = state(&mut page);
    let error = s["replay"]["error"].as_str().unwrap();
    let hex = "ab".repeat(32);
    assert!(
        error.contains(&format!("/levels/{hex}"))
            && error.contains("404")
            && error.contains(&format!("does not play level {hex}"))
            && error.contains("--level FILE"),
        "{s}"
    );

    // A replay whose server hashes say otherwise half way: it plays up to
    // there, then says from which tick it differs.
    let mut replay = replay::decode(&bytes).unwrap();
    let hashes = replay
        .events
        .iter()
        .filter(|e| matches!(e, Event::Hash(_)))
        .count();
    let mut seen = 0;
    for e in &mut replay.events {
        if let Event::Hash(h) = e {
            seen += 1;
            if seen == hashes / 2 {
                *h ^= 1;
            }
        }
    }
    let mut headless = Playback::new(&default_level(), replay.clone()).unwrap();
    let Err(ReplayError::Diverged { tick, .. }) = headless.play_to_end() else {
        panic!("the changed replay diverges headless");
    };
    let diverged = "000000000000d1ff";
    let file = folder.path().join(format!("{diverged}.ledgereplay"));
    std::fs::write(file, replay::encode(&replay).unwrap()).unwrap();
    let rate = f64::from(replay.header.tick_rate);
    let seek = ((tick - replay.start_tick()) as f64 / rate - 1.0).max(0.0);
    let url = format!("http://{web}/?replay={diverged}&seek={seek:.2}&follow=ann");
    let mut page = open_replay(&browser, &url, "r.error");
    let s = state(&mut page);
    let error = s["replay"]["error"].as_str().unwrap();
    assert!(
        error.contains(&format!("from tick {tick}")),
        "diverges at {tick}: {s}"
    );
    assert!(s["replay"]["tick"].as_u64().unwrap() <= tick, "{s}");
    drop(browser);
    runtime.block_on(server.stop()).unwrap();
}
