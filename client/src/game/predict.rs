//! Client-side prediction and reconciliation.
//!
//! The [`Predictor`] owns a copy of the game for the joined level and runs
//! it ahead of the server with our inputs: every local tick it steps the
//! predicted game with our buttons (the other players hold nothing: they
//! are drawn from snapshots, and players never touch each other). It keeps
//! the inputs the server may not have applied yet and our predicted state
//! at every recent tick. On each authoritative snapshot (tick `S`):
//!
//! 1. our state in it is compared with what we predicted for tick `S`
//!    (every field: position, velocity, flags, timers): a difference is a
//!    *misprediction*;
//! 2. the predicted game is restored to the snapshot and our inputs for
//!    ticks `S..now` are replayed (the server has applied our inputs up to
//!    `last_input_tick`, normally `S - 1`; inputs it never got were replaced
//!    by repeats there, and the snapshot already holds the outcome);
//! 3. the new prediction of *now* is compared with the old one: if our
//!    player moved, that is a *correction* of that many pixels. Small ones
//!    are hidden by a visual offset that starts at the old position and
//!    decays over a few ticks; big ones (over [`SNAP_PX`], e.g. a respawn)
//!    snap.
//!
//! Everything here is integer except the visual offset (pixels, for
//! drawing only).

use std::collections::VecDeque;

use glam::{IVec2, Vec2};
use ledge_shared::game::{Game, GameConfig, GameError};
use ledge_shared::input::Buttons;
use ledge_shared::level::Level;
use ledge_shared::protocol::{EntityState, PlayerId, StateSnapshot};

use crate::view::px2;

/// Corrections larger than this (pixels) snap instead of blending.
pub const SNAP_PX: f32 = 32.0;
/// The visual offset keeps this fraction of itself each tick (0.75: a
/// correction is 94% gone after 10 ticks, a sixth of a second).
pub const BLEND_KEEP: f32 = 0.75;
/// Offsets below this (pixels) are dropped.
const OFFSET_EPSILON: f32 = 0.01;
/// Ticks of inputs and predicted states kept (the server accepts inputs at
/// most this far ahead, and a snapshot older than that is useless).
pub const PREDICTION_WINDOW: usize = 256;

/// What one snapshot did to the prediction.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Reconciled {
    /// The snapshot's tick.
    pub tick: u64,
    /// Ticks replayed after restoring it.
    pub replayed: u32,
    /// Our prediction of that tick was still kept and was compared.
    pub compared: bool,
    /// Our state at that tick differed from the prediction of it.
    pub mispredicted: bool,
    /// How far our predicted player moved at the newest tick, pixels
    /// (0: no correction).
    pub correction_px: f32,
    /// The correction was over [`SNAP_PX`] and snapped.
    pub snapped: bool,
    /// The snapshot was ahead of our newest predicted tick: our clock is
    /// late and the prediction jumped forward to it.
    pub ahead: bool,
    /// The first snapshot: prediction starts here.
    pub first: bool,
}

/// Our state in a snapshot beside what we had predicted for its tick: the
/// newest [`Reconciled::mispredicted`], kept to say what differed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mismatch {
    /// The snapshot's tick.
    pub tick: u64,
    /// Our player in the snapshot (`None`: not in it).
    pub theirs: Option<EntityState>,
    /// What we had predicted for that tick.
    pub mine: EntityState,
}

/// Counters of the predictor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PredictionStats {
    /// Snapshots reconciled.
    pub snapshots: u64,
    /// Snapshots whose state of our player differed from our prediction.
    pub mispredictions: u64,
    /// Snapshots that moved our predicted player at the newest tick.
    pub corrections: u64,
    /// Of those, how many snapped.
    pub snaps: u64,
    /// Ticks replayed in total.
    pub replayed_ticks: u64,
    /// Snapshots that could not be restored (wrong level?).
    pub refused: u64,
    /// Snapshots ahead of our clock.
    pub ahead: u64,
}

/// The predicted game and the bookkeeping to reconcile it.
#[derive(Debug, Clone)]
pub struct Predictor {
    game: Game,
    me: PlayerId,
    /// Prediction started (a snapshot was restored).
    synced: bool,
    /// Tick of the newest snapshot restored.
    restored: u64,
    /// The next tick to step (== `game.tick()` once synced).
    next_tick: u64,
    /// Our inputs by tick, contiguous, oldest first.
    inputs: VecDeque<(u64, Buttons)>,
    /// Our predicted state at game tick `t` (after stepping `t - 1`).
    predicted: VecDeque<(u64, EntityState)>,
    /// Our centre one tick before the newest, units (for blending).
    prev_pos: Option<IVec2>,
    /// Visual correction offset, pixels.
    offset: Vec2,
    last_correction_px: f32,
    last_mismatch: Option<Mismatch>,
    stats: PredictionStats,
}

impl Predictor {
    /// A predictor for player `me` in `level`, starting to record inputs at
    /// tick `start_tick`. Prediction begins at the first snapshot.
    pub fn new(level: &Level, me: PlayerId, start_tick: u64) -> Result<Predictor, GameError> {
        Self::with_config(level, GameConfig::default(), me, start_tick)
    }

    /// [`Predictor::new`] with the server's game constants (from
    /// [`ledge_shared::protocol::Welcome::sim_config`]): prediction is exact
    /// only with exactly the server's rules.
    pub fn with_config(
        level: &Level,
        config: GameConfig,
        me: PlayerId,
        start_tick: u64,
    ) -> Result<Predictor, GameError> {
        Ok(Predictor {
            game: Game::with_config(level, config)?,
            me,
            synced: false,
            restored: 0,
            next_tick: start_tick,
            inputs: VecDeque::new(),
            predicted: VecDeque::new(),
            prev_pos: None,
            offset: Vec2::ZERO,
            last_correction_px: 0.0,
            last_mismatch: None,
            stats: PredictionStats::default(),
        })
    }

    /// Takes over `other`'s inputs of ticks `since` and later, and its
    /// next tick, before the first snapshot: the game of the room's next
    /// level, whose first ticks (from `since`, the change's) the server
    /// runs with the inputs already sent for them, predicted on the old
    /// level. Without them the replay after the new level's first
    /// snapshot would hold nothing for those ticks and mispredict.
    pub fn carry_inputs(&mut self, other: &Predictor, since: u64) {
        if self.synced {
            return;
        }
        self.inputs = other
            .inputs
            .iter()
            .filter(|&&(t, _)| t >= since)
            .copied()
            .collect();
        self.next_tick = other.next_tick;
    }

    /// A predictor running `game` locally with no server: `me` is added to
    /// it and prediction starts at once (offline play, tests).
    pub fn offline(mut game: Game, me: PlayerId) -> Result<Predictor, GameError> {
        if game.player(me).is_none() {
            game.add_player(me)?;
        }
        let tick = game.tick();
        Ok(Predictor {
            game,
            me,
            synced: true,
            restored: tick,
            next_tick: tick,
            inputs: VecDeque::new(),
            predicted: VecDeque::new(),
            prev_pos: None,
            offset: Vec2::ZERO,
            last_correction_px: 0.0,
            last_mismatch: None,
            stats: PredictionStats::default(),
        })
    }

    /// Our player id.
    pub fn me(&self) -> PlayerId {
        self.me
    }

    /// The predicted game (the server's future, if we predicted right).
    pub fn game(&self) -> &Game {
        &self.game
    }

    /// Whether prediction has started (a snapshot arrived).
    pub fn synced(&self) -> bool {
        self.synced
    }

    /// The next tick [`Predictor::step`] will run: the tick of the next input.
    pub fn next_tick(&self) -> u64 {
        self.next_tick
    }

    /// Counters.
    pub fn stats(&self) -> PredictionStats {
        self.stats
    }

    /// The size of the last correction, pixels.
    pub fn last_correction_px(&self) -> f32 {
        self.last_correction_px
    }

    /// The newest misprediction: what the server had and what we predicted.
    pub fn last_mismatch(&self) -> Option<Mismatch> {
        self.last_mismatch
    }

    /// The visual offset still applied to our player, pixels.
    pub fn offset(&self) -> Vec2 {
        self.offset
    }

    /// Our centre at the tick before the newest, units (`None` before two
    /// predicted ticks).
    pub fn prev_pos(&self) -> Option<IVec2> {
        self.prev_pos
    }

    /// The buttons recorded for `tick`, if still kept.
    pub fn input(&self, tick: u64) -> Option<Buttons> {
        let &(first, _) = self.inputs.front()?;
        let i = tick.checked_sub(first)?;
        self.inputs.get(usize::try_from(i).ok()?).map(|&(_, b)| b)
    }

    /// Our predicted state at game tick `tick`, if still kept.
    pub fn predicted_at(&self, tick: u64) -> Option<&EntityState> {
        let &(first, _) = self.predicted.front()?;
        let i = usize::try_from(tick.checked_sub(first)?).ok()?;
        self.predicted.get(i).map(|(_, s)| s)
    }

    /// Runs one local tick with our `buttons`: records them for
    /// [`Predictor::next_tick`] (returned: the tick to send them for) and,
    /// once synced, steps the predicted game. The visual offset decays.
    pub fn step(&mut self, buttons: Buttons) -> u64 {
        let tick = self.next_tick;
        if self.inputs.back().is_some_and(|&(t, _)| t + 1 != tick) {
            self.inputs.clear();
        }
        self.inputs.push_back((tick, buttons));
        while self.inputs.len() > PREDICTION_WINDOW {
            self.inputs.pop_front();
        }
        if self.synced {
            self.prev_pos = self.game.player(self.me).map(|p| p.pos);
            self.game.step(&[(self.me, buttons)]);
            self.record();
        }
        self.next_tick = tick + 1;
        self.offset *= BLEND_KEEP;
        if self.offset.length_squared() < OFFSET_EPSILON * OFFSET_EPSILON {
            self.offset = Vec2::ZERO;
        }
        tick
    }

    /// Records our predicted state at the game's tick.
    fn record(&mut self) {
        let tick = self.game.tick();
        let Some(state) = self.my_state() else {
            return;
        };
        while self.predicted.back().is_some_and(|&(t, _)| t >= tick) {
            self.predicted.pop_back();
        }
        if self.predicted.back().is_some_and(|&(t, _)| t + 1 != tick) {
            self.predicted.clear();
        }
        self.predicted.push_back((tick, state));
        while self.predicted.len() > PREDICTION_WINDOW {
            self.predicted.pop_front();
        }
    }

    /// Our full entity state in the predicted game.
    fn my_state(&self) -> Option<EntityState> {
        // The snapshot holds a few dozen entities: cheap enough per tick,
        // and exactly what the server compares.
        self.game.snapshot().get(self.me.0).copied()
    }

    /// Reconciles with the authoritative `state`: restore, replay our inputs
    /// from its tick to now, measure and smooth the correction. A snapshot
    /// not newer than the last one is ignored (`None`), as is one the game
    /// refuses (counted in [`PredictionStats::refused`]).
    pub fn reconcile(&mut self, state: &StateSnapshot) -> Option<Reconciled> {
        let s = state.tick;
        if self.synced && s <= self.restored {
            return None;
        }
        let mut out = Reconciled {
            tick: s,
            first: !self.synced,
            ..Reconciled::default()
        };
        let theirs = state.get(self.me.0).copied();
        if self.synced {
            if let Some(mine) = self.predicted_at(s) {
                out.compared = true;
                out.mispredicted = theirs.as_ref() != Some(mine);
                if out.mispredicted {
                    self.last_mismatch = Some(Mismatch {
                        tick: s,
                        theirs,
                        mine: *mine,
                    });
                }
            }
        }
        let old_pos = if self.synced {
            self.game.player(self.me).map(|p| p.pos)
        } else {
            None
        };
        if let Err(e) = self.game.restore(state) {
            tracing::debug!("snapshot {s} refused: {e}");
            self.stats.refused += 1;
            return None;
        }
        self.synced = true;
        self.restored = s;
        if s > self.next_tick {
            out.ahead = true;
            self.stats.ahead += 1;
            self.next_tick = s;
        }
        // Replay: our inputs for ticks s..next_tick (a missing one repeats
        // the previous, as the server does).
        self.prev_pos = None;
        self.predicted.retain(|&(t, _)| t < s);
        self.record();
        let mut last = self.input(s.saturating_sub(1)).unwrap_or(Buttons::NONE);
        for t in s..self.next_tick {
            let b = self.input(t).unwrap_or(last);
            last = b;
            self.prev_pos = self.game.player(self.me).map(|p| p.pos);
            self.game.step(&[(self.me, b)]);
            self.record();
            out.replayed += 1;
        }
        // Inputs before the snapshot are settled.
        while self.inputs.front().is_some_and(|&(t, _)| t + 1 < s) {
            self.inputs.pop_front();
        }
        while self.predicted.front().is_some_and(|&(t, _)| t < s) {
            self.predicted.pop_front();
        }
        self.stats.snapshots += 1;
        self.stats.replayed_ticks += u64::from(out.replayed);
        if out.mispredicted {
            self.stats.mispredictions += 1;
        }
        let new_pos = self.game.player(self.me).map(|p| p.pos);
        if let (Some(old), Some(new)) = (old_pos, new_pos) {
            if old != new {
                let delta = px2(old - new);
                out.correction_px = delta.length();
                self.last_correction_px = out.correction_px;
                self.stats.corrections += 1;
                if out.correction_px > SNAP_PX {
                    out.snapped = true;
                    self.stats.snaps += 1;
                    self.offset = Vec2::ZERO;
                } else {
                    self.offset += delta;
                    if self.offset.length() > SNAP_PX {
                        self.offset = Vec2::ZERO;
                    }
                }
            }
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_levels::default_level;

    fn buttons(t: u64) -> Buttons {
        Buttons(match t % 90 {
            0..=30 => Buttons::RIGHT,
            31..=40 => Buttons::RIGHT | Buttons::JUMP,
            41..=70 => Buttons::LEFT,
            _ => 0,
        })
    }

    /// A server game `lag` ticks behind the predictor, getting `server_b`
    /// for each tick; snapshots every 2 ticks. Returns the reconciliations.
    fn run(
        p: &mut Predictor,
        server: &mut Game,
        ticks: u64,
        lag: u64,
        server_b: impl Fn(u64) -> Buttons,
    ) -> Vec<Reconciled> {
        let me = p.me();
        let mut out = Vec::new();
        for _ in 0..ticks {
            let t = p.next_tick();
            p.step(buttons(t));
            while server.tick() + lag < p.next_tick() {
                let st = server.tick();
                server.step(&[(me, server_b(st))]);
                if server.tick() % 2 == 0 {
                    out.extend(p.reconcile(&server.snapshot()));
                }
            }
        }
        out
    }

    fn setup() -> (Predictor, Game) {
        let level = default_level();
        let me = PlayerId(1);
        let mut server = Game::from_level(&level).unwrap();
        server.add_player(me).unwrap();
        server.step(&[]);
        let mut p = Predictor::new(&level, me, server.tick()).unwrap();
        let first = p.reconcile(&server.snapshot()).unwrap();
        assert!(first.first && p.synced());
        (p, server)
    }

    #[test]
    fn exact_inputs_predict_exactly_whatever_the_lag() {
        for lag in [0, 1, 4, 12] {
            let (mut p, mut server) = setup();
            let log = run(&mut p, &mut server, 400, lag, buttons);
            assert!(log.len() > 150);
            assert!(
                log.iter()
                    .all(|r| !r.mispredicted && r.correction_px == 0.0),
                "lag {lag}: {log:?}"
            );
            assert!(log.iter().skip(1).all(|r| r.compared));
            assert!(
                log.iter().skip(1).all(|r| r.replayed as u64 == lag),
                "lag {lag}"
            );
            assert_eq!(p.stats().corrections, 0);
            // The prediction is the server's future.
            let mut future = server.clone();
            for t in server.tick()..p.next_tick() {
                future.step(&[(p.me(), buttons(t))]);
            }
            assert_eq!(future.state_hash(), p.game().state_hash(), "lag {lag}");
        }
    }

    #[test]
    fn a_small_misprediction_blends_and_a_large_one_snaps() {
        let (mut p, mut server) = setup();
        // The server misses 6 ticks of our input (repeats nothing).
        let lost = |t: u64| {
            if (20..26).contains(&t) {
                Buttons::NONE
            } else {
                buttons(t)
            }
        };
        let log = run(&mut p, &mut server, 60, 4, lost);
        let fixed: Vec<&Reconciled> = log.iter().filter(|r| r.correction_px > 0.0).collect();
        assert!(!fixed.is_empty(), "{log:?}");
        assert!(fixed
            .iter()
            .all(|r| !r.snapped && r.correction_px < SNAP_PX));
        assert!(log.iter().any(|r| r.mispredicted));
        // What differed is kept to say so.
        let m = p.last_mismatch().expect("a mismatch kept");
        assert_ne!(m.theirs, Some(m.mine));
        assert!(log.iter().any(|r| r.mispredicted && r.tick == m.tick));
        // Later snapshots agree again, and the offset has decayed.
        let _ = run(&mut p, &mut server, 60, 4, lost);
        let log = run(&mut p, &mut server, 60, 4, lost);
        assert!(log
            .iter()
            .all(|r| !r.mispredicted && r.correction_px == 0.0));
        assert_eq!(p.offset(), Vec2::ZERO);

        // A blended correction: the offset starts at the correction and
        // decays by BLEND_KEEP per tick.
        let mut shifted = server.snapshot();
        let e = shifted.entities.iter_mut().find(|e| e.id == 1).unwrap();
        e.pos.x += 10 * 256;
        server.restore(&shifted).unwrap();
        let r = run(&mut p, &mut server, 2, 4, buttons);
        let r = r.iter().find(|r| r.correction_px > 0.0).expect("corrected");
        assert!(!r.snapped && (r.correction_px - 10.0).abs() < 4.0, "{r:?}");
        let o = p.offset().length();
        assert!(o > 5.0, "{o}");
        p.step(Buttons::NONE);
        server.step(&[(p.me(), Buttons::NONE)]);
        assert!((p.offset().length() - o * BLEND_KEEP).abs() < 1e-3);

        // A teleport of 100 px snaps.
        let mut far = server.snapshot();
        let e = far.entities.iter_mut().find(|e| e.id == 1).unwrap();
        e.pos.x += 100 * 256;
        server.restore(&far).unwrap();
        let r = run(&mut p, &mut server, 2, 4, buttons);
        let r = r.iter().find(|r| r.correction_px > 0.0).expect("corrected");
        assert!(r.snapped && r.correction_px > SNAP_PX, "{r:?}");
        assert_eq!(p.offset(), Vec2::ZERO);
        assert_eq!(p.stats().snaps, 1);
    }

    #[test]
    fn a_snapshot_ahead_of_the_prediction_jumps_forward_and_old_ones_are_ignored() {
        let (mut p, mut server) = setup();
        for _ in 0..10 {
            server.step(&[]);
        }
        let r = p.reconcile(&server.snapshot()).unwrap();
        assert!(r.ahead);
        assert_eq!(p.next_tick(), server.tick());
        let old = server.snapshot();
        server.step(&[]);
        server.step(&[]);
        assert!(p.reconcile(&server.snapshot()).is_some());
        assert!(p.reconcile(&old).is_none(), "older than the last one");
    }

    #[test]
    fn idle_players_coming_and_going_never_disturb_the_prediction() {
        // Idle players join and leave the server's game at their own ticks
        // (freed body slots are reused there, so the client's bodies and
        // colliders get other ids): with exact inputs we still predict
        // the server exactly.
        let level = default_level();
        let me = PlayerId(5);
        let mut server = Game::from_level(&level).unwrap();
        for id in 1..5 {
            server.add_player(PlayerId(id)).unwrap();
            for _ in 0..7 {
                server.step(&[]);
            }
        }
        server.add_player(me).unwrap();
        server.step(&[]);
        let lag = 6;
        let first = server.tick() + lag;
        let mut p = Predictor::new(&level, me, first).unwrap();
        p.reconcile(&server.snapshot()).unwrap();
        // Our inputs start at `first`: the server holds nothing before.
        let ours = |t: u64| if t < first { Buttons::NONE } else { buttons(t) };
        let (mut next_id, mut present) = (6, vec![1, 2, 3, 4]);
        let mut churn = 0;
        for _ in 0..1200 {
            let t = p.next_tick();
            p.step(buttons(t));
            while server.tick() + lag < p.next_tick() {
                let st = server.tick();
                if st % 37 == 0 && present.len() < 12 {
                    server.add_player(PlayerId(next_id)).unwrap();
                    present.push(next_id);
                    next_id += 1;
                    churn += 1;
                }
                if st % 53 == 0 && present.len() > 2 {
                    assert!(server.remove_player(PlayerId(present.remove(0))));
                    churn += 1;
                }
                server.step(&[(me, ours(st))]);
                if server.tick() % 2 == 0 {
                    let r = p.reconcile(&server.snapshot()).unwrap();
                    assert!(!r.mispredicted && r.correction_px == 0.0, "{r:?}");
                }
            }
        }
        assert!(churn > 30, "{churn}");
        assert!(p.stats().snapshots > 500);
        assert_eq!(p.stats().mispredictions, 0);
        let mut future = server.clone();
        for t in server.tick()..p.next_tick() {
            future.step(&[(me, ours(t))]);
        }
        assert_eq!(future.state_hash(), p.game().state_hash());
    }

    #[test]
    fn four_players_on_the_move_are_each_predicted_exactly() {
        // Four players running the script from other points, joining at
        // other ticks, each predicted by its own client 4 to 6 ticks
        // ahead: the coins they race for, the crate and the elevator
        // never make a prediction of one's own player wrong.
        let level = default_level();
        for phase in 0..8u64 {
            let mut server = Game::from_level(&level).unwrap();
            for _ in 0..phase * 3 {
                server.step(&[]);
            }
            let lag = 4 + phase % 3;
            let mut clients = Vec::new();
            for k in 0..4u32 {
                let id = PlayerId(k + 1);
                server.add_player(id).unwrap();
                for _ in 0..(phase % 7) + 2 {
                    server.step(&[]);
                }
                let mut p = Predictor::new(&level, id, server.tick()).unwrap();
                p.reconcile(&server.snapshot()).unwrap();
                clients.push(p);
            }
            let start = server.tick() + lag;
            let b = |k: usize, t: u64| {
                if t < start {
                    Buttons::NONE
                } else {
                    crate::bot::brain::drill(t + k as u64 * 57)
                }
            };
            for (k, p) in clients.iter_mut().enumerate() {
                while p.next_tick() < server.tick() + lag {
                    let t = p.next_tick();
                    p.step(b(k, t));
                }
            }
            for _ in 0..1800 {
                let st = server.tick();
                let inputs: Vec<_> = (0..4).map(|k| (PlayerId(k as u32 + 1), b(k, st))).collect();
                server.step(&inputs);
                for (k, p) in clients.iter_mut().enumerate() {
                    let t = p.next_tick();
                    p.step(b(k, t));
                    if server.tick() % 2 == 0 {
                        let r = p.reconcile(&server.snapshot()).unwrap();
                        assert!(
                            !r.mispredicted,
                            "phase {phase}, player {}: {:?}",
                            k + 1,
                            p.last_mismatch()
                        );
                    }
                }
            }
            let moved = clients.iter().filter(|p| {
                p.game()
                    .player(p.me())
                    .is_some_and(|pl| pl.pos.x != 88 * 256)
            });
            assert!(moved.count() > 0);
        }
    }
}
