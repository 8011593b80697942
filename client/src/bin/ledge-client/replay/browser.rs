//! The page's `?replay=ID` (`wasm32-unknown-unknown`): the replay fetched
//! from the server that served the page (`/replays/ID`, at most
//! [`MAX_FILE_BYTES`]), decoded, its level found (the embedded default
//! level, else the same server's `/levels/HEX`: at most the offered size,
//! itself at most [`MAX_LEVEL_BUNDLE`], its SHA-256 checked), then played
//! in the replay's window ([`window::watch`]: the same keys, HUD and
//! following as natively).
//!
//! The address's options: `follow=NAME`, `speed=X` (the nearest of the
//! viewer's speeds), `seek=SECS` (seconds into the replay, as its HUD
//! counts them). While it loads, the canvas says what it fetches; what
//! stops it opening (no such replay: the server's words; a damaged file:
//! the replay's own error; a level the server does not have; an option
//! that does not fit) is drawn on the canvas and published as
//! `window.ledgeState.replay.error`.

use ledge_client::net::download::{embedded, Download};
use ledge_levels::LevelBundle;
use ledge_shared::protocol::{LevelOffer, MAX_LEVEL_BUNDLE};
use ledge_shared::replay::{self, Replay};
use macroquad::prelude::*;

use crate::draw::hud;
use crate::draw::render::palette;
use crate::input::keys::Bindings;
use crate::outcome::tell;
use crate::page::{self, host, param, Fetch, Fetched};
use crate::replay::advice::advice;
use crate::replay::open::{self, is_id, Opening, Refused, MAX_FILE_BYTES};
use crate::replay::window::{self, PageReplay, Watch};

/// Plays the replay `id` (the address's `replay=`) in the page's canvas.
pub fn main(id: String) {
    let conf = macroquad::window::Conf {
        window_title: "ledge replay".to_owned(),
        window_width: 960,
        window_height: 540,
        window_resizable: true,
        ..Default::default()
    };
    macroquad::Window::from_config(conf, play(id));
}

/// Opens the replay, then watches it; or shows why it did not open.
async fn play(id: String) {
    match open_replay(&id).await {
        Ok(watch) => window::watch(watch).await,
        Err(message) => {
            tell(&message);
            page::report_replay_opening(&id, None, Some(&message));
            loop {
                clear_background(palette::SKY);
                hud::failure(&message);
                next_frame().await;
            }
        }
    }
}

/// The address's options, read and checked before anything is fetched.
struct Asked {
    follow: Option<String>,
    speed: Option<f32>,
    /// Seconds into the replay.
    seek: Option<f64>,
}

impl Asked {
    /// `follow=`, `speed=`, `seek=`; what is wrong with them, in words.
    fn read() -> Result<Asked, String> {
        let number = |name: &str, what: &str, example: &str| -> Result<Option<f64>, String> {
            let Some(text) = param(name).filter(|t| !t.is_empty()) else {
                return Ok(None);
            };
            match text.trim().parse::<f64>() {
                Ok(v) if v.is_finite() && v >= 0.0 => Ok(Some(v)),
                _ => Err(format!(
                    "{name}={text}: give {what}, e.g. {name}={example} (or leave it out)"
                )),
            }
        };
        let speed = number("speed", "the speed to play at (0.25 to 4)", "2")?;
        if speed == Some(0.0) {
            return Err("speed=0: give the speed to play at (0.25 to 4), e.g. speed=2".into());
        }
        Ok(Asked {
            follow: param("follow").filter(|f| !f.is_empty()),
            speed: speed.map(|s| s as f32),
            seek: number(
                "seek",
                "the seconds into the replay to open at (as its HUD counts them)",
                "12.5",
            )?,
        })
    }
}

/// Everything before the window: the options, the replay, its level, the
/// viewer opened as asked.
async fn open_replay(id: &str) -> Result<Watch, String> {
    let asked = Asked::read()?;
    if !is_id(id) {
        return Err(format!(
            "replay={id}: a replay is named by {} hex digits (the server's records page, \
             /records, links each run's replay)",
            open::ID_DIGITS
        ));
    }
    let id = id.to_ascii_lowercase();
    let url = format!("http://{}/replays/{id}", host());
    let bytes = fetch(
        &id,
        "replay",
        &format!("/replays/{id}"),
        MAX_FILE_BYTES as u32,
        "check its ID, or ask the server's operator whether it still keeps it",
    )
    .await?;
    let replay = replay::decode(&bytes)
        .map_err(|e| format!("{url} is not a replay ledge can play: {e}: {}", advice(&e)))?;
    let opening = opening(&asked, &replay)?;
    let (level, level_from) = level(&id, &replay).await?;
    let viewer =
        open::viewer(&level.level, replay, &opening).map_err(|refused| refusal(&url, refused))?;
    Ok(Watch {
        viewer,
        level: level.level,
        level_art: level.art,
        bindings: Bindings::default(),
        source: url,
        exit_after: None,
        page: PageReplay { id, level_from },
        debug: param("debug").is_some(),
        hud: param("nohud").is_none(),
        volume: 0.8,
        mute: false,
    })
}

/// The viewer's opening from the address's options (`seek` in seconds
/// from the replay's start).
fn opening(asked: &Asked, replay: &Replay) -> Result<Opening, String> {
    let rate = f64::from(replay.header.tick_rate.max(1));
    let seek = match asked.seek {
        None => None,
        Some(secs) => {
            let length = replay.ticks() as f64 / rate;
            if secs > length {
                return Err(format!(
                    "seek={secs}: the replay is {length:.2} s long: give seek=0 to seek={}",
                    length.floor()
                ));
            }
            Some(replay.start_tick() + ((secs * rate).round() as u64).min(replay.ticks()))
        }
    };
    Ok(Opening {
        follow: asked.follow.clone(),
        seek,
        speed: asked.speed,
    })
}

/// What `refused` means for the page's options.
fn refusal(url: &str, refused: Refused) -> String {
    match refused {
        Refused::NoSuchPlayer { name, players } => format!(
            "follow={name}: nobody of that name plays in the replay (its players: {})",
            players.join(", ")
        ),
        Refused::SeekOutside { tick, start, end } => {
            format!("seek: tick {tick} is not in the replay (ticks {start} to {end})")
        }
        Refused::NotPlayed(e) => format!("the replay {url} {e}: {}", advice(&e)),
    }
}

/// The replay's level: the embedded default level, else the server's
/// `/levels/HEX`, checked against the header's offer; and where it came
/// from ("embedded", or the URL).
async fn level(id: &str, replay: &Replay) -> Result<(LevelBundle, String), String> {
    let header = &replay.header;
    let offer: LevelOffer = header.level;
    if offer == embedded().1 {
        return Ok((embedded().0.clone(), "embedded".to_owned()));
    }
    let named = format!(
        "the replay's level \"{}\" (bundle sha256 {}, {} bytes)",
        header.level_name,
        offer.hex(),
        offer.size
    );
    if offer.size > MAX_LEVEL_BUNDLE {
        return Err(format!(
            "{named} is more than any level ledge downloads ({MAX_LEVEL_BUNDLE} bytes): it \
             cannot be played"
        ));
    }
    let path = format!("/levels/{}", offer.hex());
    let bytes = fetch(
        id,
        "level",
        &path,
        offer.size as u32,
        "the server no longer plays the replay's level: watch it with ledge-client --replay \
         and --level FILE",
    )
    .await?;
    let url = format!("http://{}{path}", host());
    let refused = |e: ledge_client::ClientError| {
        format!("{named} from {url}: {e}: reload the page to try again")
    };
    let mut download = Download::new(offer, Vec::new()).map_err(refused)?;
    download.push(&bytes).map_err(refused)?;
    let (bundle, _) = download.finish().map_err(refused)?;
    Ok((bundle, url))
}

/// The body of `path` on the page's server (at most `max` bytes), frames
/// drawn saying what loads meanwhile; or why not, in words (`what`: the
/// thing fetched; `not_found`: what to do about a 404).
async fn fetch(
    id: &str,
    what: &str,
    path: &str,
    max: u32,
    not_found: &str,
) -> Result<Vec<u8>, String> {
    let url = format!("http://{}{path}", host());
    let mut fetching = Fetch::start(path, max);
    let shown = format!("loading the {what} ({url})");
    loop {
        if let Some(done) = fetching.poll() {
            return fetched(&url, what, not_found, done);
        }
        page::report_replay_opening(id, Some(what), None);
        clear_background(palette::SKY);
        hud::banner(&shown);
        next_frame().await;
    }
}

/// The bytes of a finished fetch, or why there are none (the server's
/// own words after the status).
fn fetched(url: &str, what: &str, not_found: &str, done: Fetched) -> Result<Vec<u8>, String> {
    let said = |status: &str, text: &str| {
        if text.is_empty() {
            status.to_owned()
        } else {
            format!("{status}: {text}")
        }
    };
    match done {
        Fetched::Body(bytes) => Ok(bytes),
        Fetched::Status {
            status: 404, text, ..
        } => Err(format!(
            "{url}: the server has no such {what} ({}): {not_found}",
            said("404 Not Found", &text)
        )),
        Fetched::Status {
            status: 429,
            retry_after,
            ..
        } => Err(format!(
            "{url}: the server refuses more requests from this address for now (429 Too Many \
             Requests): reload the page in {}",
            retry_after.map_or_else(|| "a little while".to_owned(), |s| format!("{s} s"))
        )),
        Fetched::Status { status, text, .. } => Err(format!(
            "{url}: the server answered {} instead of the {what}: reload the page later",
            said(&status.to_string(), &text)
        )),
        Fetched::Failed(why) => Err(format!("{url}: cannot fetch the {what}: {why}")),
    }
}
