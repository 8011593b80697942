//! Keyboard to buttons: arrow keys or WASD to move, space to jump.

use ledge_shared::input::Buttons;
use macroquad::input::{is_key_down, KeyCode};

/// Each button with the keys that hold it.
const BINDINGS: [(u8, &[KeyCode]); 5] = [
    (Buttons::LEFT, &[KeyCode::Left, KeyCode::A]),
    (Buttons::RIGHT, &[KeyCode::Right, KeyCode::D]),
    (Buttons::UP, &[KeyCode::Up, KeyCode::W]),
    (Buttons::DOWN, &[KeyCode::Down, KeyCode::S]),
    (Buttons::JUMP, &[KeyCode::Space]),
];

/// The buttons held right now.
pub fn held_buttons() -> Buttons {
    let mut bits = 0;
    for (bit, keys) in BINDINGS {
        if keys.iter().any(|&key| is_key_down(key)) {
            bits |= bit;
        }
    }
    Buttons(bits)
}
