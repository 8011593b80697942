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

    /// No button held.
    pub const NONE: Buttons = Buttons(0);

    /// Whether every bit of `mask` is held.
    #[inline]
    pub fn held(self, mask: u8) -> bool {
        self.0 & mask == mask
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
