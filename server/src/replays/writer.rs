//! The replays writer: a task that takes replays from the rooms (through a
//! bounded queue, so a slow disk never holds up a tick), encodes and saves
//! them, and past the size cap deletes the oldest, keeping those of each
//! level's top runs in the records.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use ledge_shared::protocol::MAX_TOP;
use ledge_shared::replay;
use prometheus_client::metrics::counter::Counter;
use tokio::sync::mpsc;
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

/// Where rooms send replays (cheap to clone); off: nothing is recorded.
#[derive(Debug, Clone, Default)]
pub struct ReplaysHandle {
    queue: Option<mpsc::Sender<ToSave>>,
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
    pub fn channel(capacity: usize) -> (ReplaysHandle, mpsc::Receiver<ToSave>) {
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
        let Some(queue) = &self.queue else {
            return;
        };
        if let Err(e) = queue.try_send(replay) {
            self.metrics.failed.inc();
            let reason = match e {
                mpsc::error::TrySendError::Full(_) => "too many replays waiting to be saved",
                mpsc::error::TrySendError::Closed(_) => "the replays writer has stopped",
            };
            warn!("replay not saved: {reason}");
        }
    }
}

/// The writer task: saves what `rx` brings until every sender is gone.
async fn write(
    dir: ReplayDir,
    records: RecordsHandle,
    mut rx: mpsc::Receiver<ToSave>,
    metrics: ReplayMetrics,
) {
    let mut dir = Some(dir);
    while let Some(mut job) = rx.recv().await {
        let ticks = job.replay.ticks();
        let rate = u64::from(job.replay.header.tick_rate.max(1));
        job.replay.header.recorded_at_ms =
            crate::records::unix_millis().saturating_sub((ticks * 1000 / rate) as i64) as u64;
        let mut d = dir.take().expect("returned after each save");
        let (back, saved) = tokio::task::spawn_blocking(move || {
            let saved = save(&mut d, &job);
            (d, saved)
        })
        .await
        .expect("saving does not panic");
        dir = Some(back);
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
