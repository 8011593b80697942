//! `ledge-client`: the macroquad front end.
//!
//! * offline (no `--connect`/`--local`): the default level in a local game;
//! * `--connect HOST:PORT`: joins a server on a background network thread
//!   (macroquad owns the main thread) and predicts our player with the
//!   shared simulation. The server's certificate is pinned with
//!   `--cert-hash HEX`, or else trusted on first use and remembered in a
//!   known-hosts file (`--known-hosts PATH`, default
//!   `$XDG_CONFIG_HOME/ledge/known_hosts`); a changed certificate is refused
//!   with a message saying what to do, and exit code 3;
//! * `--local`: starts the real server in-process on `127.0.0.1:0` and
//!   joins it: one command, a playable game;
//! * `--replay FILE|URL`: plays a replay in the window ([`replay`]), or
//!   checks it without one (`--check`); in the browser `?replay=ID`.
//!
//! The simulation runs at a fixed 60 Hz (accumulator); frames are drawn
//! interpolated between the last two ticks. `--script`, `--screenshot` and
//! `--exit-after-ticks` drive it without a human, for tests.
//!
//! A session that fails (the server cannot be reached, refuses us, drops
//! us; its certificate is refused) is told once on stderr, prefixed
//! `ledge-client: `, and in the window, wrapped to its size, until the
//! player quits; the message says what to do next. Exit codes (also in
//! `--help`):
//!
//! * 0: the game ended normally (Esc, window closed, `--exit-after-ticks`);
//! * 1 ([`outcome::EXIT_FAILED`]): the session failed, or the game could not start
//!   (a level or keys file, the screenshot);
//! * 2 ([`outcome::EXIT_JOIN_TIMEOUT`]): not joined within `--join-timeout` (with
//!   `--exit-after-ticks`); also clap's code for command-line errors;
//! * 3 ([`outcome::EXIT_UNTRUSTED`]): the server's certificate was refused.
//!
//! Modules, top to bottom (each uses only those below it): the entry
//! points ([`native`] with [`local`], and `web` in the browser) prepare a
//! [`game_loop::Setup`]; the [`game_loop`] runs the frames (a replay's
//! entry and window are [`replay`]'s, beside it); [`play`] (the
//! game, offline or online) and [`shot`] (`--screenshot`) serve it, with
//! three groups that do one thing each for it: [`draw`] (the camera, the
//! world, the players' animation, effects, the HUD, the debug overlay),
//! [`sound`] (which effects a frame cues, and playing them) and [`input`]
//! (keys, gamepads, scripts, typing); at the bottom the page's glue (`page`, in the
//! browser), the gamepads' state ([`input::pad`]), the chat's state
//! ([`chat`]: the line typed, the lines received, who is muted) and how a
//! run ends ([`outcome`]), with the split times against a ghost ([`splits`])
//! and a spectator's camera ([`spectate`]). The presentation here (animation, sound, cues) is the
//! window's alone: the headless library leaves it out.

// The browser build leaves out the command line, files and the network
// thread, and with them some helpers the native build uses.
#![cfg_attr(target_arch = "wasm32", allow(dead_code))]

mod chat;
mod draw;
mod frame;
mod game_loop;
mod input;
#[cfg(not(target_arch = "wasm32"))]
mod local;
#[cfg(not(target_arch = "wasm32"))]
mod native;
mod outcome;
#[cfg(target_arch = "wasm32")]
mod page;
mod play;
mod replay;
mod shot;
mod sound;
mod spectate;
mod splits;
#[cfg(target_arch = "wasm32")]
mod web;

fn main() {
    #[cfg(not(target_arch = "wasm32"))]
    native::main();
    #[cfg(target_arch = "wasm32")]
    web::main();
}
