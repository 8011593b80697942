//! The WebTransport transport (`wtransport`, over HTTP/3 on quinn): a
//! session at [`PATH`] is a ledge connection. The client opens one
//! bidirectional stream, the control stream, carrying exactly what a
//! native client's does; datagrams are the native datagrams; the level
//! bundle goes on a server-opened one-way stream, as natively. The
//! endpoint and its certificates: [`crate::web::webtransport_endpoint`].

use bytes::Bytes;
use ledge_shared::protocol::CloseCode;
use wtransport::endpoint::IncomingSession;
use wtransport::error::{ConnectionError, StreamReadError};
use wtransport::VarInt;

use super::outcome::{Gone, Received, READ_CHUNK};

/// The path of ledge sessions (`https://HOST:PORT/ledge`); others are
/// refused with 404.
pub const PATH: &str = "/ledge";

/// Longest close reason sent, bytes: it must fit one packet.
const MAX_CLOSE_REASON: usize = 200;

/// Finishes the QUIC handshake and accepts the session request if it is
/// for [`PATH`].
pub async fn accept(incoming: IncomingSession) -> Result<wtransport::Connection, String> {
    let request = incoming.await.map_err(|e| e.to_string())?;
    let path = request
        .path()
        .split('?')
        .next()
        .unwrap_or_default()
        .to_owned();
    if path != PATH {
        request.not_found().await;
        return Err(format!("refused a session at {path:?} (only {PATH})"));
    }
    request.accept().await.map_err(|e| e.to_string())
}

/// The next chunk of a control stream (cancel-safe).
pub async fn read(recv: &mut wtransport::RecvStream) -> Received {
    let mut buf = [0u8; READ_CHUNK];
    match recv.read(&mut buf).await {
        Ok(Some(n)) => Received::Stream(Bytes::copy_from_slice(&buf[..n])),
        Ok(None) => Received::StreamEnd,
        Err(StreamReadError::NotConnected) => {
            Received::Gone(Gone::Lost("the session is gone".into()))
        }
        Err(e) => Received::Gone(Gone::Lost(e.to_string())),
    }
}

/// The session ended under it: the client closing it on purpose is a
/// leave; a timeout or reset is a loss.
pub fn gone(e: ConnectionError) -> Gone {
    match e {
        ConnectionError::ApplicationClosed(_) | ConnectionError::ConnectionClosed(_) => {
            Gone::Closed(e.to_string())
        }
        e => Gone::Lost(e.to_string()),
    }
}

/// Closes the session with `code` as the application error code and
/// `reason` (cut to fit one packet).
pub fn close(connection: &wtransport::Connection, code: CloseCode, reason: &str) {
    let mut end = reason.len().min(MAX_CLOSE_REASON);
    while !reason.is_char_boundary(end) {
        end -= 1;
    }
    connection.close(VarInt::from_u32(code.to_u32()), &reason.as_bytes()[..end]);
}
