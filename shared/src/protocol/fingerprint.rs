//! SHA-256 certificate fingerprints: the server identity clients pin.
//!
//! The server's certificate is self-signed, so no CA vouches for it; the
//! server prints the SHA-256 digest of its DER certificate and clients trust
//! exactly that certificate. This module is the value only (printing and
//! parsing, as 64 hex digits, colons allowed when parsing, as many tools
//! print them); the server and the client compute the digest with their TLS
//! library's SHA-256.

use std::fmt;
use std::str::FromStr;

/// The SHA-256 digest of a DER-encoded certificate.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Fingerprint(pub [u8; 32]);

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
        let mut bytes = [0u8; 32];
        let mut count = 0usize;
        for c in s.trim().chars().filter(|&c| c != ':') {
            let d = c.to_digit(16).ok_or(ParseFingerprintError::Char(c))? as u8;
            if let Some(byte) = bytes.get_mut(count / 2) {
                *byte = *byte << 4 | d;
            }
            count += 1;
        }
        if count != 64 {
            return Err(ParseFingerprintError::Length(count));
        }
        Ok(Fingerprint(bytes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_round_trips_and_accepts_colons_and_upper_case() {
        let fp = Fingerprint(core::array::from_fn(|i| (i * 37 + 5) as u8));
        assert_eq!(fp.to_string().len(), 64);
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
            "0".repeat(65).parse::<Fingerprint>(),
            Err(ParseFingerprintError::Length(65))
        );
        assert_eq!(
            "g".repeat(64).parse::<Fingerprint>(),
            Err(ParseFingerprintError::Char('g'))
        );
    }
}
