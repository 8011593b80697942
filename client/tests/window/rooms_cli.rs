//! The real `ledge-client` binary lists a server's rooms without joining
//! (`--list-rooms`, no window): a room a friend opened by name shows with
//! its level and players.

use crate::common;

use std::process::Command;
use std::time::Duration;

use common::{run_to_end, TestServer};
use ledge_client::{connect_with, JoinOptions};

#[test]
fn list_rooms_shows_a_room_opened_by_name() {
    let server = TestServer::start();
    let options = JoinOptions {
        player_name: "ana".into(),
        room: Some("friends".into()),
        resume: None,
        spectate: false,
    };
    let ana = server
        .block_on(connect_with(
            server.addr,
            "localhost",
            server.fingerprint,
            &options,
        ))
        .expect("ana opens the room");
    let level = ana.welcome().level_id.clone();
    let home = tempfile::tempdir().unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_ledge-client"));
    command
        .env("XDG_CONFIG_HOME", home.path())
        .env("HOME", home.path())
        .env("RUST_LOG", "warn")
        .args(["--connect", &server.addr.to_string()])
        .args(["--cert-hash", &server.fingerprint.to_string()])
        .arg("--list-rooms");
    let out = run_to_end(command, Duration::from_secs(30));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "stdout:\n{stdout}\nstderr:\n{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines[0], format!("2 rooms on {}:", server.addr), "{stdout}");
    assert_eq!(
        lines[1].split_whitespace().collect::<Vec<_>>(),
        ["friends", "level", &level, "1/16", "players"]
    );
    assert_eq!(
        lines[2].split_whitespace().collect::<Vec<_>>(),
        ["room-1", "level", &level, "0/16", "players"]
    );
    assert!(lines[3].contains("--room NAME"), "{stdout}");
    drop(ana);
    server.stop();
}
