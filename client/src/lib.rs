//! `ledge-client`: connecting to a ledge server, headless.
//!
//! Everything here runs without a window, so bots and tests use it
//! directly; the macroquad front end (the `ledge-client` binary, feature
//! `gui`) is a thin layer on top.
//!
//! * [`verifier`]: trust the server certificate by pinned fingerprint only;
//! * [`transport`]: resolve and dial a server over QUIC;
//! * [`session`]: the hello/welcome handshake and control requests;
//! * [`background`]: the network on its own thread, for GUI front ends;
//! * [`timestep`]: fixed-step accumulator for render loops;
//! * [`error`]: what can fail ([`ClientError`]).
#![deny(missing_docs)]

pub mod background;
pub mod error;
pub mod session;
pub mod timestep;
pub mod transport;
pub mod verifier;

pub use error::ClientError;
pub use ledge_server::Fingerprint;
pub use session::{connect, handshake, Session};
