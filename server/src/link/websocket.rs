//! The WebSocket transport (browsers without WebTransport): one socket
//! carries the control stream, datagrams and the level bundle as tagged
//! binary messages ([`ledge_shared::protocol::web`]).
//!
//! The socket is split: the connection task reads ([`Reader`]); a writer
//! task owns the write half and takes, in order, what the control stream
//! and the level download send (a bounded queue the senders wait on, like
//! a stream's flow control) and datagrams (a small queue; a full one drops
//! the datagram, as quinn's datagram buffer does). A close goes ahead of
//! anything queued, as a QUIC close does.

use std::net::SocketAddr;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use axum::extract::ws::{CloseFrame, Message, WebSocket};
use bytes::Bytes;
use futures_util::stream::{SplitSink, SplitStream};
use futures_util::{SinkExt, StreamExt};
use ledge_shared::protocol::web::{self, Tag, WebMessage};
use ledge_shared::protocol::CloseCode;
use tokio::sync::{mpsc, oneshot, Notify};

use super::outcome::{DatagramError, Gone, Received};

/// Largest snapshot datagram sent on a WebSocket: what every QUIC path
/// takes, so a browser sees the same datagrams as a native client.
pub const MAX_DATAGRAM: usize = 1200;
/// Stream and level messages queued for the writer (senders wait beyond).
const CONTROL_QUEUE: usize = 16;
/// Datagrams queued for the writer; more are dropped (counted by the
/// caller), so a backed-up socket gets the newest snapshots, not a backlog.
const DATAGRAM_QUEUE: usize = 4;
/// How long the close frame may take to go out.
const CLOSE_LINGER: Duration = Duration::from_secs(1);

/// Bytes the WebSocket library may buffer for writing before a send waits
/// (then errs past [`MAX_WRITE_BUFFER`]).
pub const WRITE_BUFFER: usize = 64 * 1024;
/// Most bytes the WebSocket library buffers for writing.
pub const MAX_WRITE_BUFFER: usize = 256 * 1024;

/// An upgraded WebSocket, admitted, with where it comes from.
pub struct Upgraded {
    socket: WebSocket,
    remote: SocketAddr,
    idle_timeout: Duration,
}

impl Upgraded {
    /// `socket` from `remote`; a joined client silent for `idle_timeout`
    /// is lost (clients send an input every tick).
    pub fn new(socket: WebSocket, remote: SocketAddr, idle_timeout: Duration) -> Upgraded {
        Upgraded {
            socket,
            remote,
            idle_timeout,
        }
    }

    /// The TCP peer's address.
    pub fn remote_address(&self) -> SocketAddr {
        self.remote
    }
}

/// What the writer task takes from the control queue.
enum Out {
    /// A whole message (tag included).
    Message(Vec<u8>),
    /// Answer once everything before is written.
    Flush(oneshot::Sender<()>),
}

/// The close asked for, shared by the handles and the writer.
#[derive(Debug, Default)]
struct Closing {
    frame: Mutex<Option<(u16, String)>>,
    notify: Notify,
}

/// The cheap-clone sending side of a WebSocket session.
#[derive(Debug, Clone)]
pub struct Handle {
    remote: SocketAddr,
    control: mpsc::Sender<Out>,
    datagrams: mpsc::Sender<Vec<u8>>,
    closing: Arc<Closing>,
}

impl std::fmt::Debug for Out {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Out::Message(m) => write!(f, "Message({} bytes)", m.len()),
            Out::Flush(_) => f.write_str("Flush"),
        }
    }
}

/// Splits the socket and starts its writer task.
pub fn start(upgraded: Upgraded) -> (Handle, Reader) {
    let (sink, stream) = upgraded.socket.split();
    let (control, control_rx) = mpsc::channel(CONTROL_QUEUE);
    let (datagrams, datagram_rx) = mpsc::channel(DATAGRAM_QUEUE);
    let closing = Arc::new(Closing::default());
    tokio::spawn(write(sink, control_rx, datagram_rx, closing.clone()));
    let handle = Handle {
        remote: upgraded.remote,
        control,
        datagrams,
        closing,
    };
    let reader = Reader {
        stream: Some(stream),
        handle: handle.clone(),
        idle_timeout: upgraded.idle_timeout,
    };
    (handle, reader)
}

impl Handle {
    /// The TCP peer's address.
    pub fn remote_address(&self) -> SocketAddr {
        self.remote
    }

    async fn send(&self, tag: Tag, payload: &[u8]) -> Result<(), String> {
        self.control
            .send(Out::Message(web::encode(tag, payload)))
            .await
            .map_err(|_| "the WebSocket is closed".to_owned())
    }

    /// Sends bytes of the control stream (waits while the queue is full).
    pub async fn send_stream(&self, bytes: &[u8]) -> Result<(), String> {
        self.send(Tag::Stream, bytes).await
    }

    /// Sends a chunk of the level bundle.
    pub async fn send_level(&self, chunk: &[u8]) -> Result<(), String> {
        self.send(Tag::Level, chunk).await
    }

    /// Says the level bundle is complete.
    pub async fn send_level_end(&self) -> Result<(), String> {
        self.send(Tag::LevelEnd, &[]).await
    }

    /// Resolves once everything queued so far is written to the socket
    /// (or the socket is gone).
    pub async fn flushed(&self) {
        let (done, written) = oneshot::channel();
        if self.control.send(Out::Flush(done)).await.is_ok() {
            let _ = written.await;
        }
    }

    /// Queues a datagram; a full queue drops it.
    pub fn send_datagram(&self, datagram: &[u8]) -> Result<(), DatagramError> {
        match self
            .datagrams
            .try_send(web::encode(Tag::Datagram, datagram))
        {
            Ok(()) => Ok(()),
            Err(mpsc::error::TrySendError::Full(_)) => Err(DatagramError::Failed(
                "the WebSocket is backed up: datagram dropped".into(),
            )),
            Err(mpsc::error::TrySendError::Closed(_)) => Err(DatagramError::Lost),
        }
    }

    /// Closes the socket with close code `4000 + code` and `reason` (cut
    /// to a close frame's 123 bytes), ahead of anything still queued. The
    /// first close wins.
    pub fn close(&self, code: CloseCode, reason: &str) {
        let mut frame = self
            .closing
            .frame
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        if frame.is_none() {
            *frame = Some((web::close_code(code), web::close_reason(reason).to_owned()));
            self.closing.notify.notify_one();
        }
    }
}

/// Writes what the handles queue until the socket closes or is closed.
async fn write(
    mut sink: SplitSink<WebSocket, Message>,
    mut control: mpsc::Receiver<Out>,
    mut datagrams: mpsc::Receiver<Vec<u8>>,
    closing: Arc<Closing>,
) {
    loop {
        let message = tokio::select! {
            biased;
            () = closing.notify.notified() => break,
            out = control.recv() => match out {
                Some(Out::Message(m)) => m,
                Some(Out::Flush(done)) => {
                    let _ = done.send(());
                    continue;
                }
                // Every handle is gone.
                None => break,
            },
            Some(datagram) = datagrams.recv() => datagram,
        };
        tokio::select! {
            biased;
            // A client that reads nothing blocks the send: close anyway
            // (dropping the socket).
            () = closing.notify.notified() => return,
            sent = sink.send(Message::Binary(message)) => if sent.is_err() { return },
        }
    }
    let frame = closing
        .frame
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .take();
    if let Some((code, reason)) = frame {
        let close = Message::Close(Some(CloseFrame {
            code,
            reason: reason.into(),
        }));
        let _ = tokio::time::timeout(CLOSE_LINGER, sink.send(close)).await;
    }
    let _ = tokio::time::timeout(CLOSE_LINGER, sink.close()).await;
}

/// The receive side of a WebSocket session. Dropped, it keeps reading
/// (and discarding) for up to `CLOSE_LINGER`, until the client answers
/// the close: a socket closed with unread input is reset, and a reset
/// makes the client's system discard what it had not read yet, the close
/// frame and the goodbye before it included.
pub struct Reader {
    stream: Option<SplitStream<WebSocket>>,
    handle: Handle,
    idle_timeout: Duration,
}

impl Drop for Reader {
    fn drop(&mut self) {
        let (Some(mut stream), Ok(runtime)) =
            (self.stream.take(), tokio::runtime::Handle::try_current())
        else {
            return;
        };
        runtime.spawn(async move {
            let deadline = tokio::time::Instant::now() + CLOSE_LINGER;
            loop {
                match tokio::time::timeout_at(deadline, stream.next()).await {
                    // The client answered the close, or time is up.
                    Ok(Some(Ok(Message::Close(_)))) | Err(_) => return,
                    Ok(Some(Ok(_))) => {}
                    // Unreadable (e.g. a message over the limit, whose
                    // rest stays unread): hold the socket until the
                    // deadline all the same.
                    Ok(Some(Err(_)) | None) => {
                        tokio::time::sleep_until(deadline).await;
                        return;
                    }
                }
            }
        });
    }
}

impl Reader {
    /// A sending handle of the same socket.
    pub fn handle(&self) -> Handle {
        self.handle.clone()
    }

    /// The next stream bytes or (with `datagrams`) datagram; without,
    /// datagrams are dropped. Pings are answered by the library.
    /// Cancel-safe.
    pub async fn next(&mut self, datagrams: bool) -> Received {
        let Some(stream) = self.stream.as_mut() else {
            return Received::Gone(Gone::Lost("the socket ended".into()));
        };
        loop {
            let next = tokio::time::timeout(self.idle_timeout, stream.next()).await;
            let message = match next {
                Err(_) => {
                    return Received::Gone(Gone::Lost(format!(
                        "nothing received for {:?}",
                        self.idle_timeout
                    )))
                }
                Ok(None) => return Received::Gone(Gone::Lost("the socket ended".into())),
                Ok(Some(Err(e))) => return read_error(e),
                Ok(Some(Ok(message))) => message,
            };
            match message {
                Message::Binary(bytes) => match web::decode_from_client(&bytes) {
                    Ok(WebMessage::Stream(_)) => {
                        return Received::Stream(Bytes::from(bytes).slice(1..))
                    }
                    Ok(WebMessage::Datagram(_)) if datagrams => {
                        return Received::Datagram(Bytes::from(bytes).slice(1..))
                    }
                    Ok(WebMessage::Datagram(_)) => continue,
                    // Only the server sends them: decode_from_client says so.
                    Ok(WebMessage::Level(_) | WebMessage::LevelEnd) => continue,
                    Err(e) => return Received::Malformed(e),
                },
                Message::Text(_) => return Received::Malformed(web::WebError::Text),
                Message::Ping(_) | Message::Pong(_) => continue,
                Message::Close(frame) => {
                    let why = frame.map_or_else(
                        || "the client closed the socket".to_owned(),
                        |f| format!("the client closed the socket ({}: {})", f.code, f.reason),
                    );
                    return Received::Gone(Gone::Closed(why));
                }
            }
        }
    }
}

/// A read error: a message over the limit breaks the socket (the library
/// stops reading it); a closed socket is a leave; anything else a loss.
fn read_error(e: axum::Error) -> Received {
    use tokio_tungstenite::tungstenite::error::{CapacityError, Error};
    let text = e.to_string();
    match e.into_inner().downcast::<Error>() {
        Ok(e) => match *e {
            Error::Capacity(CapacityError::MessageTooLong { size, max_size }) => Received::Broken(
                format!("a WebSocket message of {size} bytes, over the limit of {max_size}"),
            ),
            Error::Capacity(e) => Received::Broken(format!("WebSocket: {e}")),
            Error::ConnectionClosed | Error::AlreadyClosed => {
                Received::Gone(Gone::Closed("the socket closed".into()))
            }
            e => Received::Gone(Gone::Lost(e.to_string())),
        },
        Err(_) => Received::Gone(Gone::Lost(text)),
    }
}
