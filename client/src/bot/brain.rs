//! Bot brains: what a bot presses each tick, given the predicted game.
//!
//! A [`Brain`] is asked once per local tick, before that tick is
//! predicted, with the predicted [`Game`] as it stands (exactly the
//! server's state when the prediction is right) and our player id.

use ledge_shared::game::Game;
use ledge_shared::input::Buttons;
use ledge_shared::level::Level;
use ledge_shared::protocol::PlayerId;

/// Decides a bot's buttons, tick by tick.
pub trait Brain: Send {
    /// A short name for reports (`idle`, `walker`, `runner`).
    fn name(&self) -> &'static str;

    /// The buttons to hold during the next tick (`game.tick()`), given the
    /// predicted game. Called once per tick, in order.
    fn buttons(&mut self, game: &Game, me: PlayerId) -> Buttons;

    /// Whether the brain has nothing more to do (a runner at the goal).
    fn done(&self) -> bool {
        false
    }

    /// A snapshot corrected the prediction: plans made on the old one are
    /// stale.
    fn on_correction(&mut self) {}

    /// The room moved to another level, `level` (our player respawned at
    /// its spawn, the run afresh): whatever was planned on the old one is
    /// void.
    fn on_level(&mut self, _level: &Level) {}

    /// A one-line progress note for reports (a runner's waypoint).
    fn progress(&self) -> String {
        String::new()
    }
}

/// A varied script that repeats every 4 s (240 ticks) and stays around
/// the spawn of the default level (its crate, its elevator): runs, jumps,
/// turns and stands. The buttons for `tick`; played from other offsets
/// by several players, it exercises prediction on every kind of move
/// (`tests/e2e/prediction.rs`, the predictor's tests).
pub fn drill(tick: u64) -> Buttons {
    Buttons(match tick % 240 {
        0..=49 => Buttons::RIGHT,
        50..=70 => Buttons::RIGHT | Buttons::JUMP,
        71..=100 => Buttons::RIGHT,
        101..=110 => 0,
        111..=160 => Buttons::LEFT,
        161..=175 => Buttons::LEFT | Buttons::JUMP,
        176..=200 => Buttons::LEFT,
        201..=205 => Buttons::JUMP,
        _ => 0,
    })
}

/// Holds no button, ever.
#[derive(Debug, Clone, Copy, Default)]
pub struct Idle;

impl Brain for Idle {
    fn name(&self) -> &'static str {
        "idle"
    }

    fn buttons(&mut self, _game: &Game, _me: PlayerId) -> Buttons {
        Buttons::NONE
    }
}

/// Random buttons, changed at random intervals, from a seed (the same seed
/// presses the same buttons on the same ticks).
#[derive(Debug, Clone)]
pub struct RandomWalker {
    rng: SplitMix64,
    current: Buttons,
    hold: u32,
}

impl RandomWalker {
    /// A walker seeded with `seed`.
    pub fn new(seed: u64) -> RandomWalker {
        RandomWalker {
            rng: SplitMix64(seed),
            current: Buttons::NONE,
            hold: 0,
        }
    }

    /// The buttons of the next tick: a direction (or none), maybe jump,
    /// rarely down, held together for 5 to 44 ticks. Needs no game, so thin
    /// bots (no prediction) walk the same way.
    pub fn next_buttons(&mut self) -> Buttons {
        if self.hold == 0 {
            let r = self.rng.next_u64();
            let dir = match r % 3 {
                0 => Buttons::LEFT,
                1 => Buttons::RIGHT,
                _ => 0,
            };
            let jump = if (r >> 8) % 4 == 0 { Buttons::JUMP } else { 0 };
            let down = if (r >> 16) % 16 == 0 {
                Buttons::DOWN
            } else {
                0
            };
            self.current = Buttons(dir | jump | down);
            self.hold = 5 + ((r >> 24) % 40) as u32;
        }
        self.hold -= 1;
        self.current
    }
}

impl Brain for RandomWalker {
    fn name(&self) -> &'static str {
        "walker"
    }

    fn buttons(&mut self, _game: &Game, _me: PlayerId) -> Buttons {
        self.next_buttons()
    }
}

pub use crate::rng::SplitMix64;
