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
    start_with(&["--bind", bind], cert_dir)
}

/// The server with `args`, its certificates in `cert_dir`.
fn start_with(args: &[&str], cert_dir: &std::path::Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_ledge-server"))
        .args(args)
        .arg("--cert-dir")
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

/// All the child's stderr (to its end: call once it exited).
fn stderr_of(child: &mut Child) -> String {
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    err
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

/// What a server bound to `bind` printed until Ctrl-C stopped it
/// (cleanly, within 5 s) after its first three lines.
struct Printed {
    /// The first three lines of stdout: address, fingerprint, first join
    /// line.
    head: Vec<String>,
    /// The rest of stdout.
    rest: String,
    /// All of stderr.
    err: String,
    /// The port it listened on.
    port: String,
    /// Its certificate's fingerprint.
    fingerprint: String,
}

fn run_until_interrupted(bind: &str) -> Printed {
    let certs = tempfile::tempdir().unwrap();
    let mut child = start_on(bind, certs.path());
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut head = Vec::new();
    for _ in 0..3 {
        let mut line = String::new();
        stdout.read_line(&mut line).unwrap();
        head.push(line.trim_end().to_owned());
    }
    interrupt(&child);
    let status = exits_within(&mut child, Duration::from_secs(5)).expect("stopped on SIGINT");
    assert!(status.success(), "{status}");
    let err = stderr_of(&mut child);
    let mut rest = String::new();
    stdout.read_to_string(&mut rest).unwrap();
    let port = head[0].rsplit(':').next().unwrap().to_owned();
    let fingerprint = head[1]
        .strip_prefix("certificate SHA-256 fingerprint: ")
        .unwrap_or_else(|| panic!("no fingerprint line: {head:?}"))
        .to_owned();
    Printed {
        head,
        rest,
        err,
        port,
        fingerprint,
    }
}

/// The join command for `ip` of the server that printed `p`.
fn join_command(p: &Printed, ip: &str) -> String {
    format!(
        "cargo run --release -p ledge-client -- --connect {ip}:{} --cert-hash {} \
         --name YOUR_NAME",
        p.port, p.fingerprint
    )
}

#[test]
fn logs_go_to_stderr_without_colour_and_stdout_says_how_to_join() {
    let p = run_until_interrupted("127.0.0.1:0");
    let (lines, err, rest) = (&p.head, &p.err, &p.rest);
    assert!(
        lines[0].starts_with("ledge server listening on 127.0.0.1:"),
        "{lines:?}"
    );
    // Bound to one address: one join line, for this machine.
    assert_eq!(
        lines[2],
        format!("join from this machine: {}", join_command(&p, "127.0.0.1"))
    );
    assert!(
        err.contains("INFO") && err.contains("room started"),
        "{err}"
    );
    assert!(
        !err.contains('\u{1b}'),
        "colour codes in a log that is not a terminal: {err:?}"
    );
    assert!(!rest.contains("INFO"), "logs on stdout: {rest}");
    assert!(!rest.contains("join"), "one join line: {rest}");
    // Last, what the level's warnings come to (the embedded level has none).
    assert!(
        rest.lines().any(|l| l == "level \"default\": no warnings"),
        "{rest}"
    );
}

#[test]
fn bound_to_all_interfaces_it_says_how_to_join_at_each_address() {
    let p = run_until_interrupted("0.0.0.0:0");
    assert!(p.head[0].starts_with("ledge server listening on 0.0.0.0:"));
    let joins: Vec<&str> = p.head[2..]
        .iter()
        .map(String::as_str)
        .chain(p.rest.lines())
        .filter(|l| l.starts_with("join"))
        .collect();
    // This machine first, then every IPv4 address of an interface that
    // is up, named.
    assert_eq!(
        joins[0],
        format!("join from this machine: {}", join_command(&p, "127.0.0.1"))
    );
    let mut expected: Vec<String> = Vec::new();
    for i in if_addrs::get_if_addrs().unwrap() {
        let ip = i.ip();
        if ip.is_ipv4() && !ip.is_loopback() && i.oper_status != if_addrs::IfOperStatus::Down {
            let line = format!(
                "join from your network ({}): {}",
                i.name,
                join_command(&p, &ip.to_string())
            );
            if !expected.iter().any(|e| e.contains(&format!(" {ip}:"))) {
                expected.push(line);
            }
        }
    }
    assert_eq!(joins[1..], expected, "{:?}{}", p.head, p.rest);
    if expected.is_empty() {
        assert!(p.rest.contains("no network interface found"), "{}", p.rest);
    }
}

#[test]
fn a_port_in_use_fails_naming_the_option_to_change() {
    let taken = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap();
    let certs = tempfile::tempdir().unwrap();
    let mut child = start_on(&addr.to_string(), certs.path());
    let status = exits_within(&mut child, Duration::from_secs(30)).expect("exits");
    let err = stderr_of(&mut child);
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

/// `GET /metrics` from `addr`: the body.
fn scrape(addr: &str) -> String {
    use std::io::Write;
    let mut stream = std::net::TcpStream::connect(addr).expect("metrics endpoint");
    write!(
        stream,
        "GET /metrics HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut text = String::new();
    stream.read_to_string(&mut text).unwrap();
    text
}

/// The value of the metric line starting `name ` in a scrape.
fn metric(text: &str, name: &str) -> f64 {
    text.lines()
        .find_map(|l| l.strip_prefix(name)?.strip_prefix(' '))
        .unwrap_or_else(|| panic!("no {name} in:\n{text}"))
        .trim()
        .parse()
        .unwrap()
}

#[test]
fn one_thread_runs_the_whole_server() {
    let certs = tempfile::tempdir().unwrap();
    let mut child = start_with(
        &[
            "--bind",
            "127.0.0.1:0",
            "--metrics-bind",
            "127.0.0.1:0",
            "--threads",
            "1",
        ],
        certs.path(),
    );
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    let metrics = loop {
        line.clear();
        assert!(stdout.read_line(&mut line).unwrap() > 0, "no metrics line");
        if let Some(url) = line.trim().strip_prefix("metrics at http://") {
            break url.trim_end_matches("/metrics").to_owned();
        }
    };
    // The process is one thread: the runtime's, which is main's. The
    // records database's migration used an SQLite connection, whose worker
    // thread (sqlx runs SQLite on one) ends just after the connection is
    // closed: wait for it, a moment at most.
    let threads_now = || {
        let status = std::fs::read_to_string(format!("/proc/{}/status", child.id())).unwrap();
        let threads = status
            .lines()
            .find_map(|l| l.strip_prefix("Threads:"))
            .unwrap()
            .trim()
            .to_owned();
        (threads, status)
    };
    let deadline = Instant::now() + Duration::from_secs(5);
    let (threads, status) = loop {
        let (threads, status) = threads_now();
        if threads == "1" || Instant::now() > deadline {
            break (threads, status);
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(threads, "1", "{status}");
    // Its room ticks on it: 60 a second.
    let ticks = |text: &str| metric(text, "ledge_tick_duration_seconds_count{room=\"room-1\"}");
    let before = ticks(&scrape(&metrics));
    std::thread::sleep(Duration::from_millis(500));
    let after = ticks(&scrape(&metrics));
    assert!(after - before >= 10.0, "{before} -> {after} ticks in 0.5 s");
    interrupt(&child);
    let status = exits_within(&mut child, Duration::from_secs(5)).expect("stopped on SIGINT");
    assert!(status.success(), "{status}: {}", stderr_of(&mut child));

    // Zero threads is refused, saying the range.
    let mut child = start_with(&["--bind", "127.0.0.1:0", "--threads", "0"], certs.path());
    let status = exits_within(&mut child, Duration::from_secs(30)).expect("exits");
    let err = stderr_of(&mut child);
    assert_eq!(status.code(), Some(1), "{err}");
    assert!(err.contains("threads must be 1..=1024"), "{err}");
}
