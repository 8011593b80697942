//! The in-process server's log, for tests that check what it says:
//! [`capture`] installs (once per process) a `tracing` subscriber that keeps
//! every event at `info` and above in memory, and also writes it to stderr
//! (shown with a failing test's output).
//!
//! Every test of a process shares it: under nextest each test has a process
//! of its own; under `cargo test` a test should look for lines only it can
//! cause (its names, its ports).

use std::io::Write;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

/// The captured log (cheap to clone).
#[derive(Debug, Clone)]
pub struct Logs {
    text: Arc<Mutex<Vec<u8>>>,
}

/// One event's writer: into the buffer and to stderr.
struct Tee(Arc<Mutex<Vec<u8>>>);

impl Write for Tee {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.lock().expect("log buffer").extend_from_slice(buf);
        let _ = std::io::stderr().write_all(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Starts keeping the log (the first call in a process), and returns it.
/// Panics if another subscriber was installed first.
pub fn capture() -> Logs {
    static LOGS: OnceLock<Logs> = OnceLock::new();
    LOGS.get_or_init(|| {
        let text = Arc::new(Mutex::new(Vec::new()));
        let writer = text.clone();
        tracing_subscriber::fmt()
            .with_max_level(tracing::Level::INFO)
            .with_ansi(false)
            .with_writer(move || Tee(writer.clone()))
            .try_init()
            .expect("no other tracing subscriber in the test process");
        Logs { text }
    })
    .clone()
}

impl Logs {
    /// Everything logged so far.
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.text.lock().expect("log buffer")).into_owned()
    }

    /// The lines logged so far that contain every one of `parts`.
    pub fn lines_with(&self, parts: &[&str]) -> Vec<String> {
        self.text()
            .lines()
            .filter(|line| parts.iter().all(|p| line.contains(p)))
            .map(str::to_owned)
            .collect()
    }

    /// Waits up to `within` for a line that contains every one of `parts`;
    /// the first such line.
    pub async fn wait_for(&self, parts: &[&str], within: Duration) -> Option<String> {
        let deadline = Instant::now() + within;
        loop {
            if let Some(line) = self.lines_with(parts).into_iter().next() {
                return Some(line);
            }
            if Instant::now() >= deadline {
                return None;
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    }
}
