//! Length-prefixed frames on the control stream: a `u32` little-endian
//! payload length, then the payload (one bincode-encoded message).

use super::codec::Message;
use super::{ProtocolError, MAX_FRAME};

/// Bytes of the length prefix.
pub const FRAME_HEADER: usize = 4;

/// Appends `message` as one frame (length prefix and payload) to `out`.
pub fn write_frame<M: Message>(message: &M, out: &mut Vec<u8>) -> Result<(), ProtocolError> {
    let payload = message.encode()?;
    if payload.len() > MAX_FRAME {
        return Err(ProtocolError::too_large(
            "frame payload",
            payload.len(),
            MAX_FRAME,
        ));
    }
    out.extend_from_slice(&(payload.len() as u32).to_le_bytes());
    out.extend_from_slice(&payload);
    Ok(())
}

/// Reassembles frames from stream bytes arriving in arbitrary chunks.
///
/// [`FrameDecoder::push`] bytes as they arrive, then [`FrameDecoder::pop`]
/// complete payloads until it returns `None`. Memory is bounded: a length
/// prefix over the frame limit is rejected as soon as its four bytes arrive,
/// before the chunk holding it is stored (nothing is ever reserved from a
/// prefix), and the decoder never holds more than its buffer limit (pop
/// everything between pushes; one full frame plus a chunk always fits with
/// the default limit). After an error the stream is out of sync: `push`
/// keeps returning the error and the connection should be closed.
#[derive(Debug, Clone)]
pub struct FrameDecoder {
    buf: Vec<u8>,
    /// Start of the first frame not popped yet (a frame boundary).
    head: usize,
    /// Offset in `buf` of the first length prefix not checked yet (a frame
    /// boundary at or after `head`; may lie beyond the bytes received).
    scan: usize,
    max_frame: usize,
    max_buffered: usize,
    error: Option<ProtocolError>,
}

impl Default for FrameDecoder {
    fn default() -> Self {
        FrameDecoder::new(MAX_FRAME)
    }
}

impl FrameDecoder {
    /// A decoder accepting payloads of at most `max_frame` bytes and
    /// holding at most two full frames.
    pub fn new(max_frame: usize) -> Self {
        let one = FRAME_HEADER.saturating_add(max_frame);
        FrameDecoder::with_buffer_limit(max_frame, one.saturating_mul(2))
    }

    /// A decoder accepting payloads of at most `max_frame` bytes and holding
    /// at most `max_buffered` bytes (raised to one full frame if lower).
    pub fn with_buffer_limit(max_frame: usize, max_buffered: usize) -> Self {
        FrameDecoder {
            buf: Vec::new(),
            head: 0,
            scan: 0,
            max_frame,
            max_buffered: max_buffered.max(FRAME_HEADER.saturating_add(max_frame)),
            error: None,
        }
    }

    /// Bytes held: partial frames and frames not popped yet.
    pub fn buffered(&self) -> usize {
        self.buf.len() - self.head
    }

    /// The error the decoder failed with, if it did.
    pub fn error(&self) -> Option<&ProtocolError> {
        self.error.as_ref()
    }

    fn fail(&mut self, e: ProtocolError) -> Result<(), ProtocolError> {
        self.error = Some(e.clone());
        Err(e)
    }

    /// Adds stream bytes. Errors, storing nothing and staying failed, on a
    /// length prefix over the frame limit or when the buffer limit would be
    /// exceeded.
    pub fn push(&mut self, bytes: &[u8]) -> Result<(), ProtocolError> {
        if let Some(e) = &self.error {
            return Err(e.clone());
        }
        // Drop popped frames so offsets and the limit see unread bytes only.
        if self.head > 0 {
            self.buf.drain(..self.head);
            self.scan -= self.head;
            self.head = 0;
        }
        // Check every length prefix that completes with the new bytes.
        let held = self.buf.len();
        let total = held + bytes.len();
        let mut scan = self.scan;
        while scan + FRAME_HEADER <= total {
            let mut prefix = [0u8; FRAME_HEADER];
            for (k, b) in prefix.iter_mut().enumerate() {
                let i = scan + k;
                *b = if i < held {
                    self.buf[i]
                } else {
                    bytes[i - held]
                };
            }
            let len = u32::from_le_bytes(prefix) as usize;
            if len > self.max_frame {
                return self.fail(ProtocolError::too_large(
                    "frame length prefix",
                    len,
                    self.max_frame,
                ));
            }
            scan += FRAME_HEADER + len;
        }
        if total > self.max_buffered {
            return self.fail(ProtocolError::too_large(
                "unread control stream bytes",
                total,
                self.max_buffered,
            ));
        }
        self.buf.extend_from_slice(bytes);
        self.scan = scan;
        Ok(())
    }

    /// The next complete frame's payload, if one has arrived.
    pub fn pop(&mut self) -> Option<Vec<u8>> {
        // `scan > head`: the prefix at `head` was checked by `push`.
        if self.scan <= self.head {
            return None;
        }
        let avail = &self.buf[self.head..];
        if avail.len() < FRAME_HEADER {
            return None;
        }
        let len = u32::from_le_bytes([avail[0], avail[1], avail[2], avail[3]]) as usize;
        let end = FRAME_HEADER + len;
        if avail.len() < end {
            return None;
        }
        let payload = avail[FRAME_HEADER..end].to_vec();
        self.head += end;
        Some(payload)
    }

    /// Pops the next complete frame and decodes it as `M`.
    pub fn pop_message<M: Message>(&mut self) -> Option<Result<M, ProtocolError>> {
        self.pop().map(|payload| M::decode(&payload))
    }
}
