//! Ghosts: a run to race against ([`GhostRun`], sent by the server: the
//! level's record or the player's own best), played once from its replay
//! with the shared simulation into a track: where the runner was at each
//! tick of its run timer, and when it first reached each checkpoint. A
//! front end draws the ghost at the tick its own player's timer shows, so
//! both start together, and compares split times at checkpoints.

use glam::IVec2;
use ledge_shared::level::Level;
use ledge_shared::protocol::GhostRun;
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
    /// ghost.
    pub fn from_run(level: &Level, run: &GhostRun) -> Result<Ghost, GhostError> {
        let replay = replay::decode(&run.replay)?;
        let ReplayKind::Run { player, .. } = replay.header.kind else {
            return Err(GhostError::NotARun("a match's, not a run's"));
        };
        if replay.ticks() > MAX_GHOST_TICKS {
            return Err(GhostError::TooLong(replay.ticks()));
        }
        let mut playing = Playback::new(level, replay)?;
        let mut ghost = Ghost {
            record: run.record,
            player: run.player.clone(),
            millis: run.millis,
            track: Vec::new(),
            half: IVec2::ZERO,
            splits: Vec::new(),
        };
        let mut finished = false;
        while !finished && playing.step()? {
            let Some(view) = playing.game().player(player) else {
                continue;
            };
            if !view.run_started {
                continue;
            }
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
            finished = view.won;
        }
        if !finished {
            return Err(GhostError::NotARun("one whose runner never finishes"));
        }
        Ok(ghost)
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
