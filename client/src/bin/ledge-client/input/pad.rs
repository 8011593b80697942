//! One gamepad's state, whatever reports it (gilrs natively, the page's
//! Gamepad API in a browser), and the buttons it presses: the keys read
//! it, the page's glue fills it, so it sits below both.

use ledge_shared::input::Buttons;

/// One gamepad's controls that ledge reads, whatever reports them (gilrs
/// natively, the browser's Gamepad API in a page).
#[cfg_attr(
    not(any(feature = "gamepad", target_arch = "wasm32")),
    allow(dead_code, reason = "read only by builds with gamepads")
)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PadState {
    /// D-pad directions held.
    pub left: bool,
    pub right: bool,
    pub up: bool,
    pub down: bool,
    /// The south (A/cross) and east (B/circle) face buttons.
    pub south: bool,
    pub east: bool,
    /// Select (back/share).
    pub select: bool,
    /// The left stick, -1..=1, x to the right and y up.
    pub stick: (f32, f32),
}

#[cfg_attr(
    not(any(feature = "gamepad", target_arch = "wasm32")),
    allow(dead_code, reason = "read only by builds with gamepads")
)]
impl PadState {
    /// D-pad or left stick to move, south or east to jump (down + jump
    /// drops through), select to restart.
    pub fn buttons(&self) -> Buttons {
        let (x, y) = self.stick;
        let mut bits = 0;
        if self.left || x < -0.5 {
            bits |= Buttons::LEFT;
        }
        if self.right || x > 0.5 {
            bits |= Buttons::RIGHT;
        }
        if self.up || y > 0.5 {
            bits |= Buttons::UP;
        }
        if self.down || y < -0.5 {
            bits |= Buttons::DOWN;
        }
        if self.south || self.east {
            bits |= Buttons::JUMP;
        }
        if self.select {
            bits |= Buttons::RESTART;
        }
        Buttons(bits)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gamepad_moves_jumps_and_restarts_like_the_keys() {
        let none = PadState::default();
        assert_eq!(none.buttons(), Buttons::NONE);
        let dpad = PadState {
            right: true,
            south: true,
            ..none
        };
        assert_eq!(dpad.buttons(), Buttons(Buttons::RIGHT | Buttons::JUMP));
        // The stick past half way counts; a resting stick's drift does not.
        let stick = PadState {
            stick: (-0.9, -0.8),
            east: true,
            ..none
        };
        assert_eq!(
            stick.buttons(),
            Buttons(Buttons::LEFT | Buttons::DOWN | Buttons::JUMP)
        );
        let drift = PadState {
            stick: (0.2, -0.3),
            ..none
        };
        assert_eq!(drift.buttons(), Buttons::NONE);
        let restart = PadState {
            select: true,
            ..none
        };
        assert_eq!(restart.buttons(), Buttons(Buttons::RESTART));
    }
}
