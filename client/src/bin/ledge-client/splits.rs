//! Split times against a ghost: when our player first reaches a
//! checkpoint the ghost has a split for, how far ahead (`-0.31`, faster)
//! or behind (`+0.42`, slower) of it our run is, shown for
//! [`SPLIT_SECONDS`]; at the goal, the difference of the finish times,
//! shown until the run starts again. Sans IO: fed our player each frame.

use ledge_client::ghost::Ghost;
use ledge_shared::game::PlayerView;

/// A checkpoint's split stays this long on screen, seconds.
pub const SPLIT_SECONDS: f64 = 3.0;

/// A split shown.
#[derive(Debug, Clone, PartialEq)]
pub struct Split {
    /// Our time minus the ghost's, ticks (negative: we are faster).
    pub delta: i64,
    /// The checkpoint's entity id (`None`: the finish).
    pub checkpoint: Option<u32>,
    /// Against the level's record (else our own best).
    pub record: bool,
    /// Who ran the ghost.
    pub against: String,
    /// When it was taken, seconds (the frame clock).
    pub at: f64,
}

impl Split {
    /// Whether our run was faster (`false`: slower or as fast).
    pub fn faster(&self) -> bool {
        self.delta < 0
    }

    /// `+0.42` / `-0.31` / `+0.00`, seconds at `rate` ticks a second.
    pub fn text(&self, rate: u32) -> String {
        split_text(self.delta, rate)
    }
}

/// `delta` ticks at `rate` a second as a signed time: `+0.42`, `-1:02.31`
/// past a minute.
pub fn split_text(delta: i64, rate: u32) -> String {
    let sign = if delta < 0 { '-' } else { '+' };
    let cs = delta.unsigned_abs() * 100 / u64::from(rate.max(1));
    if cs >= 6000 {
        format!("{sign}{}:{:02}.{:02}", cs / 6000, cs / 100 % 60, cs % 100)
    } else {
        format!("{sign}{}.{:02}", cs / 100, cs % 100)
    }
}

/// Our run's splits against a ghost (see the module documentation).
#[derive(Debug, Clone, Default)]
pub struct Splits {
    /// Checkpoints reached in this run.
    reached: Vec<u32>,
    /// The run's ticks last seen (fewer: it started again).
    last_ticks: u32,
    /// The finish was compared.
    finished: bool,
    /// The split shown last.
    last: Option<Split>,
}

impl Splits {
    /// Takes our player `me` as it is at `now` (seconds), against `ghost`
    /// (the record, else our best; `None`: no ghost, nothing compared).
    pub fn observe(&mut self, me: &PlayerView, ghost: Option<&Ghost>, now: f64) {
        if !me.run_started || me.run_ticks < self.last_ticks {
            // A new run (or none yet): nothing of the last one is shown.
            *self = Splits::default();
        }
        self.last_ticks = me.run_ticks;
        if !me.run_started {
            return;
        }
        let split = |delta: i64, checkpoint: Option<u32>, ghost: &Ghost| Split {
            delta,
            checkpoint,
            record: ghost.record,
            against: ghost.player.clone(),
            at: now,
        };
        if let Some(c) = me.checkpoint.filter(|c| !self.reached.contains(c)) {
            self.reached.push(c);
            if let Some((ghost, theirs)) = ghost.and_then(|g| Some((g, g.split(c)?))) {
                let delta = i64::from(me.run_ticks) - i64::from(theirs);
                self.last = Some(split(delta, Some(c), ghost));
            }
        }
        if me.won && !self.finished {
            self.finished = true;
            if let Some(ghost) = ghost {
                let delta = i64::from(me.run_ticks) - i64::from(ghost.ticks());
                self.last = Some(split(delta, None, ghost));
            }
        }
    }

    /// The split to show at `now`: a checkpoint's for [`SPLIT_SECONDS`],
    /// the finish's until the run starts again.
    pub fn shown(&self, now: f64) -> Option<&Split> {
        self.last
            .as_ref()
            .filter(|s| s.checkpoint.is_none() || now - s.at < SPLIT_SECONDS)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::IVec2;
    use ledge_shared::protocol::PlayerId;

    fn ghost() -> Ghost {
        Ghost {
            record: true,
            player: "bob".into(),
            millis: 2_000,
            track: vec![IVec2::ZERO; 121],
            half: IVec2::ONE,
            splits: vec![(7, 60), (9, 90)],
        }
    }

    fn me(run_ticks: u32, checkpoint: Option<u32>, won: bool) -> PlayerView {
        let mut game = ledge_shared::game::Game::from_level(&ledge_levels::default_level())
            .expect("the default level plays");
        game.add_player(PlayerId(1)).expect("a player joins");
        let mut me = game.player(PlayerId(1)).expect("in the game");
        me.run_started = true;
        me.run_ticks = run_ticks;
        me.checkpoint = checkpoint;
        me.won = won;
        me
    }

    #[test]
    fn split_times_read_as_seconds_ahead_or_behind() {
        assert_eq!(split_text(25, 60), "+0.41");
        assert_eq!(split_text(-19, 60), "-0.31");
        assert_eq!(split_text(0, 60), "+0.00");
        assert_eq!(split_text(3_725, 60), "+1:02.08");
    }

    #[test]
    fn a_checkpoint_shows_its_split_for_a_while_and_the_finish_stays() {
        let g = ghost();
        let mut splits = Splits::default();
        splits.observe(&me(10, None, false), Some(&g), 0.0);
        assert_eq!(splits.shown(0.0), None);
        // Checkpoint 7 at tick 85, the ghost at 60: 25 ticks slower.
        splits.observe(&me(85, Some(7), false), Some(&g), 1.0);
        let s = splits.shown(1.5).expect("shown");
        assert_eq!((s.delta, s.checkpoint, s.faster()), (25, Some(7), false));
        assert_eq!(s.text(60), "+0.41");
        // Not again for the same checkpoint; gone after a while.
        splits.observe(&me(86, Some(7), false), Some(&g), 2.0);
        assert_eq!(splits.shown(2.0).map(|s| s.at), Some(1.0));
        assert_eq!(splits.shown(1.0 + SPLIT_SECONDS), None);
        // A checkpoint the ghost never reached: nothing.
        splits.observe(&me(95, Some(8), false), Some(&g), 5.0);
        assert_eq!(splits.shown(5.0), None);
        // The finish at 100 against 120: faster, shown until a new run.
        splits.observe(&me(100, Some(8), true), Some(&g), 6.0);
        let s = splits.shown(60.0).expect("the finish stays");
        assert_eq!((s.delta, s.checkpoint, s.faster()), (-20, None, true));
        splits.observe(&me(100, Some(8), true), Some(&g), 7.0);
        assert_eq!(splits.shown(60.0).map(|s| s.at), Some(6.0));
        splits.observe(&me(3, None, false), Some(&g), 8.0);
        assert_eq!(splits.shown(8.0), None);
        // No ghost: nothing compared.
        let mut alone = Splits::default();
        alone.observe(&me(85, Some(7), true), None, 0.0);
        assert_eq!(alone.shown(0.0), None);
    }
}
