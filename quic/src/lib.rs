//! `ledge-quic`: QUIC transport settings that the server and the client
//! must agree on, kept in one place.
//!
//! [`GameWindow`], the congestion controller both ends install (see
//! [`install`]), and smaller packets ([`packets`]): short connection ids.

pub mod packets;
mod window;

pub use window::{install, GameWindow, GameWindowFactory, WINDOW_FLOOR};
