//! The transports a client connects over, behind one interface, so one
//! connection path ([`crate::connection`]) serves them all: native QUIC
//! ([`quic`]), WebTransport for browsers ([`webtransport`]) and WebSocket
//! for browsers without it ([`websocket`]).
//!
//! A session needs the same few things from each: a reliable control
//! stream (read as [`Received::Stream`] chunks, written through a
//! [`ControlSend`]), unreliable datagrams both ways, a one-way stream for
//! the level bundle ([`LevelSend`]), and a close with a [`CloseCode`] and a
//! reason. [`Link`] is the cheap-clone handle the room keeps (datagrams,
//! level stream, close); [`Receiver`] is the connection task's receive
//! side. Enums rather than trait objects: the native QUIC path stays a
//! direct call into quinn, with no extra task, copy or allocation per
//! datagram.

mod outcome;
pub mod quic;
pub mod websocket;
pub mod webtransport;

use std::net::SocketAddr;

use bytes::Bytes;
use ledge_shared::protocol::CloseCode;
use prometheus_client::encoding::{EncodeLabelValue, LabelValueEncoder};

pub use outcome::{DatagramError, Gone, Received, READ_CHUNK};

/// Which transport a connection uses (a metric label).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Transport {
    /// Native QUIC (the `ledge-client`).
    Quic,
    /// WebTransport over HTTP/3 (browsers).
    WebTransport,
    /// WebSocket over HTTP/1.1 (browsers without WebTransport).
    WebSocket,
}

impl Transport {
    /// Every transport.
    pub const ALL: [Transport; 3] = [
        Transport::Quic,
        Transport::WebTransport,
        Transport::WebSocket,
    ];

    /// Its label value: `quic`, `webtransport`, `websocket`.
    pub fn as_str(self) -> &'static str {
        match self {
            Transport::Quic => "quic",
            Transport::WebTransport => "webtransport",
            Transport::WebSocket => "websocket",
        }
    }
}

impl EncodeLabelValue for Transport {
    fn encode(&self, encoder: &mut LabelValueEncoder) -> Result<(), std::fmt::Error> {
        std::fmt::Write::write_str(encoder, self.as_str())
    }
}

/// A new connection before its transport handshake.
pub enum Incoming {
    /// A QUIC connection attempt.
    Quic(quinn::Incoming),
    /// A WebTransport (HTTP/3) connection attempt.
    WebTransport(wtransport::endpoint::IncomingSession),
    /// A WebSocket, already upgraded.
    WebSocket(websocket::Upgraded),
}

impl std::fmt::Debug for Incoming {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Incoming({:?} from {})",
            self.transport(),
            self.remote_address()
        )
    }
}

impl Incoming {
    /// Its transport.
    pub fn transport(&self) -> Transport {
        match self {
            Incoming::Quic(_) => Transport::Quic,
            Incoming::WebTransport(_) => Transport::WebTransport,
            Incoming::WebSocket(_) => Transport::WebSocket,
        }
    }

    /// The client's address (UDP for QUIC and WebTransport, the TCP peer
    /// for WebSocket).
    pub fn remote_address(&self) -> SocketAddr {
        match self {
            Incoming::Quic(i) => i.remote_address(),
            Incoming::WebTransport(i) => i.remote_address(),
            Incoming::WebSocket(u) => u.remote_address(),
        }
    }

    /// Finishes the transport's handshake (QUIC; QUIC and the HTTP/3
    /// session request; nothing for an upgraded WebSocket).
    pub async fn connect(self) -> Result<(Link, Acceptor), String> {
        match self {
            Incoming::Quic(incoming) => {
                let connection = incoming.await.map_err(|e| e.to_string())?;
                Ok((Link::Quic(connection.clone()), Acceptor::Quic(connection)))
            }
            Incoming::WebTransport(incoming) => {
                let connection = webtransport::accept(incoming).await?;
                Ok((
                    Link::WebTransport(connection.clone()),
                    Acceptor::WebTransport(connection),
                ))
            }
            Incoming::WebSocket(upgraded) => {
                let (handle, reader) = websocket::start(upgraded);
                Ok((Link::WebSocket(handle), Acceptor::WebSocket(reader)))
            }
        }
    }
}

/// A connected client whose control stream is not open yet.
pub enum Acceptor {
    /// QUIC.
    Quic(quinn::Connection),
    /// WebTransport.
    WebTransport(wtransport::Connection),
    /// WebSocket (its control stream is the socket itself).
    WebSocket(websocket::Reader),
}

impl Acceptor {
    /// Waits for the client's control stream: its write half and the
    /// connection's receive side.
    pub async fn accept_control(self) -> Result<(ControlSend, Receiver), Gone> {
        match self {
            Acceptor::Quic(connection) => {
                let (send, recv) = connection.accept_bi().await.map_err(quic::gone)?;
                Ok((ControlSend::Quic(send), Receiver::Quic { recv, connection }))
            }
            Acceptor::WebTransport(connection) => {
                let (send, recv) = connection.accept_bi().await.map_err(webtransport::gone)?;
                Ok((
                    ControlSend::WebTransport(send),
                    Receiver::WebTransport { recv, connection },
                ))
            }
            Acceptor::WebSocket(reader) => Ok((
                ControlSend::WebSocket(reader.handle()),
                Receiver::WebSocket(reader),
            )),
        }
    }
}

/// The write half of a client's control stream.
pub enum ControlSend {
    /// A QUIC stream.
    Quic(quinn::SendStream),
    /// A WebTransport stream.
    WebTransport(wtransport::SendStream),
    /// `Stream` messages on the WebSocket.
    WebSocket(websocket::Handle),
}

impl ControlSend {
    /// Writes all of `bytes` (waiting while the client's window is full).
    pub async fn write_all(&mut self, bytes: &[u8]) -> Result<(), String> {
        match self {
            ControlSend::Quic(s) => s.write_all(bytes).await.map_err(|e| e.to_string()),
            ControlSend::WebTransport(s) => s.write_all(bytes).await.map_err(|e| e.to_string()),
            ControlSend::WebSocket(h) => h.send_stream(bytes).await,
        }
    }

    /// Finishes the stream (nothing more will be written); false if it
    /// was already finished or reset.
    pub async fn finish(&mut self) -> bool {
        match self {
            ControlSend::Quic(s) => s.finish().is_ok(),
            ControlSend::WebTransport(s) => s.finish().await.is_ok(),
            // The socket carries the stream until it closes.
            ControlSend::WebSocket(_) => true,
        }
    }

    /// Resolves once the client has everything written (or stopped
    /// reading, or the connection is gone). Not bounded: callers time it
    /// out where the client may not read at all.
    pub async fn stopped(&mut self) {
        match self {
            ControlSend::Quic(s) => {
                let _ = s.stopped().await;
            }
            ControlSend::WebTransport(s) => {
                let _ = s.stopped().await;
            }
            ControlSend::WebSocket(h) => h.flushed().await,
        }
    }
}

/// A connection's receive side: control stream and datagrams.
pub enum Receiver {
    /// QUIC: the control stream's read half and the connection.
    Quic {
        /// The control stream.
        recv: quinn::RecvStream,
        /// For datagrams.
        connection: quinn::Connection,
    },
    /// WebTransport: the control stream's read half and the session.
    WebTransport {
        /// The control stream.
        recv: wtransport::RecvStream,
        /// For datagrams.
        connection: wtransport::Connection,
    },
    /// WebSocket: every message.
    WebSocket(websocket::Reader),
}

impl Receiver {
    /// The next chunk of the control stream, before the hello: datagrams
    /// are left to the transport's buffer (QUIC, WebTransport) or dropped
    /// (WebSocket: there is no player yet to take them). Cancel-safe.
    pub async fn next_stream(&mut self) -> Received {
        match self {
            Receiver::Quic { recv, .. } => quic::read(recv).await,
            Receiver::WebTransport { recv, .. } => webtransport::read(recv).await,
            Receiver::WebSocket(reader) => reader.next(false).await,
        }
    }

    /// The next chunk of the control stream or datagram, whichever comes
    /// first. Cancel-safe.
    pub async fn next(&mut self) -> Received {
        match self {
            Receiver::Quic { recv, connection } => tokio::select! {
                read = quic::read(recv) => read,
                datagram = connection.read_datagram() => match datagram {
                    Ok(datagram) => Received::Datagram(datagram),
                    Err(e) => Received::Gone(quic::gone(e)),
                },
            },
            Receiver::WebTransport { recv, connection } => tokio::select! {
                read = webtransport::read(recv) => read,
                datagram = connection.receive_datagram() => match datagram {
                    Ok(datagram) => Received::Datagram(datagram.payload()),
                    Err(e) => Received::Gone(webtransport::gone(e)),
                },
            },
            Receiver::WebSocket(reader) => reader.next(true).await,
        }
    }
}

/// UDP totals of a connection: datagrams and their payload bytes (QUIC
/// packets, coalesced ones counted once; IP and UDP headers not included).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Wire {
    /// Datagrams received.
    pub datagrams_in: u64,
    /// Their UDP payload bytes.
    pub bytes_in: u64,
    /// Datagrams sent.
    pub datagrams_out: u64,
    /// Their UDP payload bytes.
    pub bytes_out: u64,
}

/// What the room keeps to reach a client: cheap to clone.
#[derive(Debug, Clone)]
pub enum Link {
    /// QUIC.
    Quic(quinn::Connection),
    /// WebTransport.
    WebTransport(wtransport::Connection),
    /// WebSocket.
    WebSocket(websocket::Handle),
}

impl Link {
    /// Its transport.
    pub fn transport(&self) -> Transport {
        match self {
            Link::Quic(_) => Transport::Quic,
            Link::WebTransport(_) => Transport::WebTransport,
            Link::WebSocket(_) => Transport::WebSocket,
        }
    }

    /// The client's address.
    pub fn remote_address(&self) -> SocketAddr {
        match self {
            Link::Quic(c) => c.remote_address(),
            Link::WebTransport(c) => c.remote_address(),
            Link::WebSocket(h) => h.remote_address(),
        }
    }

    /// The largest datagram the client takes now; `None`: none at all.
    pub fn max_datagram_size(&self) -> Option<usize> {
        match self {
            Link::Quic(c) => c.max_datagram_size(),
            Link::WebTransport(c) => c.max_datagram_size(),
            Link::WebSocket(_) => Some(websocket::MAX_DATAGRAM),
        }
    }

    /// What the connection has put through its UDP socket so far (native
    /// QUIC only: the other transports' counts are not exposed).
    pub fn wire(&self) -> Option<Wire> {
        match self {
            Link::Quic(c) => {
                let s = c.stats();
                Some(Wire {
                    datagrams_in: s.udp_rx.datagrams,
                    bytes_in: s.udp_rx.bytes,
                    datagrams_out: s.udp_tx.datagrams,
                    bytes_out: s.udp_tx.bytes,
                })
            }
            Link::WebTransport(_) | Link::WebSocket(_) => None,
        }
    }

    /// Sends one datagram (QUIC: zero-copy). A congested client loses
    /// datagrams rather than queueing them.
    pub fn send_datagram(&self, datagram: Bytes) -> Result<(), DatagramError> {
        match self {
            Link::Quic(c) => c.send_datagram(datagram).map_err(|e| match e {
                quinn::SendDatagramError::ConnectionLost(_) => DatagramError::Lost,
                e => DatagramError::Failed(e.to_string()),
            }),
            Link::WebTransport(c) => c.send_datagram(&datagram).map_err(|e| match e {
                wtransport::error::SendDatagramError::NotConnected => DatagramError::Lost,
                e => DatagramError::Failed(e.to_string()),
            }),
            Link::WebSocket(h) => h.send_datagram(&datagram),
        }
    }

    /// Closes the connection with `code` and `reason` (cut to fit). What
    /// was not yet delivered may be lost: say goodbye first and wait.
    pub fn close(&self, code: CloseCode, reason: &str) {
        match self {
            Link::Quic(c) => quic::close(c, code, reason),
            Link::WebTransport(c) => webtransport::close(c, code, reason),
            Link::WebSocket(h) => h.close(code, reason),
        }
    }

    /// Opens the one-way stream the level bundle goes on; `None` if the
    /// connection is gone.
    pub async fn open_level(&self) -> Option<LevelSend> {
        match self {
            Link::Quic(c) => c.open_uni().await.ok().map(LevelSend::Quic),
            Link::WebTransport(c) => {
                let opening = c.open_uni().await.ok()?;
                opening.await.ok().map(LevelSend::WebTransport)
            }
            Link::WebSocket(h) => Some(LevelSend::WebSocket(h.clone())),
        }
    }
}

/// The level bundle's one-way stream.
pub enum LevelSend {
    /// A QUIC stream.
    Quic(quinn::SendStream),
    /// A WebTransport stream.
    WebTransport(wtransport::SendStream),
    /// `Level` messages, then `LevelEnd`.
    WebSocket(websocket::Handle),
}

impl LevelSend {
    /// Writes one chunk; false if the client is gone or stopped it.
    pub async fn write_all(&mut self, chunk: &[u8]) -> bool {
        match self {
            LevelSend::Quic(s) => s.write_all(chunk).await.is_ok(),
            LevelSend::WebTransport(s) => s.write_all(chunk).await.is_ok(),
            LevelSend::WebSocket(h) => h.send_level(chunk).await.is_ok(),
        }
    }

    /// Finishes the stream; false if it could not be.
    pub async fn finish(mut self) -> bool {
        match &mut self {
            LevelSend::Quic(s) => s.finish().is_ok(),
            LevelSend::WebTransport(s) => s.finish().await.is_ok(),
            LevelSend::WebSocket(h) => h.send_level_end().await.is_ok(),
        }
    }
}
