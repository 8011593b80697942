//! One client connection: handshake, then the control stream and input
//! datagrams until either side ends it. The same code serves every
//! transport ([`crate::link`]: native QUIC, WebTransport, WebSocket).
//!
//! The client opens one bidirectional stream and sends a `Hello` (or
//! `HelloRoom`); the server answers `Welcome` after joining a room, or
//! `Reject` and closes. Afterwards:
//!
//! * control messages (chat, ping, leave) arrive on the stream as
//!   length-prefixed frames ([`FrameDecoder`], at most
//!   [`CLIENT_MAX_FRAME`] bytes each);
//! * inputs arrive as datagrams ([`InputPacket`]) and go to the client's
//!   [`PlayerInbox`], which the room drains one tick at a time;
//! * everything the server sends on the stream goes through one writer
//!   task fed by a bounded queue ([`Outbound`]): the room's chat relays,
//!   roster (queued by the room when the client joins, so written right
//!   after the `Welcome`, which is written before the writer starts) and
//!   joins and departures, oversized snapshots, pongs, notices.
//!
//! Robustness: each client has token buckets for datagrams and control
//! messages (over the limit: dropped and counted), a malformed message is
//! dropped and counted, and a client that keeps doing either (its strike
//! bucket runs dry) is disconnected with a reason: a `Notice{Kick}`, then
//! the close code. A broken control stream (bad length prefix) closes at
//! once with [`CloseCode::ProtocolViolation`]. Nothing here panics on
//! input or buffers more than the bounded queues and windows.

use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use ledge_shared::protocol::{
    check_version, write_frame, ClientControl, CloseCode, FrameDecoder, InputPacket, Message,
    NoticeKind, PlayerId, ProtocolError, RejectReason, ServerControl, SessionToken, Welcome,
    PROTOCOL_VERSION,
};
use tokio::sync::{mpsc, watch};
use tokio::task::JoinHandle;
use tracing::{debug, info, warn, Instrument};

use crate::admission::{Refusal, Ticket};
use crate::config::Limits;
use crate::link::{Acceptor, ControlSend, Gone, Incoming, Link, Received, Receiver, Transport};
use crate::metrics::{Channel, ClientBytes, DropReason, KickLabel, KickReason, Metrics};
use crate::ratelimit::TokenBucket;
use crate::room::{ClientLink, JoinError, Outbound, RoomHandle};
use crate::room_logic::{self, PlayerInbox};
use crate::shared::Shared;
use crate::shutdown::stopped;

/// Largest control frame a client may send: every valid client message is
/// far smaller (a chat line is at most 256 bytes).
pub const CLIENT_MAX_FRAME: usize = 1024;

/// Level downloads one connection may start (resumes included); a client
/// asking for more is disconnected, so nobody can make the server send its
/// level over and over.
pub const MAX_LEVEL_DOWNLOADS: u32 = 4;

/// Ticks an acknowledged snapshot may be ahead of the room's published
/// tick (the room publishes its tick just after sending): more is forged.
const ACK_SLACK: u64 = 64;

/// Bytes of the level written to its stream at a time (and counted).
const LEVEL_CHUNK: usize = 16 * 1024;

/// Frames queued for one client's control stream; more are dropped.
pub const CONTROL_QUEUE: usize = 64;

/// How long a rejected client gets to receive the `Reject` (or a lister
/// its room list) before the close.
const REJECT_LINGER: Duration = Duration::from_secs(1);
/// How long a departing client gets to receive what was queued for it.
const LEAVE_LINGER: Duration = Duration::from_millis(500);
/// How long a kicked client gets to receive its `Notice{Kick}`.
const KICK_LINGER: Duration = Duration::from_millis(250);
/// How long each client gets to receive `Notice{Shutdown}`.
pub const SHUTDOWN_LINGER: Duration = Duration::from_secs(1);

/// Counts an open connection (the `connections` gauges) while it lives.
struct OpenGuard<'a>(&'a Shared, Transport);

impl Drop for OpenGuard<'_> {
    fn drop(&mut self) {
        self.0.metrics.closed_connection(self.1);
    }
}

/// Serves one admitted connection to its end; `ticket` counts it for
/// admission. It has [`AdmissionConfig::hello_timeout`] from now to finish
/// its transport's handshake and send its hello, and is closed at once if
/// evicted from the pending pool meanwhile. Errors are logged, not
/// returned.
///
/// [`AdmissionConfig::hello_timeout`]: crate::admission::AdmissionConfig::hello_timeout
pub async fn serve(incoming: Incoming, mut ticket: Ticket, shared: Arc<Shared>) {
    let transport = incoming.transport();
    let _open = OpenGuard(&shared, transport);
    shared.metrics.opened_connection(transport);
    let remote = incoming.remote_address();
    let span = tracing::info_span!("conn", %remote, transport = transport.as_str());
    let deadline = tokio::time::Instant::now() + shared.admission.config().hello_timeout;
    async {
        let handshake = tokio::time::timeout_at(deadline, incoming.connect());
        let (link, acceptor) = tokio::select! {
            connection = handshake => match connection {
                Ok(Ok(connection)) => connection,
                Ok(Err(e)) => {
                    debug!("handshake failed: {e}");
                    return;
                }
                Err(_) => {
                    shared.metrics.refused_on(transport, Refusal::HelloTimeout);
                    debug!("handshake not finished in time");
                    return;
                }
            },
            () = ticket.evicted() => {
                shared.metrics.evicted_on(transport);
                debug!("evicted from the pending pool during the handshake");
                return;
            }
        };
        ticket.handshaken(Instant::now());
        debug!("connected");
        match session(&link, acceptor, &shared, &mut ticket, deadline).await {
            Ok(()) => link.close(CloseCode::Normal, "bye"),
            Err(End::Closed(e)) => debug!("connection lost: {e}"),
            Err(End::Close(code, reason)) => {
                if code == CloseCode::ProtocolViolation {
                    warn!("closing: {reason}");
                } else {
                    info!("closing: {reason}");
                }
                link.close(code, &reason);
            }
        }
    }
    .instrument(span)
    .await
}

/// The end of a connection evicted from the pending pool.
fn evicted() -> End {
    End::Close(
        CloseCode::Timeout,
        "too many connections are waiting to join: the oldest of the address with the most \
         was closed; connect again"
            .into(),
    )
}

/// How a session ended abnormally.
#[derive(Debug)]
enum End {
    /// The connection is already gone (peer closed, timed out, endpoint shut).
    Closed(String),
    /// We close the connection with this code and reason.
    Close(CloseCode, String),
}

/// Ends the player's membership however the session ends: a lost
/// connection keeps the player for a resume ([`Sessions::lose`]), any
/// other end removes it from its room; its metric series go either way.
///
/// [`Sessions::lose`]: crate::sessions::Sessions::lose
struct Membership<'a> {
    room: RoomHandle,
    player_id: PlayerId,
    generation: u32,
    token: SessionToken,
    shared: &'a Shared,
    /// The connection was lost (rather than left, kicked or shut down).
    lost: bool,
}

impl Drop for Membership<'_> {
    fn drop(&mut self) {
        let sessions = &self.shared.sessions;
        if self.lost && !*self.shared.shutdown.borrow() {
            self.room.detach(self.player_id, self.generation);
            sessions.lose(&self.token, self.generation, Instant::now());
        } else {
            self.room.leave(self.player_id, self.generation);
            sessions.end(&self.token, self.generation);
        }
        self.shared.metrics.forget_client(self.player_id.0);
    }
}

/// Serves a connected client: its hello, then a listing or a seat in a
/// room, then its messages until the session ends.
async fn session(
    connection: &Link,
    acceptor: Acceptor,
    shared: &Shared,
    ticket: &mut Ticket,
    deadline: tokio::time::Instant,
) -> Result<(), End> {
    let mut shutdown = shared.shutdown.clone();
    let transport = connection.transport();
    let (mut send, mut recv, hello, mut decoder) =
        await_hello(transport, acceptor, shared, ticket, deadline, &mut shutdown).await?;
    let first = match hello {
        Ok(first) => first,
        Err(reason) => return Err(rejected(&mut send, reason).await),
    };
    if let ClientControl::ListRooms { version } = first {
        return list_rooms(&mut send, shared, version).await;
    }
    let (version, _, _) = first.as_hello().expect("handshake returns a hello");
    if let Some(reason) = refusal(version, &shutdown) {
        return Err(rejected(&mut send, reason).await);
    }

    let (control, queue) = mpsc::channel(CONTROL_QUEUE);
    let (room, mut joined, token) =
        take_seat(connection, shared, &first, &control, &mut send).await?;
    let player_id = joined.welcome.player_id;
    let bytes = shared.metrics.client(player_id.0);
    shared
        .sessions
        .start(token, room.clone(), player_id, joined.generation);
    joined.welcome.session_token = token;
    let mut membership = Membership {
        room,
        player_id,
        generation: joined.generation,
        token,
        shared,
        lost: false,
    };
    send_welcome(&mut send, joined.welcome, &shared.metrics, &bytes).await?;

    let writer = tokio::spawn(write_control(
        send,
        queue,
        connection.clone(),
        shared.metrics.clone(),
        bytes.clone(),
    ));
    let mut client = Client {
        shared,
        connection: connection.clone(),
        downloads: 0,
        download: None,
        room: &membership.room,
        player_id,
        inbox: joined.inbox,
        bytes,
        control,
        decoder: &mut decoder,
        buckets: Buckets::new(&shared.limits, Instant::now()),
    };
    let ending = client.run(&mut recv, &mut shutdown).await;
    if let Some(download) = client.download.take() {
        download.abort();
    }
    // A spectator has nothing to keep: lost, it leaves.
    membership.lost = matches!(ending, Ending::Lost(_)) && !first.is_spectate();
    say_goodbye(&ending, &client.control, writer).await;
    ending.into_result(&shared.metrics)
}

/// Waits for the client's first message, within the hello deadline unless
/// it is evicted from the pending pool or the server stops first; then
/// takes the connection out of the pending pool.
async fn await_hello(
    transport: Transport,
    acceptor: Acceptor,
    shared: &Shared,
    ticket: &mut Ticket,
    deadline: tokio::time::Instant,
    shutdown: &mut watch::Receiver<bool>,
) -> Result<(ControlSend, Receiver, Hello, FrameDecoder), End> {
    let received = tokio::select! {
        handshake = tokio::time::timeout_at(deadline, handshake(acceptor, shared)) => {
            handshake.map_err(|_| {
                shared.metrics.refused_on(transport, Refusal::HelloTimeout);
                End::Close(CloseCode::Timeout, "no hello in time".into())
            })??
        }
        () = ticket.evicted() => {
            shared.metrics.evicted_on(transport);
            return Err(evicted());
        }
        () = stopped(shutdown) => {
            return Err(End::Close(CloseCode::ServerShutdown, "server shutting down".into()))
        }
    };
    if !ticket.join() {
        shared.metrics.evicted_on(transport);
        return Err(evicted());
    }
    Ok(received)
}

/// Why a valid hello is turned away: another protocol version, or a server
/// shutting down.
fn refusal(version: u32, shutdown: &watch::Receiver<bool>) -> Option<RejectReason> {
    if check_version(version).is_err() {
        Some(RejectReason::ProtocolVersion {
            server: PROTOCOL_VERSION,
            client: version,
        })
    } else if *shutdown.borrow() {
        Some(RejectReason::ShuttingDown)
    } else {
        None
    }
}

/// A room, its seat and the session token for this connection.
type Seat = (RoomHandle, room_logic::Joined, SessionToken);

/// Seats the client: its player back if it resumes, else a new player in
/// the room it asked for (or the least full one); rejects it if there is
/// no place.
async fn take_seat(
    connection: &Link,
    shared: &Shared,
    hello: &ClientControl,
    control: &mpsc::Sender<Outbound>,
    send: &mut ControlSend,
) -> Result<Seat, End> {
    let (_, name, wanted_room) = hello.as_hello().expect("handshake returns a hello");
    let link = |player_id: PlayerId| ClientLink {
        link: connection.clone(),
        control: control.clone(),
        bytes: shared.metrics.client(player_id.0),
    };
    if hello.is_spectate() {
        return join_new(shared, (wanted_room, true), name, &link, send).await;
    }
    match resume(shared, hello.resume_token(), &link).await {
        Some(resumed) => {
            shared.metrics.sessions_resumed.inc();
            Ok(resumed)
        }
        None => join_new(shared, (wanted_room, false), name, &link, send).await,
    }
}

/// The player a resume token names, back in its room over this
/// connection; `None` for no token, an unknown or expired one, or a player
/// gone meanwhile (the client then joins as new).
async fn resume(
    shared: &Shared,
    token: Option<SessionToken>,
    link: impl Fn(PlayerId) -> ClientLink,
) -> Option<Seat> {
    let token = token?;
    let parked = shared.sessions.find(&token, Instant::now())?;
    parked
        .room
        .rejoin(parked.player_id, link(parked.player_id))
        .await
        .map(|joined| (parked.room, joined, token))
}

/// Joins as a new player or spectator (a new id and session token) the
/// room wanted (`None`: any), or rejects the client and forgets the id's
/// metric series.
async fn join_new(
    shared: &Shared,
    (wanted, spectate): (Option<&str>, bool),
    name: &str,
    link: impl Fn(PlayerId) -> ClientLink,
    send: &mut ControlSend,
) -> Result<Seat, End> {
    let player_id = PlayerId(shared.next_player.fetch_add(1, Ordering::Relaxed));
    match join(shared, (wanted, spectate), player_id, name, link(player_id)).await {
        Ok((room, joined)) => Ok((room, joined, shared.sessions.new_token())),
        Err(reason) => {
            shared.metrics.forget_client(player_id.0);
            Err(rejected(send, reason).await)
        }
    }
}

/// Writes the `Welcome` on the control stream directly, before the writer
/// task starts, so it comes before anything the room queued (the roster).
async fn send_welcome(
    send: &mut ControlSend,
    welcome: Welcome,
    metrics: &Metrics,
    bytes: &ClientBytes,
) -> Result<(), End> {
    let mut frame = Vec::new();
    write_frame(&ServerControl::Welcome(welcome), &mut frame)
        .map_err(|e| End::Close(CloseCode::ProtocolViolation, format!("welcome: {e}")))?;
    send.write_all(&frame)
        .await
        .map_err(|e| End::Closed(e.to_string()))?;
    metrics.sent(bytes, Channel::Stream, frame.len());
    Ok(())
}

/// Says goodbye on the stream (a notice when shutting down or kicking),
/// then lets the writer flush it, for at most the ending's linger: nothing
/// for a lost connection.
async fn say_goodbye(ending: &Ending, control: &mpsc::Sender<Outbound>, writer: JoinHandle<()>) {
    let (notice, linger) = match ending {
        Ending::Left => (None, LEAVE_LINGER),
        Ending::Shutdown => (Some(NoticeKind::Shutdown), SHUTDOWN_LINGER),
        Ending::Kick { notice, .. } => (
            Some(NoticeKind::Kick {
                reason: notice.to_string(),
            }),
            KICK_LINGER,
        ),
        Ending::Lost(_) => (None, Duration::ZERO),
    };
    if linger.is_zero() {
        return;
    }
    let goodbye = async {
        if let Some(kind) = notice {
            let mut frame = Vec::new();
            if write_frame(&ServerControl::Notice { kind }, &mut frame).is_ok() {
                let _ = control.send(Outbound::Frame(frame)).await;
            }
        }
        let _ = control.send(Outbound::Finish).await;
        let _ = writer.await;
    };
    let _ = tokio::time::timeout(linger, goodbye).await;
}

/// Joins the wanted room (opening it if need be), or the least full one
/// with a free place.
async fn join(
    shared: &Shared,
    (wanted, spectate): (Option<&str>, bool),
    player_id: PlayerId,
    name: &str,
    link: ClientLink,
) -> Result<(RoomHandle, room_logic::Joined), RejectReason> {
    let mut rooms = shared.rooms.for_join(wanted, Instant::now())?;
    if spectate {
        // A spectator watches the room with the most players.
        rooms.reverse();
    }
    for room in rooms {
        if wanted.is_none() && !spectate && !room.has_room() {
            continue;
        }
        match room
            .join(player_id, name.to_owned(), link.clone(), spectate)
            .await
        {
            Ok(joined) => return Ok((room, joined)),
            Err(JoinError::Rejected(RejectReason::RoomFull)) if wanted.is_none() => continue,
            Err(JoinError::Rejected(reason)) => return Err(reason),
            Err(JoinError::Closed) => return Err(RejectReason::ShuttingDown),
        }
    }
    Err(RejectReason::RoomFull)
}

/// Answers a `ListRooms` (or rejects another protocol version) and ends
/// the session normally.
async fn list_rooms(send: &mut ControlSend, shared: &Shared, version: u32) -> Result<(), End> {
    if check_version(version).is_err() {
        let reason = RejectReason::ProtocolVersion {
            server: PROTOCOL_VERSION,
            client: version,
        };
        return Err(rejected(send, reason).await);
    }
    let rooms = ServerControl::Rooms {
        rooms: shared.rooms.list(),
    };
    say_last(send, &rooms).await;
    Ok(())
}

/// The client's first message (a hello or `ListRooms`), or the polite
/// rejection of a hello that failed validation.
type Hello = Result<ClientControl, RejectReason>;

/// Accepts the control stream and reads the first message, which must be a
/// hello or `ListRooms`. A hello whose name is invalid is answered with
/// [`RejectReason::InvalidName`]; anything else malformed closes.
async fn handshake(
    acceptor: Acceptor,
    shared: &Shared,
) -> Result<(ControlSend, Receiver, Hello, FrameDecoder), End> {
    let (send, mut recv) = acceptor
        .accept_control()
        .await
        .map_err(|e| End::Closed(e.to_string()))?;
    let mut decoder = FrameDecoder::new(CLIENT_MAX_FRAME);
    let payload = loop {
        if let Some(payload) = decoder.pop() {
            break payload;
        }
        let bytes = match recv.next_stream().await {
            Received::Stream(bytes) => bytes,
            Received::StreamEnd => {
                return Err(End::Close(
                    CloseCode::ProtocolViolation,
                    "stream ended before hello".into(),
                ))
            }
            Received::Gone(e) => return Err(End::Closed(e.to_string())),
            // Not asked for; never returned before the hello.
            Received::Datagram(_) => continue,
            Received::Malformed(e) => {
                shared.metrics.malformed(Channel::WebSocket);
                return Err(End::Close(
                    CloseCode::ProtocolViolation,
                    format!("reading hello: {e}"),
                ));
            }
            Received::Broken(e) => {
                shared.metrics.malformed(Channel::WebSocket);
                return Err(End::Close(CloseCode::ProtocolViolation, e));
            }
        };
        shared
            .metrics
            .bytes_in
            .get_or_create(&crate::metrics::ChannelLabel {
                channel: Channel::Stream,
            })
            .inc_by(bytes.len() as u64);
        if let Err(e) = decoder.push(&bytes) {
            shared.metrics.malformed(Channel::Stream);
            return Err(End::Close(
                CloseCode::ProtocolViolation,
                format!("reading hello: {e}"),
            ));
        }
    };
    let hello = match ClientControl::decode(&payload) {
        Ok(m) if m.as_hello().is_some() || matches!(m, ClientControl::ListRooms { .. }) => Ok(m),
        Ok(_) => {
            return Err(End::Close(
                CloseCode::ProtocolViolation,
                "expected hello".into(),
            ))
        }
        Err(ProtocolError::InvalidString {
            field: "player name",
            ..
        }) => Err(RejectReason::InvalidName),
        Err(e) => {
            shared.metrics.malformed(Channel::Stream);
            return Err(End::Close(
                CloseCode::ProtocolViolation,
                format!("reading hello: {e}"),
            ));
        }
    };
    Ok((send, recv, hello, decoder))
}

/// How a joined session ends.
#[derive(Debug)]
enum Ending {
    /// The client left (`Leave`, or it finished its stream).
    Left,
    /// The server is shutting down.
    Shutdown,
    /// The server disconnects the client.
    Kick {
        code: CloseCode,
        reason: KickReason,
        /// Told to the client in the notice.
        notice: &'static str,
        /// Logged and sent as the close reason.
        detail: String,
    },
    /// The connection is gone.
    Lost(String),
}

impl Ending {
    /// The session's result: `Ok` for a leave, else how the connection
    /// ends; a kick is counted.
    fn into_result(self, metrics: &Metrics) -> Result<(), End> {
        match self {
            Ending::Left => Ok(()),
            Ending::Shutdown => Err(End::Close(
                CloseCode::ServerShutdown,
                "server shutting down".into(),
            )),
            Ending::Kick {
                code,
                reason,
                detail,
                ..
            } => {
                metrics.kicks.get_or_create(&KickLabel { reason }).inc();
                Err(End::Close(code, detail))
            }
            Ending::Lost(e) => Err(End::Closed(e)),
        }
    }

    /// The connection ended under the session: the client closing it on
    /// purpose (it quit) is a leave; a timeout or reset is a loss, and the
    /// player is kept for a resume.
    fn gone(e: Gone) -> Ending {
        match e {
            Gone::Closed(_) => Ending::Left,
            Gone::Lost(e) => Ending::Lost(e),
        }
    }

    fn malformed(detail: String) -> Ending {
        Ending::Kick {
            code: CloseCode::ProtocolViolation,
            reason: KickReason::Malformed,
            notice: "too many malformed messages",
            detail,
        }
    }

    fn flooding(detail: String) -> Ending {
        Ending::Kick {
            code: CloseCode::Kicked,
            reason: KickReason::Flooding,
            notice: "sending too fast",
            detail,
        }
    }
}

/// A client's token buckets.
struct Buckets {
    datagrams: TokenBucket,
    control: TokenBucket,
    malformed: TokenBucket,
    flood: TokenBucket,
}

impl Buckets {
    fn new(l: &Limits, now: Instant) -> Buckets {
        Buckets {
            datagrams: TokenBucket::new(l.datagram_burst, l.datagrams_per_second, now),
            control: TokenBucket::new(l.control_burst, l.control_per_second, now),
            malformed: TokenBucket::new(l.malformed_burst, l.malformed_per_second, now),
            flood: TokenBucket::new(l.flood_burst, l.flood_per_second, now),
        }
    }
}

/// A joined client's receive side.
struct Client<'a> {
    shared: &'a Shared,
    connection: Link,
    /// Level downloads started.
    downloads: u32,
    /// The level download running, if any.
    download: Option<tokio::task::JoinHandle<()>>,
    room: &'a RoomHandle,
    player_id: PlayerId,
    inbox: Arc<Mutex<PlayerInbox>>,
    bytes: ClientBytes,
    control: mpsc::Sender<Outbound>,
    decoder: &'a mut FrameDecoder,
    buckets: Buckets,
}

impl Client<'_> {
    async fn run(&mut self, recv: &mut Receiver, shutdown: &mut watch::Receiver<bool>) -> Ending {
        // Frames that arrived with the hello.
        if let Err(ending) = self.drain_frames() {
            return ending;
        }
        loop {
            let step = tokio::select! {
                () = stopped(shutdown) => Err(Ending::Shutdown),
                received = recv.next() => match received {
                    Received::Stream(bytes) => {
                        let n = bytes.len();
                        self.shared.metrics.received(&self.bytes, Channel::Stream, n);
                        match self.decoder.push(&bytes) {
                            Ok(()) => self.drain_frames(),
                            Err(e) => {
                                self.shared.metrics.malformed(Channel::Stream);
                                Err(Ending::malformed(format!("control stream: {e}")))
                            }
                        }
                    }
                    // The client finished its side: it left.
                    Received::StreamEnd => Err(Ending::Left),
                    Received::Datagram(datagram) => self.datagram(&datagram),
                    Received::Malformed(e) => {
                        self.shared.metrics.malformed(Channel::WebSocket);
                        debug!("malformed WebSocket message: {e}");
                        self.strike_malformed(Instant::now(), "WebSocket message", &e.to_string())
                    }
                    Received::Broken(e) => {
                        self.shared.metrics.malformed(Channel::WebSocket);
                        Err(Ending::malformed(e))
                    }
                    Received::Gone(e) => Err(Ending::gone(e)),
                },
            };
            if let Err(ending) = step {
                return ending;
            }
        }
    }

    /// Handles every complete frame buffered.
    fn drain_frames(&mut self) -> Result<(), Ending> {
        while let Some(payload) = self.decoder.pop() {
            let now = Instant::now();
            if !self.buckets.control.try_take(now) {
                self.shared
                    .metrics
                    .count_drop(DropReason::ControlRateLimited);
                self.strike_flood(now, "control messages")?;
                continue;
            }
            let message = match ClientControl::decode(&payload) {
                Ok(m) => m,
                Err(e) => {
                    self.shared.metrics.malformed(Channel::Stream);
                    debug!("malformed control message: {e}");
                    self.strike_malformed(now, "control message", &e.to_string())?;
                    continue;
                }
            };
            match message {
                ClientControl::Hello { .. }
                | ClientControl::HelloRoom { .. }
                | ClientControl::Resume { .. }
                | ClientControl::Spectate { .. }
                | ClientControl::ListRooms { .. } => {
                    return Err(Ending::malformed("second hello".into()));
                }
                ClientControl::Chat { text } => self.room.chat(self.player_id, text),
                ClientControl::Ping { nonce } => {
                    let mut frame = Vec::new();
                    if write_frame(&ServerControl::Pong { nonce }, &mut frame).is_ok() {
                        let sent = self.control.try_send(Outbound::Frame(frame));
                        self.shared.metrics.count_queue_error(sent);
                    }
                }
                ClientControl::Leave => return Err(Ending::Left),
                ClientControl::GetLevel { offset, sha256 } => self.send_level(offset, &sha256)?,
                ClientControl::Vote { level } => self.room.vote(self.player_id, level),
            }
        }
        Ok(())
    }

    /// Starts sending the level bundle from `offset` on a stream of its own
    /// (so the control stream is never stuck behind it); one download at a
    /// time, at most [`MAX_LEVEL_DOWNLOADS`] per connection.
    fn send_level(&mut self, offset: u64, sha256: &[u8; 32]) -> Result<(), Ending> {
        let Some(level) = self.shared.levels.by_sha256(sha256) else {
            return Err(Ending::malformed(
                "asked for a level this server does not play".into(),
            ));
        };
        let bundle = level.bundle.clone();
        let Some(rest) = usize::try_from(offset)
            .ok()
            .and_then(|at| bundle.get(at..).map(<[u8]>::len))
        else {
            return Err(Ending::malformed(format!(
                "level asked for from byte {offset} of {}",
                bundle.len()
            )));
        };
        if self.download.as_ref().is_some_and(|d| !d.is_finished()) {
            self.shared
                .metrics
                .count_drop(DropReason::ControlRateLimited);
            return Ok(());
        }
        self.downloads += 1;
        if self.downloads > MAX_LEVEL_DOWNLOADS {
            return Err(Ending::flooding(format!(
                "asked for the level more than {MAX_LEVEL_DOWNLOADS} times"
            )));
        }
        let metrics = self.shared.metrics.clone();
        let connection = self.connection.clone();
        metrics.level_downloads.inc();
        debug!(offset, rest, "sending the level");
        self.download = Some(tokio::spawn(async move {
            let at = bundle.len() - rest;
            let Some(mut stream) = connection.open_level().await else {
                return;
            };
            for chunk in bundle[at..].chunks(LEVEL_CHUNK) {
                if !stream.write_all(chunk).await {
                    return;
                }
                metrics.level_download_bytes.inc_by(chunk.len() as u64);
            }
            if stream.finish().await {
                metrics.level_downloads_completed.inc();
            }
        }));
        Ok(())
    }

    fn datagram(&mut self, datagram: &[u8]) -> Result<(), Ending> {
        let now = Instant::now();
        self.shared
            .metrics
            .received(&self.bytes, Channel::Datagram, datagram.len());
        if !self.buckets.datagrams.try_take(now) {
            self.shared
                .metrics
                .count_drop(DropReason::DatagramRateLimited);
            return self.strike_flood(now, "datagrams");
        }
        match InputPacket::decode(datagram) {
            Ok(mut packet) => {
                // An acknowledgement of a snapshot the room cannot have sent
                // yet (e.g. u64::MAX) is a lie: believed, it would stick and
                // cost the client every delta. Its inputs still count.
                let sent_up_to = self.room.status().tick + ACK_SLACK;
                let forged = packet.ack_snapshot.is_some_and(|ack| ack > sent_up_to);
                if forged {
                    packet.ack_snapshot = None;
                }
                let r = room_logic::lock(&self.inbox).receive(&packet);
                let m = &self.shared.metrics;
                m.count_drops(DropReason::InputLate, u64::from(r.late));
                m.count_drops(DropReason::InputTooEarly, u64::from(r.too_early));
                if forged {
                    m.malformed(Channel::Datagram);
                    let e = ProtocolError::Malformed {
                        what: "input datagram",
                        detail: "acknowledges a snapshot never sent".into(),
                    };
                    return self.strike_malformed(now, "input datagram", &e.to_string());
                }
                Ok(())
            }
            Err(e) => {
                self.shared.metrics.malformed(Channel::Datagram);
                self.strike_malformed(now, "input datagram", &e.to_string())
            }
        }
    }

    fn strike_malformed(&mut self, now: Instant, what: &str, error: &str) -> Result<(), Ending> {
        if self.buckets.malformed.try_take(now) {
            Ok(())
        } else {
            Err(Ending::malformed(format!(
                "too many malformed messages (last: {what}: {error})"
            )))
        }
    }

    fn strike_flood(&mut self, now: Instant, what: &str) -> Result<(), Ending> {
        if self.buckets.flood.try_take(now) {
            Ok(())
        } else {
            Err(Ending::flooding(format!("flooding the server with {what}")))
        }
    }
}

/// Writes queued frames to the control stream in order; on
/// [`Outbound::Finish`] (or when every sender is gone) finishes the stream
/// and waits until the client has everything.
async fn write_control(
    mut send: ControlSend,
    mut queue: mpsc::Receiver<Outbound>,
    connection: Link,
    metrics: Arc<Metrics>,
    bytes: ClientBytes,
) {
    let mut close = None;
    while let Some(out) = queue.recv().await {
        match out {
            Outbound::Frame(frame) => {
                if send.write_all(&frame).await.is_err() {
                    return;
                }
                metrics.sent(&bytes, Channel::Stream, frame.len());
            }
            Outbound::Finish => break,
            Outbound::Close(code, reason) => {
                close = Some((code, reason));
                break;
            }
        }
    }
    if send.finish().await {
        // Bounded when closing: the client may not read at all.
        let stopped = send.stopped();
        if close.is_some() {
            let _ = tokio::time::timeout(KICK_LINGER, stopped).await;
        } else {
            let _ = stopped.await;
        }
    }
    if let Some((code, reason)) = close {
        connection.close(code, &reason);
    }
}

/// Sends a `Reject` (waiting briefly until the client has it) and gives
/// the session's end for it.
async fn rejected(send: &mut ControlSend, reason: RejectReason) -> End {
    reject(send, &reason).await;
    End::Close(CloseCode::Rejected, reason.to_string())
}

/// Sends a `Reject` and waits (briefly) until the client has it.
async fn reject(send: &mut ControlSend, reason: &RejectReason) {
    let reject = ServerControl::Reject {
        reason: reason.clone(),
    };
    say_last(send, &reject).await;
}

/// Sends the session's last message and waits (briefly) until the client
/// has it, since closing the connection discards unacknowledged stream
/// data.
async fn say_last(send: &mut ControlSend, message: &ServerControl) {
    let mut frame = Vec::new();
    if write_frame(message, &mut frame).is_err()
        || send.write_all(&frame).await.is_err()
        || !send.finish().await
    {
        return;
    }
    let _ = tokio::time::timeout(REJECT_LINGER, send.stopped()).await;
}
