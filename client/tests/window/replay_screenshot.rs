//! A replay through the real client binary under Xvfb: a recorded match
//! opened at a tick, following a player by name, shows that player (drawn
//! in our colour, the HUD naming it) where a headless playback of the
//! same replay has it at that tick, and the others with their names where
//! the playback has them; a run's replay remembers the run's start, and at
//! its end says "end of replay" with the keys.
//!
//! Needs `xvfb-run` (see `common::xvfb_or_skip`).

use std::path::Path;
use std::time::Duration;

use crate::common::{self, pair, run_to_end, Png};
use crate::replay_files::{played_to, record, write};
use ledge_client::net::download::embedded;
use ledge_levels::default_level;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::protocol::PlayerId;
use serde_json::Value;

const CLIENT_TIMEOUT: Duration = Duration::from_secs(120);

/// Runs the client on replay `file` for `ticks` ticks of replay with
/// `args`; returns its screenshot and description.
fn watch(file: &Path, ticks: u64, name: &str, args: &[&str]) -> Option<(Png, Value)> {
    watch_ending(file, ticks, name, args, 0).map(|(png, json, _)| (png, json))
}

/// [`watch`] for a client that exits with `code`; its stderr too.
fn watch_ending(
    file: &Path,
    ticks: u64,
    name: &str,
    args: &[&str],
    code: i32,
) -> Option<(Png, Value, String)> {
    let xvfb = common::xvfb_or_skip("the replay screenshot tests")?;
    let tmp = tempfile::tempdir().unwrap();
    let dir = common::screenshot_dir(tmp.path());
    let png = dir.join(format!("{name}.png"));
    let mut command =
        common::client_under_xvfb(&xvfb, env!("CARGO_BIN_EXE_ledge-client"), ticks, &png);
    command
        .arg("--replay")
        .arg(file)
        .arg("--level-cache")
        .arg(tmp.path().join("cache"))
        .arg("--mute")
        .args(args);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(
        out.status.code(),
        Some(code),
        "the client ended with {}; stderr:\n{stderr}",
        out.status
    );
    let text = std::fs::read_to_string(dir.join(format!("{name}.png.json"))).unwrap();
    Some((
        Png::load(&png),
        serde_json::from_str(&text).unwrap(),
        stderr,
    ))
}

fn close(a: [u8; 3], b: [u8; 3]) -> bool {
    a.iter().zip(b).all(|(&x, y)| x.abs_diff(y) <= 3)
}

fn rgb(v: &Value) -> [u8; 3] {
    let a = v.as_array().expect("[r, g, b]");
    [0, 1, 2].map(|i| a[i].as_u64().expect("byte") as u8)
}

/// Tick 1548 of the match: bob (player 2, drilling 122 ticks ahead) stands
/// still, 25 ticks after his last jump; everyone has joined, nobody left.
const SEEK: u64 = 1500;
const PLAYED: u64 = 48;

#[test]
fn a_replay_shows_the_followed_player_where_the_playback_has_him() {
    let level = default_level();
    let rec = record(&level, embedded().1, 2400);
    let tmp = tempfile::tempdir().unwrap();
    let file = write(tmp.path(), "match.ledgereplay", &rec.replay());
    let seek = SEEK.to_string();
    let args = ["--replay-seek", seek.as_str(), "--follow", "bob"];
    let Some((img, json)) = watch(&file, PLAYED, "replay_match", &args) else {
        return;
    };
    let tick = SEEK + PLAYED;
    let game = played_to(&level, rec.replay(), tick);
    let replay = &json["replay"];
    assert_eq!(replay["tick"], tick, "{json}");
    assert_eq!(json["tick"], PLAYED, "ticks played in the window");
    assert_eq!(replay["following"]["name"], "bob", "{replay}");
    assert_eq!(replay["following"]["id"], 2);
    assert_eq!(
        (replay["start_tick"].as_u64(), replay["end_tick"].as_u64()),
        (Some(0), Some(2400))
    );
    assert_eq!(replay["run"], false);
    let lines = &replay["lines"];
    assert_eq!(lines["clock"], "replay 0:25.80 / 0:40.00   1x", "{lines}");
    assert!(
        lines["kind"]
            .as_str()
            .unwrap()
            .starts_with("match   room-1 on "),
        "{lines}"
    );
    assert!(
        lines["follow"]
            .as_str()
            .unwrap()
            .starts_with("following bob (Tab: next)   tick 1548"),
        "{lines}"
    );
    assert_eq!(json["hud"]["name"], "bob");

    // Bob where the playback has him, exactly, and drawn there.
    let bob = game.player(PlayerId(2)).unwrap();
    let player = &json["player"];
    assert_eq!(player["id"], 2);
    assert_eq!(player["server_pos_units"][0], bob.pos.x, "{player}");
    assert_eq!(player["server_pos_units"][1], bob.pos.y, "{player}");
    assert_eq!(json["hud"]["deaths"], bob.deaths);
    assert_eq!(json["hud"]["run_ticks"], bob.run_ticks);
    let (cx, cy) = pair(&player["server_screen"]);
    let (dx, dy) = pair(&player["drawn_screen"]);
    assert!(
        (dx - cx).abs() <= 1.0 && (dy - cy).abs() <= 1.0,
        "drawn at ({dx}, {dy}), the playback has ({cx}, {cy})"
    );
    // In our colour, the body's middle.
    let me = rgb(&json["colors"]["local_player"]);
    let mut body = 0;
    for ddy in -3..=3 {
        for ddx in -3..=3 {
            let p = img.rgb_at(cx + ddx as f64, cy + 2.0 + ddy as f64).unwrap();
            body += close(p, me) as u32;
        }
    }
    assert!(
        body >= 30,
        "bob's colour {me:?} at {body}/49 pixels around ({cx}, {cy})"
    );

    // The others with their names, where the playback has them (fanned
    // out by at most a few pixels where they stand together).
    let zoom = json["camera"]["zoom"].as_f64().unwrap();
    let (ox, oy) = pair(&json["camera"]["offset"]);
    let remotes = json["remotes"].as_array().unwrap();
    let mut labels: Vec<&str> = remotes
        .iter()
        .map(|r| r["label"].as_str().unwrap())
        .collect();
    labels.sort_unstable();
    assert_eq!(labels, ["ada", "cy", "dee"], "{json}");
    for r in remotes {
        let id = PlayerId(r["id"].as_u64().unwrap() as u32);
        let p = game.player(id).unwrap().pos;
        let units = UNITS_PER_PX as f64;
        let want = (
            p.x as f64 / units * zoom + ox,
            p.y as f64 / units * zoom + oy,
        );
        let (x, y) = pair(&r["drawn_screen"]);
        assert!(
            (x - want.0).abs() <= 16.0 * zoom && (y - want.1).abs() <= 1.0,
            "{} drawn at ({x}, {y}), the playback has {want:?}",
            r["label"]
        );
    }
}

#[test]
fn a_run_replay_remembers_its_start_and_says_when_it_ends() {
    let level = default_level();
    let rec = record(&level, embedded().1, 2400);
    // cy's "run", from tick 700 (after the keyframe at 600) to the end.
    let run = rec
        .recorder
        .run(&rec.game, PlayerId(3), 700, 1700, 2)
        .expect("a keyframe before tick 700");
    assert_eq!(run.start_tick(), 600);
    let tmp = tempfile::tempdir().unwrap();
    let file = write(tmp.path(), "run.ledgereplay", &run);
    let Some((_, json)) = watch(&file, 10, "replay_run_end", &["--replay-seek", "2400"]) else {
        return;
    };
    let replay = &json["replay"];
    assert_eq!(replay["run"], true, "{replay}");
    assert_eq!(replay["home"], 700, "opened at the run's start");
    assert_eq!(replay["tick"], 2400);
    assert_eq!(replay["at_end"], true);
    assert_eq!(replay["following"]["name"], "cy", "the runner");
    let lines = &replay["lines"];
    assert_eq!(
        lines["clock"], "replay 0:30.00 / 0:30.00   1x   end",
        "{lines}"
    );
    assert!(
        lines["kind"]
            .as_str()
            .unwrap()
            .starts_with("cy's run: 0:28.33, 2nd   room-1 on "),
        "{lines}"
    );
    let end = &replay["end_banner"];
    assert_eq!(end[0], "end of replay", "{replay}");
    let keys = end[1].as_str().expect("the keys that go on");
    assert!(
        keys.contains("Home") && keys.contains("Esc: quit"),
        "{keys}"
    );
    let cy = rec.game.player(PlayerId(3)).unwrap();
    assert_eq!(json["player"]["server_pos_units"][0], cy.pos.x);
    assert_eq!(json["player"]["server_pos_units"][1], cy.pos.y);
}

#[test]
fn a_replay_that_plays_differently_stops_where_it_does_and_says_why() {
    let level = default_level();
    let mut replay = record(&level, embedded().1, 1200).replay();
    // The server's 10th hash (tick 600) was another.
    let mut seen = 0;
    for e in &mut replay.events {
        if let ledge_shared::replay::Event::Hash(h) = e {
            seen += 1;
            if seen == 10 {
                *h ^= 1;
            }
        }
    }
    let tmp = tempfile::tempdir().unwrap();
    let file = write(tmp.path(), "diverged.ledgereplay", &replay);
    let args = ["--replay-seek", "590"];
    let Some((_, json, stderr)) = watch_ending(&file, 30, "replay_diverged", &args, 1) else {
        return;
    };
    let said = "plays differently from the server from tick 600 on";
    assert_eq!(stderr.matches(said).count(), 1, "told once: {stderr}");
    let replay = &json["replay"];
    assert_eq!(replay["tick"], 600, "stopped where it failed: {replay}");
    assert_eq!(replay["at_end"], true);
    assert!(replay["end_banner"].is_null(), "not an end: {replay}");
    assert!(replay["lines"]["failure"].as_str().unwrap().contains(said));
    let failure = json["failure"]["message"]
        .as_str()
        .expect("the failure shown");
    assert!(
        failure.contains(said) && failure.contains(&file.display().to_string()),
        "{failure}"
    );
}
