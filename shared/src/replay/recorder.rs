//! Builds replays from what a room does: the room tells it each join,
//! leave and step; it keeps the events, a state hash every
//! [`ReplayHeader::hash_interval`] ticks and a keyframe (the game's exact
//! state) every [`KEYFRAME_TICKS`], so that a player's run can be cut out
//! of a long match ([`ReplayRecorder::run`]) starting shortly before it.
//!
//! Memory grows with the match: the room starts a new recorder when
//! [`ReplayRecorder::full`] says so (about [`SPLIT_BYTES`] of events or
//! [`SPLIT_TICKS`] ticks), saving the old one as a match replay.

use std::collections::BTreeMap;

use crate::game::Game;
use crate::input::Buttons;
use crate::protocol::{PlayerId, StateSnapshot};

use super::{Event, Replay, ReplayHeader, ReplayKind, MAX_REPLAY_NAMES};

/// Ticks between two keyframes (10 s at 60 Hz).
pub const KEYFRAME_TICKS: u64 = 600;

/// A recorder is [`full`](ReplayRecorder::full) past this many bytes of
/// events (a quarter of [`super::MAX_REPLAY_BYTES`]: keyframes and names
/// fit beside them).
pub const SPLIT_BYTES: usize = super::MAX_REPLAY_BYTES / 4;

/// A recorder is [`full`](ReplayRecorder::full) past this many ticks (30
/// minutes at 60 Hz).
pub const SPLIT_TICKS: u64 = 30 * 60 * 60;

/// Bytes one event takes in memory (an upper bound of its file size).
const EVENT_BYTES: usize = std::mem::size_of::<Event>();

/// The game's exact state at a tick, and where the events stood.
#[derive(Debug, Clone)]
struct Keyframe {
    state: StateSnapshot,
    held: Vec<(PlayerId, Buttons)>,
    /// Events before this keyframe.
    events: usize,
}

/// A room's match as it is played (see the module documentation).
#[derive(Debug, Clone)]
pub struct ReplayRecorder {
    header: ReplayHeader,
    keyframes: Vec<Keyframe>,
    events: Vec<Event>,
    /// Buttons held, ascending by id, none zero.
    held: Vec<(PlayerId, Buttons)>,
    names: BTreeMap<PlayerId, String>,
    ticks: u64,
    /// Scratch for [`ReplayRecorder::step`].
    now: Vec<(PlayerId, Buttons)>,
}

impl ReplayRecorder {
    /// Starts recording `game` as it stands (before its next step), with
    /// `header` (its kind and names are set by the recorder).
    pub fn new(mut header: ReplayHeader, game: &Game) -> ReplayRecorder {
        header.kind = ReplayKind::Match;
        header.names.clear();
        header.hash_interval = header.hash_interval.max(1);
        ReplayRecorder {
            header,
            keyframes: vec![Keyframe {
                state: game.snapshot(),
                held: Vec::new(),
                events: 0,
            }],
            events: Vec::new(),
            held: Vec::new(),
            names: BTreeMap::new(),
            ticks: 0,
            now: Vec::new(),
        }
    }

    /// Ticks recorded.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// The game's tick where the recording starts.
    pub fn start_tick(&self) -> u64 {
        self.keyframes[0].state.tick
    }

    /// About how many bytes the recording holds.
    pub fn bytes(&self) -> usize {
        self.events.len() * EVENT_BYTES
    }

    /// Whether the room should save this recording and start another.
    pub fn full(&self) -> bool {
        self.bytes() >= SPLIT_BYTES || self.ticks >= SPLIT_TICKS
    }

    /// Player `id` joined the game, called `name`.
    pub fn join(&mut self, id: PlayerId, name: &str) {
        self.name(id, name);
        self.events.push(Event::Join(id));
    }

    /// Player `id` is called `name` (for players in the game before the
    /// recording started). Names past [`MAX_REPLAY_NAMES`] are not kept.
    pub fn name(&mut self, id: PlayerId, name: &str) {
        if self.names.len() < MAX_REPLAY_NAMES || self.names.contains_key(&id) {
            self.names.insert(id, name.to_owned());
        }
    }

    /// Player `id` left the game.
    pub fn leave(&mut self, id: PlayerId) {
        self.events.push(Event::Leave(id));
    }

    /// `game` was just stepped with `inputs` (as `Game::step` takes them:
    /// the first entry of a player counts, a player without one holds
    /// nothing).
    pub fn step(&mut self, game: &Game, inputs: &[(PlayerId, Buttons)]) {
        self.now.clear();
        for &(id, b) in inputs {
            if !self.now.iter().any(|&(p, _)| p == id) {
                self.now.push((id, b));
            }
        }
        self.now.retain(|&(_, b)| b.0 != 0);
        self.now.sort_unstable_by_key(|&(id, _)| id);
        self.press_changes();
        std::mem::swap(&mut self.held, &mut self.now);
        let floor = self.keyframes.last().map_or(0, |k| k.events);
        let len = self.events.len();
        match self.events.last_mut() {
            Some(Event::Step(n)) if len > floor && *n < u32::MAX => *n += 1,
            _ => self.events.push(Event::Step(1)),
        }
        self.ticks += 1;
        let tick = game.tick();
        if tick % u64::from(self.header.hash_interval) == 0 {
            self.events.push(Event::Hash(game.state_hash()));
        }
        if tick % KEYFRAME_TICKS == 0 {
            self.keyframes.push(Keyframe {
                state: game.snapshot(),
                held: self.held.clone(),
                events: self.events.len(),
            });
        }
    }

    /// Pushes a `Press` for each player whose buttons differ between
    /// `held` (before) and `now` (this step), both ascending.
    fn press_changes(&mut self) {
        let (mut i, mut j) = (0, 0);
        while i < self.held.len() || j < self.now.len() {
            let before = self.held.get(i).copied();
            let after = self.now.get(j).copied();
            match (before, after) {
                (Some((a, x)), Some((b, y))) if a == b => {
                    if x != y {
                        self.events.push(Event::Press(b, y));
                    }
                    i += 1;
                    j += 1;
                }
                (Some((a, _)), Some((b, _))) if a > b => {
                    self.events.push(Event::Press(b, after.unwrap().1));
                    j += 1;
                }
                (Some((a, _)), _) => {
                    self.events.push(Event::Press(a, Buttons(0)));
                    i += 1;
                }
                (None, Some((b, y))) => {
                    self.events.push(Event::Press(b, y));
                    j += 1;
                }
                (None, None) => break,
            }
        }
    }

    /// The match so far, `game` being the game recorded (its hash ends the
    /// replay).
    pub fn replay(&self, game: &Game) -> Replay {
        self.cut(0, self.header.kind, game)
    }

    /// Player `player`'s run, which started at `start_tick` and finished
    /// with the last step recorded, in `ticks` ticks and place `place`:
    /// from the newest keyframe at or before its start. `None` when the
    /// run started before this recording did.
    pub fn run(
        &self,
        game: &Game,
        player: PlayerId,
        start_tick: u64,
        ticks: u64,
        place: u32,
    ) -> Option<Replay> {
        let k = self
            .keyframes
            .iter()
            .rposition(|k| k.state.tick <= start_tick)?;
        let kind = ReplayKind::Run {
            player,
            start_tick,
            ticks,
            place,
        };
        Some(self.cut(k, kind, game))
    }

    /// The replay from keyframe `k` to now.
    fn cut(&self, k: usize, kind: ReplayKind, game: &Game) -> Replay {
        let key = &self.keyframes[k];
        let mut events = self.events[key.events..].to_vec();
        if !matches!(events.last(), Some(Event::Hash(_)) | None) {
            events.push(Event::Hash(game.state_hash()));
        }
        let mut header = self.header.clone();
        header.kind = kind;
        header.names = self.names.iter().map(|(&id, n)| (id, n.clone())).collect();
        Replay {
            header,
            start: key.state.clone(),
            held: key.held.clone(),
            events,
        }
    }
}
