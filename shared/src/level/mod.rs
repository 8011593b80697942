//! Levels: the data model every loader produces and the game is built from,
//! the loaders (OGMO Editor 3, Tiled) and the embedded default level.
//!
//! A [`Level`] is plain data: a tilemap plus a list of entity definitions in
//! world units. Loaders translate editor files into it through a documented
//! name table; [`crate::game::Game::from_level`] turns it into a running
//! simulation.

mod model;

pub use model::{EntityDef, EntityKind, Level, PlatformMotion};
