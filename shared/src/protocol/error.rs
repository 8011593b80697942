//! The one error type of the wire protocol.

use thiserror::Error;

/// Why bytes could not be decoded, or a value could not be encoded.
///
/// Every decoder in [`crate::protocol`] returns this instead of panicking,
/// whatever the input. A peer that sends bytes producing any of these errors
/// is misbehaving (or speaks another version): drop the message and count it;
/// disconnect peers that keep doing it.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ProtocolError {
    /// A length (a frame's length prefix, a datagram, a string, an entity
    /// count) is over its limit. Checked before anything is allocated.
    #[error("{what} is {len} bytes or items, over the limit of {max}")]
    TooLarge {
        /// What was too large (for example "frame length prefix").
        what: &'static str,
        /// The length found.
        len: u64,
        /// The largest accepted length.
        max: u64,
    },
    /// The bytes are not a valid encoding (bad tag, truncated, bad varint,
    /// ids out of order, ...).
    #[error("malformed {what}: {detail}")]
    Malformed {
        /// Which message or structure.
        what: &'static str,
        /// What is wrong with it.
        detail: String,
    },
    /// A message decoded but bytes were left over after it.
    #[error("malformed {what}: {extra} trailing bytes")]
    TrailingBytes {
        /// Which message.
        what: &'static str,
        /// How many bytes were left over.
        extra: usize,
    },
    /// The peer speaks another protocol version.
    #[error("protocol version mismatch: we speak {ours}, the peer {theirs}")]
    BadVersion {
        /// [`crate::protocol::PROTOCOL_VERSION`].
        ours: u32,
        /// The version the peer announced.
        theirs: u32,
    },
    /// A string field is empty when it must not be, too long, or contains
    /// control characters.
    #[error("invalid {field}: {problem}")]
    InvalidString {
        /// Which field (for example "player name").
        field: &'static str,
        /// What is wrong with it.
        problem: &'static str,
    },
    /// A delta names a baseline other than the one given to the decoder
    /// (`None`: no baseline / a full snapshot).
    #[error(
        "snapshot baseline mismatch: the delta needs {}, got {}",
        baseline_text(*needed),
        baseline_text(*given)
    )]
    BaselineMismatch {
        /// The baseline tick the delta was encoded against.
        needed: Option<u64>,
        /// The baseline tick supplied.
        given: Option<u64>,
    },
    /// A value handed to an encoder breaks an invariant (entities not sorted
    /// by id, a baseline newer than the snapshot, ...): a bug in the caller,
    /// reported rather than sent.
    #[error("cannot encode {what}: {detail}")]
    InvalidValue {
        /// Which value.
        what: &'static str,
        /// The broken invariant.
        detail: &'static str,
    },
}

impl ProtocolError {
    /// A [`ProtocolError::Malformed`] with a fixed description.
    pub(crate) fn malformed(what: &'static str, detail: impl Into<String>) -> Self {
        ProtocolError::Malformed {
            what,
            detail: detail.into(),
        }
    }

    /// A [`ProtocolError::TooLarge`].
    pub(crate) fn too_large(
        what: &'static str,
        len: impl TryInto<u64>,
        max: impl TryInto<u64>,
    ) -> Self {
        ProtocolError::TooLarge {
            what,
            len: len.try_into().unwrap_or(u64::MAX),
            max: max.try_into().unwrap_or(u64::MAX),
        }
    }
}

/// A baseline tick in words (no `Some(..)` for a person to read).
fn baseline_text(tick: Option<u64>) -> String {
    match tick {
        Some(t) => format!("the snapshot of tick {t}"),
        None => "no baseline (a full snapshot)".to_owned(),
    }
}
