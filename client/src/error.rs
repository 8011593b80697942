//! Everything that can go wrong on the client side of a connection.

use ledge_shared::protocol::{CloseCode, Fingerprint, ProtocolError, RejectReason};

/// Why connecting or talking to a server failed.
#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    /// `HOST:PORT` could not be parsed or resolved.
    #[error("cannot resolve server address {0:?} (expected HOST:PORT)")]
    Address(String),
    /// The local UDP socket could not be opened.
    #[error("cannot open a UDP socket: {0}")]
    Socket(std::io::Error),
    /// The TLS/QUIC client configuration was refused.
    #[error("client TLS configuration: {0}")]
    Config(String),
    /// quinn refused to start the connection (e.g. an invalid server name).
    #[error("cannot connect: {0}")]
    Connect(#[from] quinn::ConnectError),
    /// The server's certificate is not the pinned one.
    #[error("server certificate fingerprint is {presented}, expected {expected}")]
    FingerprintMismatch {
        /// The pinned fingerprint.
        expected: Fingerprint,
        /// The fingerprint of the certificate the server presented.
        presented: Fingerprint,
    },
    /// The server closed the connection with an application close code.
    #[error("{}", closed_text(*code, reason))]
    ClosedByServer {
        /// The close code, if this version knows it.
        code: Option<CloseCode>,
        /// The server's reason text.
        reason: String,
    },
    /// The connection failed (handshake, timeout, reset, ...).
    #[error("connection failed: {0}")]
    Connection(quinn::ConnectionError),
    /// The server refused the hello.
    #[error("server rejected us: {0}")]
    Rejected(RejectReason),
    /// A message could not be encoded, or one from the server was
    /// malformed (the control stream is then out of sync).
    #[error("protocol: {0}")]
    Protocol(#[from] ProtocolError),
    /// Reading or writing the control stream failed.
    #[error("control stream: {0}")]
    Stream(String),
    /// A datagram could not be sent.
    #[error("cannot send a datagram: {0}")]
    Datagram(#[from] quinn::SendDatagramError),
    /// The server sent a valid message at the wrong time.
    #[error("unexpected message from server: {0}")]
    Unexpected(String),
    /// The server ended the control stream.
    #[error("server ended the control stream")]
    StreamEnded,
    /// The server did not answer in time.
    #[error("server did not answer in time")]
    Timeout,
    /// The server plays a level we do not have (or a different version).
    #[error(
        "the server plays level {level_id:?} (hash {server:016x}), but {tried} has hash \
         {ours:016x}: pass the server's level file (--level)"
    )]
    LevelMismatch {
        /// The level id the server sent.
        level_id: String,
        /// What we tried.
        tried: String,
        /// The server's level hash.
        server: u64,
        /// Ours.
        ours: u64,
    },
    /// A level file could not be loaded.
    #[error("level: {0}")]
    Level(String),
    /// The server offers a level bigger than any client downloads.
    #[error(
        "the server's level is {size} bytes, more than the {max} a client downloads: the \
         server's host should use a smaller level (fewer or smaller images)"
    )]
    LevelTooLarge {
        /// The offered size.
        size: u64,
        /// The client's limit.
        max: u64,
    },
    /// Downloading the server's level failed (it resumes on the next join).
    #[error("downloading the server's level failed: {0}; joining again resumes it")]
    LevelDownload(String),
    /// The downloaded level is not the one the server named.
    #[error(
        "the downloaded level does not match the hash the server announced ({expected}); \
         it was deleted: join again to download it afresh"
    )]
    LevelHashMismatch {
        /// The announced SHA-256, hex.
        expected: String,
    },
    /// The game refused something (a snapshot, a player).
    #[error("game: {0}")]
    Game(#[from] ledge_shared::game::GameError),
    /// The server's certificate is not the one this client trusted for
    /// this address before (trust on first use).
    #[error("{0}")]
    Trust(#[from] crate::trust::TrustError),
}

impl ClientError {
    /// Classifies a quinn connection error, decoding application closes.
    pub fn from_connection_error(error: quinn::ConnectionError) -> ClientError {
        match error {
            quinn::ConnectionError::ApplicationClosed(close) => ClientError::ClosedByServer {
                code: u32::try_from(close.error_code.into_inner())
                    .ok()
                    .and_then(CloseCode::from_u32),
                reason: String::from_utf8_lossy(&close.reason).into_owned(),
            },
            other => ClientError::Connection(other),
        }
    }
}

/// Why the server closed the connection, in words (not the close code's
/// debug form), with the server's own reason when it gave one.
fn closed_text(code: Option<CloseCode>, reason: &str) -> String {
    let what = match code {
        Some(CloseCode::ServerShutdown) => "the server shut down",
        Some(CloseCode::Kicked) => "the server removed us from the game",
        Some(CloseCode::Timeout) => "the server closed the connection: we sent nothing in time",
        Some(CloseCode::ProtocolViolation) => {
            "the server closed the connection: it could not read what we sent (client and server versions may differ)"
        }
        Some(CloseCode::Rejected) => "the server refused us",
        Some(CloseCode::Normal) => "the server closed the connection",
        None => "the server closed the connection (a reason this version does not know)",
    };
    match reason.trim() {
        "" => what.to_owned(),
        r => format!("{what} ({r})"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_server_close_is_told_in_words() {
        let closed = |code, reason: &str| {
            ClientError::ClosedByServer {
                code,
                reason: reason.into(),
            }
            .to_string()
        };
        assert_eq!(
            closed(Some(CloseCode::ServerShutdown), "server shutting down"),
            "the server shut down (server shutting down)"
        );
        assert_eq!(
            closed(Some(CloseCode::Kicked), ""),
            "the server removed us from the game"
        );
        assert_eq!(
            closed(None, "bye"),
            "the server closed the connection (a reason this version does not know) (bye)"
        );
        for code in [
            Some(CloseCode::Normal),
            Some(CloseCode::ProtocolViolation),
            Some(CloseCode::Rejected),
            Some(CloseCode::Timeout),
            Some(CloseCode::ServerShutdown),
            Some(CloseCode::Kicked),
            None,
        ] {
            let text = closed(code, "why");
            assert!(!text.contains("Some(") && !text.contains("None"), "{text}");
        }
    }
}
