//! The native QUIC transport (quinn): what [`super`] needs of it.

use ledge_shared::protocol::CloseCode;

use super::outcome::{Gone, Received, READ_CHUNK};

/// Longest close reason sent, bytes: it must fit one packet.
const MAX_CLOSE_REASON: usize = 200;

/// The next chunk of a control stream (cancel-safe, no copy).
pub async fn read(recv: &mut quinn::RecvStream) -> Received {
    match recv.read_chunk(READ_CHUNK, true).await {
        Ok(Some(chunk)) => Received::Stream(chunk.bytes),
        // The client finished its side.
        Ok(None) => Received::StreamEnd,
        Err(quinn::ReadError::ConnectionLost(e)) => Received::Gone(gone(e)),
        Err(e) => Received::Gone(Gone::Lost(e.to_string())),
    }
}

/// The connection ended under the session: the client closing it on
/// purpose (it quit) is a leave; a timeout or reset is a loss.
pub fn gone(e: quinn::ConnectionError) -> Gone {
    match e {
        quinn::ConnectionError::ApplicationClosed(_)
        | quinn::ConnectionError::ConnectionClosed(_) => Gone::Closed(e.to_string()),
        e => Gone::Lost(e.to_string()),
    }
}

/// Closes `connection` with `code` and `reason` (cut to fit one packet).
pub fn close(connection: &quinn::Connection, code: CloseCode, reason: &str) {
    let mut end = reason.len().min(MAX_CLOSE_REASON);
    while !reason.is_char_boundary(end) {
        end -= 1;
    }
    connection.close(code.to_u32().into(), &reason.as_bytes()[..end]);
}
