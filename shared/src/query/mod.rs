//! Geometric queries between placed shapes: contacts (with minimum
//! translation vectors) and ray casts.

pub mod contact;
pub mod ray;
pub mod sweep;

pub use contact::{contact, Contact, Proximity};
pub use ray::{cast_ray, Ray, RayCast, RayHit, Toi};
pub use sweep::{advance, reflect, slide, sweep, sweep_tiles, Sweep, SweepHit, TileHit};
