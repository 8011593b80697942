//! QUIC/TLS configuration of the server endpoint.
//!
//! TLS 1.3 only (QUIC requires it) with the ring provider chosen
//! explicitly, so the build never depends on a process-wide default
//! provider; ALPN [`ALPN`]; one control stream per connection.

use std::sync::Arc;
use std::time::Duration;

use quinn::crypto::rustls::QuicServerConfig;

use crate::cert::Identity;
use crate::protocol::ALPN;

/// A connection with no traffic for this long is dropped (clients send
/// keep-alives well within it).
pub const IDLE_TIMEOUT: Duration = Duration::from_secs(10);

/// Why the TLS/QUIC configuration could not be built.
#[derive(Debug, thiserror::Error)]
pub enum TlsError {
    /// rustls refused the protocol versions or the certificate/key.
    #[error("TLS configuration: {0}")]
    Rustls(#[from] rustls::Error),
    /// The rustls configuration is unusable for QUIC.
    #[error("QUIC crypto configuration: {0}")]
    Quic(#[from] quinn::crypto::rustls::NoInitialCipherSuite),
}

/// The quinn server configuration serving `identity`.
pub fn server_config(identity: &Identity) -> Result<quinn::ServerConfig, TlsError> {
    let provider = Arc::new(rustls::crypto::ring::default_provider());
    let mut tls = rustls::ServerConfig::builder_with_provider(provider)
        .with_protocol_versions(&[&rustls::version::TLS13])?
        .with_no_client_auth()
        .with_single_cert(vec![identity.cert.clone()], identity.key.clone_key())?;
    tls.alpn_protocols = vec![ALPN.to_vec()];
    let mut config = quinn::ServerConfig::with_crypto(Arc::new(QuicServerConfig::try_from(tls)?));
    let mut transport = quinn::TransportConfig::default();
    transport
        .max_idle_timeout(Some(
            quinn::IdleTimeout::try_from(IDLE_TIMEOUT).expect("constant fits a QUIC varint"),
        ))
        // One control stream; datagrams will carry inputs and snapshots.
        .max_concurrent_bidi_streams(1u8.into())
        .max_concurrent_uni_streams(0u8.into());
    config.transport_config(Arc::new(transport));
    Ok(config)
}
