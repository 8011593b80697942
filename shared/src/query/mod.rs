//! Geometric queries between placed shapes: contacts (with minimum
//! translation vectors) and ray casts.

pub mod contact;
pub mod ray;

pub use contact::{contact, Contact, Proximity};
