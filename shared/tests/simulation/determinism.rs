//! Determinism: a scripted 100,000-tick run of the warm-up room gives the
//! same state hash on repeated runs, from a cloned mid-run state, and in a
//! release build (the `ledge-determinism` binary, run through cargo) as in
//! this (debug) build.

use std::path::Path;
use std::process::Command;

use ledge_shared::scene::{run_scripted, warmup_room};

const TICKS: u64 = 100_000;

fn scripted_hash(ticks: u64) -> u64 {
    let mut w = warmup_room();
    run_scripted(&mut w, ticks);
    w.state_hash()
}

#[test]
fn repeated_runs_and_a_cloned_state_agree() {
    let a = scripted_hash(TICKS);
    assert_eq!(a, scripted_hash(TICKS));
    // A clone taken mid-run (what a client does to predict) ends the same.
    let mut w = warmup_room();
    run_scripted(&mut w, TICKS / 2);
    let mut c = w.clone();
    assert_eq!(c.state_hash(), w.state_hash());
    run_scripted(&mut w, TICKS / 2);
    run_scripted(&mut c, TICKS / 2);
    assert_eq!(w.state_hash(), a);
    assert_eq!(c.state_hash(), a);
    // And the hash does depend on the run.
    assert_ne!(scripted_hash(TICKS - 1), a);
}

#[test]
fn debug_and_release_builds_agree() {
    let here = format!("{:016x}", scripted_hash(TICKS));
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = Command::new(env!("CARGO"))
        .current_dir(&root)
        // Plain rustc: CI lints while it builds (.ci/run sets clippy-driver
        // as the workspace's compiler wrapper), and this release build is
        // for the hashes, not the lint.
        .env_remove("RUSTC_WORKSPACE_WRAPPER")
        .env_remove("CLIPPY_ARGS")
        .args([
            "run",
            "--quiet",
            "--release",
            "-p",
            "ledge-shared",
            "--bin",
            "ledge-determinism",
            "--",
        ])
        .arg(TICKS.to_string())
        .output()
        .expect("run cargo");
    assert!(
        out.status.success(),
        "release example failed: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let release = String::from_utf8(out.stdout).expect("utf-8 output");
    assert_eq!(
        release.trim(),
        here,
        "release build hash differs from debug"
    );
    // The example prints only the hash.
    assert_eq!(release, format!("{here}\n"));
}
