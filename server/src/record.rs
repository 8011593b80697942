//! Match recording: what a room's simulation actually did, tick by tick, so
//! a match can be replayed headlessly and checked against the server.
//!
//! A [`MatchRecord`] holds, for every tick a room ran, the players that
//! joined or left before it ([`Change`]), the inputs the game was stepped
//! with (after the room's own input handling: a late or missing input is
//! already replaced by the repeat the room applied) and the game's
//! [`Game::state_hash`] after the step. Replaying it from the same level
//! and [`GameConfig`] — add and remove players as recorded, step with the
//! recorded inputs — must give the same hash at every tick: that is the
//! determinism of the simulation across the wire.
//!
//! Recording is off by default (`ServerConfig::record_ticks`). When on, each
//! room writes into a [`Recorder`] (shared, cheap to clone) that
//! [`crate::Server::recorder`] hands out; [`Recorder::snapshot`] copies the
//! record at any time, while the server runs or after it stopped.
//!
//! Bounded: a record keeps the *first* `limit` ticks of the room and then
//! stops (`truncated` is set and later ticks are only counted). Keeping the
//! beginning rather than a ring of the latest ticks means a record always
//! replays from the level's initial state, with no game state to store.

use std::sync::{Arc, Mutex, MutexGuard};

use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use serde::{Deserialize, Serialize};

/// A player joining or leaving the game, between two ticks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Change {
    /// `Game::add_player` succeeded for this player.
    Join(PlayerId),
    /// `Game::remove_player` removed this player.
    Leave(PlayerId),
}

/// One tick the room ran.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecordedTick {
    /// The game's tick before the step (the step makes it `tick + 1`).
    pub tick: u64,
    /// Joins and leaves applied since the previous tick, in order.
    pub changes: Vec<Change>,
    /// The inputs the game was stepped with, in the order given.
    pub inputs: Vec<(PlayerId, Buttons)>,
    /// `Game::state_hash` after the step.
    pub state_hash: u64,
}

/// A room's match, tick by tick (see the module documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MatchRecord {
    /// The room's name.
    pub room: String,
    /// The level's id (as sent in `Welcome`).
    pub level_id: String,
    /// The level's hash (as sent in `Welcome`).
    pub level_hash: u64,
    /// The game's configuration: replay with `Game::with_config`.
    pub config: GameConfig,
    /// The game's tick when recording started.
    pub start_tick: u64,
    /// The game's state hash when recording started.
    pub start_hash: u64,
    /// Every tick run since, oldest first, at most `limit`.
    pub ticks: Vec<RecordedTick>,
    /// Most ticks kept.
    pub limit: usize,
    /// Ticks run after the record was full (not recorded).
    pub dropped_ticks: u64,
    /// Whether the room started: before, the record is empty.
    pub started: bool,
    /// Changes waiting for the next tick.
    pending: Vec<Change>,
}

impl MatchRecord {
    /// An empty record for `room` keeping at most `limit` ticks.
    pub fn new(room: &str, level_id: &str, level_hash: u64, limit: usize) -> MatchRecord {
        MatchRecord {
            room: room.to_owned(),
            level_id: level_id.to_owned(),
            level_hash,
            config: GameConfig::default(),
            start_tick: 0,
            start_hash: 0,
            ticks: Vec::new(),
            limit,
            dropped_ticks: 0,
            started: false,
            pending: Vec::new(),
        }
    }

    /// Whether ticks were dropped because the record was full.
    pub fn truncated(&self) -> bool {
        self.dropped_ticks > 0
    }

    fn full(&self) -> bool {
        self.ticks.len() >= self.limit
    }
}

/// A room's handle on its [`MatchRecord`]; clones share the record.
#[derive(Debug, Clone)]
pub struct Recorder(Arc<Mutex<MatchRecord>>);

impl Recorder {
    /// A recorder for `room` keeping at most `limit` ticks.
    pub fn new(room: &str, level_id: &str, level_hash: u64, limit: usize) -> Recorder {
        Recorder(Arc::new(Mutex::new(MatchRecord::new(
            room, level_id, level_hash, limit,
        ))))
    }

    /// Locks the record, ignoring poisoning (every update leaves it
    /// consistent).
    fn lock(&self) -> MutexGuard<'_, MatchRecord> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The room's name.
    pub fn room(&self) -> String {
        self.lock().room.clone()
    }

    /// Starts recording `game` (the room's game before its first tick).
    pub fn start(&self, game: &Game) {
        let mut r = self.lock();
        r.config = *game.config();
        r.start_tick = game.tick();
        r.start_hash = game.state_hash();
        r.ticks.clear();
        r.pending.clear();
        r.dropped_ticks = 0;
        r.started = true;
    }

    /// A player was added to the game.
    pub fn join(&self, player: PlayerId) {
        self.change(Change::Join(player));
    }

    /// A player was removed from the game.
    pub fn leave(&self, player: PlayerId) {
        self.change(Change::Leave(player));
    }

    fn change(&self, change: Change) {
        let mut r = self.lock();
        // Once full nothing more is kept; the pending changes are bounded
        // by the commands a room handles between two ticks.
        if r.started && !r.full() {
            r.pending.push(change);
        }
    }

    /// The room stepped tick `tick` with `inputs`; `state_hash` gives the
    /// hash after the step (only computed while there is room for it).
    pub fn tick(
        &self,
        tick: u64,
        inputs: &[(PlayerId, Buttons)],
        state_hash: impl FnOnce() -> u64,
    ) {
        let mut r = self.lock();
        if !r.started {
            return;
        }
        if r.full() {
            r.dropped_ticks += 1;
            r.pending.clear();
            return;
        }
        let changes = std::mem::take(&mut r.pending);
        r.ticks.push(RecordedTick {
            tick,
            changes,
            inputs: inputs.to_vec(),
            state_hash: state_hash(),
        });
    }

    /// A copy of the record as it stands.
    pub fn snapshot(&self) -> MatchRecord {
        self.lock().clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_levels::default_level;

    fn game() -> Game {
        Game::from_level(&default_level()).unwrap()
    }

    /// Plays a few ticks with a join and a leave, recording them.
    fn play(recorder: &Recorder, game: &mut Game, ticks: u64) {
        recorder.start(game);
        let (a, b) = (PlayerId(1), PlayerId(2));
        for t in 0..ticks {
            if t == 2 {
                game.add_player(a).unwrap();
                recorder.join(a);
            }
            if t == 5 {
                game.add_player(b).unwrap();
                recorder.join(b);
            }
            if t == 9 && game.remove_player(a) {
                recorder.leave(a);
            }
            let mut inputs = Vec::new();
            for (id, _) in game.players() {
                let b = [
                    Buttons::RIGHT,
                    Buttons::RIGHT | Buttons::JUMP,
                    Buttons::LEFT,
                ];
                inputs.push((id, Buttons(b[(t % 3) as usize])));
            }
            let tick = game.tick();
            game.step(&inputs);
            recorder.tick(tick, &inputs, || game.state_hash());
        }
    }

    #[test]
    fn a_record_replays_to_the_same_hashes() {
        let mut g = game();
        let recorder = Recorder::new("room-1", "default", 7, 100);
        play(&recorder, &mut g, 20);
        let record = recorder.snapshot();
        assert_eq!(record.ticks.len(), 20);
        assert!(!record.truncated());
        assert_eq!(record.ticks[2].changes, [Change::Join(PlayerId(1))]);
        assert_eq!(record.ticks[9].changes, [Change::Leave(PlayerId(1))]);
        let mut replay = Game::with_config(&default_level(), record.config).unwrap();
        assert_eq!(replay.state_hash(), record.start_hash);
        for t in &record.ticks {
            for c in &t.changes {
                match *c {
                    Change::Join(p) => replay.add_player(p).unwrap(),
                    Change::Leave(p) => assert!(replay.remove_player(p)),
                }
            }
            assert_eq!(replay.tick(), t.tick);
            replay.step(&t.inputs);
            assert_eq!(replay.state_hash(), t.state_hash, "tick {}", t.tick);
        }
        assert_eq!(replay.state_hash(), g.state_hash());
    }

    #[test]
    fn a_full_record_keeps_the_beginning_and_counts_the_rest() {
        let mut g = game();
        let recorder = Recorder::new("room-1", "default", 7, 8);
        play(&recorder, &mut g, 20);
        let record = recorder.snapshot();
        assert_eq!(record.ticks.len(), 8);
        assert_eq!(record.ticks[0].tick, 0);
        assert_eq!(record.dropped_ticks, 12);
        assert!(record.truncated());
        // The leave at tick 9 came after the record was full.
        assert!(record
            .ticks
            .iter()
            .all(|t| !t.changes.contains(&Change::Leave(PlayerId(1)))));
    }

    #[test]
    fn nothing_is_recorded_before_the_start() {
        let recorder = Recorder::new("room-1", "default", 7, 8);
        recorder.join(PlayerId(1));
        recorder.tick(0, &[], || unreachable!("not started"));
        let record = recorder.snapshot();
        assert!(record.ticks.is_empty() && !record.started);
    }
}
