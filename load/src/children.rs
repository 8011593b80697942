//! Child processes that cannot outlive the benchmark: a [`Guarded`] child
//! is killed when dropped (on success, on error and on panic), and a
//! [`Stop`] flag set by Ctrl-C or SIGTERM makes every wait return an error,
//! so `main` unwinds through those drops. Waits are polled with timeouts:
//! nothing here blocks forever.

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Child, Command, ExitStatus};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::thread;
use std::time::{Duration, Instant};

use anyhow::{bail, Context};

/// How often waits check the stop flag and the children.
const POLL: Duration = Duration::from_millis(50);
/// Lines kept for [`Lines::wait_for`] beyond which output is only logged.
const LINE_QUEUE: usize = 256;

/// Set when the user asked the benchmark to stop.
#[derive(Debug, Clone, Default)]
pub struct Stop(Arc<AtomicBool>);

impl Stop {
    /// A flag set on Ctrl-C and SIGTERM (installs the process's handler:
    /// call once).
    pub fn install() -> anyhow::Result<Stop> {
        let stop = Stop::default();
        let flag = stop.0.clone();
        ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst))
            .context("installing the Ctrl-C/SIGTERM handler")?;
        Ok(stop)
    }

    /// Asks for a stop (as the signal handler does).
    pub fn request(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    /// Whether a stop was asked for.
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }

    /// An error if a stop was asked for.
    pub fn check(&self) -> anyhow::Result<()> {
        if self.requested() {
            bail!("interrupted");
        }
        Ok(())
    }

    /// Sleeps `duration`, or less and an error when a stop is asked for.
    pub fn sleep(&self, duration: Duration) -> anyhow::Result<()> {
        let end = Instant::now() + duration;
        loop {
            self.check()?;
            let left = end.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Ok(());
            }
            thread::sleep(left.min(POLL));
        }
    }
}

/// A child process killed (and reaped) when dropped.
#[derive(Debug)]
pub struct Guarded {
    name: String,
    child: Child,
    done: Option<ExitStatus>,
}

impl Guarded {
    /// Starts `command`, naming it `name` in errors.
    pub fn spawn(name: &str, command: &mut Command) -> anyhow::Result<Guarded> {
        let child = command
            .spawn()
            .with_context(|| format!("starting {name} ({command:?})"))?;
        Ok(Guarded {
            name: name.to_owned(),
            child,
            done: None,
        })
    }

    /// Its name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Its standard output, if piped and not taken yet.
    pub fn take_stdout(&mut self) -> Option<std::process::ChildStdout> {
        self.child.stdout.take()
    }

    /// Its exit status if it has exited.
    pub fn exited(&mut self) -> anyhow::Result<Option<ExitStatus>> {
        if self.done.is_none() {
            self.done = self
                .child
                .try_wait()
                .with_context(|| format!("waiting for {}", self.name))?;
        }
        Ok(self.done)
    }

    /// Waits up to `timeout` for it to exit; `None` if it is still running.
    pub fn wait_timeout(
        &mut self,
        timeout: Duration,
        stop: &Stop,
    ) -> anyhow::Result<Option<ExitStatus>> {
        let end = Instant::now() + timeout;
        loop {
            if let Some(status) = self.exited()? {
                return Ok(Some(status));
            }
            if Instant::now() >= end {
                return Ok(None);
            }
            stop.sleep(POLL)?;
        }
    }

    /// Sends SIGTERM, waits up to `grace`, then kills it. Returns whether it
    /// exited by itself.
    pub fn terminate(&mut self, grace: Duration) -> bool {
        if matches!(self.exited(), Ok(Some(_))) {
            return true;
        }
        let sent = Command::new("kill")
            .args(["-TERM", &self.pid().to_string()])
            .status()
            .is_ok_and(|s| s.success());
        if sent {
            let end = Instant::now() + grace;
            while Instant::now() < end {
                if matches!(self.exited(), Ok(Some(_))) {
                    return true;
                }
                thread::sleep(POLL);
            }
        }
        self.kill();
        false
    }

    /// Kills it (SIGKILL) unless it has exited, and reaps it.
    pub fn kill(&mut self) {
        if matches!(self.exited(), Ok(Some(_))) {
            return;
        }
        let _ = self.child.kill();
        if let Ok(status) = self.child.wait() {
            self.done = Some(status);
        }
    }
}

impl Drop for Guarded {
    fn drop(&mut self) {
        self.kill();
    }
}

/// The lines a child writes to a pipe, read by a thread that also appends
/// them to a log file (so the pipe never fills up).
#[derive(Debug)]
pub struct Lines {
    rx: mpsc::Receiver<String>,
}

impl Lines {
    /// Starts reading `pipe`, logging every line to `log`.
    pub fn spawn(pipe: impl Read + Send + 'static, log: &Path) -> anyhow::Result<Lines> {
        let mut file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(log)
            .with_context(|| format!("opening {}", log.display()))?;
        let (tx, rx) = mpsc::sync_channel(LINE_QUEUE);
        thread::Builder::new()
            .name("child-output".into())
            .spawn(move || {
                for line in BufReader::new(pipe).lines() {
                    let Ok(line) = line else { break };
                    let _ = writeln!(file, "{line}");
                    // Nobody listening, or too far behind: logged only.
                    let _ = tx.try_send(line);
                }
            })
            .context("starting an output reader thread")?;
        Ok(Lines { rx })
    }

    /// Waits up to `timeout` for a line satisfying `wanted` and returns it.
    /// Fails at the timeout, on a stop, or when the pipe closes.
    pub fn wait_for(
        &self,
        timeout: Duration,
        stop: &Stop,
        mut wanted: impl FnMut(&str) -> bool,
    ) -> anyhow::Result<String> {
        let end = Instant::now() + timeout;
        loop {
            stop.check()?;
            let left = end.saturating_duration_since(Instant::now());
            if left.is_zero() {
                bail!("timed out after {timeout:?}");
            }
            match self.rx.recv_timeout(left.min(POLL)) {
                Ok(line) if wanted(&line) => return Ok(line),
                Ok(_) | Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => bail!("the output ended"),
            }
        }
    }
}

/// A file for a child's output (created or truncated).
pub fn log_file(path: &Path) -> anyhow::Result<File> {
    File::create(path).with_context(|| format!("creating {}", path.display()))
}

/// The last `n` lines of a log file (for error messages); empty if it
/// cannot be read.
pub fn tail(path: &Path, n: usize) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::process::Stdio;

    #[test]
    fn a_dropped_child_is_killed() {
        let mut command = Command::new("sleep");
        command.arg("100");
        let child = Guarded::spawn("sleep", &mut command).unwrap();
        let pid = child.pid();
        assert!(Path::new(&format!("/proc/{pid}")).exists());
        drop(child);
        // Killed and reaped: the pid is gone (or reused by an unrelated
        // process, which is not a `sleep 100` zombie of ours).
        let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
        assert!(!stat.contains("(sleep) Z"), "{stat}");
        assert!(!stat.contains("(sleep) S"), "{stat}");
    }

    #[test]
    fn waits_time_out_and_stop_interrupts_them() {
        let stop = Stop::default();
        let mut command = Command::new("sleep");
        command.arg("100");
        let mut child = Guarded::spawn("sleep", &mut command).unwrap();
        let t = Instant::now();
        assert_eq!(
            child
                .wait_timeout(Duration::from_millis(200), &stop)
                .unwrap(),
            None
        );
        assert!(t.elapsed() >= Duration::from_millis(200));
        stop.request();
        assert!(child.wait_timeout(Duration::from_secs(100), &stop).is_err());
        assert!(stop.sleep(Duration::from_secs(100)).is_err());
        assert!(t.elapsed() < Duration::from_secs(10));
        // SIGTERM ends `sleep` at once.
        assert!(child.terminate(Duration::from_secs(5)));
    }

    #[test]
    fn lines_are_matched_logged_and_time_out() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("out.log");
        let stop = Stop::default();
        let mut command = Command::new("sh");
        command
            .args(["-c", "echo one; echo 'key: 42'; exec sleep 100"])
            .stdout(Stdio::piped());
        let mut child = Guarded::spawn("sh", &mut command).unwrap();
        let lines = Lines::spawn(child.take_stdout().unwrap(), &log).unwrap();
        let line = lines
            .wait_for(Duration::from_secs(10), &stop, |l| l.starts_with("key:"))
            .unwrap();
        assert_eq!(line, "key: 42");
        let t = Instant::now();
        let err = lines
            .wait_for(Duration::from_millis(300), &stop, |l| l == "never")
            .unwrap_err();
        assert!(err.to_string().contains("timed out"), "{err}");
        assert!(t.elapsed() < Duration::from_secs(5));
        assert_eq!(tail(&log, 1), "key: 42");
        assert_eq!(tail(&log, 5), "one\nkey: 42");
        child.kill();
        // The pipe closes with the child.
        let err = lines
            .wait_for(Duration::from_secs(10), &stop, |_| false)
            .unwrap_err();
        assert!(err.to_string().contains("ended"), "{err}");
    }
}
