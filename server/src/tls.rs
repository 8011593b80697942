//! QUIC/TLS configuration of the server endpoint.
//!
//! TLS 1.3 only (QUIC requires it) with the ring provider chosen
//! explicitly, so the build never depends on a process-wide default
//! provider; ALPN [`ALPN`]; one control stream per connection; small,
//! bounded buffers for datagrams and the control stream, so nothing a
//! client sends can make the server buffer much, and stale snapshots are
//! dropped rather than queued behind newer ones.

use std::sync::Arc;
use std::time::Duration;

use ledge_shared::protocol::ALPN;
use quinn::crypto::rustls::QuicServerConfig;

use crate::quic_cert::Identity;

/// Outgoing datagram buffer per connection, in bytes: about two
/// snapshots. When it is full quinn drops the oldest queued datagram, so a
/// congested client gets the newest snapshot, not a backlog.
pub const DATAGRAM_SEND_BUFFER: usize = 4 * 1024;
/// Incoming datagram buffer per connection, in bytes (about 100 input
/// packets); older ones are dropped when a client floods.
pub const DATAGRAM_RECEIVE_BUFFER: usize = 8 * 1024;
/// Flow-control window of the control stream, in bytes: the most a client
/// can make the server buffer on it.
pub const STREAM_RECEIVE_WINDOW: u32 = 16 * 1024;

/// Why the TLS/QUIC configuration could not be built.
#[derive(Debug, thiserror::Error)]
pub enum TlsError {
    /// rustls refused the protocol versions or the certificate/key.
    #[error("TLS configuration: {0}")]
    Rustls(#[from] rustls::Error),
    /// The rustls configuration is unusable for QUIC.
    #[error("QUIC crypto configuration: {0}")]
    Quic(#[from] quinn::crypto::rustls::NoInitialCipherSuite),
    /// The idle timeout does not fit QUIC's encoding.
    #[error("idle timeout {0:?} is out of range")]
    IdleTimeout(Duration),
}

/// The quinn server configuration serving `identity`; connections silent
/// for `idle_timeout` are dropped.
pub fn server_config(
    identity: &Identity,
    idle_timeout: Duration,
) -> Result<quinn::ServerConfig, TlsError> {
    let provider = Arc::new(rustls::crypto::ring::default_provider());
    let mut tls = rustls::ServerConfig::builder_with_provider(provider)
        .with_protocol_versions(&[&rustls::version::TLS13])?
        .with_no_client_auth()
        .with_single_cert(vec![identity.cert.clone()], identity.key.clone_key())?;
    tls.alpn_protocols = vec![ALPN.to_vec()];
    let mut config = quinn::ServerConfig::with_crypto(Arc::new(QuicServerConfig::try_from(tls)?));
    let mut transport = quinn::TransportConfig::default();
    // Resume within a round trip after an outage (see `ledge_quic`).
    ledge_quic::install(&mut transport)
        .max_idle_timeout(Some(
            quinn::IdleTimeout::try_from(idle_timeout)
                .map_err(|_| TlsError::IdleTimeout(idle_timeout))?,
        ))
        // Keeps a quiet client's path alive from our side too.
        .keep_alive_interval(Some(idle_timeout / 3))
        .max_concurrent_bidi_streams(1u8.into())
        .max_concurrent_uni_streams(0u8.into())
        .stream_receive_window(STREAM_RECEIVE_WINDOW.into())
        .receive_window((4 * STREAM_RECEIVE_WINDOW).into())
        .datagram_receive_buffer_size(Some(DATAGRAM_RECEIVE_BUFFER))
        .datagram_send_buffer_size(DATAGRAM_SEND_BUFFER);
    config.transport_config(Arc::new(transport));
    Ok(config)
}
