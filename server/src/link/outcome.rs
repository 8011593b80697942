//! What every transport's reads and sends come to, whatever the transport:
//! [`Received`], [`Gone`], [`DatagramError`]. Below the transports and the
//! [`Link`](super::Link) facade, which all use them.

use bytes::Bytes;
use ledge_shared::protocol::web::WebError;

/// Bytes read from a control stream at a time.
pub const READ_CHUNK: usize = 4096;

/// How a connection went away under a session.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Gone {
    /// The peer closed it on purpose (it quit): a leave.
    Closed(String),
    /// Timed out, reset, or broken: a loss (the player is kept for a resume).
    Lost(String),
}

impl std::fmt::Display for Gone {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Gone::Closed(why) | Gone::Lost(why) => f.write_str(why),
        }
    }
}

/// What a [`Receiver`](super::Receiver) got next.
#[derive(Debug)]
pub enum Received {
    /// The next bytes of the control stream.
    Stream(Bytes),
    /// The client finished its control stream.
    StreamEnd,
    /// One datagram.
    Datagram(Bytes),
    /// A malformed transport message (WebSocket only): dropped, counted
    /// and struck like malformed input.
    Malformed(WebError),
    /// The transport cannot go on (WebSocket: a message over the limit):
    /// closed at once with [`CloseCode::ProtocolViolation`](ledge_shared::protocol::CloseCode::ProtocolViolation).
    Broken(String),
    /// The connection is gone.
    Gone(Gone),
}

/// Why a datagram was not sent.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DatagramError {
    /// The connection is gone.
    Lost,
    /// The transport refused it (too large, its buffer full, ...).
    Failed(String),
}
