//! The browser page's glue (`wasm32-unknown-unknown`): the imports of
//! `web/ledge.js` (a miniquad plugin) and what the game makes of them: the
//! address's parameters, the page's host, its gamepads, its connection to
//! the server ([`WebNet`]: WebTransport, or a WebSocket where the browser
//! has no WebTransport), files fetched from that server ([`Fetch`]: a
//! replay and its level), and the game's state reported to the page.
//!
//! Below the game: [`crate::web`], the browser's entry point, and the
//! game loop call it; it calls nothing of theirs.

use std::collections::BTreeMap;

use ledge_client::net::page_session::{PageSession, Transmit};
use ledge_client::net::{NetEvent, Network};
use ledge_client::netstats::TransportSample;
use ledge_client::time::Instant;
use ledge_client::JoinOptions;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{web, PlayerId};

use crate::input::pad::PadState;
use crate::outcome::tell;

/// The glue's version: `web/ledge.js` says the same, and miniquad's loader
/// compares them (`ledge_crate_version`) so a stale page says so.
const GLUE_VERSION: u32 = 2;

/// Longest address parameter read (a player name is at most 32 bytes).
const MAX_PARAM: usize = 256;

extern "C" {
    /// Writes the address's parameter `name` (decoded, UTF-8) into `out`
    /// (at most `cap` bytes); returns its length, or -1 if absent.
    fn ledge_page_param(name: *const u8, name_len: u32, out: *mut u8, cap: u32) -> i32;
    /// Publishes the game's state (JSON) as `window.ledgeState`, for the
    /// page and for tests.
    fn ledge_report(json: *const u8, len: u32);
    /// Writes the page's `HOST:PORT` into `out` (at most `cap` bytes);
    /// returns its length.
    fn ledge_page_host(out: *mut u8, cap: u32) -> u32;
    /// The page's gamepads (standard mapping) into `out`, 12 bytes each:
    /// the pressed buttons as a bit set (bit i: `buttons[i]`, u32 LE),
    /// then the left stick's x and y (f32 LE, y down); returns the bytes
    /// written.
    fn ledge_gamepads(out: *mut u8, cap: u32) -> u32;
    /// Starts connecting to the server that served the page.
    fn ledge_net_open();
    /// The next message from the connection (tag byte, payload) into
    /// `out`; its length, or -1 if none.
    fn ledge_net_poll(out: *mut u8, cap: u32) -> i32;
    /// Sends on the control stream (`kind` 0) or as a datagram (1);
    /// 0 if dropped.
    fn ledge_net_send(kind: u32, bytes: *const u8, len: u32) -> u32;
    /// Starts fetching `path` from the server that served the page, a
    /// body of at most `max` bytes (more is refused, unread); returns the
    /// fetch's handle.
    fn ledge_fetch_start(path: *const u8, path_len: u32, max: u32) -> u32;
    /// Fetch `handle`'s outcome: -1 while it runs; else 0, with three
    /// u32 LE written to `info`: the HTTP status (0: no answer, and the
    /// body says why), the body's length (an error's text: at most
    /// [`MAX_FETCH_TEXT`]), the answer's `Retry-After` seconds
    /// (`u32::MAX` if none).
    fn ledge_fetch_poll(handle: u32, info: *mut u8) -> i32;
    /// Copies the finished fetch's body into `out` (at most `cap` bytes)
    /// and forgets the fetch; returns the bytes copied.
    fn ledge_fetch_take(handle: u32, out: *mut u8, cap: u32) -> u32;
}

/// Longest error text (an HTTP error's body, or why there was no answer)
/// a fetch keeps (`web/ledge.js` cuts longer ones).
pub const MAX_FETCH_TEXT: u32 = 4096;

/// A file being fetched from the server that served the page, its body
/// bounded (the glue refuses a larger one before or while reading it, and
/// the bound is checked again here before anything is allocated).
#[derive(Debug)]
pub struct Fetch {
    handle: u32,
    max: u32,
}

/// How a fetch ended.
#[derive(Debug)]
pub enum Fetched {
    /// 200 OK: the body.
    Body(Vec<u8>),
    /// Another HTTP status, with the server's text (cut to
    /// [`MAX_FETCH_TEXT`] bytes) and its `Retry-After` seconds.
    Status {
        /// The HTTP status.
        status: u16,
        /// The server's text, trimmed.
        text: String,
        /// `Retry-After`, seconds.
        retry_after: Option<u32>,
    },
    /// No answer, or one refused: why.
    Failed(String),
}

impl Fetch {
    /// Starts fetching `path` (absolute, on the page's server): a body of
    /// at most `max` bytes.
    pub fn start(path: &str, max: u32) -> Fetch {
        let len = u32::try_from(path.len()).unwrap_or(0);
        // SAFETY: a valid buffer and its length.
        let handle = unsafe { ledge_fetch_start(path.as_ptr(), len, max) };
        Fetch { handle, max }
    }

    /// How it ended, once it has (then the fetch is forgotten).
    pub fn poll(&mut self) -> Option<Fetched> {
        let mut info = [0u8; 12];
        // SAFETY: `info` is valid for the 12 bytes the glue writes.
        if unsafe { ledge_fetch_poll(self.handle, info.as_mut_ptr()) } < 0 {
            return None;
        }
        let word =
            |at: usize| u32::from_le_bytes([info[at], info[at + 1], info[at + 2], info[at + 3]]);
        let (status, len, retry) = (word(0), word(4), word(8));
        let cap = if status == 200 {
            self.max
        } else {
            MAX_FETCH_TEXT
        };
        if len > cap {
            // SAFETY: nothing is written with a capacity of 0.
            unsafe { ledge_fetch_take(self.handle, std::ptr::null_mut(), 0) };
            return Some(Fetched::Failed(format!(
                "the answer is {len} bytes, more than it can be ({cap} bytes): refused"
            )));
        }
        let mut body = vec![0u8; len as usize];
        // SAFETY: `body` is valid for its length; the glue writes at most that.
        let n = unsafe { ledge_fetch_take(self.handle, body.as_mut_ptr(), len) };
        body.truncate(n.min(len) as usize);
        let text = || String::from_utf8_lossy(&body).trim().to_owned();
        Some(match status {
            200 => Fetched::Body(body),
            0 => Fetched::Failed(text()),
            _ => Fetched::Status {
                status: u16::try_from(status).unwrap_or(u16::MAX),
                text: text(),
                retry_after: (retry != u32::MAX).then_some(retry),
            },
        })
    }
}

/// Message tags from the glue (`web/ledge.js`) besides the WebSocket
/// framing's ([`web::Tag`]): the connection's own news.
mod tag {
    pub const OPENED: u8 = 0xF0;
    pub const CLOSED: u8 = 0xF1;
    pub const FAILED: u8 = 0xF2;
}

/// Largest message taken from the glue at once (longer stream and level
/// chunks come split; a snapshot datagram is far smaller).
const POLL_BUFFER: usize = 64 * 1024;

/// The page's connection as a [`Network`]: the glue's messages fed to a
/// [`PageSession`] (the session's protocol), its transmits handed to the glue.
#[derive(Debug)]
pub struct WebNet {
    session: PageSession,
    buf: Vec<u8>,
    /// "WebTransport" or "WebSocket", once open.
    transport: Option<String>,
}

impl WebNet {
    /// Starts connecting, to join as `options` say.
    pub fn open(options: JoinOptions) -> WebNet {
        // SAFETY: an import without arguments.
        unsafe { ledge_net_open() };
        WebNet {
            session: PageSession::new(options),
            buf: vec![0; POLL_BUFFER],
            transport: None,
        }
    }

    /// The transport's name, once open.
    pub fn transport_name(&self) -> Option<&str> {
        self.transport.as_deref()
    }

    /// Feeds the glue's messages to the session; pings when due.
    fn pump(&mut self) {
        let now = Instant::now();
        loop {
            // SAFETY: `buf` is valid for its length; the glue writes at
            // most that many bytes.
            let n = unsafe { ledge_net_poll(self.buf.as_mut_ptr(), self.buf.len() as u32) };
            let Ok(n) = usize::try_from(n) else { break };
            let message = &self.buf[..n.min(self.buf.len())];
            let Some((&t, payload)) = message.split_first() else {
                continue;
            };
            match t {
                tag::OPENED => {
                    self.transport = Some(String::from_utf8_lossy(payload).into_owned());
                    self.session.on_open(now);
                }
                tag::CLOSED => {
                    let code = payload
                        .get(..4)
                        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                        .filter(|&c| c != u32::MAX);
                    let reason = String::from_utf8_lossy(payload.get(4..).unwrap_or(&[]));
                    self.session.on_closed(code, &reason);
                }
                tag::FAILED => self.session.on_failed(&String::from_utf8_lossy(payload)),
                // The session's own messages, in the WebSocket framing.
                _ => match web::decode(message) {
                    Ok(m) => self.session.on_message(m, now),
                    Err(e) => tell(&format!("the page's glue sent a bad message: {e}")),
                },
            }
        }
        self.session.poll(now);
        self.flush();
    }

    /// Hands the session's transmits to the glue.
    fn flush(&mut self) {
        while let Some(t) = self.session.poll_transmit() {
            let (kind, bytes) = match &t {
                Transmit::Stream(b) => (web::Tag::Stream as u32, b),
                Transmit::Datagram(b) => (web::Tag::Datagram as u32, b),
            };
            // SAFETY: a valid buffer and its length.
            unsafe { ledge_net_send(kind, bytes.as_ptr(), bytes.len() as u32) };
        }
    }
}

impl Network for WebNet {
    fn try_recv(&mut self) -> Option<NetEvent> {
        if let Some(event) = self.session.try_recv() {
            return Some(event);
        }
        self.pump();
        self.session.try_recv()
    }

    fn send_input(&mut self, tick: u64, buttons: Buttons) -> bool {
        let sent = self.session.send_input(tick, buttons);
        self.flush();
        sent
    }

    fn chat(&mut self, text: &str) -> bool {
        let sent = self.session.chat(text);
        self.flush();
        sent
    }

    fn vote(&mut self, level: u32) -> bool {
        let sent = self.session.vote(level);
        self.flush();
        sent
    }

    fn transport(&self) -> Option<TransportSample> {
        self.session.transport()
    }

    fn players(&self) -> BTreeMap<PlayerId, String> {
        self.session.players()
    }
}

/// Tells the loader which glue this build expects.
#[no_mangle]
pub extern "C" fn ledge_crate_version() -> u32 {
    GLUE_VERSION
}

/// The address's parameter `name`, if present (cut to [`MAX_PARAM`]
/// bytes, invalid UTF-8 replaced).
pub fn param(name: &str) -> Option<String> {
    let mut out = vec![0u8; MAX_PARAM];
    let len = u32::try_from(name.len()).ok()?;
    // SAFETY: both buffers are valid for the lengths given; the glue
    // writes at most `cap` bytes.
    let n = unsafe { ledge_page_param(name.as_ptr(), len, out.as_mut_ptr(), MAX_PARAM as u32) };
    let n = usize::try_from(n).ok()?.min(MAX_PARAM);
    out.truncate(n);
    Some(String::from_utf8_lossy(&out).into_owned())
}

/// Gamepads read at most.
const MAX_PADS: usize = 4;

/// The page's gamepads now (the Gamepad API's standard mapping: buttons
/// 0 south, 1 east, 8 select, 12 to 15 the d-pad up, down, left, right).
pub fn gamepads() -> Vec<PadState> {
    let mut out = [0u8; 12 * MAX_PADS];
    // SAFETY: `out` is valid for its length; the glue writes at most that.
    let n = unsafe { ledge_gamepads(out.as_mut_ptr(), out.len() as u32) } as usize;
    out[..n.min(out.len())]
        .chunks_exact(12)
        .map(|pad| {
            let word = |at: usize| [pad[at], pad[at + 1], pad[at + 2], pad[at + 3]];
            let bits = u32::from_le_bytes(word(0));
            let held = |i: u32| bits & (1 << i) != 0;
            let x = f32::from_le_bytes(word(4));
            let y = f32::from_le_bytes(word(8));
            let finite = |v: f32| if v.is_finite() { v } else { 0.0 };
            PadState {
                south: held(0),
                east: held(1),
                select: held(8),
                up: held(12),
                down: held(13),
                left: held(14),
                right: held(15),
                // The Gamepad API's y points down; ledge's up.
                stick: (finite(x), -finite(y)),
            }
        })
        .collect()
}

/// The page's `HOST:PORT` (the server that served it).
pub fn host() -> String {
    let mut out = vec![0u8; MAX_PARAM];
    // SAFETY: `out` is valid for its length; the glue writes at most that.
    let n = unsafe { ledge_page_host(out.as_mut_ptr(), MAX_PARAM as u32) } as usize;
    out.truncate(n.min(MAX_PARAM));
    String::from_utf8_lossy(&out).into_owned()
}

/// What a frame showed, for the page (and tests).
pub struct Report<'a> {
    /// Ticks played.
    pub played: u64,
    /// The status line.
    pub status: &'a str,
    /// The failure shown, if any.
    pub failure: Option<&'a str>,
    /// Whether we are in a game (offline, or welcomed with the level).
    pub joined: bool,
    /// Our player's centre, units (the predicted game's).
    pub me: Option<glam::IVec2>,
    /// The players drawn (ours first, if drawn).
    pub players: Vec<DrawnPlayer>,
    /// We watch rather than play (`?spectate`).
    pub spectating: bool,
    /// The server's level, once welcomed: its id (the name the server
    /// gives it) and how many times the room moved to another level since
    /// we joined.
    pub level: Option<(&'a str, u64)>,
}

/// A player as drawn this frame: its box on the canvas and its colour.
pub struct DrawnPlayer {
    /// Its id.
    pub id: u32,
    /// Its name label (ours: our name).
    pub name: String,
    /// Ours.
    pub local: bool,
    /// Its box's top left corner and size, canvas pixels.
    pub screen: [f32; 4],
    /// Its centre as drawn, world pixels.
    pub world: [f32; 2],
    /// Its body colour, RGB 0..=255.
    pub rgb: [u8; 3],
}

/// A replay's state on the page (`window.ledgeState.replay`).
pub struct ReplayState<'a> {
    /// The replay's id.
    pub id: &'a str,
    /// Its level's name.
    pub level: &'a str,
    /// Where the level came from: "embedded", or the URL it was
    /// downloaded from.
    pub level_from: &'a str,
    /// The game's tick shown.
    pub tick: u64,
    /// The replay's first and last game ticks.
    pub start_tick: u64,
    /// Its last.
    pub end_tick: u64,
    /// Where it opened (a run's start, or the replay's).
    pub home: u64,
    /// The speed (1: as played).
    pub speed: f32,
    /// Paused by the viewer.
    pub paused: bool,
    /// At its end (or where it failed).
    pub at_end: bool,
    /// The followed player's name.
    pub following: Option<&'a str>,
    /// The followed player's centre at `tick`, units (the replay's game).
    pub follow_pos: Option<glam::IVec2>,
    /// The camera is free.
    pub free_camera: bool,
    /// The HUD's clock line.
    pub clock: &'a str,
    /// Why it stopped playing, if it did.
    pub error: Option<&'a str>,
}

/// World pixels of `units`.
fn px(units: i32) -> f64 {
    f64::from(units) / f64::from(UNITS_PER_PX)
}

/// Publishes `report` as `window.ledgeState` (a few times a second is
/// plenty; every frame is cheap too).
pub fn report(r: &Report<'_>) {
    publish(&state(r));
}

/// Publishes a replay's frame: `report`, and `replay` as its `replay`.
pub fn report_replay(r: &Report<'_>, replay: &ReplayState<'_>) {
    let mut json = state(r);
    json["replay"] = serde_json::json!({
        "id": replay.id,
        "level": { "name": replay.level, "from": replay.level_from },
        "tick": replay.tick,
        "start_tick": replay.start_tick,
        "end_tick": replay.end_tick,
        "ticks": replay.end_tick.saturating_sub(replay.start_tick),
        "home": replay.home,
        "speed": replay.speed,
        "paused": replay.paused,
        "at_end": replay.at_end,
        "following": replay.following,
        "follow_pos": replay.follow_pos.map(|p| [px(p.x), px(p.y)]),
        "free_camera": replay.free_camera,
        "clock": replay.clock,
        "error": replay.error,
    });
    publish(&json);
}

/// Publishes a replay not playing yet: what is `loading` ("replay",
/// "level"), or the `error` that stopped it opening.
pub fn report_replay_opening(id: &str, loading: Option<&str>, error: Option<&str>) {
    publish(&serde_json::json!({
        "played": 0,
        "status": loading.map_or("", |_| "loading the replay"),
        "failure": error,
        "joined": false,
        "spectating": false,
        "me": null,
        "players": [],
        "replay": { "id": id, "loading": loading, "error": error },
    }));
}

/// `json` as `window.ledgeState`.
fn publish(json: &serde_json::Value) {
    let json = json.to_string();
    // SAFETY: a valid buffer and its length.
    unsafe { ledge_report(json.as_ptr(), json.len() as u32) };
}

/// The page's state of a frame.
fn state(r: &Report<'_>) -> serde_json::Value {
    let players: Vec<serde_json::Value> = r
        .players
        .iter()
        .map(|p| {
            serde_json::json!({
                "id": p.id, "name": p.name, "local": p.local,
                "screen": p.screen, "world": p.world, "rgb": p.rgb,
            })
        })
        .collect();
    serde_json::json!({
        "played": r.played,
        "status": r.status,
        "failure": r.failure,
        "joined": r.joined,
        "spectating": r.spectating,
        "level": r.level.map(|(id, changes)| serde_json::json!({"id": id, "changes": changes})),
        "me": r.me.map(|p| serde_json::json!({"x": px(p.x), "y": px(p.y)})),
        "players": players,
        // The level's flat colours, for tests of what the canvas shows.
        "palette": {
            "sky": crate::draw::render::palette::bytes(crate::draw::render::palette::SKY),
            "solid": crate::draw::render::palette::bytes(crate::draw::render::palette::SOLID),
            "grass": crate::draw::render::palette::bytes(crate::draw::render::palette::GRASS),
        },
    })
}
