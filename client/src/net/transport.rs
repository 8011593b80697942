//! Opening a QUIC connection to a ledge server, pinned by fingerprint.

use std::net::{Ipv4Addr, Ipv6Addr, SocketAddr};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use ledge_shared::protocol::{Fingerprint, ALPN};
use quinn::crypto::rustls::QuicClientConfig;

use crate::error::ClientError;
use crate::net::verifier::PinnedCertVerifier;

/// Keep-alive interval: well inside the server's 10 s idle timeout.
pub const KEEP_ALIVE: Duration = Duration::from_secs(3);
/// A connection with no traffic for this long is considered lost.
pub const IDLE_TIMEOUT: Duration = Duration::from_secs(10);
/// Outgoing datagram buffer, in bytes (a few dozen input packets).
pub const DATAGRAM_SEND_BUFFER: usize = 2048;

/// A connected QUIC endpoint; the connection is established and the
/// server's certificate matched the pin.
#[derive(Debug)]
pub struct Dialed {
    /// The local endpoint (one per connection, so closing it is local).
    pub endpoint: quinn::Endpoint,
    /// The connection to the server.
    pub connection: quinn::Connection,
}

/// Where the verifier records the fingerprint of a certificate.
type Slot = Arc<Mutex<Option<Fingerprint>>>;

/// The quinn client configuration trusting only `pin`, or any certificate
/// when `None` (TLS 1.3, ring, ALPN); with the verifier's refused and
/// presented slots.
fn client_config(
    pin: Option<Fingerprint>,
) -> Result<(quinn::ClientConfig, Slot, Slot), ClientError> {
    let provider = Arc::new(rustls::crypto::ring::default_provider());
    let verifier = Arc::new(match pin {
        Some(pin) => PinnedCertVerifier::new(pin, &provider),
        None => PinnedCertVerifier::any(&provider),
    });
    let refused = verifier.refused();
    let presented = verifier.presented();
    let mut tls = rustls::ClientConfig::builder_with_provider(provider)
        .with_protocol_versions(&[&rustls::version::TLS13])
        .map_err(|e| ClientError::Config(e.to_string()))?
        .dangerous()
        .with_custom_certificate_verifier(verifier)
        .with_no_client_auth();
    tls.alpn_protocols = vec![ALPN.to_vec()];
    let quic = QuicClientConfig::try_from(tls).map_err(|e| ClientError::Config(e.to_string()))?;
    let mut config = quinn::ClientConfig::new(Arc::new(quic));
    let mut transport = quinn::TransportConfig::default();
    // Resume within a round trip after an outage (see `ledge_quic`).
    ledge_quic::install(&mut transport)
        .keep_alive_interval(Some(KEEP_ALIVE))
        // Inputs repeat the last ticks, so an old queued one is worthless:
        // keep the queue short and let quinn drop the oldest.
        .datagram_send_buffer_size(DATAGRAM_SEND_BUFFER)
        .max_idle_timeout(Some(
            quinn::IdleTimeout::try_from(IDLE_TIMEOUT).expect("constant fits a QUIC varint"),
        ));
    config.transport_config(Arc::new(transport));
    Ok((config, refused, presented))
}

/// Connects to `addr`, trusting only the certificate whose SHA-256 is `pin`.
///
/// `server_name` is sent as SNI (a DNS name or IP literal); it is not
/// checked against the certificate, the pin is. A mismatching certificate
/// gives [`ClientError::FingerprintMismatch`].
pub async fn dial(
    addr: SocketAddr,
    server_name: &str,
    pin: Fingerprint,
) -> Result<Dialed, ClientError> {
    dial_any_or(addr, server_name, Some(pin))
        .await
        .map(|(d, _)| d)
}

/// Connects to `addr` trusting only `pin`, or any certificate when `None`
/// (trust on first use); returns the connection and the fingerprint of the
/// certificate the server presented.
pub async fn dial_any_or(
    addr: SocketAddr,
    server_name: &str,
    pin: Option<Fingerprint>,
) -> Result<(Dialed, Fingerprint), ClientError> {
    let local: SocketAddr = if addr.is_ipv6() {
        (Ipv6Addr::UNSPECIFIED, 0).into()
    } else {
        (Ipv4Addr::UNSPECIFIED, 0).into()
    };
    dial_from(local, addr, server_name, pin).await
}

/// [`dial_any_or`] from the local address `local` (e.g. `127.0.0.2:0`:
/// tests stand for another machine on a loopback address of its own).
pub async fn dial_from(
    local: SocketAddr,
    addr: SocketAddr,
    server_name: &str,
    pin: Option<Fingerprint>,
) -> Result<(Dialed, Fingerprint), ClientError> {
    let (config, refused, presented) = client_config(pin)?;
    let mut endpoint = ledge_quic::packets::client_endpoint(local).map_err(ClientError::Socket)?;
    endpoint.set_default_client_config(config);
    let connecting = endpoint.connect(addr, server_name)?;
    match connecting.await {
        Ok(connection) => {
            let fingerprint = presented
                .lock()
                .ok()
                .and_then(|slot| *slot)
                .ok_or_else(|| ClientError::Config("no certificate was presented".into()))?;
            Ok((
                Dialed {
                    endpoint,
                    connection,
                },
                fingerprint,
            ))
        }
        Err(e) => {
            let refused = refused.lock().ok().and_then(|slot| *slot);
            Err(match (refused, pin) {
                (Some(presented), Some(expected)) => ClientError::FingerprintMismatch {
                    expected,
                    presented,
                },
                _ => ClientError::from_connection_error(e),
            })
        }
    }
}

/// A client endpoint bound to `local` whose connections trust only `pin`
/// (any certificate when `None`): for connecting many times from one
/// socket (the admission tests' attackers); players use [`dial`].
pub fn endpoint(
    local: SocketAddr,
    pin: Option<Fingerprint>,
) -> Result<quinn::Endpoint, ClientError> {
    bind(local, client_config(pin)?.0)
}

fn bind(local: SocketAddr, config: quinn::ClientConfig) -> Result<quinn::Endpoint, ClientError> {
    let mut endpoint = quinn::Endpoint::client(local).map_err(ClientError::Socket)?;
    endpoint.set_default_client_config(config);
    Ok(endpoint)
}

/// Resolves `HOST:PORT` (also `[v6]:PORT`) to an address and the host part
/// to use as the server name.
pub async fn resolve(host_port: &str) -> Result<(SocketAddr, String), ClientError> {
    let bad = || ClientError::Address(host_port.to_owned());
    let (host, _port) = host_port.rsplit_once(':').ok_or_else(bad)?;
    let host = host.trim_start_matches('[').trim_end_matches(']');
    if host.is_empty() {
        return Err(bad());
    }
    let addr = tokio::net::lookup_host(host_port)
        .await
        .map_err(|_| bad())?
        .next()
        .ok_or_else(bad)?;
    Ok((addr, host.to_owned()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn resolves_ip_literals_and_keeps_the_host_as_server_name() {
        let (addr, name) = resolve("127.0.0.1:4433").await.unwrap();
        assert_eq!(addr, "127.0.0.1:4433".parse().unwrap());
        assert_eq!(name, "127.0.0.1");
        let (addr, name) = resolve("[::1]:5").await.unwrap();
        assert_eq!(addr, "[::1]:5".parse().unwrap());
        assert_eq!(name, "::1");
    }

    #[tokio::test]
    async fn refuses_addresses_without_a_port() {
        assert!(matches!(
            resolve("localhost").await,
            Err(ClientError::Address(_))
        ));
        assert!(matches!(resolve(":80").await, Err(ClientError::Address(_))));
    }
}
