//! `--local`: the real server in-process on `127.0.0.1:0`, playing the
//! embedded default level, on a tokio runtime of its own thread; the front
//! end then joins it over QUIC like any other client.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::mpsc;
use std::thread;

use anyhow::Context;
use ledge_client::Fingerprint;
use ledge_server::{Server, ServerConfig, ShutdownHandle};

/// A server running on a background thread; stopped when dropped.
pub struct LocalServer {
    /// Where it listens.
    pub addr: SocketAddr,
    /// Its certificate's fingerprint (freshly generated).
    pub fingerprint: Fingerprint,
    shutdown: ShutdownHandle,
    thread: Option<thread::JoinHandle<()>>,
    cert_dir: PathBuf,
}

impl LocalServer {
    /// Binds the server and starts it; returns once it listens.
    pub fn start() -> anyhow::Result<LocalServer> {
        let cert_dir = std::env::temp_dir().join(format!("ledge-local-{}", std::process::id()));
        let config = ServerConfig {
            bind: SocketAddr::from(([127, 0, 0, 1], 0)),
            cert_dir: cert_dir.clone(),
            ..ServerConfig::default()
        };
        let (ready_tx, ready_rx) = mpsc::channel();
        let thread = thread::Builder::new()
            .name("ledge-local-server".into())
            .spawn(move || {
                let runtime = match tokio::runtime::Builder::new_multi_thread()
                    .worker_threads(1)
                    .thread_name("ledge-local-server")
                    .enable_all()
                    .build()
                {
                    Ok(rt) => rt,
                    Err(e) => {
                        let _ = ready_tx.send(Err(anyhow::anyhow!("tokio runtime: {e}")));
                        return;
                    }
                };
                runtime.block_on(async move {
                    let server = match Server::bind(config) {
                        Ok(s) => s,
                        Err(e) => {
                            let _ = ready_tx.send(Err(anyhow::anyhow!("binding: {e}")));
                            return;
                        }
                    };
                    let ready = (
                        server.local_addr(),
                        server.fingerprint(),
                        server.shutdown_handle(),
                    );
                    if ready_tx.send(Ok(ready)).is_err() {
                        return;
                    }
                    if let Err(e) = server.run().await {
                        tracing::error!("local server stopped: {e}");
                    }
                });
            })
            .context("starting the local server thread")?;
        let (addr, fingerprint, shutdown) = ready_rx
            .recv()
            .context("the local server thread ended early")?
            .context("starting the local server")?;
        tracing::info!(%addr, %fingerprint, "local server listening");
        Ok(LocalServer {
            addr,
            fingerprint,
            shutdown,
            thread: Some(thread),
            cert_dir,
        })
    }
}

impl Drop for LocalServer {
    fn drop(&mut self) {
        self.shutdown.shutdown();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
        let _ = std::fs::remove_dir_all(&self.cert_dir);
    }
}
