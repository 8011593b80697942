//! Trust the server certificate by its pinned SHA-256 fingerprint only (or,
//! for trust on first use, any certificate once, recording which).
//!
//! ledge servers use self-signed certificates, so there is no CA chain to
//! check: the certificate is trusted if and only if its fingerprint equals
//! the one the player pinned. The server name is deliberately not checked
//! (the pin already names exactly one certificate, and players connect by
//! LAN addresses that are not in its SANs). The handshake signatures are
//! still verified with the ring provider, which proves the server holds the
//! certificate's private key.

use std::sync::{Arc, Mutex};

use ledge_shared::protocol::Fingerprint;
use rustls::client::danger::{HandshakeSignatureValid, ServerCertVerified, ServerCertVerifier};
use rustls::crypto::{
    verify_tls12_signature, verify_tls13_signature, CryptoProvider, WebPkiSupportedAlgorithms,
};
use rustls::pki_types::{CertificateDer, ServerName, UnixTime};
use rustls::{CertificateError, DigitallySignedStruct, SignatureScheme};

/// The SHA-256 fingerprint of a DER-encoded certificate (what the server
/// prints and players pin).
pub fn fingerprint_of(der: &[u8]) -> Fingerprint {
    let digest = ring::digest::digest(&ring::digest::SHA256, der);
    let mut bytes = [0u8; 32];
    bytes.copy_from_slice(digest.as_ref());
    Fingerprint(bytes)
}

/// A rustls verifier accepting exactly one certificate, by fingerprint.
#[derive(Debug)]
pub struct PinnedCertVerifier {
    /// `None`: accept any certificate (first use), recording it.
    pin: Option<Fingerprint>,
    algorithms: WebPkiSupportedAlgorithms,
    /// The fingerprint of the last refused certificate, so the caller can
    /// report what the server actually presented.
    refused: Arc<Mutex<Option<Fingerprint>>>,
    /// The fingerprint of the last certificate presented.
    presented: Arc<Mutex<Option<Fingerprint>>>,
}

impl PinnedCertVerifier {
    /// Trusts only the certificate with fingerprint `pin`; signatures are
    /// checked with `provider`'s algorithms.
    pub fn new(pin: Fingerprint, provider: &CryptoProvider) -> PinnedCertVerifier {
        PinnedCertVerifier {
            pin: Some(pin),
            algorithms: provider.signature_verification_algorithms,
            refused: Arc::default(),
            presented: Arc::default(),
        }
    }

    /// Trusts any certificate (trust on first use: the caller stores what
    /// [`PinnedCertVerifier::presented`] recorded). Signatures are still
    /// checked, so the server holds the key of the certificate recorded.
    pub fn any(provider: &CryptoProvider) -> PinnedCertVerifier {
        PinnedCertVerifier {
            pin: None,
            algorithms: provider.signature_verification_algorithms,
            refused: Arc::default(),
            presented: Arc::default(),
        }
    }

    /// Where the fingerprint of the presented certificate is recorded.
    pub fn presented(&self) -> Arc<Mutex<Option<Fingerprint>>> {
        self.presented.clone()
    }

    /// Where the fingerprint of a refused certificate is recorded.
    pub fn refused(&self) -> Arc<Mutex<Option<Fingerprint>>> {
        self.refused.clone()
    }
}

impl ServerCertVerifier for PinnedCertVerifier {
    fn verify_server_cert(
        &self,
        end_entity: &CertificateDer<'_>,
        _intermediates: &[CertificateDer<'_>],
        _server_name: &ServerName<'_>,
        _ocsp_response: &[u8],
        _now: UnixTime,
    ) -> Result<ServerCertVerified, rustls::Error> {
        let presented = fingerprint_of(end_entity);
        if let Ok(mut slot) = self.presented.lock() {
            *slot = Some(presented);
        }
        if self.pin.is_none_or(|pin| pin == presented) {
            return Ok(ServerCertVerified::assertion());
        }
        if let Ok(mut refused) = self.refused.lock() {
            *refused = Some(presented);
        }
        Err(rustls::Error::InvalidCertificate(
            CertificateError::ApplicationVerificationFailure,
        ))
    }

    fn verify_tls12_signature(
        &self,
        message: &[u8],
        cert: &CertificateDer<'_>,
        dss: &DigitallySignedStruct,
    ) -> Result<HandshakeSignatureValid, rustls::Error> {
        verify_tls12_signature(message, cert, dss, &self.algorithms)
    }

    fn verify_tls13_signature(
        &self,
        message: &[u8],
        cert: &CertificateDer<'_>,
        dss: &DigitallySignedStruct,
    ) -> Result<HandshakeSignatureValid, rustls::Error> {
        verify_tls13_signature(message, cert, dss, &self.algorithms)
    }

    fn supported_verify_schemes(&self) -> Vec<SignatureScheme> {
        self.algorithms.supported_schemes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn verifier(pin: Fingerprint) -> PinnedCertVerifier {
        PinnedCertVerifier::new(pin, &rustls::crypto::ring::default_provider())
    }

    #[test]
    fn accepts_only_the_pinned_certificate() {
        let cert = CertificateDer::from(b"pretend DER".to_vec());
        let other = CertificateDer::from(b"another DER".to_vec());
        let name = ServerName::try_from("localhost").unwrap();
        let v = verifier(fingerprint_of(&cert));
        assert!(v
            .verify_server_cert(&cert, &[], &name, &[], UnixTime::now())
            .is_ok());
        assert!(v.refused().lock().unwrap().is_none());
        assert!(v
            .verify_server_cert(&other, &[], &name, &[], UnixTime::now())
            .is_err());
        assert_eq!(*v.refused().lock().unwrap(), Some(fingerprint_of(&other)));
    }

    #[test]
    fn trust_on_first_use_accepts_any_and_records_it() {
        let cert = CertificateDer::from(b"pretend DER".to_vec());
        let name = ServerName::try_from("localhost").unwrap();
        let v = PinnedCertVerifier::any(&rustls::crypto::ring::default_provider());
        assert!(v
            .verify_server_cert(&cert, &[], &name, &[], UnixTime::now())
            .is_ok());
        assert_eq!(*v.presented().lock().unwrap(), Some(fingerprint_of(&cert)));
    }

    #[test]
    fn fingerprints_are_sha256() {
        // SHA-256("abc"), FIPS 180-2 test vector.
        assert_eq!(
            fingerprint_of(b"abc").to_string(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn offers_the_providers_signature_schemes() {
        let v = verifier(Fingerprint([0; 32]));
        assert!(v
            .supported_verify_schemes()
            .contains(&SignatureScheme::ECDSA_NISTP256_SHA256));
    }
}
