//! The real `ledge-server` binary as a child process, for tests that kill
//! it (`SIGKILL`) or restart it: where it listens and its certificate's
//! fingerprint, read from the lines it prints for the host.

use std::io::{BufRead, BufReader};
use std::net::SocketAddr;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use ledge_shared::protocol::Fingerprint;

/// The `ledge-server` binary built beside this test binary (`cargo nextest
/// run --workspace` builds it, for the server's own tests).
pub fn server_binary() -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    // target/PROFILE/deps/TEST -> target/PROFILE/ledge-server
    let dir = exe
        .parent()
        .and_then(|deps| deps.parent())
        .expect("the test binary is in target/PROFILE/deps");
    let bin = dir.join("ledge-server");
    assert!(
        bin.is_file(),
        "{} is missing: build it first (cargo build -p ledge-server, or run the whole \
         workspace's tests as scripts/test does)",
        bin.display()
    );
    bin
}

/// A running `ledge-server` process, killed (and reaped) when dropped.
#[derive(Debug)]
pub struct ServerProcess {
    child: Child,
    /// Where it listens (QUIC).
    pub addr: SocketAddr,
    /// Its certificate's fingerprint.
    pub fingerprint: Fingerprint,
}

impl ServerProcess {
    /// Starts the server with `args` (add `--bind 127.0.0.1:0`) and waits
    /// (up to 20 s) for the lines saying where it listens.
    pub fn start(args: &[&str]) -> ServerProcess {
        let mut child = Command::new(server_binary())
            .args(args)
            .env("RUST_LOG", "warn")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("ledge-server starts");
        let stdout = child.stdout.take().expect("piped");
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut lines = BufReader::new(stdout).lines();
            let mut addr = None;
            while let Some(Ok(line)) = lines.next() {
                if let Some(a) = line.strip_prefix("ledge server listening on ") {
                    addr = a.trim().parse::<SocketAddr>().ok();
                }
                if let Some(f) = line.strip_prefix("certificate SHA-256 fingerprint: ") {
                    let _ = tx.send((addr, f.trim().parse::<Fingerprint>().ok()));
                }
            }
        });
        let (addr, fingerprint) = match rx.recv_timeout(Duration::from_secs(20)) {
            Ok((Some(addr), Some(fp))) => (addr, fp),
            other => {
                let _ = child.kill();
                panic!("ledge-server did not say where it listens: {other:?}");
            }
        };
        ServerProcess {
            child,
            addr,
            fingerprint,
        }
    }

    /// Kills it at once (`SIGKILL`: no goodbye, no flush) and reaps it.
    pub fn kill_now(&self) {
        // SAFETY: kill(2) on our own child's pid, which is not reaped yet
        // (the child is reaped only in `drop`).
        unsafe {
            libc::kill(self.child.id() as libc::pid_t, libc::SIGKILL);
        }
    }
}

impl Drop for ServerProcess {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
