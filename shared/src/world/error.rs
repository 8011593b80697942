//! Why a world could not be built or changed.

use crate::fixed::BoundsError;
use thiserror::Error;

use super::id::BodyId;

/// A body, collider, controller or configuration the world refuses.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum BuildError {
    /// A value outside the numeric bounds (names the value).
    #[error(transparent)]
    Bounds(#[from] BoundsError),
    /// A body mass of zero.
    #[error("body mass must be positive, got {value}")]
    Mass {
        /// The offending mass.
        value: u32,
    },
    /// A static body given a velocity.
    #[error("a static body cannot have a velocity")]
    StaticVelocity,
    /// An id that names no body.
    #[error("no body {0:?}")]
    NoBody(BodyId),
    /// A trigger collider marked one-way (one-way is a property of solids).
    #[error("a trigger collider cannot be one-way")]
    OneWayTrigger,
    /// A controller attached to a static body.
    #[error("controller for {0:?}: a static body cannot be controlled")]
    StaticController(BodyId),
    /// A configuration value out of range.
    #[error("{what} = {value} is out of range")]
    Config {
        /// Which setting.
        what: &'static str,
        /// The offending value.
        value: i64,
    },
}
