//! What can go wrong: a bad configuration or a socket that cannot be set up.

use thiserror::Error;

/// A [`crate::LinkConfig`] that makes no sense.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ConfigError {
    /// A probability that is not a number in `0..=1`.
    #[error("{name} must be a probability in 0..=1, not {value}")]
    Probability {
        /// Which one.
        name: &'static str,
        /// Its value.
        value: f64,
    },
}

/// A relay that cannot start.
#[derive(Debug, Error)]
pub enum RelayError {
    /// Binding or configuring a socket failed.
    #[error("socket: {0}")]
    Io(#[from] std::io::Error),
    /// A link configuration is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
}
