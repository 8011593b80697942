//! The browser entry (`wasm32-unknown-unknown`): the options come from the
//! page's address (`?name=ada`), the window is the page's canvas, and the
//! page's glue ([`crate::page`]) gives the clock, the address's parameters
//! and a place to report the game's state.
//!
//! The page joins the server that served it ([`WebNet`]: WebTransport,
//! or a WebSocket where the browser has no WebTransport), in the room the
//! address names (`?room=friends`); `?offline` plays the embedded level
//! without a server; `?spectate` watches (`&follow=NAME`) rather than
//! plays; `?replay=ID` plays the server's replay ID
//! ([`crate::replay::browser`]).
//!
//! On top, beside [`crate::native`]: it builds the game's [`Setup`] and
//! runs the game loop; nothing calls into it but `main`.

use std::time::Duration;

use ledge_client::JoinOptions;

use crate::game_loop::{game, Setup};
use crate::input::keys::Bindings;
use crate::outcome::tell;
use crate::page::{host, param, WebNet};
use crate::play;

/// The player name from `?name=`, when the server would accept it.
fn name() -> String {
    match param("name") {
        Some(name) if ledge_shared::protocol::check_name(&name).is_ok() => name,
        Some(name) => {
            tell(&format!(
                "the name {name:?} is not allowed (1 to 32 bytes, no control characters): \
                 playing as \"player\""
            ));
            "player".to_owned()
        }
        None => "player".to_owned(),
    }
}

/// Starts the game in the page's canvas.
pub fn main() {
    if let Some(id) = param("replay") {
        crate::replay::browser::main(id);
        return;
    }
    let name = name();
    let level = ledge_levels::default_level();
    let spectate = param("spectate").is_some();
    let made = if param("offline").is_some() {
        play::Play::offline(level, &name)
    } else {
        let options = JoinOptions {
            room: param("room").filter(|r| !r.is_empty()),
            spectate,
            ..JoinOptions::new(&name)
        };
        let mut play = play::Play::web(WebNet::open(options), &host(), level, &name);
        play.set_spectating(spectate);
        Ok(play)
    };
    let play = match made {
        Ok(play) => play,
        Err(e) => {
            tell(&format!("cannot start the game: {e:#}"));
            return;
        }
    };
    let setup = Setup {
        play,
        bindings: Bindings::default(),
        script: None,
        exit_after: None,
        screenshot: None,
        join_timeout: Duration::from_secs(20),
        name,
        debug: param("debug").is_some(),
        net: param("net").is_some(),
        collision: param("collision").is_some(),
        hud: param("nohud").is_none(),
        volume: 0.8,
        mute: false,
        look_at: None,
        spectate,
        follow: param("follow").filter(|f| !f.is_empty()),
        level_art: Default::default(),
    };
    let conf = macroquad::window::Conf {
        window_title: "ledge".to_owned(),
        window_width: 960,
        window_height: 540,
        window_resizable: true,
        ..Default::default()
    };
    macroquad::Window::from_config(conf, game(setup));
}
