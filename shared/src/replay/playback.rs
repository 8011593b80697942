//! Plays a [`Replay`]: the game set to its keyframe, then stepped with its
//! events, its state hashes checked on the way; seeking goes back to the
//! nearest checkpoint (a copy of the game's state taken every
//! [`CHECKPOINT_TICKS`] on the way forward) and steps from there.

use crate::game::Game;
use crate::input::Buttons;
use crate::level::Level;
use crate::protocol::{PlayerId, StateSnapshot};

use super::{Event, Replay, ReplayError};

/// Ticks between two checkpoints (5 s at 60 Hz): the most a backward seek
/// steps.
pub const CHECKPOINT_TICKS: u64 = 300;

/// Most checkpoints kept (past them, seeking back into the end of a long
/// replay steps further).
pub const MAX_CHECKPOINTS: usize = 4096;

/// Where the playback stands in the replay.
#[derive(Debug, Clone)]
struct Cursor {
    /// The next event.
    event: usize,
    /// Steps left of the `Step` before `event`.
    steps_left: u32,
    /// Buttons held, ascending, none zero.
    held: Vec<(PlayerId, Buttons)>,
}

#[derive(Debug, Clone)]
struct Checkpoint {
    state: StateSnapshot,
    cursor: Cursor,
}

/// A replay being played (see the module documentation).
#[derive(Debug)]
pub struct Playback {
    replay: Replay,
    game: Game,
    cursor: Cursor,
    checkpoints: Vec<Checkpoint>,
}

impl Playback {
    /// Sets the game of `level` (the replay's) to the replay's start.
    pub fn new(level: &Level, replay: Replay) -> Result<Playback, ReplayError> {
        let tick = replay.start_tick();
        let unplayable = |detail: String| ReplayError::Unplayable { tick, detail };
        let mut game = Game::with_config(level, replay.header.config)
            .map_err(|e| unplayable(e.to_string()))?;
        game.restore(&replay.start)
            .map_err(|e| unplayable(format!("its start does not fit this level: {e}")))?;
        let cursor = Cursor {
            event: 0,
            steps_left: 0,
            held: replay.held.clone(),
        };
        let mut playback = Playback {
            replay,
            game,
            cursor,
            checkpoints: Vec::new(),
        };
        playback.between_steps()?;
        playback.checkpoints.push(playback.checkpoint());
        Ok(playback)
    }

    /// The replay.
    pub fn replay(&self) -> &Replay {
        &self.replay
    }

    /// The game as it stands.
    pub fn game(&self) -> &Game {
        &self.game
    }

    /// The game's tick.
    pub fn tick(&self) -> u64 {
        self.game.tick()
    }

    /// Whether every event was played.
    pub fn at_end(&self) -> bool {
        self.cursor.steps_left == 0 && self.cursor.event >= self.replay.events.len()
    }

    /// Steps one tick; `false` at the end (nothing done).
    pub fn step(&mut self) -> Result<bool, ReplayError> {
        if self.cursor.steps_left == 0 {
            // After a failure the cursor is still on the event that failed:
            // this fails again, saying why.
            self.between_steps()?;
            if self.at_end() {
                return Ok(false);
            }
            let Event::Step(n) = self.replay.events[self.cursor.event] else {
                unreachable!("between_steps stops at a step or the end");
            };
            self.cursor.steps_left = n;
            self.cursor.event += 1;
        }
        self.game.step(&self.cursor.held);
        self.cursor.steps_left -= 1;
        if self.cursor.steps_left == 0 {
            self.between_steps()?;
        }
        let tick = self.game.tick();
        let last = self.checkpoints.last().map_or(0, |c| c.state.tick);
        if tick % CHECKPOINT_TICKS == 0 && tick > last && self.checkpoints.len() < MAX_CHECKPOINTS {
            self.checkpoints.push(self.checkpoint());
        }
        Ok(true)
    }

    /// Plays every event up to the next `Step` (or the end).
    fn between_steps(&mut self) -> Result<(), ReplayError> {
        while let Some(&event) = self.replay.events.get(self.cursor.event) {
            let tick = self.game.tick();
            let unplayable = |detail: String| ReplayError::Unplayable { tick, detail };
            match event {
                Event::Step(_) => return Ok(()),
                Event::Join(id) => self
                    .game
                    .add_player(id)
                    .map_err(|e| unplayable(format!("player {} cannot join: {e}", id.0)))?,
                Event::Leave(id) => {
                    if !self.game.remove_player(id) {
                        return Err(unplayable(format!("player {} leaves, not there", id.0)));
                    }
                }
                Event::Press(id, b) => set_held(&mut self.cursor.held, id, b),
                Event::Hash(theirs) => {
                    let ours = self.game.state_hash();
                    if ours != theirs {
                        return Err(ReplayError::Diverged { tick, ours, theirs });
                    }
                }
            }
            self.cursor.event += 1;
        }
        Ok(())
    }

    fn checkpoint(&self) -> Checkpoint {
        Checkpoint {
            state: self.game.snapshot(),
            cursor: self.cursor.clone(),
        }
    }

    /// Goes to `tick`, clamped to the replay's span: backwards from the
    /// nearest checkpoint at or before it, forwards by stepping.
    pub fn seek(&mut self, tick: u64) -> Result<(), ReplayError> {
        let tick = tick.clamp(self.replay.start_tick(), self.replay.end_tick());
        if tick < self.game.tick() {
            let i = self
                .checkpoints
                .iter()
                .rposition(|c| c.state.tick <= tick)
                .unwrap_or(0);
            self.restore_checkpoint(i)?;
        }
        while self.game.tick() < tick && self.step()? {}
        Ok(())
    }

    /// Goes to the nearest checkpoint at or before `tick` (clamped to the
    /// replay's span) when that is nearer to it than where the playback
    /// stands (`tick` is behind, or a checkpoint lies ahead on the way);
    /// steps nothing. Stepping on to `tick` then lands exactly where
    /// [`Playback::seek`] does, a few ticks at a time if need be.
    pub fn restore_nearest(&mut self, tick: u64) -> Result<(), ReplayError> {
        let tick = tick.clamp(self.replay.start_tick(), self.replay.end_tick());
        let now = self.game.tick();
        let Some(i) = self.checkpoints.iter().rposition(|c| c.state.tick <= tick) else {
            return Ok(());
        };
        let at = self.checkpoints[i].state.tick;
        if tick < now || at > now {
            self.restore_checkpoint(i)?;
        }
        Ok(())
    }

    /// Puts the game and the event cursor back to checkpoint `i`.
    fn restore_checkpoint(&mut self, i: usize) -> Result<(), ReplayError> {
        let c = &self.checkpoints[i];
        self.game
            .restore(&c.state)
            .map_err(|e| ReplayError::Unplayable {
                tick: c.state.tick,
                detail: e.to_string(),
            })?;
        self.cursor = c.cursor.clone();
        Ok(())
    }

    /// Plays to the end, checking every hash: the ticks stepped.
    pub fn play_to_end(&mut self) -> Result<u64, ReplayError> {
        let mut n = 0;
        while self.step()? {
            n += 1;
        }
        Ok(n)
    }
}

/// Sets `id`'s buttons in `held` (ascending by id, none zero).
fn set_held(held: &mut Vec<(PlayerId, Buttons)>, id: PlayerId, b: Buttons) {
    match held.binary_search_by_key(&id, |&(p, _)| p) {
        Ok(i) if b.0 == 0 => {
            held.remove(i);
        }
        Ok(i) => held[i].1 = b,
        Err(_) if b.0 == 0 => {}
        Err(i) => held.insert(i, (id, b)),
    }
}
