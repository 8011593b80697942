//! bincode 2 (serde) encoding shared by every message and envelope.

use serde::de::DeserializeOwned;
use serde::Serialize;

use super::{ProtocolError, MAX_FRAME};

/// The bincode configuration of every message: variable-length integers,
/// little endian, and a limit so a hostile length field (a string, a byte
/// blob) cannot make the decoder allocate more than [`MAX_FRAME`] bytes.
pub(crate) fn config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<MAX_FRAME>()
}

/// A message with an encoding: control messages and datagram envelopes.
///
/// [`Message::encode`] and [`Message::decode`] check the length limit and the
/// message's own invariants ([`Message::validate`]) in both directions, so a
/// valid peer never sends what the other side rejects.
pub trait Message: Serialize + DeserializeOwned {
    /// Name used in errors.
    const WHAT: &'static str;
    /// Largest encoded length accepted, in bytes.
    const MAX_LEN: usize;

    /// Checks what the type system does not: string lengths and characters,
    /// counts, tick orders.
    fn validate(&self) -> Result<(), ProtocolError>;

    /// Encodes the message (validated first) into a new buffer.
    fn encode(&self) -> Result<Vec<u8>, ProtocolError> {
        self.validate()?;
        let bytes = bincode::serde::encode_to_vec(self, config())
            .map_err(|e| ProtocolError::malformed(Self::WHAT, format!("cannot encode: {e}")))?;
        if bytes.len() > Self::MAX_LEN {
            return Err(ProtocolError::too_large(
                Self::WHAT,
                bytes.len(),
                Self::MAX_LEN,
            ));
        }
        Ok(bytes)
    }

    /// Decodes exactly one message from `bytes` (no trailing bytes) and
    /// validates it. Never panics; allocates at most about `bytes.len()`.
    fn decode(bytes: &[u8]) -> Result<Self, ProtocolError> {
        if bytes.len() > Self::MAX_LEN {
            return Err(ProtocolError::too_large(
                Self::WHAT,
                bytes.len(),
                Self::MAX_LEN,
            ));
        }
        let (message, used): (Self, usize) = bincode::serde::decode_from_slice(bytes, config())
            .map_err(|e| ProtocolError::malformed(Self::WHAT, e.to_string()))?;
        if used != bytes.len() {
            return Err(ProtocolError::TrailingBytes {
                what: Self::WHAT,
                extra: bytes.len() - used,
            });
        }
        message.validate()?;
        Ok(message)
    }
}

/// Serde helper: a `Vec<u8>` as one length-prefixed byte string (bincode
/// then claims the length against its limit before allocating, which a
/// sequence of `u8` would not do).
pub(crate) mod bytes {
    use serde::de::{Error, SeqAccess, Visitor};
    use serde::{Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &[u8], s: S) -> Result<S::Ok, S::Error> {
        s.serialize_bytes(v)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<u8>, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Vec<u8>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a byte string")
            }
            fn visit_bytes<E: Error>(self, v: &[u8]) -> Result<Vec<u8>, E> {
                Ok(v.to_vec())
            }
            fn visit_byte_buf<E: Error>(self, v: Vec<u8>) -> Result<Vec<u8>, E> {
                Ok(v)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<u8>, A::Error> {
                // Other formats: grow as elements arrive, never by a hint.
                let mut v = Vec::new();
                while let Some(b) = seq.next_element()? {
                    v.push(b);
                }
                Ok(v)
            }
        }
        d.deserialize_byte_buf(V)
    }
}
