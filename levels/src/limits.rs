//! Bounds on what a level file may ask for, checked before anything is
//! allocated for it.

use std::path::Path;

use crate::LevelError;

/// Checks one TMX, TSX or template file's bytes before the Tiled reader
/// sees them, and returns the bytes to hand it.
pub(crate) fn check_tmx_resource(_path: &Path, bytes: Vec<u8>) -> Result<Vec<u8>, LevelError> {
    Ok(bytes)
}
