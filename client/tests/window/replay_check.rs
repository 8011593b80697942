//! `ledge-client --replay FILE --check` through the real binary, without
//! a window: a good file plays to its end as recorded and the line says
//! how many ticks and how fast; a bit flipped, a file cut short, a file
//! that plays differently from the server's hashes and a level nobody has
//! are each refused with the reason (and what to do) on stderr, and the
//! exit code tells an unreadable file (2) from one that does not play (1).

use std::path::Path;
use std::process::{Command, Output};
use std::time::Duration;

use crate::common::run_to_end;
use crate::replay_files::{record, write};
use ledge_client::net::download::embedded;
use ledge_levels::{default_level, LevelBundle};
use ledge_shared::protocol::LevelOffer;
use ledge_shared::replay::{self, Event};

const TIMEOUT: Duration = Duration::from_secs(120);

/// The client checking `file` (`extra` arguments after), with an empty
/// level cache of its own.
fn check(file: &Path, extra: &[&str]) -> Output {
    let cache = tempfile::tempdir().unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_ledge-client"));
    command
        .arg("--replay")
        .arg(file)
        .arg("--check")
        .arg("--level-cache")
        .arg(cache.path())
        .args(extra);
    run_to_end(command, TIMEOUT)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn a_good_replay_checks_out_and_says_how_fast_it_played() {
    let tmp = tempfile::tempdir().unwrap();
    let rec = record(&default_level(), embedded().1, 2400);
    let file = write(tmp.path(), "match.ledgereplay", &rec.replay());
    let out = check(&file, &[]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    let line = stdout.trim();
    assert!(
        line.starts_with("replay OK: 2,400 ticks (0:40.00 of play) in ")
            && line.ends_with(" ticks/s"),
        "{line}"
    );
    assert_eq!(stdout.lines().count(), 1, "one line: {stdout}");
}

#[test]
fn damaged_or_missing_replays_are_refused_with_their_reason() {
    let tmp = tempfile::tempdir().unwrap();
    let rec = record(&default_level(), embedded().1, 600);
    let bytes = replay::encode(&rec.replay()).unwrap();
    let mut flipped = bytes.clone();
    let middle = bytes.len() / 2;
    flipped[middle] ^= 0x10;
    let cut = &bytes[..bytes.len() - 10];
    let cases: [(&str, &[u8], &str); 3] = [
        ("flipped.ledgereplay", &flipped, "damaged: its checksum is"),
        ("cut.ledgereplay", cut, "truncated:"),
        (
            "png.ledgereplay",
            b"\x89PNG\r\n\x1a\n",
            "not a ledge replay",
        ),
    ];
    for (name, content, reason) in cases {
        let file = tmp.path().join(name);
        std::fs::write(&file, content).unwrap();
        let out = check(&file, &[]);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {stderr}");
        assert!(stderr.contains(reason), "{name}: {stderr}");
        assert!(stderr.contains(&file.display().to_string()), "{stderr}");
        assert!(out.stdout.is_empty(), "{name}: {}", text(&out.stdout));
    }
    assert!(
        text(&check(&tmp.path().join("cut.ledgereplay"), &[]).stderr).contains("download it again")
    );
    let out = check(&tmp.path().join("missing.ledgereplay"), &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("check the path"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn a_replay_that_plays_differently_says_from_which_tick() {
    let tmp = tempfile::tempdir().unwrap();
    let rec = record(&default_level(), embedded().1, 1200);
    let mut replay = rec.replay();
    // The server's 10th hash (tick 600) was another: a well-formed file
    // (re-encoded, its checksum right) that does not play as recorded.
    let mut seen = 0;
    for e in &mut replay.events {
        if let Event::Hash(h) = e {
            seen += 1;
            if seen == 10 {
                *h ^= 1;
            }
        }
    }
    let file = write(tmp.path(), "diverged.ledgereplay", &replay);
    let out = check(&file, &[]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("plays differently from the server from tick 600 on"),
        "{stderr}"
    );
    assert!(
        stderr.contains("watch it with the version of ledge"),
        "{stderr}"
    );
}

#[test]
fn the_level_is_found_in_a_level_file_or_named_with_what_to_do() {
    let tmp = tempfile::tempdir().unwrap();
    // A Tiled level of the importer's fixtures: not embedded, not cached.
    let tmx = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../levels/tests/fixtures/levels/tiled/level.tmx");
    let loaded = ledge_levels::load_level(&tmx, None).expect("the fixture loads");
    let bundle = LevelBundle {
        level: loaded.level,
        art: loaded.art,
    };
    let offer = LevelBundle::offer(&bundle.encode());
    let rec = record(&bundle.level, offer, 600);
    let file = write(tmp.path(), "tiled.ledgereplay", &rec.replay());
    let tmx_arg = tmx.display().to_string();
    let out = check(&file, &["--level", &tmx_arg]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stdout).starts_with("replay OK: 600 ticks"));

    // Without it: the level is named, and what to do.
    let out = check(&file, &[]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(&offer.hex()), "{stderr}");
    assert!(
        stderr.contains("pass its file with --level FILE"),
        "{stderr}"
    );
    assert!(stderr.contains("http://HOST:PORT/replays/ID"), "{stderr}");

    // Another level's file: said to be another.
    let other = Path::new(env!("CARGO_MANIFEST_DIR")).join("../levels/default/default.json");
    let out = check(&file, &["--level", &other.display().to_string()]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("is another level"), "{stderr}");

    // The embedded level needs nothing (a made-up offer is not it).
    let mut replay = rec.replay();
    replay.header.level = LevelOffer {
        sha256: [7; 32],
        size: 1234,
    };
    let file = write(tmp.path(), "nowhere.ledgereplay", &replay);
    let out = check(&file, &[]);
    assert!(
        text(&out.stderr).contains(&"07".repeat(32)),
        "{}",
        text(&out.stderr)
    );
}
