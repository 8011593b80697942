//! `ledge-bot --brain thin` (the thin bots `ledge-load --client thin`
//! starts) against a real server in-process on loopback: every bot joins,
//! sends an input per tick, receives snapshots, leaves cleanly, and prints
//! the report line `ledge-load` reads.

use crate::common;

use std::process::Command;
use std::time::Duration;

use common::{run_to_end, TestServer};

/// `ledge-bot` must have exited within this time.
const BOT_TIMEOUT: Duration = Duration::from_secs(60);

/// The number after `name` on a report line.
fn field(line: &str, name: &str) -> u64 {
    let words: Vec<&str> = line.split_whitespace().collect();
    let i = words
        .iter()
        .position(|w| *w == name)
        .unwrap_or_else(|| panic!("no {name} in {line}"));
    words[i + 1]
        .parse()
        .unwrap_or_else(|e| panic!("{name} in {line}: {e}"))
}

#[test]
fn thin_bots_play_and_report() {
    let server = TestServer::start();
    let mut command = Command::new(env!("CARGO_BIN_EXE_ledge-bot"));
    command
        .args(["--connect", &server.addr.to_string()])
        .args(["--cert-hash", &server.fingerprint.to_string()])
        .args(["--brain", "thin", "--count", "3", "--seconds", "2"])
        .args(["--name", "p1"])
        .env("RUST_LOG", "warn");
    let out = run_to_end(command, BOT_TIMEOUT);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{}\n{stdout}\n{stderr}", out.status);

    let reports: Vec<&str> = stdout.lines().filter(|l| l.starts_with("p1-")).collect();
    assert_eq!(reports.len(), 3, "{stdout}");
    for line in reports {
        assert_eq!(line.split_whitespace().nth(1), Some("thin"), "{line}");
        assert!(!line.contains("ended:"), "{line}");
        // 2 s at 60 Hz ticks (one input each) and 30 Hz snapshots, with
        // room for a slow machine.
        assert!(field(line, "ticks") >= 60, "{line}");
        assert!(field(line, "snapshots") >= 15, "{line}");
        // Welcomed: a player id (`#N`), not `-`.
        let words: Vec<&str> = line.split_whitespace().collect();
        assert!(words[3].starts_with('#'), "{line}");
    }

    server.stop();
}
