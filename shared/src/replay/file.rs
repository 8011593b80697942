//! The replay file: `LEDGEREP`, the format version (u16), the body's
//! length (u32) and its CRC-32 (all little endian), then the body: the
//! [`Replay`] in bincode 2 (variable-length integers).
//!
//! Reading checks, in order, before allocating anything the file claims:
//! the magic, the version, the length against [`MAX_REPLAY_BYTES`] and the
//! bytes present, the checksum, then the body's own rules
//! ([`Replay::validate`]). Each failure is its own [`ReplayError`].

use super::{Replay, ReplayError};

/// The first 8 bytes of every replay file.
pub const MAGIC: [u8; 8] = *b"LEDGEREP";

/// The format this build writes and the newest it reads.
pub const FORMAT_VERSION: u16 = 1;

/// Largest body accepted (and written), bytes. A room's recorder starts a
/// new match replay before its events get near it.
pub const MAX_REPLAY_BYTES: usize = 32 << 20;

/// Bytes before the body: magic, version, length, checksum.
pub const HEADER_LEN: usize = 8 + 2 + 4 + 4;

fn config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<MAX_REPLAY_BYTES>()
}

/// The file's bytes for `replay` (validated first).
pub fn encode(replay: &Replay) -> Result<Vec<u8>, ReplayError> {
    replay.validate()?;
    let body = bincode::serde::encode_to_vec(replay, config())
        .map_err(|e| ReplayError::Invalid(format!("cannot encode: {e}")))?;
    if body.len() > MAX_REPLAY_BYTES {
        return Err(ReplayError::TooLarge {
            what: "size",
            len: body.len() as u64,
            max: MAX_REPLAY_BYTES as u64,
        });
    }
    let mut out = Vec::with_capacity(HEADER_LEN + body.len());
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(body.len() as u32).to_le_bytes());
    out.extend_from_slice(&crc32fast::hash(&body).to_le_bytes());
    out.extend_from_slice(&body);
    Ok(out)
}

/// Reads a replay file's bytes (see the module documentation). Never
/// panics; allocates at most about [`MAX_REPLAY_BYTES`].
pub fn decode(bytes: &[u8]) -> Result<Replay, ReplayError> {
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err(ReplayError::NotAReplay);
    }
    if bytes.len() < HEADER_LEN {
        return Err(ReplayError::Truncated {
            have: bytes.len() as u64,
            need: HEADER_LEN as u64,
        });
    }
    let version = u16::from_le_bytes([bytes[8], bytes[9]]);
    if version > FORMAT_VERSION {
        return Err(ReplayError::NewerFormat {
            found: version,
            known: FORMAT_VERSION,
        });
    }
    if version == 0 {
        return Err(ReplayError::Invalid("format version 0".into()));
    }
    let len = u32::from_le_bytes([bytes[10], bytes[11], bytes[12], bytes[13]]) as usize;
    if len > MAX_REPLAY_BYTES {
        return Err(ReplayError::TooLarge {
            what: "size",
            len: len as u64,
            max: MAX_REPLAY_BYTES as u64,
        });
    }
    let body = &bytes[HEADER_LEN..];
    if body.len() < len {
        return Err(ReplayError::Truncated {
            have: bytes.len() as u64,
            need: (HEADER_LEN + len) as u64,
        });
    }
    if body.len() > len {
        return Err(ReplayError::TrailingBytes {
            extra: (body.len() - len) as u64,
        });
    }
    let found = u32::from_le_bytes([bytes[14], bytes[15], bytes[16], bytes[17]]);
    let computed = crc32fast::hash(body);
    if found != computed {
        return Err(ReplayError::Checksum { found, computed });
    }
    let (replay, used): (Replay, usize) = bincode::serde::decode_from_slice(body, config())
        .map_err(|e| ReplayError::Invalid(e.to_string()))?;
    if used != body.len() {
        return Err(ReplayError::Invalid(format!(
            "{} bytes left after the replay's content",
            body.len() - used
        )));
    }
    replay.validate()?;
    Ok(replay)
}
