//! Reading level files from disk with a cap on their size, so that no file
//! is read past [`MAX_FILE_BYTES`] (or a smaller cap of the caller's).

use std::path::Path;

use crate::error::LevelError;
use crate::options::MAX_FILE_BYTES;

/// Reads a file of at most [`MAX_FILE_BYTES`] as UTF-8.
pub(crate) fn read_text(path: &Path) -> Result<String, LevelError> {
    let bytes = read_bytes(path)?;
    String::from_utf8(bytes).map_err(|e| LevelError::Syntax {
        file: path.display().to_string(),
        field: format!("byte {}", e.utf8_error().valid_up_to()),
        format: "UTF-8 text",
        message: e.to_string(),
    })
}

/// Reads a file of at most [`MAX_FILE_BYTES`].
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, LevelError> {
    read_bytes_capped(path, MAX_FILE_BYTES)
}

/// Reads a file of at most `cap` bytes (a larger one is refused unread
/// past the cap).
pub(crate) fn read_bytes_capped(path: &Path, cap: u64) -> Result<Vec<u8>, LevelError> {
    use std::io::Read;
    let io = |e: std::io::Error| LevelError::Io {
        file: path.display().to_string(),
        message: e.to_string(),
    };
    let f = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    f.take(cap + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > cap {
        return Err(LevelError::Io {
            file: path.display().to_string(),
            message: format!("larger than {cap} bytes"),
        });
    }
    Ok(bytes)
}
