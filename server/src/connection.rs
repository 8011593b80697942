//! One client connection: handshake, then the control-stream loop.
//!
//! The client opens one bidirectional stream and sends a
//! [`ClientMessage::Hello`]; the server answers [`ServerMessage::Welcome`]
//! (after joining the room) or [`ServerMessage::Reject`]. Afterwards the
//! stream carries control requests until either side ends it. Anything
//! malformed or out of order closes this connection with
//! [`CloseCode::ProtocolViolation`] and a reason; it never panics and never
//! affects other connections.

use std::time::Duration;

use quinn::{Connection, RecvStream, SendStream};
use tracing::{debug, info, warn, Instrument};

use crate::framing::{read_message, write_message, FrameError};
use crate::protocol::{
    is_valid_name, ClientMessage, CloseCode, Hello, PlayerId, RejectReason, ServerMessage,
    PROTOCOL_VERSION,
};
use crate::room::RoomHandle;

/// How long a client has from connecting to finishing its `Hello`.
pub const HELLO_TIMEOUT: Duration = Duration::from_secs(5);

/// How long a rejected client gets to receive the `Reject` before the close.
const REJECT_LINGER: Duration = Duration::from_secs(1);

/// Serves one incoming connection to its end. Errors are logged, not returned.
pub async fn serve(incoming: quinn::Incoming, room: RoomHandle) {
    let remote = incoming.remote_address();
    let span = tracing::info_span!("conn", %remote);
    async move {
        let connection = match incoming.await {
            Ok(connection) => connection,
            Err(e) => {
                debug!("handshake failed: {e}");
                return;
            }
        };
        debug!("connected");
        let outcome = session(&connection, &room).await;
        match outcome {
            Ok(()) => close(&connection, CloseCode::Normal, "bye"),
            Err(End::Closed(e)) => debug!("connection lost: {e}"),
            Err(End::Close(code, reason)) => {
                if code == CloseCode::ProtocolViolation {
                    warn!("closing: {reason}");
                } else {
                    info!("closing: {reason}");
                }
                close(&connection, code, &reason);
            }
        }
    }
    .instrument(span)
    .await
}

/// How a session ended abnormally.
enum End {
    /// The connection is already gone (peer closed, timed out, endpoint shut).
    Closed(String),
    /// We close the connection with this code and reason.
    Close(CloseCode, String),
}

impl End {
    fn from_frame(error: FrameError, context: &str) -> End {
        if error.is_protocol_violation() {
            End::Close(CloseCode::ProtocolViolation, format!("{context}: {error}"))
        } else {
            End::Closed(error.to_string())
        }
    }
}

/// Removes the player from the room however the session ends.
struct Membership<'a> {
    room: &'a RoomHandle,
    player_id: PlayerId,
}

impl Drop for Membership<'_> {
    fn drop(&mut self) {
        self.room.leave(self.player_id);
    }
}

async fn session(connection: &Connection, room: &RoomHandle) -> Result<(), End> {
    let (mut send, mut recv, hello) = tokio::time::timeout(HELLO_TIMEOUT, handshake(connection))
        .await
        .map_err(|_| End::Close(CloseCode::Timeout, "no hello in time".into()))??;

    let rejection = if hello.protocol_version != PROTOCOL_VERSION {
        Some(RejectReason::ProtocolVersion {
            server: PROTOCOL_VERSION,
            client: hello.protocol_version,
        })
    } else if !is_valid_name(&hello.name) {
        Some(RejectReason::InvalidName)
    } else {
        None
    };
    if let Some(reason) = rejection {
        reject(&mut send, &reason).await;
        return Err(End::Close(CloseCode::Rejected, reason.to_string()));
    }

    let welcome = room
        .join(hello.name)
        .await
        .map_err(|_| End::Close(CloseCode::ServerShutdown, "server shutting down".into()))?;
    let _membership = Membership {
        room,
        player_id: welcome.player_id,
    };
    write_message(&mut send, &ServerMessage::Welcome(welcome))
        .await
        .map_err(|e| End::from_frame(e, "sending welcome"))?;

    loop {
        let message = read_message::<ClientMessage, _>(&mut recv)
            .await
            .map_err(|e| End::from_frame(e, "reading a control message"))?;
        match message {
            None => return Ok(()),
            Some(ClientMessage::Ping(nonce)) => {
                write_message(&mut send, &ServerMessage::Pong(nonce))
                    .await
                    .map_err(|e| End::from_frame(e, "sending pong"))?;
            }
            Some(ClientMessage::Hello(_)) => {
                return Err(End::Close(
                    CloseCode::ProtocolViolation,
                    "second hello".into(),
                ))
            }
        }
    }
}

/// Accepts the control stream and reads the `Hello`.
async fn handshake(connection: &Connection) -> Result<(SendStream, RecvStream, Hello), End> {
    let (send, mut recv) = connection
        .accept_bi()
        .await
        .map_err(|e| End::Closed(e.to_string()))?;
    match read_message::<ClientMessage, _>(&mut recv).await {
        Ok(Some(ClientMessage::Hello(hello))) => Ok((send, recv, hello)),
        Ok(Some(_)) => Err(End::Close(
            CloseCode::ProtocolViolation,
            "expected hello".into(),
        )),
        Ok(None) => Err(End::Close(
            CloseCode::ProtocolViolation,
            "stream ended before hello".into(),
        )),
        Err(e) => Err(End::from_frame(e, "reading hello")),
    }
}

/// Sends a `Reject` and waits (briefly) until the client has it, since
/// closing the connection discards unacknowledged stream data.
async fn reject(send: &mut SendStream, reason: &RejectReason) {
    if write_message(send, &ServerMessage::Reject(reason.clone()))
        .await
        .is_err()
        || send.finish().is_err()
    {
        return;
    }
    let _ = tokio::time::timeout(REJECT_LINGER, send.stopped()).await;
}

fn close(connection: &Connection, code: CloseCode, reason: &str) {
    // Keep the reason well inside one packet.
    let mut end = reason.len().min(200);
    while !reason.is_char_boundary(end) {
        end -= 1;
    }
    connection.close(code.into(), &reason.as_bytes()[..end]);
}
