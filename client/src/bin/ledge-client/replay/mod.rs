//! Replays played with the game's own renderer: natively
//! `ledge-client --replay FILE|URL` (or checked without a window,
//! `--check`: [`cli`]), in the browser the page's `?replay=ID`
//! (`browser`). Both open the replay where the viewer asks ([`open`]) and
//! show it in the same window ([`window`]: the viewer's keys, the HUD,
//! following a player); every failure says what went wrong and what to do
//! ([`advice`]).
//!
//! Natively only: where it comes from ([`source`]: a file, or
//! `http://HOST:PORT/replays/ID` over [`http`]), its level found
//! ([`level`]: the embedded one, the cache, `--level`, the server), and
//! [`check`]. In the browser the page's glue fetches both from the server
//! that served the page.

mod advice;
#[cfg(target_arch = "wasm32")]
pub mod browser;
#[cfg(not(target_arch = "wasm32"))]
mod check;
#[cfg(not(target_arch = "wasm32"))]
mod cli;
#[cfg(not(target_arch = "wasm32"))]
mod http;
#[cfg(not(target_arch = "wasm32"))]
mod level;
mod open;
#[cfg(not(target_arch = "wasm32"))]
mod source;
mod window;

#[cfg(not(target_arch = "wasm32"))]
pub use cli::{run, ReplayArgs};
