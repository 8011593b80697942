//! The buttons a player holds during one tick: the only thing a client sends.

use serde::{Deserialize, Serialize};

/// Button bits held during one tick.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Buttons(pub u8);

impl Buttons {
    /// Move left.
    pub const LEFT: u8 = 1 << 0;
    /// Move right.
    pub const RIGHT: u8 = 1 << 1;
    /// Move up (top-down movers) or look up.
    pub const UP: u8 = 1 << 2;
    /// Move down, or drop through one-way platforms with jump.
    pub const DOWN: u8 = 1 << 3;
    /// Jump.
    pub const JUMP: u8 = 1 << 4;
    /// Restart the run: a press (held now, not last tick) puts the player
    /// back at its spawn with a fresh run (see `Game`'s "Runs" docs in
    /// `game/mod.rs`). Holding it does nothing more.
    pub const RESTART: u8 = 1 << 5;

    /// The buttons that play: the first tick holding any of them starts a
    /// player's run timer. [`Buttons::RESTART`] and the unused bits 6 and 7
    /// are not among them.
    pub const PLAY: u8 = Self::LEFT | Self::RIGHT | Self::UP | Self::DOWN | Self::JUMP;

    /// No button held.
    pub const NONE: Buttons = Buttons(0);

    /// Whether every bit of `mask` is held.
    #[inline]
    pub fn held(self, mask: u8) -> bool {
        self.0 & mask == mask
    }

    /// Whether any of the buttons that play ([`Buttons::PLAY`]) is held.
    #[inline]
    pub fn plays(self) -> bool {
        self.0 & Self::PLAY != 0
    }

    /// Horizontal direction held: -1, 0 or 1 (both cancel out).
    #[inline]
    pub fn dir_x(self) -> i32 {
        self.held(Self::RIGHT) as i32 - self.held(Self::LEFT) as i32
    }

    /// Vertical direction held: -1 (up), 0 or 1 (down).
    #[inline]
    pub fn dir_y(self) -> i32 {
        self.held(Self::DOWN) as i32 - self.held(Self::UP) as i32
    }
}
