//! `ledge-client --spectate` through the real client binary under Xvfb:
//! a runner bot plays in a room of one place; the window joins it to
//! watch (taking no player's place), follows the bot (`--follow`) and
//! takes a screenshot. The followed player is drawn where the server's
//! newest snapshot has it, give or take the ticks it is drawn behind
//! (interpolation).
//!
//! Needs `xvfb-run` (see `common::xvfb_or_skip`).

use crate::common;

use std::time::Duration;

use common::{run_to_end, TestServer};
use ledge_client::bot::{connect_and_run, BotOptions, Brain, Runner};
use ledge_client::Trust;
use ledge_levels::default_route;
use serde_json::Value;

/// The client must have saved its screenshot within this time.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(120);

/// Fastest a player moves, world px a tick, with room to spare (runs are
/// 2.5 px a tick; falls are faster).
const MAX_PX_PER_TICK: f64 = 8.0;

#[test]
fn a_spectator_follows_a_player_where_the_server_has_it() {
    let Some(xvfb) = common::xvfb_or_skip("the spectator screenshot test") else {
        return;
    };
    // One player's place: the spectator must not need it.
    let server = TestServer::start_with(|c| c.max_players = 1);
    let (addr, fingerprint) = (server.addr.to_string(), server.fingerprint);
    let bot_addr = addr.clone();
    let bob = std::thread::spawn(move || {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        let mut runner = Runner::new(default_route());
        let options = BotOptions::new("bob", Duration::from_secs(25));
        runtime.block_on(connect_and_run(
            &bot_addr,
            &Trust::Pinned(fingerprint),
            &mut runner as &mut dyn Brain,
            &options,
        ))
    });
    std::thread::sleep(Duration::from_secs(2));
    let tmp = tempfile::tempdir().unwrap();
    let png = common::screenshot_dir(tmp.path()).join("spectate.png");
    let mut command =
        common::client_under_xvfb(&xvfb, env!("CARGO_BIN_EXE_ledge-client"), 150, &png);
    command
        .args(["--connect", &addr])
        .args(["--cert-hash", &fingerprint.to_string()])
        .args(["--name", "eve"])
        .arg("--spectate")
        .args(["--follow", "bob"]);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    let bob = bob.join().expect("bob's thread");
    server.stop();
    assert!(
        out.status.success(),
        "the spectator failed: {}; stderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let bob_id = bob.player.expect("bob played").0;
    assert!(bob.snapshots > 100, "bob played on: {bob}");
    let text = std::fs::read_to_string(png.with_extension("png.json")).expect("the sidecar");
    let json: Value = serde_json::from_str(&text).expect("JSON");
    // No body of ours.
    assert!(json["player"].is_null(), "{json}");
    let watch = &json["spectate"];
    assert_eq!(watch["room"], "room-1", "{json}");
    assert_eq!(watch["free_camera"], false, "{watch}");
    assert_eq!(
        watch["line"], "spectating room-1 - following bob (Tab: next)",
        "{watch}"
    );
    let following = &watch["following"];
    assert_eq!(following["id"], bob_id, "{watch}");
    assert_eq!(following["name"], "bob", "{watch}");
    // Drawn where the server has him, the ticks drawn behind allowed for.
    let (x, y) = common::pair(&following["drawn_px"]);
    let (sx, sy) = common::pair(&following["server_pos_px"]);
    let behind =
        following["server_tick"].as_f64().unwrap() - following["render_tick"].as_f64().unwrap();
    // (A little ahead at most: the interpolator extrapolates briefly when
    // the next snapshot is late.)
    assert!(
        (-2.0..12.0).contains(&behind),
        "drawn {behind} ticks behind: {watch}"
    );
    let off = ((x - sx).powi(2) + (y - sy).powi(2)).sqrt();
    assert!(
        off <= (behind.abs() + 2.0) * MAX_PX_PER_TICK,
        "bob drawn {off:.1} px from the server's position, {behind:.1} ticks behind: {watch}"
    );
    // The HUD shows bob's run and the room's results table (if anyone finished).
    assert_eq!(json["hud"]["name"], "bob", "{json}");
    eprintln!("watched: {watch}; the PNG: {}", png.display());
}
