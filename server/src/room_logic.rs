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

use ledge_shared::game::{Game, GameEvent};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{
    clip_text, encode_sim_config, name_key, write_frame, InputPacket, LevelOffer, NetTiming,
    NoticeKind, Outgoing, PlayerId, RejectReason, RosterEntry, ServerControl, SessionToken,
    Snapshot, Welcome, MAX_REASON_LEN, MAX_ROSTER,
};
use ledge_shared::replay::{ReplayHeader, MAX_LEVEL_NAME_LEN};
use prometheus_client::metrics::counter::Counter;
use tracing::{error, info, warn};

use crate::config::RotationConfig;
use crate::inputs::{InputBuffer, Received};
use crate::levels::LevelSet;
use crate::metrics::{DropReason, KickLabel, KickReason, Metrics, RoomLabel, SnapshotKind};
use crate::record::Recorder;
use crate::records::{FinishedRun, RecordsHandle};
use crate::replays::recording::ToSave;
use crate::replays::{MatchRecording, ReplaysHandle};
use crate::rotation::Rotation;
use crate::snapshots::RoomSnapshots;
use crate::tls::DATAGRAM_SEND_BUFFER;

/// The slowest download a level change allows for before a silent
/// client counts as idle, bytes a second.
pub const LEVEL_DOWNLOAD_FLOOR: u64 = 256 * 1024;

/// Longest extra silence a level change allows for its download.
pub const MAX_DOWNLOAD_GRACE: Duration = Duration::from_secs(120);

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
    /// This server's instance (random at start): with the room, player
    /// and tick, the key of a finished run in the records.
    pub instance: String,
    /// Where finished runs go ([`crate::records`]).
    pub records: RecordsHandle,
    /// Where replays go ([`crate::replays`]); the room records its
    /// matches only when they are on.
    pub replays: ReplaysHandle,
    /// Most spectators at once (they take no player's place).
    pub max_spectators: usize,
    /// The levels the room plays in turn (`level_id`, `level_hash` and
    /// `level` above are the current one's).
    pub levels: LevelSet,
    /// When the room moves to its next level, and how players vote.
    pub rotation: RotationConfig,
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
    /// The level being played (an index into [`RoomConfig::levels`]).
    pub level: usize,
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
    /// A player's run finished: store it in the records and tell the
    /// player where it stands.
    RunFinished {
        /// The player.
        to: PlayerId,
        /// The run (its finishing time still 0: the I/O side sets it).
        run: FinishedRun,
    },
    /// Save a replay (a run's, or a match's).
    SaveReplay(Box<ToSave>),
    /// The room moved to another level: send player `to` (named `name`)
    /// the new level's ghosts.
    FindGhosts {
        /// The player.
        to: PlayerId,
        /// Its name (records go by name).
        name: String,
    },
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
    /// Watching, with no body in the game.
    spectator: bool,
    /// After a level change at this tick: snapshots go on the control
    /// stream (after the `LevelChange`, so never before it) until the
    /// client acknowledges one of this tick or later.
    stream_until: Option<u64>,
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
        // A level change it has not acknowledged yet (made while it was
        // lost, say) still holds: its snapshots stay on the stream.
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
    /// The match, while anyone is in the room (replays on).
    recording: Option<MatchRecording>,
    /// Which level, which next, the votes.
    rotation: Rotation,
    /// The players and whether each finished, refilled each tick for the
    /// rotation (kept to spare an allocation a tick).
    finished: Vec<(PlayerId, bool)>,
}

impl RoomLogic {
    /// A room playing `game`, counting into `metrics` (its series labelled
    /// with the room's name).
    pub fn new(game: Game, config: RoomConfig, metrics: Arc<Metrics>) -> RoomLogic {
        let label = RoomLabel {
            room: config.name.clone(),
        };
        let recording = config
            .replays
            .is_on()
            .then(|| MatchRecording::new(replay_header(&game, &config), config.instance.clone()));
        let rotation = Rotation::new(
            config.levels.choices(),
            &config.rotation,
            config.tick_rate,
            game.tick(),
        );
        RoomLogic {
            rotation,
            recording,
            starvation: metrics.input_starvation.get_or_create_owned(&label),
            snapshots: RoomSnapshots::new(config.history),
            game,
            members: BTreeMap::new(),
            inputs: Vec::new(),
            metrics,
            config,
            actions: Vec::new(),
            finished: Vec::new(),
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
        self.members.values().filter(|m| !m.spectator).count()
    }

    /// Spectators in the room.
    pub fn spectators(&self) -> usize {
        self.members.len() - self.players()
    }

    /// The room's progress now.
    pub fn status(&self) -> RoomStatus {
        RoomStatus {
            tick: self.game.tick(),
            state_hash: self.game.state_hash(),
            players: self.players(),
            level: self.rotation.current(),
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
        if self.players() >= self.config.max_players {
            return Err(RejectReason::RoomFull);
        }
        self.check_name_free(&name)?;
        if let Some(r) = &mut self.recording {
            r.before_join(&self.game, names(&self.members));
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
        if let Some(r) = &mut self.recording {
            r.joined(player_id, &name);
        }
        info!(room = %self.config.name, %player_id, %name, tick = self.game.tick(), "player joined");
        let joined = self.add_member(player_id, name, false);
        self.announce_join(player_id);
        Ok(joined)
    }

    /// Adds a spectator named `name`: no body in the game, no player's
    /// place (the room's spectator cap instead), in no roster; it is sent
    /// the roster and the snapshots like a player.
    pub fn spectate(&mut self, id: PlayerId, name: String) -> Result<Joined, RejectReason> {
        let max = self.config.max_spectators;
        if self.spectators() >= max {
            return Err(RejectReason::Other {
                reason: format!(
                    "this room's {max} spectator places are taken: try another room, or later"
                ),
            });
        }
        self.check_name_free(&name)?;
        info!(room = %self.config.name, spectator = %id, %name, "spectator joined");
        let joined = self.add_member(id, name, true);
        self.send_roster(id);
        self.send_levels(id);
        Ok(joined)
    }

    /// Refuses a name another member's looks like ([`name_key`]).
    fn check_name_free(&self, name: &str) -> Result<(), RejectReason> {
        let key = name_key(name);
        match self.members.values().find(|m| name_key(&m.name) == key) {
            Some(taken) => Err(RejectReason::Other {
                reason: format!(
                    "the name \"{name}\" is taken in this room (by \"{}\"; names must differ by \
                     more than case or look-alike letters): choose another with --name",
                    taken.name
                ),
            }),
            None => Ok(()),
        }
    }

    /// A new member (a player already in the game, or a spectator) and
    /// what its connection needs.
    fn add_member(&mut self, id: PlayerId, name: String, spectator: bool) -> Joined {
        let tick = self.game.tick();
        let inbox = Arc::new(Mutex::new(PlayerInbox::new(self.config.input_window, tick)));
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
            spectator,
            stream_until: None,
        };
        self.members.insert(id, member);
        Joined {
            welcome: self.welcome(id, tick),
            inbox,
            generation: 0,
        }
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
        self.send_levels(player_id);
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

    /// The room stops: the match being recorded ends and is saved
    /// ([`Action::SaveReplay`]).
    pub fn stop(&mut self) {
        if let Some(done) = self.recording.as_mut().and_then(|r| r.end(&self.game)) {
            self.actions.push(Action::SaveReplay(Box::new(done)));
        }
    }

    /// Relays a chat line to everyone in the room.
    /// A spectator's line goes nowhere: it is told so (players know each
    /// other's names from the roster, which spectators are not in).
    pub fn chat(&mut self, from: PlayerId, text: String) {
        if self.members.get(&from).is_some_and(|m| m.spectator) {
            let notice = NoticeKind::Info {
                text: "spectators cannot chat: join as a player to talk".into(),
            };
            self.send_control(from, &ServerControl::Notice { kind: notice });
            return;
        }
        self.broadcast(&ServerControl::Chat { from, text });
    }

    /// Records a player's vote for the next level and tells everyone the
    /// new counts; a spectator's vote, or one the rotation refuses, is
    /// answered with why.
    pub fn vote(&mut self, from: PlayerId, level: u32) {
        let refused = match self.members.get(&from) {
            None => return,
            Some(m) if m.spectator => {
                Err("spectators cannot vote: join as a player to choose the next level".into())
            }
            Some(_) => self.rotation.vote(from, level),
        };
        match refused {
            Ok(true) => self.broadcast_levels(),
            Ok(false) => {}
            Err(text) => {
                let text = clip_text(&text, MAX_REASON_LEN);
                let notice = NoticeKind::Info { text };
                self.send_control(from, &ServerControl::Notice { kind: notice });
            }
        }
    }

    /// The players (not spectators) by id, with their names.
    pub fn player_names(&self) -> Vec<(PlayerId, String)> {
        names(&self.members)
            .map(|(id, name)| (id, name.to_owned()))
            .collect()
    }

    /// The level being played (an index into [`RoomConfig::levels`]).
    pub fn level_index(&self) -> usize {
        self.rotation.current()
    }

    /// Runs the rotation for the tick just stepped: tells everyone when
    /// its plan changes, and moves to the next level when it says so.
    fn rotate(&mut self) {
        if !self.rotation.is_on() {
            return;
        }
        let mut players = std::mem::take(&mut self.finished);
        self.fill_finished(&mut players);
        let step = self.rotation.tick(self.game.tick(), &players);
        self.finished = players;
        match step.change_to {
            Some(level) => self.change_level(level),
            None if step.changed => self.broadcast_levels(),
            None => {}
        }
    }

    /// The players by id, each with whether it finished the level (for
    /// the rare list sent; the tick reuses a buffer).
    fn finished(&self) -> Vec<(PlayerId, bool)> {
        let mut players = Vec::new();
        self.fill_finished(&mut players);
        players
    }

    /// `players`: the players by id, each with whether it finished the
    /// level.
    fn fill_finished(&self, players: &mut Vec<(PlayerId, bool)>) {
        players.clear();
        players.extend(
            self.members
                .iter()
                .filter(|(_, m)| !m.spectator)
                .map(|(&id, _)| {
                    let done = self.game.player(id).is_some_and(|v| v.place.is_some());
                    (id, done)
                }),
        );
    }

    /// Moves the room to level `index` of its rotation: the match so far is
    /// saved, a fresh game of the new level continues the tick count with
    /// every player in it again (respawned, run timers reset), and each
    /// member gets a [`ServerControl::LevelChange`], its snapshots on the
    /// control stream until it acknowledges one of the new level, the new
    /// list and (players) the new level's ghosts.
    pub fn change_level(&mut self, index: usize) {
        let tick = self.game.tick();
        if let Some(done) = self.recording.as_mut().and_then(|r| r.end(&self.game)) {
            self.actions.push(Action::SaveReplay(Box::new(done)));
        }
        let level = self.config.levels.get(index).clone();
        let mut game = level.game;
        game.start_at(tick);
        self.config.level_id = level.id;
        self.config.level_hash = level.hash;
        self.config.level = level.offer;
        if self.config.record.take().is_some() {
            info!(room = %self.config.name, "the match record stops at the level change");
        }
        self.game = game;
        self.recording = self.config.replays.is_on().then(|| {
            MatchRecording::new(
                replay_header(&self.game, &self.config),
                self.config.instance.clone(),
            )
        });
        let players = self.player_names();
        for (id, name) in &players {
            if let Some(r) = &mut self.recording {
                // The game is empty before the first: nobody to name.
                r.before_join(&self.game, std::iter::empty());
            }
            if let Err(e) = self.game.add_player(*id) {
                error!(room = %self.config.name, player = %id, "the new level refused a player: {e}");
            } else if let Some(r) = &mut self.recording {
                r.joined(*id, name);
            }
        }
        self.snapshots = RoomSnapshots::new(self.config.history);
        self.rotation.changed_to(index, tick);
        let grace = self.download_grace(level.offer.size);
        let ids: Vec<PlayerId> = self.members.keys().copied().collect();
        for id in ids {
            let welcome = self.welcome(id, tick);
            if let Some(m) = self.members.get_mut(&id) {
                m.last_snapshot = None;
                m.stream_pending = None;
                m.stream_until = Some(tick);
                // Downloading the level, a client sends no input.
                m.heard_at = m.heard_at.max(tick + grace);
                lock(&m.inbox).ack = None;
                if !m.spectator {
                    let name = m.name.clone();
                    self.actions.push(Action::FindGhosts { to: id, name });
                }
            }
            self.send_control(id, &ServerControl::LevelChange(welcome));
        }
        self.broadcast_levels();
        info!(room = %self.config.name, level = %self.config.level_id, tick, "moved to the next level");
    }

    /// Ticks a member may stay silent after a level change on top of the
    /// idle kick's, while it downloads a level of `size` bytes at
    /// [`LEVEL_DOWNLOAD_FLOOR`] (at most [`MAX_DOWNLOAD_GRACE`]).
    fn download_grace(&self, size: u64) -> u64 {
        let secs =
            (size as f64 / LEVEL_DOWNLOAD_FLOOR as f64).min(MAX_DOWNLOAD_GRACE.as_secs_f64());
        (secs * f64::from(self.config.tick_rate)) as u64
    }

    /// Queues the rotation's list for member `id` (none when the room
    /// plays one level: there is nothing to choose).
    fn send_levels(&mut self, id: PlayerId) {
        if !self.rotation.is_on() {
            return;
        }
        let list = self.rotation.list(&self.finished());
        self.send_control(id, &ServerControl::Levels(list));
    }

    /// Queues the rotation's list for every member.
    fn broadcast_levels(&mut self) {
        if !self.rotation.is_on() {
            return;
        }
        let list = self.rotation.list(&self.finished());
        self.broadcast(&ServerControl::Levels(list));
    }

    /// Runs one tick at `now`. `datagram_size` is a player's connection's
    /// largest datagram now (`None`: datagrams unavailable).
    pub fn tick(&mut self, now: Instant, datagram_size: impl Fn(PlayerId) -> Option<usize>) {
        let tick = self.game.tick();
        self.take_inputs(tick);
        self.remove_idle(tick);
        self.game.step(&self.inputs);
        if let Some(r) = &mut self.recording {
            if let Some(full) = r.stepped(&self.game, &self.inputs, names(&self.members)) {
                self.actions.push(Action::SaveReplay(Box::new(full)));
            }
        }
        self.collect_finished(tick);
        self.rotate();
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

    /// Hands each run that finished in `tick` to the records.
    fn collect_finished(&mut self, tick: u64) {
        for event in self.game.events() {
            let GameEvent::Finished {
                player,
                ticks,
                place,
            } = *event
            else {
                continue;
            };
            let Some(m) = self.members.get(&player) else {
                continue;
            };
            let view = self.game.player(player);
            let c = &self.config;
            let key = format!("{}/{}/{}/{tick}", c.instance, c.name, player.0);
            let replay = self
                .recording
                .as_ref()
                .and_then(|r| r.run(&self.game, &key, player, u64::from(ticks), place));
            let run = FinishedRun {
                key,
                level_hash: c.level.hex(),
                level_name: self.game.level_name().to_owned(),
                player: m.name.clone(),
                ticks,
                tick_rate: c.tick_rate,
                deaths: view.as_ref().map_or(0, |v| v.deaths),
                coins: view.as_ref().map_or(0, |v| v.coins),
                place,
                finished_at_ms: 0,
                replay_id: replay.as_ref().map(|r| r.id.clone()),
            };
            // Saved before the run is stored, so a record's replay exists.
            if let Some(replay) = replay {
                self.actions.push(Action::SaveReplay(Box::new(replay)));
            }
            self.actions.push(Action::RunFinished { to: player, run });
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
            if !m.spectator {
                self.inputs.push((id, m.buttons));
            }
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
        let Some(member) = self.members.remove(&player_id) else {
            return;
        };
        if member.spectator {
            info!(room = %self.config.name, spectator = %player_id, name = %member.name, "spectator left");
            self.actions.push(Action::Left(player_id));
            return;
        }
        {
            let removed = self.game.remove_player(player_id);
            if let (true, Some(r)) = (removed, &self.config.record) {
                r.leave(player_id);
            }
            if let (true, Some(r)) = (removed, &mut self.recording) {
                let empty = self.members.values().all(|m| m.spectator);
                if let Some(done) = r.left(&self.game, player_id, empty) {
                    self.actions.push(Action::SaveReplay(Box::new(done)));
                }
            }
            info!(room = %self.config.name, %player_id, name = %member.name, "player left");
            self.broadcast(&ServerControl::PlayerLeft { id: player_id });
            if self.rotation.left(player_id) {
                self.broadcast_levels();
            }
            self.actions.push(Action::Left(player_id));
        }
    }

    /// Removes the connected players that sent no input for the idle time
    /// (half of it while the room is full): a silent client must not
    /// hold a seat. Each gets a `Notice{Kick}` and a close saying why.
    fn remove_idle(&mut self, tick: u64) {
        let mut limit = self.config.idle_kick;
        if self.players() >= self.config.max_players {
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
            // After a level change, an acknowledgement of the old level's
            // ticks names no baseline: full snapshots on the stream until
            // one of the new level is acknowledged.
            let changed_at = m.stream_until.filter(|&at| ack.is_none_or(|a| a < at));
            m.stream_until = changed_at;
            let ack = ack.filter(|_| changed_at.is_none());
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
            let max = datagram_size(id)
                .filter(|_| changed_at.is_none())
                .map(|max| max.min(DATAGRAM_SEND_BUFFER / 2));
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
        self.send_levels(id);
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
            .filter(|(_, m)| !m.spectator)
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
/// The players in the room, by id and name.
fn names(members: &BTreeMap<PlayerId, Member>) -> impl Iterator<Item = (PlayerId, &str)> {
    members
        .iter()
        .filter(|(_, m)| !m.spectator)
        .map(|(&id, m)| (id, m.name.as_str()))
}

/// What every replay of the room says it is of.
fn replay_header(game: &Game, config: &RoomConfig) -> ReplayHeader {
    ReplayHeader::for_match(
        &config.name,
        (
            &config.level_id,
            &clip_text(game.level_name(), MAX_LEVEL_NAME_LEN),
            config.level,
        ),
        *game.config(),
        config.tick_rate.min(u32::from(u16::MAX)) as u16,
    )
}

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

#[cfg(test)]
mod tests {
    use super::*;

    const RIGHT: Buttons = Buttons(Buttons::RIGHT);
    const JUMP: Buttons = Buttons(Buttons::JUMP);
    const A: PlayerId = PlayerId(1);
    const B: PlayerId = PlayerId(2);
    const C: PlayerId = PlayerId(3);
    /// A datagram size every snapshot of the default level fits.
    const ROOMY: Option<usize> = Some(1200);

    fn config(max_players: usize) -> RoomConfig {
        RoomConfig {
            name: "test".into(),
            tick_rate: 60,
            snapshot_interval: 2,
            max_players,
            max_catch_up: 15,
            input_window: 64,
            input_redundancy: 16,
            history: 64,
            level_id: "default".into(),
            level_hash: 7,
            level: LevelOffer::default(),
            record: None,
            idle_kick: Duration::from_secs(30),
            instance: "test".into(),
            records: RecordsHandle::default(),
            replays: Default::default(),
            max_spectators: 2,
            levels: crate::levels::LevelSet::load(&[], None, Default::default(), 32).unwrap(),
            rotation: Default::default(),
        }
    }

    fn game() -> Game {
        Game::from_level(&ledge_levels::default_level()).unwrap()
    }

    fn room_with(config: RoomConfig) -> (RoomLogic, Arc<Metrics>) {
        let (metrics, _registry) = Metrics::new();
        (RoomLogic::new(game(), config, metrics.clone()), metrics)
    }

    fn room(max_players: usize) -> (RoomLogic, Arc<Metrics>) {
        room_with(config(max_players))
    }

    fn frame(message: &ServerControl) -> Vec<u8> {
        let mut frame = Vec::new();
        write_frame(message, &mut frame).unwrap();
        frame
    }

    fn control(to: PlayerId, message: &ServerControl) -> Action {
        Action::Control {
            to,
            frame: frame(message),
        }
    }

    fn roster(players: &[(PlayerId, &str)]) -> ServerControl {
        ServerControl::Roster {
            players: players
                .iter()
                .map(|&(id, name)| RosterEntry {
                    id,
                    name: name.into(),
                })
                .collect(),
        }
    }

    fn actions(room: &mut RoomLogic) -> Vec<Action> {
        let mut out = Vec::new();
        room.take_actions(&mut out);
        out
    }

    fn join(room: &mut RoomLogic, id: PlayerId, name: &str) -> Joined {
        let joined = room.join(id, name.into()).unwrap();
        actions(room);
        joined
    }

    /// Runs `n` ticks 16 ms apart from `t0`, every client's datagrams at
    /// most `datagram` bytes, and reports every snapshot as sent (a
    /// perfect link). Returns the actions, in order.
    fn ticks(room: &mut RoomLogic, n: u64, datagram: Option<usize>, t0: Instant) -> Vec<Action> {
        let mut all = Vec::new();
        for _ in 0..n {
            let now = t0 + Duration::from_millis(16 * room.game().tick());
            room.tick(now, |_| datagram);
            for action in actions(room) {
                if let Action::Snapshot {
                    to, tick, outgoing, ..
                } = &action
                {
                    match outgoing {
                        Outgoing::Datagram(_) => room.datagram_sent(*to, *tick),
                        Outgoing::Control(_) => room.stream_queued(*to, *tick, now),
                    }
                }
                all.push(action);
            }
        }
        all
    }

    /// The snapshots in `actions`: to whom, of which tick, full or delta,
    /// as a datagram or not.
    fn snapshots(actions: &[Action]) -> Vec<(PlayerId, u64, SnapshotKind, bool)> {
        actions
            .iter()
            .filter_map(|a| match a {
                Action::Snapshot {
                    to,
                    tick,
                    kind,
                    outgoing,
                } => Some((*to, *tick, *kind, matches!(outgoing, Outgoing::Datagram(_)))),
                _ => None,
            })
            .collect()
    }

    /// Client `joined` sends `buttons` for the ticks from `first`, and
    /// acknowledges snapshot `ack`.
    fn send(joined: &Joined, first: u64, buttons: &[Buttons], ack: Option<u64>) -> Received {
        let newest = first + buttons.len() as u64 - 1;
        let newest_first: Vec<Buttons> = buttons.iter().rev().copied().collect();
        lock(&joined.inbox).receive(&InputPacket::new(newest, &newest_first, ack))
    }

    /// The state hash of a game with `players` stepped with `steps`.
    fn reference(players: &[PlayerId], steps: &[Vec<(PlayerId, Buttons)>]) -> u64 {
        let mut game = game();
        for &id in players {
            game.add_player(id).unwrap();
        }
        for inputs in steps {
            game.step(inputs);
        }
        game.state_hash()
    }

    fn starvation(metrics: &Metrics) -> u64 {
        let label = RoomLabel {
            room: "test".into(),
        };
        metrics.input_starvation.get_or_create(&label).get()
    }

    fn dropped(metrics: &Metrics, reason: DropReason) -> u64 {
        metrics
            .dropped
            .get_or_create(&crate::metrics::DropLabel { reason })
            .get()
    }

    #[test]
    fn a_join_is_welcomed_with_a_roster_and_announced_to_the_others() {
        let (mut room, _) = room(4);
        let ann = room.join(A, "ann".into()).unwrap();
        assert_eq!(ann.generation, 0);
        let w = &ann.welcome;
        assert_eq!(
            (w.player_id, w.room.as_str(), w.server_tick),
            (A, "test", 0)
        );
        assert_eq!((w.level_id.as_str(), w.level_hash), ("default", 7));
        assert_eq!((w.timing.tick_rate, w.timing.snapshot_interval), (60, 2));
        assert_eq!(w.timing.input_redundancy, 16);
        assert_eq!(
            w.sim_config,
            encode_sim_config(room.game().config()).unwrap()
        );
        assert_eq!(w.session_token, SessionToken::default());
        assert_eq!(actions(&mut room), [control(A, &roster(&[(A, "ann")]))]);

        ticks(&mut room, 3, ROOMY, Instant::now());
        let bob = room.join(B, "bob".into()).unwrap();
        assert_eq!(bob.welcome.server_tick, 3);
        let joined = ServerControl::PlayerJoined(RosterEntry {
            id: B,
            name: "bob".into(),
        });
        assert_eq!(
            actions(&mut room),
            [
                control(B, &roster(&[(A, "ann"), (B, "bob")])),
                control(A, &joined)
            ]
        );
        assert_eq!(room.players(), 2);
        assert_eq!(room.status().players, 2);
        assert_eq!(room.game().players().count(), 2);
    }

    #[test]
    fn a_full_room_and_a_name_taken_are_refused() {
        let (mut room, _) = room(2);
        join(&mut room, A, "ann");
        let taken = room.join(B, "ANN".into()).unwrap_err();
        assert!(
            matches!(&taken, RejectReason::Other { reason } if reason.contains("is taken")),
            "{taken:?}"
        );
        join(&mut room, B, "bob");
        assert_eq!(
            room.join(C, "carl".into()).unwrap_err(),
            RejectReason::RoomFull
        );
        assert_eq!(actions(&mut room), []);
        assert_eq!(room.players(), 2);
        assert_eq!(room.game().players().count(), 2);
    }

    #[test]
    fn a_leave_of_the_connection_holding_the_player_removes_it() {
        let (mut room, _) = room(4);
        join(&mut room, A, "ann");
        join(&mut room, B, "bob");
        // Another connection's leave, and an unknown player's: nothing.
        room.leave(A, 1);
        room.leave(C, 0);
        room.detach(C, 0);
        room.datagram_sent(C, 0);
        assert_eq!(actions(&mut room), []);
        assert_eq!(room.players(), 2);

        room.leave(A, 0);
        assert_eq!(
            actions(&mut room),
            [
                control(B, &ServerControl::PlayerLeft { id: A }),
                Action::Left(A)
            ]
        );
        assert_eq!(room.players(), 1);
        assert!(room.game().player(A).is_none());
        // Its name is free again.
        assert!(room.join(C, "Ann".into()).is_ok());
    }

    #[test]
    fn a_lost_player_stays_sent_nothing_until_it_resumes() {
        let (mut room, _) = room(4);
        let t0 = Instant::now();
        join(&mut room, A, "ann");
        join(&mut room, B, "bob");
        room.detach(A, 0);
        assert_eq!(actions(&mut room), []);
        let sent = ticks(&mut room, 4, ROOMY, t0);
        assert!(!sent.contains(&Action::SampleWire(A)));
        let to: Vec<PlayerId> = snapshots(&sent).iter().map(|s| s.0).collect();
        assert_eq!(to, [B, B]);
        assert!(room.game().player(A).is_some(), "kept in the game");

        // Within the grace time (the sessions' to judge): the same body, a
        // new generation, and the room as it is now.
        let resumed = room.rejoin(A).unwrap();
        assert!(!resumed.close_old);
        assert_eq!(resumed.joined.generation, 1);
        assert_eq!(resumed.joined.welcome.player_id, A);
        assert_eq!(resumed.joined.welcome.server_tick, 4);
        assert_eq!(
            actions(&mut room),
            [control(A, &roster(&[(A, "ann"), (B, "bob")]))]
        );
        // The lost connection's late detach and leave change nothing.
        room.detach(A, 0);
        room.leave(A, 0);
        assert_eq!(room.players(), 2);
        let sent = ticks(&mut room, 2, ROOMY, t0);
        let to: Vec<(PlayerId, SnapshotKind)> =
            snapshots(&sent).iter().map(|s| (s.0, s.2)).collect();
        assert_eq!(to, [(A, SnapshotKind::Full), (B, SnapshotKind::Full)]);
    }

    #[test]
    fn a_player_resumed_while_still_attached_has_its_old_connection_closed() {
        let (mut room, _) = room(4);
        join(&mut room, A, "ann");
        let resumed = room.rejoin(A).unwrap();
        assert!(resumed.close_old);
        assert_eq!(resumed.joined.generation, 1);
        assert_eq!(room.rejoin(A).unwrap().joined.generation, 2);
    }

    #[test]
    fn after_the_grace_time_a_lost_player_is_gone_and_cannot_resume() {
        let (mut room, _) = room(4);
        join(&mut room, A, "ann");
        join(&mut room, B, "bob");
        room.detach(A, 0);
        // The sessions end it after the grace time.
        room.leave(A, 0);
        assert_eq!(
            actions(&mut room),
            [
                control(B, &ServerControl::PlayerLeft { id: A }),
                Action::Left(A)
            ]
        );
        assert!(room.rejoin(A).is_none());
        assert_eq!(actions(&mut room), []);
    }

    #[test]
    fn a_resumer_gone_before_its_welcome_leaves_the_player_lost() {
        let (mut room, _) = room(4);
        join(&mut room, A, "ann");
        room.detach(A, 0);
        let resumed = room.rejoin(A).unwrap();
        actions(&mut room);
        room.resumer_gone(A, 0); // an older generation: ignored
        assert_eq!(
            snapshots(&ticks(&mut room, 2, ROOMY, Instant::now())).len(),
            1
        );
        room.resumer_gone(A, resumed.joined.generation);
        assert_eq!(snapshots(&ticks(&mut room, 2, ROOMY, Instant::now())), []);
        assert_eq!(room.rejoin(A).unwrap().joined.generation, 2);
    }

    #[test]
    fn a_tick_steps_the_game_with_each_players_input() {
        let (mut room, metrics) = room(4);
        let ann = join(&mut room, A, "ann");
        join(&mut room, B, "bob");
        let r = send(&ann, 0, &[RIGHT, RIGHT, JUMP], None);
        assert_eq!((r.fresh, r.late, r.too_early), (3, 0, 0));
        ticks(&mut room, 3, ROOMY, Instant::now());
        let steps: Vec<_> = [RIGHT, RIGHT, JUMP]
            .iter()
            .map(|&b| vec![(A, b), (B, Buttons::NONE)])
            .collect();
        assert_eq!(room.status().tick, 3);
        assert_eq!(room.status().state_hash, reference(&[A, B], &steps));
        // Bob never sent anything: not starving.
        assert_eq!(starvation(&metrics), 0);
    }

    #[test]
    fn a_missing_input_repeats_the_last_one_and_counts_as_starvation() {
        let (mut room, metrics) = room(4);
        let ann = join(&mut room, A, "ann");
        send(&ann, 0, &[RIGHT], None);
        ticks(&mut room, 3, ROOMY, Instant::now());
        let steps = vec![vec![(A, RIGHT)]; 3];
        assert_eq!(room.status().state_hash, reference(&[A], &steps));
        assert_eq!(starvation(&metrics), 2);
    }

    #[test]
    fn inputs_for_past_or_too_far_future_ticks_are_not_applied() {
        let (mut room, metrics) = room(4);
        let ann = join(&mut room, A, "ann");
        ticks(&mut room, 2, ROOMY, Instant::now());
        // Tick 0 was simulated; 2 + 64 lies beyond the window.
        let late = send(&ann, 0, &[RIGHT], None);
        assert_eq!((late.fresh, late.late), (0, 1));
        let early = send(&ann, 2 + 64, &[RIGHT], None);
        assert_eq!((early.fresh, early.too_early), (0, 1));
        ticks(&mut room, 1, ROOMY, Instant::now());
        let steps = vec![vec![(A, Buttons::NONE)]; 3];
        assert_eq!(room.status().state_hash, reference(&[A], &steps));
        // Nothing for tick 2: a starved tick, now that it sent something.
        assert_eq!(starvation(&metrics), 1);
    }

    #[test]
    fn snapshots_go_full_then_delta_against_the_acknowledged_one() {
        let (mut room, _) = room(4);
        let ann = join(&mut room, A, "ann");
        let t0 = Instant::now();
        let sent = ticks(&mut room, 2, ROOMY, t0);
        // The wire is sampled once a second, from tick 0.
        assert_eq!(sent[0], Action::SampleWire(A));
        assert_eq!(snapshots(&sent), [(A, 2, SnapshotKind::Full, true)]);
        // Unacknowledged: full again.
        let sent = ticks(&mut room, 2, ROOMY, t0);
        assert_eq!(snapshots(&sent), [(A, 4, SnapshotKind::Full, true)]);
        send(&ann, 4, &[RIGHT], Some(4));
        let sent = ticks(&mut room, 2, ROOMY, t0);
        assert_eq!(snapshots(&sent), [(A, 6, SnapshotKind::Delta, true)]);
        assert!(!sent.contains(&Action::SampleWire(A)));
    }

    #[test]
    fn a_snapshot_that_fits_no_datagram_goes_on_the_stream_once_until_acknowledged() {
        let (mut room, metrics) = room(4);
        let ann = join(&mut room, A, "ann");
        let t0 = Instant::now();
        let sent = ticks(&mut room, 2, None, t0);
        assert_eq!(snapshots(&sent), [(A, 2, SnapshotKind::Full, false)]);
        // Within STREAM_SNAPSHOT_RESEND, unacknowledged: deferred.
        let sent = ticks(&mut room, 4, None, t0);
        assert_eq!(snapshots(&sent), []);
        assert_eq!(dropped(&metrics, DropReason::SnapshotDeferred), 2);
        // Acknowledged: the next one goes.
        send(&ann, 6, &[RIGHT], Some(2));
        let sent = ticks(&mut room, 2, None, t0);
        assert_eq!(snapshots(&sent), [(A, 8, SnapshotKind::Delta, false)]);
        // Unacknowledged for STREAM_SNAPSHOT_RESEND: sent again.
        let sent = ticks(&mut room, 64, None, t0);
        assert_eq!(snapshots(&sent).len(), 1);
        assert_eq!(snapshots(&sent)[0].1, 8 + 64);
    }

    #[test]
    fn a_snapshot_not_sent_is_not_taken_as_the_last_one() {
        let (mut room, _) = room(4);
        join(&mut room, A, "ann");
        let now = Instant::now();
        // Stream snapshots that never got queued (a full queue) defer nothing.
        for tick in [2, 4] {
            room.tick(now, |_| None);
            room.tick(now, |_| None);
            assert_eq!(
                snapshots(&actions(&mut room)),
                [(A, tick, SnapshotKind::Full, false)]
            );
        }
    }

    #[test]
    fn an_idle_player_is_kicked_and_the_others_are_told() {
        let mut config = config(3);
        config.idle_kick = Duration::from_millis(100); // 6 ticks at 60 Hz
        let (mut room, metrics) = room_with(config);
        join(&mut room, A, "ann");
        let bob = join(&mut room, B, "bob");
        let t0 = Instant::now();
        for tick in 0..7 {
            send(&bob, tick, &[RIGHT], None);
            let sent = ticks(&mut room, 1, ROOMY, t0);
            assert!(
                !sent.iter().any(|a| matches!(a, Action::Kick { .. })),
                "tick {tick}"
            );
        }
        send(&bob, 7, &[RIGHT], None);
        let sent = ticks(&mut room, 1, ROOMY, t0);
        let reason = "no input for 0 s (or half of it in a full room)".to_string();
        let notice = ServerControl::Notice {
            kind: NoticeKind::Kick {
                reason: reason.clone(),
            },
        };
        assert_eq!(
            sent[..4],
            [
                control(A, &notice),
                Action::Kick { to: A, reason },
                control(B, &ServerControl::PlayerLeft { id: A }),
                Action::Left(A),
            ]
        );
        assert_eq!(room.players(), 1);
        let kicks = metrics.kicks.get_or_create(&KickLabel {
            reason: KickReason::Idle,
        });
        assert_eq!(kicks.get(), 1);
    }

    #[test]
    fn a_full_room_kicks_an_idle_player_in_half_the_time() {
        let mut config = config(2);
        config.idle_kick = Duration::from_millis(100);
        let (mut room, _) = room_with(config);
        join(&mut room, A, "ann");
        join(&mut room, B, "bob");
        let kicks = |sent: &[Action]| {
            sent.iter()
                .filter(|a| matches!(a, Action::Kick { .. }))
                .count()
        };
        let t0 = Instant::now();
        // Silent since tick 0, past 3 ticks (not 6) at tick 4.
        assert_eq!(kicks(&ticks(&mut room, 4, ROOMY, t0)), 0);
        let kicked = kicks(&ticks(&mut room, 1, ROOMY, t0));
        assert_eq!(kicked, 2, "both at once");
        assert_eq!(room.players(), 0);
    }

    #[test]
    fn a_lost_player_is_not_kicked_for_its_silence() {
        let mut config = config(3);
        config.idle_kick = Duration::from_millis(100);
        let (mut room, _) = room_with(config);
        join(&mut room, A, "ann");
        room.detach(A, 0);
        let sent = ticks(&mut room, 20, ROOMY, Instant::now());
        assert_eq!(sent, []);
        assert_eq!(room.players(), 1);
    }

    #[test]
    fn a_quiet_client_in_a_still_room_is_skipped_up_to_quiet_max() {
        let (mut room, metrics) = room(4);
        let ann = join(&mut room, A, "ann");
        let t0 = Instant::now();
        // Standing still, once landed.
        ticks(&mut room, 240, ROOMY, t0);
        let mut packet = InputPacket::new(239, &[Buttons::NONE], Some(240));
        packet.hold = true;
        lock(&ann.inbox).receive(&packet);
        // It spoke: one snapshot; then none while nothing changes, until
        // QUIET_MAX (30 ticks) after the last one sent.
        let sent = ticks(&mut room, 2, ROOMY, t0);
        assert_eq!(snapshots(&sent), [(A, 242, SnapshotKind::Delta, true)]);
        let sent = ticks(&mut room, 28, ROOMY, t0);
        assert_eq!(snapshots(&sent), []);
        assert_eq!(metrics.snapshots_skipped.get(), 14);
        let sent = ticks(&mut room, 2, ROOMY, t0);
        assert_eq!(snapshots(&sent), [(A, 272, SnapshotKind::Delta, true)]);
    }

    #[test]
    fn chat_goes_to_everyone_in_the_room() {
        let (mut room, _) = room(4);
        join(&mut room, A, "ann");
        join(&mut room, B, "bob");
        room.detach(B, 0);
        room.chat(A, "hi".into());
        let chat = ServerControl::Chat {
            from: A,
            text: "hi".into(),
        };
        assert_eq!(actions(&mut room), [control(A, &chat), control(B, &chat)]);
    }

    #[test]
    fn a_match_is_recorded_from_the_first_join_and_saved_when_the_room_empties() {
        let (replays, mut queue) = ReplaysHandle::channel(8);
        let (mut room, _) = room_with(RoomConfig {
            replays,
            ..config(4)
        });
        let t0 = Instant::now();
        ticks(&mut room, 20, None, t0);
        let (a, b) = (PlayerId(1), PlayerId(2));
        let ja = join(&mut room, a, "ann");
        ticks(&mut room, 10, None, t0);
        let jb = join(&mut room, b, "bob");
        let right = [Buttons(Buttons::RIGHT); 40];
        let jump = [Buttons(Buttons::JUMP | Buttons::LEFT); 40];
        send(&ja, room.game().tick(), &right, None);
        send(&jb, room.game().tick(), &jump, None);
        ticks(&mut room, 100, None, t0);
        room.leave(a, 0);
        assert!(actions(&mut room)
            .iter()
            .all(|a| !matches!(a, Action::SaveReplay(_))));
        ticks(&mut room, 5, None, t0);
        room.leave(b, 0);
        let saved: Vec<ToSave> = actions(&mut room)
            .into_iter()
            .filter_map(|a| match a {
                Action::SaveReplay(s) => Some(*s),
                _ => None,
            })
            .collect();
        assert_eq!(saved.len(), 1, "the match, when the room emptied");
        let replay = saved[0].replay.clone();
        assert_eq!(replay.start_tick(), 20);
        assert_eq!(replay.ticks(), 115);
        assert_eq!(replay.name_of(b), Some("bob"));
        let mut playing =
            ledge_shared::replay::Playback::new(&ledge_levels::default_level(), replay).unwrap();
        playing.play_to_end().unwrap();
        assert_eq!(playing.game().state_hash(), room.game().state_hash());
        // Nothing went to the handle's queue: the room task sends them.
        assert!(queue.try_recv().is_err());
        // Stopping an empty room saves nothing more.
        room.stop();
        assert!(actions(&mut room).is_empty());
    }

    #[test]
    fn spectators_watch_without_a_body_or_a_place() {
        // One player's place, two spectators'.
        let (mut room, _) = room(1);
        let (ann, sam, sue, tom) = (PlayerId(1), PlayerId(2), PlayerId(3), PlayerId(4));
        join(&mut room, ann, "ann");
        let spectator = room.spectate(sam, "sam".into()).unwrap();
        // Told who plays; nobody is told of it.
        let told = actions(&mut room);
        assert_eq!(told, [control(sam, &roster(&[(ann, "ann")]))]);
        assert_eq!((room.players(), room.spectators()), (1, 1));
        assert_eq!(room.status().players, 1);
        assert_eq!(room.game().players().count(), 1, "no body in the game");
        // Its place is not a player's, and the player's is not its.
        assert!(matches!(
            room.join(tom, "tom".into()),
            Err(RejectReason::RoomFull)
        ));
        room.spectate(sue, "sue".into()).unwrap();
        actions(&mut room);
        let Err(RejectReason::Other { reason }) = room.spectate(tom, "tom".into()) else {
            panic!("a third spectator");
        };
        assert!(reason.contains("2 spectator places"), "{reason}");
        assert!(room.spectate(tom, "Ann".into()).is_err(), "a player's name");
        // It gets snapshots; its buttons move nothing.
        let t0 = Instant::now();
        send(&spectator, room.game().tick(), &[RIGHT; 30], None);
        let before = room.game().state_hash();
        let sent = snapshots(&ticks(&mut room, 10, Some(1200), t0));
        assert!(sent.iter().any(|s| s.0 == sam), "{sent:?}");
        assert_eq!(
            room.game().player(ann).unwrap().vel.x,
            0,
            "ann holds nothing"
        );
        assert_ne!(room.game().state_hash(), before, "time passes");
        // It cannot chat, and is told why.
        room.chat(sam, "hi".into());
        let answer = actions(&mut room);
        assert_eq!(answer.len(), 1);
        assert!(matches!(&answer[0], Action::Control { to, .. } if *to == sam));
        // It leaves quietly.
        room.leave(sam, 0);
        assert_eq!(actions(&mut room), [Action::Left(sam)]);
        assert_eq!(room.spectators(), 1);
    }
}

#[cfg(test)]
mod level_change_tests {
    use std::path::PathBuf;

    use ledge_shared::protocol::{decode_sim_config, FrameDecoder, Message, VoteRule};

    use super::*;
    use crate::metrics::Metrics;

    /// The default level, and a copy of it named `second` (another
    /// content hash, the same route).
    pub(crate) fn two_levels(dir: &std::path::Path) -> Vec<PathBuf> {
        ledge_levels::write_default_copies(dir, &["default", "second"]).unwrap()
    }

    fn room(dir: &std::path::Path, rule: VoteRule) -> RoomLogic {
        room_of(
            LevelSet::load(&two_levels(dir), None, Default::default(), 32).unwrap(),
            rule,
        )
    }

    fn room_of(levels: LevelSet, rule: VoteRule) -> RoomLogic {
        let first = levels.get(0).clone();
        let config = RoomConfig {
            name: "test".into(),
            tick_rate: 60,
            snapshot_interval: 2,
            max_players: 4,
            max_catch_up: 15,
            input_window: 64,
            input_redundancy: 16,
            history: 64,
            level_id: first.id.clone(),
            level_hash: first.hash,
            level: first.offer,
            record: None,
            idle_kick: Duration::from_secs(30),
            instance: "test".into(),
            records: RecordsHandle::default(),
            replays: Default::default(),
            max_spectators: 2,
            levels,
            rotation: RotationConfig {
                level_time: None,
                results_time: Duration::from_secs(1),
                vote: rule,
            },
        };
        let (metrics, _registry) = Metrics::new();
        RoomLogic::new(first.game, config, metrics)
    }

    /// The control messages in `actions` for `to`.
    fn controls(actions: &[Action], to: PlayerId) -> Vec<ServerControl> {
        let mut decoder = FrameDecoder::new(ledge_shared::protocol::MAX_FRAME);
        for a in actions {
            if let Action::Control { to: t, frame } = a {
                if *t == to {
                    decoder.push(frame).unwrap();
                }
            }
        }
        std::iter::from_fn(|| decoder.pop())
            .map(|f| ServerControl::decode(&f).unwrap())
            .collect()
    }

    fn step(room: &mut RoomLogic, n: u64, t0: Instant) -> Vec<Action> {
        let mut all = Vec::new();
        for _ in 0..n {
            room.tick(t0 + Duration::from_millis(16 * room.game().tick()), |_| {
                Some(1200)
            });
            room.take_actions(&mut all);
        }
        all
    }

    /// The player configuration a `Welcome` or `LevelChange` carries.
    fn player_of(w: &ledge_shared::protocol::Welcome) -> ledge_shared::game::PlayerConfig {
        decode_sim_config::<ledge_shared::game::GameConfig>(&w.sim_config)
            .unwrap()
            .player
    }

    #[test]
    fn each_level_of_a_rotation_sends_its_own_player_scale() {
        let dir = tempfile::tempdir().unwrap();
        let paths = two_levels(dir.path());
        // The second level's settings make its player twice ledge's.
        std::fs::write(dir.path().join("second.ledge.toml"), "scale = 2.0\n").unwrap();
        let levels = LevelSet::load(&paths, None, Default::default(), 32).unwrap();
        let mut room = room_of(levels, VoteRule::Off);
        let welcome = room.join(PlayerId(1), "ann".into()).unwrap().welcome;
        room.take_actions(&mut Vec::new());
        let base = ledge_shared::game::PlayerConfig::default();
        assert_eq!(player_of(&welcome), base);
        room.change_level(1);
        let mut changed = Vec::new();
        room.take_actions(&mut changed);
        let change = controls(&changed, PlayerId(1))
            .into_iter()
            .find_map(|m| match m {
                ServerControl::LevelChange(w) => Some(w),
                _ => None,
            })
            .expect("a LevelChange");
        let p = player_of(&change);
        assert_eq!((p.half, p.jump_speed), (base.half * 2, base.jump_speed * 2));
        assert_eq!(
            p,
            room.game().config().player,
            "the room plays what it sends"
        );
        // Back to the first level: ledge's own player again.
        room.change_level(0);
        let mut back = Vec::new();
        room.take_actions(&mut back);
        let again = controls(&back, PlayerId(1))
            .into_iter()
            .find_map(|m| match m {
                ServerControl::LevelChange(w) => Some(w),
                _ => None,
            })
            .expect("a LevelChange");
        assert_eq!(player_of(&again), base);
    }

    #[test]
    fn a_majority_vote_moves_the_room_to_the_next_level_ticks_going_on() {
        let dir = tempfile::tempdir().unwrap();
        let mut room = room(dir.path(), VoteRule::Majority);
        let t0 = Instant::now();
        let ann = room.join(PlayerId(1), "ann".into()).unwrap();
        let watcher = room.spectate(PlayerId(2), "eve".into()).unwrap();
        let mut joined = Vec::new();
        room.take_actions(&mut joined);
        let listed = controls(&joined, PlayerId(1));
        let Some(ServerControl::Levels(list)) = listed.last() else {
            panic!("no level list after the roster: {listed:?}");
        };
        assert_eq!((list.current, list.next, list.change_at), (0, 1, None));
        assert_eq!(list.levels[1].id, "second");
        step(&mut room, 30, t0);

        // The spectator may not vote; ann's vote is a majority of one.
        room.vote(PlayerId(2), 1);
        room.vote(PlayerId(1), 1);
        let mut voted = Vec::new();
        room.take_actions(&mut voted);
        assert!(matches!(
            &controls(&voted, PlayerId(2))[0],
            ServerControl::Notice { .. }
        ));
        let before = step(&mut room, 1, t0);
        let Some(ServerControl::Levels(list)) = controls(&before, PlayerId(1)).pop() else {
            panic!("the vote's decision not announced");
        };
        let at = list.change_at.expect("a change planned");
        assert_eq!(list.votes, vec![0, 1]);
        assert_eq!(at, 31 + 60, "one second of results after the vote's tick");
        assert_eq!(room.level_index(), 0);

        let left = at - room.game().tick();
        let until = step(&mut room, left, t0);
        assert_eq!(room.level_index(), 1);
        assert_eq!(room.game().tick(), at, "the tick count goes on");
        for who in [PlayerId(1), PlayerId(2)] {
            let got = controls(&until, who);
            let change = got.iter().find_map(|m| match m {
                ServerControl::LevelChange(w) => Some(w.clone()),
                _ => None,
            });
            let w = change.expect("a LevelChange");
            assert_eq!(
                (w.player_id, w.level_id.as_str(), w.server_tick),
                (who, "second", at)
            );
            assert_eq!(w.level, room.config().levels.get(1).offer);
            assert!(decode_sim_config::<ledge_shared::game::GameConfig>(&w.sim_config).is_ok());
        }
        assert!(
            room.game().player(PlayerId(1)).is_some(),
            "ann is in the new level"
        );
        assert!(
            room.game().player(PlayerId(2)).is_none(),
            "the spectator has no body"
        );

        // New-level snapshots go on the stream until one is acknowledged.
        let after = step(&mut room, 4, t0);
        let sent: Vec<(u64, bool)> = after
            .iter()
            .filter_map(|a| match a {
                Action::Snapshot {
                    to, tick, outgoing, ..
                } if *to == PlayerId(1) => Some((*tick, matches!(outgoing, Outgoing::Datagram(_)))),
                _ => None,
            })
            .collect();
        assert!(
            !sent.is_empty() && sent.iter().all(|&(t, dgram)| t > at && !dgram),
            "{sent:?}"
        );
        room.stream_queued(PlayerId(1), sent[0].0, t0);
        // An old level's acknowledgement changes nothing; a new one does.
        lock(&ann.inbox).ack = Some(at - 2);
        let old_ack = step(&mut room, 2, t0);
        assert!(old_ack.iter().all(|a| !matches!(a, Action::Snapshot { to, outgoing: Outgoing::Datagram(_), .. } if *to == PlayerId(1))));
        lock(&ann.inbox).ack = Some(sent[0].0);
        let acked = step(&mut room, 2, t0);
        assert!(acked.iter().any(|a| matches!(a, Action::Snapshot { to, outgoing: Outgoing::Datagram(_), .. } if *to == PlayerId(1))), "datagrams again once acknowledged");
        drop(watcher);
    }

    #[test]
    fn a_player_lost_during_a_change_resumes_on_the_new_level() {
        let dir = tempfile::tempdir().unwrap();
        let mut room = room(dir.path(), VoteRule::Off);
        let t0 = Instant::now();
        room.join(PlayerId(1), "ann".into()).unwrap();
        step(&mut room, 10, t0);
        room.detach(PlayerId(1), 0);
        room.change_level(1);
        let at = room.game().tick();
        step(&mut room, 10, t0);
        let resumed = room.rejoin(PlayerId(1)).expect("kept for a resume");
        assert_eq!(resumed.joined.welcome.level_id, "second");
        assert_eq!(
            resumed.joined.welcome.level,
            room.config().levels.get(1).offer
        );
        let after = step(&mut room, 4, t0);
        let sent: Vec<bool> = after
            .iter()
            .filter_map(|a| match a {
                Action::Snapshot {
                    to, tick, outgoing, ..
                } if *to == PlayerId(1) => {
                    assert!(*tick > at);
                    Some(matches!(outgoing, Outgoing::Datagram(_)))
                }
                _ => None,
            })
            .collect();
        assert!(
            !sent.is_empty() && sent.iter().all(|d| !d),
            "on the stream: {sent:?}"
        );
    }

    #[test]
    fn a_level_change_gives_silent_downloaders_time_by_the_levels_size() {
        let dir = tempfile::tempdir().unwrap();
        let mut room = room(dir.path(), VoteRule::Off);
        assert_eq!(room.download_grace(1 << 20), 4 * 60, "1 MiB at 256 KiB/s");
        assert_eq!(
            room.download_grace(96 << 20),
            120 * 60,
            "capped at 2 minutes"
        );
        room.config.idle_kick = Duration::from_millis(500);
        let t0 = Instant::now();
        room.join(PlayerId(1), "ann".into()).unwrap();
        step(&mut room, 10, t0);
        room.change_level(1);
        let grace = room.download_grace(room.config().level.size);
        let kicked = |actions: &[Action]| actions.iter().any(|a| matches!(a, Action::Kick { .. }));
        assert!(
            !kicked(&step(&mut room, 30 + grace, t0)),
            "silent within the idle time and the grace"
        );
        assert!(kicked(&step(&mut room, 10, t0)), "then idle");
    }

    #[test]
    fn one_level_sends_no_list_and_refuses_votes() {
        let levels = LevelSet::load(&[], None, Default::default(), 32).unwrap();
        let mut room = room_of(levels, VoteRule::Majority);
        room.join(PlayerId(1), "ann".into()).unwrap();
        let mut joined = Vec::new();
        room.take_actions(&mut joined);
        assert!(!controls(&joined, PlayerId(1))
            .iter()
            .any(|m| matches!(m, ServerControl::Levels(_))));
        room.vote(PlayerId(1), 0);
        let mut voted = Vec::new();
        room.take_actions(&mut voted);
        let refused = controls(&voted, PlayerId(1));
        assert!(
            matches!(&refused[..], [ServerControl::Notice { kind: NoticeKind::Info { text } }] if text.contains("one level")),
            "{refused:?}"
        );
    }
}
