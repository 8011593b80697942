//! Why a tilemap could not be built.

use crate::fixed::BoundsError;
use thiserror::Error;

/// A tilemap (or tile code) the simulation refuses.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum TilemapError {
    /// The origin or far corner outside the world bounds, or a tile size
    /// beyond the largest shape extent (names the value).
    #[error(transparent)]
    Bounds(#[from] BoundsError),
    /// A tile size that is odd or below 2 units (a whole number of pixels is
    /// always fine: 1 px is 256 units). Sizes beyond
    /// [`crate::fixed::MAX_EXTENT`] are [`TilemapError::Bounds`].
    #[error("tile size = {value} units must be an even number of at least 2 units")]
    TileSize {
        /// The offending size.
        value: i64,
    },
    /// A tile vector whose length is not `width * height`.
    #[error("a {width} x {height} tilemap needs {expected} tiles, got {got}")]
    TileCount {
        /// Grid width in tiles.
        width: u32,
        /// Grid height in tiles.
        height: u32,
        /// `width * height`.
        expected: u64,
        /// The length given.
        got: u64,
    },
    /// A byte that is no tile's code.
    #[error("tile code = {value} is not a tile (codes are 0 to 9)")]
    TileCode {
        /// The offending code.
        value: u8,
    },
}
