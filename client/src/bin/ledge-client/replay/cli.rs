//! `ledge-client --replay FILE|URL`: a replay played with the game's own
//! renderer, or checked without a window (`--check`).
//!
//! Opening it, in order: where it comes from ([`source`]: a file, or
//! `http://HOST:PORT/replays/ID` over [`crate::replay::http`]), its bytes
//! read within the largest replay, decoded
//! ([`ledge_shared::replay::decode`]: damaged, cut short, newer files
//! refused with their reason), then its level found ([`level`]). Then
//! [`check`](mod@check) plays it to its end, or [`window`] shows it
//! ([`ledge_client::replay::ReplayViewer`] under the viewer's keys, opened
//! as the options say: [`open`](mod@open)). Every failure says what went
//! wrong and what to do ([`advice`]); exit codes: 0 played (or checked) to
//! the end, 1 it does not play (its level not found, it plays differently
//! from the server, the window could not start), 2 the replay cannot be
//! read.

use std::path::PathBuf;
use std::sync::atomic::Ordering;

use ledge_client::net::bundle::LevelCache;
use ledge_levels::LevelBundle;
use ledge_shared::replay::{self, Replay, ReplayKind};

use crate::input::keys::Bindings;
use crate::outcome::{tell, EXIT_CODE, EXIT_FAILED, EXIT_UNREADABLE};
use crate::replay::open::{self, Opening, Refused};
use crate::replay::{advice, check, level, source, window};

/// The command line's replay options, and those of the window it uses.
pub struct ReplayArgs {
    /// `--replay FILE|URL`.
    pub replay: String,
    /// `--check`: play it to the end without a window.
    pub check: bool,
    /// `--replay-seek TICK`: open at this game tick.
    pub seek: Option<u64>,
    /// `--follow NAME`.
    pub follow: Option<String>,
    /// `--replay-speed X`.
    pub speed: Option<f32>,
    /// `--level FILE`, `--level-settings FILE`, `--level-cache DIR`.
    pub level: Option<PathBuf>,
    /// The level's settings file.
    pub level_settings: Option<PathBuf>,
    /// The level cache's folder (default: the client's).
    pub level_cache: Option<PathBuf>,
    /// Esc, F1, F2, M.
    pub bindings: Bindings,
    /// `--exit-after-ticks`.
    pub exit_after: Option<u64>,
    /// `--screenshot`.
    pub screenshot: Option<PathBuf>,
    /// `--debug`.
    pub debug: bool,
    /// Not `--no-hud`.
    pub hud: bool,
    /// 0..=1.
    pub volume: f32,
    /// `--mute`.
    pub mute: bool,
    /// `--window`.
    pub window: (i32, i32),
}

/// A failure to tell, and the exit code it ends with.
struct Failure {
    code: i32,
    error: anyhow::Error,
}

/// `code` for failures of `result`.
fn or_exit<T>(code: i32, result: anyhow::Result<T>) -> Result<T, Failure> {
    result.map_err(|error| Failure { code, error })
}

/// A replay read and its level found.
struct Opened {
    source: source::Source,
    replay: Replay,
    level: LevelBundle,
}

/// Plays (or checks) the replay `args` names; returns the exit code.
pub fn run(args: ReplayArgs) -> i32 {
    let result = open(&args).and_then(|opened| {
        if args.check {
            check(opened)
        } else {
            show(opened, args)
        }
    });
    match result {
        Ok(code) => code,
        Err(Failure { code, error }) => {
            tell(&format!("{error:#}"));
            code
        }
    }
}

/// Reads the replay and finds its level.
fn open(args: &ReplayArgs) -> Result<Opened, Failure> {
    let source = or_exit(EXIT_UNREADABLE, source::Source::parse(&args.replay))?;
    let bytes = or_exit(EXIT_UNREADABLE, source.read())?;
    let replay = replay::decode(&bytes).map_err(|e| Failure {
        code: EXIT_UNREADABLE,
        error: anyhow::anyhow!(
            "{} is not a replay ledge can play: {e}: {}",
            source.describe(),
            advice::advice(&e)
        ),
    })?;
    let cache = args
        .level_cache
        .clone()
        .or_else(LevelCache::default_dir)
        .map(LevelCache::new);
    let search = level::LevelSearch {
        file: args.level.as_deref(),
        settings: args.level_settings.as_deref(),
        cache,
        server: source.server(),
    };
    let found = or_exit(EXIT_FAILED, level::find(&replay.header, &search))?;
    let h = &replay.header;
    let kind = match h.kind {
        ReplayKind::Match => "a match".to_owned(),
        ReplayKind::Run { player, .. } => format!(
            "{}'s run",
            replay.name_of(player).unwrap_or("an unnamed player")
        ),
    };
    let about = format!(
        "replay {}: {kind} in room {} on level {} ({} ticks), the level from {}",
        source.describe(),
        h.room,
        h.level_name,
        replay.ticks(),
        found.from
    );
    // `--check`'s output is its one line.
    if args.check {
        tracing::debug!("{about}");
    } else {
        tracing::info!("{about}");
    }
    Ok(Opened {
        source,
        replay,
        level: found.bundle,
    })
}

/// `--check`: the line on stdout, or the failure.
fn check(opened: Opened) -> Result<i32, Failure> {
    let described = opened.source.describe();
    match check::check(&opened.level.level, opened.replay) {
        Ok(checked) => {
            println!("{}", checked.line());
            Ok(0)
        }
        Err(e) => Err(Failure {
            code: EXIT_FAILED,
            error: anyhow::anyhow!("the replay {described} {e}: {}", advice::advice(&e)),
        }),
    }
}

/// The replay in the window, opened where the options say.
fn show(opened: Opened, args: ReplayArgs) -> Result<i32, Failure> {
    let described = opened.source.describe();
    let opening = Opening {
        follow: args.follow.clone(),
        seek: args.seek,
        speed: args.speed,
    };
    let viewer = open::viewer(&opened.level.level, opened.replay, &opening).map_err(|refused| {
        let error = match refused {
            Refused::NoSuchPlayer { name, players } => anyhow::anyhow!(
                "--follow {name}: nobody of that name plays in the replay (its players: {})",
                players.join(", ")
            ),
            Refused::SeekOutside { tick, start, end } => anyhow::anyhow!(
                "--replay-seek {tick}: the replay runs from tick {start} to tick {end}"
            ),
            Refused::NotPlayed(e) => {
                anyhow::anyhow!("the replay {described} {e}: {}", advice::advice(&e))
            }
        };
        Failure {
            code: EXIT_FAILED,
            error,
        }
    })?;
    let watch = window::Watch {
        viewer,
        level: opened.level.level,
        level_art: opened.level.art,
        bindings: args.bindings,
        source: described,
        exit_after: args.exit_after,
        screenshot: args.screenshot,
        debug: args.debug,
        hud: args.hud,
        volume: args.volume,
        mute: args.mute,
    };
    let conf = macroquad::window::Conf {
        window_title: "ledge replay".to_owned(),
        window_width: args.window.0,
        window_height: args.window.1,
        window_resizable: true,
        ..Default::default()
    };
    macroquad::Window::from_config(conf, window::watch(watch));
    Ok(EXIT_CODE.load(Ordering::Relaxed))
}
