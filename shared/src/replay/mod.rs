//! Replays: a room's match, or one player's run, as the inputs the server
//! stepped its game with, so that the same simulation plays it again
//! exactly (the game is deterministic: level + configuration + state +
//! inputs give every later state).
//!
//! A [`Replay`] is a [`ReplayHeader`] (what was played, by whom, with which
//! configuration), a keyframe (the game's exact state where the replay
//! starts, [`Game::snapshot`]) and a stream of [`Event`]s: joins, leaves,
//! button changes, steps and the server's state hash every
//! [`ReplayHeader::hash_interval`] ticks, so a replay that plays out
//! differently (another build, a damaged file, the wrong level) says so and
//! where ([`ReplayError::Diverged`]).
//!
//! * [`file`]: the file format (versioned, checksummed, bounded);
//! * [`recorder`]: builds replays from what a room does, with keyframes so
//!   a run can be cut out of a long match;
//! * [`playback`]: plays one, with seeking.
//!
//! [`Game::snapshot`]: crate::game::Game::snapshot

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::game::GameConfig;
use crate::input::Buttons;
use crate::protocol::{
    check_name, check_text, LevelOffer, PlayerId, ProtocolError, StateSnapshot, MAX_ID_LEN,
    MAX_ROSTER,
};

pub mod file;
pub mod playback;
pub mod recorder;

pub use file::{decode, encode, FORMAT_VERSION, MAGIC, MAX_REPLAY_BYTES};
pub use playback::Playback;
pub use recorder::ReplayRecorder;

/// Most ticks one replay may step (a day at 60 Hz): a bound on playing a
/// file, checked when it is read.
pub const MAX_REPLAY_TICKS: u64 = 24 * 3600 * 60;

/// Most player names one replay lists.
pub const MAX_REPLAY_NAMES: usize = 4 * MAX_ROSTER;

/// Most bytes of a level name in a header.
pub const MAX_LEVEL_NAME_LEN: usize = 128;

/// What a replay holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ReplayKind {
    /// Everything a room ran, while anyone was in it.
    Match,
    /// One player's finished run, cut out of its room's match: the replay
    /// starts at a keyframe at or before the run's start and ends at its
    /// finish.
    Run {
        /// Whose run.
        player: PlayerId,
        /// The tick the run's timer started (the game's tick).
        start_tick: u64,
        /// The run's time, in ticks.
        ticks: u64,
        /// Its finishing place in the room (1 = first).
        place: u32,
    },
}

/// What a replay is of.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ReplayHeader {
    /// Match or run.
    pub kind: ReplayKind,
    /// The room's name.
    pub room: String,
    /// The level's id (as in `Welcome`).
    pub level_id: String,
    /// The level's name, for titles.
    pub level_name: String,
    /// The level bundle played: find it in the cache or download it.
    pub level: LevelOffer,
    /// The game's configuration: play with `Game::with_config`.
    pub config: GameConfig,
    /// Ticks per second the room ran at.
    pub tick_rate: u16,
    /// Ticks between two [`Event::Hash`]es.
    pub hash_interval: u32,
    /// When the replay starts (Unix time, milliseconds; informative only,
    /// the simulation never reads it).
    pub recorded_at_ms: u64,
    /// The players' names, by id (ascending ids).
    pub names: Vec<(PlayerId, String)>,
}

impl ReplayHeader {
    /// The header of a match in `room` on the level `level_id` (named
    /// `level_name`, its bundle `level`) played with `config` at
    /// `tick_rate`: a hash a second, no names yet (the recorder adds
    /// them), no start time (the writer sets it).
    pub fn for_match(
        room: &str,
        (level_id, level_name, level): (&str, &str, LevelOffer),
        config: GameConfig,
        tick_rate: u16,
    ) -> ReplayHeader {
        ReplayHeader {
            kind: ReplayKind::Match,
            room: room.to_owned(),
            level_id: level_id.to_owned(),
            level_name: level_name.to_owned(),
            level,
            config,
            tick_rate,
            hash_interval: u32::from(tick_rate.max(1)),
            recorded_at_ms: 0,
            names: Vec::new(),
        }
    }
}

/// One step of a replay's stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Event {
    /// `Game::step` this many times (at least once) with the buttons held.
    Step(u32),
    /// `Game::add_player`.
    Join(PlayerId),
    /// `Game::remove_player`.
    Leave(PlayerId),
    /// From the next step on, the player holds these buttons (0: none).
    Press(PlayerId, Buttons),
    /// `Game::state_hash` after the steps so far.
    Hash(u64),
}

/// A match or a run, ready to play (see the module documentation).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Replay {
    /// What it is of.
    pub header: ReplayHeader,
    /// The game's exact state where the replay starts.
    pub start: StateSnapshot,
    /// Buttons held at the start, ascending by player id, none zero.
    pub held: Vec<(PlayerId, Buttons)>,
    /// What happened since, in order.
    pub events: Vec<Event>,
}

impl Replay {
    /// The game's tick at the start.
    pub fn start_tick(&self) -> u64 {
        self.start.tick
    }

    /// Ticks stepped in all.
    pub fn ticks(&self) -> u64 {
        self.events
            .iter()
            .map(|e| match e {
                Event::Step(n) => u64::from(*n),
                _ => 0,
            })
            .sum()
    }

    /// The game's tick at the end.
    pub fn end_tick(&self) -> u64 {
        self.start_tick() + self.ticks()
    }

    /// A player's name in the header, if listed.
    pub fn name_of(&self, id: PlayerId) -> Option<&str> {
        let names = &self.header.names;
        let i = names.binary_search_by_key(&id, |(p, _)| *p).ok()?;
        Some(&names[i].1)
    }

    /// Checks what decoding does not: strings, counts, orders and the
    /// tick total; the first problem found.
    pub fn validate(&self) -> Result<(), ReplayError> {
        let h = &self.header;
        let text = |e: ProtocolError| ReplayError::Invalid(e.to_string());
        check_text("room", &h.room, 1, MAX_ID_LEN).map_err(text)?;
        check_text("level id", &h.level_id, 1, MAX_ID_LEN).map_err(text)?;
        check_text("level name", &h.level_name, 0, MAX_LEVEL_NAME_LEN).map_err(text)?;
        if h.tick_rate == 0 || h.tick_rate > 1000 {
            return Err(invalid(format!(
                "tick rate {} outside 1..=1000",
                h.tick_rate
            )));
        }
        if h.hash_interval == 0 {
            return Err(invalid("hash interval 0".into()));
        }
        if h.names.len() > MAX_REPLAY_NAMES {
            return Err(ReplayError::TooLarge {
                what: "player names",
                len: h.names.len() as u64,
                max: MAX_REPLAY_NAMES as u64,
            });
        }
        for (_, name) in &h.names {
            check_name(name).map_err(text)?;
        }
        if !h.names.windows(2).all(|w| w[0].0 < w[1].0) {
            return Err(invalid("player names not in ascending id order".into()));
        }
        if !self.held.windows(2).all(|w| w[0].0 < w[1].0) || self.held.iter().any(|h| h.1 .0 == 0) {
            return Err(invalid("held buttons not ascending or zero".into()));
        }
        self.start.validate().map_err(text)?;
        if self.events.contains(&Event::Step(0)) {
            return Err(invalid("a step of 0 ticks".into()));
        }
        let ticks = self.ticks();
        if ticks > MAX_REPLAY_TICKS {
            return Err(ReplayError::TooLarge {
                what: "tick count",
                len: ticks,
                max: MAX_REPLAY_TICKS,
            });
        }
        Ok(())
    }
}

fn invalid(detail: String) -> ReplayError {
    ReplayError::Invalid(detail)
}

/// Why a replay cannot be read or played.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ReplayError {
    /// The bytes do not start with [`MAGIC`].
    #[error("not a ledge replay (it does not start with \"LEDGEREP\")")]
    NotAReplay,
    /// A newer ledge wrote it.
    #[error("made by a newer ledge (replay format {found}; this one reads up to {known}): update ledge to play it")]
    NewerFormat {
        /// The file's format version.
        found: u16,
        /// [`FORMAT_VERSION`].
        known: u16,
    },
    /// The file ends early.
    #[error("truncated: {have} of {need} bytes")]
    Truncated {
        /// Bytes present.
        have: u64,
        /// Bytes the header promises.
        need: u64,
    },
    /// Bytes follow the replay.
    #[error("{extra} bytes after the end of the replay")]
    TrailingBytes {
        /// How many.
        extra: u64,
    },
    /// A size or count over its bound.
    #[error("its {what} is {len}, over the limit of {max}")]
    TooLarge {
        /// What was too large.
        what: &'static str,
        /// The size or count found.
        len: u64,
        /// The largest accepted.
        max: u64,
    },
    /// The checksum does not match: the file was damaged.
    #[error("damaged: its checksum is {found:08x}, its content hashes to {computed:08x}")]
    Checksum {
        /// The checksum the file carries.
        found: u32,
        /// What its bytes give.
        computed: u32,
    },
    /// The content does not decode or breaks a rule.
    #[error("invalid: {0}")]
    Invalid(String),
    /// The game cannot be set up or stepped as the replay says.
    #[error("cannot play at tick {tick}: {detail}")]
    Unplayable {
        /// The game's tick.
        tick: u64,
        /// What failed.
        detail: String,
    },
    /// The game's state hash differs from the one recorded: this build,
    /// this level or this file does not play as the server did.
    #[error("plays differently from the server from tick {tick} on: state hash {ours:016x}, the server's {theirs:016x}")]
    Diverged {
        /// The game's tick after the step whose hash differs.
        tick: u64,
        /// Ours.
        ours: u64,
        /// The recorded one.
        theirs: u64,
    },
}
