//! Ghosts: a run to race against ([`GhostRun`], sent by the server: the
//! level's record or the player's own best), played once from its replay
//! with the shared simulation into a track: where the runner was at each
//! tick of its run timer, and when it first reached each checkpoint. A
//! front end draws the ghost at the tick its own player's timer shows, so
//! both start together, and compares split times at checkpoints.

use glam::IVec2;
use ledge_shared::level::Level;
use ledge_shared::protocol::{GhostRun, PlayerId};
use ledge_shared::replay::{self, Playback, ReplayKind};

/// Longest run a ghost follows, in ticks (30 minutes at 60 Hz): a bound on
/// the time and memory a server's replay can cost.
pub const MAX_GHOST_TICKS: u64 = 30 * 60 * 60;

/// Why a ghost cannot be made.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GhostError {
    /// The replay does not read or play.
    #[error("the ghost's replay: {0}")]
    Replay(#[from] replay::ReplayError),
    /// It is not a run's replay, or the runner never finished in it.
    #[error("the ghost's replay is {0}")]
    NotARun(&'static str),
    /// Longer than [`MAX_GHOST_TICKS`].
    #[error("the ghost's run is {0} ticks, over the limit of {MAX_GHOST_TICKS}")]
    TooLong(u64),
}

/// A run, ready to race against (see the module documentation).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ghost {
    /// The level's record (`false`: our own best).
    pub record: bool,
    /// Who ran it.
    pub player: String,
    /// Its time, milliseconds (as the records keep it).
    pub millis: u64,
    /// The runner's centre at each tick of its run timer: index 0 when the
    /// timer started, the last at its finish.
    pub track: Vec<IVec2>,
    /// The runner's half size.
    pub half: IVec2,
    /// The timer's tick at which the runner first reached each checkpoint
    /// (by entity id), in the order reached.
    pub splits: Vec<(u32, u32)>,
}

impl Ghost {
    /// Plays `run`'s replay on `level` (the level the server plays) into a
    /// ghost, all at once ([`GhostBuilder`] driven to its end: for tests
    /// and headless users; a frame loop builds it a few ticks per frame).
    pub fn from_run(level: &Level, run: &GhostRun) -> Result<Ghost, GhostError> {
        let mut builder = GhostBuilder::new(level, run)?;
        while !builder.is_done() {
            builder.build(u64::MAX)?;
        }
        Ok(builder
            .finish()
            .expect("a builder that is done has its ghost"))
    }

    /// Ticks of the run.
    pub fn ticks(&self) -> u32 {
        self.track.len().saturating_sub(1) as u32
    }

    /// Where the runner was at tick `run_tick` of its timer (at the goal
    /// once finished).
    pub fn at(&self, run_tick: u32) -> Option<IVec2> {
        let last = self.track.len().checked_sub(1)?;
        Some(self.track[(run_tick as usize).min(last)])
    }

    /// The timer's tick at which the runner reached checkpoint `id`.
    pub fn split(&self, id: u32) -> Option<u32> {
        self.splits.iter().find(|&&(c, _)| c == id).map(|&(_, t)| t)
    }
}

/// Simulation ticks a [`GhostBuilder`] steps per frame
/// ([`crate::net::online::OnlineGame`]'s update spends this on the ghosts
/// being built).
///
/// A tick of a ghost's replay costs about 1.6 µs with the runner alone
/// and 4 to 5 µs with the 8 players of a full room in a release build on
/// a 2-core VM (`cargo run --release -p ledge-client --example
/// ghost_build -- 8 29`: a 29-minute run among 8 players took 484 ms in
/// one go, one frame; 300 ticks per frame, a median of 1.1 ms over 350
/// frames). 300 ticks keeps a frame's share near 1 ms (a fraction of a
/// 60 Hz frame's 16.7 ms, even at a few times that cost in a browser's
/// wasm); a 10 s record is built in two to four frames, a 30-minute run
/// (108,000 ticks) in 360, 6 s.
pub const GHOST_TICKS_PER_FRAME: u64 = 300;

/// A ghost being played from its replay a few ticks at a time
/// ([`GhostBuilder::build`]), so that a long run does not stall a frame.
/// Once [`GhostBuilder::is_done`], [`GhostBuilder::finish`] gives exactly
/// the ghost [`Ghost::from_run`] gives; an error is reported by the call
/// that finds it.
#[derive(Debug)]
pub struct GhostBuilder {
    playing: Playback,
    runner: PlayerId,
    /// The ghost so far (its track as far as played).
    ghost: Ghost,
    /// Ticks stepped so far.
    stepped: u64,
    /// The runner finished: the ghost is complete.
    done: bool,
}

impl GhostBuilder {
    /// Reads `run`'s replay and sets it to its start on `level` (the
    /// level the server plays); nothing is stepped yet. Refuses a replay
    /// that does not read, is not a run's, or is too long.
    pub fn new(level: &Level, run: &GhostRun) -> Result<GhostBuilder, GhostError> {
        let replay = replay::decode(&run.replay)?;
        let ReplayKind::Run { player, .. } = replay.header.kind else {
            return Err(GhostError::NotARun("a match's, not a run's"));
        };
        if replay.ticks() > MAX_GHOST_TICKS {
            return Err(GhostError::TooLong(replay.ticks()));
        }
        let playing = Playback::new(level, replay)?;
        Ok(GhostBuilder {
            playing,
            runner: player,
            ghost: Ghost {
                record: run.record,
                player: run.player.clone(),
                millis: run.millis,
                track: Vec::new(),
                half: IVec2::ZERO,
                splits: Vec::new(),
            },
            stepped: 0,
            done: false,
        })
    }

    /// Whether it is the level's record (`false`: our own best).
    pub fn record(&self) -> bool {
        self.ghost.record
    }

    /// Who ran it.
    pub fn player(&self) -> &str {
        &self.ghost.player
    }

    /// Whether the ghost is complete (the runner finished).
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// Ticks of the replay stepped so far.
    pub fn stepped(&self) -> u64 {
        self.stepped
    }

    /// Steps at most `max_ticks` more ticks of the replay (none once
    /// done); returns how many it stepped. An error: the replay does not
    /// play on, or it ended without the runner finishing.
    pub fn build(&mut self, max_ticks: u64) -> Result<u64, GhostError> {
        let mut n = 0;
        while !self.done && n < max_ticks {
            if !self.playing.step()? {
                return Err(GhostError::NotARun("one whose runner never finishes"));
            }
            n += 1;
            self.stepped += 1;
            self.track_runner();
        }
        Ok(n)
    }

    /// Notes where the runner is after a step.
    fn track_runner(&mut self) {
        let Some(view) = self.playing.game().player(self.runner) else {
            return;
        };
        if !view.run_started {
            return;
        }
        let ghost = &mut self.ghost;
        let at = view.run_ticks as usize;
        if at + 1 < ghost.track.len() {
            // The runner restarted: this is another run.
            ghost.track.clear();
            ghost.splits.clear();
        }
        ghost.track.resize(at + 1, view.pos);
        ghost.track[at] = view.pos;
        ghost.half = view.half;
        if let Some(c) = view.checkpoint {
            if !ghost.splits.iter().any(|&(id, _)| id == c) {
                ghost.splits.push((c, view.run_ticks));
            }
        }
        self.done = view.won;
    }

    /// The ghost, once done (`None` before).
    pub fn finish(self) -> Option<Ghost> {
        self.done.then_some(self.ghost)
    }
}

#[cfg(test)]
pub(crate) mod tests;
