//! A joined session: handshake over the control stream, then requests.

use std::net::SocketAddr;
use std::time::{Duration, Instant};

use ledge_server::framing::{read_message, write_message, FrameError};
use ledge_server::protocol::{
    ClientMessage, CloseCode, Hello, ServerMessage, Welcome, PROTOCOL_VERSION,
};
use ledge_server::Fingerprint;

use crate::error::ClientError;
use crate::transport::{dial, Dialed};

/// How long the server has to answer a hello or a ping.
pub const REPLY_TIMEOUT: Duration = Duration::from_secs(5);

/// How long [`Session::close`] waits for the close to reach the server.
const CLOSE_LINGER: Duration = Duration::from_secs(1);

/// Connects to a ledge server and joins as `player_name`.
///
/// Trusts only the certificate whose SHA-256 is `cert_fingerprint`, sends a
/// [`Hello`] with this build's [`PROTOCOL_VERSION`] and returns once the
/// server welcomed us. Headless: usable from bots and tests.
pub async fn connect(
    addr: SocketAddr,
    server_name: &str,
    cert_fingerprint: Fingerprint,
    player_name: &str,
) -> Result<Session, ClientError> {
    let dialed = dial(addr, server_name, cert_fingerprint).await?;
    handshake(
        dialed,
        Hello {
            protocol_version: PROTOCOL_VERSION,
            name: player_name.to_owned(),
        },
    )
    .await
}

/// Opens the control stream on a dialed connection, sends `hello` as given
/// and waits for the answer. [`connect`] is the usual entry point; this one
/// lets tests send any hello.
pub async fn handshake(dialed: Dialed, hello: Hello) -> Result<Session, ClientError> {
    let Dialed {
        endpoint,
        connection,
    } = dialed;
    let result = tokio::time::timeout(REPLY_TIMEOUT, async {
        let (mut send, mut recv) = connection
            .open_bi()
            .await
            .map_err(ClientError::from_connection_error)?;
        write_message(&mut send, &ClientMessage::Hello(hello)).await?;
        match read_message::<ServerMessage, _>(&mut recv).await? {
            Some(ServerMessage::Welcome(welcome)) => Ok((send, recv, welcome)),
            Some(ServerMessage::Reject(reason)) => Err(ClientError::Rejected(reason)),
            Some(other) => Err(ClientError::Unexpected(format!("{other:?} before welcome"))),
            None => Err(ClientError::StreamEnded),
        }
    })
    .await
    .unwrap_or(Err(ClientError::Timeout));
    match result {
        Ok((send, recv, welcome)) => Ok(Session {
            endpoint,
            connection,
            send,
            recv,
            welcome,
            next_nonce: 0,
        }),
        Err(e) => {
            let e = explain(&connection, e);
            connection.close(CloseCode::Normal.into(), b"handshake failed");
            Err(e)
        }
    }
}

/// Replaces a stream-level error by the connection's close reason when the
/// connection is gone, which says why (e.g. the server's close code).
fn explain(connection: &quinn::Connection, error: ClientError) -> ClientError {
    match (&error, connection.close_reason()) {
        (ClientError::Frame(FrameError::Io(_)) | ClientError::StreamEnded, Some(reason)) => {
            ClientError::from_connection_error(reason)
        }
        _ => error,
    }
}

/// A session with a server that welcomed us.
#[derive(Debug)]
pub struct Session {
    endpoint: quinn::Endpoint,
    connection: quinn::Connection,
    send: quinn::SendStream,
    recv: quinn::RecvStream,
    welcome: Welcome,
    next_nonce: u64,
}

impl Session {
    /// What the server said when we joined (player id, tick, state hash).
    pub fn welcome(&self) -> &Welcome {
        &self.welcome
    }

    /// The server's address.
    pub fn remote_address(&self) -> SocketAddr {
        self.connection.remote_address()
    }

    /// The underlying QUIC connection (for datagrams, stats, close reason).
    pub fn connection(&self) -> &quinn::Connection {
        &self.connection
    }

    /// Sends a ping on the control stream and returns the round-trip time.
    pub async fn ping(&mut self) -> Result<Duration, ClientError> {
        let nonce = self.next_nonce;
        self.next_nonce = self.next_nonce.wrapping_add(1);
        let sent = Instant::now();
        let result = tokio::time::timeout(REPLY_TIMEOUT, async {
            write_message(&mut self.send, &ClientMessage::Ping(nonce)).await?;
            match read_message::<ServerMessage, _>(&mut self.recv).await? {
                Some(ServerMessage::Pong(n)) if n == nonce => Ok(sent.elapsed()),
                Some(other) => Err(ClientError::Unexpected(format!(
                    "{other:?} in answer to ping {nonce}"
                ))),
                None => Err(ClientError::StreamEnded),
            }
        })
        .await
        .unwrap_or(Err(ClientError::Timeout));
        result.map_err(|e| explain(&self.connection, e))
    }

    /// Leaves gracefully: ends the control stream, closes the connection
    /// and waits briefly for the close to be delivered.
    pub async fn close(mut self) {
        let _ = self.send.finish();
        self.connection.close(CloseCode::Normal.into(), b"bye");
        let _ = tokio::time::timeout(CLOSE_LINGER, self.endpoint.wait_idle()).await;
    }
}
