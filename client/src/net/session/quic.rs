//! The session over QUIC (quinn): dial, handshake, then the protocol of
//! [`SessionState`] driven by the connection's control stream and
//! datagrams.

use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::time::{Duration, Instant};

use ledge_shared::input::Buttons;
use ledge_shared::protocol::{
    write_frame, ClientControl, CloseCode, Fingerprint, FrameDecoder, Message, PlayerId, RoomInfo,
    ServerControl, SnapshotHistory, StateSnapshot, Welcome, MAX_FRAME, PROTOCOL_VERSION,
};

use super::{JoinOptions, SessionEvent, SessionState, SessionStats, REPLY_TIMEOUT};
use crate::error::ClientError;
use crate::net::transport::{dial, Dialed};

/// How long [`Session::close`] waits for the server to close after `Leave`.
const CLOSE_LINGER: Duration = Duration::from_secs(1);

/// Connects to a ledge server and joins any room as `player_name`.
///
/// Trusts only the certificate whose SHA-256 is `cert_fingerprint`, sends a
/// `Hello` with this build's [`PROTOCOL_VERSION`] and returns once the
/// server welcomed us. Headless: usable from bots and tests.
pub async fn connect(
    addr: SocketAddr,
    server_name: &str,
    cert_fingerprint: Fingerprint,
    player_name: &str,
) -> Result<Session, ClientError> {
    connect_with(
        addr,
        server_name,
        cert_fingerprint,
        &JoinOptions::new(player_name),
    )
    .await
}

/// [`connect`] with a choice of room.
pub async fn connect_with(
    addr: SocketAddr,
    server_name: &str,
    cert_fingerprint: Fingerprint,
    options: &JoinOptions,
) -> Result<Session, ClientError> {
    // Refuse a bad name here, with the reason, rather than sending it.
    let hello = options.hello();
    hello.validate()?;
    let dialed = dial(addr, server_name, cert_fingerprint).await?;
    handshake(dialed, hello).await
}

/// Opens the control stream on a dialed connection, sends `hello` as given
/// (any message: tests use this to send wrong ones) and waits for the
/// answer. [`connect`] is the usual entry point.
pub async fn handshake(dialed: Dialed, hello: ClientControl) -> Result<Session, ClientError> {
    let Dialed {
        endpoint,
        connection,
    } = dialed;
    let mut decoder = FrameDecoder::new(MAX_FRAME);
    let result = ask(&connection, &hello, &mut decoder)
        .await
        .and_then(|(send, recv, answer)| match answer {
            ServerControl::Welcome(welcome) => Ok((send, recv, welcome)),
            ServerControl::Reject { reason } => Err(ClientError::Rejected(reason)),
            other => Err(ClientError::Unexpected(format!(
                "{} before the welcome",
                other.kind()
            ))),
        });
    // The roster often arrives with the welcome: the state handles what
    // the decoder already holds.
    let result = result.and_then(|(send, recv, welcome)| {
        Ok((
            send,
            recv,
            SessionState::new(welcome, decoder, Instant::now())?,
        ))
    });
    match result {
        Ok((send, recv, state)) => Ok(Session {
            endpoint,
            connection,
            send,
            recv,
            buf: vec![0u8; 8192],
            stream_ended: false,
            state,
        }),
        Err(e) => {
            let e = explain(&connection, e);
            connection.close(CloseCode::Normal.to_u32().into(), b"handshake failed");
            Err(e)
        }
    }
}

/// Opens the control stream, sends `first` and reads the server's first
/// answer (within [`REPLY_TIMEOUT`]).
async fn ask(
    connection: &quinn::Connection,
    first: &ClientControl,
    decoder: &mut FrameDecoder,
) -> Result<(quinn::SendStream, quinn::RecvStream, ServerControl), ClientError> {
    tokio::time::timeout(REPLY_TIMEOUT, async {
        let (mut send, mut recv) = connection
            .open_bi()
            .await
            .map_err(ClientError::from_connection_error)?;
        let mut frame = Vec::new();
        write_frame(first, &mut frame)?;
        send.write_all(&frame)
            .await
            .map_err(|e| ClientError::Stream(e.to_string()))?;
        let mut buf = vec![0u8; 8192];
        loop {
            if let Some(message) = decoder.pop_message::<ServerControl>() {
                return Ok((send, recv, message?));
            }
            match recv.read(&mut buf).await {
                Ok(Some(n)) => decoder.push(&buf[..n])?,
                Ok(None) => return Err(ClientError::StreamEnded),
                Err(e) => return Err(ClientError::Stream(e.to_string())),
            }
        }
    })
    .await
    .unwrap_or(Err(ClientError::Timeout))
}

/// Asks a dialed server for its rooms (`ListRooms`) instead of joining,
/// then closes the connection.
pub async fn list_rooms(dialed: Dialed) -> Result<Vec<RoomInfo>, ClientError> {
    let Dialed {
        endpoint,
        connection,
    } = dialed;
    let first = ClientControl::ListRooms {
        version: PROTOCOL_VERSION,
    };
    let mut decoder = FrameDecoder::new(MAX_FRAME);
    let result = ask(&connection, &first, &mut decoder)
        .await
        .and_then(|(_, _, answer)| match answer {
            ServerControl::Rooms { rooms } => Ok(rooms),
            ServerControl::Reject { reason } => Err(ClientError::Rejected(reason)),
            other => Err(ClientError::Unexpected(format!(
                "{} instead of the room list",
                other.kind()
            ))),
        })
        .map_err(|e| explain(&connection, e));
    connection.close(CloseCode::Normal.to_u32().into(), b"listed");
    // Lets the close reach the server (bounded: it may be gone).
    let _ = tokio::time::timeout(CLOSE_LINGER, endpoint.wait_idle()).await;
    result
}

/// Replaces a stream-level error by the connection's close reason when the
/// connection is gone, which says why (e.g. the server's close code).
fn explain(connection: &quinn::Connection, error: ClientError) -> ClientError {
    match (&error, connection.close_reason()) {
        (ClientError::Stream(_) | ClientError::StreamEnded, Some(reason)) => {
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
    buf: Vec<u8>,
    stream_ended: bool,
    state: SessionState,
}

impl Session {
    /// What the server said when we joined (player id, room, level, tick,
    /// timing), or the latest level change's welcome
    /// ([`SessionEvent::LevelChange`]).
    pub fn welcome(&self) -> &Welcome {
        self.state.welcome()
    }

    /// The server's address.
    pub fn remote_address(&self) -> SocketAddr {
        self.connection.remote_address()
    }

    /// The underlying QUIC connection (stats, close reason, raw datagrams).
    pub fn connection(&self) -> &quinn::Connection {
        &self.connection
    }

    /// Who is in our room, by id (us included, once the roster arrived):
    /// at most [`ledge_shared::protocol::MAX_ROSTER`] names.
    pub fn players(&self) -> &BTreeMap<PlayerId, String> {
        self.state.players()
    }

    /// The name of player `id`, if known.
    pub fn player_name(&self, id: PlayerId) -> Option<&str> {
        self.state.player_name(id)
    }

    /// The newest decoded snapshot.
    pub fn latest_snapshot(&self) -> Option<&StateSnapshot> {
        self.state.latest_snapshot()
    }

    /// The snapshots decoded so far (the newest
    /// [`super::SNAPSHOT_HISTORY`]).
    pub fn snapshots(&self) -> &SnapshotHistory {
        self.state.snapshots()
    }

    /// The tick we acknowledge: the newest decoded snapshot's.
    pub fn ack(&self) -> Option<u64> {
        self.state.ack()
    }

    /// Counters of what was received and sent.
    pub fn stats(&self) -> SessionStats {
        self.state.stats()
    }

    /// Whether we are quiet ([`SessionState::is_quiet`]).
    pub fn is_quiet(&self) -> bool {
        self.state.is_quiet()
    }

    /// Records our buttons for `tick` and, when one is due, sends an input
    /// datagram carrying it and the ticks before it (as many as the server
    /// asked for in `Welcome`), plus the acknowledgement of the newest
    /// snapshot ([`SessionState::input_datagram`]). Never blocks: quinn
    /// drops the oldest queued datagram when its small buffer is full.
    pub fn send_input(&mut self, tick: u64, buttons: Buttons) -> Result<(), ClientError> {
        if let Some(datagram) = self.state.input_datagram(tick, buttons)? {
            self.connection.send_datagram(datagram.into())?;
        }
        Ok(())
    }

    /// Sends a control message.
    pub async fn send_control(&mut self, message: &ClientControl) -> Result<(), ClientError> {
        let mut frame = Vec::new();
        write_frame(message, &mut frame)?;
        self.send_raw_control(&frame).await
    }

    /// Writes raw bytes on the control stream, as they are: for tests of
    /// what the server does with broken or hostile input.
    pub async fn send_raw_control(&mut self, bytes: &[u8]) -> Result<(), ClientError> {
        let written = self.send.write_all(bytes).await;
        written.map_err(|e| explain(&self.connection, ClientError::Stream(e.to_string())))
    }

    /// Says `text` to the room (1..=256 bytes, no control characters).
    pub async fn chat(&mut self, text: &str) -> Result<(), ClientError> {
        self.send_control(&ClientControl::Chat {
            text: text.to_owned(),
        })
        .await
    }

    /// Votes for the level the room plays next: `level` is an index into
    /// the [`SessionEvent::Levels`] list (a later vote replaces this one;
    /// a spectator's is refused with a notice).
    pub async fn vote(&mut self, level: u32) -> Result<(), ClientError> {
        let frame = SessionState::vote_frame(level)?;
        self.send_raw_control(&frame).await
    }

    /// The room's levels, votes and when it moves on, as last heard.
    pub fn levels(&self) -> Option<&ledge_shared::protocol::LevelList> {
        self.state.levels()
    }

    /// Sends a ping and returns its nonce; the [`SessionEvent::Pong`]
    /// carries the round-trip time.
    pub async fn send_ping(&mut self) -> Result<u64, ClientError> {
        let (nonce, frame) = self.state.ping_frame(Instant::now())?;
        self.send_raw_control(&frame).await?;
        Ok(nonce)
    }

    /// Pings the server and waits for the answer; returns the round-trip
    /// time. Other events arriving meanwhile are kept for [`Session::recv`].
    pub async fn ping(&mut self) -> Result<Duration, ClientError> {
        let sent = Instant::now();
        let nonce = self.send_ping().await?;
        let mut kept: Vec<SessionEvent> = Vec::new();
        while let Some(event) = self.state.poll_event() {
            kept.push(event);
        }
        let answer = tokio::time::timeout(REPLY_TIMEOUT, async {
            loop {
                match self.recv().await? {
                    SessionEvent::Pong { nonce: n, .. } if n == nonce => return Ok(sent.elapsed()),
                    other => kept.push(other),
                }
            }
        })
        .await
        .unwrap_or(Err(ClientError::Timeout));
        self.state.unpoll(kept);
        answer
    }

    /// The next event from the server. Cancel-safe: dropping the future
    /// loses nothing. Errors when the connection ends (the server's close
    /// code and reason in [`ClientError::ClosedByServer`]) or the control
    /// stream breaks.
    pub async fn recv(&mut self) -> Result<SessionEvent, ClientError> {
        loop {
            if let Some(event) = self.state.poll_event() {
                return Ok(event);
            }
            tokio::select! {
                // Stream first: a notice buffered before the close is
                // delivered before the close itself.
                biased;
                read = self.recv.read(&mut self.buf), if !self.stream_ended => match read {
                    Ok(Some(n)) => self
                        .state
                        .on_stream(&self.buf[..n], Instant::now())
                        .map_err(|e| explain(&self.connection, e))?,
                    // The server finished the stream: the close follows.
                    Ok(None) => self.stream_ended = true,
                    Err(e) => {
                        return Err(explain(&self.connection, ClientError::Stream(e.to_string())))
                    }
                },
                datagram = self.connection.read_datagram() => match datagram {
                    Ok(bytes) => self.state.on_datagram(&bytes, Instant::now()),
                    Err(e) => return Err(ClientError::from_connection_error(e)),
                },
            }
        }
    }

    /// Leaves gracefully: sends `Leave`, finishes the control stream, waits
    /// briefly for the server to close, then closes the connection.
    pub async fn close(mut self) {
        let _ = tokio::time::timeout(CLOSE_LINGER, async {
            if self.send_control(&ClientControl::Leave).await.is_ok() {
                let _ = self.send.finish();
                self.connection.closed().await;
            }
        })
        .await;
        self.connection
            .close(CloseCode::Normal.to_u32().into(), b"bye");
        let _ = tokio::time::timeout(CLOSE_LINGER, self.endpoint.wait_idle()).await;
    }
}
