//! `ledge-tests`: helpers for end-to-end tests of ledge over real QUIC.
//!
//! [`TestServer::start`] runs the real server in-process on `127.0.0.1:0`
//! with a throw-away certificate directory; tests connect to it with the
//! headless client library exactly as players and bots do.

use std::net::SocketAddr;
use std::time::Duration;

use ledge_server::{Fingerprint, Server, ServerConfig, ServerError, ShutdownHandle};
use tokio::task::JoinHandle;

/// How long [`TestServer::stop`] may take before it counts as hung.
pub const STOP_TIMEOUT: Duration = Duration::from_secs(5);

/// A server running in-process on loopback, stopped on [`TestServer::stop`]
/// (or aborted when dropped).
#[derive(Debug)]
pub struct TestServer {
    /// Where the server listens (loopback, ephemeral port).
    pub addr: SocketAddr,
    /// SHA-256 of its freshly generated certificate.
    pub fingerprint: Fingerprint,
    shutdown: ShutdownHandle,
    task: Option<JoinHandle<Result<(), ServerError>>>,
    _cert_dir: tempfile::TempDir,
}

impl TestServer {
    /// Starts a server at the default tick rate. Call inside a tokio runtime.
    pub async fn start() -> TestServer {
        Self::start_with(|_| {}).await
    }

    /// Starts a server after letting `adjust` change its configuration
    /// (the address and certificate directory are set for you).
    pub async fn start_with(adjust: impl FnOnce(&mut ServerConfig)) -> TestServer {
        let cert_dir = tempfile::tempdir().expect("temporary certificate directory");
        let mut config = ServerConfig {
            bind: SocketAddr::from(([127, 0, 0, 1], 0)),
            cert_dir: cert_dir.path().to_owned(),
            ..ServerConfig::default()
        };
        adjust(&mut config);
        let server = Server::bind(config).expect("server binds to loopback");
        TestServer {
            addr: server.local_addr(),
            fingerprint: server.fingerprint(),
            shutdown: server.shutdown_handle(),
            task: Some(tokio::spawn(server.run())),
            _cert_dir: cert_dir,
        }
    }

    /// Shuts the server down gracefully and returns what `run` returned.
    ///
    /// Panics if shutdown takes longer than [`STOP_TIMEOUT`].
    pub async fn stop(mut self) -> Result<(), ServerError> {
        self.shutdown.shutdown();
        let task = self.task.take().expect("stop is called once");
        tokio::time::timeout(STOP_TIMEOUT, task)
            .await
            .expect("server shut down in time")
            .expect("server task did not panic")
    }
}

impl Drop for TestServer {
    fn drop(&mut self) {
        if let Some(task) = self.task.take() {
            self.shutdown.shutdown();
            task.abort();
        }
    }
}
