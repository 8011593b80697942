//! The real `ledge-server` binary as a host runs it: logs on stderr without
//! colour codes when stderr is not a terminal, the join instructions on
//! stdout, and Ctrl-C (SIGINT) stops it promptly even after whoever read its
//! output went away (`ledge-server 2>&1 | head -1`), and a port in use is
//! a failure (exit code 1) saying which option to change.

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn start(cert_dir: &std::path::Path) -> Child {
    start_on("127.0.0.1:0", cert_dir)
}

fn start_on(bind: &str, cert_dir: &std::path::Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_ledge-server"))
        .args(["--bind", bind, "--cert-dir"])
        .arg(cert_dir)
        .env("RUST_LOG", "info")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("ledge-server starts")
}

fn interrupt(child: &Child) {
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success());
}

/// Waits up to `limit` for the child to exit.
fn exits_within(child: &mut Child, limit: Duration) -> Option<std::process::ExitStatus> {
    let deadline = Instant::now() + limit;
    while Instant::now() < deadline {
        if let Some(status) = child.try_wait().unwrap() {
            return Some(status);
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    None
}

#[test]
fn logs_go_to_stderr_without_colour_and_stdout_says_how_to_join() {
    let certs = tempfile::tempdir().unwrap();
    let mut child = start(certs.path());
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut lines = Vec::new();
    for _ in 0..3 {
        let mut line = String::new();
        stdout.read_line(&mut line).unwrap();
        lines.push(line);
    }
    interrupt(&child);
    let status = exits_within(&mut child, Duration::from_secs(5)).expect("stopped on SIGINT");
    assert!(status.success(), "{status}");
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert!(
        lines[0].starts_with("ledge server listening on 127.0.0.1:"),
        "{lines:?}"
    );
    assert!(
        lines[1].starts_with("certificate SHA-256 fingerprint: "),
        "{lines:?}"
    );
    assert!(lines[2].starts_with("connect with: "), "{lines:?}");
    assert!(
        err.contains("INFO") && err.contains("room started"),
        "{err}"
    );
    assert!(
        !err.contains('\u{1b}'),
        "colour codes in a log that is not a terminal: {err:?}"
    );
    let mut rest = String::new();
    stdout.read_to_string(&mut rest).unwrap();
    assert!(!rest.contains("INFO"), "logs on stdout: {rest}");
}

#[test]
fn sigint_stops_it_after_its_readers_went_away() {
    let certs = tempfile::tempdir().unwrap();
    let mut child = start(certs.path());
    // `2>&1 | head -1`: read one line, then close both pipes.
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    stdout.read_line(&mut line).unwrap();
    assert!(line.starts_with("ledge server listening"), "{line}");
    drop(stdout);
    drop(child.stderr.take());
    std::thread::sleep(Duration::from_millis(300));
    interrupt(&child);
    let started = Instant::now();
    let status = exits_within(&mut child, Duration::from_secs(2));
    assert!(
        status.is_some(),
        "still running {:?} after SIGINT",
        started.elapsed()
    );
}

#[test]
fn a_port_in_use_fails_naming_the_option_to_change() {
    let taken = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap();
    let certs = tempfile::tempdir().unwrap();
    let mut child = start_on(&addr.to_string(), certs.path());
    let status = exits_within(&mut child, Duration::from_secs(30)).expect("exits");
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert_eq!(status.code(), Some(1), "{err}");
    let next = format!("--bind 127.0.0.1:{}", addr.port() + 1);
    for needle in [
        "ledge-server: ",
        &format!("cannot bind {addr}"),
        &format!("uses port {}", addr.port()),
        &next,
    ] {
        assert!(err.contains(needle), "{needle:?} missing from:\n{err}");
    }
    // Words, not a debug report; the cause said once.
    assert!(!err.contains("Caused by") && !err.contains("Os {"), "{err}");
    assert_eq!(err.matches("in use").count(), 1, "{err}");
    drop(taken);
}
