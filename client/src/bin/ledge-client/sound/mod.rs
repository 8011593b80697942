//! What the window plays: which sound effects a frame cues, from our
//! player's frame-to-frame changes ([`cues`], also the start of our visual
//! effects), and the effects themselves, synthesized and played through
//! ALSA loaded at run time ([`audio`]).
//!
//! Grouped so that the front end's layout says what it does; this module
//! only declares them.

pub mod audio;
pub mod cues;
