//! The replays writer: a task that takes replays from the rooms (through a
//! bounded queue, so a slow disk never holds up a tick), encodes and saves
//! them, and past the size cap deletes the oldest, keeping those of each
//! level's top runs in the records.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use ledge_shared::protocol::MAX_TOP;
use ledge_shared::replay;
use prometheus_client::metrics::counter::Counter;
use tokio::sync::{mpsc, oneshot};
use tokio::task::JoinHandle;
use tracing::{error, info, warn};

use super::dir::ReplayDir;
use super::recording::ToSave;
use crate::records::{RecordStore, RecordsHandle};

/// Replays waiting to be saved, at most; more are dropped (and counted).
pub const SAVE_QUEUE: usize = 256;

/// The writer's counters (in [`crate::metrics::Metrics`]).
#[derive(Debug, Clone, Default)]
pub struct ReplayMetrics {
    /// Replays saved.
    pub saved: Counter,
    /// Their bytes.
    pub saved_bytes: Counter,
    /// Replays not saved (queue full, encoding or disk failed).
    pub failed: Counter,
    /// Replays deleted past the cap.
    pub pruned: Counter,
}

/// A replay to save, and who to tell once its file is written (`true`)
/// or not (`false`, or the sender dropped).
#[derive(Debug)]
pub struct SaveJob {
    /// The replay.
    pub replay: ToSave,
    /// Told when the file is on disk (a record naming it waits for this).
    pub saved: Option<oneshot::Sender<bool>>,
}

/// Where rooms send replays (cheap to clone); off: nothing is recorded.
#[derive(Debug, Clone, Default)]
pub struct ReplaysHandle {
    queue: Option<mpsc::Sender<SaveJob>>,
    dir: Option<PathBuf>,
    metrics: ReplayMetrics,
}

impl ReplaysHandle {
    /// No replays.
    pub fn off() -> ReplaysHandle {
        ReplaysHandle::default()
    }

    /// A handle whose replays go to the returned receiver, not to disk
    /// (tests, tools).
    pub fn channel(capacity: usize) -> (ReplaysHandle, mpsc::Receiver<SaveJob>) {
        let (tx, rx) = mpsc::channel(capacity);
        let handle = ReplaysHandle {
            queue: Some(tx),
            dir: None,
            metrics: ReplayMetrics::default(),
        };
        (handle, rx)
    }

    /// Whether replays are saved (rooms record only then).
    pub fn is_on(&self) -> bool {
        self.queue.is_some()
    }

    /// The folder (`None`: off).
    pub fn dir(&self) -> Option<&Path> {
        self.dir.as_deref()
    }

    /// Starts the writer for `dir`; `records`, when on, says which
    /// replays the cap must keep. The task ends once every handle is gone
    /// and the queue is saved.
    pub fn spawn(
        dir: ReplayDir,
        records: RecordsHandle,
        metrics: ReplayMetrics,
    ) -> (ReplaysHandle, JoinHandle<()>) {
        let (tx, rx) = mpsc::channel(SAVE_QUEUE);
        let handle = ReplaysHandle {
            queue: Some(tx),
            dir: Some(dir.dir().to_owned()),
            metrics: metrics.clone(),
        };
        (handle, tokio::spawn(write(dir, records, rx, metrics)))
    }

    /// Queues a replay for saving (dropped, counted and logged when the
    /// queue is full).
    pub fn save(&self, replay: ToSave) {
        self.save_then(replay, None);
    }

    /// Queues a replay for saving; `saved` is told whether its file was
    /// written (`false` at once when the queue is full or replays are off).
    pub fn save_then(&self, replay: ToSave, saved: Option<oneshot::Sender<bool>>) {
        let Some(queue) = &self.queue else {
            if let Some(tell) = saved {
                let _ = tell.send(false);
            }
            return;
        };
        if let Err(e) = queue.try_send(SaveJob { replay, saved }) {
            self.metrics.failed.inc();
            let reason = match e {
                mpsc::error::TrySendError::Full(_) => "too many replays waiting to be saved",
                mpsc::error::TrySendError::Closed(_) => "the replays writer has stopped",
            };
            warn!("replay not saved: {reason}");
            let job = match e {
                mpsc::error::TrySendError::Full(j) | mpsc::error::TrySendError::Closed(j) => j,
            };
            if let Some(tell) = job.saved {
                let _ = tell.send(false);
            }
        }
    }
}

/// The writer task: saves what `rx` brings until every sender is gone.
async fn write(
    dir: ReplayDir,
    records: RecordsHandle,
    mut rx: mpsc::Receiver<SaveJob>,
    metrics: ReplayMetrics,
) {
    let mut dir = Some(dir);
    while let Some(SaveJob {
        replay: mut job,
        saved: tell,
    }) = rx.recv().await
    {
        let ticks = job.replay.ticks();
        let rate = u64::from(job.replay.header.tick_rate.max(1));
        job.replay.header.recorded_at_ms =
            crate::records::unix_millis().saturating_sub((ticks * 1000 / rate) as i64) as u64;
        let mut d = dir.take().expect("returned after each save");
        let done = tokio::task::spawn_blocking(move || {
            let saved = save(&mut d, &job);
            (d, saved)
        })
        .await;
        let (back, saved) = match done {
            Ok(done) => done,
            // The runtime is going away (the save never ran), or the save
            // panicked: either way this writer is done, and says so.
            Err(e) => {
                metrics.failed.inc();
                if e.is_panic() {
                    error!("replay not saved, and no more will be: saving panicked: {e}");
                }
                return;
            }
        };
        dir = Some(back);
        if let Some(tell) = tell {
            let _ = tell.send(saved.is_ok());
        }
        match saved {
            Ok(bytes) => {
                metrics.saved.inc();
                metrics.saved_bytes.inc_by(bytes);
            }
            Err(e) => {
                metrics.failed.inc();
                error!("replay not saved: {e}");
            }
        }
        let d = dir.as_mut().expect("just returned");
        if d.over_cap() {
            let keep = kept(records.store().as_ref()).await;
            match d.prune(&keep) {
                Ok(p) => {
                    metrics.pruned.inc_by(p.files);
                    info!(
                        files = p.files,
                        bytes = p.bytes,
                        "deleted the oldest replays (over --replays-cap-mib)"
                    );
                }
                Err(e) => error!("cannot delete old replays in {}: {e}", d.dir().display()),
            }
        }
    }
}

/// Encodes and saves one replay: its size.
fn save(dir: &mut ReplayDir, job: &ToSave) -> Result<u64, String> {
    let bytes = replay::encode(&job.replay).map_err(|e| format!("replay {}: {e}", job.id))?;
    dir.save(&job.id, &bytes)
        .map_err(|e| format!("{}: {e}", ReplayDir::path_of(dir.dir(), &job.id).display()))?;
    Ok(bytes.len() as u64)
}

/// The replays of each level's top [`MAX_TOP`] in the records (none when
/// records are off or cannot be read: then the oldest go regardless).
async fn kept(records: Option<&RecordStore>) -> BTreeSet<String> {
    let mut keep = BTreeSet::new();
    let Some(store) = records else {
        return keep;
    };
    let levels = match store.levels().await {
        Ok(l) => l,
        Err(e) => {
            warn!("cannot read which replays the records keep: {e}");
            return keep;
        }
    };
    for level in levels {
        match store.top(&level.hash, MAX_TOP as u32).await {
            Ok(top) => keep.extend(top.into_iter().filter_map(|t| t.replay)),
            Err(e) => warn!("cannot read which replays the records keep: {e}"),
        }
    }
    keep
}

#[cfg(test)]
mod tests {
    use ledge_levels::default_level;
    use ledge_shared::game::{Game, GameConfig};
    use ledge_shared::protocol::{LevelOffer, PlayerId};
    use ledge_shared::replay::ReplayHeader;

    use super::super::MatchRecording;
    use super::*;

    /// A short match's replay.
    fn a_replay() -> ToSave {
        let header = ReplayHeader::for_match(
            "room-1",
            ("default", "Default", LevelOffer::default()),
            GameConfig::default(),
            60,
        );
        let mut game = Game::from_level(&default_level()).unwrap();
        let mut rec = MatchRecording::new(header, "inst".into());
        rec.before_join(&game, std::iter::empty());
        game.add_player(PlayerId(1)).unwrap();
        rec.joined(PlayerId(1), "ann");
        for _ in 0..10 {
            game.step(&[]);
            rec.stepped(&game, &[], std::iter::empty());
        }
        game.remove_player(PlayerId(1));
        rec.left(&game, PlayerId(1), true).expect("the match")
    }

    #[tokio::test]
    async fn the_saver_is_told_once_the_file_is_on_disk_or_that_it_is_not() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = ReplayDir::open(tmp.path(), 1 << 30).unwrap();
        let (handle, task) =
            ReplaysHandle::spawn(dir, RecordsHandle::default(), Default::default());
        let job = a_replay();
        let path = ReplayDir::path_of(tmp.path(), &job.id);
        let (tell, saved) = oneshot::channel();
        handle.save_then(job, Some(tell));
        assert_eq!(saved.await, Ok(true));
        assert!(path.is_file(), "the file exists when the saver is told");
        drop(handle);
        task.await.unwrap();

        // Off: told at once that nothing was saved.
        let (tell, saved) = oneshot::channel();
        ReplaysHandle::off().save_then(a_replay(), Some(tell));
        assert_eq!(saved.await, Ok(false));
    }
}
