//! SHA-256 fingerprints of certificates, the identity clients pin.
//!
//! The value type is [`ledge_shared::protocol::Fingerprint`] (printing and
//! parsing); this module computes it with ring.

pub use ledge_shared::protocol::{Fingerprint, ParseFingerprintError};

/// The fingerprint of a DER-encoded certificate.
pub fn of_der(der: &[u8]) -> Fingerprint {
    let digest = ring::digest::digest(&ring::digest::SHA256, der);
    let mut bytes = [0u8; 32];
    bytes.copy_from_slice(digest.as_ref());
    Fingerprint(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_digest() {
        // SHA-256("abc"), FIPS 180-2 test vector.
        assert_eq!(
            of_der(b"abc").to_string(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
