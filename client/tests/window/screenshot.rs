//! The real client binary, under Xvfb, joined to a real server, scripted
//! to run right and stop; its screenshot must show the level and our player
//! where the server says it is, and another player ("bob", who ran to the
//! left wall) with his name above him.
//!
//! Needs `xvfb-run` (Debian: `apt-get install xvfb`; `.ci/run` installs
//! it). Without it the test fails when `CI=true` and otherwise prints a
//! loud notice and passes without checking anything.

use crate::common;
use std::net::SocketAddr;

use std::time::{Duration, Instant};

use common::{pair, run_to_end, xvfb_run, Png};

use ledge_client::{connect, Session};
use ledge_levels::default_level;
use ledge_server::{Server, ServerConfig};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::game::Game;
use ledge_shared::input::Buttons;
use ledge_shared::tilemap::Tile;
use serde_json::Value;

/// The client must have saved its screenshot within this time.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(90);
/// Ticks of play before the screenshot: run right, then come to rest.
const TICKS: u64 = 150;
const SCRIPT: &str = "0-14 -> right";
/// The other player's name.
const BOB: &str = "bob";

/// Joins as [`BOB`] and holds left for `run` (the server repeats the last
/// buttons, so he keeps pushing against the level's left wall, away from
/// our player's spawn).
async fn bob_runs_left(
    addr: SocketAddr,
    fingerprint: ledge_client::Fingerprint,
    run: Duration,
) -> Session {
    let mut bob = connect(addr, "localhost", fingerprint, BOB)
        .await
        .expect("bob is welcomed");
    let start_tick = bob.welcome().server_tick;
    let rate = f64::from(bob.welcome().timing.tick_rate);
    let t0 = Instant::now();
    while t0.elapsed() < run {
        let tick = start_tick + 2 + (t0.elapsed().as_secs_f64() * rate) as u64;
        bob.send_input(tick, Buttons(Buttons::LEFT))
            .expect("input queued");
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    bob
}

fn close(a: [u8; 3], b: [u8; 3]) -> bool {
    a.iter().zip(b).all(|(&x, y)| x.abs_diff(y) <= 3)
}

fn rgb(v: &Value) -> [u8; 3] {
    let a = v.as_array().expect("[r, g, b]");
    [0, 1, 2].map(|i| a[i].as_u64().expect("byte") as u8)
}

#[test]
fn the_client_draws_the_level_and_our_player_where_the_server_says() {
    let Some(xvfb) = xvfb_run() else {
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("xvfb-run is not on PATH: install xvfb (apt-get install xvfb) to run the screenshot test in CI");
        }
        // Straight to the process's stderr: the test harness captures
        // `eprintln!`, and this notice must be seen.
        let notice = "\n\
            ************************************************************\n\
            *  SKIPPED screenshot test: xvfb-run is not on PATH.       *\n\
            *  Install it (apt-get install xvfb xauth) to run it;      *\n\
            *  with CI=true this test fails instead of skipping.       *\n\
            ************************************************************\n\n";
        let _ = std::io::Write::write_all(&mut std::io::stderr(), notice.as_bytes());
        return;
    };

    // A real server, in-process, on loopback.
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .unwrap();
    let certs = tempfile::tempdir().unwrap();
    let (addr, fingerprint, shutdown, task, bob) = runtime.block_on(async {
        let server = Server::bind(ServerConfig {
            bind: SocketAddr::from(([127, 0, 0, 1], 0)),
            cert_dir: certs.path().to_owned(),
            ..ServerConfig::default()
        })
        .expect("server binds");
        let (addr, fingerprint) = (server.local_addr(), server.fingerprint());
        let (shutdown, task) = (server.shutdown_handle(), tokio::spawn(server.run()));
        let bob = bob_runs_left(addr, fingerprint, Duration::from_millis(1500)).await;
        (addr, fingerprint, shutdown, task, bob)
    });

    // The real client, scripted, in a virtual X server.
    // LEDGE_SCREENSHOT_DIR keeps the picture (to look at it); by default
    // a temporary directory.
    let out = tempfile::tempdir().unwrap();
    let dir = std::env::var_os("LEDGE_SCREENSHOT_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| out.path().to_owned());
    std::fs::create_dir_all(&dir).unwrap();
    let png_path = dir.join("shot.png");
    let mut command =
        common::client_under_xvfb(&xvfb, env!("CARGO_BIN_EXE_ledge-client"), TICKS, &png_path);
    command
        .args(["--connect", &addr.to_string()])
        .args(["--cert-hash", &fingerprint.to_string()])
        .args(["--name", "shot"])
        .args(["--script", SCRIPT]);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    let status = out.status;
    runtime.block_on(bob.close());
    shutdown.shutdown();
    runtime.block_on(async {
        let _ = tokio::time::timeout(Duration::from_secs(5), task).await;
    });
    assert!(
        status.success(),
        "the client failed: {status}; stderr:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let json_path = dir.join("shot.png.json");
    let json: Value = serde_json::from_str(
        &std::fs::read_to_string(&json_path).expect("the screenshot's JSON exists"),
    )
    .expect("valid JSON");
    let img = Png::load(&png_path);
    let screen = pair(&json["screen"]);
    assert_eq!((img.width as f64, img.height as f64), screen, "{json}");
    let zoom = json["camera"]["zoom"].as_f64().unwrap();
    let (ox, oy) = pair(&json["camera"]["offset"]);
    let to_screen = |x: f64, y: f64| (x * zoom + ox, y * zoom + oy);
    let colors = &json["colors"];
    let (sky, solid, grass, me) = (
        rgb(&colors["sky"]),
        rgb(&colors["solid"]),
        rgb(&colors["grass"]),
        rgb(&colors["local_player"]),
    );

    // The level: every visible interior solid tile (itself and its four
    // neighbours solid) has the solid colour at its centre, and exposed
    // ground tops are grass.
    let level = default_level();
    let map = &level.tilemap;
    let t = (map.tile_size() / UNITS_PER_PX) as f64;
    let o = (
        (map.origin().x / UNITS_PER_PX) as f64,
        (map.origin().y / UNITS_PER_PX) as f64,
    );
    let tile = |c: i32, r: i32| map.tile(glam::IVec2::new(c, r));
    let (mut interior, mut solid_ok, mut tops, mut grass_ok) = (0, 0, 0, 0);
    for r in 0..map.height() as i32 {
        for c in 0..map.width() as i32 {
            if tile(c, r) != Tile::Solid {
                continue;
            }
            let (x, y) = (o.0 + c as f64 * t, o.1 + r as f64 * t);
            let around = [(-1, 0), (1, 0), (0, -1), (0, 1)].map(|(dc, dr)| tile(c + dc, r + dr));
            if around.iter().all(|&n| n == Tile::Solid) {
                let (sx, sy) = to_screen(x + t / 2.0, y + t / 2.0);
                if let Some(p) = img.rgb_at(sx, sy) {
                    interior += 1;
                    solid_ok += close(p, solid) as u32;
                }
            }
            if tile(c, r - 1) == Tile::Empty {
                let (sx, sy) = to_screen(x + t / 2.0, y + 1.0);
                if let Some(p) = img.rgb_at(sx, sy) {
                    tops += 1;
                    grass_ok += close(p, grass) as u32;
                }
            }
        }
    }
    assert!(
        interior >= 20,
        "only {interior} interior solid tiles on screen: {json}"
    );
    assert!(
        solid_ok * 10 >= interior * 9,
        "{solid_ok} of {interior} interior solid tiles have the solid colour {solid:?}"
    );
    assert!(tops >= 5, "only {tops} ground tops on screen");
    assert!(
        grass_ok * 10 >= tops * 8,
        "{grass_ok} of {tops} ground tops are grass"
    );

    // Our player: where the server says, at rest, drawn there.
    let player = &json["player"];
    assert!(player.is_object(), "no player in {json}");
    let (px, py) = pair(&player["server_pos_px"]);
    let spawn_x = 88.0;
    assert!(
        px > spawn_x + 8.0,
        "the scripted run moved us right: x = {px}"
    );
    let (cx, cy) = pair(&player["server_screen"]);
    // (The JSON has three decimals: 98.3125 px is printed 98.312.)
    let (sx, sy) = to_screen(px, py);
    assert!(
        (sx - cx).abs() < 0.01 && (sy - cy).abs() < 0.01,
        "server_screen follows the camera: ({sx}, {sy}) vs ({cx}, {cy})"
    );
    let (dx, dy) = pair(&player["drawn_screen"]);
    assert!(
        (dx - cx).abs() <= 3.0 && (dy - cy).abs() <= 3.0,
        "drawn at ({dx}, {dy}), the server says ({cx}, {cy})"
    );
    let (w, h) = pair(&player["size_px"]);
    let (hw, hh) = (w * zoom / 2.0, h * zoom / 2.0);
    // The centre of the body (a few pixels around it, eyes are higher up).
    let mut body = 0;
    for ddy in -3..=3 {
        for ddx in -3..=3 {
            let p = img.rgb_at(cx + ddx as f64, cy + 2.0 + ddy as f64).unwrap();
            body += close(p, me) as u32;
        }
    }
    assert!(
        body >= 40,
        "player colour {me:?} at only {body}/49 pixels around ({cx}, {cy})"
    );
    // Nowhere else: every player-coloured pixel is inside its box (+-3 px).
    let mut stray = Vec::new();
    let mut total = 0;
    for y in 0..img.height {
        for x in 0..img.width {
            if close(img.rgb_at(x as f64, y as f64).unwrap(), me) {
                total += 1;
                let (fx, fy) = (x as f64 + 0.5, y as f64 + 0.5);
                if (fx - cx).abs() > hw + 3.0 || (fy - cy).abs() > hh + 3.0 {
                    stray.push((x, y));
                }
            }
        }
    }
    assert!(
        total as f64 >= hw * hh * 2.0,
        "player drawn too small: {total} px"
    );
    assert!(
        stray.len() <= 4,
        "player colour away from the player: {:?}",
        &stray[..stray.len().min(10)]
    );
    // Bob: drawn with his name (from the server's roster), and the label's
    // white text is above his head.
    let remotes = json["remotes"].as_array().expect("remotes listed");
    let bob: Vec<&Value> = remotes
        .iter()
        .filter(|r| r["label"].as_str() == Some(BOB))
        .collect();
    assert_eq!(bob.len(), 1, "bob drawn once with his name: {json}");
    let (bx, by) = pair(&bob[0]["drawn_screen"]);
    let (bw, bh) = pair(&bob[0]["size_px"]);
    let (bob_x, bob_y) = ((bx - ox) / zoom, (by - oy) / zoom);
    assert!(
        (bob_x - px).abs() > 40.0,
        "bob ran away from our player: {bob_x} vs {px}"
    );
    let head = by - bh * zoom / 2.0;
    let mut white = 0;
    for y in (head - 26.0) as i32..(head - 2.0) as i32 {
        for x in (bx - 24.0) as i32..(bx + 24.0) as i32 {
            white += img
                .rgb_at(x as f64, y as f64)
                .is_some_and(|p| p.iter().all(|&c| c >= 250)) as u32;
        }
    }
    assert!(
        white >= 10,
        "only {white} white label pixels above bob at ({bx}, {head})"
    );
    let body = img.rgb_at(bx, by + 2.0).expect("bob on screen");
    assert!(!close(body, sky), "bob's body is drawn: {body:?}");

    // Background around it, where the level is empty (no tile, no entity
    // or other player near: flags, labels and animations reach a little
    // outside boxes).
    let game = Game::from_level(&level).unwrap();
    let clear = |x: f64, y: f64| {
        let away_from_bob =
            (x - bob_x).abs() > bw / 2.0 + 24.0 || (y - bob_y).abs() > bh / 2.0 + 24.0;
        let tile_empty = tile(
            ((x - o.0) / t).floor() as i32,
            ((y - o.1) / t).floor() as i32,
        ) == Tile::Empty;
        tile_empty
            && away_from_bob
            && game.entities().all(|e| {
                let u = UNITS_PER_PX as f64;
                let (ex, ey) = (e.pos.x as f64 / u, e.pos.y as f64 / u);
                let (ew, eh) = (e.half.x as f64 / u + 6.0, e.half.y as f64 / u + 16.0);
                (x - ex).abs() > ew || (y - ey).abs() > eh
            })
    };
    let mut checked = 0;
    for (kx, ky) in [
        (-1.0, 0.0),
        (1.0, 0.0),
        (-2.0, 0.0),
        (2.0, 0.0),
        (0.0, -2.0),
        (0.0, -3.0),
        (-1.5, -2.0),
        (1.5, -2.0),
        (-2.0, -3.0),
        (2.0, -3.0),
    ] {
        let (wx, wy) = (px + kx * w, py + ky * h);
        if !clear(wx, wy) {
            continue;
        }
        let (sx, sy) = to_screen(wx, wy);
        let p = img.rgb_at(sx, sy).expect("on screen");
        assert!(
            close(p, sky),
            "background {sky:?} expected at world ({wx}, {wy}), screen ({sx}, {sy}): {p:?}"
        );
        checked += 1;
    }
    assert!(checked >= 4, "only {checked} background points checked");
}

/// The default HUD, offline: the screenshot's JSON reports our name, coins
/// (of the level's), deaths and run ticks, equal to the simulation's after
/// the same scripted ticks, and no network panel; the panel is drawn in
/// the top-left corner.
#[test]
fn the_default_hud_shows_name_coins_deaths_and_timer_as_the_simulation_says() {
    use ledge_shared::game::PlayerView;
    use ledge_shared::level::EntityKind;
    use ledge_shared::protocol::PlayerId;

    let Some(xvfb) = common::xvfb_or_skip("the default HUD screenshot test") else {
        return;
    };
    const HUD_TICKS: u64 = 200;
    // Run right, jumping now and then, over the level's first coins.
    const HUD_SCRIPT: &str = "0-199 -> right; 20-34 -> jump; 70-84 -> jump; 120-134 -> jump";
    let out = tempfile::tempdir().unwrap();
    let dir = common::screenshot_dir(out.path());
    let png_path = dir.join("hud.png");
    let mut command = common::client_under_xvfb(
        &xvfb,
        env!("CARGO_BIN_EXE_ledge-client"),
        HUD_TICKS,
        &png_path,
    );
    command
        .args(["--name", "ada"])
        .args(["--script", HUD_SCRIPT]);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    assert!(
        out.status.success(),
        "the client failed: {}; stderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let json: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("hud.png.json")).expect("the screenshot's JSON"),
    )
    .expect("valid JSON");

    // The same ticks in the simulation (offline: player 1, the script's
    // buttons tick by tick).
    let level = default_level();
    let mut game = Game::from_level(&level).unwrap();
    game.add_player(PlayerId(1)).unwrap();
    let script = |t: u64| {
        let mut b = 0;
        if t < 200 {
            b |= Buttons::RIGHT;
        }
        if (20..=34).contains(&t) || (70..=84).contains(&t) || (120..=134).contains(&t) {
            b |= Buttons::JUMP;
        }
        Buttons(b)
    };
    for t in 0..HUD_TICKS {
        game.step(&[(PlayerId(1), script(t))]);
    }
    let me: PlayerView = game.player(PlayerId(1)).unwrap();
    let total = level
        .entities
        .iter()
        .filter(|e| matches!(e.kind, EntityKind::Coin))
        .count();
    let hud = &json["hud"];
    assert_eq!(hud["name"], "ada", "{json}");
    assert_eq!(hud["coins"], me.coins, "{json}");
    assert_eq!(hud["coins_total"], total as u64, "{json}");
    assert_eq!(hud["deaths"], me.deaths, "{json}");
    assert_eq!(hud["run_ticks"], me.run_ticks, "{json}");
    assert_eq!(
        me.run_ticks as u64, HUD_TICKS,
        "the timer ran from the first press"
    );
    assert_eq!(hud["net_panel"], false, "{json}");
    assert!(hud["place"].is_null(), "{json}");
    assert_eq!(hud["time"], "0:03.33", "{json}");
    eprintln!("HUD: {hud}");

    // The panel is drawn top-left: darker than the sky behind it.
    let img = Png::load(&png_path);
    let sky = rgb(&json["colors"]["sky"]);
    let [r, g, b] = img.rgb_at(12.0, 12.0).expect("inside");
    let lum = |c: [u8; 3]| c.iter().map(|&v| u32::from(v)).sum::<u32>();
    assert!(lum([r, g, b]) < lum(sky), "{:?} vs sky {sky:?}", [r, g, b]);
}
