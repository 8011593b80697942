//! Attackers for the hostile-load tests: tasks on a runtime of their own
//! (one thread), as an attacker runs on a machine of its own, so they never
//! hold up the server's tasks in the test's runtime; a shared stop flag and
//! counters of what got through.

use std::future::Future;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

use tokio::runtime::{Handle, Runtime};
use tokio::task::JoinSet;

/// Attack tasks and their shared stop flag and counters.
pub struct Attack {
    runtime: Option<Runtime>,
    tasks: JoinSet<()>,
    /// Set when the attack is over: tasks end at their next check.
    pub stop: Arc<AtomicBool>,
    /// Connections (or requests) the attackers got through.
    pub opened: Arc<AtomicU64>,
    /// Attempts that failed (refused, closed).
    pub failed: Arc<AtomicU64>,
}

impl Default for Attack {
    fn default() -> Attack {
        Attack::new()
    }
}

impl Attack {
    /// An attack with no task yet, on a one-thread runtime of its own.
    pub fn new() -> Attack {
        Attack {
            runtime: Some(
                tokio::runtime::Builder::new_multi_thread()
                    .worker_threads(1)
                    .enable_all()
                    .build()
                    .expect("attacker runtime"),
            ),
            tasks: JoinSet::new(),
            stop: Arc::default(),
            opened: Arc::default(),
            failed: Arc::default(),
        }
    }

    /// The attackers' runtime (enter it to make sockets there).
    pub fn handle(&self) -> Handle {
        self.runtime
            .as_ref()
            .expect("attack running")
            .handle()
            .clone()
    }

    /// Whether the attack was stopped.
    pub fn stopped(&self) -> bool {
        self.stop.load(Ordering::SeqCst)
    }

    /// Runs `task` on the attackers' runtime.
    pub fn spawn(&mut self, task: impl Future<Output = ()> + Send + 'static) {
        let handle = self.handle();
        self.tasks.spawn_on(task, &handle);
    }

    /// Stops every task and waits for them: (opened, failed).
    pub async fn stop(mut self) -> (u64, u64) {
        self.stop.store(true, Ordering::SeqCst);
        while let Some(done) = self.tasks.join_next().await {
            done.expect("attack task");
        }
        if let Some(runtime) = self.runtime.take() {
            runtime.shutdown_background();
        }
        (
            self.opened.load(Ordering::SeqCst),
            self.failed.load(Ordering::SeqCst),
        )
    }
}
