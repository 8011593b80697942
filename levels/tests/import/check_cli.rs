//! `ledge-level check`, the real binary: what it prints for a level and
//! its exit status for good and refused files.

use std::process::Command;

const FIXTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/levels/tiled/level.tmx"
);

fn check(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ledge-level"))
        .arg("check")
        .args(args)
        .output()
        .expect("ledge-level runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_good_level_is_described_and_exits_zero() {
    let (ok, out, err) = check(&[FIXTURE]);
    assert!(ok, "{out}\n{err}");
    for needle in [
        "level.tmx: ok, level \"level\"",
        "grid: 20 x 10 tiles of 16 px at (0, 0) px",
        "tiles: ",
        "entities: ",
        "spawn: (",
        "layer \"ground\" (layers[0]), tiles: ",
        "settings: none (",
    ] {
        assert!(out.contains(needle), "{needle:?} not in:\n{out}");
    }
}

#[test]
fn a_refused_level_names_the_problem_and_exits_one() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"layers\": [}").unwrap();
    let missing = dir.path().join("missing.tmx");
    let (ok, out, err) = check(&[FIXTURE, bad.to_str().unwrap(), missing.to_str().unwrap()]);
    assert!(!ok);
    assert!(out.contains("level.tmx: ok"), "{out}");
    assert!(
        err.contains("bad.json: line 1 column 13: malformed JSON"),
        "{err}"
    );
    assert!(err.contains("missing.tmx: cannot read the file"), "{err}");
    assert!(err.contains("2 of 3 level file(s) refused"), "{err}");
    // A bad settings file refuses the level it is for.
    let settings = dir.path().join("s.toml");
    std::fs::write(&settings, "colision_layers = []\n").unwrap();
    let (ok, _, err) = check(&["--settings", settings.to_str().unwrap(), FIXTURE]);
    assert!(!ok);
    assert!(err.contains("unknown field `colision_layers`"), "{err}");
}
