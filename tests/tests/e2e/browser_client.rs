//! The browser client end to end: the real web page (`scripts/build-web`:
//! the client's wasm, miniquad's loader, ledge's glue) served by a real
//! server's web port, in headless Chromium, once over WebTransport and once
//! with WebTransport removed from the page (the WebSocket fallback, chosen
//! by the page itself).
//!
//! Each time the page joins room "friends", where a native player ("bob")
//! stands; real key events (held Right, then Space) move the page's player,
//! and bob's session, fed by the server, sees it move; the screenshot shows
//! the level (ground and grass in the level's colours), our player, and bob
//! in his colour where the page says it drew him.
//!
//! A page opened with `?spectate&follow=bob` watches a native runner in a
//! one-player room: it takes no place, draws bob only, and sees him run.
//! A page in a two-level rotation follows its room to the next level
//! (downloaded in the page) and plays on there.
//!
//! Without `chromium` these tests print a loud SKIPPED notice and pass,
//! except with `CI=true`, where they fail.

use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use ledge_client::{JoinOptions, SessionEvent};
use ledge_server::config::WebConfig;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::protocol::PlayerId;
use ledge_tests::browser::{build_web, skip_without_chromium, Browser, Key, Options, Page};
use ledge_tests::TestServer;
use serde_json::Value;

/// A server on its own runtime serving the freshly built page on a web
/// port (loopback, WebTransport on), after `adjust` changed its settings.
fn web_server(
    adjust: impl FnOnce(&mut ledge_server::ServerConfig),
) -> (tokio::runtime::Runtime, TestServer) {
    let dist = build_web();
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    let server = runtime.block_on(TestServer::start_with(move |c| {
        let mut web = WebConfig::new(SocketAddr::from(([127, 0, 0, 1], 0)));
        web.root = dist;
        c.web = Some(web);
        adjust(c);
    }));
    (runtime, server)
}

/// Where the server says each player is (x, world pixels), by name, as
/// bob's session hears it.
type Seen = Arc<Mutex<BTreeMap<String, Vec<f64>>>>;

/// Joins room "friends" as bob (a native QUIC client that stands still)
/// and records every player's x from the server's snapshots.
async fn bob(server: SocketAddr, fingerprint: ledge_client::Fingerprint, seen: Seen) {
    let mut session = ledge_client::connect_with(
        server,
        "localhost",
        fingerprint,
        &JoinOptions {
            room: Some("friends".into()),
            ..JoinOptions::new("bob")
        },
    )
    .await
    .expect("bob joins");
    let mut tick = session.welcome().server_tick;
    loop {
        let event = tokio::time::timeout(Duration::from_millis(16), session.recv()).await;
        tick += 1;
        let _ = session.send_input(tick, ledge_shared::input::Buttons::NONE);
        let update = match event {
            Ok(Ok(SessionEvent::Snapshot(update))) => update,
            Ok(Ok(_)) | Err(_) => continue,
            // The session ended (the server stopped).
            Ok(Err(_)) => return,
        };
        if let Some(last) = update.last_input_tick {
            tick = tick.max(last + 4);
        }
        let names: BTreeMap<PlayerId, String> = session.players().clone();
        let mut seen = seen.lock().unwrap();
        for (id, name) in names {
            if let Some(e) = update.state.get(id.0) {
                let x = f64::from(e.pos.x) / f64::from(UNITS_PER_PX);
                seen.entry(name).or_default().push(x);
            }
        }
    }
}

/// The page's state (`window.ledgeState`).
fn state(page: &mut Page) -> Value {
    page.eval("window.ledgeState || null")
        .expect("read the page's state")
}

/// The page's state and a screenshot of the frame it describes: the
/// players' drawn rectangles read before and after the screenshot agree
/// (else the camera or a player was still moving: a loaded machine may
/// draw a frame between the two reads, so it tries again).
fn still_screenshot(page: &mut Page, transport: &str) -> (Value, Vec<u8>) {
    let drawn = |s: &Value| s["players"].clone();
    let mut last = Value::Null;
    for _ in 0..30 {
        let before = state(page);
        let png = page.screenshot_png().expect("a screenshot");
        let after = state(page);
        if drawn(&before) == drawn(&after) {
            return (before, png);
        }
        last = after;
        std::thread::sleep(Duration::from_millis(100));
    }
    panic!("{transport}: the page never held still for a screenshot in 3 s: {last}");
}

/// Pixels of `png` (RGBA) within `tolerance` of `rgb` inside `rect`
/// (x, y, w, h), and how many pixels the rect held.
fn count(png: &[u8], rect: [f64; 4], rgb: [u8; 3], tolerance: i32) -> (u32, u32) {
    let decoder = png::Decoder::new(png);
    let mut reader = decoder.read_info().expect("a PNG");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("a frame");
    let channels = info.color_type.samples();
    let (w, h) = (info.width as i64, info.height as i64);
    let (mut hits, mut total) = (0, 0);
    let x0 = (rect[0].floor() as i64).clamp(0, w);
    let y0 = (rect[1].floor() as i64).clamp(0, h);
    let x1 = ((rect[0] + rect[2]).ceil() as i64).clamp(0, w);
    let y1 = ((rect[1] + rect[3]).ceil() as i64).clamp(0, h);
    for y in y0..y1 {
        for x in x0..x1 {
            let at = ((y * w + x) as usize) * channels;
            let p = &buf[at..at + 3];
            total += 1;
            if (0..3).all(|i| (i32::from(p[i]) - i32::from(rgb[i])).abs() <= tolerance) {
                hits += 1;
            }
        }
    }
    (hits, total)
}

fn rgb_of(v: &Value) -> [u8; 3] {
    let a = v.as_array().expect("an RGB triple");
    [0, 1, 2].map(|i| a[i].as_u64().expect("a byte") as u8)
}

fn rect_of(v: &Value) -> [f64; 4] {
    let a = v.as_array().expect("a rectangle");
    [0, 1, 2, 3].map(|i| a[i].as_f64().expect("a number"))
}

/// Plays once in a fresh browser: joins, moves, checks what the server and
/// the screenshot say. `webtransport`: whether the browser has it.
fn play(web: SocketAddr, name: &str, webtransport: bool, seen: &Seen) {
    let transport = if webtransport {
        "WebTransport"
    } else {
        "WebSocket"
    };
    let browser = Browser::launch_with(Options {
        webtransport,
        ..Options::default()
    })
    .expect("launch chromium");
    let mut page = browser.new_page().expect("a tab");
    let url = format!("http://{web}/?name={name}&room=friends");
    page.open(&url).expect("the page loads");
    let joined = page.wait_until(
        "window.ledgeState && ledgeState.joined && ledgeState.players.length >= 2",
        Duration::from_secs(30),
    );
    if let Err(e) = joined {
        panic!(
            "{transport}: not joined with bob drawn: {e}\nstate: {}\nconsole:\n{}",
            state(&mut page),
            page.console_text()
        );
    }
    let s = state(&mut page);
    let status = s["status"].as_str().unwrap_or_default();
    assert!(
        status.contains("friends") && status.contains(&format!("via {transport}")),
        "{transport}: the status line says where and how: {status}"
    );
    let x0 = s["me"]["x"].as_f64().expect("our position");

    // Real keys: hold Right, jumping on the way (Space held a few frames:
    // the game reads held buttons each tick), until the page has us
    // `WALK` px right of the start. A distance, not a time: on a loaded
    // machine a key held "1.5 s" walked far enough to put bob (standing
    // at the start) off the screen the camera keeps centred on us.
    const WALK: f64 = 150.0;
    page.key_down(Key::ArrowRight).unwrap();
    std::thread::sleep(Duration::from_millis(350));
    page.key_down(Key::Space).unwrap();
    std::thread::sleep(Duration::from_millis(250));
    page.key_up(Key::Space).unwrap();
    let walked = page.wait_until(
        &format!("ledgeState.me.x > {}", x0 + WALK),
        Duration::from_secs(10),
    );
    page.key_up(Key::ArrowRight).unwrap();
    if let Err(e) = walked {
        panic!("{transport}: holding Right did not move us {WALK} px right: {e}");
    }
    std::thread::sleep(Duration::from_millis(300));

    let (s, png) = still_screenshot(&mut page, transport);
    let x1 = s["me"]["x"].as_f64().expect("our position");
    assert!(
        x1 > x0 + 60.0,
        "{transport}: the held key moved us right on the page: {x0} -> {x1}"
    );
    // The server saw it: bob's snapshots put us far right of where we
    // started.
    let server_xs = seen.lock().unwrap().get(name).cloned().unwrap_or_default();
    let (first, last) = (
        server_xs.first().copied().unwrap_or(0.0),
        server_xs.iter().copied().fold(f64::MIN, f64::max),
    );
    assert!(
        last > first + 60.0,
        "{transport}: the server moved {name}: {first} -> {last} ({} snapshots)",
        server_xs.len()
    );

    // The screenshot: the level, us, bob.
    std::fs::write(
        std::env::temp_dir().join(format!("ledge-browser-{transport}.png")),
        &png,
    )
    .ok();
    let whole = [0.0, 0.0, 960.0, 540.0];
    let palette = &s["palette"];
    let (solid, total) = count(&png, whole, rgb_of(&palette["solid"]), 6);
    let (grass, _) = count(&png, whole, rgb_of(&palette["grass"]), 6);
    assert!(
        solid * 20 > total && grass > 200,
        "{transport}: the level is drawn: {solid} ground and {grass} grass pixels of {total}"
    );
    let players = s["players"].as_array().expect("players drawn");
    for who in [name, "bob"] {
        let p = players
            .iter()
            .find(|p| p["name"] == who)
            .unwrap_or_else(|| panic!("{transport}: {who} is drawn: {s}"));
        let (hits, pixels) = count(&png, rect_of(&p["screen"]), rgb_of(&p["rgb"]), 24);
        assert!(
            hits * 5 > pixels,
            "{transport}: {who} is on the screenshot in its colour where the page drew it: \
             {hits} of {pixels} pixels ({})",
            p
        );
    }
    assert_eq!(s["failure"], Value::Null, "{transport}: no failure shown");
}

#[test]
fn a_browser_joins_over_webtransport_and_over_websocket_plays_and_sees_a_native_player() {
    if skip_without_chromium("browser_client") {
        return;
    }
    let (runtime, server) = web_server(|c| {
        // Bob only stands there.
        c.idle_kick = Duration::from_secs(600);
    });
    let web = server.web_addr.expect("the web port");
    let seen: Seen = Arc::default();
    runtime.spawn(bob(server.addr, server.fingerprint, seen.clone()));

    play(web, "ada", true, &seen);
    play(web, "cy", false, &seen);

    let m = server.metrics();
    for transport in ["webtransport", "websocket"] {
        let opened = ledge_tests::metric(
            &m,
            &format!("ledge_transport_connections_opened_total{{transport=\"{transport}\"}}"),
        );
        assert!(
            opened >= 1.0,
            "a {transport} connection was counted: {opened}"
        );
    }
    runtime.block_on(server.stop()).unwrap();
}

/// A standard-mapping gamepad the page sees through `navigator.getGamepads`
/// (headless Chromium has no gamepads and the DevTools protocol cannot make
/// one): `window.fakePad.buttons[i].pressed` and `.axes` are the test's.
const FAKE_GAMEPAD: &str = r#"
window.fakePad = {
  connected: true, mapping: "standard", id: "ledge test pad", index: 0,
  axes: [0, 0, 0, 0],
  buttons: Array.from({ length: 17 }, () => ({ pressed: false, value: 0 })),
};
navigator.getGamepads = () => [window.fakePad, null, null, null];
"#;

#[test]
fn a_gamepad_moves_and_jumps_the_player_in_the_page() {
    if skip_without_chromium("browser_client gamepad") {
        return;
    }
    // The page alone (offline: the embedded level), from a server's web
    // port.
    let (runtime, server) = web_server(|c| {
        if let Some(web) = &mut c.web {
            web.webtransport = None;
        }
    });
    let web = server.web_addr.expect("the web port");
    let browser = Browser::launch().expect("launch chromium");
    let mut page = browser.new_page().expect("a tab");
    page.call(
        "Page.addScriptToEvaluateOnNewDocument",
        serde_json::json!({ "source": FAKE_GAMEPAD }),
    )
    .expect("install the fake gamepad");
    page.open(&format!("http://{web}/?offline&name=pad"))
        .expect("the page loads");
    page.wait_until(
        "window.ledgeState && ledgeState.joined && ledgeState.me",
        Duration::from_secs(20),
    )
    .unwrap_or_else(|e| panic!("the offline game starts: {e}\n{}", page.console_text()));
    let start = state(&mut page);
    let (x0, y0) = (
        start["me"]["x"].as_f64().unwrap(),
        start["me"]["y"].as_f64().unwrap(),
    );

    // The d-pad's right (button 15) for a second: we walk right.
    page.eval("fakePad.buttons[15].pressed = true").unwrap();
    std::thread::sleep(Duration::from_millis(1000));
    page.eval("fakePad.buttons[15].pressed = false").unwrap();
    std::thread::sleep(Duration::from_millis(200));
    let walked = state(&mut page);
    let x1 = walked["me"]["x"].as_f64().unwrap();
    // (The crate 50 px to the right stops us there.)
    assert!(x1 > x0 + 30.0, "the d-pad walked us right: {x0} -> {x1}");

    // The south button (0) jumps: we rise above the ground we stood on.
    page.eval("fakePad.buttons[0].pressed = true").unwrap();
    let rose = page.wait_until(
        &format!(
            "ledgeState.me.y < {} - 20",
            walked["me"]["y"].as_f64().unwrap()
        ),
        Duration::from_secs(3),
    );
    page.eval("fakePad.buttons[0].pressed = false").unwrap();
    rose.unwrap_or_else(|e| panic!("button 0 jumped: {e}: {}", state(&mut page)));

    // The left stick past half way walks left.
    std::thread::sleep(Duration::from_millis(600));
    let before = state(&mut page)["me"]["x"].as_f64().unwrap();
    page.eval("fakePad.axes[0] = -1").unwrap();
    std::thread::sleep(Duration::from_millis(600));
    page.eval("fakePad.axes[0] = 0").unwrap();
    let after = state(&mut page)["me"]["x"].as_f64().unwrap();
    assert!(
        after < before - 30.0,
        "the stick walked us left: {before} -> {after}"
    );
    assert!(y0 > 0.0);
    drop(browser);
    runtime.block_on(server.stop()).unwrap();
}

#[test]
fn a_browser_spectates_a_runner_without_a_body() {
    if skip_without_chromium("browser_client spectate") {
        return;
    }
    // One player's place, taken by a native runner bot; WebSocket only.
    let (runtime, server) = web_server(|c| {
        c.max_players = 1;
        if let Some(web) = &mut c.web {
            web.webtransport = None;
        }
    });
    let web = server.web_addr.expect("the web port");
    let (addr, fingerprint) = (server.addr.to_string(), server.fingerprint);
    let bot = runtime.spawn(async move {
        let mut runner = ledge_client::bot::Runner::new(ledge_levels::default_route());
        let options = ledge_client::bot::BotOptions {
            stop_when_done: true,
            ..ledge_client::bot::BotOptions::new("bob", Duration::from_secs(40))
        };
        ledge_client::bot::connect_and_run(
            &addr,
            &ledge_client::net::trust::Trust::Pinned(fingerprint),
            &mut runner as &mut dyn ledge_client::bot::Brain,
            &options,
        )
        .await
    });
    let browser = Browser::launch().expect("launch chromium");
    let mut page = browser.new_page().expect("a tab");
    page.open(&format!("http://{web}/?spectate&follow=bob&name=sam"))
        .expect("the page loads");
    page.wait_until(
        "window.ledgeState && ledgeState.joined && ledgeState.players.some(p => p.name == 'bob')",
        Duration::from_secs(30),
    )
    .unwrap_or_else(|e| panic!("the spectator sees bob: {e}\n{}", page.console_text()));
    let first = state(&mut page);
    assert_eq!(first["spectating"], true, "{first}");
    // No body of ours: the one player drawn is bob, followed (drawn as
    // the one the camera is on), and nobody is called sam.
    let drawn = first["players"].as_array().unwrap();
    assert_eq!(drawn.len(), 1, "{first}");
    assert_eq!(drawn[0]["name"], "bob", "{first}");
    assert!(
        first["status"].as_str().unwrap().starts_with("spectating"),
        "{first}"
    );
    let bob_x = |s: &Value| {
        s["players"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == "bob")
            .map(|p| p["world"][0].as_f64().unwrap())
    };
    let x0 = bob_x(&first).unwrap();
    // bob runs the route: the page draws him moving.
    page.wait_until(
        &format!(
            "ledgeState.players.some(p => p.name == 'bob' && Math.abs(p.world[0] - {x0}) > 100)"
        ),
        Duration::from_secs(20),
    )
    .unwrap_or_else(|e| panic!("bob moves on the page: {e}: {}", state(&mut page)));
    let report = runtime.block_on(bot).expect("the bot task");
    assert!(
        report.won,
        "bob reached the goal beside a spectator: {report}"
    );
    drop(browser);
    runtime.block_on(server.stop()).unwrap();
}

/// A page in a room of a two-level rotation follows the room to the next
/// level when its time is up: re-welcomed, the level downloaded in the
/// page (not the embedded one), the page's `ledgeState.level` names it,
/// and held Right still moves us there.
#[test]
fn a_browser_follows_its_room_to_the_next_level_and_plays_on() {
    if skip_without_chromium("browser_client level change") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let levels = crate::rotation::two_levels(dir.path());
    let (runtime, server) = web_server(move |c| {
        c.levels = levels;
        c.rooms = 1;
        c.rotation = ledge_server::config::RotationConfig {
            level_time: Some(Duration::from_secs(6)),
            results_time: Duration::from_secs(1),
            vote: ledge_shared::protocol::VoteRule::Off,
        };
        if let Some(web) = &mut c.web {
            web.webtransport = None;
        }
    });
    let web = server.web_addr.expect("the web port");
    let browser = Browser::launch().expect("launch chromium");
    let mut page = browser.new_page().expect("a tab");
    page.open(&format!("http://{web}/?name=ann"))
        .expect("the page loads");
    page.wait_until(
        "window.ledgeState && ledgeState.joined && ledgeState.level && ledgeState.me",
        Duration::from_secs(30),
    )
    .unwrap_or_else(|e| panic!("the page joins: {e}\n{}", page.console_text()));
    let first = state(&mut page);
    assert_eq!(first["level"]["id"], "default", "{first}");
    assert_eq!(first["level"]["changes"], 0, "{first}");

    // The level's time runs out: the room moves to "second", which the
    // page has to download.
    page.wait_until(
        "ledgeState.level && ledgeState.level.id == 'second' && ledgeState.joined && ledgeState.me",
        Duration::from_secs(30),
    )
    .unwrap_or_else(|e| {
        panic!(
            "the page moves on: {e}\n{}\n{}",
            state(&mut page),
            page.console_text()
        )
    });
    let moved = state(&mut page);
    assert_eq!(moved["level"]["changes"], 1, "{moved}");
    assert_eq!(moved["failure"], Value::Null, "{moved}");
    let x0 = moved["me"]["x"].as_f64().expect("our position");
    page.key_down(Key::ArrowRight).unwrap();
    let walked = page.wait_until(
        &format!(
            "ledgeState.level.id == 'second' && ledgeState.me.x > {}",
            // The crate block stands 50 px right of the spawn.
            x0 + 30.0
        ),
        Duration::from_secs(5),
    );
    page.key_up(Key::ArrowRight).unwrap();
    walked.unwrap_or_else(|e| {
        panic!(
            "held Right moves us on the second level: {e}: {}",
            state(&mut page)
        )
    });
    drop(browser);
    runtime.block_on(server.stop()).unwrap();
}
