//! A room: one authoritative [`Game`], its fixed-step tick loop, and the
//! snapshots it sends its players.
//!
//! The room runs as its own task and owns its game outright; connection
//! tasks talk to it through a [`RoomHandle`] (join, leave, chat) and drop
//! each client's decoded inputs into that client's [`PlayerInbox`], which
//! the room drains one tick at a time. The loop follows a [`TickSchedule`]:
//! ticks run on an absolute grid, a stall is caught up by a bounded number
//! of ticks, and skipped ticks are logged and counted.
//!
//! Every tick: take each player's input for this tick from its inbox (or
//! repeat its last one and count the starvation), step the game, and every
//! `snapshot_interval` ticks capture a snapshot and send each player a
//! delta against the snapshot it acknowledged, as a datagram when it fits
//! and on the control stream when it does not.
//!
//! A quiet client (one that sent nothing since its last snapshot, holding
//! its buttons: [`InputPacket::hold`]) gets no snapshot that would change
//! nothing for it: nothing but time changed since both the one it
//! acknowledged and the last one it was sent
//! (`StateSnapshot::extrapolates_to`). It gets one again when it speaks,
//! when anything changes, or after [`QUIET_MAX`]. An idle room then costs a
//! few packets a second per player instead of 30 snapshots and their ACKs.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use ledge_shared::game::Game;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{
    encode_sim_config, name_key, write_frame, CloseCode, InputPacket, LevelOffer, NetTiming,
    NoticeKind, Outgoing, PlayerId, RejectReason, RosterEntry, ServerControl, SessionToken,
    Welcome, MAX_ROSTER,
};
use prometheus_client::metrics::counter::Counter;
use prometheus_client::metrics::histogram::Histogram;
use tokio::sync::{mpsc, oneshot, watch};
use tokio::task::JoinHandle;
use tracing::{debug, error, info, warn};

use crate::clock::TickSchedule;
use crate::inputs::{InputBuffer, Received};
use crate::link::{DatagramError, Link, Wire};
use crate::metrics::{
    Channel, ClientBytes, DropReason, KickLabel, KickReason, Metrics, RoomLabel, SnapshotKind,
    SnapshotLabel,
};
use crate::record::Recorder;
use crate::snapshots::RoomSnapshots;
use crate::tls::DATAGRAM_SEND_BUFFER;

/// How long the room waits for a client to acknowledge a snapshot sent on
/// the control stream before it sends another one there.
const STREAM_SNAPSHOT_RESEND: Duration = Duration::from_millis(1000);

/// Longest a client goes without a snapshot while nothing changes (should
/// its own quiet inputs, 5 a second, be lost): its clock and loss figure
/// keep a sample, its acknowledged baseline stays in the room's history,
/// and the client, which calls a server silent for 1 s stalled, never does.
pub const QUIET_MAX: Duration = Duration::from_millis(500);

/// Something for a client's control-stream writer.
#[derive(Debug)]
pub enum Outbound {
    /// A complete frame (length prefix included).
    Frame(Vec<u8>),
    /// Finish the stream after what was queued before, wait (briefly) until
    /// the client has it, and stop.
    Finish,
    /// Like `Finish`, then close the connection with this code and reason
    /// (the room removing a player: what was queued, a kick notice, arrives
    /// first).
    Close(CloseCode, String),
}

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

/// What a connection gives the room to reach its client.
#[derive(Debug, Clone)]
pub struct ClientLink {
    /// The connection (any transport), for snapshot datagrams and closing.
    pub link: Link,
    /// The client's control-stream writer.
    pub control: mpsc::Sender<Outbound>,
    /// The client's byte counters.
    pub bytes: ClientBytes,
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

/// Why a join failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum JoinError {
    /// The room refused (full, or the game refused the player).
    #[error("{0}")]
    Rejected(RejectReason),
    /// The room task has stopped (the server is shutting down).
    #[error("the room has stopped")]
    Closed,
}

/// Requests to the room task.
#[derive(Debug)]
enum Command {
    Join {
        player_id: PlayerId,
        name: String,
        link: ClientLink,
        reply: oneshot::Sender<Result<Joined, RejectReason>>,
    },
    Leave {
        player_id: PlayerId,
        generation: u32,
    },
    Detach {
        player_id: PlayerId,
        generation: u32,
    },
    Rejoin {
        player_id: PlayerId,
        link: ClientLink,
        reply: oneshot::Sender<Option<Joined>>,
    },
    Chat {
        from: PlayerId,
        text: String,
    },
}

/// A cheap, cloneable way to talk to a running room. The room stops when
/// the last handle is dropped.
#[derive(Debug, Clone)]
pub struct RoomHandle {
    name: Arc<str>,
    commands: mpsc::UnboundedSender<Command>,
    players: Arc<AtomicUsize>,
    max_players: usize,
    status: watch::Receiver<RoomStatus>,
}

impl RoomHandle {
    /// The room's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Players in the room now (or about to be).
    pub fn players(&self) -> usize {
        self.players.load(Ordering::Relaxed)
    }

    /// Whether the room has a free place now.
    pub fn has_room(&self) -> bool {
        self.players() < self.max_players
    }

    /// Adds a player. Commands are unbounded but each connection sends one
    /// join, one leave and rate-limited chat, so the queue stays small.
    pub async fn join(
        &self,
        player_id: PlayerId,
        name: String,
        link: ClientLink,
    ) -> Result<Joined, JoinError> {
        let (reply, answer) = oneshot::channel();
        self.commands
            .send(Command::Join {
                player_id,
                name,
                link,
                reply,
            })
            .map_err(|_| JoinError::Closed)?;
        match answer.await {
            Ok(Ok(joined)) => Ok(joined),
            Ok(Err(reason)) => Err(JoinError::Rejected(reason)),
            Err(_) => Err(JoinError::Closed),
        }
    }

    /// Removes a player, if connection `generation` still holds it (no-op
    /// if unknown or the room has stopped).
    pub fn leave(&self, player_id: PlayerId, generation: u32) {
        let _ = self.commands.send(Command::Leave {
            player_id,
            generation,
        });
    }

    /// Keeps a player whose connection (of `generation`) was lost: it stays
    /// in the game, standing still, and gets nothing sent until
    /// [`RoomHandle::rejoin`] or [`RoomHandle::leave`].
    pub fn detach(&self, player_id: PlayerId, generation: u32) {
        let _ = self.commands.send(Command::Detach {
            player_id,
            generation,
        });
    }

    /// Gives player `player_id` to a new connection (a resumed session):
    /// the same body, a new link and inbox, a new generation; the old
    /// connection, if still open, is closed. `None` if the player is gone.
    pub async fn rejoin(&self, player_id: PlayerId, link: ClientLink) -> Option<Joined> {
        let (reply, answer) = oneshot::channel();
        self.commands
            .send(Command::Rejoin {
                player_id,
                link,
                reply,
            })
            .ok()?;
        answer.await.ok().flatten()
    }

    /// Relays a chat line to everyone in the room.
    pub fn chat(&self, from: PlayerId, text: String) {
        let _ = self.commands.send(Command::Chat { from, text });
    }

    /// The latest published status.
    pub fn status(&self) -> RoomStatus {
        *self.status.borrow()
    }
}

/// Starts a room owning `game` on the current tokio runtime.
pub fn spawn(
    game: Game,
    config: RoomConfig,
    metrics: Arc<Metrics>,
) -> (RoomHandle, JoinHandle<()>) {
    let (commands, command_rx) = mpsc::unbounded_channel();
    let (status_tx, status) = watch::channel(RoomStatus {
        tick: game.tick(),
        state_hash: game.state_hash(),
        players: 0,
    });
    let players = Arc::new(AtomicUsize::new(0));
    let label = RoomLabel {
        room: config.name.clone(),
    };
    let room = Room {
        tick_duration: metrics.tick_duration.get_or_create_owned(&label),
        missed_ticks: metrics.missed_ticks.get_or_create_owned(&label),
        starvation: metrics.input_starvation.get_or_create_owned(&label),
        players_gauge: metrics.players.get_or_create_owned(&label),
        game,
        members: BTreeMap::new(),
        inputs: Vec::new(),
        snapshots: RoomSnapshots::new(config.history),
        players: players.clone(),
        commands: command_rx,
        status: status_tx,
        metrics,
        config: config.clone(),
    };
    let handle = RoomHandle {
        name: config.name.as_str().into(),
        commands,
        players,
        max_players: config.max_players,
        status,
    };
    (handle, tokio::spawn(room.run()))
}

/// Counts a snapshot datagram sent to a client.
fn record_snapshot(metrics: &Metrics, bytes: &ClientBytes, kind: SnapshotKind, len: usize) {
    metrics.sent(bytes, Channel::Datagram, len);
    metrics
        .snapshot_bytes
        .get_or_create(&SnapshotLabel {
            kind,
            channel: Channel::Datagram,
        })
        .observe(len as f64);
}

/// A player in the room.
#[derive(Debug)]
struct Member {
    name: String,
    link: ClientLink,
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
    /// Its connection's UDP totals at the last sample.
    wire: Wire,
}

/// The room task's state.
struct Room {
    config: RoomConfig,
    game: Game,
    members: BTreeMap<PlayerId, Member>,
    inputs: Vec<(PlayerId, Buttons)>,
    snapshots: RoomSnapshots,
    players: Arc<AtomicUsize>,
    commands: mpsc::UnboundedReceiver<Command>,
    status: watch::Sender<RoomStatus>,
    metrics: Arc<Metrics>,
    tick_duration: Histogram,
    missed_ticks: Counter,
    starvation: Counter,
    players_gauge: prometheus_client::metrics::gauge::Gauge,
}

impl Room {
    async fn run(mut self) {
        let rate = self.config.tick_rate.max(1);
        let mut schedule = TickSchedule::new(Instant::now(), rate, self.config.max_catch_up);
        info!(room = %self.config.name, tick_rate = rate, "room started");
        loop {
            let deadline = tokio::time::Instant::from_std(schedule.next_deadline());
            tokio::select! {
                command = self.commands.recv() => match command {
                    Some(command) => self.handle(command),
                    None => break,
                },
                () = tokio::time::sleep_until(deadline) => {
                    let now = Instant::now();
                    let late = now.saturating_duration_since(deadline.into_std());
                    self.metrics.tick_lateness.observe(late.as_secs_f64());
                    let due = schedule.poll(now);
                    for _ in 0..due.run {
                        self.tick();
                    }
                    if due.skipped > 0 {
                        self.missed_ticks.inc_by(due.skipped);
                        warn!(
                            room = %self.config.name,
                            caught_up = due.run,
                            skipped = due.skipped,
                            tick = self.game.tick(),
                            "tick loop fell behind; skipped ticks"
                        );
                    } else if due.run > 1 {
                        debug!(room = %self.config.name, caught_up = due.run, "tick loop caught up");
                    }
                    self.publish();
                }
            }
        }
        self.players_gauge.set(0);
        info!(room = %self.config.name, tick = self.game.tick(), "room stopped");
    }

    fn handle(&mut self, command: Command) {
        match command {
            Command::Join {
                player_id,
                name,
                link,
                reply,
            } => {
                let answer = self.join(player_id, name, link);
                let joined = answer.is_ok();
                // The joiner may have gone while the command was queued.
                if reply.send(answer).is_err() && joined {
                    debug!(%player_id, "joiner gone before the welcome");
                    self.remove(player_id);
                }
            }
            Command::Leave {
                player_id,
                generation,
            } => {
                if self
                    .members
                    .get(&player_id)
                    .is_some_and(|m| m.generation == generation)
                {
                    self.remove(player_id);
                }
            }
            Command::Detach {
                player_id,
                generation,
            } => {
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
            Command::Rejoin {
                player_id,
                link,
                reply,
            } => {
                let rejoined = self.rejoin(player_id, link);
                if let Err(Some(joined)) = reply.send(rejoined) {
                    // The resumer is gone already: it is lost again.
                    let m = self.members.get_mut(&player_id);
                    if let Some(m) = m.filter(|m| m.generation == joined.generation) {
                        m.attached = false;
                    }
                }
            }
            Command::Chat { from, text } => {
                let mut frame = Vec::new();
                if write_frame(&ServerControl::Chat { from, text }, &mut frame).is_err() {
                    return;
                }
                for m in self.members.values() {
                    self.send_control(m, frame.clone());
                }
            }
        }
        self.publish();
    }

    fn join(
        &mut self,
        player_id: PlayerId,
        name: String,
        link: ClientLink,
    ) -> Result<Joined, RejectReason> {
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
        self.members.insert(
            player_id,
            Member {
                name,
                link,
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
                wire: Wire::default(),
            },
        );
        self.players.store(self.members.len(), Ordering::Relaxed);
        self.players_gauge.set(self.members.len() as i64);
        self.announce_join(player_id);
        Ok(Joined {
            welcome: self.welcome(player_id, tick),
            inbox,
            generation: 0,
        })
    }

    /// Hands a kept (or still attached) player to a new connection.
    fn rejoin(&mut self, player_id: PlayerId, link: ClientLink) -> Option<Joined> {
        let tick = self.game.tick();
        let inbox = Arc::new(Mutex::new(PlayerInbox::new(self.config.input_window, tick)));
        let m = self.members.get_mut(&player_id)?;
        if m.attached {
            // The client gave up on it before we noticed.
            m.link.link.close(CloseCode::Normal, "resumed elsewhere");
        }
        m.link = link;
        m.wire = Wire::default();
        m.inbox = inbox.clone();
        m.buttons = Buttons::NONE;
        m.last_applied = None;
        m.stream_pending = None;
        m.generation += 1;
        m.attached = true;
        m.heard_at = tick;
        m.packets_seen = 0;
        m.packets_at_snapshot = 0;
        m.last_snapshot = None;
        let generation = m.generation;
        info!(room = %self.config.name, %player_id, generation, tick, "player resumed");
        // The room as it is now: who joined and left meanwhile.
        self.send_roster(player_id);
        Some(Joined {
            welcome: self.welcome(player_id, tick),
            inbox,
            generation,
        })
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
        }
        self.players.store(self.members.len(), Ordering::Relaxed);
        self.players_gauge.set(self.members.len() as i64);
    }

    fn tick(&mut self) {
        let started = Instant::now();
        let tick = self.game.tick();
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
        self.remove_idle(tick);
        self.game.step(&self.inputs);
        if let Some(r) = &self.config.record {
            r.tick(tick, &self.inputs, || self.game.state_hash());
        }
        if tick % u64::from(self.config.tick_rate.max(1)) == 0 {
            self.sample_wire();
        }
        let interval = u64::from(self.config.snapshot_interval.max(1));
        if self.game.tick() % interval == 0 && !self.members.is_empty() {
            self.send_snapshots();
        }
        let took = started.elapsed().as_secs_f64();
        self.tick_duration.observe(took);
        self.metrics.tick_duration_fine.observe(took);
    }

    /// Adds what each player's connection put through its socket since the
    /// last sample to the wire metrics (once a second: reading quinn's
    /// statistics takes the connection's lock).
    fn sample_wire(&mut self) {
        for m in self.members.values_mut().filter(|m| m.attached) {
            if let Some(now) = m.link.link.wire() {
                self.metrics.wire(&mut m.wire, now);
            }
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
            if let Some(m) = self.members.get(&id) {
                let mut frame = Vec::new();
                let kick = ServerControl::Notice {
                    kind: NoticeKind::Kick {
                        reason: reason.clone(),
                    },
                };
                if write_frame(&kick, &mut frame).is_ok() {
                    self.send_control(m, frame);
                }
                let close = Outbound::Close(CloseCode::Kicked, reason.clone());
                if m.link.control.try_send(close).is_err() {
                    // Its queue is full (it reads nothing): close at once.
                    m.link.link.close(CloseCode::Kicked, &reason);
                }
            }
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

    fn send_snapshots(&mut self) {
        let tick = self.game.tick();
        let state = self.game.snapshot();
        if let Err(e) = self.snapshots.capture(tick, state.entities) {
            error!(room = %self.config.name, tick, "cannot capture a snapshot: {e}");
            return;
        }
        let now = Instant::now();
        let quiet_max = (QUIET_MAX.as_secs_f64() * f64::from(self.config.tick_rate)) as u64;
        for m in self.members.values_mut().filter(|m| m.attached) {
            let (ack, timing) = {
                let mut inbox = lock(&m.inbox);
                let quiet = inbox.packets == m.packets_at_snapshot
                    && m.stream_pending.is_none()
                    && m.last_snapshot.is_some_and(|p| {
                        tick.saturating_sub(p) < quiet_max && self.snapshots.unchanged_since(p)
                    })
                    && inbox.ack.is_some_and(|a| self.snapshots.unchanged_since(a));
                if quiet {
                    self.metrics.snapshots_skipped.inc();
                    continue;
                }
                m.packets_at_snapshot = inbox.packets;
                (inbox.ack, inbox.take_timing())
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
            let kind = if snapshot.baseline_tick.is_some() {
                SnapshotKind::Delta
            } else {
                SnapshotKind::Full
            };
            let max = m
                .link
                .link
                .max_datagram_size()
                .map(|max| max.min(DATAGRAM_SEND_BUFFER / 2));
            let outgoing = match snapshot.into_outgoing(max) {
                Ok(o) => o,
                Err(e) => {
                    error!(tick, "cannot encode a snapshot: {e}");
                    continue;
                }
            };
            match outgoing {
                Outgoing::Datagram(bytes) => {
                    let len = bytes.len();
                    match m.link.link.send_datagram(bytes.into()) {
                        Ok(()) => {
                            m.last_snapshot = Some(tick);
                            record_snapshot(&self.metrics, &m.link.bytes, kind, len);
                        }
                        Err(DatagramError::Lost) => {}
                        Err(DatagramError::Failed(e)) => {
                            debug!(tick, "snapshot datagram not sent: {e}");
                            self.metrics.count_drop(DropReason::SnapshotSendFailed);
                        }
                    }
                }
                Outgoing::Control(frame) => {
                    if m.stream_pending
                        .is_some_and(|(_, at)| now.duration_since(at) < STREAM_SNAPSHOT_RESEND)
                    {
                        self.metrics.count_drop(DropReason::SnapshotDeferred);
                        continue;
                    }
                    let len = frame.len();
                    match m.link.control.try_send(Outbound::Frame(frame)) {
                        Ok(()) => {
                            m.last_snapshot = Some(tick);
                            m.stream_pending = Some((tick, now));
                            // Bytes are counted by the writer when written.
                            self.metrics
                                .snapshot_bytes
                                .get_or_create(&SnapshotLabel {
                                    kind,
                                    channel: Channel::Stream,
                                })
                                .observe(len as f64);
                        }
                        Err(e) => self.metrics.count_queue_error::<Outbound>(Err(e)),
                    }
                }
            }
        }
    }

    /// Tells the newcomer `id` who is in the room (a `Roster`, queued now
    /// and so written right after its `Welcome`) and everyone else that it
    /// joined.
    fn announce_join(&self, id: PlayerId) {
        self.send_roster(id);
        let Some(joined) = self.members.get_key_value(&id).map(roster_entry) else {
            return;
        };
        let mut frame = Vec::new();
        if write_frame(&ServerControl::PlayerJoined(joined), &mut frame).is_ok() {
            for (_, m) in self.members.iter().filter(|(&other, _)| other != id) {
                self.send_control(m, frame.clone());
            }
        }
    }

    /// Queues a `Roster` of the room as it is now for member `id`.
    fn send_roster(&self, id: PlayerId) {
        let players = self
            .members
            .iter()
            .take(MAX_ROSTER)
            .map(roster_entry)
            .collect();
        let mut frame = Vec::new();
        if let (Some(m), Ok(())) = (
            self.members.get(&id),
            write_frame(&ServerControl::Roster { players }, &mut frame),
        ) {
            self.send_control(m, frame);
        }
    }

    /// Sends `message` to every member's control stream.
    fn broadcast(&self, message: &ServerControl) {
        let mut frame = Vec::new();
        if write_frame(message, &mut frame).is_ok() {
            for m in self.members.values() {
                self.send_control(m, frame.clone());
            }
        }
    }

    /// Queues a frame for a member's control stream; drops it (counted)
    /// when that client's queue is full.
    fn send_control(&self, m: &Member, frame: Vec<u8>) {
        let sent = m.link.control.try_send(Outbound::Frame(frame));
        self.metrics.count_queue_error(sent);
    }

    fn publish(&self) {
        self.status.send_replace(RoomStatus {
            tick: self.game.tick(),
            state_hash: self.game.state_hash(),
            players: self.members.len(),
        });
    }
}

/// A member as the roster lists it.
fn roster_entry((&id, m): (&PlayerId, &Member)) -> RosterEntry {
    RosterEntry {
        id,
        name: m.name.clone(),
    }
}
