//! Length-prefixed frames on a byte stream, and messages inside them.
//!
//! A frame is a big-endian `u32` payload length followed by the payload,
//! at most [`MAX_FRAME_LEN`] bytes. The length is checked before anything is
//! allocated, so a peer cannot make us buffer more than one maximal frame.
//! Generic over tokio's `AsyncRead`/`AsyncWrite`, so the same code runs on
//! quinn streams and, in tests, on in-memory pipes.

use serde::de::DeserializeOwned;
use serde::Serialize;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};

use crate::protocol::{self, CodecError, MAX_FRAME_LEN};

/// Size of the length prefix in bytes.
const HEADER_LEN: usize = 4;

/// Why a frame could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum FrameError {
    /// The announced payload is larger than [`MAX_FRAME_LEN`].
    #[error("frame of {0} bytes exceeds the {MAX_FRAME_LEN}-byte limit")]
    TooLarge(usize),
    /// The stream ended in the middle of a frame.
    #[error("stream ended inside a frame")]
    Truncated,
    /// The payload is not a valid message.
    #[error(transparent)]
    Codec(#[from] CodecError),
    /// The underlying stream failed (connection lost, reset, ...).
    #[error("stream error: {0}")]
    Io(#[from] std::io::Error),
}

impl FrameError {
    /// Whether the peer broke the protocol (as opposed to the transport
    /// failing): such peers are disconnected with a protocol-violation code.
    pub fn is_protocol_violation(&self) -> bool {
        !matches!(self, FrameError::Io(_))
    }
}

/// Reads one frame's payload. `Ok(None)` means the stream ended cleanly
/// between frames.
pub async fn read_frame<R: AsyncRead + Unpin>(
    reader: &mut R,
) -> Result<Option<Vec<u8>>, FrameError> {
    let mut header = [0u8; HEADER_LEN];
    let mut filled = 0;
    while filled < HEADER_LEN {
        let n = reader.read(&mut header[filled..]).await?;
        if n == 0 {
            return if filled == 0 {
                Ok(None)
            } else {
                Err(FrameError::Truncated)
            };
        }
        filled += n;
    }
    let len = u32::from_be_bytes(header) as usize;
    if len > MAX_FRAME_LEN {
        return Err(FrameError::TooLarge(len));
    }
    let mut payload = vec![0u8; len];
    match reader.read_exact(&mut payload).await {
        Ok(_) => Ok(Some(payload)),
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => Err(FrameError::Truncated),
        Err(e) => Err(FrameError::Io(e)),
    }
}

/// Writes one frame with the given payload.
pub async fn write_frame<W: AsyncWrite + Unpin>(
    writer: &mut W,
    payload: &[u8],
) -> Result<(), FrameError> {
    if payload.len() > MAX_FRAME_LEN {
        return Err(FrameError::TooLarge(payload.len()));
    }
    // Header and payload in one buffer: one write, one QUIC STREAM frame.
    let mut frame = Vec::with_capacity(HEADER_LEN + payload.len());
    frame.extend_from_slice(&(payload.len() as u32).to_be_bytes());
    frame.extend_from_slice(payload);
    writer.write_all(&frame).await?;
    Ok(())
}

/// Reads and decodes one message. `Ok(None)` means the stream ended cleanly.
pub async fn read_message<M: DeserializeOwned, R: AsyncRead + Unpin>(
    reader: &mut R,
) -> Result<Option<M>, FrameError> {
    match read_frame(reader).await? {
        Some(payload) => Ok(Some(protocol::decode(&payload)?)),
        None => Ok(None),
    }
}

/// Encodes and writes one message.
pub async fn write_message<M: Serialize, W: AsyncWrite + Unpin>(
    writer: &mut W,
    message: &M,
) -> Result<(), FrameError> {
    let payload = protocol::encode(message)?;
    write_frame(writer, &payload).await
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::ClientMessage;

    #[tokio::test]
    async fn messages_cross_a_pipe() {
        let (mut a, mut b) = tokio::io::duplex(1024);
        write_message(&mut a, &ClientMessage::Ping(42))
            .await
            .unwrap();
        write_message(&mut a, &ClientMessage::Ping(43))
            .await
            .unwrap();
        drop(a);
        let first: Option<ClientMessage> = read_message(&mut b).await.unwrap();
        let second: Option<ClientMessage> = read_message(&mut b).await.unwrap();
        let end: Option<ClientMessage> = read_message(&mut b).await.unwrap();
        assert_eq!(first, Some(ClientMessage::Ping(42)));
        assert_eq!(second, Some(ClientMessage::Ping(43)));
        assert_eq!(end, None);
    }

    #[tokio::test]
    async fn oversized_length_is_refused_before_reading_the_payload() {
        let (mut a, mut b) = tokio::io::duplex(64);
        a.write_all(&u32::MAX.to_be_bytes()).await.unwrap();
        let err = read_frame(&mut b).await.unwrap_err();
        assert!(matches!(err, FrameError::TooLarge(n) if n == u32::MAX as usize));
        assert!(err.is_protocol_violation());
    }

    #[tokio::test]
    async fn truncated_frames_are_errors() {
        let (mut a, mut b) = tokio::io::duplex(64);
        a.write_all(&[0, 0]).await.unwrap();
        drop(a);
        assert!(matches!(
            read_frame(&mut b).await,
            Err(FrameError::Truncated)
        ));

        let (mut a, mut b) = tokio::io::duplex(64);
        a.write_all(&[0, 0, 0, 10, 1, 2]).await.unwrap();
        drop(a);
        assert!(matches!(
            read_frame(&mut b).await,
            Err(FrameError::Truncated)
        ));
    }

    #[tokio::test]
    async fn garbage_payload_is_a_codec_error() {
        let (mut a, mut b) = tokio::io::duplex(64);
        write_frame(&mut a, &[0xee; 8]).await.unwrap();
        let err = read_message::<ClientMessage, _>(&mut b).await.unwrap_err();
        assert!(matches!(err, FrameError::Codec(_)));
        assert!(err.is_protocol_violation());
    }
}
