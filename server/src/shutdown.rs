//! The shutdown signal: a `watch` flag that turns true once, the handle
//! that raises it ([`ShutdownHandle`]) and the wait for it (`stopped`).
//!
//! Separate from [`crate::server`], which owns the flag, so that every task
//! ending with the server (connections, the metrics endpoint, the web port,
//! certificate rotation, the Agones driver) can wait for the signal, or
//! raise it, without importing the server that starts it.

use tokio::sync::watch;

/// Asks a running server to shut down gracefully. Cloneable; any clone works.
#[derive(Debug, Clone)]
pub struct ShutdownHandle(pub(crate) watch::Sender<bool>);

impl ShutdownHandle {
    /// Requests shutdown: every client gets `Notice{Shutdown}`, connections
    /// close with [`CloseCode::ServerShutdown`] and [`Server::run`] returns.
    ///
    /// [`CloseCode::ServerShutdown`]: ledge_shared::protocol::CloseCode::ServerShutdown
    /// [`Server::run`]: crate::Server::run
    pub fn shutdown(&self) {
        self.0.send_replace(true);
    }
}

/// Resolves once the shutdown flag is true (at once if it already is, or if
/// the sender is gone).
pub(crate) async fn stopped(flag: &mut watch::Receiver<bool>) {
    let _ = flag.wait_for(|&stop| stop).await;
}
