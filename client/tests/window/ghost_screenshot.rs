//! Ghosts in the window (issue 32), through the real client binary under
//! Xvfb: a runner bot finishes first, so the records hold its run with
//! its replay; then the window joins, runs right for a while and takes a
//! screenshot. The ghost is drawn where the record run was at the tick
//! our run timer shows, as the run's replay file, played here with the
//! shared simulation, says.
//!
//! Needs `xvfb-run` (see `common::xvfb_or_skip`).

use crate::common;

use std::time::Duration;

use common::{run_to_end, TestServer};
use glam::IVec2;
use ledge_levels::default_level;
use ledge_shared::replay::{self, Playback, ReplayKind};
use serde_json::Value;

/// The client must have saved its screenshot within this time.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(120);

/// Ticks of play before the screenshot (the run starts on the first).
const TICKS: u64 = 150;

/// Where the runner of the run `replay` was at tick `run_tick` of its
/// run timer (its centre, units), the replay played with the shared
/// simulation.
fn runner_at(replay: replay::Replay, run_tick: u32) -> IVec2 {
    let ReplayKind::Run { player, .. } = replay.header.kind else {
        panic!("a run's replay");
    };
    let mut playing = Playback::new(&default_level(), replay).expect("the replay plays");
    let mut at = None;
    while playing.step().expect("the replay steps") {
        let Some(p) = playing.game().player(player) else {
            continue;
        };
        if p.run_started && p.run_ticks == run_tick {
            at = Some(p.pos);
        }
        if p.run_started && p.run_ticks > run_tick {
            break;
        }
    }
    at.unwrap_or_else(|| panic!("the run never reached tick {run_tick}"))
}

#[test]
fn the_record_runs_beside_us_as_a_ghost_where_its_replay_says() {
    let Some(xvfb) = common::xvfb_or_skip("the ghost screenshot test") else {
        return;
    };
    let server = TestServer::start();
    let (addr, fingerprint) = (server.addr.to_string(), server.fingerprint);
    // "bob", a runner bot, to the goal: his run is the level's record.
    let bob = server.runner_to_goal("bob");
    assert!(matches!(bob.standing, Some(Ok(_))), "bob's run: {bob}");
    let (_, record) = common::run_replay(server.cert_dir(), "bob");
    // Then "ada" runs right in the window, the record's ghost beside her.
    let tmp = tempfile::tempdir().unwrap();
    let png = common::screenshot_dir(tmp.path()).join("ghost.png");
    let mut command =
        common::client_under_xvfb(&xvfb, env!("CARGO_BIN_EXE_ledge-client"), TICKS, &png);
    command
        .args(["--connect", &addr])
        .args(["--cert-hash", &fingerprint.to_string()])
        .args(["--name", "ada"])
        .args(["--script", "0-199 -> right"]);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    server.stop();
    assert!(
        out.status.success(),
        "the client failed: {}; stderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(png.with_extension("png.json")).expect("the sidecar");
    let json: Value = serde_json::from_str(&text).expect("JSON");
    assert_eq!(json["ghosts_shown"], true, "{json}");
    let ghosts = json["ghosts"].as_array().expect("ghosts");
    assert_eq!(ghosts.len(), 1, "bob's record only: {json}");
    let ghost = &ghosts[0];
    assert_eq!(ghost["kind"], "record", "{ghost}");
    assert_eq!(ghost["player"], "bob", "{ghost}");
    // Our run timer runs: the ghost is at the tick it shows.
    let run_tick = ghost["run_tick"].as_u64().expect("a run tick") as u32;
    assert_eq!(json["hud"]["run_ticks"], run_tick, "{json}");
    assert!(run_tick > 60, "our run started at once: {json}");
    let units = &ghost["pos_units"];
    let drawn = IVec2::new(
        units[0].as_i64().unwrap() as i32,
        units[1].as_i64().unwrap() as i32,
    );
    assert_eq!(drawn, runner_at(record, run_tick), "{ghost}");
    eprintln!("the ghost: {ghost}; the PNG: {}", png.display());
}
