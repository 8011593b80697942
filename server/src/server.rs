//! The server: endpoint, room and connection tasks, and their shutdown.

use std::net::SocketAddr;
use std::time::Duration;

use tokio::sync::watch;
use tokio::task::JoinSet;
use tracing::{error, info, warn};

use crate::cert::{CertError, Identity};
use crate::config::ServerConfig;
use crate::connection;
use crate::fingerprint::Fingerprint;
use crate::protocol::CloseCode;
use crate::room::{self, RoomConfig};
use crate::tls::{self, TlsError};

/// How long shutdown waits for connection tasks and the endpoint to finish.
const SHUTDOWN_GRACE: Duration = Duration::from_secs(3);

/// Why the server could not start.
#[derive(Debug, thiserror::Error)]
pub enum ServerError {
    /// The certificate could not be loaded or created.
    #[error(transparent)]
    Cert(#[from] CertError),
    /// The TLS/QUIC configuration was refused.
    #[error(transparent)]
    Tls(#[from] TlsError),
    /// The UDP socket could not be bound.
    #[error("cannot bind {addr}: {source}")]
    Bind {
        /// The address asked for.
        addr: SocketAddr,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// A bound, not yet running server.
///
/// `bind` then `run`; keep a [`ShutdownHandle`] to stop it. Tests bind to
/// `127.0.0.1:0` and read the real port from [`Server::local_addr`].
#[derive(Debug)]
pub struct Server {
    endpoint: quinn::Endpoint,
    local_addr: SocketAddr,
    fingerprint: Fingerprint,
    config: ServerConfig,
    shutdown: watch::Sender<bool>,
}

/// Asks a running server to shut down gracefully. Cloneable; any clone works.
#[derive(Debug, Clone)]
pub struct ShutdownHandle(watch::Sender<bool>);

impl ShutdownHandle {
    /// Requests shutdown: [`Server::run`] closes every connection and returns.
    pub fn shutdown(&self) {
        self.0.send_replace(true);
    }
}

impl Server {
    /// Loads or creates the certificate and binds the QUIC endpoint.
    ///
    /// Must be called inside a tokio runtime (the endpoint registers its
    /// socket with it).
    pub fn bind(config: ServerConfig) -> Result<Server, ServerError> {
        let identity = Identity::load_or_generate(&config.cert_dir)?;
        if identity.generated {
            info!(dir = %config.cert_dir.display(), "generated a new self-signed certificate");
        }
        let quic = tls::server_config(&identity)?;
        let bind_err = |source| ServerError::Bind {
            addr: config.bind,
            source,
        };
        let endpoint = quinn::Endpoint::server(quic, config.bind).map_err(bind_err)?;
        let local_addr = endpoint.local_addr().map_err(bind_err)?;
        Ok(Server {
            endpoint,
            local_addr,
            fingerprint: identity.fingerprint,
            config,
            shutdown: watch::Sender::new(false),
        })
    }

    /// The address actually bound (the real port when binding port 0).
    pub fn local_addr(&self) -> SocketAddr {
        self.local_addr
    }

    /// SHA-256 of the certificate: what clients pin.
    pub fn fingerprint(&self) -> Fingerprint {
        self.fingerprint
    }

    /// A handle that stops [`Server::run`].
    pub fn shutdown_handle(&self) -> ShutdownHandle {
        ShutdownHandle(self.shutdown.clone())
    }

    /// Runs the room and serves connections until shutdown is requested,
    /// then closes every connection and waits (bounded) for the endpoint to
    /// go idle.
    pub async fn run(self) -> Result<(), ServerError> {
        let Server {
            endpoint,
            local_addr,
            config,
            shutdown,
            ..
        } = self;
        let mut stop = shutdown.subscribe();
        let (room, room_task) = room::spawn(
            ledge_shared::scene::warmup_room(),
            RoomConfig {
                tick_rate: config.tick_rate,
                max_catch_up: config.max_catch_up,
            },
        );
        info!(%local_addr, "listening");
        let mut connections = JoinSet::new();
        loop {
            tokio::select! {
                // `shutdown` lives until the end of `run`, so this never errs.
                _ = stop.wait_for(|&stop| stop) => break,
                incoming = endpoint.accept() => match incoming {
                    Some(incoming) => {
                        connections.spawn(connection::serve(incoming, room.clone()));
                    }
                    None => break,
                },
                Some(done) = connections.join_next(), if !connections.is_empty() => {
                    if let Err(e) = done {
                        error!("connection task failed: {e}");
                    }
                }
            }
        }

        info!("shutting down");
        endpoint.close(CloseCode::ServerShutdown.into(), b"server shutting down");
        let drained = tokio::time::timeout(SHUTDOWN_GRACE, async {
            while connections.join_next().await.is_some() {}
        })
        .await;
        if drained.is_err() {
            warn!("connection tasks still running after {SHUTDOWN_GRACE:?}; aborting them");
            connections.shutdown().await;
        }
        if tokio::time::timeout(SHUTDOWN_GRACE, endpoint.wait_idle())
            .await
            .is_err()
        {
            warn!("endpoint not idle after {SHUTDOWN_GRACE:?}");
        }
        // The room stops once its last handle is gone.
        drop(room);
        if let Err(e) = room_task.await {
            error!("room task failed: {e}");
        }
        drop(shutdown);
        info!("stopped");
        Ok(())
    }
}
