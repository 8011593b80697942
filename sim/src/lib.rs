//! Simulation tools for ledge: the speed/accuracy trade-off measurements
//! behind `ledge-sim tradeoff` and `docs/TRADEOFFS.md`.
//!
//! * [`settings`]: the knob settings measured (one knob at a time from the
//!   default, plus the presets);
//! * [`scenes`]: one deterministic, seeded scene per accuracy metric;
//! * [`cost`]: median nanoseconds per tick of the busy scenes;
//! * [`tradeoff`]: runs every scene for every setting;
//! * [`report`]: the table and the CSV; [`plot`]: the SVG plot.

pub mod cost;
pub mod plot;
pub mod report;
pub mod scenes;
pub mod settings;
pub mod tradeoff;
