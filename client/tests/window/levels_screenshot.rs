//! Level rotation through the real window client under Xvfb, on a real
//! server rotating two levels (votes by majority): the script opens the
//! level list (V) and votes for level 2 (the number key); alone in the
//! room that is a majority, so the room moves on. The window downloads
//! the second level and plays on there; reopened, the list marks it as
//! the one playing. The screenshot's description tells all of it.
//!
//! Needs `xvfb-run` (see `common::xvfb_or_skip`).

use crate::common;

use std::time::Duration;

use common::{run_to_end, TestServer};
use serde_json::Value;

/// The client must have saved its screenshot within this time.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(120);
/// Ticks of play before the screenshot (5 s: the vote at 1 s, the change
/// a second later, the list reopened after it).
const TICKS: u64 = 300;
const SCRIPT: &str = "30 -> levels\n60 -> vote 2\n240 -> levels\n";

#[test]
fn a_vote_in_the_window_moves_the_room_and_the_window_follows() {
    let Some(xvfb) = common::xvfb_or_skip("the level rotation screenshot test") else {
        return;
    };
    let levels = tempfile::tempdir().unwrap();
    let server = TestServer::rotating(levels.path());
    let tmp = tempfile::tempdir().unwrap();
    let png = common::screenshot_dir(tmp.path()).join("levels.png");
    let script = tmp.path().join("levels.script");
    std::fs::write(&script, SCRIPT).unwrap();
    let mut command =
        common::client_under_xvfb(&xvfb, env!("CARGO_BIN_EXE_ledge-client"), TICKS, &png);
    command
        .args(["--connect", &server.addr.to_string()])
        .args(["--cert-hash", &server.fingerprint.to_string()])
        .args(["--name", "ada"])
        .arg("--level-cache")
        .arg(tmp.path().join("cache"))
        .arg("--script")
        .arg(&script);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    server.stop();
    assert!(
        out.status.success(),
        "the client failed: {}; stderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(png.with_extension("png.json")).expect("the JSON");
    let json: Value = serde_json::from_str(&text).expect("valid JSON");
    let levels = &json["levels"];
    assert_eq!(levels["level_changes"], 1, "{levels}");
    assert_eq!(levels["current"], 1, "{levels}");
    assert_eq!(levels["rule"], "majority");
    let names: Vec<&str> = levels["list"]
        .as_array()
        .expect("levels.list")
        .iter()
        .map(|l| l["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["default", "second"]);
    let lines = &levels["panel"]["lines"];
    assert_eq!(lines[1], "2. second   0 votes   < playing", "{levels}");
    assert_eq!(lines[0], "1. default   0 votes   < next", "{levels}");
    assert!(json["downloading"].is_null(), "{}", json["downloading"]);
    // Playing on the second level: our player drawn, the HUD's run afresh.
    assert!(!json["player"].is_null(), "{}", json["player"]);
    assert_eq!(json["hud"]["deaths"], 0);
    // The chat said the vote went.
    let said: Vec<&str> = json["chat"]["lines"]
        .as_array()
        .expect("chat.lines")
        .iter()
        .filter_map(|l| l["text"].as_str())
        .collect();
    assert!(said.contains(&"voted for 2. second"), "{said:?}");
}
