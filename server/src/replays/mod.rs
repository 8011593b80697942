//! The server's replays: every finished run and every match, saved as a
//! replay file ([`ledge_shared::replay`]) in a folder (`--replays`), the
//! oldest deleted past a size cap except those the records show.
//!
//! A room records its match while anyone is in it ([`recording`]); a run
//! that finishes is cut out of it and saved, its id stored with the run in
//! the records; the match is saved when the room empties (or every half
//! hour of play). The writer ([`writer`]) encodes and writes them off the
//! room's thread; the folder ([`dir`]) keeps the files and their order.
//! The web port serves them at `/replays/ID`.

pub mod dir;
pub mod ghosts;
pub mod recording;
pub mod writer;

use std::path::{Path, PathBuf};

pub use dir::ReplayDir;
pub use recording::MatchRecording;
pub use writer::{ReplaysHandle, SaveJob, SAVE_QUEUE};

/// Where replays go (`--replays`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReplaysTarget {
    /// No replays (`--replays off`).
    Off,
    /// This folder, created if missing.
    Dir(PathBuf),
}

/// Folder of the default replays, in the certificate directory.
pub const DEFAULT_DIR: &str = "replays";

/// The default size cap, MiB.
pub const DEFAULT_CAP_MIB: u64 = 1024;

/// A replay file's extension.
pub const EXTENSION: &str = "ledgereplay";

/// Hex digits in a replay id.
pub const ID_LEN: usize = 16;

impl ReplaysTarget {
    /// `--replays`'s value: `off` or a folder.
    pub fn parse(value: &str) -> ReplaysTarget {
        let v = value.trim();
        if v.eq_ignore_ascii_case("off") || v.eq_ignore_ascii_case("none") {
            ReplaysTarget::Off
        } else {
            ReplaysTarget::Dir(PathBuf::from(v))
        }
    }

    /// The default: [`DEFAULT_DIR`] in `cert_dir`.
    pub fn in_state_dir(cert_dir: &Path) -> ReplaysTarget {
        ReplaysTarget::Dir(cert_dir.join(DEFAULT_DIR))
    }
}

/// The id of the replay saved under `key` (a run's records key, or a
/// match's): the first [`ID_LEN`] hex digits of its SHA-256, so ids are
/// safe in paths and URLs and the same key always gives the same id.
pub fn replay_id(key: &str) -> String {
    let digest = ring::digest::digest(&ring::digest::SHA256, key.as_bytes());
    digest.as_ref()[..ID_LEN / 2]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Whether `id` is a replay id: [`ID_LEN`] lower-case hex digits.
pub fn is_replay_id(id: &str) -> bool {
    id.len() == ID_LEN && id.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_short_hex_and_stable() {
        let id = replay_id("abc/room-1/7/1234");
        assert!(is_replay_id(&id), "{id}");
        assert_eq!(id, replay_id("abc/room-1/7/1234"));
        assert_ne!(id, replay_id("abc/room-1/7/1235"));
        assert!(!is_replay_id("../../etc/passwd"));
        assert!(!is_replay_id(&id.to_uppercase()));
        assert!(!is_replay_id(&id[1..]));
    }

    #[test]
    fn targets_parse() {
        assert_eq!(ReplaysTarget::parse("off"), ReplaysTarget::Off);
        assert_eq!(
            ReplaysTarget::parse("/srv/replays"),
            ReplaysTarget::Dir("/srv/replays".into())
        );
        assert_eq!(
            ReplaysTarget::in_state_dir(Path::new("certs")),
            ReplaysTarget::Dir("certs/replays".into())
        );
    }
}
