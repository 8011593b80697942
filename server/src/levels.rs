//! The levels a server plays ([`LevelSet`]): files, folders of them,
//! playlists and Tiled worlds (`--level`, repeated), or the embedded
//! default level; each with its id, content hash and the bundle clients
//! download, ready as a fresh [`Game`].

use std::path::{Path, PathBuf};
use std::sync::Arc;

use ledge_levels::LevelBundle;
use ledge_shared::game::{Game, GameConfig, GameError};
use ledge_shared::level::Level;
use ledge_shared::protocol::{check_text, LevelChoice, LevelOffer, MAX_ID_LEN, MAX_LEVELS};
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
    /// A folder, playlist or world could not be read, or names nothing.
    #[error("cannot read the level list {path}: {message}")]
    List {
        /// The folder, playlist or world.
        path: String,
        /// What went wrong, and what to do.
        message: String,
    },
    /// More levels than a rotation takes.
    #[error(
        "{count} levels given (--level, folders, playlists, worlds): a server rotates through \
         at most {MAX_LEVELS}; split them over several servers or rooms' hosts"
    )]
    TooMany {
        /// How many were named.
        count: usize,
    },
    /// `--level-settings` names one level's settings, but several levels
    /// were given.
    #[error(
        "--level-settings applies to one level, but {count} were given: put each level's \
         settings beside it as LEVEL.ledge.toml instead"
    )]
    SettingsForMany {
        /// How many levels.
        count: usize,
    },
    /// The level loads but the game refuses it.
    #[error("level {path} cannot be played: {source}")]
    Game {
        /// The file.
        path: String,
        /// Why.
        source: GameError,
    },
    /// A level's bundle is bigger than clients may download.
    #[error(
        "the level {path} and its images are {size} bytes once encoded for clients, more \
         than the server's limit of {max_mib} MiB: raise --max-level-mib (at most 96), or use \
         smaller images"
    )]
    TooLarge {
        /// The file.
        path: String,
        /// The encoded bundle's size.
        size: u64,
        /// The limit.
        max_mib: u64,
    },
}

/// One level of the server's rotation, loaded and checked.
#[derive(Debug, Clone)]
pub struct PlayLevel {
    /// The level id sent in `Welcome` ([`level_id`]).
    pub id: String,
    /// The level's content hash.
    pub hash: u64,
    /// The bundle clients download (hash and size).
    pub offer: LevelOffer,
    /// The bundle's bytes.
    pub bundle: bytes::Bytes,
    /// The level.
    pub level: Level,
    /// A fresh game of it, with the server's rules, at tick 0.
    pub game: Game,
    /// Its warnings, as the start line counts them.
    pub warnings: LevelWarnings,
}

/// What a level's warnings come to: how many, and the worst (the kind a
/// host must see first, [`ledge_levels::report::worst_warning`]).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LevelWarnings {
    /// How many (art warnings included).
    pub count: usize,
    /// The worst.
    pub worst: Option<ledge_levels::report::Warning>,
}

impl std::fmt::Display for LevelWarnings {
    /// `no warnings`, `1 warning: collision guessed`, `3 warnings, the
    /// worst: collision guessed`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (&self.worst, self.count) {
            (None, _) | (_, 0) => write!(f, "no warnings"),
            (Some(w), 1) => write!(f, "1 warning: {}", w.kind.summary()),
            (Some(w), n) => write!(f, "{n} warnings, the worst: {}", w.kind.summary()),
        }
    }
}

/// The levels a server plays, in rotation order: at least one, at most
/// [`MAX_LEVELS`].
#[derive(Debug, Clone)]
pub struct LevelSet {
    levels: Arc<[PlayLevel]>,
}

impl LevelSet {
    /// Loads every level `paths` names (each a level file, a folder of
    /// them, a playlist `.txt` or a Tiled `.world`; none: the embedded
    /// default level), each with `settings` or its own settings file, as
    /// games of `config` with the player scaled for each level
    /// ([`GameConfig::for_level`]); each bundle at most `max_bundle` bytes.
    pub fn load(
        paths: &[PathBuf],
        settings: Option<&Path>,
        config: GameConfig,
        max_level_mib: u64,
    ) -> Result<LevelSet, LevelLoadError> {
        let files = if paths.is_empty() {
            vec![None]
        } else {
            expand(paths)?.into_iter().map(Some).collect()
        };
        if files.len() > MAX_LEVELS {
            return Err(LevelLoadError::TooMany { count: files.len() });
        }
        if files.len() > 1 && settings.is_some() {
            return Err(LevelLoadError::SettingsForMany { count: files.len() });
        }
        let mut levels = Vec::with_capacity(files.len());
        for file in files {
            let path = file.as_deref().map_or_else(
                || "(embedded default level)".to_owned(),
                |p| p.display().to_string(),
            );
            let (bundle, warnings) = load_counted(file.as_deref(), settings)?;
            // The level's player scale: what this level's `Welcome` and
            // `LevelChange` carry, and clients predict with.
            let game = config
                .for_level(&bundle.level)
                .map_err(GameError::BadConfig)
                .and_then(|c| Game::with_config(&bundle.level, c))
                .map_err(|source| LevelLoadError::Game {
                    path: path.clone(),
                    source,
                })?;
            let bytes = bundle.encode();
            if bytes.len() as u64 > max_level_mib << 20 {
                return Err(LevelLoadError::TooLarge {
                    path,
                    size: bytes.len() as u64,
                    max_mib: max_level_mib,
                });
            }
            levels.push(PlayLevel {
                id: level_id(&bundle.level),
                hash: bundle.level.content_hash(),
                offer: LevelBundle::offer(&bytes),
                bundle: bytes::Bytes::from(bytes),
                level: bundle.level,
                game,
                warnings,
            });
        }
        Ok(LevelSet {
            levels: levels.into(),
        })
    }

    /// The levels, in rotation order (never empty).
    pub fn levels(&self) -> &[PlayLevel] {
        &self.levels
    }

    /// Level `i` (`i` below [`LevelSet::len`]; else the first).
    pub fn get(&self, i: usize) -> &PlayLevel {
        self.levels.get(i).unwrap_or(&self.levels[0])
    }

    /// How many levels.
    pub fn len(&self) -> usize {
        self.levels.len()
    }

    /// Always false: a set has at least one level.
    pub fn is_empty(&self) -> bool {
        self.levels.is_empty()
    }

    /// The level whose bundle has this SHA-256, if the server plays it.
    pub fn by_sha256(&self, sha256: &[u8; 32]) -> Option<&PlayLevel> {
        self.levels.iter().find(|l| &l.offer.sha256 == sha256)
    }

    /// The levels' warnings for the start lines: `level "castle": 2
    /// warnings, the worst: collision guessed` (the log lists them); for a
    /// rotation each level with warnings (at most 8 named).
    pub fn warnings_line(&self) -> String {
        if let [one] = &self.levels[..] {
            return format!("level {:?}: {}", one.id, one.warnings);
        }
        let warned: Vec<&PlayLevel> = self
            .levels
            .iter()
            .filter(|l| l.warnings.count > 0)
            .collect();
        let mut line = format!(
            "{} levels, {} with warnings",
            self.levels.len(),
            warned.len()
        );
        for (i, l) in warned.iter().take(8).enumerate() {
            line.push_str(if i == 0 { ": " } else { "; " });
            line.push_str(&format!("{:?} {}", l.id, l.warnings));
        }
        if warned.len() > 8 {
            line.push_str(&format!("; and {} more", warned.len() - 8));
        }
        line
    }

    /// The rotation as players choose from it.
    pub fn choices(&self) -> Vec<LevelChoice> {
        self.levels
            .iter()
            .map(|l| LevelChoice {
                id: l.id.clone(),
                name: l.id.clone(),
            })
            .collect()
    }
}

/// Most files one folder, playlist or world may name.
const MAX_LISTED: usize = 4 * MAX_LEVELS;

/// Largest playlist or world file read, bytes.
const MAX_LIST_BYTES: u64 = 1 << 20;

/// Level files by extension (what [`ledge_levels::load_level`] reads; an
/// LDtk project stands for all its levels, its `.ldtkl` files are read
/// through it).
fn is_level_file(path: &Path) -> bool {
    matches!(
        path.extension().and_then(|e| e.to_str()),
        Some("json" | "tmx" | "ldtk")
    )
}

/// Whether `path` names a whole LDtk project (`game.ldtk`, not
/// `game.ldtk#Level_2`).
fn is_ldtk_project(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ldtk"))
}

/// `path`'s levels onto `files`: an LDtk project's every level in its
/// order (`PROJECT.ldtk#LEVEL` each), any other path as it is.
fn push_levels(files: &mut Vec<PathBuf>, path: PathBuf) -> Result<(), LevelLoadError> {
    if !is_ldtk_project(&path) {
        files.push(path);
        return Ok(());
    }
    let levels = ledge_levels::ldtk::level_paths(&path).map_err(|e| LevelLoadError::List {
        path: path.display().to_string(),
        message: format!("{e}: name one of its levels as {}#LEVEL", path.display()),
    })?;
    files.extend(levels.into_iter().take(MAX_LISTED + 1));
    Ok(())
}

/// The level files `paths` name, in order: files as given, a folder's
/// level files by name, a playlist's lines (relative to it; `#` starts a
/// comment), a Tiled world's maps in its order, an LDtk project's levels
/// in its order (wherever it is named).
fn expand(paths: &[PathBuf]) -> Result<Vec<PathBuf>, LevelLoadError> {
    let mut files = Vec::new();
    for path in paths {
        let list = |message: String| LevelLoadError::List {
            path: path.display().to_string(),
            message,
        };
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if path.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(path)
                .map_err(|e| list(e.to_string()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && is_level_file(p))
                .take(MAX_LISTED + 1)
                .collect();
            if found.is_empty() {
                return Err(list(
                    "no level files (.json, .tmx, .ldtk) in this folder".into(),
                ));
            }
            found.sort();
            for file in found {
                push_levels(&mut files, file)?;
            }
        } else if ext == "txt" || ext == "world" {
            let text = read_list(path).map_err(list)?;
            let dir = path.parent().unwrap_or(Path::new("."));
            let named = if ext == "txt" {
                playlist(&text)
            } else {
                world_maps(&text).map_err(list)?
            };
            if named.is_empty() {
                return Err(list("it names no levels".into()));
            }
            for name in named.into_iter().take(MAX_LISTED + 1) {
                push_levels(&mut files, dir.join(name))?;
            }
        } else {
            push_levels(&mut files, path.clone())?;
        }
        if files.len() > MAX_LISTED {
            return Err(LevelLoadError::TooMany { count: files.len() });
        }
    }
    Ok(files)
}

/// Reads a playlist or world file, at most [`MAX_LIST_BYTES`].
fn read_list(path: &Path) -> Result<String, String> {
    use std::io::Read;
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut text = String::new();
    file.take(MAX_LIST_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(|e| e.to_string())?;
    if text.len() as u64 > MAX_LIST_BYTES {
        return Err(format!("larger than {MAX_LIST_BYTES} bytes"));
    }
    Ok(text)
}

/// A playlist's level paths: one per line, blank lines and comments
/// skipped (a `#` at the line's start or after a space: in
/// `game.ldtk#Level_2` it names an LDtk level).
fn playlist(text: &str) -> Vec<String> {
    let uncommented = |line: &str| -> usize {
        let bytes = line.as_bytes();
        (0..bytes.len())
            .find(|&i| bytes[i] == b'#' && (i == 0 || bytes[i - 1].is_ascii_whitespace()))
            .unwrap_or(bytes.len())
    };
    text.lines()
        .map(|l| l[..uncommented(l)].trim())
        .filter(|l| !l.is_empty())
        .map(str::to_owned)
        .collect()
}

/// A Tiled `.world`'s maps (`maps[].fileName`), in the file's order.
/// Pattern worlds (`patterns`) name no files: refused with what to do.
fn world_maps(text: &str) -> Result<Vec<String>, String> {
    let world: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("not a Tiled world (JSON): {e}"))?;
    let Some(maps) = world.get("maps").and_then(|m| m.as_array()) else {
        return Err(if world.get("patterns").is_some() {
            "a world of file-name patterns: list its maps in a playlist (.txt) instead".into()
        } else {
            "a Tiled world lists its maps in \"maps\"; this one has none".into()
        });
    };
    maps.iter()
        .map(|m| {
            m.get("fileName")
                .and_then(|f| f.as_str())
                .map(str::to_owned)
                .ok_or_else(|| "a map without a \"fileName\"".to_owned())
        })
        .collect()
}

/// Loads `path` (OGMO `.json` or Tiled `.tmx`) with its settings file
/// (`settings`, else `LEVEL.ledge.toml` beside it when there is one; see
/// [`ledge_levels::load_level`]), logging every warning the importer gives
/// (what it ignored or placed, and where), with the art clients draw it
/// with; or the embedded default level (no art).
pub fn load(path: Option<&Path>, settings: Option<&Path>) -> Result<LevelBundle, LevelLoadError> {
    load_counted(path, settings).map(|(bundle, _)| bundle)
}

/// [`load`], and what its warnings come to.
fn load_counted(
    path: Option<&Path>,
    settings: Option<&Path>,
) -> Result<(LevelBundle, LevelWarnings), LevelLoadError> {
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
            let warnings = LevelWarnings {
                count: loaded.warnings.len() + loaded.art.warnings.len(),
                worst: ledge_levels::report::worst_warning(&loaded),
            };
            let bundle = LevelBundle {
                level: loaded.level,
                art: loaded.art,
            };
            Ok((bundle, warnings))
        }
        None => Ok((LevelBundle::default_level(), LevelWarnings::default())),
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

    /// A folder holding the default level twice, as `a.json` and `b.json`.
    fn two_copies() -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        ledge_levels::write_default_copies(dir.path(), &["b", "a"]).unwrap();
        dir
    }

    fn ids(set: &LevelSet) -> Vec<&str> {
        set.levels().iter().map(|l| l.id.as_str()).collect()
    }

    #[test]
    fn folders_playlists_and_worlds_name_levels_in_order() {
        let dir = two_copies();
        let d = dir.path();
        let load = |paths: &[PathBuf]| LevelSet::load(paths, None, GameConfig::default(), 32);
        assert_eq!(
            ids(&load(&[d.to_owned()]).unwrap()),
            ["a", "b"],
            "a folder, by name"
        );
        std::fs::write(
            d.join("list.txt"),
            "# the order\nb.json\n\n a.json # first\n",
        )
        .unwrap();
        let set = load(&[d.join("list.txt")]).unwrap();
        assert_eq!(ids(&set), ["b", "a"]);
        assert_ne!(set.get(0).offer, set.get(1).offer);
        assert_eq!(set.by_sha256(&set.get(1).offer.sha256).unwrap().id, "a");
        let world = r#"{"maps": [{"fileName": "a.json", "x": 0, "y": 0}, {"fileName": "b.json"}], "type": "world"}"#;
        std::fs::write(d.join("game.world"), world).unwrap();
        assert_eq!(ids(&load(&[d.join("game.world")]).unwrap()), ["a", "b"]);
        assert_eq!(ids(&load(&[]).unwrap()).len(), 1, "the embedded level");
    }

    /// LDtk's own platformer sample (MIT, `../shared/testdata/levels`).
    const LDTK_PLATFORMER: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/testdata/levels/ldtk-samples/Typical_2D_platformer_example.ldtk"
    );

    #[test]
    fn an_ldtk_project_rotates_through_all_its_levels() {
        let load = |paths: &[PathBuf]| LevelSet::load(paths, None, GameConfig::default(), 32);
        let project = PathBuf::from(LDTK_PLATFORMER);
        let names = ledge_levels::ldtk::level_names(&project).unwrap();
        assert!(names.len() > 1, "{names:?}");
        let all = load(std::slice::from_ref(&project)).unwrap();
        assert_eq!(all.levels().len(), names.len());
        let offers: std::collections::BTreeSet<_> =
            all.levels().iter().map(|l| l.offer.sha256).collect();
        assert_eq!(offers.len(), names.len(), "a bundle per level");
        // One level of it, by name, is one level; in a playlist, all.
        let one = format!("{LDTK_PLATFORMER}#{}", names[1]);
        let single = load(&[PathBuf::from(&one)]).unwrap();
        assert_eq!(single.levels().len(), 1);
        assert_eq!(single.get(0).offer, all.get(1).offer);
        let dir = tempfile::tempdir().unwrap();
        let list = dir.path().join("list.txt");
        std::fs::write(&list, format!("{LDTK_PLATFORMER}\n{one}\n")).unwrap();
        assert_eq!(load(&[list]).unwrap().levels().len(), names.len() + 1);
        // A project that does not read says what to name instead.
        let bad = dir.path().join("broken.ldtk");
        std::fs::write(&bad, "{").unwrap();
        let err = load(&[bad]).unwrap_err().to_string();
        assert!(
            err.contains("broken.ldtk") && err.contains("#LEVEL"),
            "{err}"
        );
    }

    #[test]
    fn bad_lists_say_what_to_do() {
        let dir = two_copies();
        let d = dir.path();
        let load = |paths: &[PathBuf]| LevelSet::load(paths, None, GameConfig::default(), 32);
        std::fs::write(d.join("empty.txt"), "# nothing\n").unwrap();
        std::fs::write(d.join("p.world"), r#"{"patterns": [{"regexp": "x"}]}"#).unwrap();
        std::fs::create_dir(d.join("none")).unwrap();
        let many = "a.json\n".repeat(MAX_LEVELS + 1);
        std::fs::write(d.join("many.txt"), many).unwrap();
        for (path, says) in [
            ("empty.txt", "names no levels"),
            ("p.world", "playlist"),
            ("none", "no level files"),
            ("many.txt", "at most 64"),
        ] {
            let err = load(&[d.join(path)]).unwrap_err().to_string();
            assert!(err.contains(says), "{path}: {err}");
        }
        let err = LevelSet::load(
            &[d.to_owned()],
            Some(&d.join("x.toml")),
            GameConfig::default(),
            32,
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("LEVEL.ledge.toml"), "{err}");
    }

    #[test]
    fn a_missing_file_is_an_error() {
        let err = load(Some(Path::new("/nonexistent/level.json")), None).unwrap_err();
        assert!(err.to_string().contains("/nonexistent/level.json"), "{err}");
    }

    /// The start line counts a level's warnings and names the worst:
    /// echo-slopes' `slopes.json` (shared/testdata) has no collision data.
    #[test]
    fn the_warnings_line_names_the_worst_warning() {
        let slopes = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../shared/testdata/levels/echo-slopes/slopes.json");
        let set = LevelSet::load(&[], None, GameConfig::default(), 64).unwrap();
        assert_eq!(set.warnings_line(), "level \"default\": no warnings");
        if !slopes.is_file() {
            return;
        }
        let set = LevelSet::load(&[slopes], None, GameConfig::default(), 64).unwrap();
        assert_eq!(
            set.warnings_line(),
            "level \"slopes\": 2 warnings, the worst: collision guessed"
        );
        let w = &set.get(0).warnings;
        assert_eq!(
            w.worst.as_ref().unwrap().kind,
            ledge_levels::report::WarningKind::GuessedCollision
        );
    }
}
