//! A replay as a front end shows it, sans IO: [`ReplayViewer`] plays a
//! [`ledge_shared::replay::Replay`] against the clock at a chosen speed,
//! paused, seeking, following one player or none; [`view`] turns its game
//! into the same [`crate::view::FrameView`] a live game gives, so a front
//! end draws a replay with the code it plays with.
//!
//! * [`viewer`]: the playback under the viewer's controls;
//! * [`view`]: what a frame of it shows (players and entities blended
//!   between two ticks, the followed player as `local`).
//!
//! Reading the file, fetching it and its level, and the window are the
//! front end's (`ledge-client --replay`).

pub mod view;
pub mod viewer;

pub use viewer::{Follow, ReplayViewer, SPEEDS};
