//! The browser entry (`wasm32-unknown-unknown`): the options come from the
//! page's address (`?name=ada`), the window is the page's canvas, and the
//! page's glue (`web/ledge.js`, a miniquad plugin) gives the clock, the
//! address's parameters and a place to report the game's state.
//!
//! This build plays the embedded default level offline; joining a server
//! from the browser (WebTransport, WebSocket) comes next (issue 18).

use std::time::Duration;

use ledge_shared::fixed::UNITS_PER_PX;

use crate::keys::Bindings;
use crate::{game, play, tell, Setup};

/// The glue's version: `web/ledge.js` says the same, and miniquad's loader
/// compares them (`ledge_crate_version`) so a stale page says so.
const GLUE_VERSION: u32 = 1;

/// Longest address parameter read (a player name is at most 32 bytes).
const MAX_PARAM: usize = 256;

extern "C" {
    /// Writes the address's parameter `name` (decoded, UTF-8) into `out`
    /// (at most `cap` bytes); returns its length, or -1 if absent.
    fn ledge_page_param(name: *const u8, name_len: u32, out: *mut u8, cap: u32) -> i32;
    /// Publishes the game's state (JSON) as `window.ledgeState`, for the
    /// page and for tests.
    fn ledge_report(json: *const u8, len: u32);
}

/// Tells the loader which glue this build expects.
#[no_mangle]
pub extern "C" fn ledge_crate_version() -> u32 {
    GLUE_VERSION
}

/// The address's parameter `name`, if present (cut to [`MAX_PARAM`]
/// bytes, invalid UTF-8 replaced).
fn param(name: &str) -> Option<String> {
    let mut out = vec![0u8; MAX_PARAM];
    let len = u32::try_from(name.len()).ok()?;
    // SAFETY: both buffers are valid for the lengths given; the glue
    // writes at most `cap` bytes.
    let n = unsafe { ledge_page_param(name.as_ptr(), len, out.as_mut_ptr(), MAX_PARAM as u32) };
    let n = usize::try_from(n).ok()?.min(MAX_PARAM);
    out.truncate(n);
    Some(String::from_utf8_lossy(&out).into_owned())
}

/// The player name from `?name=`, when the server would accept it.
fn name() -> String {
    match param("name") {
        Some(name) if ledge_shared::protocol::check_name(&name).is_ok() => name,
        Some(name) => {
            tell(&format!(
                "the name {name:?} is not allowed (1 to 32 bytes, no control characters): \
                 playing as \"player\""
            ));
            "player".to_owned()
        }
        None => "player".to_owned(),
    }
}

/// Starts the game in the page's canvas.
pub fn main() {
    let name = name();
    let level = ledge_levels::default_level();
    let play = match play::Play::offline(level, &name) {
        Ok(play) => play,
        Err(e) => {
            tell(&format!("cannot start the game: {e:#}"));
            return;
        }
    };
    let setup = Setup {
        play,
        bindings: Bindings::default(),
        script: None,
        exit_after: None,
        screenshot: None,
        join_timeout: Duration::from_secs(20),
        name,
        debug: param("debug").is_some(),
        net: param("net").is_some(),
        hud: param("nohud").is_none(),
        volume: 0.8,
        mute: false,
        look_at: None,
        level_art: Default::default(),
    };
    let conf = macroquad::window::Conf {
        window_title: "ledge".to_owned(),
        window_width: 960,
        window_height: 540,
        window_resizable: true,
        ..Default::default()
    };
    macroquad::Window::from_config(conf, game(setup));
}

/// What a frame showed, for the page (and tests).
pub struct Report<'a> {
    /// Ticks played.
    pub played: u64,
    /// The status line.
    pub status: &'a str,
    /// The failure shown, if any.
    pub failure: Option<&'a str>,
    /// Our player's centre, units (the predicted game's).
    pub me: Option<glam::IVec2>,
}

/// Publishes `report` as `window.ledgeState` (a few times a second is
/// plenty; every frame is cheap too).
pub fn report(r: &Report<'_>) {
    let px = |v: i32| f64::from(v) / f64::from(UNITS_PER_PX);
    let json = serde_json::json!({
        "played": r.played,
        "status": r.status,
        "failure": r.failure,
        "me": r.me.map(|p| serde_json::json!({"x": px(p.x), "y": px(p.y)})),
    })
    .to_string();
    // SAFETY: a valid buffer and its length.
    unsafe { ledge_report(json.as_ptr(), json.len() as u32) };
}
