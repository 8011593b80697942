//! The session's protocol, sans IO: what to send and what the server's
//! bytes mean, without sockets or a clock of its own (the caller passes
//! `now`). [`super::Session`] drives it over QUIC; the browser front end
//! over WebTransport or WebSocket.

use std::collections::{BTreeMap, VecDeque};

use ledge_shared::input::Buttons;
use ledge_shared::protocol::{
    write_frame, ClientControl, FrameDecoder, InputPacket, LevelList, Message, PlayerId,
    RosterEntry, ServerControl, Snapshot, SnapshotHistory, StateSnapshot, Welcome, MAX_FRAME,
    MAX_INPUT_HISTORY, MAX_ROSTER,
};

use super::{JoinOptions, SessionEvent, SessionStats, SnapshotUpdate, SNAPSHOT_HISTORY};
use crate::error::ClientError;
use crate::time::Instant;

/// Pings remembered for round-trip times.
const PINGS_REMEMBERED: usize = 8;

/// Events queued and not yet taken; beyond this the oldest snapshot events
/// are dropped (a caller that stopped polling must not grow memory).
pub const MAX_PENDING_EVENTS: usize = 1024;

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

    /// How many ticks (newest last, at most the history) the newest
    /// buttons have been held.
    fn steady(&self) -> usize {
        let Some(&(_, newest)) = self.ticks.back() else {
            return 0;
        };
        self.ticks
            .iter()
            .rev()
            .take_while(|&&(_, b)| b == newest)
            .count()
    }

    /// A packet of the newest `n` ticks.
    fn packet(&self, n: usize, ack: Option<u64>) -> Option<InputPacket> {
        let &(newest, _) = self.ticks.back()?;
        let buttons: Vec<Buttons> = self.ticks.iter().rev().take(n).map(|&(_, b)| b).collect();
        Some(InputPacket::new(newest, &buttons, ack))
    }
}

/// The start of a session: our hello sent, waiting for the server's first
/// answer on the control stream.
#[derive(Debug)]
pub struct Handshake {
    decoder: FrameDecoder,
}

impl Default for Handshake {
    fn default() -> Self {
        Handshake::new()
    }
}

impl Handshake {
    /// Ready to read the answer.
    pub fn new() -> Handshake {
        Handshake {
            decoder: FrameDecoder::new(MAX_FRAME),
        }
    }

    /// The bytes that open the control stream for `options` (the name is
    /// checked first: a bad one is refused here, with the reason).
    pub fn hello_frame(options: &JoinOptions) -> Result<Vec<u8>, ClientError> {
        let hello = options.hello();
        hello.validate()?;
        let mut frame = Vec::new();
        write_frame(&hello, &mut frame)?;
        Ok(frame)
    }

    /// Feeds bytes of the control stream, received at `now`. `Ok(None)`:
    /// no answer yet; `Ok(Some(state))`: welcomed (what followed the
    /// welcome is the session's); a `Reject` or another message is an
    /// error.
    pub fn on_stream(
        &mut self,
        bytes: &[u8],
        now: Instant,
    ) -> Result<Option<SessionState>, ClientError> {
        self.decoder.push(bytes)?;
        match self.decoder.pop_message::<ServerControl>() {
            None => Ok(None),
            Some(message) => match message? {
                ServerControl::Welcome(welcome) => {
                    let decoder = std::mem::replace(&mut self.decoder, FrameDecoder::new(0));
                    SessionState::new(welcome, decoder, now).map(Some)
                }
                ServerControl::Reject { reason } => Err(ClientError::Rejected(reason)),
                other => Err(ClientError::Unexpected(format!(
                    "{} before the welcome",
                    other.kind()
                ))),
            },
        }
    }
}

/// Most input datagrams a client sends per second: at 60 Hz ticks every
/// datagram carries two ticks. Every datagram costs its ~50 bytes of
/// QUIC, UDP and IP header and the server a receive, a decryption and an
/// ACK to track, whatever it carries; the tick between two datagrams
/// reaches the server one tick later (and the input clock leads by that
/// tick more: see [`SnapshotUpdate::input_timing`]).
pub const INPUT_SEND_HZ: u32 = 30;

/// Ticks between input datagrams at `tick_rate`: the fewest that keep
/// them at most [`INPUT_SEND_HZ`] (1 at 30 Hz and below, 2 at 60 Hz).
pub fn input_interval(tick_rate: u32) -> u64 {
    u64::from(tick_rate.div_ceil(INPUT_SEND_HZ).max(1))
}

/// Input datagrams a second while quiet: our buttons held for
/// [`QUIET_AFTER`], our player standing still, and the world still (the
/// newest snapshot the one before it with nothing but time changed: players
/// standing or running steadily, run timers counting, walkers walking on).
/// Each says its buttons hold ([`InputPacket::hold`]), so the server
/// applies them meanwhile; and since it sends a quiet client snapshots only
/// when something changes or it hears from it, an idle player costs a few
/// small packets a second each way instead of ~30. A button pressed ends it
/// at once; a player on the move is never quiet (its inputs and snapshots
/// keep the full rate).
pub const QUIET_SEND_HZ: u32 = 5;

/// How long our buttons must stay the same before we go quiet.
pub const QUIET_AFTER: std::time::Duration = std::time::Duration::from_millis(250);

/// A welcomed session's protocol state: the roster, the snapshot history,
/// our recent inputs, pings in flight, and the events not yet taken.
#[derive(Debug)]
pub struct SessionState {
    decoder: FrameDecoder,
    welcome: Welcome,
    inputs: InputHistory,
    redundancy: usize,
    /// Ticks between input datagrams ([`input_interval`]).
    input_every: u64,
    /// Ticks between input datagrams while quiet ([`QUIET_SEND_HZ`]).
    quiet_every: u64,
    /// Ticks of steady buttons before going quiet ([`QUIET_AFTER`]).
    quiet_after: usize,
    /// Whether the last input datagram held its buttons (we are quiet).
    quiet: bool,
    /// Whether in the newest snapshot our player stood still and nothing
    /// but time changed from the one before ([`StateSnapshot::extrapolates_to`]).
    world_still: bool,
    /// Newest tick sent in an input datagram.
    input_sent: Option<u64>,
    /// The server's last `input_timing` (for a datagram's newest tick).
    server_timing: i16,
    history: SnapshotHistory,
    /// Set by a level change: the tick the current level started at.
    /// Snapshots of earlier ticks are of a level the room has left.
    level_start: Option<u64>,
    /// The room's levels and votes, as last heard.
    levels: Option<LevelList>,
    pending: VecDeque<SessionEvent>,
    pings: VecDeque<(u64, Instant)>,
    players: BTreeMap<PlayerId, String>,
    next_nonce: u64,
    stats: SessionStats,
}

impl SessionState {
    /// The state after `welcome`, at `now`; `decoder` holds the control
    /// stream's bytes that followed it (often the roster, read with the
    /// welcome), handled here. A broken stream is an error.
    pub fn new(
        welcome: Welcome,
        decoder: FrameDecoder,
        now: Instant,
    ) -> Result<SessionState, ClientError> {
        let mut state = SessionState {
            decoder,
            inputs: InputHistory::default(),
            redundancy: 1,
            input_every: 1,
            quiet_every: 1,
            quiet_after: 1,
            quiet: false,
            world_still: false,
            input_sent: None,
            server_timing: 0,
            welcome,
            history: SnapshotHistory::new(SNAPSHOT_HISTORY),
            level_start: None,
            levels: None,
            pending: VecDeque::new(),
            pings: VecDeque::new(),
            players: BTreeMap::new(),
            next_nonce: 0,
            stats: SessionStats::default(),
        };
        state.retime();
        state.drain_stream_at(now)?;
        Ok(state)
    }

    /// Sets the input pacing from the welcome's timing.
    fn retime(&mut self) {
        let timing = &self.welcome.timing;
        self.redundancy = usize::from(timing.input_redundancy).clamp(1, MAX_INPUT_HISTORY);
        self.input_every = input_interval(timing.tick_rate);
        self.quiet_every = u64::from(timing.tick_rate.div_ceil(QUIET_SEND_HZ).max(1));
        self.quiet_after = ((QUIET_AFTER.as_secs_f64() * f64::from(timing.tick_rate)) as usize)
            .clamp(1, MAX_INPUT_HISTORY);
    }

    /// What the server said when we joined, or the latest level change's
    /// welcome (which keeps the first `session_token`, the one a resume
    /// names).
    pub fn welcome(&self) -> &Welcome {
        &self.welcome
    }

    /// The room's levels, votes and when it moves on, as last heard.
    pub fn levels(&self) -> Option<&LevelList> {
        self.levels.as_ref()
    }

    /// The control frame of a vote for level `level` (an index into
    /// [`SessionState::levels`]); an index no list can have is refused.
    pub fn vote_frame(level: u32) -> Result<Vec<u8>, ClientError> {
        let vote = ClientControl::Vote { level };
        vote.validate()?;
        let mut frame = Vec::new();
        write_frame(&vote, &mut frame)?;
        Ok(frame)
    }

    /// Who is in our room, by id (us included, once the roster arrived).
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

    /// Whether we are quiet: the last input datagram held its buttons
    /// ([`QUIET_SEND_HZ`]).
    pub fn is_quiet(&self) -> bool {
        self.quiet
    }

    /// Records our buttons for `tick` and, when one is due (every
    /// [`input_interval`] ticks, or [`QUIET_SEND_HZ`] times a second while
    /// quiet), returns the input datagram to send: this tick and the ticks
    /// before it (as many as the server asked for in `Welcome`, so those
    /// between datagrams go too), plus the acknowledgement of the newest
    /// snapshot.
    pub fn input_datagram(
        &mut self,
        tick: u64,
        buttons: Buttons,
    ) -> Result<Option<Vec<u8>>, ClientError> {
        self.inputs.record(tick, buttons);
        let quiet = self.world_still && self.inputs.steady() >= self.quiet_after;
        let due = match self.input_sent {
            None => true,
            Some(sent) if tick < sent => true,
            Some(sent) => {
                // Quiet only once quiet was said: the datagram that says
                // it goes at the usual time.
                let every = if quiet && self.quiet {
                    self.quiet_every
                } else {
                    self.input_every
                };
                let due_at = sent.saturating_add(every);
                tick >= due_at
                    || (tick.saturating_add(self.input_every) > due_at
                        && self.lands_before_snapshot(tick))
            }
        };
        if !due {
            return Ok(None);
        }
        let packet = self
            .inputs
            .packet(self.redundancy, self.ack())
            .expect("just recorded")
            .holding(quiet);
        let bytes = packet.encode()?;
        self.quiet = quiet;
        self.input_sent = Some(tick);
        self.stats.inputs_sent += 1;
        Ok(Some(bytes))
    }

    /// Whether a datagram whose newest tick is `tick` should reach the
    /// server in the tick before it sends snapshots, so that the server's
    /// ACK of it rides on the next snapshot instead of going alone when its
    /// ACK timer runs out first (quinn holds an ACK at most 25 ms, its
    /// default `max_ack_delay`, less than a 33 ms snapshot interval). Input
    /// for `tick` arrives while the server's next tick is about
    /// `tick - timing`; snapshots go after a tick `k` with
    /// `(k + 1) % every == 0`. Only when snapshots go every `input_every`
    /// ticks, as at 60 Hz.
    fn lands_before_snapshot(&self, tick: u64) -> bool {
        if u64::from(self.welcome.timing.snapshot_interval) != self.input_every {
            return false;
        }
        let arrives = i128::from(tick) - i128::from(self.server_timing);
        (arrives + 1).rem_euclid(i128::from(self.input_every)) == 0
    }

    /// A ping sent at `now`: its nonce and the control frame to write; the
    /// [`SessionEvent::Pong`] carries the round-trip time.
    pub fn ping_frame(&mut self, now: Instant) -> Result<(u64, Vec<u8>), ClientError> {
        let nonce = self.next_nonce;
        let mut frame = Vec::new();
        write_frame(&ClientControl::Ping { nonce }, &mut frame)?;
        self.next_nonce = self.next_nonce.wrapping_add(1);
        if self.pings.len() == PINGS_REMEMBERED {
            self.pings.pop_front();
        }
        self.pings.push_back((nonce, now));
        Ok((nonce, frame))
    }

    /// Feeds bytes of the control stream, received at `now`; the messages
    /// they complete become events. A broken stream is an error.
    pub fn on_stream(&mut self, bytes: &[u8], now: Instant) -> Result<(), ClientError> {
        self.decoder.push(bytes)?;
        self.drain_stream_at(now)
    }

    fn drain_stream_at(&mut self, now: Instant) -> Result<(), ClientError> {
        while let Some(message) = self.decoder.pop_message::<ServerControl>() {
            self.control(message?, now);
        }
        Ok(())
    }

    /// Feeds one datagram received at `now` (a snapshot); an undecodable
    /// one is counted and dropped.
    pub fn on_datagram(&mut self, bytes: &[u8], now: Instant) {
        match Snapshot::decode(bytes) {
            Ok(snapshot) => self.snapshot(snapshot, false, bytes.len(), now),
            Err(_) => self.stats.malformed += 1,
        }
    }

    /// The next event, oldest first.
    pub fn poll_event(&mut self) -> Option<SessionEvent> {
        self.pending.pop_front()
    }

    /// Puts events back in front (in their order), e.g. those read while
    /// waiting for one in particular.
    pub fn unpoll(&mut self, events: Vec<SessionEvent>) {
        for event in events.into_iter().rev() {
            self.pending.push_front(event);
        }
    }

    /// Queues an event, dropping the oldest snapshot (or else the oldest
    /// event) beyond [`MAX_PENDING_EVENTS`].
    fn push(&mut self, event: SessionEvent) {
        if self.pending.len() >= MAX_PENDING_EVENTS {
            let at = self
                .pending
                .iter()
                .position(|e| matches!(e, SessionEvent::Snapshot(_)))
                .unwrap_or(0);
            self.pending.remove(at);
        }
        self.pending.push_back(event);
    }

    /// Handles one control message.
    fn control(&mut self, message: ServerControl, now: Instant) {
        match message {
            ServerControl::FullState(snapshot) => {
                let len = snapshot.delta.len();
                self.stats.stream_snapshots += 1;
                self.snapshot(snapshot, true, len, now);
            }
            ServerControl::Chat { from, text } => self.push(SessionEvent::Chat { from, text }),
            ServerControl::Notice { kind } => self.push(SessionEvent::Notice(kind)),
            ServerControl::Pong { nonce } => {
                let rtt = self
                    .pings
                    .iter()
                    .find(|(n, _)| *n == nonce)
                    .map(|(_, at)| now.saturating_duration_since(*at));
                self.push(SessionEvent::Pong { nonce, rtt });
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
            ServerControl::RunRecorded(standing) => {
                self.push(SessionEvent::RunRecorded(Ok(standing)));
            }
            ServerControl::RunNotRecorded { reason } => {
                self.push(SessionEvent::RunRecorded(Err(reason)));
            }
            ServerControl::Ghost(ghost) => self.push(SessionEvent::Ghost(ghost)),
            ServerControl::Levels(list) => {
                self.levels = Some(list.clone());
                self.push(SessionEvent::Levels(list));
            }
            ServerControl::LevelChange(welcome) => self.level_change(welcome),
            ServerControl::Welcome(_)
            | ServerControl::Reject { .. }
            | ServerControl::Rooms { .. } => {
                tracing::warn!("ignoring a second welcome, a reject or a room list");
            }
        }
    }

    /// The room moved to another level: `welcome` replaces ours (keeping
    /// the first session token: the server does not send it again), the
    /// snapshots of the old level are forgotten, and those of ticks before
    /// the new level's first are dropped from now on.
    fn level_change(&mut self, mut welcome: Welcome) {
        if welcome.player_id != self.welcome.player_id {
            tracing::warn!(
                "a level change for player {} (we are {})",
                welcome.player_id,
                self.welcome.player_id
            );
        }
        welcome.session_token = self.welcome.session_token;
        self.level_start = Some(welcome.server_tick);
        self.history = SnapshotHistory::new(SNAPSHOT_HISTORY);
        self.world_still = false;
        self.welcome = welcome.clone();
        self.retime();
        self.push(SessionEvent::LevelChange(welcome));
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
        self.push(SessionEvent::PlayerJoined { id, name });
    }

    /// Removes a player from the roster and reports it.
    fn player_left(&mut self, id: PlayerId) {
        let name = self.players.remove(&id);
        self.push(SessionEvent::PlayerLeft { id, name });
    }

    /// Decodes a snapshot against our history and queues it if it is new.
    fn snapshot(&mut self, snapshot: Snapshot, via_stream: bool, wire_bytes: usize, now: Instant) {
        if self.level_start.is_some_and(|start| snapshot.tick < start) {
            // Of the level the room left (sent before the change).
            self.stats.stale_snapshots += 1;
            return;
        }
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
        let me = self.welcome.player_id.0;
        let still = self
            .history
            .latest()
            .is_some_and(|l| l.tick < state.tick && l.extrapolates_to(&state))
            && state.get(me).is_none_or(|e| e.vel == glam::IVec2::ZERO);
        if !self.history.insert(state.clone()) {
            self.stats.stale_snapshots += 1;
            return;
        }
        self.world_still = still;
        self.stats.snapshots += 1;
        self.server_timing = snapshot.input_timing;
        if snapshot.baseline_tick.is_none() {
            self.stats.full_snapshots += 1;
        }
        self.push(SessionEvent::Snapshot(SnapshotUpdate {
            state,
            baseline_tick: snapshot.baseline_tick,
            previous_tick: snapshot.previous_tick(),
            last_input_tick: snapshot.last_input_tick,
            // The server times a datagram by its newest tick; the oldest
            // tick it brings first is `input_every - 1` ticks less early.
            input_timing: snapshot
                .input_timing
                .saturating_sub(i16::try_from(self.input_every - 1).unwrap_or(i16::MAX)),
            via_stream,
            wire_bytes,
            received: now,
        }));
    }
}

#[cfg(test)]
mod tests {

    /// A welcome at `tick_rate` Hz, snapshots every other tick.
    fn welcome_at(tick_rate: u32) -> Welcome {
        use ledge_shared::protocol::NetTiming;
        Welcome {
            player_id: PlayerId(1),
            room: "room-1".into(),
            level_id: "level".into(),
            level_hash: 0,
            level: Default::default(),
            session_token: Default::default(),
            server_tick: 0,
            timing: NetTiming {
                tick_rate,
                snapshot_interval: 2,
                input_redundancy: 8,
            },
            sim_config: vec![],
        }
    }

    /// An empty full snapshot of `tick` reporting `input_timing`, encoded.
    fn snapshot_datagram(tick: u64, input_timing: i16) -> Vec<u8> {
        use ledge_shared::protocol::Snapshot;
        let mut delta = Vec::new();
        let empty = StateSnapshot {
            tick,
            ..StateSnapshot::default()
        };
        ledge_shared::protocol::encode_delta(None, &empty, &mut delta).unwrap();
        let snapshot = Snapshot {
            tick,
            baseline_tick: None,
            last_input_tick: None,
            input_timing,
            since_previous: 0,
            delta,
        };
        snapshot.encode().unwrap()
    }

    #[test]
    fn what_came_with_the_welcome_is_handled_at_once() {
        use ledge_shared::protocol::RosterEntry;
        let welcome = welcome_at(60);
        // The roster read in the same chunk as the welcome.
        let mut bytes = Vec::new();
        write_frame(&ServerControl::Welcome(welcome.clone()), &mut bytes).unwrap();
        let roster = ServerControl::Roster {
            players: vec![RosterEntry {
                id: PlayerId(1),
                name: "ada".into(),
            }],
        };
        write_frame(&roster, &mut bytes).unwrap();
        let mut decoder = FrameDecoder::new(MAX_FRAME);
        decoder.push(&bytes).unwrap();
        let first = decoder.pop_message::<ServerControl>().unwrap().unwrap();
        assert_eq!(first, ServerControl::Welcome(welcome.clone()));
        let mut state = SessionState::new(welcome, decoder, Instant::now()).unwrap();
        assert_eq!(
            state.poll_event(),
            Some(SessionEvent::PlayerJoined {
                id: PlayerId(1),
                name: "ada".into()
            }),
            "the roster is an event before any more bytes arrive"
        );
        assert_eq!(state.players().len(), 1);
    }

    use super::*;

    /// An empty full snapshot of `tick`, undecoded.
    fn full_snapshot(tick: u64) -> Snapshot {
        Snapshot::decode(&snapshot_datagram(tick, 0)).unwrap()
    }

    /// The events queued, oldest first.
    fn drain(state: &mut SessionState) -> Vec<SessionEvent> {
        std::iter::from_fn(|| state.poll_event()).collect()
    }

    #[test]
    fn a_level_change_replaces_the_welcome_keeps_the_token_and_drops_the_old_level() {
        use ledge_shared::protocol::{LevelOffer, SessionToken};
        let now = Instant::now();
        let mut first = welcome_at(60);
        first.session_token = SessionToken([7; 16]);
        let mut state = SessionState::new(first, FrameDecoder::new(MAX_FRAME), now).unwrap();
        state.on_datagram(&snapshot_datagram(90, 0), now);
        assert_eq!(state.ack(), Some(90));
        // The room moves on at tick 100: the new welcome has no token.
        let mut next = welcome_at(60);
        next.level_id = "second".into();
        next.level_hash = 0x5eed;
        next.level = LevelOffer {
            sha256: [9; 32],
            size: 1234,
        };
        next.server_tick = 100;
        let mut bytes = Vec::new();
        write_frame(&ServerControl::LevelChange(next.clone()), &mut bytes).unwrap();
        state.on_stream(&bytes, now).unwrap();
        assert_eq!(state.welcome().level_id, "second");
        assert_eq!(state.welcome().level, next.level);
        assert_eq!(state.welcome().server_tick, 100);
        assert_eq!(
            state.welcome().session_token,
            SessionToken([7; 16]),
            "the first token still resumes"
        );
        assert_eq!(state.ack(), None, "the old level's snapshots are forgotten");
        let events = drain(&mut state);
        assert!(
            matches!(&events[..], [SessionEvent::Snapshot(s), SessionEvent::LevelChange(w)]
                if s.state.tick == 90 && w.level_id == "second"
                    && w.session_token == SessionToken([7; 16])),
            "{events:?}"
        );
        // A datagram of the old level, late: dropped as stale.
        let stale = state.stats().stale_snapshots;
        state.on_datagram(&snapshot_datagram(98, 0), now);
        assert!(drain(&mut state).is_empty());
        assert_eq!(state.stats().stale_snapshots, stale + 1);
        assert_eq!(state.ack(), None);
        // The new level's first snapshot, on the stream: taken.
        let mut bytes = Vec::new();
        write_frame(&ServerControl::FullState(full_snapshot(100)), &mut bytes).unwrap();
        state.on_stream(&bytes, now).unwrap();
        match &drain(&mut state)[..] {
            [SessionEvent::Snapshot(update)] => {
                assert_eq!(update.state.tick, 100);
                assert!(update.via_stream);
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(state.ack(), Some(100));
        assert_eq!(state.stats().stream_snapshots, 1);
        // And the datagrams after it.
        state.on_datagram(&snapshot_datagram(102, 0), now);
        assert_eq!(state.ack(), Some(102));
    }

    #[test]
    fn the_level_list_is_an_event_and_kept_and_votes_are_checked() {
        use ledge_shared::protocol::{LevelChoice, VoteRule, MAX_LEVELS};
        let now = Instant::now();
        let mut state =
            SessionState::new(welcome_at(60), FrameDecoder::new(MAX_FRAME), now).unwrap();
        assert!(state.levels().is_none());
        let list = LevelList {
            levels: ["one", "two"]
                .map(|n| LevelChoice {
                    id: n.into(),
                    name: n.to_uppercase(),
                })
                .to_vec(),
            current: 0,
            next: 1,
            votes: vec![0, 2],
            rule: VoteRule::Majority,
            change_at: Some(900),
        };
        let mut bytes = Vec::new();
        write_frame(&ServerControl::Levels(list.clone()), &mut bytes).unwrap();
        state.on_stream(&bytes, now).unwrap();
        assert_eq!(drain(&mut state), [SessionEvent::Levels(list.clone())]);
        assert_eq!(state.levels(), Some(&list));

        let frame = SessionState::vote_frame(1).unwrap();
        let mut decoder = FrameDecoder::new(MAX_FRAME);
        decoder.push(&frame).unwrap();
        assert_eq!(
            decoder.pop_message::<ClientControl>().unwrap().unwrap(),
            ClientControl::Vote { level: 1 }
        );
        assert!(SessionState::vote_frame(MAX_LEVELS as u32).is_err());
    }

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
    fn inputs_go_at_most_thirty_times_a_second_and_the_timing_counts_the_wait() {
        assert_eq!(
            [1, 20, 30, 31, 60, 120, 144].map(input_interval),
            [1, 1, 1, 2, 2, 4, 5]
        );
        let welcome = welcome_at(120);
        let now = Instant::now();
        let mut state = SessionState::new(welcome, FrameDecoder::new(MAX_FRAME), now).unwrap();
        let sent: Vec<u64> = (10..20)
            .filter(|&t| state.input_datagram(t, Buttons(1)).unwrap().is_some())
            .collect();
        assert_eq!(sent, [10, 14, 18], "every fourth tick at 120 Hz");
        assert_eq!(state.stats().inputs_sent, 3);
        // A clock set back (a resync) sends at once.
        assert!(state.input_datagram(12, Buttons(1)).unwrap().is_some());
        // A datagram the server saw 5 ticks early brought 3 ticks due
        // earlier: the oldest was 2 ticks early.
        state.on_datagram(&snapshot_datagram(2, 5), now);
        match state.poll_event() {
            Some(SessionEvent::Snapshot(update)) => assert_eq!(update.input_timing, 2),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn inputs_land_in_the_tick_before_a_snapshot() {
        let welcome = welcome_at(60);
        let now = Instant::now();
        let mut state = SessionState::new(welcome, FrameDecoder::new(MAX_FRAME), now).unwrap();
        let sent = |state: &mut SessionState, ticks: std::ops::Range<u64>| -> Vec<u64> {
            ticks
                .filter(|&t| state.input_datagram(t, Buttons(1)).unwrap().is_some())
                .collect()
        };
        // Timing 0 until told: tick T arrives while the server is at T,
        // and snapshots go after odd ticks: the odd ones are sent.
        assert_eq!(sent(&mut state, 10..17), [10, 11, 13, 15]);
        // The server says inputs arrive 3 ticks early: now the even ones
        // (17 still goes: no tick waits longer than the interval).
        state.on_datagram(&snapshot_datagram(2, 3), now);
        assert_eq!(sent(&mut state, 17..24), [17, 18, 20, 22]);
    }

    #[test]
    fn a_still_player_in_a_still_world_goes_quiet_and_a_press_ends_it_at_once() {
        use ledge_shared::protocol::{EntityState, Message};
        let welcome = welcome_at(60);
        let now = Instant::now();
        let mut state = SessionState::new(welcome, FrameDecoder::new(MAX_FRAME), now).unwrap();
        let sent = |state: &mut SessionState, ticks: std::ops::Range<u64>, b: u8| {
            ticks
                .filter_map(|t| {
                    let bytes = state.input_datagram(t, Buttons(b)).unwrap()?;
                    Some((t, InputPacket::decode(&bytes).unwrap().hold))
                })
                .collect::<Vec<_>>()
        };
        // The world not known still yet: 30 a second, never holding.
        assert_eq!(
            sent(&mut state, 10..16, 0),
            [10, 11, 13, 15].map(|t| (t, false))
        );
        state.on_datagram(&snapshot_datagram(2, 0), now);
        state.on_datagram(&snapshot_datagram(4, 0), now);
        // Still for 15 ticks (250 ms) from tick 10: the regular datagram
        // after that holds, then one every 12 ticks (odd ones, which land
        // in the tick before a snapshot).
        let quiet = sent(&mut state, 16..60, 0);
        assert_eq!(
            quiet[..4],
            [(17, false), (19, false), (21, false), (23, false)]
        );
        assert_eq!(quiet[4..], [(25, true), (37, true), (49, true)]);
        assert!(state.is_quiet());
        // A press goes at once, not holding.
        assert_eq!(sent(&mut state, 60..62, 16), [(60, false), (61, false)]);
        assert!(!state.is_quiet());

        // Quiet again, then the world moves: back to 30 a second at once.
        let quiet = sent(&mut state, 62..100, 0);
        assert!(quiet.last().unwrap().1, "{quiet:?}");
        let mut moved = Vec::new();
        let one = StateSnapshot {
            tick: 6,
            entities: vec![EntityState::zero(7)],
        };
        ledge_shared::protocol::encode_delta(None, &one, &mut moved).unwrap();
        let moved = Snapshot {
            tick: 6,
            baseline_tick: None,
            last_input_tick: None,
            input_timing: 0,
            since_previous: 2,
            delta: moved,
        };
        state.on_datagram(&moved.encode().unwrap(), now);
        assert_eq!(sent(&mut state, 100..102, 0), [(100, false), (101, false)]);

        // Our own player running steadily (the world only extrapolates):
        // on the move, never quiet.
        let running = |tick: u64| {
            let me = EntityState {
                pos: glam::IVec2::new(100 * tick as i32, 0),
                vel: glam::IVec2::new(100, 0),
                ..EntityState::zero(1)
            };
            let state = StateSnapshot {
                tick,
                entities: vec![me],
            };
            let mut delta = Vec::new();
            ledge_shared::protocol::encode_delta(None, &state, &mut delta).unwrap();
            let snapshot = Snapshot {
                tick,
                delta,
                ..moved.clone()
            };
            snapshot.encode().unwrap()
        };
        state.on_datagram(&running(8), now);
        state.on_datagram(&running(10), now);
        let on_the_move = sent(&mut state, 102..140, 0);
        assert!(
            on_the_move.iter().all(|&(_, hold)| !hold),
            "{on_the_move:?}"
        );
        assert_eq!(on_the_move.len(), 19, "{on_the_move:?}");
    }
}
