//! The real `ledge-client` binary's trust options against a real server:
//! `--connect` without `--cert-hash` trusts on first use with a known-hosts
//! file, and a changed certificate is refused on the terminal (before any
//! window opens) with the message saying what to do, and exit code 3.
//!
//! The refusal needs no display. The first-use test opens a window, so it
//! runs under `xvfb-run` like the screenshot test (skipped with a notice
//! when it is missing, failing when `CI=true`).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use common::{run_to_end, xvfb_or_skip, TestServer};
use ledge_client::Fingerprint;

/// The client must have exited within this time.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(60);

/// Exit code of a refused certificate.
const EXIT_UNTRUSTED: i32 = 3;

/// Runs `command` to its end (killed after [`CLIENT_TIMEOUT`]).
fn run(command: Command) -> Output {
    run_to_end(command, CLIENT_TIMEOUT)
}

/// The client binary, with no configuration directory of the user's.
fn client(config_home: &Path) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_ledge-client"));
    command
        .env("XDG_CONFIG_HOME", config_home)
        .env("HOME", config_home)
        .env("RUST_LOG", "warn");
    command
}

/// Asserts the client refused the certificate as the known-hosts file at
/// `path` (line 1) says, and told the player what to do.
fn assert_refused(out: &Output, server: &TestServer, wrong: Fingerprint, path: &Path) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(EXIT_UNTRUSTED),
        "a changed certificate exits with {EXIT_UNTRUSTED}; stderr:\n{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    for needle in [
        "CHANGED".to_owned(),
        server.addr.to_string(),
        server.fingerprint.to_string(),
        wrong.to_string(),
        path.display().to_string(),
        "remove line 1".to_owned(),
        format!("--cert-hash {}", server.fingerprint),
    ] {
        assert!(
            stderr.contains(&needle),
            "{needle:?} missing from:\n{stderr}"
        );
    }
}

#[test]
fn a_changed_certificate_is_refused_with_what_to_do() {
    let server = TestServer::start();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("known_hosts");
    let wrong = Fingerprint([0x5a; 32]);
    let stored = format!("{} {wrong}\n", server.addr);
    std::fs::write(&path, &stored).unwrap();

    let mut command = client(dir.path());
    command
        .args(["--connect", &server.addr.to_string()])
        .arg("--known-hosts")
        .arg(&path)
        .args(["--exit-after-ticks", "30"]);
    let out = run(command);
    assert_refused(&out, &server, wrong, &path);
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        stored,
        "the stored fingerprint is kept"
    );
    server.stop();
}

#[test]
fn the_default_known_hosts_file_is_under_the_config_directory() {
    let server = TestServer::start();
    let home = tempfile::tempdir().unwrap();
    let path: PathBuf = home.path().join("ledge").join("known_hosts");
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let wrong = Fingerprint([0xa5; 32]);
    std::fs::write(&path, format!("{} {wrong}\n", server.addr)).unwrap();

    let mut command = client(home.path());
    command
        .args(["--connect", &server.addr.to_string()])
        .args(["--exit-after-ticks", "30"]);
    let out = run(command);
    assert_refused(&out, &server, wrong, &path);
    server.stop();
}

#[test]
fn known_hosts_and_a_pin_are_exclusive_and_need_a_server() {
    let dir = tempfile::tempdir().unwrap();
    let pin = Fingerprint([1; 32]).to_string();
    let both = run({
        let mut c = client(dir.path());
        c.args(["--connect", "127.0.0.1:1", "--cert-hash", &pin])
            .args(["--known-hosts", "kh"]);
        c
    });
    assert_eq!(both.status.code(), Some(2), "a usage error");
    let stderr = String::from_utf8_lossy(&both.stderr);
    assert!(stderr.contains("cannot be used with"), "{stderr}");
    let alone = run({
        let mut c = client(dir.path());
        c.args(["--known-hosts", "kh"]);
        c
    });
    assert_eq!(alone.status.code(), Some(2), "a usage error");
    assert!(String::from_utf8_lossy(&alone.stderr).contains("--connect"));
}

#[test]
fn a_wrong_pinned_fingerprint_is_refused_saying_where_the_right_one_is() {
    let server = TestServer::start();
    let dir = tempfile::tempdir().unwrap();
    let wrong = Fingerprint([0x3c; 32]);
    let mut command = client(dir.path());
    command
        .args(["--connect", &server.addr.to_string()])
        .args(["--cert-hash", &wrong.to_string()])
        .args(["--exit-after-ticks", "30"]);
    let out = run(command);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(EXIT_UNTRUSTED),
        "a wrong --cert-hash exits with {EXIT_UNTRUSTED}; stderr:\n{stderr}"
    );
    for needle in [
        "ledge-client: ".to_owned(),
        format!("not {wrong}"),
        "certificate SHA-256 fingerprint: ...".to_owned(),
        format!("--cert-hash {}", server.fingerprint),
    ] {
        assert!(
            stderr.contains(&needle),
            "{needle:?} missing from:\n{stderr}"
        );
    }
    // Told once.
    assert_eq!(stderr.matches("ledge-client: ").count(), 1, "{stderr}");
    server.stop();
}

#[test]
fn the_first_connection_stores_the_certificate() {
    let Some(xvfb) = xvfb_or_skip("the trust-on-first-use client test") else {
        return;
    };
    let server = TestServer::start();
    let dir = tempfile::tempdir().unwrap();
    // A folder that does not exist yet: the client creates it.
    let path = dir.path().join("new").join("known_hosts");
    let mut command = Command::new(xvfb);
    command
        .args(["-a", "-s", "-screen 0 640x480x24"])
        .arg(env!("CARGO_BIN_EXE_ledge-client"))
        .args(["--connect", &server.addr.to_string()])
        .arg("--known-hosts")
        .arg(&path)
        .args(["--exit-after-ticks", "30", "--window", "320x240"])
        .env("XDG_CONFIG_HOME", dir.path())
        .env("LIBGL_ALWAYS_SOFTWARE", "1")
        .env("RUST_LOG", "warn");
    let out = run(command);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "the client failed: {stderr}");
    let text = std::fs::read_to_string(&path).expect("the known-hosts file was written");
    assert!(
        text.contains(&format!("{} {}", server.addr, server.fingerprint)),
        "{text}"
    );
    server.stop();
}
