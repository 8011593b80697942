//! The records writer: a task that takes finished runs from the rooms
//! (through a bounded queue, so a slow database never holds up a tick),
//! stores them in batches of one transaction each, retrying a failed batch
//! a few times, and only then answers each run's player.

use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use ledge_shared::protocol::Standing;
use prometheus_client::metrics::counter::Counter;
use prometheus_client::metrics::histogram::Histogram;
use tokio::sync::mpsc;
use tokio::task::JoinHandle;
use tracing::{error, warn};

use super::{FinishedRun, RecordStore};

/// Runs waiting to be stored, at most; more are answered "not recorded"
/// at once (and counted).
pub const WRITE_QUEUE: usize = 4096;
/// Most runs stored in one transaction.
pub const BATCH: usize = 256;
/// Waits before each retry of a failed batch; then its runs are answered
/// "not recorded". While the database is down, each try fails after
/// [`super::store::ACQUIRE_TIMEOUT`].
pub const RETRIES: [Duration; 3] = [
    Duration::from_millis(200),
    Duration::from_secs(1),
    Duration::from_secs(3),
];

/// What a run's player is told: where it stands, or why it was not
/// stored.
pub type Reply = Box<dyn FnOnce(Result<Standing, String>) + Send>;

struct Pending {
    run: FinishedRun,
    reply: Reply,
}

/// The writer's counters (in [`crate::metrics::Metrics`]).
#[derive(Debug, Clone, Default)]
pub struct WriterMetrics {
    /// Runs stored.
    pub stored: Counter,
    /// Runs not stored (queue full, or the database failed).
    pub failed: Counter,
    /// Time from a batch's first try to its commit, seconds.
    pub write_seconds: Option<Histogram>,
}

/// Where rooms send finished runs (cheap to clone; clones share one
/// writer). Off: every run is answered "not recorded" with the reason,
/// until [`RecordsHandle::go_live`] (a database reached later).
#[derive(Clone)]
pub struct RecordsHandle {
    live: Arc<OnceLock<Live>>,
    off: Arc<str>,
    metrics: WriterMetrics,
}

/// An open store and its writer's queue.
struct Live {
    queue: mpsc::Sender<Pending>,
    store: RecordStore,
}

impl std::fmt::Debug for RecordsHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordsHandle")
            .field("store", &self.live.get().map(|l| l.store.target()))
            .field("off", &self.off)
            .finish()
    }
}

impl Default for RecordsHandle {
    fn default() -> RecordsHandle {
        RecordsHandle::off("this server keeps no records")
    }
}

impl RecordsHandle {
    /// No records (yet); runs are answered with `reason`.
    pub fn off(reason: &str) -> RecordsHandle {
        RecordsHandle {
            live: Arc::new(OnceLock::new()),
            off: reason.into(),
            metrics: WriterMetrics::default(),
        }
    }

    /// Starts the writer for `store`: the handle and the task, which ends
    /// once every handle is gone and the queue is stored.
    pub fn spawn(store: RecordStore, metrics: WriterMetrics) -> (RecordsHandle, JoinHandle<()>) {
        let handle = RecordsHandle {
            metrics,
            ..RecordsHandle::off("")
        };
        let task = handle.go_live(store).expect("a new handle is not live");
        (handle, task)
    }

    /// Starts storing in `store` (a database reached after the server
    /// started), with `metrics`: every clone of this handle stores from
    /// now on. The writer task, or `None` if this handle was live already.
    pub fn go_live(&self, store: RecordStore) -> Option<JoinHandle<()>> {
        let (tx, rx) = mpsc::channel(WRITE_QUEUE);
        let mut task = None;
        self.live.get_or_init(|| {
            task = Some(tokio::spawn(write(store.clone(), rx, self.metrics.clone())));
            Live { queue: tx, store }
        });
        task
    }

    /// The same handle counting into `metrics`.
    pub fn with_metrics(mut self, metrics: WriterMetrics) -> RecordsHandle {
        self.metrics = metrics;
        self
    }

    /// The store, for reading (`None`: records are off).
    pub fn store(&self) -> Option<RecordStore> {
        self.live.get().map(|l| l.store.clone())
    }

    /// Queues `run`; `reply` is called once it is stored or not.
    pub fn submit(&self, run: FinishedRun, reply: Reply) {
        let Some(live) = self.live.get() else {
            reply(Err(self.off.to_string()));
            return;
        };
        if let Err(e) = live.queue.try_send(Pending { run, reply }) {
            self.metrics.failed.inc();
            let (reason, pending) = match e {
                mpsc::error::TrySendError::Full(p) => ("too many runs waiting to be stored", p),
                mpsc::error::TrySendError::Closed(p) => ("the records writer has stopped", p),
            };
            warn!(player = %pending.run.player, "run not recorded: {reason}");
            (pending.reply)(Err(reason.into()));
        }
    }
}

/// The writer task: batches from `rx` until every sender is gone.
async fn write(store: RecordStore, mut rx: mpsc::Receiver<Pending>, metrics: WriterMetrics) {
    let mut batch: Vec<Pending> = Vec::with_capacity(BATCH);
    while rx.recv_many(&mut batch, BATCH).await > 0 {
        let runs: Vec<FinishedRun> = batch.iter().map(|p| p.run.clone()).collect();
        let started = Instant::now();
        let mut result = store.store(&runs).await;
        for wait in RETRIES {
            let Err(e) = &result else { break };
            warn!(
                "records: storing {} runs failed, retrying in {wait:?}: {e}",
                runs.len()
            );
            tokio::time::sleep(wait).await;
            result = store.store(&runs).await;
        }
        match result {
            Ok(standings) => {
                if let Some(h) = &metrics.write_seconds {
                    h.observe(started.elapsed().as_secs_f64());
                }
                metrics.stored.inc_by(runs.len() as u64);
                for (p, standing) in batch.drain(..).zip(standings) {
                    (p.reply)(Ok(standing));
                }
            }
            Err(e) => {
                error!("records: {} runs not stored: {e}", runs.len());
                metrics.failed.inc_by(runs.len() as u64);
                let reason = format!("the records database failed: {e}");
                for p in batch.drain(..) {
                    (p.reply)(Err(reason.clone()));
                }
            }
        }
    }
}
