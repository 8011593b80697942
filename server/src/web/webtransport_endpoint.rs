//! The WebTransport endpoint (HTTP/3 over UDP, `wtransport`) and the
//! rotation of its certificate ([`super::webtransport_cert`]), driven by
//! tokio timers. Sessions themselves are served like any connection
//! ([`crate::link::webtransport`], [`crate::connection`]).

use std::net::SocketAddr;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, SystemTime};

use tokio::sync::watch;
use tracing::{info, warn};
use wtransport::endpoint::endpoint_side;
use wtransport::tls::{Certificate, CertificateChain, PrivateKey};

use super::webtransport_cert::{self, CertInfo, Rotation, Step, WebCert};
use crate::tls::{DATAGRAM_RECEIVE_BUFFER, DATAGRAM_SEND_BUFFER, STREAM_RECEIVE_WINDOW};

/// The server side of a wtransport endpoint.
pub type Endpoint = wtransport::Endpoint<endpoint_side::Server>;

/// How long to wait before trying again when making a certificate failed.
const RETRY_AFTER: Duration = Duration::from_secs(60);

/// Why the WebTransport endpoint could not start.
#[derive(Debug, thiserror::Error)]
pub enum WebTransportError {
    /// The certificate could not be made.
    #[error("cannot make the WebTransport certificate: {0}")]
    Certificate(#[from] rcgen::Error),
    /// The made certificate was refused.
    #[error("the WebTransport certificate was refused: {0}")]
    Invalid(String),
    /// The idle timeout does not fit QUIC's encoding.
    #[error("idle timeout {0:?} is out of range")]
    IdleTimeout(Duration),
}

/// The certificates a page may meet, shared with `/web.json`.
#[derive(Debug)]
pub struct WebCerts {
    state: Mutex<State>,
}

#[derive(Debug)]
struct State {
    rotation: Rotation,
    /// The next certificate's key material, until promoted.
    next: Option<WebCert>,
}

impl WebCerts {
    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The hashes a page may meet, current first.
    pub fn hashes(&self) -> Vec<[u8; 32]> {
        self.lock().rotation.hashes()
    }

    /// The current certificate.
    pub fn current(&self) -> CertInfo {
        *self.lock().rotation.current()
    }
}

/// How the endpoint is configured, kept to rebuild it with a new
/// certificate.
#[derive(Debug, Clone)]
pub struct Settings {
    /// UDP address.
    pub bind: SocketAddr,
    /// Idle timeout (keep-alives at a third of it).
    pub idle_timeout: Duration,
    /// How long its certificates live.
    pub cert_life: webtransport_cert::CertLife,
}

/// The names in the certificate (browsers check only its hash).
fn names() -> Vec<String> {
    vec!["localhost".to_owned(), "127.0.0.1".to_owned()]
}

fn server_config(
    settings: &Settings,
    cert: &WebCert,
) -> Result<wtransport::ServerConfig, WebTransportError> {
    let certificate = Certificate::from_der(cert.der.clone())
        .map_err(|e| WebTransportError::Invalid(e.to_string()))?;
    let identity = wtransport::Identity::new(
        CertificateChain::single(certificate),
        PrivateKey::from_der_pkcs8(cert.key.clone()),
    );
    let mut transport = wtransport::quinn::TransportConfig::default();
    let idle = settings.idle_timeout;
    transport
        .max_idle_timeout(Some(
            wtransport::quinn::IdleTimeout::try_from(idle)
                .map_err(|_| WebTransportError::IdleTimeout(idle))?,
        ))
        .keep_alive_interval(Some(idle / 3))
        // HTTP/3's request stream and our control stream; its control and
        // QPACK streams: a few of each, no more.
        .max_concurrent_bidi_streams(4u8.into())
        .max_concurrent_uni_streams(8u8.into())
        .stream_receive_window(STREAM_RECEIVE_WINDOW.into())
        .receive_window((4 * STREAM_RECEIVE_WINDOW).into())
        .datagram_receive_buffer_size(Some(DATAGRAM_RECEIVE_BUFFER))
        .datagram_send_buffer_size(DATAGRAM_SEND_BUFFER);
    Ok(wtransport::ServerConfig::builder()
        .with_bind_address(settings.bind)
        .with_custom_transport(identity, transport)
        .build())
}

/// Makes the first certificate and binds the endpoint.
pub fn bind(settings: &Settings) -> Result<(Arc<Endpoint>, Arc<WebCerts>), BindError> {
    let cert = webtransport_cert::generate(SystemTime::now(), &names(), settings.cert_life)
        .map_err(|e| BindError::Setup(e.into()))?;
    let config = server_config(settings, &cert).map_err(BindError::Setup)?;
    let endpoint = Endpoint::server(config).map_err(BindError::Io)?;
    let certs = WebCerts {
        state: Mutex::new(State {
            rotation: Rotation::new(cert.info),
            next: None,
        }),
    };
    Ok((Arc::new(endpoint), Arc::new(certs)))
}

/// Why [`bind`] failed.
#[derive(Debug)]
pub enum BindError {
    /// The certificate or configuration.
    Setup(WebTransportError),
    /// The socket.
    Io(std::io::Error),
}

/// Rotates the certificate until `stop`: makes the next one and serves it
/// to new sessions when [`Rotation`] says so.
pub async fn rotate(
    endpoint: Arc<Endpoint>,
    certs: Arc<WebCerts>,
    settings: Settings,
    mut stop: watch::Receiver<bool>,
) {
    loop {
        let due = certs.lock().rotation.due_at();
        let wait = due
            .duration_since(SystemTime::now())
            .unwrap_or(Duration::ZERO);
        tokio::select! {
            () = crate::shutdown::stopped(&mut stop) => return,
            () = tokio::time::sleep(wait) => {}
        }
        let now = SystemTime::now();
        let step = certs.lock().rotation.poll(now);
        match step {
            None => {}
            Some(Step::Prepare) => {
                match webtransport_cert::generate(now, &names(), settings.cert_life) {
                    Ok(next) => {
                        info!(
                            sha256 = %crate::Fingerprint(next.info.sha256),
                            "made the next WebTransport certificate (listed in /web.json)"
                        );
                        let mut state = certs.lock();
                        state.rotation.prepared(next.info);
                        state.next = Some(next);
                    }
                    Err(e) => {
                        warn!("cannot make the next WebTransport certificate: {e}; trying again");
                        tokio::time::sleep(RETRY_AFTER).await;
                    }
                }
            }
            Some(Step::Promote) => {
                let next = certs.lock().next.take();
                let Some(next) = next else { continue };
                let reloaded = server_config(&settings, &next)
                    .map_err(|e| e.to_string())
                    .and_then(|c| endpoint.reload_config(c, false).map_err(|e| e.to_string()));
                match reloaded {
                    Ok(()) => {
                        certs.lock().rotation.promote();
                        info!(
                            sha256 = %crate::Fingerprint(next.info.sha256),
                            "new WebTransport sessions get the next certificate"
                        );
                    }
                    Err(e) => {
                        warn!("cannot switch the WebTransport certificate: {e}; trying again");
                        certs.lock().next = Some(next);
                        tokio::time::sleep(RETRY_AFTER).await;
                    }
                }
            }
        }
    }
}
