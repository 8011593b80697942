//! Everything that can go wrong on the client side of a connection.

#[cfg(not(target_arch = "wasm32"))]
use std::path::PathBuf;

use ledge_shared::protocol::{CloseCode, Fingerprint, ProtocolError, RejectReason, MAX_NAME_LEN};

/// Why connecting or talking to a server failed.
#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    /// `HOST:PORT` could not be parsed or resolved.
    #[error(
        "cannot find the server address \"{0}\": give it as HOST:PORT (for example \
         192.168.1.20:4433, the address and port the server printed when it started)"
    )]
    Address(String),
    /// The local UDP socket could not be opened.
    #[error("cannot open a UDP socket: {0}")]
    Socket(std::io::Error),
    /// The TLS/QUIC client configuration was refused.
    #[error("client TLS configuration: {0}")]
    Config(String),
    /// quinn refused to start the connection (e.g. an invalid server name).
    #[cfg(not(target_arch = "wasm32"))]
    #[error("cannot connect: {0}")]
    Connect(#[from] quinn::ConnectError),
    /// The server's certificate is not the pinned one.
    #[error(
        "the server's certificate has fingerprint {presented}, not {expected} as --cert-hash \
         says. The server prints its fingerprint when it starts (\"certificate SHA-256 \
         fingerprint: ...\"): ask its operator for that line and pass the fingerprint with \
         --cert-hash. If it is {presented}, connect again with --cert-hash {presented}; \
         otherwise this is not the server you meant (or someone is intercepting the \
         connection). Refusing to connect."
    )]
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
    #[cfg(not(target_arch = "wasm32"))]
    #[error("{}", connection_text(.0))]
    Connection(quinn::ConnectionError),
    /// The server refused the hello.
    #[error("{}", rejected_text(.0))]
    Rejected(RejectReason),
    /// A message could not be encoded, or one from the server was
    /// malformed (the control stream is then out of sync).
    #[error("{}", protocol_text(.0))]
    Protocol(#[from] ProtocolError),
    /// Reading or writing the control stream failed.
    #[error("the connection to the server broke: {0}")]
    Stream(String),
    /// A datagram could not be sent.
    #[cfg(not(target_arch = "wasm32"))]
    #[error("cannot send a datagram: {0}")]
    Datagram(#[from] quinn::SendDatagramError),
    /// The server sent a valid message at the wrong time.
    #[error("the server sent something unexpected ({0}): client and server versions may differ")]
    Unexpected(String),
    /// The server ended the control stream.
    #[error("the server ended the session")]
    StreamEnded,
    /// The server did not answer in time.
    #[error(
        "the server did not answer in time: check that it is running and that the address is \
         a ledge server's"
    )]
    Timeout,
    /// The server plays a level we do not have (or a different version).
    #[error(
        "the server plays level \"{level_id}\" (hash {server:016x}), but {tried} has hash \
         {ours:016x}: leave out --level to download the server's level, or pass the \
         server's own level file with --level FILE"
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
    #[error("cannot load the level: {0}")]
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
    #[error("the game refused what the server sent: {0}")]
    Game(#[from] ledge_shared::game::GameError),
    /// The server's certificate is not the one this client trusted for
    /// this address before (trust on first use).
    #[cfg(not(target_arch = "wasm32"))]
    #[error("{0}")]
    Trust(#[from] TrustError),
}

#[cfg(not(target_arch = "wasm32"))]
/// Why a certificate was not trusted, or the known-hosts file not used
/// (see [`crate::net::trust`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TrustError {
    /// The server presented a different certificate than the one stored for
    /// its address.
    #[error(
        "the certificate of {host} has CHANGED: it presented fingerprint {presented}, but \
         {path} (line {line}) trusts {stored} for this address. If the server was \
         reinstalled or its certificate regenerated, this is expected; otherwise someone may \
         be intercepting the connection. Ask the server's operator for its fingerprint; if it \
         is {presented}, remove line {line} from {path} and connect again (or pass \
         --cert-hash {presented}). Refusing to connect."
    )]
    Changed {
        /// The address, as looked up in the file.
        host: String,
        /// What the server presented now.
        presented: Fingerprint,
        /// What the file holds.
        stored: Fingerprint,
        /// The file.
        path: PathBuf,
        /// The line holding `stored` (1-based).
        line: usize,
    },
    /// The file could not be read or written.
    #[error("known hosts file {path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What failed.
        message: String,
    },
    /// A line of the file is not `HOST:PORT FINGERPRINT`.
    #[error("known hosts file {path}, line {line}: {message} (expected `HOST:PORT FINGERPRINT`)")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// The line (1-based).
        line: usize,
        /// What is wrong.
        message: String,
    },
}

#[cfg(not(target_arch = "wasm32"))]
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

/// A failed connection in words, with what to check.
#[cfg(not(target_arch = "wasm32"))]
fn connection_text(error: &quinn::ConnectionError) -> String {
    use quinn::ConnectionError as E;
    match error {
        E::TimedOut => "the server did not answer (timed out): check the address and port (the \
             server prints them when it starts), that the server is running, and that no \
             firewall blocks UDP to that port"
            .to_owned(),
        E::Reset => "the server reset the connection (it may have restarted): connect again".into(),
        E::VersionMismatch => {
            "the server speaks another QUIC version: client and server versions differ".into()
        }
        E::LocallyClosed => "the connection was closed on our side".into(),
        E::ConnectionClosed(close)
            if close.error_code == quinn::TransportErrorCode::CONNECTION_REFUSED =>
        {
            "the server refused the connection: it is full, or your address (this machine, or \
             everyone behind your router) already has as many connections as the server allows \
             (4 unless its host sets --max-per-address). Close other ledge clients on your \
             network, or try again in a few seconds"
                .into()
        }
        E::ApplicationClosed(close) => format!("the server closed the connection ({close})"),
        other => format!("the connection failed: {other}"),
    }
}

/// A refused hello in words, with what to do.
fn rejected_text(reason: &RejectReason) -> String {
    match reason {
        RejectReason::InvalidName => format!(
            "the server refused the player name: a name is 1 to {MAX_NAME_LEN} bytes without \
             control characters; choose another with --name"
        ),
        RejectReason::RoomFull => "the server refused us: the room is full. Try again later, or \
             ask the host for more places (ledge-server --max-players or --rooms)"
            .to_owned(),
        RejectReason::ShuttingDown => {
            "the server refused us: it is shutting down. Connect again once it is back".to_owned()
        }
        RejectReason::ProtocolVersion { server, client } => format!(
            "the server speaks protocol version {server} and this client {client}: use a \
             client of the server's version"
        ),
        other => format!("the server refused us: {other}"),
    }
}

/// A protocol error in words: our own bad input as it is, anything else
/// from the server as a likely version difference.
fn protocol_text(error: &ProtocolError) -> String {
    match error {
        ProtocolError::InvalidString { .. } | ProtocolError::InvalidValue { .. } => {
            error.to_string()
        }
        ProtocolError::BadVersion { .. } => {
            format!("{error}: use a client of the server's version")
        }
        other => format!(
            "cannot read what the server sent ({other}): client and server versions may differ"
        ),
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

    /// Every failure a player can meet, in words, saying what to do next.
    #[test]
    fn failures_say_what_to_do_next() {
        let fp = |b| Fingerprint([b; 32]);
        let cases: Vec<(ClientError, &[&str])> = vec![
            (
                ClientError::FingerprintMismatch {
                    expected: fp(1),
                    presented: fp(2),
                },
                &[
                    "certificate SHA-256 fingerprint: ...",
                    "--cert-hash 0202",
                    "not 0101",
                ],
            ),
            (
                ClientError::Connection(quinn::ConnectionError::TimedOut),
                &["address and port", "server is running", "firewall", "UDP"],
            ),
            (
                ClientError::Rejected(RejectReason::InvalidName),
                &["1 to 32 bytes", "--name"],
            ),
            (
                ClientError::Rejected(RejectReason::RoomFull),
                &["room is full", "Try again later"],
            ),
            (
                ClientError::Rejected(RejectReason::Other {
                    reason: "banned".into(),
                }),
                &["refused us: banned"],
            ),
            (
                ClientError::LevelMismatch {
                    level_id: "desert".into(),
                    tried: "the embedded default level".into(),
                    server: 1,
                    ours: 2,
                },
                &["\"desert\"", "--level FILE", "0000000000000001"],
            ),
            (
                ClientError::Address("nowhere".into()),
                &["\"nowhere\"", "HOST:PORT"],
            ),
            (
                ClientError::Protocol(ProtocolError::InvalidString {
                    field: "player name",
                    problem: "too long",
                }),
                &["invalid player name: too long"],
            ),
            (ClientError::Timeout, &["running"]),
        ];
        for (error, needles) in cases {
            let text = error.to_string();
            for needle in needles {
                assert!(text.contains(needle), "{needle:?} missing from {text:?}");
            }
            // Words, not debug forms.
            for debug in ["Some(", "None", "{ ", "\\\""] {
                assert!(!text.contains(debug), "{debug:?} in {text:?}");
            }
        }
    }
}
