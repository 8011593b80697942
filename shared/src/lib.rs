//! `ledge-shared`: ledge's deterministic fixed-step simulation.
//!
//! Pure and I/O-free ("sans-IO", like `quinn-proto`): a function of
//! `(state, inputs) -> state`. Sockets, threads and clocks live in
//! `ledge-server` and `ledge-client`.
//!
//! * [`fixed`]: the numeric model (integer subpixel units and their bounds);
//! * [`shape`]: point, segment, circle, box, oriented box, convex polygon;
//! * [`query`]: contacts with minimum translation vectors, ray casts;
//! * [`broad`]: the broad phase (spatial partition, parallel pair search);
//! * [`world`]: bodies, colliders, the tick pipeline (move, detect,
//!   restitute) and its events;
//! * [`input`]: the buttons a player sends each tick;
//! * [`tilemap`]: tile grids with slopes and one-way tiles, by direct lookup;
//! * [`protocol`]: versioned wire messages and delta-compressed snapshots;
//! * [`level`]: the level data model (tilemap, entities, bot route) and
//!   what a level uses; the editor importers (OGMO, Tiled) and the default
//!   level are in the `ledge-levels` crate, not here;
//! * [`game`]: the platformer rules over the world (what the server runs);
//! * [`replay`]: matches and runs as inputs, played again exactly;
//! * [`scene`]: built-in scenes (the warm-up room).
#![deny(missing_docs)]

pub mod broad;
pub mod fixed;
pub mod game;
pub mod input;
pub mod level;
pub mod protocol;
pub mod query;
pub mod replay;
pub mod scene;
pub mod shape;
pub mod tilemap;
pub mod world;
