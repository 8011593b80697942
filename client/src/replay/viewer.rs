//! [`ReplayViewer`]: a [`Playback`] under a viewer's controls, sans IO.
//!
//! The front end calls [`ReplayViewer::advance`] once per frame with the
//! frame's duration: the replay steps as many ticks as are due at its
//! speed ([`SPEEDS`]), and the frame is drawn between the last two
//! ([`ReplayViewer::view`]). Space pauses, the speed keys pick another of
//! [`SPEEDS`], seeking goes anywhere between the start and the end, and
//! the camera follows one of the players in the game or none
//! ([`Follow`]).
//!
//! A seek ([`ReplayViewer::seek`]) goes at once to the nearest checkpoint
//! at or before its target (one every 5 s of what was played so far,
//! [`Playback::restore_nearest`]) and steps the rest in the frames after,
//! at most [`SEEK_TICKS_PER_FRAME`] each ([`ReplayViewer::seeking`] says
//! where to; [`ReplayViewer::tick`] is the tick reached so far): the End
//! of a 30-minute match played for the first time takes a few seconds of
//! frames rather than one frozen frame. It lands exactly where one seek
//! in one go does ([`ReplayViewer::finish_seek`]: the same tick and
//! state); a newer seek replaces one under way.
//!
//! A run's replay opens at the run's start (the replay itself starts at a
//! keyframe up to 10 s earlier), following the runner; a match's at its
//! start, following its first player.
//!
//! A replay that fails to play on (it plays differently from the server,
//! [`ReplayError::Diverged`], or cannot be stepped) stops at the tick it
//! failed at: [`ReplayViewer::failure`] says why, and everything before
//! that tick can still be watched. (The playback is not stepped again past
//! a failure: its events there are not a step.)

use ledge_shared::game::Game;
use ledge_shared::level::Level;
use ledge_shared::protocol::PlayerId;
use ledge_shared::replay::{Playback, Replay, ReplayError, ReplayKind};

pub use crate::follow::Follow;
use crate::replay::view::{frame_view, Before};
use crate::view::FrameView;

/// The speeds a replay plays at, slowest first (1.0: as it was played).
pub const SPEEDS: [f32; 5] = [0.25, 0.5, 1.0, 2.0, 4.0];

/// [`SPEEDS`]' index of 1x.
const NORMAL_SPEED: usize = 2;

/// At most this many ticks are due at once (a frame that took seconds
/// does not stall the next one stepping them all).
pub const MAX_DUE_TICKS: f64 = 240.0;

/// Most ticks a seek steps per frame ([`ReplayViewer::advance`]). A tick
/// of a match replay costs about 4 µs with 8 players in a release build
/// (the ghosts' measure, [`crate::ghost::GHOST_TICKS_PER_FRAME`]): 600
/// ticks (10 s of play) is about 2 ms of a frame (`cargo run --release -p
/// ledge-client --example replay_seek`), so a 5 s skip lands
/// in the frame it was asked in, and the End of a 30-minute match played
/// for the first time (108,000 ticks) in 180 frames, 3 s, each frame
/// drawn.
pub const SEEK_TICKS_PER_FRAME: u64 = 600;

/// A replay being watched (see the module documentation).
#[derive(Debug)]
pub struct ReplayViewer {
    playback: Playback,
    /// Index into [`SPEEDS`].
    speed: usize,
    paused: bool,
    /// Ticks due and not yet stepped; its fraction is how far the frame is
    /// drawn between the last two ticks.
    due: f64,
    /// Where things stood before the last step.
    before: Before,
    follow: Follow,
    /// Where the viewer opened: the run's start, or the replay's.
    home: u64,
    /// The tick the replay failed to play on at, and why.
    failed: Option<(u64, ReplayError)>,
    /// Where a seek under way goes.
    target: Option<u64>,
}

impl ReplayViewer {
    /// Opens `replay` on `level` (its level): at a run's start following
    /// the runner, else at the start following the first player; playing
    /// at 1x.
    pub fn new(level: &Level, replay: Replay) -> Result<ReplayViewer, ReplayError> {
        let kind = replay.header.kind;
        let playback = Playback::new(level, replay)?;
        let before = Before::of(playback.game());
        let mut viewer = ReplayViewer {
            home: playback.tick(),
            playback,
            speed: NORMAL_SPEED,
            paused: false,
            due: 0.0,
            before,
            follow: Follow::Free,
            failed: None,
            target: None,
        };
        match kind {
            ReplayKind::Run {
                player, start_tick, ..
            } => {
                viewer.follow = Follow::Player(player);
                viewer.seek(start_tick)?;
                viewer.finish_seek()?;
                viewer.home = viewer.tick();
            }
            ReplayKind::Match => {
                let first = viewer.players().first().copied();
                let named = viewer.replay().header.names.first().map(|n| n.0);
                if let Some(id) = first.or(named) {
                    viewer.follow = Follow::Player(id);
                }
            }
        }
        Ok(viewer)
    }

    /// The replay.
    pub fn replay(&self) -> &Replay {
        self.playback.replay()
    }

    /// The game as it stands.
    pub fn game(&self) -> &Game {
        self.playback.game()
    }

    /// The game's tick.
    pub fn tick(&self) -> u64 {
        self.playback.tick()
    }

    /// Ticks per second the replay was played at.
    pub fn tick_rate(&self) -> u32 {
        u32::from(self.replay().header.tick_rate.max(1))
    }

    /// The game's tick where the replay starts.
    pub fn start_tick(&self) -> u64 {
        self.replay().start_tick()
    }

    /// The game's tick where it ends.
    pub fn end_tick(&self) -> u64 {
        self.replay().end_tick()
    }

    /// Where the viewer opened (a run's start, or the replay's start):
    /// [`ReplayViewer::seek_home`] goes back there.
    pub fn home(&self) -> u64 {
        self.home
    }

    /// Ticks since the replay's start.
    pub fn elapsed(&self) -> u64 {
        self.tick() - self.start_tick()
    }

    /// Ticks in the whole replay.
    pub fn total(&self) -> u64 {
        self.end_tick() - self.start_tick()
    }

    /// The last tick that can be shown: the end, or the tick before a
    /// failure.
    fn limit(&self) -> u64 {
        self.failed
            .as_ref()
            .map_or(self.end_tick(), |(tick, _)| tick.saturating_sub(1))
            .max(self.start_tick())
    }

    /// Whether it stands at its end (or where it failed): nothing more
    /// plays.
    pub fn at_end(&self) -> bool {
        self.playback.at_end() || self.tick() >= self.limit()
    }

    /// Why the replay does not play on past [`ReplayViewer::failed_at`],
    /// if it failed.
    pub fn failure(&self) -> Option<&ReplayError> {
        self.failed.as_ref().map(|(_, e)| e)
    }

    /// The tick it failed at, if it did.
    pub fn failed_at(&self) -> Option<u64> {
        self.failed.as_ref().map(|(t, _)| *t)
    }

    /// Paused (by the viewer; the end stops it too).
    pub fn paused(&self) -> bool {
        self.paused
    }

    /// Pauses or plays on. At the end (not a failure's), it plays again
    /// from [`ReplayViewer::home`].
    pub fn toggle_pause(&mut self) -> Result<(), ReplayError> {
        if self.at_end() && self.failed.is_none() {
            self.seek_home()?;
            self.paused = false;
        } else {
            self.paused = !self.paused;
        }
        Ok(())
    }

    /// The speed (1.0: as played).
    pub fn speed(&self) -> f32 {
        SPEEDS[self.speed]
    }

    /// The next faster speed of [`SPEEDS`] (the fastest stays).
    pub fn faster(&mut self) {
        self.speed = (self.speed + 1).min(SPEEDS.len() - 1);
    }

    /// The next slower speed (the slowest stays).
    pub fn slower(&mut self) {
        self.speed = self.speed.saturating_sub(1);
    }

    /// Sets the speed to the one of [`SPEEDS`] nearest `speed`.
    pub fn set_speed(&mut self, speed: f32) {
        let distance = |s: f32| (s.ln() - speed.max(0.01).ln()).abs();
        self.speed = (0..SPEEDS.len())
            .min_by(|&a, &b| distance(SPEEDS[a]).total_cmp(&distance(SPEEDS[b])))
            .unwrap_or(NORMAL_SPEED);
    }

    /// A frame of `seconds` passed: steps the ticks due at the speed (none
    /// while paused or at the end), at most `max_ticks`. Returns the ticks
    /// stepped; an error stops the replay where it failed.
    ///
    /// During a seek it plays nothing (and returns 0): it steps on towards
    /// the seek's target, at most [`SEEK_TICKS_PER_FRAME`] ticks.
    pub fn advance(&mut self, seconds: f64, max_ticks: u64) -> Result<u64, ReplayError> {
        if self.target.is_some() {
            self.seek_on(SEEK_TICKS_PER_FRAME)?;
            return Ok(0);
        }
        if !self.paused && !self.at_end() {
            let ticks = seconds.max(0.0) * f64::from(self.tick_rate()) * f64::from(self.speed());
            self.due = (self.due + ticks).min(MAX_DUE_TICKS);
        }
        let mut stepped = 0;
        while self.due >= 1.0 && stepped < max_ticks && !self.at_end() {
            self.before.take(self.playback.game());
            if let Err(e) = self.playback.step() {
                return Err(self.fail(e));
            }
            self.due -= 1.0;
            stepped += 1;
        }
        if self.at_end() || stepped == max_ticks {
            // Nothing more is stepped now (the end, or as many ticks as
            // the caller wanted): draw the tick reached, exactly.
            self.due = 1.0;
        }
        Ok(stepped)
    }

    /// Notes a failure at the current tick; returns it.
    fn fail(&mut self, e: ReplayError) -> ReplayError {
        self.failed = Some((self.tick(), e.clone()));
        self.due = 1.0;
        e
    }

    /// How far the frame is drawn from the tick before towards the current
    /// one, 0..=1.
    pub fn alpha(&self) -> f32 {
        self.due.clamp(0.0, 1.0) as f32
    }

    /// Starts a seek to game tick `tick`, clamped to the replay (and to
    /// before a failure), replacing one under way: at once to the nearest
    /// checkpoint at or before it, then on in the frames after
    /// ([`ReplayViewer::advance`]; see the module documentation).
    pub fn seek(&mut self, tick: u64) -> Result<(), ReplayError> {
        let target = tick.clamp(self.start_tick(), self.limit());
        if let Err(e) = self.playback.restore_nearest(target) {
            self.target = None;
            return Err(self.fail(e));
        }
        self.target = Some(target);
        self.seek_on(0)
    }

    /// Where the seek under way goes, if one is.
    pub fn seeking(&self) -> Option<u64> {
        self.target
    }

    /// Steps the seek under way to its target now, however far.
    pub fn finish_seek(&mut self) -> Result<(), ReplayError> {
        self.seek_on(u64::MAX)
    }

    /// Steps the seek under way at most `max_ticks` on; once at its target
    /// it is done (nothing blended across it). An error stops the replay
    /// there, as playing does.
    fn seek_on(&mut self, max_ticks: u64) -> Result<(), ReplayError> {
        let Some(target) = self.target else {
            return Ok(());
        };
        let mut stepped = 0;
        while self.tick() < target && stepped < max_ticks {
            match self.playback.step() {
                Ok(true) => stepped += 1,
                Ok(false) => break,
                Err(e) => {
                    self.target = None;
                    return Err(self.fail(e));
                }
            }
        }
        self.before.take(self.playback.game());
        if self.tick() >= target || self.playback.at_end() {
            self.target = None;
            self.due = 0.0;
        } else {
            // Drawn as reached so far.
            self.due = 1.0;
        }
        Ok(())
    }

    /// Seeks `seconds` forward (negative: back) from where it stands (or
    /// from where the seek under way goes).
    pub fn skip(&mut self, seconds: f64) -> Result<(), ReplayError> {
        let ticks = (seconds * f64::from(self.tick_rate())).round() as i64;
        let from = self.target.unwrap_or_else(|| self.tick());
        let target = (from as i64).saturating_add(ticks).max(0) as u64;
        self.seek(target)
    }

    /// Back to where the viewer opened ([`ReplayViewer::home`]).
    pub fn seek_home(&mut self) -> Result<(), ReplayError> {
        self.seek(self.home)
    }

    /// To the end (or just before a failure).
    pub fn seek_end(&mut self) -> Result<(), ReplayError> {
        self.seek(self.end_tick())
    }

    /// Whom the camera follows, as chosen.
    pub fn follow(&self) -> Follow {
        self.follow
    }

    /// Follows `follow` from now on.
    pub fn set_follow(&mut self, follow: Follow) {
        self.follow = follow;
    }

    /// The player followed now: the chosen one while in the game, else
    /// the first player in the game; `None` with a free camera or an empty
    /// game.
    pub fn followed(&self) -> Option<PlayerId> {
        self.follow.resolve(&self.players())
    }

    /// Follows the next player in the game by id (`forward`), or the one
    /// before, wrapping around; from a free camera the first (or last).
    pub fn follow_next(&mut self, forward: bool) {
        self.follow = self.follow.next(&self.players(), forward);
    }

    /// The players in the game now, ascending by id.
    pub fn players(&self) -> Vec<PlayerId> {
        self.game().players().map(|(id, _)| id).collect()
    }

    /// Player `id`'s name in the replay's header, else `player #ID`.
    pub fn name_of(&self, id: PlayerId) -> String {
        self.replay()
            .name_of(id)
            .map_or_else(|| format!("player #{}", id.0), str::to_owned)
    }

    /// The player the replay's header calls `name`, if any.
    pub fn player_named(&self, name: &str) -> Option<PlayerId> {
        let names = &self.replay().header.names;
        names.iter().find(|(_, n)| n == name).map(|(id, _)| *id)
    }

    /// What to draw now: the followed player as `local`.
    pub fn view(&self) -> FrameView {
        frame_view(
            self.game(),
            &self.before,
            self.alpha(),
            self.followed(),
            self.tick_rate(),
            |id| Some(self.name_of(id)),
        )
    }
}

#[cfg(test)]
mod tests;
