//! What presses the game's buttons, and a watching camera's keys
//! ([`follow`]): the keyboard and gamepads through
//! rebindable bindings ([`keys`]), one gamepad's state whatever reports it
//! ([`pad`]), scripted input for tests and demos ([`script`]), and the
//! keys typed into the chat line ([`typing`]).
//!
//! Grouped so that the front end's layout says what it does; this module
//! only declares them.

pub mod follow;
pub mod keys;
pub mod pad;
pub mod script;
pub mod typing;
