//! The control-stream wire protocol: message types and their encoding.
//!
//! Each message travels as one frame on the connection's reliable
//! bidirectional stream (see [`crate::framing`]) and is encoded with
//! bincode 2 through serde, decoded with a size limit and rejected when it
//! has trailing bytes. This module is pure (no I/O) so that a later step can
//! move it into `ledge-shared` unchanged.

use std::fmt;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Protocol version carried in [`Hello`]; the server rejects any other.
pub const PROTOCOL_VERSION: u32 = 1;

/// ALPN identifier negotiated in the TLS handshake, so a ledge server never
/// talks to an unrelated QUIC client (and vice versa).
pub const ALPN: &[u8] = b"ledge/1";

/// Largest frame payload either side accepts or sends, in bytes.
pub const MAX_FRAME_LEN: usize = 64 * 1024;

/// Longest accepted player name, in bytes of UTF-8.
pub const MAX_NAME_LEN: usize = 32;

/// The bincode configuration of every message: the limit caps what a
/// decoder may allocate, so a hostile length field cannot exhaust memory.
fn config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<MAX_FRAME_LEN>()
}

/// A player's id, unique within one server run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct PlayerId(pub u32);

impl fmt::Display for PlayerId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{}", self.0)
    }
}

/// The first message a client sends: who it is and which protocol it speaks.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Hello {
    /// Must equal [`PROTOCOL_VERSION`].
    pub protocol_version: u32,
    /// Display name, 1..=[`MAX_NAME_LEN`] bytes, no control characters.
    pub name: String,
}

/// Messages a client sends on the control stream.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum ClientMessage {
    /// Opens the session; must be the first and only `Hello`.
    Hello(Hello),
    /// Asks for a [`ServerMessage::Pong`] echoing the nonce (liveness and
    /// round-trip time; later the basis of clock sync).
    Ping(u64),
}

/// The server's answer to an accepted [`Hello`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Welcome {
    /// The id the server gave this player.
    pub player_id: PlayerId,
    /// The room's simulation tick when the player joined.
    pub tick: u64,
    /// The room's state hash at that tick.
    pub state_hash: u64,
    /// The room's fixed tick rate in Hz.
    pub tick_rate: u32,
}

/// Why the server refused a [`Hello`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum RejectReason {
    /// The client speaks another protocol version.
    ProtocolVersion {
        /// The version the server speaks.
        server: u32,
        /// The version the client announced.
        client: u32,
    },
    /// The name is empty, too long or contains control characters.
    InvalidName,
}

impl fmt::Display for RejectReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RejectReason::ProtocolVersion { server, client } => write!(
                f,
                "protocol version mismatch: server speaks {server}, client {client}"
            ),
            RejectReason::InvalidName => write!(
                f,
                "invalid player name (1..={MAX_NAME_LEN} bytes, no control characters)"
            ),
        }
    }
}

/// Messages the server sends on the control stream.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum ServerMessage {
    /// The [`Hello`] was accepted.
    Welcome(Welcome),
    /// The [`Hello`] was refused; the server closes the connection next.
    Reject(RejectReason),
    /// Answer to [`ClientMessage::Ping`] with the same nonce.
    Pong(u64),
}

/// Application close codes of a QUIC connection (`Connection::close`), so
/// either side can tell why the other hung up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum CloseCode {
    /// Normal end of a session (the client left).
    Normal = 0,
    /// The peer sent a malformed or unexpected frame or message.
    ProtocolViolation = 1,
    /// The server refused the [`Hello`] (a [`ServerMessage::Reject`] precedes it).
    Rejected = 2,
    /// The peer did not send what was due in time.
    Timeout = 3,
    /// The server is shutting down.
    ServerShutdown = 4,
}

impl CloseCode {
    /// The code as sent on the wire.
    pub fn to_u32(self) -> u32 {
        self as u32
    }

    /// Decodes a wire code; `None` for codes this version does not know.
    pub fn from_u32(code: u32) -> Option<CloseCode> {
        Some(match code {
            0 => CloseCode::Normal,
            1 => CloseCode::ProtocolViolation,
            2 => CloseCode::Rejected,
            3 => CloseCode::Timeout,
            4 => CloseCode::ServerShutdown,
            _ => return None,
        })
    }
}

impl From<CloseCode> for quinn::VarInt {
    fn from(code: CloseCode) -> quinn::VarInt {
        quinn::VarInt::from_u32(code.to_u32())
    }
}

/// Why a message could not be encoded or decoded.
#[derive(Debug, thiserror::Error)]
pub enum CodecError {
    /// bincode could not decode the bytes (wrong layout, bad tag, over limit).
    #[error("malformed message: {0}")]
    Decode(#[from] bincode::error::DecodeError),
    /// The message decoded but bytes were left over.
    #[error("malformed message: {0} trailing bytes")]
    TrailingBytes(usize),
    /// bincode could not encode the value.
    #[error("cannot encode message: {0}")]
    Encode(#[from] bincode::error::EncodeError),
    /// The encoded message would exceed [`MAX_FRAME_LEN`].
    #[error("encoded message is {0} bytes, over the {MAX_FRAME_LEN}-byte frame limit")]
    TooLarge(usize),
}

/// Encodes a message into one frame payload (at most [`MAX_FRAME_LEN`] bytes).
pub fn encode<M: Serialize>(message: &M) -> Result<Vec<u8>, CodecError> {
    let bytes = bincode::serde::encode_to_vec(message, config())?;
    if bytes.len() > MAX_FRAME_LEN {
        return Err(CodecError::TooLarge(bytes.len()));
    }
    Ok(bytes)
}

/// Decodes one frame payload into a message; the whole payload must be used.
pub fn decode<M: DeserializeOwned>(payload: &[u8]) -> Result<M, CodecError> {
    let (message, used) = bincode::serde::decode_from_slice(payload, config())?;
    if used != payload.len() {
        return Err(CodecError::TrailingBytes(payload.len() - used));
    }
    Ok(message)
}

/// Whether `name` is acceptable as a player name (see [`Hello::name`]).
pub fn is_valid_name(name: &str) -> bool {
    !name.is_empty() && name.len() <= MAX_NAME_LEN && !name.chars().any(char::is_control)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_round_trip() {
        let hello = ClientMessage::Hello(Hello {
            protocol_version: PROTOCOL_VERSION,
            name: "ada".into(),
        });
        assert_eq!(
            decode::<ClientMessage>(&encode(&hello).unwrap()).unwrap(),
            hello
        );
        let welcome = ServerMessage::Welcome(Welcome {
            player_id: PlayerId(7),
            tick: 123_456,
            state_hash: u64::MAX,
            tick_rate: 60,
        });
        assert_eq!(
            decode::<ServerMessage>(&encode(&welcome).unwrap()).unwrap(),
            welcome
        );
    }

    #[test]
    fn garbage_and_trailing_bytes_are_errors_not_panics() {
        assert!(decode::<ClientMessage>(&[]).is_err());
        assert!(decode::<ClientMessage>(&[0xff; 16]).is_err());
        let mut bytes = encode(&ClientMessage::Ping(1)).unwrap();
        bytes.push(0);
        assert!(matches!(
            decode::<ClientMessage>(&bytes),
            Err(CodecError::TrailingBytes(1))
        ));
    }

    #[test]
    fn huge_length_prefix_inside_a_message_is_refused() {
        // Variant 0 (Hello), version 1, then a string length of u64::MAX:
        // the decode limit must refuse it instead of allocating.
        let mut bytes = vec![0u8, 1, 0xff];
        bytes.extend_from_slice(&u64::MAX.to_le_bytes());
        assert!(decode::<ClientMessage>(&bytes).is_err());
    }

    #[test]
    fn oversized_messages_are_not_encoded() {
        let hello = ClientMessage::Hello(Hello {
            protocol_version: PROTOCOL_VERSION,
            name: "x".repeat(MAX_FRAME_LEN),
        });
        assert!(matches!(encode(&hello), Err(CodecError::TooLarge(_))));
    }

    #[test]
    fn close_codes_round_trip() {
        for code in [
            CloseCode::Normal,
            CloseCode::ProtocolViolation,
            CloseCode::Rejected,
            CloseCode::Timeout,
            CloseCode::ServerShutdown,
        ] {
            assert_eq!(CloseCode::from_u32(code.to_u32()), Some(code));
        }
        assert_eq!(CloseCode::from_u32(99), None);
    }

    #[test]
    fn names_are_validated() {
        assert!(is_valid_name("ada"));
        assert!(!is_valid_name(""));
        assert!(!is_valid_name(&"x".repeat(MAX_NAME_LEN + 1)));
        assert!(!is_valid_name("a\nb"));
    }
}
