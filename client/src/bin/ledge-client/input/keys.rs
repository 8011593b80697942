//! Keyboard (and, with the `gamepad` feature, gamepad) to buttons, with
//! bindings rebindable in a TOML file (`--keys FILE`).
//!
//! The file lists, for each action, the keys that trigger it, by macroquad
//! key name (case-insensitive: `Left`, `A`, `Space`, `F1`, `Key1` or `1`,
//! `LeftShift`, `Kp0`, ...). Actions missing from the file keep their
//! defaults; unknown actions and key names are errors. The defaults are
//! [`DEFAULT_KEYS`] (also printed by `ledge-client --print-keys`).

use ledge_shared::input::Buttons;
use macroquad::input::{is_key_down, is_key_pressed, KeyCode};
use serde::Deserialize;

/// The default bindings, as a key file.
pub const DEFAULT_KEYS: &str = r#"# ledge key bindings: action = [keys] (macroquad key names, any case).
left = ["Left", "A"]
right = ["Right", "D"]
up = ["Up", "W"]
# Down + jump drops through one-way ledges.
down = ["Down", "S"]
jump = ["Space", "Z", "K"]
# Restart the run: back to the spawn, timer, deaths and coins cleared.
restart = ["R"]
# Sound on/off.
mute = ["M"]
# Debug overlay: colliders, contacts and their MTVs, touched sides.
debug = ["F1"]
# The whole HUD on/off.
hud = ["F2"]
# Network panel and graph on/off.
net = ["F3"]
# Ghosts (the level's record, your best) on/off.
ghosts = ["G"]
# Collision overlay (what collides, entity boxes, spawns) on/off.
collision = ["C"]
# Opens the chat line (then Enter sends it, Escape closes it).
chat = ["T", "Enter"]
# The server's level list opens/closes (then 1-9 vote for a level).
levels = ["V"]
quit = ["Escape"]
"#;

/// The key file's shape.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct KeyFile {
    left: Option<Vec<String>>,
    right: Option<Vec<String>>,
    up: Option<Vec<String>>,
    down: Option<Vec<String>>,
    jump: Option<Vec<String>>,
    restart: Option<Vec<String>>,
    mute: Option<Vec<String>>,
    debug: Option<Vec<String>>,
    hud: Option<Vec<String>>,
    net: Option<Vec<String>>,
    ghosts: Option<Vec<String>>,
    collision: Option<Vec<String>>,
    chat: Option<Vec<String>>,
    levels: Option<Vec<String>>,
    quit: Option<Vec<String>>,
}

/// Keys for every action.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bindings {
    /// Keys holding each button, in [`Buttons`] bit order (restart last).
    buttons: [(u8, Vec<KeyCode>); 6],
    /// Toggles sound.
    pub mute: Vec<KeyCode>,
    /// Toggles the debug overlay.
    pub debug: Vec<KeyCode>,
    /// Toggles the whole HUD.
    pub hud: Vec<KeyCode>,
    /// Toggles the network panel and graph.
    pub net: Vec<KeyCode>,
    /// Toggles the ghosts.
    pub ghosts: Vec<KeyCode>,
    /// Toggles the collision overlay.
    pub collision: Vec<KeyCode>,
    /// Opens the chat line.
    pub chat: Vec<KeyCode>,
    /// Opens and closes the server's level list (votes).
    pub levels: Vec<KeyCode>,
    /// Quits.
    pub quit: Vec<KeyCode>,
}

impl Default for Bindings {
    fn default() -> Bindings {
        let empty = Bindings {
            buttons: [
                (Buttons::LEFT, Vec::new()),
                (Buttons::RIGHT, Vec::new()),
                (Buttons::UP, Vec::new()),
                (Buttons::DOWN, Vec::new()),
                (Buttons::JUMP, Vec::new()),
                (Buttons::RESTART, Vec::new()),
            ],
            mute: Vec::new(),
            debug: Vec::new(),
            hud: Vec::new(),
            net: Vec::new(),
            ghosts: Vec::new(),
            collision: Vec::new(),
            chat: Vec::new(),
            levels: Vec::new(),
            quit: Vec::new(),
        };
        empty
            .with(DEFAULT_KEYS)
            .expect("the default key file is valid")
    }
}

impl Bindings {
    /// The defaults overridden by the key file at `path`.
    pub fn load(path: &std::path::Path) -> Result<Bindings, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("reading key file {}: {e}", path.display()))?;
        Bindings::default()
            .with(&text)
            .map_err(|e| format!("key file {}: {e}", path.display()))
    }

    /// These bindings overridden by the actions in key file `text`.
    pub fn with(mut self, text: &str) -> Result<Bindings, String> {
        let file: KeyFile = toml::from_str(text).map_err(|e| e.to_string())?;
        let keys = |names: Option<Vec<String>>, into: &mut Vec<KeyCode>| -> Result<(), String> {
            if let Some(names) = names {
                *into = names
                    .iter()
                    .map(|n| key_by_name(n).ok_or_else(|| format!("unknown key name {n:?}")))
                    .collect::<Result<_, _>>()?;
            }
            Ok(())
        };
        let [l, r, u, d, j, restart] = &mut self.buttons;
        keys(file.left, &mut l.1)?;
        keys(file.right, &mut r.1)?;
        keys(file.up, &mut u.1)?;
        keys(file.down, &mut d.1)?;
        keys(file.jump, &mut j.1)?;
        keys(file.restart, &mut restart.1)?;
        keys(file.mute, &mut self.mute)?;
        keys(file.debug, &mut self.debug)?;
        keys(file.hud, &mut self.hud)?;
        keys(file.net, &mut self.net)?;
        keys(file.ghosts, &mut self.ghosts)?;
        keys(file.collision, &mut self.collision)?;
        keys(file.chat, &mut self.chat)?;
        keys(file.levels, &mut self.levels)?;
        keys(file.quit, &mut self.quit)?;
        Ok(self)
    }

    /// The buttons held on the keyboard right now ([`Buttons::RESTART`]
    /// too: the simulation restarts on the tick it is first held).
    pub fn held(&self) -> Buttons {
        let mut bits = 0;
        for (bit, keys) in &self.buttons {
            if keys.iter().any(|&key| is_key_down(key)) {
                bits |= bit;
            }
        }
        Buttons(bits)
    }

    /// The keys that restart the run.
    pub fn restart_keys(&self) -> &[KeyCode] {
        &self.buttons[5].1
    }

    /// The level number key (1 to 9, on the row above the letters or
    /// the keypad) pressed this frame, if any: a vote while the level list
    /// is open. No default binding uses them.
    pub fn number_pressed() -> Option<u32> {
        use KeyCode::*;
        const ROW: [KeyCode; 9] = [Key1, Key2, Key3, Key4, Key5, Key6, Key7, Key8, Key9];
        const PAD: [KeyCode; 9] = [Kp1, Kp2, Kp3, Kp4, Kp5, Kp6, Kp7, Kp8, Kp9];
        (0..9u32)
            .find(|&i| is_key_pressed(ROW[i as usize]) || is_key_pressed(PAD[i as usize]))
            .map(|i| i + 1)
    }

    /// Whether one of `keys` was pressed this frame.
    pub fn pressed(keys: &[KeyCode]) -> bool {
        keys.iter().any(|&k| is_key_pressed(k))
    }
}

/// Every key a binding can name.
const ALL_KEYS: &[KeyCode] = {
    use KeyCode::*;
    &[
        Space,
        Apostrophe,
        Comma,
        Minus,
        Period,
        Slash,
        Key0,
        Key1,
        Key2,
        Key3,
        Key4,
        Key5,
        Key6,
        Key7,
        Key8,
        Key9,
        Semicolon,
        Equal,
        A,
        B,
        C,
        D,
        E,
        F,
        G,
        H,
        I,
        J,
        K,
        L,
        M,
        N,
        O,
        P,
        Q,
        R,
        S,
        T,
        U,
        V,
        W,
        X,
        Y,
        Z,
        LeftBracket,
        Backslash,
        RightBracket,
        GraveAccent,
        Escape,
        Enter,
        Tab,
        Backspace,
        Insert,
        Delete,
        Right,
        Left,
        Down,
        Up,
        PageUp,
        PageDown,
        Home,
        End,
        CapsLock,
        ScrollLock,
        NumLock,
        PrintScreen,
        Pause,
        F1,
        F2,
        F3,
        F4,
        F5,
        F6,
        F7,
        F8,
        F9,
        F10,
        F11,
        F12,
        Kp0,
        Kp1,
        Kp2,
        Kp3,
        Kp4,
        Kp5,
        Kp6,
        Kp7,
        Kp8,
        Kp9,
        KpDecimal,
        KpDivide,
        KpMultiply,
        KpSubtract,
        KpAdd,
        KpEnter,
        KpEqual,
        LeftShift,
        LeftControl,
        LeftAlt,
        LeftSuper,
        RightShift,
        RightControl,
        RightAlt,
        RightSuper,
        Menu,
    ]
};

/// The key called `name` (its macroquad name, any case; digits also bare).
pub fn key_by_name(name: &str) -> Option<KeyCode> {
    let name = name.trim();
    let wanted = if name.len() == 1 && name.as_bytes()[0].is_ascii_digit() {
        format!("key{name}")
    } else {
        name.to_ascii_lowercase()
    };
    ALL_KEYS
        .iter()
        .copied()
        .find(|k| format!("{k:?}").to_ascii_lowercase() == wanted)
}

/// Gamepads through gilrs (see [`crate::input::pad::PadState::buttons`]).
#[cfg(all(feature = "gamepad", not(target_arch = "wasm32")))]
pub struct Gamepads {
    gilrs: Option<gilrs::Gilrs>,
}

#[cfg(all(feature = "gamepad", not(target_arch = "wasm32")))]
impl Gamepads {
    /// Opens the gamepad subsystem (none if it cannot start: keyboard only).
    pub fn new() -> Gamepads {
        let gilrs = match gilrs::Gilrs::new() {
            Ok(g) => Some(g),
            Err(e) => {
                tracing::warn!("no gamepads: {e}");
                None
            }
        };
        Gamepads { gilrs }
    }

    /// The buttons held on any connected gamepad.
    pub fn held(&mut self) -> Buttons {
        use gilrs::{Axis, Button};
        let Some(gilrs) = &mut self.gilrs else {
            return Buttons::NONE;
        };
        while gilrs.next_event().is_some() {}
        let mut bits = 0;
        for (_, pad) in gilrs.gamepads() {
            let state = crate::input::pad::PadState {
                left: pad.is_pressed(Button::DPadLeft),
                right: pad.is_pressed(Button::DPadRight),
                up: pad.is_pressed(Button::DPadUp),
                down: pad.is_pressed(Button::DPadDown),
                south: pad.is_pressed(Button::South),
                east: pad.is_pressed(Button::East),
                select: pad.is_pressed(Button::Select),
                stick: (pad.value(Axis::LeftStickX), pad.value(Axis::LeftStickY)),
            };
            bits |= state.buttons().0;
        }
        Buttons(bits)
    }
}

/// Gamepads in a browser: the page's Gamepad API, read each frame (see
/// [`crate::input::pad::PadState::buttons`]).
#[cfg(target_arch = "wasm32")]
pub struct Gamepads;

#[cfg(target_arch = "wasm32")]
impl Gamepads {
    /// The page's gamepads (none until one is touched: browsers hide
    /// them until then).
    pub fn new() -> Gamepads {
        Gamepads
    }

    /// The buttons held on any connected gamepad.
    pub fn held(&mut self) -> Buttons {
        let bits = crate::page::gamepads()
            .iter()
            .fold(0, |bits, pad| bits | pad.buttons().0);
        Buttons(bits)
    }
}

/// Without the `gamepad` feature: no gamepads.
#[cfg(not(any(feature = "gamepad", target_arch = "wasm32")))]
pub struct Gamepads;

#[cfg(not(any(feature = "gamepad", target_arch = "wasm32")))]
impl Gamepads {
    /// No gamepad support in this build.
    pub fn new() -> Gamepads {
        Gamepads
    }

    /// Nothing held.
    pub fn held(&mut self) -> Buttons {
        Buttons::NONE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_arrows_wasd_space_z() {
        let b = Bindings::default();
        assert_eq!(b.buttons[0].1, [KeyCode::Left, KeyCode::A]);
        assert_eq!(b.buttons[4].1, [KeyCode::Space, KeyCode::Z, KeyCode::K]);
        assert_eq!(b.debug, [KeyCode::F1]);
        assert_eq!(b.hud, [KeyCode::F2]);
        assert_eq!(b.net, [KeyCode::F3]);
        assert_eq!(b.mute, [KeyCode::M]);
        assert_eq!(b.ghosts, [KeyCode::G]);
        assert_eq!(b.collision, [KeyCode::C]);
        assert_eq!(b.chat, [KeyCode::T, KeyCode::Enter]);
        assert_eq!(b.levels, [KeyCode::V]);
        assert_eq!(b.buttons[5], (Buttons::RESTART, vec![KeyCode::R]));
        assert_eq!(b.quit, [KeyCode::Escape]);
    }

    /// Every button bit is bound once, in bit order, and no key does two
    /// things by default.
    #[test]
    fn defaults_bind_every_button_and_no_key_twice() {
        let b = Bindings::default();
        let bits: Vec<u8> = b.buttons.iter().map(|(bit, _)| *bit).collect();
        assert_eq!(
            bits,
            [
                Buttons::LEFT,
                Buttons::RIGHT,
                Buttons::UP,
                Buttons::DOWN,
                Buttons::JUMP,
                Buttons::RESTART
            ]
        );
        let mut all: Vec<KeyCode> = b.buttons.iter().flat_map(|(_, k)| k.clone()).collect();
        for keys in [
            &b.mute,
            &b.debug,
            &b.hud,
            &b.net,
            &b.ghosts,
            &b.collision,
            &b.chat,
            &b.levels,
            &b.quit,
        ] {
            all.extend(keys.iter().copied());
        }
        let n = all.len();
        all.sort_by_key(|k| format!("{k:?}"));
        all.dedup();
        assert_eq!(all.len(), n, "a key bound twice: {all:?}");
    }

    #[test]
    fn a_file_rebinds_restart_mute_and_net() {
        let b = Bindings::default()
            .with("restart = [\"Backspace\"]\nmute = [\"F9\"]\nnet = [\"Tab\"]")
            .unwrap();
        assert_eq!(b.buttons[5].1, [KeyCode::Backspace]);
        assert_eq!(b.mute, [KeyCode::F9]);
        assert_eq!(b.net, [KeyCode::Tab]);
        assert_eq!(b.hud, [KeyCode::F2], "kept");
    }

    #[test]
    fn a_file_overrides_some_actions() {
        let b = Bindings::default()
            .with("jump = [\"x\", \"LEFTSHIFT\"]\nleft = [\"j\", \"kp4\"]")
            .unwrap();
        assert_eq!(b.buttons[4].1, [KeyCode::X, KeyCode::LeftShift]);
        assert_eq!(b.buttons[0].1, [KeyCode::J, KeyCode::Kp4]);
        assert_eq!(b.buttons[1].1, [KeyCode::Right, KeyCode::D], "kept");
    }

    #[test]
    fn bad_files_are_refused() {
        let e = Bindings::default()
            .with("jump = [\"Spacebar\"]")
            .unwrap_err();
        assert!(e.contains("Spacebar"), "{e}");
        assert!(Bindings::default().with("fly = [\"F\"]").is_err());
        assert_eq!(key_by_name("1"), Some(KeyCode::Key1));
        assert_eq!(key_by_name("f12"), Some(KeyCode::F12));
    }
}
