//! `ledge-bot --brain thin` (the thin bots `ledge-load --client thin`
//! starts) against a real server in-process on loopback: every bot joins,
//! sends an input per tick, receives snapshots, leaves cleanly, and prints
//! the report line `ledge-load` reads.

use std::net::SocketAddr;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use ledge_server::{Server, ServerConfig};

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
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .unwrap();
    let certs = tempfile::tempdir().unwrap();
    let (addr, fingerprint, shutdown, task) = runtime.block_on(async {
        let server = Server::bind(ServerConfig {
            bind: SocketAddr::from(([127, 0, 0, 1], 0)),
            cert_dir: certs.path().to_owned(),
            ..ServerConfig::default()
        })
        .expect("server binds");
        (
            server.local_addr(),
            server.fingerprint(),
            server.shutdown_handle(),
            tokio::spawn(server.run()),
        )
    });

    let mut child = Command::new(env!("CARGO_BIN_EXE_ledge-bot"))
        .args(["--connect", &addr.to_string()])
        .args(["--cert-hash", &fingerprint.to_string()])
        .args(["--brain", "thin", "--count", "3", "--seconds", "2"])
        .args(["--name", "p1"])
        .env("RUST_LOG", "warn")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("ledge-bot starts");
    let deadline = Instant::now() + BOT_TIMEOUT;
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("ledge-bot did not exit within {BOT_TIMEOUT:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = child.wait_with_output().unwrap();
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

    shutdown.shutdown();
    runtime.block_on(async {
        let _ = tokio::time::timeout(Duration::from_secs(5), task).await;
    });
}
