//! [`ClientGame`]: the client's side of a game, sans IO. It ties together
//! the synchronised clock ([`SyncClock`]), prediction and reconciliation
//! ([`Predictor`]), the interpolation of remote players
//! ([`Interpolator`]), the network figures ([`StatsTracker`]), and builds
//! the [`FrameView`] and [`NetStats`] a front end draws.
//!
//! The caller owns the transport (a [`crate::Session`] for bots and tests,
//! a [`crate::net::background::NetThread`] for the GUI, see
//! [`crate::net::online::OnlineGame`]) and feeds it:
//!
//! ```text
//! every frame:   game.update(now, max_ticks, |i| buttons, |tick, b| send the input)
//!                (or: for _ in 0..game.advance(now) { let t = game.step(b); send(t, b) })
//! each snapshot: game.on_snapshot(&update)
//! each ping:     game.on_rtt(rtt);  now and then: game.on_transport(sample, now)
//! the roster:    game.on_player_joined(id, name), game.on_player_left(id)
//! to draw:       game.view(), game.net_stats(now)
//! ```
//!
//! The parts it ties together are its submodules:
//!
//! * [`predict`]: prediction and reconciliation ([`Predictor`]);
//! * [`interp`]: remote players drawn in the past ([`Interpolator`]);
//! * [`clock`]: the synchronised local clock ([`SyncClock`]) and the
//!   simple [`clock::InputClock`].

pub mod clock;
pub mod interp;
pub mod predict;

use std::collections::BTreeMap;
use std::time::Duration;

use crate::time::Instant;

use glam::IVec2;
use ledge_shared::game::state::{kind, player_flags};
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::level::Level;
use ledge_shared::protocol::{decode_sim_config, EntityState, PlayerId, Welcome, MAX_ROSTER};
use ledge_shared::world::Sides;

use crate::error::ClientError;
use crate::game::clock::SyncClock;
use crate::game::interp::Interpolator;
use crate::game::predict::{Predictor, Reconciled};
use crate::net::levels::check_level;
use crate::net::session::SnapshotUpdate;
use crate::netstats::{StatsTracker, TransportSample};
use crate::view::{blend, px2, EntityDraw, Facing, FrameView, NetStats, PlayerDraw};

/// At most this many inputs are handed to `send` per [`ClientGame::update`]
/// (after a long frame): each packet repeats the previous ticks anyway, and
/// a burst of datagrams would look like a flood to the server.
pub const MAX_SENDS_PER_UPDATE: u32 = 4;
/// At most this many ticks are due per [`ClientGame::advance`]; the rest
/// are due at the next calls (a window frozen for minutes must not stall
/// one frame for seconds).
pub const MAX_TICKS_PER_ADVANCE: u32 = 240;

/// The client's predicted game, clock, interpolation and statistics.
#[derive(Debug, Clone)]
pub struct ClientGame {
    level: Level,
    me: PlayerId,
    name: Option<String>,
    /// The room's players by id, from the server's roster (at most
    /// [`MAX_ROSTER`]).
    names: BTreeMap<PlayerId, String>,
    welcome: Option<Welcome>,
    predictor: Predictor,
    clock: SyncClock,
    interp: Interpolator,
    stats: StatsTracker,
    player_half: IVec2,
    /// Entity centres one tick before the newest (for blending).
    prev_entities: Vec<IVec2>,
    offline: bool,
    /// Watching, not playing: no body of ours in the game, every player
    /// interpolated, no buttons but none ([`ClientGame::set_spectating`]).
    spectating: bool,
}

impl ClientGame {
    /// The game of a session the server welcomed at `now` with `welcome`,
    /// on `level` (which must be the server's: its hash is checked), with
    /// the handshake's round-trip time `rtt` to start the clock.
    pub fn new(
        welcome: &Welcome,
        level: Level,
        rtt: Duration,
        now: Instant,
    ) -> Result<ClientGame, ClientError> {
        let clock = SyncClock::for_welcome(welcome, rtt, now);
        ClientGame::with_clock(welcome, level, rtt, clock)
    }

    /// The game of the room's next level, replacing this one: `welcome` is
    /// the level change's (the new level, the tick it started at, its
    /// config) and `level` must be its level (its hash is checked). The
    /// room's tick goes on across a change, so the clock carries on where
    /// it is (when it is not behind the new welcome's tick, at the same
    /// rate) with the inputs sent for the ticks since the change (the
    /// server ran them on the new level), as do the names known and
    /// whether we watch; the prediction, the remote players and the
    /// figures start afresh.
    pub fn next_level(
        &self,
        welcome: &Welcome,
        level: Level,
        now: Instant,
    ) -> Result<ClientGame, ClientError> {
        let rtt = self.stats.latest_rtt().unwrap_or(Duration::from_millis(50));
        let fresh = SyncClock::for_welcome(welcome, rtt, now);
        let mut going = self.clock.clone();
        going.advance(now);
        let same_rate = self
            .welcome
            .as_ref()
            .is_some_and(|w| w.timing.tick_rate == welcome.timing.tick_rate);
        let carry = same_rate && going.position() >= fresh.position();
        let clock = if carry { going } else { fresh };
        let mut game = ClientGame::with_clock(welcome, level, rtt, clock)?;
        if carry {
            // The ticks since the change ran on the server with the
            // inputs we sent for them.
            game.predictor
                .carry_inputs(&self.predictor, welcome.server_tick);
        }
        game.name = self.name.clone();
        game.names = self.names.clone();
        game.spectating = self.spectating;
        Ok(game)
    }

    /// [`ClientGame::new`] with its clock.
    fn with_clock(
        welcome: &Welcome,
        level: Level,
        rtt: Duration,
        clock: SyncClock,
    ) -> Result<ClientGame, ClientError> {
        check_level(welcome, &level, "our level")?;
        // The server's constants (an older or minimal server may send none).
        let mut config: GameConfig = if welcome.sim_config.is_empty() {
            GameConfig::default()
        } else {
            decode_sim_config(&welcome.sim_config)?
        };
        // Detection threads never change results; the client uses one.
        config.sim.threads = 1;
        let predictor = Predictor::with_config(&level, config, welcome.player_id, clock.tick())?;
        let t = &welcome.timing;
        let mut stats = StatsTracker::new(t.tick_rate, t.snapshot_interval);
        stats.rtt(rtt);
        Ok(ClientGame {
            player_half: config.player.half,
            me: welcome.player_id,
            name: None,
            names: BTreeMap::new(),
            welcome: Some(welcome.clone()),
            predictor,
            clock,
            interp: Interpolator::new(t.tick_rate, t.snapshot_interval),
            stats,
            prev_entities: Vec::new(),
            level,
            offline: false,
            spectating: false,
        })
    }

    /// A local game with no server (offline play): player 1 at the level's
    /// spawn, 60 Hz; [`ClientGame::update`] runs it and nothing needs
    /// sending.
    pub fn offline(level: Level, now: Instant) -> Result<ClientGame, ClientError> {
        let me = PlayerId(1);
        // The level's own player scale (`Game::from_level`).
        let game = Game::from_level(&level)?;
        let player_half = game.config().player.half;
        let predictor = Predictor::offline(game, me)?;
        Ok(ClientGame {
            player_half,
            me,
            name: None,
            names: BTreeMap::new(),
            welcome: None,
            predictor,
            clock: SyncClock::new(0.0, 60, now),
            interp: Interpolator::new(60, 2),
            stats: StatsTracker::new(60, 2),
            prev_entities: Vec::new(),
            level,
            offline: true,
            spectating: false,
        })
    }

    /// Sets the input margin the clock keeps with no jitter, ticks (default
    /// [`crate::game::clock::BASE_MARGIN`]).
    pub fn set_base_margin(&mut self, ticks: f64) {
        self.clock.set_base_margin(ticks);
    }

    /// Sets our player's name (shown in [`PlayerDraw::name`]).
    pub fn set_name(&mut self, name: &str) {
        self.name = Some(name.to_owned());
    }

    /// A player is in the room as `name` (from the server's roster):
    /// remote players are drawn with it ([`PlayerDraw::name`]). Beyond
    /// [`MAX_ROSTER`] names, new ids are ignored.
    pub fn on_player_joined(&mut self, id: PlayerId, name: &str) {
        if self.names.len() < MAX_ROSTER || self.names.contains_key(&id) {
            self.names.insert(id, name.to_owned());
        }
    }

    /// Player `id` left the room.
    pub fn on_player_left(&mut self, id: PlayerId) {
        self.names.remove(&id);
    }

    /// Replaces the known names by `names` (its first [`MAX_ROSTER`]).
    pub fn set_player_names(&mut self, names: &BTreeMap<PlayerId, String>) {
        self.names = names
            .iter()
            .take(MAX_ROSTER)
            .map(|(&id, n)| (id, n.clone()))
            .collect();
    }

    /// The names known, by player id.
    pub fn player_names(&self) -> &BTreeMap<PlayerId, String> {
        &self.names
    }

    /// Our player id.
    pub fn me(&self) -> PlayerId {
        self.me
    }

    /// The level (draw its tilemap once).
    pub fn level(&self) -> &Level {
        &self.level
    }

    /// The server's welcome (`None` offline).
    pub fn welcome(&self) -> Option<&Welcome> {
        self.welcome.as_ref()
    }

    /// Watch rather than play (a session joined with
    /// [`crate::net::session::JoinOptions::spectate`]): the welcome's id
    /// is nobody's in the game, so there is no player of ours to predict
    /// or draw ([`FrameView::local`] is `None`), every player in the
    /// snapshots is drawn interpolated as a remote one, and the buttons
    /// given to [`ClientGame::update`] and [`ClientGame::step`] are
    /// replaced by none (the inputs still sent only acknowledge
    /// snapshots).
    pub fn set_spectating(&mut self, spectating: bool) {
        self.spectating = spectating;
    }

    /// Whether we watch rather than play ([`ClientGame::set_spectating`]).
    pub fn spectating(&self) -> bool {
        self.spectating
    }

    /// Whether this is a local game without a server.
    pub fn is_offline(&self) -> bool {
        self.offline
    }

    /// The predicted game.
    pub fn game(&self) -> &Game {
        self.predictor.game()
    }

    /// The predictor (counters, predicted states).
    pub fn predictor(&self) -> &Predictor {
        &self.predictor
    }

    /// The local clock.
    pub fn clock(&self) -> &SyncClock {
        &self.clock
    }

    /// The remote players' playout buffer.
    pub fn interpolator(&self) -> &Interpolator {
        &self.interp
    }

    /// The raw network figures.
    pub fn tracker(&self) -> &StatsTracker {
        &self.stats
    }

    /// Whether prediction has started (the first snapshot arrived).
    pub fn synced(&self) -> bool {
        self.predictor.synced()
    }

    /// The next tick [`ClientGame::step`] runs.
    pub fn next_tick(&self) -> u64 {
        self.predictor.next_tick()
    }

    /// Advances the clock (and the remote players' render tick) to `now`;
    /// returns how many local ticks are due: call [`ClientGame::step`] that
    /// many times.
    pub fn advance(&mut self, now: Instant) -> u32 {
        self.clock.advance(now);
        self.interp.advance(now);
        let due = self.clock.tick().saturating_sub(self.predictor.next_tick());
        u32::try_from(due)
            .unwrap_or(u32::MAX)
            .min(MAX_TICKS_PER_ADVANCE)
    }

    /// Runs one local tick with our `buttons`; returns the tick they are
    /// for (send them to the server with it).
    pub fn step(&mut self, buttons: Buttons) -> u64 {
        let buttons = if self.spectating {
            Buttons::NONE
        } else {
            buttons
        };
        self.prev_entities.clear();
        let positions = self.predictor.game().entities().map(|e| e.pos);
        self.prev_entities.extend(positions);
        self.predictor.step(buttons)
    }

    /// [`ClientGame::advance`], then at most `max_ticks` of the due ticks,
    /// the i-th of this call with `buttons(i)`, handing each input to `send`
    /// (only the newest [`MAX_SENDS_PER_UPDATE`] of a long frame: each
    /// packet repeats the ticks before it anyway). Returns the ticks run;
    /// the rest stay due.
    pub fn update(
        &mut self,
        now: Instant,
        max_ticks: u64,
        mut buttons: impl FnMut(u64) -> Buttons,
        mut send: impl FnMut(u64, Buttons),
    ) -> u64 {
        let due = u64::from(self.advance(now)).min(max_ticks);
        for i in 0..due {
            let b = if self.spectating {
                Buttons::NONE
            } else {
                buttons(i)
            };
            let tick = self.step(b);
            if due - i <= u64::from(MAX_SENDS_PER_UPDATE) && !self.offline {
                send(tick, b);
            }
        }
        due
    }

    /// Takes an authoritative snapshot (received at `update.received`):
    /// network figures, clock feedback, remote players, reconciliation.
    pub fn on_snapshot(&mut self, update: &SnapshotUpdate) -> Option<Reconciled> {
        let now = update.received;
        let tick = update.state.tick;
        self.stats.snapshot(tick, update.previous_tick, now);
        let jitter = self.stats.jitter_ticks();
        let loss = self.stats.loss();
        self.interp.set_jitter(jitter);
        self.interp.set_loss(loss);
        self.clock.set_jitter(jitter);
        self.clock.set_loss(loss);
        let remotes: Vec<EntityState> = update
            .state
            .entities
            .iter()
            .filter(|e| e.kind == kind::PLAYER && e.id != self.me.0)
            .copied()
            .collect();
        if let Some(previous) = update.previous_tick {
            self.interp.skipped(previous, tick);
        }
        self.interp.push(tick, remotes, now);
        if update.last_input_tick.is_some() {
            self.clock.observe(update.input_timing);
        }
        let r = self.predictor.reconcile(&update.state)?;
        if r.correction_px > 0.0 {
            self.stats.correction(r.correction_px, now);
        }
        if r.ahead {
            self.clock
                .catch_up_to(self.predictor.next_tick() as f64 + self.clock.target_margin());
        }
        Some(r)
    }

    /// A measured round-trip time (a ping, or QUIC's estimate).
    pub fn on_rtt(&mut self, rtt: Duration) {
        self.stats.rtt(rtt);
    }

    /// The transport's byte counters (and QUIC's RTT) at `now`.
    pub fn on_transport(&mut self, sample: TransportSample, now: Instant) {
        self.stats.transport(sample, now);
    }

    /// What to draw now (as of the last [`ClientGame::advance`]).
    pub fn view(&self) -> FrameView {
        let alpha = self.clock.alpha();
        let rate = self.clock.rate() as f32;
        let game = self.predictor.game();
        let size = px2(self.player_half * 2);
        let me = game.player(self.me).filter(|_| !self.spectating);
        let local = me.map(|p| PlayerDraw {
            id: self.me,
            name: self
                .name
                .clone()
                .or_else(|| self.names.get(&self.me).cloned()),
            pos: blend(self.predictor.prev_pos(), p.pos, alpha) + self.predictor.offset(),
            size: px2(p.half * 2),
            vel: px2(p.vel) * rate,
            facing: Facing::from_left(p.facing_left),
            grounded: p.grounded,
            won: p.won,
            dead: p.dead.is_some(),
            wall: wall_side(p.sides, p.grounded),
        });
        let remotes = self
            .interp
            .sample()
            .into_iter()
            .filter(|s| s.id != self.me.0 && game.player(PlayerId(s.id)).is_some())
            .map(|s| PlayerDraw {
                id: PlayerId(s.id),
                name: self.names.get(&PlayerId(s.id)).cloned(),
                pos: s.pos,
                size,
                vel: s.vel * rate,
                facing: Facing::from_left(s.state.flags & player_flags::FACING_LEFT != 0),
                grounded: s.state.flags & player_flags::GROUNDED != 0,
                won: s.state.flags & player_flags::WON != 0,
                dead: s.state.flags & player_flags::DEAD != 0,
                // Snapshots carry no touched sides.
                wall: None,
            })
            .collect();
        let entities = game
            .entities()
            .enumerate()
            .map(|(i, e)| {
                EntityDraw::of(&e, blend(self.prev_entities.get(i).copied(), e.pos, alpha))
            })
            .collect();
        FrameView {
            local,
            remotes,
            entities,
            tick: game.tick(),
            alpha,
            remote_tick: self.interp.render_tick().unwrap_or(0.0),
        }
    }

    /// The network panel as of `now`.
    pub fn net_stats(&self, now: Instant) -> NetStats {
        let s = &self.stats;
        let (bytes_in, bytes_out) = s.bytes_per_s();
        let tick_ms = s.tick_ms();
        let p = self.predictor.stats();
        NetStats {
            rtt_ms: s.latest_rtt().map_or(0.0, |r| r.as_secs_f32() * 1000.0),
            jitter_ms: (s.jitter_ticks() * tick_ms) as f32,
            loss: s.loss() as f32,
            snapshot_hz: s.snapshot_hz(now) as f32,
            quiet: s.quiet(now),
            bytes_in_per_s: bytes_in as f32,
            bytes_out_per_s: bytes_out as f32,
            corrections_per_s: s.corrections_per_s(now) as f32,
            last_correction_px: s.last_correction_px(),
            input_margin_ticks: self.clock.margin().unwrap_or(0.0) as f32,
            target_margin_ticks: self.clock.target_margin() as f32,
            clock_adjust: self.clock.adjust() as f32,
            interp_delay_ms: (self.interp.delay() * tick_ms) as f32,
            corrections: p.corrections,
            mispredictions: p.mispredictions,
        }
    }
}

/// The side a wall touches an airborne player on (for
/// [`PlayerDraw::wall`]): `None` on the ground, or touching both sides or
/// neither.
pub(crate) fn wall_side(sides: Sides, grounded: bool) -> Option<Facing> {
    if grounded {
        return None;
    }
    match (sides.contains(Sides::LEFT), sides.contains(Sides::RIGHT)) {
        (true, false) => Some(Facing::Left),
        (false, true) => Some(Facing::Right),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wall_side_only_in_the_air_and_only_one_side() {
        let both = Sides(Sides::LEFT.0 | Sides::RIGHT.0);
        let left_and_top = Sides(Sides::LEFT.0 | Sides::TOP.0);
        assert_eq!(wall_side(Sides::LEFT, false), Some(Facing::Left));
        assert_eq!(wall_side(left_and_top, false), Some(Facing::Left));
        assert_eq!(wall_side(Sides::RIGHT, false), Some(Facing::Right));
        assert_eq!(wall_side(Sides::RIGHT, true), None);
        assert_eq!(wall_side(both, false), None);
        assert_eq!(wall_side(Sides::BOTTOM, false), None);
        assert_eq!(wall_side(Sides::NONE, false), None);
    }

    /// The next level's game keeps the clock where it is (the room's tick
    /// goes on), unless the change's tick is ahead of it; names and
    /// watching carry over, the prediction starts afresh.
    #[test]
    fn the_next_level_carries_the_clock_on() {
        use crate::net::session::SnapshotUpdate;
        use ledge_shared::protocol::NetTiming;
        let level = ledge_levels::default_level();
        let welcome = |tick: u64, hash: u64| Welcome {
            player_id: PlayerId(1),
            room: "room-1".into(),
            level_id: "default".into(),
            level_hash: hash,
            level: Default::default(),
            session_token: Default::default(),
            server_tick: tick,
            timing: NetTiming {
                tick_rate: 60,
                snapshot_interval: 2,
                input_redundancy: 16,
            },
            sim_config: vec![],
        };
        let hash = level.content_hash();
        let start = Instant::now();
        let rtt = Duration::from_millis(20);
        let mut old = ClientGame::new(&welcome(1000, hash), level.clone(), rtt, start).unwrap();
        old.set_name("ada");
        old.on_player_joined(PlayerId(2), "bo");
        // Two seconds on, the change of tick 1060 is processed (its level
        // took that long to download).
        let later = start + Duration::from_secs(2);
        old.advance(later);
        let was = old.clock().position();
        let next = old
            .next_level(&welcome(1060, hash), level.clone(), later)
            .unwrap();
        assert!(
            next.clock().position() >= was,
            "{} {was}",
            next.clock().position()
        );
        assert_eq!(next.next_tick(), old.next_tick(), "the ticks go on");
        assert!(
            !next.synced(),
            "prediction waits for the new level's snapshot"
        );
        assert_eq!(
            next.player_names().get(&PlayerId(2)).map(String::as_str),
            Some("bo")
        );
        assert_eq!(
            next.view().local.map(|p| p.name),
            None,
            "no body until synced"
        );
        // The server runs the new level from tick 1060 with the inputs we
        // sent for those ticks (predicted on the old level): after its
        // first snapshot the new game replays them, and predicts the next
        // snapshot exactly.
        let mut old = old;
        let right = Buttons(Buttons::RIGHT);
        for _ in 0..old.advance(later) {
            old.step(right);
        }
        let mut next = old
            .next_level(&welcome(1060, hash), level.clone(), later)
            .unwrap();
        assert_eq!(next.next_tick(), old.next_tick());
        let mut server = Game::from_level(&level).unwrap();
        assert!(server.start_at(1060));
        server.add_player(PlayerId(1)).unwrap();
        let snapshot = |server: &Game| SnapshotUpdate {
            state: server.snapshot(),
            baseline_tick: None,
            previous_tick: None,
            last_input_tick: Some(server.tick() - 1),
            input_timing: 0,
            via_stream: true,
            wire_bytes: 0,
            received: later,
        };
        for _ in 0..20 {
            server.step(&[(PlayerId(1), right)]);
        }
        assert!(next.on_snapshot(&snapshot(&server)).unwrap().first);
        next.step(right);
        while server.tick() < next.next_tick() {
            server.step(&[(PlayerId(1), right)]);
        }
        let r = next.on_snapshot(&snapshot(&server)).unwrap();
        assert!(r.compared && !r.mispredicted, "{r:?}");
        // A change ahead of our clock: the clock starts from it.
        let ahead = old
            .next_level(&welcome(50_000, hash), level.clone(), later)
            .unwrap();
        assert!(ahead.clock().tick() >= 50_000);
        // Another level than the welcome's: refused.
        assert!(old
            .next_level(&welcome(1060, hash ^ 1), level, later)
            .is_err());
    }

    /// A spectator's game: the welcome's id is in no snapshot; every
    /// player is drawn interpolated, nothing is predicted for us, and the
    /// inputs sent (only acknowledgements) hold no buttons.
    #[test]
    fn a_spectator_interpolates_every_player_and_sends_no_buttons() {
        use crate::net::session::SnapshotUpdate;
        use ledge_shared::protocol::NetTiming;
        let level = ledge_levels::default_level();
        let mut server = Game::from_level(&level).unwrap();
        for id in [1, 2] {
            server.add_player(PlayerId(id)).unwrap();
        }
        let welcome = Welcome {
            player_id: PlayerId(9),
            room: "room-1".into(),
            level_id: "default".into(),
            level_hash: level.content_hash(),
            level: Default::default(),
            session_token: Default::default(),
            server_tick: 0,
            timing: NetTiming {
                tick_rate: 60,
                snapshot_interval: 2,
                input_redundancy: 16,
            },
            sim_config: vec![],
        };
        let start = Instant::now();
        let mut game = ClientGame::new(&welcome, level, Duration::from_millis(20), start).unwrap();
        game.set_spectating(true);
        assert!(game.spectating());
        let mut sent = Vec::new();
        let mut previous = None;
        for tick in 1..=240u64 {
            let now = start + Duration::from_secs_f64(tick as f64 / 60.0);
            server.step(&[
                (PlayerId(1), Buttons(Buttons::RIGHT)),
                (PlayerId(2), Buttons(Buttons::LEFT)),
            ]);
            if tick % 2 == 0 {
                let update = SnapshotUpdate {
                    state: server.snapshot(),
                    baseline_tick: None,
                    previous_tick: previous,
                    last_input_tick: None,
                    input_timing: 0,
                    via_stream: false,
                    wire_bytes: 100,
                    received: now,
                };
                previous = Some(update.state.tick);
                game.on_snapshot(&update);
            }
            game.update(
                now,
                u64::MAX,
                |_| Buttons(Buttons::RIGHT | Buttons::JUMP),
                |_, b| sent.push(b),
            );
        }
        assert!(!sent.is_empty(), "inputs still go out (acknowledgements)");
        assert!(sent.iter().all(|&b| b == Buttons::NONE), "{sent:?}");
        let view = game.view();
        assert!(view.local.is_none(), "no player of ours");
        let ids: Vec<u32> = view.remotes.iter().map(|p| p.id.0).collect();
        assert_eq!(ids, [1, 2], "every player, as a remote one");
        assert!(game.game().player(PlayerId(9)).is_none());
        let stats = game.predictor().stats();
        assert_eq!((stats.mispredictions, stats.corrections), (0, 0));
        // Interpolated a little behind the server (player 1 runs right).
        let server_x = px2(server.player(PlayerId(1)).unwrap().pos).x;
        let drawn_x = view.remotes[0].pos.x;
        assert!(
            drawn_x <= server_x && drawn_x > server_x - 60.0,
            "{drawn_x} {server_x}"
        );
    }

    #[test]
    fn our_player_is_alive_and_off_walls_at_the_start() {
        let level = ledge_levels::default_level();
        let game = ClientGame::offline(level, Instant::now()).unwrap();
        let me = game.view().local.expect("our player");
        assert!(!me.dead);
        assert_eq!(me.wall, None);
    }

    #[test]
    fn names_follow_the_roster_and_stay_bounded() {
        let level = ledge_levels::default_level();
        let mut game = ClientGame::offline(level, Instant::now()).unwrap();
        game.on_player_joined(PlayerId(7), "bo");
        game.on_player_joined(PlayerId(7), "bob");
        assert_eq!(game.player_names().get(&PlayerId(7)).unwrap(), "bob");
        for i in 100..100 + MAX_ROSTER as u32 + 10 {
            game.on_player_joined(PlayerId(i), "x");
        }
        assert_eq!(game.player_names().len(), MAX_ROSTER);
        // A known id is renamed even when full; a new one is not added.
        game.on_player_joined(PlayerId(7), "bo");
        assert_eq!(game.player_names().get(&PlayerId(7)).unwrap(), "bo");
        game.on_player_left(PlayerId(7));
        assert!(!game.player_names().contains_key(&PlayerId(7)));
        game.set_player_names(&BTreeMap::from([(PlayerId(1), "me".to_string())]));
        assert_eq!(game.player_names().len(), 1);
        // Our own name falls back to the roster's.
        assert_eq!(game.view().local.unwrap().name.as_deref(), Some("me"));
        game.set_name("ada");
        assert_eq!(game.view().local.unwrap().name.as_deref(), Some("ada"));
    }
}
