//! Headless Chromium for end-to-end tests of the browser client.
//!
//! [`Browser::launch`] starts Debian's `chromium` headless (no sandbox: the
//! tests run as root; a fresh temporary profile; software WebGL through
//! SwiftShader, so no GPU is needed) and speaks the Chrome DevTools Protocol
//! to it. [`Browser::new_page`] opens a tab as a [`Page`], which loads a
//! URL ([`Page::open`]), types real key events ([`Page::press`],
//! [`Page::key_down`], [`Page::key_up`]), runs JavaScript ([`Page::eval`],
//! [`Page::wait_until`]), takes screenshots ([`Page::screenshot_png`]) and
//! keeps the page's console messages and uncaught exceptions
//! ([`Page::console`]) for a failing test to print.
//!
//! The DevTools Protocol is JSON-RPC over one WebSocket per target: each
//! command is `{"id", "method", "params"}` and gets an answer with the same
//! `id`; everything else on the socket is an event. This module speaks it
//! with `tungstenite` (blocking) and `serde_json`, for the dozen commands it
//! needs, instead of `headless_chrome` or `chromiumoxide`: both compile the
//! whole generated protocol (thousands of types), which the test build
//! cannot afford (this module adds `tungstenite` and `sha1` 0.11 with its
//! five helper crates). Everything here is blocking: from async code, call it
//! through `tokio::task::spawn_blocking` or from a plain `#[test]` whose
//! server runs on its own runtime.
//!
//! # WebTransport
//!
//! Chromium 156 here gives a page served over plain `http://127.0.0.1:PORT`
//! a secure context (`window.isSecureContext`: loopback addresses are
//! potentially trustworthy), so `WebTransport` is defined there. Such a
//! page reaches a WebTransport server at `https://127.0.0.1:PORT2/...` with
//! a self-signed ECDSA P-256 certificate valid for at most 14 days when it
//! passes the certificate's SHA-256 in `serverCertificateHashes`; no
//! Chromium flag is needed for that (no `--origin-to-force-quic-on`, no
//! `--ignore-certificate-errors-spki-list`). Checked with a throwaway echo
//! server (`wtransport` 0.7, `Identity::self_signed`: ECDSA P-256, 14
//! days): `wt.ready` resolved, and a bidirectional stream and a datagram
//! came back. That server is not kept as a test: `wtransport` would add
//! some forty crates to the test build; the browser client's end-to-end
//! test against ledge's own server covers the same path.
//!
//! Chromium has no switch that removes WebTransport (neither
//! `--disable-features=WebTransport` nor
//! `--disable-blink-features=WebTransport` does here), so
//! `webtransport: false` in [`Options`] deletes `WebTransport` from every
//! document's global object before the page's own scripts run
//! (`Page.addScriptToEvaluateOnNewDocument`), the way a browser without it
//! looks to feature detection (`typeof WebTransport === "undefined"`).
//! Workers the page starts still have it.

use std::collections::VecDeque;
use std::fmt;
use std::io::{BufRead, BufReader, ErrorKind};
use std::net::TcpStream;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use base64::Engine as _;
use serde_json::{json, Value};
use tungstenite::{Message, WebSocket};

/// How long one DevTools command may take before it counts as lost.
/// Generous: software rendering on two busy cores is slow.
const COMMAND_TIMEOUT: Duration = Duration::from_secs(60);

/// Lines of Chromium's stderr kept for error messages.
const STDERR_TAIL: usize = 40;

/// How to launch Chromium ([`Browser::launch_with`]).
#[derive(Debug, Clone)]
pub struct Options {
    /// Whether pages have `WebTransport`. When `false`, every document's
    /// `window.WebTransport` is deleted before its scripts run, to test the
    /// client's WebSocket fallback (see the [module docs](self)).
    pub webtransport: bool,
    /// The window's and every page's viewport size in CSS pixels (device
    /// scale factor 1, so screenshots have exactly this size).
    pub window_size: (u32, u32),
    /// The Chromium executable; `None` looks for `$LEDGE_CHROMIUM`, then
    /// `chromium` and `chromium-browser` on `PATH`.
    pub executable: Option<PathBuf>,
    /// More command-line switches, after ours.
    pub extra_args: Vec<String>,
    /// How long Chromium may take to print its DevTools address.
    pub launch_timeout: Duration,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            webtransport: true,
            window_size: (960, 540),
            executable: None,
            extra_args: Vec::new(),
            launch_timeout: Duration::from_secs(30),
        }
    }
}

/// The Chromium executable [`Browser::launch`] would start, if any:
/// `$LEDGE_CHROMIUM` if set, else `chromium` or `chromium-browser` on
/// `PATH`. Tests use it to decide whether they can run.
pub fn find_chromium() -> Option<PathBuf> {
    if let Some(path) = std::env::var_os("LEDGE_CHROMIUM") {
        return Some(PathBuf::from(path));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| ["chromium", "chromium-browser"].map(|name| dir.join(name)))
        .find(|candidate| candidate.is_file())
}

/// For browser tests on machines without Chromium: `true` (after a loud
/// notice on stderr) when `chromium` is missing and the test should return
/// early; panics instead when `CI=true`, where Chromium must be installed.
/// The same rule as the client's Xvfb screenshot test.
pub fn skip_without_chromium(test: &str) -> bool {
    if find_chromium().is_some() {
        return false;
    }
    if std::env::var("CI").as_deref() == Ok("true") {
        panic!("{test}: chromium is not on PATH: install it (apt-get install -y chromium) to run the browser tests in CI");
    }
    // Straight to the process's stderr: the test harness captures
    // `eprintln!`, and this notice must be seen.
    let notice = format!(
        "\n************************************************************\n\
         *  SKIPPED {test}: chromium is not on PATH.\n\
         *  Install it (apt-get install -y chromium) to run it;\n\
         *  with CI=true this test fails instead of skipping.\n\
         ************************************************************\n\n"
    );
    let _ = std::io::Write::write_all(&mut std::io::stderr(), notice.as_bytes());
    true
}

/// A headless Chromium process and its DevTools connection. Dropping it
/// kills Chromium (its whole process group) and removes its temporary
/// profile.
pub struct Browser {
    child: Child,
    profile: Option<tempfile::TempDir>,
    /// `host:port` of the DevTools server.
    devtools: String,
    connection: Mutex<Cdp>,
    stderr: Arc<Mutex<VecDeque<String>>>,
    options: Options,
}

impl fmt::Debug for Browser {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Browser")
            .field("pid", &self.child.id())
            .field("devtools", &self.devtools)
            .field("options", &self.options)
            .finish_non_exhaustive()
    }
}

impl Browser {
    /// Launches headless Chromium with the default [`Options`]
    /// (WebTransport on, 960x540).
    pub fn launch() -> Result<Self> {
        Self::launch_with(Options::default())
    }

    /// Launches headless Chromium: `--headless=new --no-sandbox`, a fresh
    /// temporary `--user-data-dir`, `--remote-debugging-port=0` (the port
    /// is read from the `DevTools listening on ws://...` line on its
    /// stderr), software WebGL (`--use-angle=swiftshader
    /// --enable-unsafe-swiftshader`: WebGL on ANGLE over SwiftShader's
    /// Vulkan; without the second switch Chromium 156 still falls back to
    /// SwiftShader but logs that the fallback is deprecated) and the window
    /// size of `options`.
    ///
    /// Fails, saying what to install or what Chromium printed, when
    /// Chromium is missing, exits, or prints no DevTools address within
    /// [`Options::launch_timeout`].
    pub fn launch_with(options: Options) -> Result<Self> {
        let executable = match options.executable.clone().or_else(find_chromium) {
            Some(path) => path,
            None => bail!(
                "chromium is not installed (not on PATH, LEDGE_CHROMIUM unset): \
                 install it with `apt-get install -y chromium`"
            ),
        };
        let profile = tempfile::Builder::new()
            .prefix("ledge-chromium-")
            .tempdir()
            .context("creating Chromium's temporary profile directory")?;
        let (width, height) = options.window_size;
        let mut command = Command::new(&executable);
        command
            .args([
                "--headless=new",
                "--no-sandbox",
                "--remote-debugging-port=0",
                "--remote-debugging-address=127.0.0.1",
                "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader",
                "--no-first-run",
                "--no-default-browser-check",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--mute-audio",
                "--hide-scrollbars",
                // A game loop in a tab that is not in front keeps running.
                "--disable-background-timer-throttling",
                "--disable-renderer-backgrounding",
                "--disable-backgrounding-occluded-windows",
            ])
            .arg(format!("--window-size={width},{height}"))
            .arg(format!("--user-data-dir={}", profile.path().display()))
            .args(&options.extra_args)
            .arg("about:blank")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            // Its own process group, so that drop kills the renderer and
            // GPU processes with it.
            .process_group(0);
        let mut child = command.spawn().map_err(|e| {
            if e.kind() == ErrorKind::NotFound {
                anyhow!(
                    "{} not found: install Chromium with `apt-get install -y chromium` \
                     (or set LEDGE_CHROMIUM to its path)",
                    executable.display()
                )
            } else {
                anyhow!("starting {}: {e}", executable.display())
            }
        })?;

        let pipe = child.stderr.take().expect("stderr is piped");
        let mut browser = Self {
            child,
            profile: Some(profile),
            devtools: String::new(),
            // Replaced below once the address is known.
            connection: Mutex::new(Cdp::placeholder()),
            stderr: Arc::new(Mutex::new(VecDeque::new())),
            options,
        };

        // Chromium's stderr: the DevTools address, then a tail for errors.
        let (address_tx, address_rx) = mpsc::channel();
        let tail = Arc::clone(&browser.stderr);
        std::thread::Builder::new()
            .name("chromium-stderr".into())
            .spawn(move || {
                for line in BufReader::new(pipe).lines() {
                    let Ok(line) = line else { break };
                    if let Some(url) = line.split("DevTools listening on ").nth(1) {
                        let _ = address_tx.send(url.trim().to_owned());
                    }
                    let mut tail = tail.lock().unwrap();
                    if tail.len() == STDERR_TAIL {
                        tail.pop_front();
                    }
                    tail.push_back(line);
                }
            })
            .context("starting the thread reading Chromium's stderr")?;
        let url = match address_rx.recv_timeout(browser.options.launch_timeout) {
            Ok(url) => url,
            Err(mpsc::RecvTimeoutError::Timeout) => bail!(
                "{} printed no `DevTools listening on ws://...` line within {:?}; its stderr:\n{}",
                executable.display(),
                browser.options.launch_timeout,
                browser.stderr_tail()
            ),
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                // Give the exit status a moment to exist.
                std::thread::sleep(Duration::from_millis(200));
                let status = browser.child.try_wait().ok().flatten();
                bail!(
                    "{} closed its stderr without a DevTools address (exit status {:?}); its stderr:\n{}",
                    executable.display(),
                    status,
                    browser.stderr_tail()
                )
            }
        };
        browser.devtools = url
            .strip_prefix("ws://")
            .and_then(|rest| rest.split('/').next())
            .with_context(|| format!("unexpected DevTools address {url:?}"))?
            .to_owned();
        let connection = Cdp::connect(&url).with_context(|| {
            format!(
                "connecting to Chromium's DevTools at {url}; its stderr:\n{}",
                browser.stderr_tail()
            )
        })?;
        browser.connection = Mutex::new(connection);
        Ok(browser)
    }

    /// Opens a new tab at `about:blank`, with its own DevTools connection,
    /// the viewport of [`Options::window_size`] and focus emulated (key
    /// events reach it as if its window were focused).
    pub fn new_page(&self) -> Result<Page> {
        let target = self
            .connection
            .lock()
            .unwrap()
            .call("Target.createTarget", json!({ "url": "about:blank" }))
            .context("opening a tab")?;
        let target_id = target["targetId"]
            .as_str()
            .context("Target.createTarget answered without a targetId")?;
        let url = format!("ws://{}/devtools/page/{target_id}", self.devtools);
        let cdp = Cdp::connect(&url).with_context(|| format!("connecting to the tab at {url}"))?;
        let mut page = Page {
            cdp,
            console: Vec::new(),
            lifecycle: Vec::new(),
            target_id: target_id.to_owned(),
        };
        let (width, height) = self.options.window_size;
        page.call("Runtime.enable", json!({}))?;
        page.call("Log.enable", json!({}))?;
        page.call("Page.enable", json!({}))?;
        page.call("Page.setLifecycleEventsEnabled", json!({ "enabled": true }))?;
        page.call(
            "Emulation.setDeviceMetricsOverride",
            json!({ "width": width, "height": height, "deviceScaleFactor": 1, "mobile": false }),
        )?;
        page.call(
            "Emulation.setFocusEmulationEnabled",
            json!({ "enabled": true }),
        )?;
        if !self.options.webtransport {
            page.call(
                "Page.addScriptToEvaluateOnNewDocument",
                json!({ "source": "delete globalThis.WebTransport;" }),
            )?;
        }
        Ok(page)
    }

    /// Chromium's process id (the leader of its process group).
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// The temporary profile directory (`--user-data-dir`), removed on drop.
    pub fn profile_dir(&self) -> &Path {
        self.profile.as_ref().expect("kept until drop").path()
    }

    /// The options it was launched with.
    pub fn options(&self) -> &Options {
        &self.options
    }

    /// The last lines Chromium wrote to stderr, for error messages.
    pub fn stderr_tail(&self) -> String {
        let tail = self.stderr.lock().unwrap();
        tail.iter().cloned().collect::<Vec<_>>().join("\n")
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        // The child is not reaped yet, so its pid (and process group id)
        // cannot have been reused: kill the whole group, then reap.
        let pgid = self.child.id() as libc::pid_t;
        // SAFETY: kill(2) with a negative pid signals that process group;
        // no memory is involved.
        unsafe {
            libc::kill(-pgid, libc::SIGKILL);
        }
        let _ = self.child.wait();
        if let Some(profile) = self.profile.take() {
            let path = profile.path().to_owned();
            if profile.close().is_err() {
                // A killed helper process may still have been writing.
                std::thread::sleep(Duration::from_millis(200));
                let _ = std::fs::remove_dir_all(path);
            }
        }
    }
}

/// A keyboard key [`Page::press`] and friends can type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    /// `ArrowLeft`.
    ArrowLeft,
    /// `ArrowRight`.
    ArrowRight,
    /// `ArrowUp`.
    ArrowUp,
    /// `ArrowDown`.
    ArrowDown,
    /// The space bar: `key` `" "`, `code` `Space`.
    Space,
    /// `Enter`.
    Enter,
    /// `Escape`.
    Escape,
    /// `Tab`.
    Tab,
    /// A letter key, `'a'..='z'` (lower case: no Shift): `key` `"z"`,
    /// `code` `KeyZ`.
    Letter(char),
}

impl Key {
    /// The DOM `key` value (`KeyboardEvent.key`).
    pub fn key(self) -> String {
        match self {
            Key::Space => " ".into(),
            Key::Letter(c) => c.to_ascii_lowercase().to_string(),
            other => other.code(),
        }
    }

    /// The DOM `code` value (`KeyboardEvent.code`).
    pub fn code(self) -> String {
        match self {
            Key::ArrowLeft => "ArrowLeft".into(),
            Key::ArrowRight => "ArrowRight".into(),
            Key::ArrowUp => "ArrowUp".into(),
            Key::ArrowDown => "ArrowDown".into(),
            Key::Space => "Space".into(),
            Key::Enter => "Enter".into(),
            Key::Escape => "Escape".into(),
            Key::Tab => "Tab".into(),
            Key::Letter(c) => format!("Key{}", c.to_ascii_uppercase()),
        }
    }

    /// The Windows virtual key code (`KeyboardEvent.keyCode`).
    pub fn key_code(self) -> u32 {
        match self {
            Key::ArrowLeft => 37,
            Key::ArrowUp => 38,
            Key::ArrowRight => 39,
            Key::ArrowDown => 40,
            Key::Space => 32,
            Key::Enter => 13,
            Key::Escape => 27,
            Key::Tab => 9,
            Key::Letter(c) => c.to_ascii_uppercase() as u32,
        }
    }

    /// The text the key types, if any.
    fn text(self) -> Option<&'static str> {
        match self {
            Key::Space => Some(" "),
            Key::Enter => Some("\r"),
            _ => None,
        }
    }

    fn check(self) -> Result<()> {
        if let Key::Letter(c) = self {
            if !c.is_ascii_alphabetic() {
                bail!("Key::Letter({c:?}): only the letters a to z have keys here");
            }
        }
        Ok(())
    }
}

/// A console message or uncaught exception of a [`Page`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConsoleMessage {
    /// `log`, `info`, `warning`, `error`, `debug`... for `console.*`
    /// calls; `exception` for uncaught exceptions and unhandled
    /// rejections; `browser-<level>` for the browser's own messages
    /// (failed loads, security errors).
    pub kind: String,
    /// The message: `console.*`'s arguments joined by spaces, or the
    /// exception with its stack.
    pub text: String,
}

impl fmt::Display for ConsoleMessage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}] {}", self.kind, self.text)
    }
}

/// A browser tab ([`Browser::new_page`]). Its methods block until Chromium
/// answers; each fails after a minute without an answer.
pub struct Page {
    cdp: Cdp,
    console: Vec<ConsoleMessage>,
    /// `Page.lifecycleEvent`s since the last navigation: (frame id,
    /// loader id, name).
    lifecycle: Vec<(String, String, String)>,
    target_id: String,
}

impl fmt::Debug for Page {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Page")
            .field("target_id", &self.target_id)
            .finish_non_exhaustive()
    }
}

impl Page {
    /// Opens `url` and waits (up to a minute) for its `load` event.
    pub fn open(&mut self, url: &str) -> Result<()> {
        self.lifecycle.clear();
        let navigated = self.call("Page.navigate", json!({ "url": url }))?;
        if let Some(error) = navigated["errorText"].as_str().filter(|e| !e.is_empty()) {
            bail!("opening {url}: {error} (is something serving that address?)");
        }
        let frame = navigated["frameId"].as_str().unwrap_or_default().to_owned();
        let Some(loader) = navigated["loaderId"].as_str().map(str::to_owned) else {
            // A same-document navigation (only the fragment changed).
            return Ok(());
        };
        let deadline = Instant::now() + COMMAND_TIMEOUT;
        loop {
            let loaded = self
                .lifecycle
                .iter()
                .any(|(f, l, name)| *f == frame && *l == loader && name == "load");
            if loaded {
                return Ok(());
            }
            if !self.pump(deadline)? {
                bail!(
                    "opening {url}: no load event within {COMMAND_TIMEOUT:?}; console:\n{}",
                    self.console_text()
                );
            }
        }
    }

    /// Presses and releases `key` ([`Page::key_down`], then
    /// [`Page::key_up`]).
    pub fn press(&mut self, key: Key) -> Result<()> {
        self.key_down(key)?;
        self.key_up(key)
    }

    /// Presses `key` (`Input.dispatchKeyEvent`, a real key event with
    /// `key`, `code` and `keyCode`): the focused element, the document and
    /// the window see `keydown` (and `keypress` for keys that type text).
    pub fn key_down(&mut self, key: Key) -> Result<()> {
        key.check()?;
        let mut params = json!({
            "type": if key.text().is_some() { "keyDown" } else { "rawKeyDown" },
            "key": key.key(),
            "code": key.code(),
            "windowsVirtualKeyCode": key.key_code(),
            "nativeVirtualKeyCode": key.key_code(),
        });
        if let Some(text) = key.text() {
            params["text"] = text.into();
            params["unmodifiedText"] = text.into();
        }
        self.call("Input.dispatchKeyEvent", params)
            .with_context(|| format!("pressing {key:?}"))?;
        Ok(())
    }

    /// Releases `key`: `keyup`.
    pub fn key_up(&mut self, key: Key) -> Result<()> {
        key.check()?;
        let params = json!({
            "type": "keyUp",
            "key": key.key(),
            "code": key.code(),
            "windowsVirtualKeyCode": key.key_code(),
            "nativeVirtualKeyCode": key.key_code(),
        });
        self.call("Input.dispatchKeyEvent", params)
            .with_context(|| format!("releasing {key:?}"))?;
        Ok(())
    }

    /// A PNG of the viewport ([`Options::window_size`] pixels).
    pub fn screenshot_png(&mut self) -> Result<Vec<u8>> {
        let shot = self.call(
            "Page.captureScreenshot",
            json!({ "format": "png", "fromSurface": true }),
        )?;
        let data = shot["data"]
            .as_str()
            .context("Page.captureScreenshot answered without data")?;
        base64::engine::general_purpose::STANDARD
            .decode(data)
            .context("Page.captureScreenshot's data is not base64")
    }

    /// Evaluates the JavaScript expression `js` in the page and returns its
    /// value as JSON (`Runtime.evaluate` with `returnByValue`; promises are
    /// awaited). `undefined` is `null`; `NaN`, `Infinity` and `-0` come as
    /// strings. Fails when `js` throws or the promise rejects, with the
    /// exception.
    pub fn eval(&mut self, js: &str) -> Result<Value> {
        let answer = self.call(
            "Runtime.evaluate",
            json!({
                "expression": js,
                "returnByValue": true,
                "awaitPromise": true,
                "userGesture": true,
            }),
        )?;
        if let Some(details) = answer.get("exceptionDetails") {
            bail!("evaluating `{js}` threw: {}", exception_text(details));
        }
        let result = &answer["result"];
        if let Some(value) = result.get("value") {
            return Ok(value.clone());
        }
        if let Some(special) = result["unserializableValue"].as_str() {
            return Ok(Value::String(special.to_owned()));
        }
        Ok(Value::Null)
    }

    /// Evaluates `js_condition` every 50 ms until its value is truthy
    /// (JavaScript's rules: not `false`, `0`, `""`, `null`, `undefined`) and
    /// returns that value; an exception counts as not yet true. Fails after
    /// `timeout` with the last value or exception and the console.
    pub fn wait_until(&mut self, js_condition: &str, timeout: Duration) -> Result<Value> {
        let deadline = Instant::now() + timeout;
        loop {
            let last = match self.eval(js_condition) {
                Ok(value) if truthy(&value) => return Ok(value),
                Ok(value) => format!("last value: {value}"),
                Err(e) => format!("last error: {e:#}"),
            };
            if Instant::now() >= deadline {
                bail!(
                    "`{js_condition}` still not true after {timeout:?} ({last}); console:\n{}",
                    self.console_text()
                );
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// The console messages and uncaught exceptions so far, oldest first
    /// (after one round trip, so that those from before the call are in).
    pub fn console(&mut self) -> &[ConsoleMessage] {
        // Best effort: a broken connection leaves what arrived before it.
        let _ = self.call("Runtime.evaluate", json!({ "expression": "0" }));
        &self.console
    }

    /// [`Page::console`] as text, one message a line (`(none)` if empty),
    /// for assertion messages.
    pub fn console_text(&mut self) -> String {
        let lines: Vec<String> = self.console().iter().map(|m| m.to_string()).collect();
        if lines.is_empty() {
            "(none)".into()
        } else {
            lines.join("\n")
        }
    }

    /// Sends a raw DevTools command to this tab and returns its result,
    /// for what the methods above do not cover.
    pub fn call(&mut self, method: &str, params: Value) -> Result<Value> {
        let result = self.cdp.call(method, params);
        self.absorb_events();
        result
    }

    /// Reads one message (until `deadline`); `false` if none came.
    fn pump(&mut self, deadline: Instant) -> Result<bool> {
        let got = self.cdp.read_one(deadline)?;
        self.absorb_events();
        Ok(got)
    }

    fn absorb_events(&mut self) {
        while let Some(event) = self.cdp.events.pop_front() {
            let params = &event["params"];
            match event["method"].as_str().unwrap_or_default() {
                "Runtime.consoleAPICalled" => {
                    let args = params["args"].as_array().map(Vec::as_slice).unwrap_or(&[]);
                    let text: Vec<String> = args.iter().map(remote_object_text).collect();
                    self.console.push(ConsoleMessage {
                        kind: params["type"].as_str().unwrap_or("log").to_owned(),
                        text: text.join(" "),
                    });
                }
                "Runtime.exceptionThrown" => self.console.push(ConsoleMessage {
                    kind: "exception".into(),
                    text: exception_text(&params["exceptionDetails"]),
                }),
                "Log.entryAdded" => {
                    let entry = &params["entry"];
                    let mut text = entry["text"].as_str().unwrap_or_default().to_owned();
                    if let Some(url) = entry["url"].as_str() {
                        text = format!("{text} ({url})");
                    }
                    self.console.push(ConsoleMessage {
                        kind: format!("browser-{}", entry["level"].as_str().unwrap_or("info")),
                        text,
                    });
                }
                "Page.lifecycleEvent" => {
                    let field = |name: &str| params[name].as_str().unwrap_or_default().to_owned();
                    self.lifecycle
                        .push((field("frameId"), field("loaderId"), field("name")));
                }
                "Inspector.targetCrashed" => self.console.push(ConsoleMessage {
                    kind: "crash".into(),
                    text: "the page's renderer crashed".into(),
                }),
                _ => {}
            }
        }
    }
}

/// JavaScript truthiness of a JSON value.
fn truthy(value: &Value) -> bool {
    match value {
        Value::Null => false,
        Value::Bool(b) => *b,
        Value::Number(n) => n.as_f64().is_some_and(|n| n != 0.0),
        Value::String(s) => !s.is_empty() && s != "NaN" && s != "-0",
        Value::Array(_) | Value::Object(_) => true,
    }
}

/// A `Runtime.RemoteObject` as `console.log` would show it (roughly).
fn remote_object_text(object: &Value) -> String {
    match object.get("value") {
        Some(Value::String(s)) => s.clone(),
        Some(value) => value.to_string(),
        None => object["unserializableValue"]
            .as_str()
            .or(object["description"].as_str())
            .or(object["type"].as_str())
            .unwrap_or("?")
            .to_owned(),
    }
}

/// A `Runtime.ExceptionDetails` as text: the exception (with its stack) or
/// the message, and where.
fn exception_text(details: &Value) -> String {
    let what = details["exception"]["description"]
        .as_str()
        .or(details["exception"]["value"].as_str())
        .or(details["text"].as_str())
        .unwrap_or("unknown exception");
    match details["url"].as_str().filter(|u| !u.is_empty()) {
        Some(url) => format!(
            "{what} (at {url}:{}:{})",
            details["lineNumber"].as_u64().unwrap_or(0) + 1,
            details["columnNumber"].as_u64().unwrap_or(0) + 1
        ),
        None => what.to_owned(),
    }
}

/// One DevTools WebSocket: commands out, answers and events in.
struct Cdp {
    socket: Option<WebSocket<TcpStream>>,
    next_id: u64,
    /// Events read while waiting for answers, for the owner to handle.
    events: VecDeque<Value>,
}

impl Cdp {
    fn placeholder() -> Self {
        Self {
            socket: None,
            next_id: 1,
            events: VecDeque::new(),
        }
    }

    fn connect(url: &str) -> Result<Self> {
        let address = url
            .strip_prefix("ws://")
            .and_then(|rest| rest.split('/').next())
            .with_context(|| format!("not a ws:// URL: {url:?}"))?;
        let stream = TcpStream::connect(address)
            .with_context(|| format!("connecting to Chromium's DevTools at {address}"))?;
        stream
            .set_read_timeout(Some(COMMAND_TIMEOUT))
            .context("setting the DevTools socket's read timeout")?;
        let (socket, _response) = tungstenite::client(url, stream)
            .map_err(|e| anyhow!("WebSocket handshake with {url}: {e}"))?;
        Ok(Self {
            socket: Some(socket),
            next_id: 1,
            events: VecDeque::new(),
        })
    }

    fn socket(&mut self) -> Result<&mut WebSocket<TcpStream>> {
        self.socket
            .as_mut()
            .context("no DevTools connection (Chromium did not start)")
    }

    /// Sends `method` and reads until its answer, keeping the events that
    /// come first.
    fn call(&mut self, method: &str, params: Value) -> Result<Value> {
        let id = self.next_id;
        self.next_id += 1;
        let request = json!({ "id": id, "method": method, "params": params });
        self.socket()?
            .send(Message::text(request.to_string()))
            .with_context(|| format!("sending {method} to Chromium (did it exit?)"))?;
        let deadline = Instant::now() + COMMAND_TIMEOUT;
        loop {
            let Some(mut message) = self.read(deadline)? else {
                bail!("{method}: no answer from Chromium within {COMMAND_TIMEOUT:?}");
            };
            if message["id"].as_u64() == Some(id) {
                if let Some(error) = message.get("error") {
                    bail!("{method} failed: {error}");
                }
                return Ok(message["result"].take());
            }
            if message.get("method").is_some() {
                self.events.push_back(message);
            }
        }
    }

    /// Reads one message into `events` (answers to nothing are dropped);
    /// `false` if none came before `deadline`.
    fn read_one(&mut self, deadline: Instant) -> Result<bool> {
        match self.read(deadline)? {
            Some(message) => {
                if message.get("method").is_some() {
                    self.events.push_back(message);
                }
                Ok(true)
            }
            None => Ok(false),
        }
    }

    /// The next JSON message, or `None` at `deadline`.
    fn read(&mut self, deadline: Instant) -> Result<Option<Value>> {
        let socket = self.socket()?;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Ok(None);
            }
            socket
                .get_mut()
                .set_read_timeout(Some(left))
                .context("setting the DevTools socket's read timeout")?;
            let text = match socket.read() {
                Ok(Message::Text(text)) => text.as_str().to_owned(),
                Ok(Message::Binary(bytes)) => String::from_utf8_lossy(&bytes).into_owned(),
                Ok(Message::Close(_)) => bail!("Chromium closed the DevTools connection"),
                Ok(_) => continue,
                Err(tungstenite::Error::Io(e))
                    if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) =>
                {
                    continue
                }
                Err(e) => return Err(e).context("reading from Chromium's DevTools (did it exit?)"),
            };
            let message = serde_json::from_str(&text).with_context(|| {
                format!("Chromium sent something that is not JSON: {text:.200}")
            })?;
            return Ok(Some(message));
        }
    }
}

/// Builds the page into `web/dist` with `scripts/build-web` (a no-op when
/// it is up to date: CI builds it before the tests) and returns that
/// directory; fails the test, with the script's output, if it does not
/// build.
pub fn build_web() -> PathBuf {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = Command::new("bash")
        .arg(root.join("scripts/build-web"))
        .current_dir(&root)
        .output()
        .expect("run scripts/build-web");
    assert!(
        out.status.success(),
        "scripts/build-web failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    root.join("web/dist")
}
