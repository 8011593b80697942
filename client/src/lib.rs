//! `ledge-client`: connecting to a ledge server, headless.
//!
//! Everything here runs without a window, so bots and tests use it
//! directly; the macroquad front end (the `ledge-client` binary, feature
//! `gui`) is a thin layer on top. The wire protocol is
//! [`ledge_shared::protocol`].
//!
//! * [`verifier`]: trust the server certificate by pinned fingerprint only;
//! * [`transport`]: resolve and dial a server over QUIC;
//! * [`session`]: the handshake, inputs out, snapshots and control messages
//!   in ([`Session`], [`SessionEvent`]);
//! * [`clock`]: which tick to send inputs for ([`InputClock`]);
//! * [`background`]: the network on its own thread, for GUI front ends;
//! * [`timestep`]: fixed-step accumulator for render loops;
//! * [`error`]: what can fail ([`ClientError`]).
#![deny(missing_docs)]

pub mod background;
pub mod clock;
pub mod error;
pub mod session;
pub mod timestep;
pub mod transport;
pub mod verifier;

pub use clock::InputClock;
pub use error::ClientError;
pub use ledge_shared::protocol::Fingerprint;
pub use session::{
    connect, connect_with, handshake, JoinOptions, Session, SessionEvent, SessionStats,
    SnapshotUpdate,
};
