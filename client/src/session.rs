//! A joined session: the handshake, then inputs out and snapshots and
//! control messages in.
//!
//! [`Session`] is driven by its caller (no task of its own): call
//! [`Session::send_input`] once per tick, and [`Session::recv`] in a loop
//! (or in a `select!`: it is cancel-safe) to get [`SessionEvent`]s:
//! decoded snapshots, chat lines, notices, pongs, players joining and
//! leaving. Snapshots are decoded against the session's own
//! [`SnapshotHistory`] and every input packet acknowledges the newest one,
//! so the server's next deltas are against it. The room's roster (who is
//! in it, by name) is kept in [`Session::players`], at most
//! [`MAX_ROSTER`] names.

use std::collections::{BTreeMap, VecDeque};
use std::net::SocketAddr;
use std::time::{Duration, Instant};

use ledge_shared::input::Buttons;
use ledge_shared::protocol::{
    write_frame, ClientControl, CloseCode, Fingerprint, FrameDecoder, InputPacket, Message,
    NoticeKind, PlayerId, RoomInfo, RosterEntry, ServerControl, SessionToken, Snapshot,
    SnapshotHistory, StateSnapshot, Welcome, MAX_FRAME, MAX_INPUT_HISTORY, MAX_ROSTER,
    PROTOCOL_VERSION,
};

use crate::error::ClientError;
use crate::transport::{dial, Dialed};

/// How long the server has to answer a hello or a ping.
pub const REPLY_TIMEOUT: Duration = Duration::from_secs(5);

/// How long [`Session::close`] waits for the server to close after `Leave`.
const CLOSE_LINGER: Duration = Duration::from_secs(1);

/// Snapshots kept to decode deltas against: more than the server keeps as
/// baselines (64), so any delta it sends can be decoded.
pub const SNAPSHOT_HISTORY: usize = 128;

/// Pings remembered for round-trip times.
const PINGS_REMEMBERED: usize = 8;

/// How to join.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct JoinOptions {
    /// Our player name (1..=32 bytes, no control characters).
    pub player_name: String,
    /// The room to join; `None`: the server picks the least full one.
    pub room: Option<String>,
    /// Resume the session this token names (a lost connection's player:
    /// same id, position, coins); an unknown or expired one joins as new.
    pub resume: Option<SessionToken>,
}

impl JoinOptions {
    /// Joins any room as `player_name`.
    pub fn new(player_name: &str) -> JoinOptions {
        JoinOptions {
            player_name: player_name.to_owned(),
            room: None,
            resume: None,
        }
    }

    /// The hello these options send.
    pub fn hello(&self) -> ClientControl {
        if let Some(token) = self.resume {
            return ClientControl::Resume {
                version: PROTOCOL_VERSION,
                name: self.player_name.clone(),
                room: self.room.clone(),
                token,
            };
        }
        match &self.room {
            None => ClientControl::Hello {
                version: PROTOCOL_VERSION,
                name: self.player_name.clone(),
            },
            Some(room) => ClientControl::HelloRoom {
                version: PROTOCOL_VERSION,
                name: self.player_name.clone(),
                room: room.clone(),
            },
        }
    }
}

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
    match result {
        Ok((send, recv, welcome)) => Ok(Session {
            endpoint,
            connection,
            send,
            recv,
            decoder,
            buf: vec![0u8; 8192],
            stream_ended: false,
            inputs: InputHistory::default(),
            redundancy: usize::from(welcome.timing.input_redundancy).clamp(1, MAX_INPUT_HISTORY),
            welcome,
            history: SnapshotHistory::new(SNAPSHOT_HISTORY),
            pending: VecDeque::new(),
            pings: VecDeque::new(),
            players: BTreeMap::new(),
            next_nonce: 0,
            stats: SessionStats::default(),
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

/// A decoded snapshot and this client's bookkeeping from the server.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SnapshotUpdate {
    /// The authoritative state at `state.tick` (every replicated entity).
    pub state: StateSnapshot,
    /// The snapshot it was a delta against (`None`: it came in full).
    pub baseline_tick: Option<u64>,
    /// Newest tick of our input the server had applied (`None` before the
    /// first): inputs after it are not in `state` yet.
    pub last_input_tick: Option<u64>,
    /// How early (+) or late (-), in ticks, our inputs arrive at the server.
    pub input_timing: i16,
    /// Whether it came on the control stream (too big for a datagram).
    pub via_stream: bool,
    /// Encoded size in bytes.
    pub wire_bytes: usize,
    /// When it was received and decoded (for jitter and interpolation).
    pub received: Instant,
}

/// Something the server sent.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SessionEvent {
    /// A new authoritative state (never older than the previous one).
    Snapshot(SnapshotUpdate),
    /// A chat line from a player in our room (ours included).
    Chat {
        /// Who said it.
        from: PlayerId,
        /// The line.
        text: String,
    },
    /// A server announcement: shutdown, kick, information.
    Notice(NoticeKind),
    /// The answer to a ping.
    Pong {
        /// The ping's nonce.
        nonce: u64,
        /// Round-trip time, if the ping was sent by this session recently.
        rtt: Option<Duration>,
    },
    /// A player is in our room: from the roster sent after the welcome
    /// (once per player, us included) or because it joined later.
    PlayerJoined {
        /// Its id.
        id: PlayerId,
        /// Its name.
        name: String,
    },
    /// A player left our room.
    PlayerLeft {
        /// Its id.
        id: PlayerId,
        /// Its name, if we knew it.
        name: Option<String>,
    },
}

/// Counters of what the session received and sent.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SessionStats {
    /// Snapshots decoded and newer than the previous one.
    pub snapshots: u64,
    /// Of those, sent in full.
    pub full_snapshots: u64,
    /// Snapshots on the control stream.
    pub stream_snapshots: u64,
    /// Snapshots older than the newest decoded (reordered), ignored.
    pub stale_snapshots: u64,
    /// Deltas against a snapshot we no longer have, dropped.
    pub missing_baselines: u64,
    /// Datagrams or snapshots that failed to decode, dropped.
    pub malformed: u64,
    /// Roster entries ignored because [`MAX_ROSTER`] names were known.
    pub roster_overflow: u64,
    /// Input packets sent.
    pub inputs_sent: u64,
}

/// The last ticks of our inputs, contiguous, newest last.
#[derive(Debug, Clone, Default)]
struct InputHistory {
    ticks: VecDeque<(u64, Buttons)>,
}

impl InputHistory {
    /// Records `buttons` for `tick`. Ticks skipped since the newest repeat
    /// its buttons; a tick at or before the newest (the clock moved back)
    /// replaces it and forgets the ticks after.
    fn record(&mut self, tick: u64, buttons: Buttons) {
        match self.ticks.back().copied() {
            Some((newest, last)) if tick > newest && tick - newest <= MAX_INPUT_HISTORY as u64 => {
                for t in newest + 1..tick {
                    self.ticks.push_back((t, last));
                }
            }
            Some((newest, _)) if tick <= newest => {
                while self.ticks.back().is_some_and(|&(t, _)| t >= tick) {
                    self.ticks.pop_back();
                }
                if self.ticks.back().is_some_and(|&(t, _)| t + 1 != tick) {
                    self.ticks.clear();
                }
            }
            _ => self.ticks.clear(),
        }
        self.ticks.push_back((tick, buttons));
        while self.ticks.len() > MAX_INPUT_HISTORY {
            self.ticks.pop_front();
        }
    }

    /// A packet of the newest `n` ticks.
    fn packet(&self, n: usize, ack: Option<u64>) -> Option<InputPacket> {
        let &(newest, _) = self.ticks.back()?;
        let buttons: Vec<Buttons> = self.ticks.iter().rev().take(n).map(|&(_, b)| b).collect();
        Some(InputPacket::new(newest, &buttons, ack))
    }
}

/// A session with a server that welcomed us.
#[derive(Debug)]
pub struct Session {
    endpoint: quinn::Endpoint,
    connection: quinn::Connection,
    send: quinn::SendStream,
    recv: quinn::RecvStream,
    decoder: FrameDecoder,
    buf: Vec<u8>,
    stream_ended: bool,
    welcome: Welcome,
    inputs: InputHistory,
    redundancy: usize,
    history: SnapshotHistory,
    pending: VecDeque<SessionEvent>,
    pings: VecDeque<(u64, Instant)>,
    players: BTreeMap<PlayerId, String>,
    next_nonce: u64,
    stats: SessionStats,
}

impl Session {
    /// What the server said when we joined (player id, room, level, tick,
    /// timing).
    pub fn welcome(&self) -> &Welcome {
        &self.welcome
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
    /// at most [`MAX_ROSTER`] names.
    pub fn players(&self) -> &BTreeMap<PlayerId, String> {
        &self.players
    }

    /// The name of player `id`, if known.
    pub fn player_name(&self, id: PlayerId) -> Option<&str> {
        self.players.get(&id).map(String::as_str)
    }

    /// The newest decoded snapshot.
    pub fn latest_snapshot(&self) -> Option<&StateSnapshot> {
        self.history.latest()
    }

    /// The snapshots decoded so far (the newest [`SNAPSHOT_HISTORY`]).
    pub fn snapshots(&self) -> &SnapshotHistory {
        &self.history
    }

    /// The tick we acknowledge: the newest decoded snapshot's.
    pub fn ack(&self) -> Option<u64> {
        self.history.latest().map(|s| s.tick)
    }

    /// Counters of what was received and sent.
    pub fn stats(&self) -> SessionStats {
        self.stats
    }

    /// Records our buttons for `tick` and sends an input datagram carrying
    /// it and the ticks before it (as many as the server asked for in
    /// `Welcome`), plus the acknowledgement of the newest snapshot. Never
    /// blocks: quinn drops the oldest queued datagram when its small buffer
    /// is full.
    pub fn send_input(&mut self, tick: u64, buttons: Buttons) -> Result<(), ClientError> {
        self.inputs.record(tick, buttons);
        let packet = self
            .inputs
            .packet(self.redundancy, self.ack())
            .expect("just recorded");
        self.connection.send_datagram(packet.encode()?.into())?;
        self.stats.inputs_sent += 1;
        Ok(())
    }

    /// Sends a control message.
    pub async fn send_control(&mut self, message: &ClientControl) -> Result<(), ClientError> {
        let mut frame = Vec::new();
        write_frame(message, &mut frame)?;
        let written = self.send.write_all(&frame).await;
        written.map_err(|e| explain(&self.connection, ClientError::Stream(e.to_string())))
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

    /// Sends a ping and returns its nonce; the [`SessionEvent::Pong`]
    /// carries the round-trip time.
    pub async fn send_ping(&mut self) -> Result<u64, ClientError> {
        let nonce = self.next_nonce;
        self.next_nonce = self.next_nonce.wrapping_add(1);
        self.send_control(&ClientControl::Ping { nonce }).await?;
        if self.pings.len() == PINGS_REMEMBERED {
            self.pings.pop_front();
        }
        self.pings.push_back((nonce, Instant::now()));
        Ok(nonce)
    }

    /// Pings the server and waits for the answer; returns the round-trip
    /// time. Other events arriving meanwhile are kept for [`Session::recv`].
    pub async fn ping(&mut self) -> Result<Duration, ClientError> {
        let sent = Instant::now();
        let nonce = self.send_ping().await?;
        let mut kept: Vec<SessionEvent> = self.pending.drain(..).collect();
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
        for event in kept.into_iter().rev() {
            self.pending.push_front(event);
        }
        answer
    }

    /// The next event from the server. Cancel-safe: dropping the future
    /// loses nothing. Errors when the connection ends (the server's close
    /// code and reason in [`ClientError::ClosedByServer`]) or the control
    /// stream breaks.
    pub async fn recv(&mut self) -> Result<SessionEvent, ClientError> {
        loop {
            if let Some(event) = self.pending.pop_front() {
                return Ok(event);
            }
            if let Some(message) = self.decoder.pop_message::<ServerControl>() {
                let message = message.map_err(|e| explain(&self.connection, e.into()))?;
                self.control(message);
                continue;
            }
            tokio::select! {
                // Stream first: a notice buffered before the close is
                // delivered before the close itself.
                biased;
                read = self.recv.read(&mut self.buf), if !self.stream_ended => match read {
                    Ok(Some(n)) => self
                        .decoder
                        .push(&self.buf[..n])
                        .map_err(|e| explain(&self.connection, e.into()))?,
                    // The server finished the stream: the close follows.
                    Ok(None) => self.stream_ended = true,
                    Err(e) => {
                        return Err(explain(&self.connection, ClientError::Stream(e.to_string())))
                    }
                },
                datagram = self.connection.read_datagram() => match datagram {
                    Ok(bytes) => match Snapshot::decode(&bytes) {
                        Ok(snapshot) => self.snapshot(snapshot, false, bytes.len()),
                        Err(_) => self.stats.malformed += 1,
                    },
                    Err(e) => return Err(ClientError::from_connection_error(e)),
                },
            }
        }
    }

    /// Handles one control message.
    fn control(&mut self, message: ServerControl) {
        match message {
            ServerControl::FullState(snapshot) => {
                let len = snapshot.delta.len();
                self.stats.stream_snapshots += 1;
                self.snapshot(snapshot, true, len);
            }
            ServerControl::Chat { from, text } => {
                self.pending.push_back(SessionEvent::Chat { from, text })
            }
            ServerControl::Notice { kind } => self.pending.push_back(SessionEvent::Notice(kind)),
            ServerControl::Pong { nonce } => {
                let rtt = self
                    .pings
                    .iter()
                    .find(|(n, _)| *n == nonce)
                    .map(|(_, at)| at.elapsed());
                self.pending.push_back(SessionEvent::Pong { nonce, rtt });
            }
            ServerControl::Roster { players } => {
                // The full list: forget whoever is not in it.
                let listed: BTreeMap<PlayerId, String> =
                    players.into_iter().map(|p| (p.id, p.name)).collect();
                let gone: Vec<PlayerId> = self
                    .players
                    .keys()
                    .filter(|id| !listed.contains_key(id))
                    .copied()
                    .collect();
                for id in gone {
                    self.player_left(id);
                }
                for (id, name) in listed {
                    self.player_joined(RosterEntry { id, name });
                }
            }
            ServerControl::PlayerJoined(entry) => self.player_joined(entry),
            ServerControl::PlayerLeft { id } => self.player_left(id),
            ServerControl::Welcome(_)
            | ServerControl::Reject { .. }
            | ServerControl::Rooms { .. } => {
                tracing::warn!("ignoring a second welcome, a reject or a room list");
            }
        }
    }

    /// Records a player in the roster (a new name for a known id replaces
    /// the old one) and reports it; beyond [`MAX_ROSTER`] names new ids are
    /// ignored and counted.
    fn player_joined(&mut self, entry: RosterEntry) {
        let RosterEntry { id, name } = entry;
        if self.players.get(&id) == Some(&name) {
            return;
        }
        if self.players.len() >= MAX_ROSTER && !self.players.contains_key(&id) {
            self.stats.roster_overflow += 1;
            return;
        }
        self.players.insert(id, name.clone());
        self.pending
            .push_back(SessionEvent::PlayerJoined { id, name });
    }

    /// Removes a player from the roster and reports it.
    fn player_left(&mut self, id: PlayerId) {
        let name = self.players.remove(&id);
        self.pending
            .push_back(SessionEvent::PlayerLeft { id, name });
    }

    /// Decodes a snapshot against our history and queues it if it is new.
    fn snapshot(&mut self, snapshot: Snapshot, via_stream: bool, wire_bytes: usize) {
        let baseline = match snapshot.baseline_tick {
            None => None,
            Some(tick) => match self.history.get(tick) {
                Some(b) => Some(b),
                None => {
                    self.stats.missing_baselines += 1;
                    return;
                }
            },
        };
        let state = match snapshot.decode_state(baseline) {
            Ok(state) => state,
            Err(e) => {
                tracing::debug!("undecodable snapshot: {e}");
                self.stats.malformed += 1;
                return;
            }
        };
        if !self.history.insert(state.clone()) {
            self.stats.stale_snapshots += 1;
            return;
        }
        self.stats.snapshots += 1;
        if snapshot.baseline_tick.is_none() {
            self.stats.full_snapshots += 1;
        }
        self.pending
            .push_back(SessionEvent::Snapshot(SnapshotUpdate {
                state,
                baseline_tick: snapshot.baseline_tick,
                last_input_tick: snapshot.last_input_tick,
                input_timing: snapshot.input_timing,
                via_stream,
                wire_bytes,
                received: Instant::now(),
            }));
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

#[cfg(test)]
mod tests {
    use super::*;

    fn ticks(h: &InputHistory) -> Vec<(u64, u8)> {
        h.ticks.iter().map(|&(t, b)| (t, b.0)).collect()
    }

    #[test]
    fn input_history_fills_gaps_and_rewinds() {
        let mut h = InputHistory::default();
        h.record(10, Buttons(1));
        h.record(11, Buttons(2));
        h.record(14, Buttons(3));
        assert_eq!(
            ticks(&h),
            [(10, 1), (11, 2), (12, 2), (13, 2), (14, 3)],
            "skipped ticks repeat the last buttons"
        );
        h.record(12, Buttons(4));
        assert_eq!(ticks(&h), [(10, 1), (11, 2), (12, 4)], "rewound");
        h.record(500, Buttons(5));
        assert_eq!(ticks(&h), [(500, 5)], "a jump restarts");
        h.record(5, Buttons(6));
        assert_eq!(ticks(&h), [(5, 6)], "far back restarts too");
        for t in 6..200 {
            h.record(t, Buttons(t as u8));
        }
        assert_eq!(h.ticks.len(), MAX_INPUT_HISTORY);
        let p = h.packet(16, Some(7)).unwrap();
        assert_eq!(p.newest_tick, 199);
        assert_eq!(p.buttons.len(), 16);
        assert_eq!(p.get(190), Some(Buttons(190)));
        assert_eq!(p.ack_snapshot, Some(7));
    }

    #[test]
    fn join_options_choose_the_hello() {
        let any = JoinOptions::new("ada");
        assert!(matches!(any.hello(), ClientControl::Hello { .. }));
        let named = JoinOptions {
            room: Some("room-2".into()),
            ..any
        };
        assert_eq!(
            named.hello().as_hello(),
            Some((PROTOCOL_VERSION, "ada", Some("room-2")))
        );
    }
}
