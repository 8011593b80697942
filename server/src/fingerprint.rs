//! SHA-256 fingerprints of certificates, the identity clients pin.
//!
//! The server's certificate is self-signed, so no CA vouches for it; instead
//! the server prints the fingerprint at start and clients trust exactly that
//! certificate. Printed and parsed as 64 hex digits (colons allowed when
//! parsing, as many tools print them).

use std::fmt;
use std::str::FromStr;

/// The SHA-256 digest of a DER-encoded certificate.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Fingerprint(pub [u8; 32]);

impl Fingerprint {
    /// The fingerprint of a DER-encoded certificate.
    pub fn of_der(der: &[u8]) -> Fingerprint {
        let digest = ring::digest::digest(&ring::digest::SHA256, der);
        let mut bytes = [0u8; 32];
        bytes.copy_from_slice(digest.as_ref());
        Fingerprint(bytes)
    }
}

impl fmt::Display for Fingerprint {
    /// Lower-case hex, no separators.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for byte in self.0 {
            write!(f, "{byte:02x}")?;
        }
        Ok(())
    }
}

impl fmt::Debug for Fingerprint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Fingerprint({self})")
    }
}

/// Why a string is not a fingerprint.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ParseFingerprintError {
    /// Not 64 hex digits after removing colons.
    #[error("expected 64 hex digits (SHA-256), got {0}")]
    Length(usize),
    /// A character other than a hex digit or a colon.
    #[error("invalid character {0:?} in fingerprint")]
    Char(char),
}

impl FromStr for Fingerprint {
    type Err = ParseFingerprintError;

    fn from_str(s: &str) -> Result<Fingerprint, ParseFingerprintError> {
        let mut digits = Vec::with_capacity(64);
        for c in s.trim().chars().filter(|&c| c != ':') {
            let d = c.to_digit(16).ok_or(ParseFingerprintError::Char(c))?;
            digits.push(d as u8);
        }
        if digits.len() != 64 {
            return Err(ParseFingerprintError::Length(digits.len()));
        }
        let mut bytes = [0u8; 32];
        for (byte, pair) in bytes.iter_mut().zip(digits.chunks_exact(2)) {
            *byte = pair[0] << 4 | pair[1];
        }
        Ok(Fingerprint(bytes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_digest() {
        // SHA-256("abc"), FIPS 180-2 test vector.
        assert_eq!(
            Fingerprint::of_der(b"abc").to_string(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn parse_round_trips_and_accepts_colons_and_upper_case() {
        let fp = Fingerprint::of_der(b"cert");
        assert_eq!(fp.to_string().parse::<Fingerprint>(), Ok(fp));
        let colons: Vec<String> = fp.0.iter().map(|b| format!("{b:02X}")).collect();
        assert_eq!(colons.join(":").parse::<Fingerprint>(), Ok(fp));
    }

    #[test]
    fn parse_rejects_bad_input() {
        assert_eq!(
            "abcd".parse::<Fingerprint>(),
            Err(ParseFingerprintError::Length(4))
        );
        assert_eq!(
            "g".repeat(64).parse::<Fingerprint>(),
            Err(ParseFingerprintError::Char('g'))
        );
    }
}
