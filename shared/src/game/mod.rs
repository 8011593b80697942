//! The platformer: players, moving platforms, enemies, pickups and the rules
//! that tie them to the physics world. (API skeleton with a stand-in
//! implementation; the platformer issue replaces the internals.)
//!
//! [`Game`] is what the server runs authoritatively and the client predicts:
//! `step` is deterministic, `snapshot`/`restore` carry the exact state, and
//! `state_hash` identifies it.

use crate::input::Buttons;
use crate::level::{EntityKind, Level};
use crate::protocol::{EntityState, PlayerId, StateSnapshot};
use glam::IVec2;
use thiserror::Error;

/// Why a game could not be built or changed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum GameError {
    /// The level has no player spawn.
    #[error("level {0:?} has no player spawn")]
    NoSpawn(String),
    /// A player with this id is already in the game.
    #[error("player {0} is already in the game")]
    DuplicatePlayer(PlayerId),
    /// A snapshot that does not describe this game.
    #[error("snapshot does not fit this game: {0}")]
    BadSnapshot(String),
}

/// Something that happened in a tick, for the server, the HUD and tests.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum GameEvent {
    /// A player entered the game.
    Joined(PlayerId),
}

/// The running platformer.
#[derive(Debug, Clone)]
pub struct Game {
    tick: u64,
    spawn: IVec2,
    players: Vec<(PlayerId, IVec2)>,
    events: Vec<GameEvent>,
}

impl Game {
    /// Builds the game for `level`.
    pub fn from_level(level: &Level) -> Result<Self, GameError> {
        let spawn = level
            .entities
            .iter()
            .find(|e| e.kind == EntityKind::PlayerSpawn)
            .map(|e| e.pos)
            .ok_or_else(|| GameError::NoSpawn(level.name.clone()))?;
        Ok(Self { tick: 0, spawn, players: Vec::new(), events: Vec::new() })
    }

    /// Adds a player at the current spawn point.
    pub fn add_player(&mut self, id: PlayerId) -> Result<(), GameError> {
        match self.players.binary_search_by_key(&id, |p| p.0) {
            Ok(_) => Err(GameError::DuplicatePlayer(id)),
            Err(i) => {
                self.players.insert(i, (id, self.spawn));
                self.events.push(GameEvent::Joined(id));
                Ok(())
            }
        }
    }

    /// Removes a player and its body; returns whether it was there.
    pub fn remove_player(&mut self, id: PlayerId) -> bool {
        match self.players.binary_search_by_key(&id, |p| p.0) {
            Ok(i) => {
                self.players.remove(i);
                true
            }
            Err(_) => false,
        }
    }

    /// Runs one tick. `inputs` holds at most one entry per player, in any
    /// order; a player without an entry holds no button.
    pub fn step(&mut self, inputs: &[(PlayerId, Buttons)]) -> &[GameEvent] {
        self.events.clear();
        for (id, pos) in &mut self.players {
            if let Some((_, b)) = inputs.iter().find(|(i, _)| i == id) {
                *pos += IVec2::new(b.dir_x(), b.dir_y()) * 256;
            }
        }
        self.tick += 1;
        &self.events
    }

    /// Ticks run so far.
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// The players and their positions, ascending by id.
    pub fn players(&self) -> impl Iterator<Item = (PlayerId, IVec2)> + '_ {
        self.players.iter().copied()
    }

    /// The exact state, as entities.
    pub fn snapshot(&self) -> StateSnapshot {
        StateSnapshot {
            tick: self.tick,
            entities: self
                .players
                .iter()
                .map(|(id, pos)| EntityState { pos: *pos, ..EntityState::zero(id.0) })
                .collect(),
        }
    }

    /// Restores the exact state of a [`Game::snapshot`] of the same level.
    pub fn restore(&mut self, snapshot: &StateSnapshot) -> Result<(), GameError> {
        self.tick = snapshot.tick;
        self.players = snapshot.entities.iter().map(|e| (PlayerId(e.id), e.pos)).collect();
        Ok(())
    }

    /// A stable 64-bit hash of the whole state.
    pub fn state_hash(&self) -> u64 {
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        let mut eat = |v: u64| {
            for b in v.to_le_bytes() {
                h = (h ^ b as u64).wrapping_mul(0x100_0000_01b3);
            }
        };
        eat(self.tick);
        for (id, p) in &self.players {
            eat(id.0 as u64);
            eat(p.x as u32 as u64);
            eat(p.y as u32 as u64);
        }
        h
    }
}
