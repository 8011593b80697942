//! Ghosts: the runs a joining player races against, read from the records
//! and the replays folder: the level's record, and the player's own best
//! when it is another run. Each goes out as a [`ServerControl::Ghost`]
//! with the run's replay file, if that file is small enough for a control
//! frame ([`MAX_GHOST_REPLAY`]).
//!
//! [`ServerControl::Ghost`]: ledge_shared::protocol::ServerControl::Ghost

use std::path::Path;

use ledge_shared::protocol::{GhostRun, MAX_GHOST_REPLAY};
use tracing::debug;

use super::{is_replay_id, ReplayDir};
use crate::records::RecordStore;

/// The ghosts for `player` on the level of content hash `level_hash`:
/// the record first, then the player's best (none when the records or the
/// files cannot be read: ghosts are a nicety, never an error for play).
pub async fn find(
    store: &RecordStore,
    dir: &Path,
    level_hash: &str,
    player: &str,
) -> Vec<GhostRun> {
    let mut out = Vec::new();
    let record = match store.top(level_hash, 1).await {
        Ok(top) => top.into_iter().next(),
        Err(e) => {
            debug!("no ghosts: {e}");
            return out;
        }
    };
    let mut record_replay = None;
    if let Some(r) = record {
        record_replay = r.replay.clone();
        if let Some(bytes) = read(dir, r.replay.as_deref()).await {
            out.push(GhostRun {
                record: true,
                player: r.player,
                millis: r.millis,
                replay: bytes,
            });
        }
    }
    if let Ok(Some((millis, replay))) = store.best_of(level_hash, player).await {
        if replay.is_some() && replay != record_replay {
            if let Some(bytes) = read(dir, replay.as_deref()).await {
                out.push(GhostRun {
                    record: false,
                    player: player.to_owned(),
                    millis,
                    replay: bytes,
                });
            }
        }
    }
    out
}

/// Replay `id`'s bytes, if it is a replay id, its file exists and it fits
/// a ghost message.
async fn read(dir: &Path, id: Option<&str>) -> Option<Vec<u8>> {
    let id = id.filter(|id| is_replay_id(id))?;
    let path = ReplayDir::path_of(dir, id);
    let len = tokio::fs::metadata(&path).await.ok()?.len();
    if len > MAX_GHOST_REPLAY as u64 {
        debug!(id, len, "a ghost's replay too big to send");
        return None;
    }
    tokio::fs::read(&path).await.ok()
}
