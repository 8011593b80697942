//! `ledge-shared`: ledge's deterministic fixed-step simulation.
//!
//! Pure and I/O-free ("sans-IO", like `quinn-proto`): a function of
//! `(state, inputs) -> state`. Sockets, threads and clocks live in
//! `ledge-server` and `ledge-client`.
//!
//! * [`fixed`]: the numeric model (integer subpixel units and their bounds);
//! * [`shape`]: point, segment, circle, box, oriented box, convex polygon;
//! * [`query`]: contacts with minimum translation vectors, ray casts;
//! * [`world`]: bodies, colliders, the tick pipeline (move, detect,
//!   restitute) and its events;
//! * [`input`]: the buttons a player sends each tick;
//! * [`scene`]: built-in scenes (the warm-up room).
#![deny(missing_docs)]

pub mod fixed;
pub mod input;
pub mod query;
pub mod scene;
pub mod shape;
pub mod world;
