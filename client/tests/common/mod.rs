//! Helpers shared by the client's integration tests that run a real binary
//! against a real server in-process on loopback.
#![allow(dead_code)] // Each test file uses its own subset.

use std::net::SocketAddr;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use ledge_client::Fingerprint;
use ledge_server::{Server, ServerConfig, ShutdownHandle};

/// A real server on loopback, in-process, on its own runtime, for one test.
pub struct TestServer {
    pub addr: SocketAddr,
    /// The web port, when configured (`ServerConfig::web`).
    pub web_addr: Option<SocketAddr>,
    pub fingerprint: Fingerprint,
    shutdown: ShutdownHandle,
    runtime: tokio::runtime::Runtime,
    task: tokio::task::JoinHandle<Result<(), ledge_server::ServerError>>,
    /// The certificate directory: the server's state, its records
    /// database included (`records.sqlite`, unless configured otherwise).
    certs: tempfile::TempDir,
}

impl TestServer {
    /// Starts a server with the default settings and a temporary
    /// certificate directory.
    pub fn start() -> TestServer {
        TestServer::start_with(|_| {})
    }

    /// Starts a server on loopback with a temporary certificate directory
    /// and the settings `configure` makes.
    pub fn start_with(configure: impl FnOnce(&mut ServerConfig)) -> TestServer {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()
            .unwrap();
        let certs = tempfile::tempdir().unwrap();
        let mut config = ServerConfig {
            bind: SocketAddr::from(([127, 0, 0, 1], 0)),
            cert_dir: certs.path().to_owned(),
            ..ServerConfig::default()
        };
        configure(&mut config);
        let (addr, web_addr, fingerprint, shutdown, task) = runtime.block_on(async {
            let server = Server::bind(config).expect("server binds");
            (
                server.local_addr(),
                server.web_addr(),
                server.fingerprint(),
                server.shutdown_handle(),
                tokio::spawn(server.run()),
            )
        });
        TestServer {
            addr,
            web_addr,
            fingerprint,
            shutdown,
            runtime,
            task,
            certs,
        }
    }

    /// Starts a server rotating through [`two_levels`] (written into
    /// `dir`) in one room, with votes by majority and a second between a
    /// decision and the change.
    pub fn rotating(dir: &std::path::Path) -> TestServer {
        TestServer::rotating_with(dir, ledge_shared::protocol::VoteRule::Majority)
    }

    /// [`TestServer::rotating`] with votes counted by `vote`.
    pub fn rotating_with(
        dir: &std::path::Path,
        vote: ledge_shared::protocol::VoteRule,
    ) -> TestServer {
        let levels = two_levels(dir);
        TestServer::start_with(move |c| {
            c.levels = levels;
            c.rooms = 1;
            c.rotation = ledge_server::config::RotationConfig {
                level_time: None,
                results_time: Duration::from_secs(1),
                vote,
            };
        })
    }

    /// Runs `name`, a runner bot, along the default level's route to the
    /// goal (it leaves once its run is recorded, or after 40 s) and
    /// returns its report.
    pub fn runner_to_goal(&self, name: &str) -> ledge_client::bot::BotReport {
        use ledge_client::bot::{connect_and_run, BotOptions, Brain, Runner};
        let mut runner = Runner::new(ledge_levels::default_route());
        let options = BotOptions {
            stop_when_done: true,
            ..BotOptions::new(name, Duration::from_secs(40))
        };
        self.block_on(connect_and_run(
            &self.addr.to_string(),
            &ledge_client::Trust::Pinned(self.fingerprint),
            &mut runner as &mut dyn Brain,
            &options,
        ))
    }

    /// The server's certificate directory, where its records are by
    /// default ([`ledge_server::records::RecordsTarget::in_state_dir`]).
    pub fn cert_dir(&self) -> &std::path::Path {
        self.certs.path()
    }

    /// Runs `future` on the server's runtime (e.g. a session of a player
    /// of the test's own).
    pub fn block_on<F: std::future::Future>(&self, future: F) -> F::Output {
        self.runtime.block_on(future)
    }

    /// Shuts the server down and waits (bounded) for it.
    pub fn stop(self) {
        self.shutdown.shutdown();
        let task = self.task;
        self.runtime.block_on(async {
            let _ = tokio::time::timeout(Duration::from_secs(5), task).await;
        });
    }
}

/// The default level's files, and a copy of the level named `second`, in
/// `dir`: a rotation of two levels (the same ground, another bundle to
/// download).
pub fn two_levels(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    ledge_levels::write_default_copies(dir, &["default", "second"]).unwrap()
}

/// Runs `command` to its end with piped output; kills it and fails the test
/// (showing its stderr) if it has not exited within `timeout`. When the
/// command is `xvfb-run` and it fails itself ("xvfb-run: error: ...", e.g.
/// its temporary directory not removed when two run at once: exit 5 in
/// place of the client's own code), the run is repeated, up to three times.
pub fn run_to_end(mut command: Command, timeout: Duration) -> Output {
    for attempt in 1.. {
        let out = run_once(&mut command, timeout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        match stderr.lines().find(|l| l.starts_with("xvfb-run: error:")) {
            Some(line) if attempt < 3 => {
                eprintln!("run_to_end: {line} (attempt {attempt}); running it again");
            }
            _ => return out,
        }
    }
    unreachable!("the loop returns")
}

fn run_once(command: &mut Command, timeout: Duration) -> Output {
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let deadline = Instant::now() + timeout;
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            let out = child.wait_with_output().unwrap();
            panic!(
                "the binary did not exit within {timeout:?}; stderr:\n{}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// `xvfb-run` on `PATH`, if any (the screenshot tests run the window
/// under it).
pub fn xvfb_run() -> Option<std::path::PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join("xvfb-run"))
        .find(|p| p.is_file())
}

/// `xvfb-run` on `PATH`; without it, `None` after a loud notice that the
/// test named `what` was skipped, or a failed test when `CI=true`.
pub fn xvfb_or_skip(what: &str) -> Option<std::path::PathBuf> {
    let found = xvfb_run();
    if found.is_none() {
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("xvfb-run is not on PATH: install xvfb (apt-get install xvfb xauth) to run {what} in CI");
        }
        // Straight to the process's stderr: the test harness captures
        // `eprintln!`, and this notice must be seen.
        let notice = format!(
            "\n*** SKIPPED {what}: xvfb-run is not on PATH (apt-get install xvfb xauth); \
             with CI=true this test fails instead ***\n\n"
        );
        let _ = std::io::Write::write_all(&mut std::io::stderr(), notice.as_bytes());
    }
    found
}

/// Where a screenshot test saves its pictures: `$LEDGE_SCREENSHOT_DIR`
/// (created; kept after the test, to look at them), else `tmp`.
pub fn screenshot_dir(tmp: &std::path::Path) -> std::path::PathBuf {
    let dir = std::env::var_os("LEDGE_SCREENSHOT_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| tmp.to_owned());
    std::fs::create_dir_all(&dir).expect("the screenshot folder can be created");
    dir
}

/// A JSON `[x, y]` pair.
pub fn pair(v: &serde_json::Value) -> (f64, f64) {
    let a = v.as_array().expect("[x, y]");
    (a[0].as_f64().unwrap(), a[1].as_f64().unwrap())
}

/// An RGBA picture.
pub struct Png {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl Png {
    /// Loads a PNG of any colour type as RGBA.
    pub fn load(path: &std::path::Path) -> Png {
        let file = std::fs::File::open(path).expect("the PNG exists");
        let mut decoder = png::Decoder::new(file);
        decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = decoder.read_info().expect("a PNG");
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).expect("PNG data");
        buf.truncate(info.buffer_size());
        let rgba = match info.color_type {
            png::ColorType::Rgba => buf,
            png::ColorType::Rgb => buf
                .chunks(3)
                .flat_map(|c| [c[0], c[1], c[2], 255])
                .collect(),
            png::ColorType::GrayscaleAlpha => buf
                .chunks(2)
                .flat_map(|c| [c[0], c[0], c[0], c[1]])
                .collect(),
            png::ColorType::Grayscale => buf.iter().flat_map(|&g| [g, g, g, 255]).collect(),
            other => panic!("unexpected PNG colour type {other:?}"),
        };
        Png {
            width: info.width,
            height: info.height,
            rgba,
        }
    }

    /// The pixel at `(x, y)`, which must lie inside.
    pub fn at(&self, x: u32, y: u32) -> [u8; 4] {
        assert!(x < self.width && y < self.height, "({x}, {y}) outside");
        let i = (y as usize * self.width as usize + x as usize) * 4;
        [
            self.rgba[i],
            self.rgba[i + 1],
            self.rgba[i + 2],
            self.rgba[i + 3],
        ]
    }

    /// The RGB of the pixel under the point `(x, y)`; `None` outside.
    pub fn rgb_at(&self, x: f64, y: f64) -> Option<[u8; 3]> {
        let (x, y) = (x.floor(), y.floor());
        if x < 0.0 || y < 0.0 || x >= self.width as f64 || y >= self.height as f64 {
            return None;
        }
        let [r, g, b, _] = self.at(x as u32, y as u32);
        Some([r, g, b])
    }
}

/// The client binary `bin` (the test's `env!("CARGO_BIN_EXE_ledge-client")`)
/// under `xvfb` (a 1280x720 virtual screen), with a 960x540 window, drawn
/// in software, taking a screenshot to `png` after `ticks` ticks of play:
/// add the arguments of the game to play.
pub fn client_under_xvfb(
    xvfb: &std::path::Path,
    bin: &str,
    ticks: u64,
    png: &std::path::Path,
) -> Command {
    let mut command = Command::new(xvfb);
    command
        .args(["-a", "-s", "-screen 0 1280x720x24"])
        .arg(bin)
        .args(["--exit-after-ticks", &ticks.to_string()])
        .arg("--screenshot")
        .arg(png)
        .args(["--window", "960x540"])
        .env("LIBGL_ALWAYS_SOFTWARE", "1");
    command
}

/// The run replay of `name` saved in the replays folder of a server whose
/// certificate directory is `cert_dir` (written shortly after the run is
/// recorded, by another task: waited for, up to 10 s), and its id (the
/// file's name, as the records keep it).
pub fn run_replay(
    cert_dir: &std::path::Path,
    name: &str,
) -> (String, ledge_shared::replay::Replay) {
    use ledge_shared::replay::{self, ReplayKind};
    let dir = cert_dir.join("replays");
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            let Ok(bytes) = std::fs::read(entry.path()) else {
                continue;
            };
            let Ok(replay) = replay::decode(&bytes) else {
                continue;
            };
            if let ReplayKind::Run { player, .. } = replay.header.kind {
                if replay.name_of(player) == Some(name) {
                    let path = entry.path();
                    let id = path.file_stem().unwrap_or_default().to_string_lossy();
                    return (id.into_owned(), replay);
                }
            }
        }
        assert!(
            Instant::now() < deadline,
            "no run replay of {name} in {}",
            dir.display()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}
