//! Helpers shared by the client's integration tests that run a real binary
//! against a real server in-process on loopback.
#![allow(dead_code)] // Each test file uses its own subset.

use std::net::SocketAddr;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use ledge_client::Fingerprint;
use ledge_server::{Server, ServerConfig, ShutdownHandle};

/// A real server on loopback, in-process, on its own runtime, for one test.
pub struct TestServer {
    pub addr: SocketAddr,
    pub fingerprint: Fingerprint,
    shutdown: ShutdownHandle,
    runtime: tokio::runtime::Runtime,
    task: tokio::task::JoinHandle<Result<(), ledge_server::ServerError>>,
    _certs: tempfile::TempDir,
}

impl TestServer {
    /// Starts a server with the default settings and a temporary
    /// certificate directory.
    pub fn start() -> TestServer {
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
        TestServer {
            addr,
            fingerprint,
            shutdown,
            runtime,
            task,
            _certs: certs,
        }
    }

    /// Shuts the server down and waits (bounded) for it.
    pub fn stop(self) {
        self.shutdown.shutdown();
        let task = self.task;
        self.runtime.block_on(async {
            let _ = tokio::time::timeout(Duration::from_secs(5), task).await;
        });
    }
}

/// Runs `command` to its end with piped output; kills it and fails the test
/// (showing its stderr) if it has not exited within `timeout`.
pub fn run_to_end(mut command: Command, timeout: Duration) -> Output {
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let deadline = Instant::now() + timeout;
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            let out = child.wait_with_output().unwrap();
            panic!(
                "the binary did not exit within {timeout:?}; stderr:\n{}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}
