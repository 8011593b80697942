//! Keys typed into the chat line ([`crate::chat`]): the characters typed
//! this frame, then Backspace, Enter (or the keypad's) and Escape.

use macroquad::input::{get_char_pressed, is_key_pressed, KeyCode};

use crate::chat::Key;

/// The chat keys of this frame, in that order. Control characters among
/// the characters typed are the keys' own (Backspace, Enter), read as keys.
pub fn keys() -> Vec<Key> {
    let mut keys: Vec<Key> = std::iter::from_fn(get_char_pressed)
        .filter(|c| !c.is_control())
        .map(Key::Char)
        .collect();
    if is_key_pressed(KeyCode::Backspace) {
        keys.push(Key::Backspace);
    }
    if is_key_pressed(KeyCode::Enter) || is_key_pressed(KeyCode::KpEnter) {
        keys.push(Key::Enter);
    }
    if is_key_pressed(KeyCode::Escape) {
        keys.push(Key::Escape);
    }
    keys
}

/// Forgets the characters typed so far (while the chat line is closed,
/// they are the game's: the key opening the line is not typed into it).
pub fn forget() {
    while get_char_pressed().is_some() {}
}
