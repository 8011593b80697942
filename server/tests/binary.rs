//! The real `ledge-server` binary as a host runs it: logs on stderr without
//! colour codes when stderr is not a terminal, the join instructions on
//! stdout (a line per address it can be reached at), Ctrl-C (SIGINT) stops
//! it promptly even after whoever read its output went away
//! (`ledge-server 2>&1 | head -1`), and a port in use is a failure (exit
//! code 1) saying which option to change.

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
    let fingerprint = lines[1]
        .trim_end()
        .strip_prefix("certificate SHA-256 fingerprint: ")
        .unwrap();
    let port = lines[0].trim_end().rsplit(':').next().unwrap();
    // Bound to one address: one join line, for this machine.
    assert_eq!(
        lines[2].trim_end(),
        format!(
            "join from this machine: cargo run --release -p ledge-client -- --connect \
             127.0.0.1:{port} --cert-hash {fingerprint} --name YOUR_NAME"
        )
    );
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
    assert!(!rest.contains("join"), "one join line: {rest}");
}

#[test]
fn bound_to_all_interfaces_it_says_how_to_join_at_each_address() {
    let certs = tempfile::tempdir().unwrap();
    let mut child = start_on("0.0.0.0:0", certs.path());
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut head = Vec::new();
    for _ in 0..3 {
        let mut line = String::new();
        stdout.read_line(&mut line).unwrap();
        head.push(line);
    }
    interrupt(&child);
    let status = exits_within(&mut child, Duration::from_secs(5)).expect("stopped on SIGINT");
    assert!(status.success(), "{status}");
    let mut rest = String::new();
    stdout.read_to_string(&mut rest).unwrap();
    let port = head[0].trim_end().rsplit(':').next().unwrap().to_owned();
    assert!(head[0].starts_with("ledge server listening on 0.0.0.0:"));
    let fingerprint = head[1]
        .trim_end()
        .strip_prefix("certificate SHA-256 fingerprint: ")
        .unwrap()
        .to_owned();
    let joins: Vec<&str> = head[2..]
        .iter()
        .map(|l| l.trim_end())
        .chain(rest.lines())
        .filter(|l| l.starts_with("join"))
        .collect();
    let command = |ip: &str| {
        format!(
            "cargo run --release -p ledge-client -- --connect {ip}:{port} \
             --cert-hash {fingerprint} --name YOUR_NAME"
        )
    };
    // This machine first, then every IPv4 address of an interface that
    // is up, named.
    assert_eq!(
        joins[0],
        format!("join from this machine: {}", command("127.0.0.1"))
    );
    let mut expected: Vec<String> = Vec::new();
    for i in if_addrs::get_if_addrs().unwrap() {
        let ip = i.ip();
        if ip.is_ipv4() && !ip.is_loopback() && i.oper_status != if_addrs::IfOperStatus::Down {
            let line = format!(
                "join from your network ({}): {}",
                i.name,
                command(&ip.to_string())
            );
            if !expected.iter().any(|e| e.contains(&format!(" {ip}:"))) {
                expected.push(line);
            }
        }
    }
    assert_eq!(joins[1..], expected, "{head:?}{rest}");
    if expected.is_empty() {
        assert!(rest.contains("no network interface found"), "{rest}");
    }
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
