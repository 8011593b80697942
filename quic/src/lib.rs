//! `ledge-quic`: QUIC transport settings that the server and the client
//! must agree on, kept in one place.
//!
//! Today that is one thing: [`GameWindow`], the congestion controller both
//! ends install (see [`install`]).

mod window;

pub use window::{install, GameWindow, GameWindowFactory, WINDOW_FLOOR};
