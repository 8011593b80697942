//! The level a server plays: a file, or the embedded default level; its id
//! and content hash for the [`ledge_shared::protocol::Welcome`].

use std::path::Path;

use ledge_levels::LevelBundle;
use ledge_shared::level::Level;
use ledge_shared::protocol::{check_text, MAX_ID_LEN};
use tracing::warn;

/// Why the level could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LevelLoadError {
    /// The file could not be read or is not a valid level.
    #[error("cannot load level {path}: {message}")]
    Load {
        /// The file.
        path: String,
        /// What the loader said.
        message: String,
    },
}

/// Loads `path` (OGMO `.json` or Tiled `.tmx`) with its settings file
/// (`settings`, else `LEVEL.ledge.toml` beside it when there is one; see
/// [`ledge_levels::load_level`]), logging every warning the importer gives
/// (what it ignored or placed, and where), with the art clients draw it
/// with; or the embedded default level (no art).
pub fn load(path: Option<&Path>, settings: Option<&Path>) -> Result<LevelBundle, LevelLoadError> {
    match path {
        Some(path) => {
            let loaded =
                ledge_levels::load_level(path, settings).map_err(|e| LevelLoadError::Load {
                    path: path.display().to_string(),
                    message: e.to_string(),
                })?;
            for w in &loaded.warnings {
                warn!("level: {w}");
            }
            for w in &loaded.art.warnings {
                warn!("level art: {w}");
            }
            Ok(LevelBundle {
                level: loaded.level,
                art: loaded.art,
            })
        }
        None => Ok(LevelBundle::default_level()),
    }
}

/// The embedded default level.
pub fn default_level() -> Level {
    ledge_levels::default_level()
}

/// The level's id as sent in `Welcome`: its name, or `"level"` when the name
/// is not a valid protocol id (empty, too long, control characters).
pub fn level_id(level: &Level) -> String {
    if check_text("level id", &level.name, 1, MAX_ID_LEN).is_ok() {
        level.name.clone()
    } else {
        "level".to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_level_loads_and_has_a_stable_identity() {
        let a = load(None, None).unwrap().level;
        let b = load(None, None).unwrap().level;
        assert_eq!(a.content_hash(), b.content_hash());
        assert!(check_text("level id", &level_id(&a), 1, MAX_ID_LEN).is_ok());
        let mut renamed = a.clone();
        renamed.name = "x\n".repeat(40);
        assert_eq!(level_id(&renamed), "level");
        assert_ne!(renamed.content_hash(), a.content_hash());
    }

    #[test]
    fn a_missing_file_is_an_error() {
        let err = load(Some(Path::new("/nonexistent/level.json")), None).unwrap_err();
        assert!(err.to_string().contains("/nonexistent/level.json"), "{err}");
    }
}
