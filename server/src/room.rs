//! A room's I/O: the task that runs a [`RoomLogic`] on a fixed-step tick
//! loop, the [`RoomHandle`] connection tasks talk to it through (join,
//! leave, detach, rejoin, chat), and the carrying out of its [`Action`]s
//! over each client's [`Link`] and control-stream writer.
//!
//! The room runs as its own task and owns its game outright; each client's
//! decoded inputs go into that client's inbox
//! ([`crate::room_logic::PlayerInbox`]), which the room drains one tick at
//! a time. The loop follows a [`TickSchedule`]: ticks run on an absolute
//! grid, a stall is caught up by a bounded number of ticks, and skipped
//! ticks are logged and counted. What a tick does, and what each client is
//! sent, is the room's logic ([`crate::room_logic`]), free of I/O.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

use ledge_shared::game::Game;
use ledge_shared::protocol::{
    clip_text, write_frame, CloseCode, Outgoing, PlayerId, RejectReason, ServerControl, Standing,
    MAX_REASON_LEN,
};
use prometheus_client::metrics::counter::Counter;
use prometheus_client::metrics::gauge::Gauge;
use prometheus_client::metrics::histogram::Histogram;
use tokio::sync::{mpsc, oneshot, watch};
use tokio::task::JoinHandle;
use tracing::{debug, info, warn};

use crate::clock::TickSchedule;
use crate::link::{DatagramError, Link, Wire};
use crate::metrics::{
    Channel, ClientBytes, DropReason, Metrics, RoomLabel, SnapshotKind, SnapshotLabel,
};
use crate::replays::ghosts;
use crate::room_logic::{Action, Joined, RoomConfig, RoomLogic, RoomStatus};

/// Longest a finished run waits for its replay file before it is stored
/// (without the replay's id, should the file not be written by then).
const REPLAY_SAVE_WAIT: std::time::Duration = std::time::Duration::from_secs(10);

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
        spectate: bool,
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
    Vote {
        from: PlayerId,
        level: u32,
    },
    /// A run set a new record (`everyone`: send the record's ghost to the
    /// whole room) or its runner's best (send it to `finisher`).
    RefreshGhosts {
        finisher: PlayerId,
        everyone: bool,
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

    /// Adds a player (a spectator with `spectate`). Commands are unbounded but each connection sends one
    /// join, one leave and rate-limited chat, so the queue stays small.
    pub async fn join(
        &self,
        player_id: PlayerId,
        name: String,
        link: ClientLink,
        spectate: bool,
    ) -> Result<Joined, JoinError> {
        let (reply, answer) = oneshot::channel();
        self.commands
            .send(Command::Join {
                player_id,
                name,
                link,
                spectate,
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

    /// Records a player's vote for the next level.
    pub fn vote(&self, from: PlayerId, level: u32) {
        let _ = self.commands.send(Command::Vote { from, level });
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
    let logic = RoomLogic::new(game, config.clone(), metrics.clone());
    let (status_tx, status) = watch::channel(logic.status());
    let players = Arc::new(AtomicUsize::new(0));
    let label = RoomLabel {
        room: config.name.clone(),
    };
    let room = Room {
        tick_duration: metrics.tick_duration.get_or_create_owned(&label),
        missed_ticks: metrics.missed_ticks.get_or_create_owned(&label),
        players_gauge: metrics.players.get_or_create_owned(&label),
        logic,
        peers: BTreeMap::new(),
        actions: Vec::new(),
        players: players.clone(),
        commands: command_rx,
        myself: commands.downgrade(),
        status: status_tx,
        metrics,
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

/// Asks the room to send the ghosts a stored run changed: the new record
/// to everyone in it, a new personal best to its runner (a ghost set while
/// players race reaches them then, not at their next join).
fn refresh_ghosts(room: &mpsc::WeakUnboundedSender<Command>, finisher: PlayerId, s: &Standing) {
    if !(s.new_record || s.new_personal_best) {
        return;
    }
    if let Some(room) = room.upgrade() {
        let _ = room.send(Command::RefreshGhosts {
            finisher,
            everyone: s.new_record,
        });
    }
}

/// Queues where a player's run stands (or why it was not recorded) on its
/// control stream; a full queue drops it (the run is stored all the same).
fn tell_standing(control: &mpsc::Sender<Outbound>, result: Result<Standing, String>) {
    let message = match result {
        Ok(standing) => ServerControl::RunRecorded(standing),
        Err(reason) => ServerControl::RunNotRecorded {
            reason: clip_text(&reason, MAX_REASON_LEN),
        },
    };
    let mut frame = Vec::new();
    match write_frame(&message, &mut frame) {
        Ok(()) => {
            let _ = control.try_send(Outbound::Frame(frame));
        }
        Err(e) => warn!("a run's standing could not be encoded: {e}"),
    }
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

/// A player's connection, as the room task holds it.
#[derive(Debug)]
struct Peer {
    link: ClientLink,
    /// Its connection's UDP totals at the last sample.
    wire: Wire,
}

impl Peer {
    fn new(link: ClientLink) -> Peer {
        Peer {
            link,
            wire: Wire::default(),
        }
    }

    /// Queues a frame for the control stream; drops it (counted) when
    /// that client's queue is full.
    fn send_control(&self, metrics: &Metrics, frame: Vec<u8>) {
        let sent = self.link.control.try_send(Outbound::Frame(frame));
        metrics.count_queue_error(sent);
    }

    /// Closes the connection after what was queued, or at once when the
    /// queue is full (the client reads nothing).
    fn kick(&self, reason: String) {
        let close = Outbound::Close(CloseCode::Kicked, reason.clone());
        if self.link.control.try_send(close).is_err() {
            self.link.link.close(CloseCode::Kicked, &reason);
        }
    }

    /// Sends a snapshot; `true` if it went (a datagram handed to the
    /// transport, or a frame queued for the control stream).
    fn send_snapshot(
        &self,
        metrics: &Metrics,
        tick: u64,
        kind: SnapshotKind,
        out: Outgoing,
    ) -> bool {
        match out {
            Outgoing::Datagram(bytes) => {
                let len = bytes.len();
                match self.link.link.send_datagram(bytes.into()) {
                    Ok(()) => {
                        record_snapshot(metrics, &self.link.bytes, kind, len);
                        return true;
                    }
                    Err(DatagramError::Lost) => {}
                    Err(DatagramError::Failed(e)) => {
                        debug!(tick, "snapshot datagram not sent: {e}");
                        metrics.count_drop(DropReason::SnapshotSendFailed);
                    }
                }
            }
            Outgoing::Control(frame) => {
                let len = frame.len();
                match self.link.control.try_send(Outbound::Frame(frame)) {
                    Ok(()) => {
                        // Bytes are counted by the writer when written.
                        metrics
                            .snapshot_bytes
                            .get_or_create(&SnapshotLabel {
                                kind,
                                channel: Channel::Stream,
                            })
                            .observe(len as f64);
                        return true;
                    }
                    Err(e) => metrics.count_queue_error::<Outbound>(Err(e)),
                }
            }
        }
        false
    }
}

/// The room task's state: the room's logic and the I/O it asks for.
struct Room {
    logic: RoomLogic,
    /// The connection of every player in the room (attached or not).
    peers: BTreeMap<PlayerId, Peer>,
    /// Actions taken from the logic, being carried out.
    actions: Vec<Action>,
    players: Arc<AtomicUsize>,
    commands: mpsc::UnboundedReceiver<Command>,
    /// Its own command queue, for the records' answers (weak: the room
    /// still stops when the last handle goes).
    myself: mpsc::WeakUnboundedSender<Command>,
    status: watch::Sender<RoomStatus>,
    metrics: Arc<Metrics>,
    tick_duration: Histogram,
    missed_ticks: Counter,
    players_gauge: Gauge,
}

impl Room {
    fn name(&self) -> &str {
        &self.logic.config().name
    }

    async fn run(mut self) {
        let rate = self.logic.config().tick_rate.max(1);
        let max_catch_up = self.logic.config().max_catch_up;
        let mut schedule = TickSchedule::new(Instant::now(), rate, max_catch_up);
        info!(room = %self.name(), tick_rate = rate, "room started");
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
                    self.log_catch_up(due.run, due.skipped);
                    self.publish();
                }
            }
        }
        self.players_gauge.set(0);
        // The match being recorded ends here: save it.
        self.logic.stop();
        self.logic.take_actions(&mut self.actions);
        for action in self.actions.drain(..) {
            if let Action::SaveReplay(replay) = action {
                self.logic.config().replays.save(*replay);
            }
        }
        info!(room = %self.name(), tick = self.logic.game().tick(), "room stopped");
    }

    /// Counts and logs the ticks a late loop skipped or ran back to back.
    fn log_catch_up(&self, run: u32, skipped: u64) {
        if skipped > 0 {
            self.missed_ticks.inc_by(skipped);
            warn!(
                room = %self.name(),
                caught_up = run,
                skipped,
                tick = self.logic.game().tick(),
                "tick loop fell behind; skipped ticks"
            );
        } else if run > 1 {
            debug!(room = %self.name(), caught_up = run, "tick loop caught up");
        }
    }

    fn handle(&mut self, command: Command) {
        match command {
            Command::Join {
                player_id,
                name,
                link,
                spectate,
                reply,
            } => {
                let answer = if spectate {
                    self.logic.spectate(player_id, name.clone())
                } else {
                    self.logic.join(player_id, name.clone())
                };
                if answer.is_ok() {
                    if !spectate {
                        Room::send_ghosts(self.logic.config(), &link.control, name);
                    }
                    self.peers.insert(player_id, Peer::new(link));
                    self.sync_players();
                }
                self.carry_out(Instant::now());
                // The joiner may have gone while the command was queued.
                if let Err(Ok(joined)) = reply.send(answer) {
                    debug!(%player_id, "joiner gone before the welcome");
                    self.logic.leave(player_id, joined.generation);
                    self.after_leave();
                }
            }
            Command::Leave {
                player_id,
                generation,
            } => {
                self.logic.leave(player_id, generation);
                self.after_leave();
            }
            Command::Detach {
                player_id,
                generation,
            } => self.logic.detach(player_id, generation),
            Command::Rejoin {
                player_id,
                link,
                reply,
            } => self.rejoin(player_id, link, reply),
            Command::Chat { from, text } => {
                self.logic.chat(from, text);
                self.carry_out(Instant::now());
            }
            Command::RefreshGhosts { finisher, everyone } => {
                let config = self.logic.config();
                for (id, name) in self.logic.player_names() {
                    if let Some(peer) = self.peers.get(&id).filter(|_| everyone || id == finisher) {
                        Room::send_ghosts(config, &peer.link.control, name);
                    }
                }
            }
            Command::Vote { from, level } => {
                self.logic.vote(from, level);
                self.carry_out(Instant::now());
            }
        }
        self.publish();
    }

    /// Hands a kept (or still attached) player to a new connection.
    fn rejoin(
        &mut self,
        player_id: PlayerId,
        link: ClientLink,
        reply: oneshot::Sender<Option<Joined>>,
    ) {
        let Some(resumed) = self.logic.rejoin(player_id) else {
            let _ = reply.send(None);
            return;
        };
        if let (true, Some(old)) = (resumed.close_old, self.peers.get(&player_id)) {
            // The client gave up on it before we noticed.
            old.link.link.close(CloseCode::Normal, "resumed elsewhere");
        }
        self.peers.insert(player_id, Peer::new(link));
        self.carry_out(Instant::now());
        if let Err(Some(joined)) = reply.send(Some(resumed.joined)) {
            // The resumer is gone already: it is lost again.
            self.logic.resumer_gone(player_id, joined.generation);
        }
    }

    fn after_leave(&mut self) {
        self.carry_out(Instant::now());
        self.sync_players();
    }

    fn tick(&mut self) {
        let started = Instant::now();
        let peers = &self.peers;
        self.logic.tick(started, |id| {
            peers.get(&id).and_then(|p| p.link.link.max_datagram_size())
        });
        self.carry_out(started);
        self.sync_players();
        let took = started.elapsed().as_secs_f64();
        self.tick_duration.observe(took);
        self.metrics.tick_duration_fine.observe(took);
    }

    /// Carries out what the logic decided, in order; `now` is the time the
    /// logic was given.
    fn carry_out(&mut self, now: Instant) {
        self.logic.take_actions(&mut self.actions);
        let metrics = &*self.metrics;
        // A run's replay is queued just before its run: the run is stored
        // once the file is written, so no record names a missing replay.
        let mut saving: BTreeMap<String, oneshot::Receiver<bool>> = BTreeMap::new();
        for action in self.actions.drain(..) {
            match action {
                Action::Control { to, frame } => {
                    if let Some(peer) = self.peers.get(&to) {
                        peer.send_control(metrics, frame);
                    }
                }
                Action::Kick { to, reason } => {
                    if let Some(peer) = self.peers.get(&to) {
                        peer.kick(reason);
                    }
                }
                Action::SampleWire(id) => {
                    if let Some(peer) = self.peers.get_mut(&id) {
                        if let Some(wire) = peer.link.link.wire() {
                            metrics.wire(&mut peer.wire, wire);
                        }
                    }
                }
                Action::Snapshot {
                    to,
                    tick,
                    kind,
                    outgoing,
                } => {
                    let Some(peer) = self.peers.get(&to) else {
                        continue;
                    };
                    let datagram = matches!(outgoing, Outgoing::Datagram(_));
                    if !peer.send_snapshot(metrics, tick, kind, outgoing) {
                        continue;
                    }
                    if datagram {
                        self.logic.datagram_sent(to, tick);
                    } else {
                        self.logic.stream_queued(to, tick, now);
                    }
                }
                Action::Left(id) => {
                    self.peers.remove(&id);
                }
                Action::SaveReplay(replay) => {
                    let (tell, saved) = oneshot::channel();
                    saving.insert(replay.id.clone(), saved);
                    self.logic.config().replays.save_then(*replay, Some(tell));
                }
                Action::FindGhosts { to, name } => {
                    if let Some(peer) = self.peers.get(&to) {
                        Room::send_ghosts(self.logic.config(), &peer.link.control, name);
                    }
                }
                Action::RunFinished { to, mut run } => {
                    run.finished_at_ms = crate::records::unix_millis();
                    let control = self.peers.get(&to).map(|p| p.link.control.clone());
                    let saved = run.replay_id.as_ref().and_then(|id| saving.remove(id));
                    let records = self.logic.config().records.clone();
                    let myself = self.myself.clone();
                    tokio::spawn(async move {
                        if let Some(saved) = saved {
                            let written = tokio::time::timeout(REPLAY_SAVE_WAIT, saved).await;
                            if !matches!(written, Ok(Ok(true))) {
                                run.replay_id = None;
                            }
                        }
                        records.submit(
                            run,
                            Box::new(move |result| {
                                if let Ok(s) = &result {
                                    refresh_ghosts(&myself, to, s);
                                }
                                if let Some(control) = control {
                                    tell_standing(&control, result);
                                }
                            }),
                        );
                    });
                }
            }
        }
    }

    /// Sends a new player the runs to race against (the record, its own
    /// best), read off the room's thread, when records and replays are on.
    fn send_ghosts(config: &RoomConfig, control: &mpsc::Sender<Outbound>, name: String) {
        let (Some(store), Some(dir)) = (config.records.store(), config.replays.dir()) else {
            return;
        };
        let (dir, level) = (dir.to_owned(), config.level.hex());
        let control = control.clone();
        tokio::spawn(async move {
            for ghost in ghosts::find(&store, &dir, &level, &name).await {
                let mut frame = Vec::new();
                match write_frame(&ServerControl::Ghost(ghost), &mut frame) {
                    Ok(()) => {
                        let _ = control.try_send(Outbound::Frame(frame));
                    }
                    Err(e) => debug!("a ghost not sent: {e}"),
                }
            }
        });
    }

    /// Publishes the number of players (for the handle and the metrics).
    fn sync_players(&self) {
        let players = self.logic.players();
        self.players.store(players, Ordering::Relaxed);
        self.players_gauge.set(players as i64);
    }

    fn publish(&self) {
        self.status.send_replace(self.logic.status());
    }
}
