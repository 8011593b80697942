//! A throwaway PostgreSQL cluster for one test: [`Postgres::start`] makes a
//! cluster in a temporary directory (`initdb`), runs its server on a free
//! TCP port of 127.0.0.1 with password authentication, creates a database
//! named after the test and gives its URL; dropping it stops the server and
//! removes the directory. [`Postgres::stop`] and [`Postgres::restart`] take
//! the database away and bring it back on the same port, with its data, for
//! tests of a server whose records database fails.
//!
//! The binaries are Debian's (`/usr/lib/postgresql/VERSION/bin`, the newest
//! version; `$LEDGE_POSTGRES_BIN` names another directory). Without them a
//! test is skipped with a loud notice, except under `CI=true`, where it
//! fails saying what to install (.ci/run installs `postgresql`).
//!
//! # Not as root
//!
//! PostgreSQL refuses to run as root, and the tests run as root here and in
//! CI. Run as root, the cluster belongs to the `postgres` system user (made
//! by Debian's package): the directory is handed to it, and `initdb` and
//! the server are started as it (the child drops to its uid and gid before
//! `exec`: [`std::os::unix::process::CommandExt::uid`], which also clears
//! root's supplementary groups). No `sudo`, `su` or `runuser` is needed.
//! Run as anyone else, the cluster is that user's.
//!
//! # Nothing left behind
//!
//! The server is the test process's own child (`postgres -D DIR`, not
//! daemonised by `pg_ctl`), in a process group of its own (a signal to the
//! test's group does not reach it), waited for by a thread that lives as
//! long as it. When that thread ends without stopping it (the test process
//! was killed, e.g. by nextest's timeout), the kernel sends the server
//! SIGQUIT (`PR_SET_PDEATHSIG`): an immediate shutdown, which ends its
//! backends and removes its shared memory. A directory left by a killed
//! test (`ledge-pg-PID-*` in the temporary directory, PID no longer
//! running) is removed by the next [`Postgres::start`].

use std::fs;
use std::io::{self, Read};
use std::net::{Ipv4Addr, SocketAddr, TcpListener};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Output, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// How long the server may take to accept connections after it starts.
const READY_TIMEOUT: Duration = Duration::from_secs(60);
/// How long a fast shutdown may take before it is made immediate.
const STOP_TIMEOUT: Duration = Duration::from_secs(30);
/// The cluster's superuser (the tests' role).
const ROLE: &str = "ledge";
/// What the temporary directories are called: `ledge-pg-PID-...`.
const DIR_PREFIX: &str = "ledge-pg-";
/// Lines of the server's log shown when it fails.
const LOG_TAIL: usize = 30;

/// A running throwaway PostgreSQL cluster (see the [module docs](self)).
pub struct Postgres {
    bin: PathBuf,
    /// The OS user the cluster runs as: `(uid, gid)`, `None`: ours.
    owner: Option<(u32, u32)>,
    port: u16,
    password: String,
    database: String,
    url: String,
    postmaster: Option<Postmaster>,
    /// Last: removed after the server stopped.
    dir: tempfile::TempDir,
}

impl std::fmt::Debug for Postgres {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Postgres")
            .field("dir", &self.dir.path())
            .field("port", &self.port)
            .field("database", &self.database)
            .field("pid", &self.postmaster.as_ref().map(|p| p.pid))
            .finish_non_exhaustive()
    }
}

/// The server process, waited for by its own thread.
struct Postmaster {
    pid: u32,
    exited: mpsc::Receiver<io::Result<ExitStatus>>,
}

/// The directory of Debian's PostgreSQL binaries (the newest version), or
/// `$LEDGE_POSTGRES_BIN` when set; `None` when it has no `initdb` and
/// `postgres`.
pub fn find_bin() -> Option<PathBuf> {
    let usable = |bin: &Path| bin.join("initdb").is_file() && bin.join("postgres").is_file();
    if let Some(dir) = std::env::var_os("LEDGE_POSTGRES_BIN") {
        return Some(PathBuf::from(dir)).filter(|bin| usable(bin));
    }
    let mut found: Vec<(Vec<u32>, PathBuf)> = fs::read_dir("/usr/lib/postgresql")
        .ok()?
        .flatten()
        .filter_map(|entry| {
            let version = entry.file_name().to_str()?.to_owned();
            let key = version
                .split('.')
                .map(|part| part.parse().ok())
                .collect::<Option<Vec<u32>>>()?;
            let bin = entry.path().join("bin");
            usable(&bin).then_some((key, bin))
        })
        .collect();
    found.sort();
    found.pop().map(|(_, bin)| bin)
}

impl Postgres {
    /// Starts a cluster for the test `test` (its name also names the
    /// database). `None`, after a loud notice, when PostgreSQL is not
    /// installed, or run as root without a `postgres` user; under
    /// `CI=true` that panics instead. Panics, with the server's log, when
    /// the cluster cannot be made or started. Blocks (about a second).
    pub fn start(test: &str) -> Option<Postgres> {
        let usable = find_bin()
            .ok_or_else(|| {
                "PostgreSQL is not installed (no initdb and postgres in \
                 /usr/lib/postgresql/*/bin, or in $LEDGE_POSTGRES_BIN if set)"
                    .to_owned()
            })
            .and_then(|bin| Ok((bin, cluster_owner()?)));
        let (bin, owner) = match usable {
            Ok(found) => found,
            Err(why) => {
                if std::env::var("CI").as_deref() == Ok("true") {
                    panic!("{test}: {why}: install it (apt-get install -y postgresql) to run the PostgreSQL tests in CI");
                }
                let notice = format!(
                    "\n************************************************************\n\
                     *  SKIPPED {test}: {why}.\n\
                     *  Install it (apt-get install -y postgresql) to run it;\n\
                     *  with CI=true this test fails instead of skipping.\n\
                     ************************************************************\n\n"
                );
                // Straight to the process's stderr: the harness captures
                // `eprintln!`, and this notice must be seen.
                let _ = io::Write::write_all(&mut io::stderr(), notice.as_bytes());
                return None;
            }
        };
        sweep_stale_dirs();
        Some(Postgres::make(bin, owner, test))
    }

    /// `initdb`, the server on a free port, the test's database.
    fn make(bin: PathBuf, owner: Option<(u32, u32)>, test: &str) -> Postgres {
        let dir = tempfile::Builder::new()
            .prefix(&format!("{DIR_PREFIX}{}-", std::process::id()))
            .tempdir()
            .expect("a temporary directory for the cluster");
        let password = random_hex(16);
        let database = database_name(test);
        let mut pg = Postgres {
            bin,
            owner,
            port: 0,
            url: String::new(),
            password,
            database,
            postmaster: None,
            dir,
        };
        pg.hand_over(pg.dir.path());
        pg.initdb();
        // A free port may be taken by someone else before the server binds
        // it: then another one.
        for attempt in 1..=5 {
            pg.port = free_port();
            match pg.launch() {
                Ok(()) => break,
                Err(log) if attempt < 5 && log.contains("could not bind") => continue,
                Err(log) => panic!("PostgreSQL did not start on port {}:\n{log}", pg.port),
            }
        }
        pg.url = format!(
            "postgres://{ROLE}:{}@127.0.0.1:{}/{}",
            pg.password, pg.port, pg.database
        );
        pg.client("createdb").arg(&pg.database).run("createdb");
        pg
    }

    /// The test database's URL (`postgres://ledge:PASSWORD@127.0.0.1:PORT/DB`).
    pub fn url(&self) -> &str {
        &self.url
    }

    /// The role's password (random; in [`Postgres::url`]).
    pub fn password(&self) -> &str {
        &self.password
    }

    /// The server's TCP port.
    pub fn port(&self) -> u16 {
        self.port
    }

    /// Whether the server is running.
    pub fn is_running(&self) -> bool {
        self.postmaster.is_some()
    }

    /// Takes the database away: a fast shutdown (every session is ended,
    /// new connections are refused), waited for. Blocks; call it through
    /// `tokio::task::block_in_place` from a test's runtime.
    pub fn stop(&mut self) {
        let Some(postmaster) = self.postmaster.take() else {
            return;
        };
        if let Err(e) = postmaster.stop(libc::SIGINT, STOP_TIMEOUT) {
            panic!("PostgreSQL did not stop: {e}\n{}", self.log_tail());
        }
    }

    /// Brings the database back after [`Postgres::stop`]: the same data on
    /// the same port (so the same URL). Blocks, as `stop`.
    pub fn restart(&mut self) {
        assert!(self.postmaster.is_none(), "PostgreSQL is running");
        if let Err(log) = self.launch() {
            panic!(
                "PostgreSQL did not start again on port {}:\n{log}",
                self.port
            );
        }
    }

    fn data_dir(&self) -> PathBuf {
        self.dir.path().join("data")
    }

    fn log_file(&self) -> PathBuf {
        self.dir.path().join("postgres.log")
    }

    /// The end of the server's log.
    pub fn log_tail(&self) -> String {
        let text = fs::read_to_string(self.log_file()).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        lines[lines.len().saturating_sub(LOG_TAIL)..].join("\n")
    }

    /// Gives `path` to the cluster's owner.
    fn hand_over(&self, path: &Path) {
        if let Some((uid, gid)) = self.owner {
            std::os::unix::fs::chown(path, Some(uid), Some(gid))
                .unwrap_or_else(|e| panic!("chown {}: {e}", path.display()));
        }
    }

    /// A server-side command (`initdb`, `postgres`), run as the owner in
    /// the cluster's directory.
    fn server_command(&self, program: &str) -> Command {
        let mut command = Command::new(self.bin.join(program));
        command.current_dir(self.dir.path()).env("LC_ALL", "C");
        without_pg_env(&mut command);
        if let Some((uid, gid)) = self.owner {
            command.uid(uid).gid(gid);
        }
        command
    }

    /// A client program (`createdb`, `pg_isready`) aimed at the server.
    fn client(&self, program: &str) -> Command {
        let mut command = Command::new(self.bin.join(program));
        without_pg_env(&mut command);
        command
            .current_dir(self.dir.path())
            .env("PGPASSWORD", &self.password)
            .args(["-h", "127.0.0.1", "-p", &self.port.to_string(), "-U", ROLE]);
        command
    }

    fn initdb(&self) {
        let pwfile = self.dir.path().join("password");
        fs::write(&pwfile, &self.password).expect("the password file is written");
        self.hand_over(&pwfile);
        self.server_command("initdb")
            .arg("-D")
            .arg(self.data_dir())
            .arg(format!("--pwfile={}", pwfile.display()))
            .args([
                "--username",
                ROLE,
                "--auth=scram-sha-256",
                "--encoding=UTF8",
                "--locale=C",
                "--no-sync",
                "--no-instructions",
            ])
            .run("initdb");
        let _ = fs::remove_file(pwfile);
    }

    /// Starts the server and waits until it accepts connections; the log's
    /// tail when it does not.
    fn launch(&mut self) -> Result<(), String> {
        let log = fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(self.log_file())
            .expect("the server's log file opens");
        let mut command = self.server_command("postgres");
        command
            .arg("-D")
            .arg(self.data_dir())
            .args(["-p", &self.port.to_string()])
            .args(["-c", "listen_addresses=127.0.0.1"])
            // No Unix socket: TCP only, as a fleet's servers reach it.
            .args(["-c", "unix_socket_directories="])
            // A test's data need not survive a crash of the machine.
            .args(["-c", "fsync=off", "-c", "full_page_writes=off"])
            .stdin(Stdio::null())
            .stdout(log.try_clone().expect("the log file's handle"))
            .stderr(log)
            .process_group(0);
        // SAFETY: only async-signal-safe calls between fork and exec.
        unsafe {
            command.pre_exec(|| {
                // Our waiting thread ends: immediate shutdown.
                if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGQUIT) != 0 {
                    return Err(io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let postmaster = Postmaster::spawn(command)
            .map_err(|e| format!("{}: {e}", self.bin.join("postgres").display()))?;
        let deadline = Instant::now() + READY_TIMEOUT;
        loop {
            if let Ok(status) = postmaster.exited.try_recv() {
                return Err(format!(
                    "the server exited ({}):\n{}",
                    describe_status(status),
                    self.log_tail()
                ));
            }
            let ready = self
                .client("pg_isready")
                .args(["-d", "postgres", "-t", "1"])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
                .is_ok_and(|s| s.success());
            if ready {
                self.postmaster = Some(postmaster);
                return Ok(());
            }
            if Instant::now() > deadline {
                let _ = postmaster.stop(libc::SIGQUIT, STOP_TIMEOUT);
                return Err(format!(
                    "not accepting connections after {READY_TIMEOUT:?}:\n{}",
                    self.log_tail()
                ));
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Postgres {
    fn drop(&mut self) {
        // Immediate shutdown: nothing of it is kept. The directory goes
        // after (the field's own drop).
        if let Some(postmaster) = self.postmaster.take() {
            if let Err(e) = postmaster.stop(libc::SIGQUIT, STOP_TIMEOUT) {
                eprintln!("the test's PostgreSQL did not stop: {e}");
            }
        }
    }
}

impl Postmaster {
    /// Spawns `command` from a thread that then waits for it (the thread
    /// its parent-death signal is tied to).
    fn spawn(mut command: Command) -> io::Result<Postmaster> {
        let (started, pid) = mpsc::channel();
        let (ended, exited) = mpsc::channel();
        std::thread::Builder::new()
            .name("postgres".into())
            .spawn(move || match command.spawn() {
                Ok(mut child) => {
                    let _ = started.send(Ok(child.id()));
                    let _ = ended.send(child.wait());
                }
                Err(e) => {
                    let _ = started.send(Err(e));
                }
            })?;
        let pid = pid
            .recv()
            .map_err(|_| io::Error::other("the waiting thread ended"))??;
        Ok(Postmaster { pid, exited })
    }

    /// Sends `signal` and waits up to `within` for the server to exit;
    /// then kills its whole process group.
    fn stop(self, signal: libc::c_int, within: Duration) -> Result<(), String> {
        let pid = self.pid as libc::pid_t;
        // SAFETY: a signal to our own child, which its thread has not
        // reaped yet (it is reaped only after it exits).
        unsafe { libc::kill(pid, signal) };
        match self.exited.recv_timeout(within) {
            Ok(_) => Ok(()),
            Err(_) => {
                // SAFETY: its process group (it leads it), as above.
                unsafe { libc::kill(-pid, libc::SIGKILL) };
                let _ = self.exited.recv_timeout(within);
                Err(format!(
                    "still running {within:?} after signal {signal}: killed"
                ))
            }
        }
    }
}

trait RunChecked {
    /// Runs to the end; panics with its output unless it succeeds.
    fn run(&mut self, what: &str) -> Output;
}

impl RunChecked for Command {
    fn run(&mut self, what: &str) -> Output {
        let output = self
            .stdin(Stdio::null())
            .output()
            .unwrap_or_else(|e| panic!("{what} did not start: {e}"));
        assert!(
            output.status.success(),
            "{what} failed ({}):\n{}{}",
            describe_status(Ok(output.status)),
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        );
        output
    }
}

fn describe_status(status: io::Result<ExitStatus>) -> String {
    match status {
        Ok(s) => match (s.code(), s.signal()) {
            (Some(code), _) => format!("exit code {code}"),
            (None, Some(signal)) => format!("signal {signal}"),
            _ => s.to_string(),
        },
        Err(e) => e.to_string(),
    }
}

/// Leaves out the environment's `PG*` variables (a `PGHOST` or
/// `PGSSLMODE` of the machine's would aim the tools elsewhere).
fn without_pg_env(command: &mut Command) {
    for (key, _) in std::env::vars_os() {
        if key.to_str().is_some_and(|k| k.starts_with("PG")) {
            command.env_remove(key);
        }
    }
}

/// Who the cluster runs as: `None` (ourselves) unless we are root, then
/// the `postgres` user.
fn cluster_owner() -> Result<Option<(u32, u32)>, String> {
    // SAFETY: no arguments, no failure.
    if unsafe { libc::geteuid() } != 0 {
        return Ok(None);
    }
    user_ids("postgres").map(Some).ok_or_else(|| {
        "running as root, and PostgreSQL refuses to; there is no `postgres` user to run it as \
         (Debian's postgresql package makes it)"
            .to_owned()
    })
}

/// `name`'s uid and gid, from the user database.
fn user_ids(name: &str) -> Option<(u32, u32)> {
    let name = std::ffi::CString::new(name).ok()?;
    let mut buf = vec![0 as libc::c_char; 16 * 1024];
    // SAFETY: `passwd` is plain data; getpwnam_r fills it with pointers
    // into `buf`, which outlives its use here.
    unsafe {
        let mut pwd: libc::passwd = std::mem::zeroed();
        let mut result = std::ptr::null_mut();
        let rc = libc::getpwnam_r(
            name.as_ptr(),
            &mut pwd,
            buf.as_mut_ptr(),
            buf.len(),
            &mut result,
        );
        (rc == 0 && !result.is_null()).then_some((pwd.pw_uid, pwd.pw_gid))
    }
}

/// A TCP port of 127.0.0.1 free a moment ago.
fn free_port() -> u16 {
    TcpListener::bind(SocketAddr::from((Ipv4Addr::LOCALHOST, 0)))
        .and_then(|l| l.local_addr())
        .expect("a free port on 127.0.0.1")
        .port()
}

/// `bytes` random bytes, in hex.
fn random_hex(bytes: usize) -> String {
    let mut raw = vec![0u8; bytes];
    fs::File::open("/dev/urandom")
        .and_then(|mut f| f.read_exact(&mut raw))
        .expect("/dev/urandom reads");
    raw.iter().map(|b| format!("{b:02x}")).collect()
}

/// A database name from a test's name: lowercase letters, digits and
/// underscores, at most 63 bytes (PostgreSQL's limit).
fn database_name(test: &str) -> String {
    let mut name: String = test
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if !name.starts_with(|c: char| c.is_ascii_lowercase()) {
        name.insert_str(0, "t_");
    }
    name.truncate(63);
    name
}

/// Removes the directories of clusters whose test process is gone (killed
/// before its drop ran), unless their server still runs.
fn sweep_stale_dirs() {
    let Ok(entries) = fs::read_dir(std::env::temp_dir()) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|n| n.strip_prefix(DIR_PREFIX))
            .and_then(|rest| rest.split('-').next())
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        let path = entry.path();
        let server_pid = fs::read_to_string(path.join("data/postmaster.pid"))
            .ok()
            .and_then(|text| text.lines().next()?.trim().parse::<u32>().ok());
        let alive = |pid: u32| Path::new(&format!("/proc/{pid}")).exists();
        if alive(pid) || server_pid.is_some_and(alive) {
            continue;
        }
        // Only directories: a file of that name is not ours.
        if entry.file_type().is_ok_and(|t| t.is_dir()) {
            let _ = fs::set_permissions(&path, fs::Permissions::from_mode(0o700));
            let _ = fs::remove_dir_all(&path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn database_names_are_plain_and_short() {
        assert_eq!(
            database_name("records_postgres::two_servers"),
            "records_postgres__two_servers"
        );
        assert_eq!(database_name("9lives"), "t_9lives");
        assert_eq!(database_name(&"x".repeat(100)).len(), 63);
    }
}
