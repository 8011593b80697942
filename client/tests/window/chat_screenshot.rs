//! Chat through the real window client under Xvfb, joined to a real
//! server with "bob", a bot session of the test's own: bob greets the
//! window's player (ada) when she joins, ada's script types a line to bob
//! and then one with a direction override. The screenshot's description
//! lists the lines drawn, names from the roster: bob's greeting and ada's
//! line as the server relayed it; the refused line still open, saying
//! why. Bob receives ada's line, and never the refused one.
//!
//! Needs `xvfb-run` (see `common::xvfb_or_skip`).

use crate::common;

use std::time::Duration;

use common::{run_to_end, TestServer};
use ledge_client::{connect, SessionEvent};
use ledge_shared::protocol::PlayerId;
use serde_json::Value;

/// The client must have saved its screenshot within this time.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(120);
/// Ticks of play before the screenshot (4 s: bob's greeting is still
/// fully shown).
const TICKS: u64 = 240;
const GREETING: &str = "hello ada, good luck";
const REPLY: &str = "thanks bob: see you at the flag";
/// Ada types this at tick 120, then the refused line at tick 180.
const SCRIPT: &str = "0..20 -> right\n120 -> say thanks bob: see you at the flag\n\
                      180 -> say sneaky \u{202E}txt.exe\n";

/// What bob heard from ada.
struct Heard {
    /// Ada's lines, in order.
    lines: Vec<String>,
}

/// After ada's line, bob listens this long more (her refused line would
/// come a second after it).
const AFTER_REPLY: Duration = Duration::from_secs(3);

/// Bob: joins, greets ada once she is in the room, then listens to her
/// (at most `listen`; [`AFTER_REPLY`] after her line).
async fn bob(server: &TestServer, listen: Duration) -> Heard {
    let mut bob = connect(server.addr, "localhost", server.fingerprint, "bob")
        .await
        .expect("bob is welcomed");
    let mut ada: Option<PlayerId> = None;
    let mut lines = Vec::new();
    let mut until = tokio::time::Instant::now() + listen;
    while let Ok(event) = tokio::time::timeout_at(until, bob.recv()).await {
        match event.expect("bob's session holds") {
            SessionEvent::PlayerJoined { id, name } if name == "ada" => {
                ada = Some(id);
                bob.chat(GREETING).await.expect("bob's line goes");
            }
            SessionEvent::Chat { from, text } if Some(from) == ada => {
                if text == REPLY {
                    until = until.min(tokio::time::Instant::now() + AFTER_REPLY);
                }
                lines.push(text);
            }
            _ => {}
        }
    }
    bob.close().await;
    Heard { lines }
}

#[test]
fn the_window_shows_chat_from_the_room_and_sends_typed_lines() {
    let Some(xvfb) = common::xvfb_or_skip("the chat screenshot test") else {
        return;
    };
    let server = TestServer::start();
    let tmp = tempfile::tempdir().unwrap();
    let png = common::screenshot_dir(tmp.path()).join("chat.png");
    let script = tmp.path().join("chat.script");
    std::fs::write(&script, SCRIPT).unwrap();
    let (out, heard) = std::thread::scope(|s| {
        let bob = s.spawn(|| server.block_on(bob(&server, Duration::from_secs(60))));
        // Bob first (the roster names him to ada).
        std::thread::sleep(Duration::from_millis(500));
        let mut command =
            common::client_under_xvfb(&xvfb, env!("CARGO_BIN_EXE_ledge-client"), TICKS, &png);
        command
            .args(["--connect", &server.addr.to_string()])
            .args(["--cert-hash", &server.fingerprint.to_string()])
            .args(["--name", "ada"])
            .arg("--script")
            .arg(&script);
        let out = run_to_end(command, CLIENT_TIMEOUT);
        (out, bob.join().expect("bob's thread"))
    });
    server.stop();
    assert!(
        out.status.success(),
        "the client failed: {}; stderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    // Bob heard ada's line, and only that one.
    assert_eq!(heard.lines, [REPLY]);

    let text = std::fs::read_to_string(png.with_extension("png.json")).expect("the JSON");
    let json: Value = serde_json::from_str(&text).expect("valid JSON");
    let chat = &json["chat"];
    let lines: Vec<(Option<&str>, &str)> = chat["lines"]
        .as_array()
        .expect("chat.lines")
        .iter()
        .map(|l| (l["from"].as_str(), l["text"].as_str().unwrap()))
        .collect();
    assert_eq!(
        lines,
        [(Some("bob"), GREETING), (Some("ada"), REPLY)],
        "{chat}"
    );
    for line in chat["lines"].as_array().unwrap() {
        assert_eq!(line["alpha"], 1.0, "{line}");
    }
    // The refused line stays open, showing the override, saying why.
    let typing = &chat["typing"];
    assert_eq!(typing["text"], "say: sneaky [U+202E]txt.exe_", "{chat}");
    assert_eq!(
        typing["error"], "not sent: U+202E is a direction override or an invisible character",
        "{chat}"
    );
    eprintln!("chat: {chat}");
}
