//! Geometric queries between placed shapes: contacts (with minimum
//! translation vectors) and ray casts.

pub mod contact;
pub mod ray;

pub use contact::{contact, Contact, Proximity};
pub use ray::{cast_ray, Ray, RayCast, RayHit, Toi};
