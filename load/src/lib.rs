//! `ledge-load`: the server load benchmark (issue 7) as a library, so that
//! its parts are tested; the `ledge-load` binary is the command.
//!
//! It runs the release `ledge-server` and `ledge-bot` binaries as child
//! processes on loopback, reads the server's Prometheus metrics (the fine
//! tick histogram, byte and missed-tick counters) at both ends of a
//! measured window, and `/proc` for CPU and peak memory. It builds nothing.
//! The bots are `ledge-bot`'s, predicting with a brain or thin
//! (`--brain thin`: inputs and snapshots, no prediction), which cost far
//! less.
//!
//! [`fleet`] is `ledge-load fleet`: a local Agones fleet of servers with
//! fake SDK sidecars, rooms allocated across them by Agones' rule, and
//! checks that no room's players end up anywhere else.

#![deny(missing_docs)]

pub mod children;
pub mod fleet;
pub mod procstat;
pub mod prom;
pub mod quantile;
pub mod report;
pub mod run;
