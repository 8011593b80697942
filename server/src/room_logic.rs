//! A room's logic, sans-IO: its authoritative [`Game`], its players, and
//! what each client is sent. Time and requests come in as arguments
//! (joins, leaves, resumes, chat, ticks); what the room sends, closes or
//! samples comes out as [`Action`]s, in order, which the room task
//! ([`crate::room`]) carries out over the clients' links. So the room's
//! rules are tested without sockets, tasks or timers, like [`crate::fleet`].
//!
//! Every tick: take each player's input for this tick from its inbox (or
//! repeat its last one and count the starvation), remove the players idle
//! too long, step the game, and every `snapshot_interval` ticks capture a
//! snapshot and send each attached player a delta against the snapshot it
//! acknowledged ([`Action::Snapshot`]: a datagram when it fits the
//! client's datagram size, a control-stream frame when not). The room task
//! reports each snapshot actually sent ([`RoomLogic::datagram_sent`],
//! [`RoomLogic::stream_queued`]), since a datagram can be lost before the
//! wire and a full control queue drops a frame.
//!
//! A quiet client (one that sent nothing since its last snapshot, holding
//! its buttons: [`InputPacket::hold`]) gets no snapshot that would change
//! nothing for it: nothing but time changed since both the one it
//! acknowledged and the last one it was sent
//! (`StateSnapshot::extrapolates_to`). It gets one again when it speaks,
//! when anything changes, or after [`QUIET_MAX`]. An idle room then costs a
//! few packets a second per player instead of 30 snapshots and their ACKs.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use ledge_shared::game::Game;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{
    encode_sim_config, name_key, write_frame, InputPacket, LevelOffer, NetTiming, NoticeKind,
    Outgoing, PlayerId, RejectReason, RosterEntry, ServerControl, SessionToken, Snapshot, Welcome,
    MAX_ROSTER,
};
use prometheus_client::metrics::counter::Counter;
use tracing::{error, info, warn};

use crate::inputs::{InputBuffer, Received};
use crate::metrics::{DropReason, KickLabel, KickReason, Metrics, RoomLabel, SnapshotKind};
use crate::record::Recorder;
use crate::snapshots::RoomSnapshots;
use crate::tls::DATAGRAM_SEND_BUFFER;

/// How long the room waits for a client to acknowledge a snapshot sent on
/// the control stream before it sends another one there.
pub const STREAM_SNAPSHOT_RESEND: Duration = Duration::from_millis(1000);

/// Longest a client goes without a snapshot while nothing changes (should
/// its own quiet inputs, 5 a second, be lost): its clock and loss figure
/// keep a sample, its acknowledged baseline stays in the room's history,
/// and the client, which calls a server silent for 1 s stalled, never does.
pub const QUIET_MAX: Duration = Duration::from_millis(500);

/// How a room runs.
#[derive(Debug, Clone)]
pub struct RoomConfig {
    /// The room's name (sent in `Welcome`).
    pub name: String,
    /// Fixed tick rate in Hz.
    pub tick_rate: u32,
    /// Ticks between snapshots.
    pub snapshot_interval: u32,
    /// Most players at once.
    pub max_players: usize,
    /// Most ticks run back to back after a stall; older ones are skipped.
    pub max_catch_up: u32,
    /// Ticks of input accepted ahead of the next simulated tick.
    pub input_window: usize,
    /// Ticks of input a client should repeat in each packet.
    pub input_redundancy: u8,
    /// Snapshots kept as baselines.
    pub history: usize,
    /// Level id sent in `Welcome`.
    pub level_id: String,
    /// Level hash sent in `Welcome`.
    pub level_hash: u64,
    /// The level bundle offered in `Welcome`.
    pub level: LevelOffer,
    /// Where to record the match (inputs, joins, leaves, hashes), if on.
    pub record: Option<Recorder>,
    /// A player sending no input for this long is removed (half of it
    /// while the room is full).
    pub idle_kick: Duration,
}

/// The room's progress, published after every tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RoomStatus {
    /// Ticks simulated so far.
    pub tick: u64,
    /// The game's state hash after that tick.
    pub state_hash: u64,
    /// Players currently in the room.
    pub players: usize,
}

/// Inputs and acknowledgements of one client, written by its connection
/// task, read by the room.
#[derive(Debug)]
pub struct PlayerInbox {
    /// Button bits by tick.
    pub inputs: InputBuffer,
    /// Newest snapshot tick the client acknowledged.
    pub ack: Option<u64>,
    /// Whether any input arrived yet (starvation counts only after).
    pub received_any: bool,
    /// Input packets received (late or early ones too): the client is
    /// there, whatever its timing.
    pub packets: u64,
    /// Earliest arrival (most negative timing) since the last snapshot.
    timing_min: Option<i16>,
    /// Timing of the last packet.
    last_timing: i16,
}

impl PlayerInbox {
    fn new(window: usize, next_tick: u64) -> PlayerInbox {
        PlayerInbox {
            inputs: InputBuffer::new(window, next_tick),
            ack: None,
            received_any: false,
            packets: 0,
            timing_min: None,
            last_timing: 0,
        }
    }

    /// Stores a decoded input packet.
    pub fn receive(&mut self, packet: &InputPacket) -> Received {
        let r = self.inputs.receive(packet);
        if let Some(ack) = packet.ack_snapshot {
            self.ack = Some(self.ack.map_or(ack, |a| a.max(ack)));
        }
        self.received_any = true;
        self.packets += 1;
        self.last_timing = r.timing;
        self.timing_min = Some(self.timing_min.map_or(r.timing, |m| m.min(r.timing)));
        r
    }

    /// The timing to report: the worst (latest) arrival since the last
    /// report, or the last one when nothing arrived since.
    fn take_timing(&mut self) -> i16 {
        self.timing_min.take().unwrap_or(self.last_timing)
    }
}

/// Locks an inbox, ignoring poisoning (the data stays consistent: every
/// update is a few plain assignments).
pub fn lock(inbox: &Mutex<PlayerInbox>) -> MutexGuard<'_, PlayerInbox> {
    inbox.lock().unwrap_or_else(|e| e.into_inner())
}

/// A successful join.
#[derive(Debug)]
pub struct Joined {
    /// What to send the client (its `session_token` is the connection's to
    /// fill in).
    pub welcome: Welcome,
    /// Where the connection puts the client's inputs.
    pub inbox: Arc<Mutex<PlayerInbox>>,
    /// Which connection holds the player: 0 on joining, one more on each
    /// resume. Leaves and detaches of an older generation are ignored.
    pub generation: u32,
}

/// A player handed to a new connection ([`RoomLogic::rejoin`]).
#[derive(Debug)]
pub struct Resumed {
    /// What the new connection is given, as on joining.
    pub joined: Joined,
    /// The old connection still held the player (the client gave up on it
    /// before the server noticed): close it, before the new one takes over.
    pub close_old: bool,
}

/// Something the room's I/O does for it. Actions come in the order the
/// room decided them; a player's frames must be queued in that order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Action {
    /// Queue a complete frame on the player's control stream (dropped, and
    /// counted, when its queue is full).
    Control {
        /// The player.
        to: PlayerId,
        /// The frame, length prefix included.
        frame: Vec<u8>,
    },
    /// Close the player's connection (`CloseCode::Kicked`, `reason`) after
    /// what was queued before, or at once when its queue is full.
    Kick {
        /// The player.
        to: PlayerId,
        /// Why (also in the `Notice` queued before).
        reason: String,
    },
    /// Add what the player's connection put through its socket since the
    /// last sample to the wire metrics.
    SampleWire(PlayerId),
    /// Send a snapshot; say whether it went with
    /// [`RoomLogic::datagram_sent`] or [`RoomLogic::stream_queued`].
    Snapshot {
        /// The player.
        to: PlayerId,
        /// The snapshot's tick.
        tick: u64,
        /// Full or delta (for the metrics).
        kind: SnapshotKind,
        /// A datagram, or a frame for the control stream.
        outgoing: Outgoing,
    },
    /// The player has left the room: its connection is the room's no more.
    Left(PlayerId),
}

/// A player in the room.
#[derive(Debug)]
struct Member {
    name: String,
    inbox: Arc<Mutex<PlayerInbox>>,
    /// Buttons applied last tick (repeated when an input is missing).
    buttons: Buttons,
    /// Newest tick of this client's own input applied.
    last_applied: Option<u64>,
    /// A snapshot sent on the control stream and when, until acknowledged.
    stream_pending: Option<(u64, Instant)>,
    /// Which connection holds it ([`Joined::generation`]).
    generation: u32,
    /// The tick its last input packet was seen at (or of its joining).
    heard_at: u64,
    /// Its inbox's packet count when last seen.
    packets_seen: u64,
    /// Its inbox's packet count when it was last sent a snapshot.
    packets_at_snapshot: u64,
    /// The tick of the last snapshot sent to it.
    last_snapshot: Option<u64>,
    /// A connection holds it (false: lost, kept for a resume).
    attached: bool,
}

impl Member {
    /// A member held by a new connection (of `generation`) from `tick`,
    /// its inputs going to `inbox`.
    fn attach(&mut self, inbox: Arc<Mutex<PlayerInbox>>, generation: u32, tick: u64) {
        self.inbox = inbox;
        self.buttons = Buttons::NONE;
        self.last_applied = None;
        self.stream_pending = None;
        self.generation = generation;
        self.attached = true;
        self.heard_at = tick;
        self.packets_seen = 0;
        self.packets_at_snapshot = 0;
        self.last_snapshot = None;
    }

    /// The acknowledged baseline and the timing to report in a snapshot
    /// at `tick`, or `None` when the client is quiet and this snapshot
    /// would change nothing for it.
    fn snapshot_due(
        &mut self,
        tick: u64,
        quiet_max: u64,
        snapshots: &RoomSnapshots,
    ) -> Option<(Option<u64>, i16)> {
        let mut inbox = lock(&self.inbox);
        let quiet = inbox.packets == self.packets_at_snapshot
            && self.stream_pending.is_none()
            && self.last_snapshot.is_some_and(|p| {
                tick.saturating_sub(p) < quiet_max && snapshots.unchanged_since(p)
            })
            && inbox.ack.is_some_and(|a| snapshots.unchanged_since(a));
        if quiet {
            return None;
        }
        self.packets_at_snapshot = inbox.packets;
        Some((inbox.ack, inbox.take_timing()))
    }
}

/// One room: its game, its players and what they are sent.
pub struct RoomLogic {
    config: RoomConfig,
    game: Game,
    members: BTreeMap<PlayerId, Member>,
    inputs: Vec<(PlayerId, Buttons)>,
    snapshots: RoomSnapshots,
    metrics: Arc<Metrics>,
    starvation: Counter,
    actions: Vec<Action>,
}

impl RoomLogic {
    /// A room playing `game`, counting into `metrics` (its series labelled
    /// with the room's name).
    pub fn new(game: Game, config: RoomConfig, metrics: Arc<Metrics>) -> RoomLogic {
        let label = RoomLabel {
            room: config.name.clone(),
        };
        RoomLogic {
            starvation: metrics.input_starvation.get_or_create_owned(&label),
            snapshots: RoomSnapshots::new(config.history),
            game,
            members: BTreeMap::new(),
            inputs: Vec::new(),
            metrics,
            config,
            actions: Vec::new(),
        }
    }

    /// How the room runs.
    pub fn config(&self) -> &RoomConfig {
        &self.config
    }

    /// The game.
    pub fn game(&self) -> &Game {
        &self.game
    }

    /// Players in the room (attached or kept for a resume).
    pub fn players(&self) -> usize {
        self.members.len()
    }

    /// The room's progress now.
    pub fn status(&self) -> RoomStatus {
        RoomStatus {
            tick: self.game.tick(),
            state_hash: self.game.state_hash(),
            players: self.members.len(),
        }
    }

    /// Moves the actions decided so far to the end of `into`, in order.
    pub fn take_actions(&mut self, into: &mut Vec<Action>) {
        into.append(&mut self.actions);
    }

    /// Adds a player named `name`: a `Roster` for it, a `PlayerJoined` for
    /// the others. Refused when the room is full, the name is taken (by
    /// [`name_key`]) or the game refuses the player.
    pub fn join(&mut self, player_id: PlayerId, name: String) -> Result<Joined, RejectReason> {
        if self.members.len() >= self.config.max_players {
            return Err(RejectReason::RoomFull);
        }
        let key = name_key(&name);
        if let Some(taken) = self.members.values().find(|m| name_key(&m.name) == key) {
            return Err(RejectReason::Other {
                reason: format!(
                    "the name \"{name}\" is taken in this room (by \"{}\"; names must differ by \
                     more than case or look-alike letters): choose another with --name",
                    taken.name
                ),
            });
        }
        if let Err(e) = self.game.add_player(player_id) {
            warn!(%player_id, "game refused the player: {e}");
            return Err(RejectReason::Other {
                reason: "the game refused the player".into(),
            });
        }
        if let Some(r) = &self.config.record {
            r.join(player_id);
        }
        let tick = self.game.tick();
        let inbox = Arc::new(Mutex::new(PlayerInbox::new(self.config.input_window, tick)));
        info!(room = %self.config.name, %player_id, %name, tick, "player joined");
        let member = Member {
            name,
            inbox: inbox.clone(),
            buttons: Buttons::NONE,
            last_applied: None,
            stream_pending: None,
            generation: 0,
            attached: true,
            heard_at: tick,
            packets_seen: 0,
            packets_at_snapshot: 0,
            last_snapshot: None,
        };
        self.members.insert(player_id, member);
        self.announce_join(player_id);
        Ok(Joined {
            welcome: self.welcome(player_id, tick),
            inbox,
            generation: 0,
        })
    }

    /// Removes a player, if connection `generation` still holds it (no-op
    /// if unknown).
    pub fn leave(&mut self, player_id: PlayerId, generation: u32) {
        if self
            .members
            .get(&player_id)
            .is_some_and(|m| m.generation == generation)
        {
            self.remove(player_id);
        }
    }

    /// Keeps a player whose connection (of `generation`) was lost: it stays
    /// in the game, standing still, and gets nothing sent until
    /// [`RoomLogic::rejoin`] or [`RoomLogic::leave`].
    pub fn detach(&mut self, player_id: PlayerId, generation: u32) {
        let tick = self.game.tick();
        let window = self.config.input_window;
        if let Some(m) = self.members.get_mut(&player_id) {
            if m.generation == generation && m.attached {
                info!(room = %self.config.name, %player_id, "connection lost; keeping the player");
                m.attached = false;
                m.buttons = Buttons::NONE;
                m.inbox = Arc::new(Mutex::new(PlayerInbox::new(window, tick)));
                m.packets_seen = 0;
                m.packets_at_snapshot = 0;
                m.last_snapshot = None;
            }
        }
    }

    /// Hands a kept (or still attached) player to a new connection (a
    /// resumed session): the same body, a new inbox, a new generation, and
    /// a `Roster` of the room as it is now. `None` if the player is gone.
    pub fn rejoin(&mut self, player_id: PlayerId) -> Option<Resumed> {
        let tick = self.game.tick();
        let inbox = Arc::new(Mutex::new(PlayerInbox::new(self.config.input_window, tick)));
        let m = self.members.get_mut(&player_id)?;
        let close_old = m.attached;
        let generation = m.generation + 1;
        m.attach(inbox.clone(), generation, tick);
        info!(room = %self.config.name, %player_id, generation, tick, "player resumed");
        // The room as it is now: who joined and left meanwhile.
        self.send_roster(player_id);
        Some(Resumed {
            joined: Joined {
                welcome: self.welcome(player_id, tick),
                inbox,
                generation,
            },
            close_old,
        })
    }

    /// The connection that resumed player `player_id` (as `generation`) was
    /// gone before it got the player: the player is lost again (kept, sent
    /// nothing).
    pub fn resumer_gone(&mut self, player_id: PlayerId, generation: u32) {
        let m = self.members.get_mut(&player_id);
        if let Some(m) = m.filter(|m| m.generation == generation) {
            m.attached = false;
        }
    }

    /// Relays a chat line to everyone in the room.
    pub fn chat(&mut self, from: PlayerId, text: String) {
        self.broadcast(&ServerControl::Chat { from, text });
    }

    /// Runs one tick at `now`. `datagram_size` is a player's connection's
    /// largest datagram now (`None`: datagrams unavailable).
    pub fn tick(&mut self, now: Instant, datagram_size: impl Fn(PlayerId) -> Option<usize>) {
        let tick = self.game.tick();
        self.take_inputs(tick);
        self.remove_idle(tick);
        self.game.step(&self.inputs);
        if let Some(r) = &self.config.record {
            r.tick(tick, &self.inputs, || self.game.state_hash());
        }
        if tick % u64::from(self.config.tick_rate.max(1)) == 0 {
            // Once a second: reading quinn's statistics takes the
            // connection's lock.
            for (&id, _) in self.members.iter().filter(|(_, m)| m.attached) {
                self.actions.push(Action::SampleWire(id));
            }
        }
        let interval = u64::from(self.config.snapshot_interval.max(1));
        if self.game.tick() % interval == 0 && !self.members.is_empty() {
            self.send_snapshots(now, &datagram_size);
        }
    }

    /// The snapshot of `tick` went to player `to` as a datagram.
    pub fn datagram_sent(&mut self, to: PlayerId, tick: u64) {
        if let Some(m) = self.members.get_mut(&to) {
            m.last_snapshot = Some(tick);
        }
    }

    /// The snapshot of `tick` was queued on player `to`'s control stream at
    /// `at` (the `now` of its tick): none goes there again until it is
    /// acknowledged or [`STREAM_SNAPSHOT_RESEND`] has passed.
    pub fn stream_queued(&mut self, to: PlayerId, tick: u64, at: Instant) {
        if let Some(m) = self.members.get_mut(&to) {
            m.last_snapshot = Some(tick);
            m.stream_pending = Some((tick, at));
        }
    }

    /// Takes each player's input for `tick` from its inbox, or repeats its
    /// last one (counting the starvation once it has sent any).
    fn take_inputs(&mut self, tick: u64) {
        self.inputs.clear();
        for (&id, m) in &mut self.members {
            let mut inbox = lock(&m.inbox);
            if inbox.packets != m.packets_seen {
                m.packets_seen = inbox.packets;
                m.heard_at = tick;
            }
            match inbox.inputs.take(tick) {
                Some(buttons) => {
                    m.buttons = buttons;
                    m.last_applied = Some(tick);
                }
                None if inbox.received_any => {
                    self.starvation.inc();
                }
                None => {}
            }
            drop(inbox);
            self.inputs.push((id, m.buttons));
        }
    }

    /// The `Welcome` for player `player_id` at `tick`.
    fn welcome(&self, player_id: PlayerId, tick: u64) -> Welcome {
        Welcome {
            player_id,
            room: self.config.name.clone(),
            level_id: self.config.level_id.clone(),
            level_hash: self.config.level_hash,
            level: self.config.level,
            server_tick: tick,
            timing: NetTiming {
                tick_rate: self.config.tick_rate,
                snapshot_interval: self.config.snapshot_interval,
                input_redundancy: self.config.input_redundancy,
            },
            // The game's constants, so the client predicts with exactly
            // the server's rules (a GameConfig is a few dozen bytes).
            sim_config: match encode_sim_config(self.game.config()) {
                Ok(bytes) => bytes,
                Err(e) => {
                    warn!("cannot send the game config: {e}");
                    Vec::new()
                }
            },
            session_token: SessionToken::default(),
        }
    }

    fn remove(&mut self, player_id: PlayerId) {
        if let Some(member) = self.members.remove(&player_id) {
            let removed = self.game.remove_player(player_id);
            if let (true, Some(r)) = (removed, &self.config.record) {
                r.leave(player_id);
            }
            info!(room = %self.config.name, %player_id, name = %member.name, "player left");
            self.broadcast(&ServerControl::PlayerLeft { id: player_id });
            self.actions.push(Action::Left(player_id));
        }
    }

    /// Removes the connected players that sent no input for the idle time
    /// (half of it while the room is full): a silent client must not
    /// hold a seat. Each gets a `Notice{Kick}` and a close saying why.
    fn remove_idle(&mut self, tick: u64) {
        let mut limit = self.config.idle_kick;
        if self.members.len() >= self.config.max_players {
            limit /= 2;
        }
        let limit = (limit.as_secs_f64() * f64::from(self.config.tick_rate)) as u64;
        let idle: Vec<PlayerId> = self
            .members
            .iter()
            .filter(|(_, m)| m.attached && tick.saturating_sub(m.heard_at) > limit)
            .map(|(&id, _)| id)
            .collect();
        if idle.is_empty() {
            return;
        }
        let secs = self.config.idle_kick.as_secs_f32();
        let reason = format!("no input for {secs:.0} s (or half of it in a full room)");
        for id in idle {
            let kick = ServerControl::Notice {
                kind: NoticeKind::Kick {
                    reason: reason.clone(),
                },
            };
            self.send_control(id, &kick);
            self.actions.push(Action::Kick {
                to: id,
                reason: reason.clone(),
            });
            info!(room = %self.config.name, player = %id, "removed: {reason}");
            self.metrics
                .kicks
                .get_or_create(&KickLabel {
                    reason: KickReason::Idle,
                })
                .inc();
            self.remove(id);
        }
        self.inputs.retain(|(id, _)| self.members.contains_key(id));
    }

    /// Captures the snapshot of the tick just run and decides what each
    /// attached player is sent.
    fn send_snapshots(&mut self, now: Instant, datagram_size: &dyn Fn(PlayerId) -> Option<usize>) {
        let tick = self.game.tick();
        let state = self.game.snapshot();
        if let Err(e) = self.snapshots.capture(tick, state.entities) {
            error!(room = %self.config.name, tick, "cannot capture a snapshot: {e}");
            return;
        }
        let quiet_max = (QUIET_MAX.as_secs_f64() * f64::from(self.config.tick_rate)) as u64;
        for (&id, m) in self.members.iter_mut().filter(|(_, m)| m.attached) {
            let Some((ack, timing)) = m.snapshot_due(tick, quiet_max, &self.snapshots) else {
                self.metrics.snapshots_skipped.inc();
                continue;
            };
            if let Some((pending, _)) = m.stream_pending {
                if ack.is_some_and(|a| a >= pending) {
                    m.stream_pending = None;
                }
            }
            let encoded = self
                .snapshots
                .encode_for(ack, m.last_snapshot, m.last_applied, timing);
            let snapshot = match encoded {
                Ok(s) => s,
                Err(e) => {
                    error!(tick, "cannot encode a snapshot: {e}");
                    return;
                }
            };
            let kind = snapshot_kind(&snapshot);
            let max = datagram_size(id).map(|max| max.min(DATAGRAM_SEND_BUFFER / 2));
            let outgoing = match snapshot.into_outgoing(max) {
                Ok(o) => o,
                Err(e) => {
                    error!(tick, "cannot encode a snapshot: {e}");
                    continue;
                }
            };
            if matches!(outgoing, Outgoing::Control(_))
                && m.stream_pending
                    .is_some_and(|(_, at)| now.duration_since(at) < STREAM_SNAPSHOT_RESEND)
            {
                self.metrics.count_drop(DropReason::SnapshotDeferred);
                continue;
            }
            self.actions.push(Action::Snapshot {
                to: id,
                tick,
                kind,
                outgoing,
            });
        }
    }

    /// Tells the newcomer `id` who is in the room (a `Roster`, queued now
    /// and so written right after its `Welcome`) and everyone else that it
    /// joined.
    fn announce_join(&mut self, id: PlayerId) {
        self.send_roster(id);
        let Some(joined) = self.members.get_key_value(&id).map(roster_entry) else {
            return;
        };
        let mut frame = Vec::new();
        if write_frame(&ServerControl::PlayerJoined(joined), &mut frame).is_ok() {
            for (&other, _) in self.members.iter().filter(|(&other, _)| other != id) {
                self.actions.push(Action::Control {
                    to: other,
                    frame: frame.clone(),
                });
            }
        }
    }

    /// Queues a `Roster` of the room as it is now for member `id`.
    fn send_roster(&mut self, id: PlayerId) {
        let players = self
            .members
            .iter()
            .take(MAX_ROSTER)
            .map(roster_entry)
            .collect();
        if self.members.contains_key(&id) {
            self.send_control(id, &ServerControl::Roster { players });
        }
    }

    /// Queues `message` for member `id`'s control stream.
    fn send_control(&mut self, id: PlayerId, message: &ServerControl) {
        let mut frame = Vec::new();
        if write_frame(message, &mut frame).is_ok() {
            self.actions.push(Action::Control { to: id, frame });
        }
    }

    /// Queues `message` for every member's control stream.
    fn broadcast(&mut self, message: &ServerControl) {
        let mut frame = Vec::new();
        if write_frame(message, &mut frame).is_ok() {
            for &to in self.members.keys() {
                self.actions.push(Action::Control {
                    to,
                    frame: frame.clone(),
                });
            }
        }
    }
}

/// Whether a snapshot is a delta or a full one.
fn snapshot_kind(snapshot: &Snapshot) -> SnapshotKind {
    if snapshot.baseline_tick.is_some() {
        SnapshotKind::Delta
    } else {
        SnapshotKind::Full
    }
}

/// A member as the roster lists it.
fn roster_entry((&id, m): (&PlayerId, &Member)) -> RosterEntry {
    RosterEntry {
        id,
        name: m.name.clone(),
    }
}
