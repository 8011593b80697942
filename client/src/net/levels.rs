//! Which level a server plays: the client needs the same one to predict.
//!
//! The server sends the level's id and content hash in `Welcome`; the
//! client has the embedded default level and, optionally, level files. The
//! hash is [`Level::content_hash`].

use std::path::Path;

use ledge_shared::level::Level;
use ledge_shared::protocol::Welcome;

use crate::error::ClientError;

/// The level `welcome` names: `file` if given (it must match), else the
/// embedded default level. Refuses a level whose hash differs from the
/// server's ([`ClientError::LevelMismatch`]): predicting another level
/// would mispredict every tick.
pub fn level_for(welcome: &Welcome, file: Option<&Path>) -> Result<Level, ClientError> {
    let (level, source) = match file {
        Some(path) => (
            ledge_levels::load_level(path, None)
                .map_err(|e| ClientError::Level(e.to_string()))?
                .level,
            path.display().to_string(),
        ),
        None => (
            ledge_levels::default_level(),
            "the embedded default level".to_owned(),
        ),
    };
    check_level(welcome, &level, &source)?;
    Ok(level)
}

/// Checks `level` (described as `source` in the error) is the server's.
pub fn check_level(welcome: &Welcome, level: &Level, source: &str) -> Result<(), ClientError> {
    let ours = level.content_hash();
    if ours == welcome.level_hash {
        Ok(())
    } else {
        Err(ClientError::LevelMismatch {
            level_id: welcome.level_id.clone(),
            tried: source.to_owned(),
            server: welcome.level_hash,
            ours,
        })
    }
}
