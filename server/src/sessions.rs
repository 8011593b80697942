//! Players kept for a reconnect: each joined player has a session token
//! (sent in its `Welcome`); when its connection is lost (not when it left
//! or was kicked) its body stays in the room, standing still, for the
//! reconnect grace time, and a client presenting the token
//! (`ClientControl::Resume`) gets the same player back: same id, position,
//! coins and checkpoint. After the grace time the player leaves the room.
//!
//! A connection that resumes a session the server still thinks is live (a
//! client that gave up before the server noticed) takes it over: the room
//! closes the old connection, and generations keep the old connection's
//! late leave or loss from touching the resumed player.

use std::collections::BTreeMap;
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use ledge_shared::protocol::{PlayerId, SessionToken};
use ring::rand::{SecureRandom, SystemRandom};

use crate::room::RoomHandle;

/// A session the server knows.
#[derive(Debug, Clone)]
pub struct Parked {
    /// The room the player is in.
    pub room: RoomHandle,
    /// The player.
    pub player_id: PlayerId,
    /// Which connection holds it (bumped on every resume).
    pub generation: u32,
    /// When its connection was lost (`None`: a connection holds it).
    pub lost_at: Option<Instant>,
}

/// Every session, by token. At most one per player in a room, so bounded
/// by the rooms' capacity.
#[derive(Debug)]
pub struct Sessions {
    grace: Duration,
    by_token: Mutex<BTreeMap<SessionToken, Parked>>,
    random: SystemRandom,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl Sessions {
    /// No sessions; lost players are kept for `grace`.
    pub fn new(grace: Duration) -> Sessions {
        Sessions {
            grace,
            by_token: Mutex::new(BTreeMap::new()),
            random: SystemRandom::new(),
        }
    }

    /// How long a lost player is kept.
    pub fn grace(&self) -> Duration {
        self.grace
    }

    /// A new, unguessable token (the OS's random source).
    pub fn new_token(&self) -> SessionToken {
        let mut bytes = [0u8; 16];
        // The OS random source does not fail on supported platforms; a
        // zero token would only make one session unresumable.
        let _ = self.random.fill(&mut bytes);
        SessionToken(bytes)
    }

    /// Records a joined (or resumed) player's session.
    pub fn start(
        &self,
        token: SessionToken,
        room: RoomHandle,
        player_id: PlayerId,
        generation: u32,
    ) {
        lock(&self.by_token).insert(
            token,
            Parked {
                room,
                player_id,
                generation,
                lost_at: None,
            },
        );
    }

    /// The session `token` names, unless expired.
    pub fn find(&self, token: &SessionToken, now: Instant) -> Option<Parked> {
        let map = lock(&self.by_token);
        let parked = map.get(token)?;
        let expired = parked
            .lost_at
            .is_some_and(|at| now.saturating_duration_since(at) >= self.grace);
        (!expired).then(|| parked.clone())
    }

    /// The connection of generation `generation` lost the session: the
    /// player is kept from `now` for the grace time. A newer connection's
    /// session is left alone.
    pub fn lose(&self, token: &SessionToken, generation: u32, now: Instant) {
        if let Some(p) = lock(&self.by_token).get_mut(token) {
            if p.generation == generation {
                p.lost_at = Some(now);
            }
        }
    }

    /// The session ended for good (left, kicked): forgotten, if
    /// `generation` still holds it.
    pub fn end(&self, token: &SessionToken, generation: u32) {
        let mut map = lock(&self.by_token);
        if map.get(token).is_some_and(|p| p.generation == generation) {
            map.remove(token);
        }
    }

    /// Removes the sessions lost longer than the grace time by `now` and
    /// returns them (their players must leave their rooms).
    pub fn expire(&self, now: Instant) -> Vec<Parked> {
        let mut expired = Vec::new();
        lock(&self.by_token).retain(|_, p| {
            let keep = p
                .lost_at
                .is_none_or(|at| now.saturating_duration_since(at) < self.grace);
            if !keep {
                expired.push(p.clone());
            }
            keep
        });
        expired
    }

    /// Sessions known (live and lost).
    pub fn len(&self) -> usize {
        lock(&self.by_token).len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
