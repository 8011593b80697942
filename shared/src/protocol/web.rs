//! The WebSocket framing of a session, for browsers (`/ws` on the server's
//! web port): what a native client carries on its QUIC connection, as
//! WebSocket binary messages. Pure (no I/O), used by the server and by
//! clients alike.
//!
//! Every binary message is one tag byte and a payload:
//!
//! | tag | name | payload | direction |
//! |---|---|---|---|
//! | `0x00` | [`Tag::Stream`] | bytes of the control stream (any slice of it: the receiver feeds a [`FrameDecoder`](super::FrameDecoder)) | both |
//! | `0x01` | [`Tag::Datagram`] | one datagram, byte for byte the native QUIC datagram ([`InputPacket`](super::InputPacket) up, a snapshot down) | both |
//! | `0x02` | [`Tag::Level`] | the next chunk of the level bundle stream a native server writes after `ClientControl::GetLevel` | server to client |
//! | `0x03` | [`Tag::LevelEnd`] | none: that stream is finished | server to client |
//!
//! Anything else is malformed: a text message, an empty message, an unknown
//! tag, a level message from a client, a payload after `LevelEnd`, a
//! message from a client over [`MAX_CLIENT_MESSAGE`].
//!
//! The server closes a session with the WebSocket close code
//! `4000 + CloseCode` ([`close_code`], [`from_close_code`]) and the reason
//! text cut to the 123 bytes a close frame holds ([`close_reason`]).

use super::CloseCode;

/// Largest WebSocket message a client may send, tag included: an input
/// datagram is at most 128 bytes and a control frame at most 1 KiB, so a
/// client never needs more. The server sets it in its WebSocket
/// configuration, so its library never buffers a larger message.
pub const MAX_CLIENT_MESSAGE: usize = 4096;

/// WebSocket close codes of a session: `CLOSE_CODE_BASE + CloseCode`
/// (4000-4999 are the application's).
pub const CLOSE_CODE_BASE: u16 = 4000;

/// Longest close reason, in bytes: a close frame's payload is at most 125
/// bytes, two of which are the code.
pub const MAX_CLOSE_REASON: usize = 123;

/// What a message carries (its first byte).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Tag {
    /// Bytes of the control stream.
    Stream = 0x00,
    /// One datagram.
    Datagram = 0x01,
    /// A chunk of the level bundle (server to client).
    Level = 0x02,
    /// The level bundle stream is finished (server to client, no payload).
    LevelEnd = 0x03,
}

impl Tag {
    /// The tag of byte `b`, if known.
    pub fn from_byte(b: u8) -> Option<Tag> {
        Some(match b {
            0x00 => Tag::Stream,
            0x01 => Tag::Datagram,
            0x02 => Tag::Level,
            0x03 => Tag::LevelEnd,
            _ => return None,
        })
    }
}

/// One decoded message, borrowing its payload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WebMessage<'a> {
    /// Bytes of the control stream.
    Stream(&'a [u8]),
    /// One datagram.
    Datagram(&'a [u8]),
    /// A chunk of the level bundle.
    Level(&'a [u8]),
    /// The level bundle stream is finished.
    LevelEnd,
}

/// Why a WebSocket message is malformed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WebError {
    /// A text message: sessions are binary.
    #[error("a text message (sessions use binary messages only)")]
    Text,
    /// A binary message with no tag.
    #[error("an empty message")]
    Empty,
    /// A tag this version does not know.
    #[error("unknown message tag {0:#04x}")]
    UnknownTag(u8),
    /// A tag only the server sends, from a client.
    #[error("a {0:?} message from a client (only the server sends it)")]
    ServerOnly(Tag),
    /// `LevelEnd` with a payload.
    #[error("LevelEnd with {0} bytes of payload (it has none)")]
    LevelEndPayload(usize),
    /// A client message over [`MAX_CLIENT_MESSAGE`].
    #[error("a message of {len} bytes, over the limit of {max}")]
    TooLarge {
        /// Its size, bytes (as far as known).
        len: usize,
        /// The limit.
        max: usize,
    },
}

/// Decodes a binary message from either side.
pub fn decode(message: &[u8]) -> Result<WebMessage<'_>, WebError> {
    let (&tag, payload) = message.split_first().ok_or(WebError::Empty)?;
    Ok(
        match Tag::from_byte(tag).ok_or(WebError::UnknownTag(tag))? {
            Tag::Stream => WebMessage::Stream(payload),
            Tag::Datagram => WebMessage::Datagram(payload),
            Tag::Level => WebMessage::Level(payload),
            Tag::LevelEnd if payload.is_empty() => WebMessage::LevelEnd,
            Tag::LevelEnd => return Err(WebError::LevelEndPayload(payload.len())),
        },
    )
}

/// Decodes a binary message a client sent: only [`WebMessage::Stream`] and
/// [`WebMessage::Datagram`], at most [`MAX_CLIENT_MESSAGE`] bytes.
pub fn decode_from_client(message: &[u8]) -> Result<WebMessage<'_>, WebError> {
    if message.len() > MAX_CLIENT_MESSAGE {
        return Err(WebError::TooLarge {
            len: message.len(),
            max: MAX_CLIENT_MESSAGE,
        });
    }
    match decode(message)? {
        m @ (WebMessage::Stream(_) | WebMessage::Datagram(_)) => Ok(m),
        WebMessage::Level(_) => Err(WebError::ServerOnly(Tag::Level)),
        WebMessage::LevelEnd => Err(WebError::ServerOnly(Tag::LevelEnd)),
    }
}

/// Encodes a message: the tag, then the payload.
pub fn encode(tag: Tag, payload: &[u8]) -> Vec<u8> {
    let mut message = Vec::with_capacity(1 + payload.len());
    message.push(tag as u8);
    message.extend_from_slice(payload);
    message
}

/// The WebSocket close code of a session closed with `code`.
pub fn close_code(code: CloseCode) -> u16 {
    // Codes are 0..=5: the sum never overflows.
    CLOSE_CODE_BASE + code.to_u32() as u16
}

/// The session close code of a WebSocket close code, if it is one.
pub fn from_close_code(code: u16) -> Option<CloseCode> {
    CloseCode::from_u32(u32::from(code.checked_sub(CLOSE_CODE_BASE)?))
}

/// `reason` cut to [`MAX_CLOSE_REASON`] bytes, on a character boundary.
pub fn close_reason(reason: &str) -> &str {
    let mut end = reason.len().min(MAX_CLOSE_REASON);
    while !reason.is_char_boundary(end) {
        end -= 1;
    }
    &reason[..end]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_tag_round_trips() {
        for (tag, payload) in [
            (Tag::Stream, &b"\x00\x03abc"[..]),
            (Tag::Datagram, b"xyz"),
            (Tag::Level, &[7u8; 100]),
            (Tag::Stream, b""),
            (Tag::Datagram, b""),
        ] {
            let m = encode(tag, payload);
            assert_eq!(m[0], tag as u8);
            let back = decode(&m).unwrap();
            let expected = match tag {
                Tag::Stream => WebMessage::Stream(payload),
                Tag::Datagram => WebMessage::Datagram(payload),
                Tag::Level => WebMessage::Level(payload),
                Tag::LevelEnd => unreachable!(),
            };
            assert_eq!(back, expected);
        }
        assert_eq!(
            decode(&encode(Tag::LevelEnd, b"")),
            Ok(WebMessage::LevelEnd)
        );
    }

    #[test]
    fn malformed_messages_are_errors() {
        assert_eq!(decode(b""), Err(WebError::Empty));
        assert_eq!(decode(b"\x04"), Err(WebError::UnknownTag(4)));
        assert_eq!(decode(b"\xffabc"), Err(WebError::UnknownTag(0xff)));
        assert_eq!(decode(b"\x03x"), Err(WebError::LevelEndPayload(1)));
        assert_eq!(decode_from_client(b""), Err(WebError::Empty));
        assert_eq!(decode_from_client(b"\x09"), Err(WebError::UnknownTag(9)));
        assert_eq!(
            decode_from_client(b"\x02abc"),
            Err(WebError::ServerOnly(Tag::Level))
        );
        assert_eq!(
            decode_from_client(b"\x03"),
            Err(WebError::ServerOnly(Tag::LevelEnd))
        );
        assert_eq!(
            decode_from_client(b"\x03zz"),
            Err(WebError::LevelEndPayload(2))
        );
        let big = encode(Tag::Stream, &[0; MAX_CLIENT_MESSAGE]);
        assert_eq!(
            decode_from_client(&big),
            Err(WebError::TooLarge {
                len: MAX_CLIENT_MESSAGE + 1,
                max: MAX_CLIENT_MESSAGE
            })
        );
        let fits = encode(Tag::Datagram, &[0; MAX_CLIENT_MESSAGE - 1]);
        assert!(matches!(
            decode_from_client(&fits),
            Ok(WebMessage::Datagram(p)) if p.len() == MAX_CLIENT_MESSAGE - 1
        ));
        // Every error says what it is.
        assert!(WebError::Text.to_string().contains("text"));
    }

    #[test]
    fn any_bytes_decode_or_fail_without_panicking() {
        for len in 0..4 {
            for seed in 0..=255u8 {
                let m: Vec<u8> = (0..len).map(|i| seed.wrapping_mul(31) ^ i).collect();
                let _ = decode(&m);
                let _ = decode_from_client(&m);
            }
        }
    }

    #[test]
    fn close_codes_map_both_ways() {
        for code in [
            CloseCode::Normal,
            CloseCode::ProtocolViolation,
            CloseCode::Rejected,
            CloseCode::Timeout,
            CloseCode::ServerShutdown,
            CloseCode::Kicked,
        ] {
            let ws = close_code(code);
            assert_eq!(ws, 4000 + code.to_u32() as u16);
            assert_eq!(from_close_code(ws), Some(code));
        }
        assert_eq!(close_code(CloseCode::Kicked), 4005);
        assert_eq!(from_close_code(1000), None);
        assert_eq!(from_close_code(3999), None);
        assert_eq!(from_close_code(4006), None);
        assert_eq!(from_close_code(0), None);
    }

    #[test]
    fn close_reasons_are_cut_on_a_char_boundary() {
        assert_eq!(close_reason("bye"), "bye");
        let long = "a".repeat(200);
        assert_eq!(close_reason(&long).len(), MAX_CLOSE_REASON);
        // 'é' is two bytes: 61 of them are 122 bytes, the 62nd would end at 124.
        let accents = "é".repeat(70);
        let cut = close_reason(&accents);
        assert_eq!(cut.len(), 122);
        assert!(cut.chars().all(|c| c == 'é'));
        let exact = "b".repeat(MAX_CLOSE_REASON);
        assert_eq!(close_reason(&exact), exact);
    }
}
