//! A replay opened where the viewer asks: following a player by name, at
//! a game tick, at a speed; shared by the command line (`--follow`,
//! `--replay-seek`, `--replay-speed`) and the page (`follow=`, `seek=`,
//! `speed=`), each of which words the refusals in its own terms.

use ledge_client::replay::{Follow, ReplayViewer};
use ledge_shared::level::Level;
use ledge_shared::replay::{file::HEADER_LEN, Replay, ReplayError, MAX_REPLAY_BYTES};

/// The largest replay file: its header and the largest body.
pub const MAX_FILE_BYTES: u64 = (MAX_REPLAY_BYTES + HEADER_LEN) as u64;

/// Digits of a replay's id (in `/replays/ID`).
pub const ID_DIGITS: usize = 16;

/// Whether `id` looks like a replay's id: [`ID_DIGITS`] hex digits.
pub fn is_id(id: &str) -> bool {
    id.len() == ID_DIGITS && id.bytes().all(|b| b.is_ascii_hexdigit())
}

/// Where and how to open a replay.
#[derive(Debug, Clone, Default)]
pub struct Opening {
    /// Follow the player of this name.
    pub follow: Option<String>,
    /// Open at this game tick.
    pub seek: Option<u64>,
    /// Play at the nearest of the viewer's speeds.
    pub speed: Option<f32>,
}

/// Why a replay does not open as asked.
#[derive(Debug)]
pub enum Refused {
    /// Nobody of the name to follow plays in it.
    NoSuchPlayer {
        /// The name asked for.
        name: String,
        /// The replay's players' names.
        players: Vec<String>,
    },
    /// The tick to open at is not in the replay.
    SeekOutside {
        /// The tick asked for.
        tick: u64,
        /// The replay's first tick.
        start: u64,
        /// Its last.
        end: u64,
    },
    /// It does not play (to where it opens).
    NotPlayed(ReplayError),
}

/// `replay` on `level`, opened as `opening` says.
pub fn viewer(level: &Level, replay: Replay, opening: &Opening) -> Result<ReplayViewer, Refused> {
    let mut viewer = ReplayViewer::new(level, replay).map_err(Refused::NotPlayed)?;
    if let Some(name) = &opening.follow {
        let Some(id) = viewer.player_named(name) else {
            let players = viewer.replay().header.names.iter();
            return Err(Refused::NoSuchPlayer {
                name: name.clone(),
                players: players.map(|(_, n)| n.clone()).collect(),
            });
        };
        viewer.set_follow(Follow::Player(id));
    }
    if let Some(tick) = opening.seek {
        let (start, end) = (viewer.start_tick(), viewer.end_tick());
        if !(start..=end).contains(&tick) {
            return Err(Refused::SeekOutside { tick, start, end });
        }
        // At once: it opens there (before the first frame).
        viewer
            .seek(tick)
            .and_then(|()| viewer.finish_seek())
            .map_err(Refused::NotPlayed)?;
    }
    if let Some(speed) = opening.speed {
        viewer.set_speed(speed);
    }
    Ok(viewer)
}
