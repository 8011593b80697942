//! The registry of the server's rooms: those open from the start
//! (`room-1`, `room-2`, ..., never closed) and those players open by name
//! (`--room NAME`), up to the room cap. A room opened by name closes once it has been empty and
//! unasked for [`IDLE_CLOSE`], so names cannot pile up; its metric series
//! go with it.
//!
//! The registry only hands out [`RoomHandle`] clones; joining, leaving and
//! the tick loop are the room's own ([`crate::room`]). A room keeps running
//! while any handle is alive, so a player who joined just before its room
//! was closed keeps playing there until it leaves.

use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use ledge_shared::game::Game;
use ledge_shared::protocol::{RejectReason, RoomInfo};
use tokio::task::JoinHandle;
use tracing::info;

use crate::fleet::{Load, RoomLoad};
use crate::metrics::Metrics;
use crate::record::Recorder;
use crate::room::{self, RoomHandle};
use crate::room_logic::RoomConfig;

/// How long a room opened by name stays open while empty.
pub const IDLE_CLOSE: Duration = Duration::from_secs(60);

/// One open room.
#[derive(Debug)]
struct Entry {
    handle: RoomHandle,
    /// Open from the start: never closed.
    permanent: bool,
    /// Last asked for or seen with players.
    used: Instant,
}

/// Every open room, in name order, and how to open more.
#[derive(Debug)]
pub struct Rooms {
    open: Mutex<Vec<Entry>>,
    /// Room tasks, awaited at shutdown (finished ones are pruned).
    tasks: Mutex<Vec<JoinHandle<()>>>,
    /// A new room's game: the level at tick 0.
    game: Game,
    /// A new room's configuration (its name and recorder replaced).
    template: RoomConfig,
    max_rooms: usize,
    metrics: Arc<Metrics>,
}

/// Locks a mutex, recovering from poisoning (the data stays consistent:
/// every critical section here is a push, a retain or a read).
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl Rooms {
    /// No rooms yet; each opens with a clone of `game` and `template`.
    pub fn new(game: Game, template: RoomConfig, max_rooms: usize, metrics: Arc<Metrics>) -> Rooms {
        Rooms {
            open: Mutex::new(Vec::new()),
            tasks: Mutex::new(Vec::new()),
            game,
            template,
            max_rooms,
            metrics,
        }
    }

    /// Opens a room that never closes (the server's start-up rooms), with
    /// an optional match recorder. Must run on a tokio runtime.
    pub fn open_permanent(&self, name: String, record: Option<Recorder>) {
        let mut open = lock(&self.open);
        self.spawn_into(&mut open, name, true, record, Instant::now());
    }

    /// The rooms to try for a join, in order. Wanted by name: that room,
    /// opened if it is not open and the cap allows; else every room, least
    /// full first (the first of equally full ones).
    pub fn for_join(
        &self,
        wanted: Option<&str>,
        now: Instant,
    ) -> Result<Vec<RoomHandle>, RejectReason> {
        let mut open = lock(&self.open);
        let Some(wanted) = wanted else {
            let mut rooms: Vec<&Entry> = open.iter().collect();
            rooms.sort_by_key(|e| e.handle.players());
            return Ok(rooms.into_iter().map(|e| e.handle.clone()).collect());
        };
        if let Some(entry) = open.iter_mut().find(|e| e.handle.name() == wanted) {
            entry.used = now;
            return Ok(vec![entry.handle.clone()]);
        }
        if open.len() >= self.max_rooms {
            return Err(RejectReason::Other {
                reason: format!(
                    "there is no room named {wanted:?}, and the server's {} rooms are all \
                     open (its room cap, --max-rooms): join one of them (--list-rooms)",
                    self.max_rooms
                ),
            });
        }
        let handle = self.spawn_into(&mut open, wanted.to_owned(), false, None, now);
        Ok(vec![handle])
    }

    /// Every open room, in name order.
    pub fn list(&self) -> Vec<RoomInfo> {
        lock(&self.open)
            .iter()
            .map(|e| RoomInfo {
                name: e.handle.name().to_owned(),
                level_id: self.template.levels.get(e.handle.status().level).id.clone(),
                players: u32::try_from(e.handle.players()).unwrap_or(u32::MAX),
                capacity: u32::try_from(self.template.max_players).unwrap_or(u32::MAX),
            })
            .collect()
    }

    /// Every open room's load, in name order, and the caps (for the fleet
    /// logic, [`crate::fleet`]).
    pub fn load(&self) -> Load {
        let rooms = lock(&self.open)
            .iter()
            .map(|e| RoomLoad {
                name: e.handle.name().to_owned(),
                players: u32::try_from(e.handle.players()).unwrap_or(u32::MAX),
                tick: e.handle.status().tick,
            })
            .collect();
        Load {
            rooms,
            room_cap: u32::try_from(self.max_rooms).unwrap_or(u32::MAX),
            players_per_room: u32::try_from(self.template.max_players).unwrap_or(u32::MAX),
        }
    }

    /// Open rooms.
    pub fn len(&self) -> usize {
        lock(&self.open).len()
    }

    /// Whether no room is open.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Closes the rooms opened by name that have been empty and unasked for
    /// [`IDLE_CLOSE`] by `now`; returns their names.
    pub fn close_idle(&self, now: Instant) -> Vec<String> {
        let mut closed = Vec::new();
        lock(&self.open).retain_mut(|e| {
            if e.handle.players() > 0 {
                e.used = now;
            }
            let keep = e.permanent || now.saturating_duration_since(e.used) < IDLE_CLOSE;
            if !keep {
                closed.push(e.handle.name().to_owned());
            }
            keep
        });
        for name in &closed {
            info!(room = %name, "closing the empty room");
            self.metrics.forget_room(name);
        }
        self.metrics.rooms.set(self.len() as i64);
        lock(&self.tasks).retain(|t| !t.is_finished());
        closed
    }

    /// Closes every room and returns their tasks, which end once the
    /// remaining handles (held by connections) are gone.
    pub fn close_all(&self) -> Vec<JoinHandle<()>> {
        lock(&self.open).clear();
        self.metrics.rooms.set(0);
        std::mem::take(&mut *lock(&self.tasks))
    }

    fn spawn_into(
        &self,
        open: &mut Vec<Entry>,
        name: String,
        permanent: bool,
        record: Option<Recorder>,
        now: Instant,
    ) -> RoomHandle {
        let config = RoomConfig {
            name,
            record,
            ..self.template.clone()
        };
        if let Some(r) = &config.record {
            r.start(&self.game);
        }
        if !permanent {
            info!(room = %config.name, "opening a room asked for by name");
        }
        let (handle, task) = room::spawn(self.game.clone(), config, self.metrics.clone());
        let at = open.partition_point(|e| e.handle.name() < handle.name());
        open.insert(
            at,
            Entry {
                handle: handle.clone(),
                permanent,
                used: now,
            },
        );
        self.metrics.rooms.set(open.len() as i64);
        lock(&self.tasks).push(task);
        handle
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rooms(max_rooms: usize) -> Rooms {
        let level = ledge_levels::default_level();
        let game = Game::from_level(&level).unwrap();
        let template = RoomConfig {
            name: String::new(),
            tick_rate: 60,
            snapshot_interval: 2,
            max_players: 4,
            max_catch_up: 15,
            input_window: 64,
            input_redundancy: 16,
            history: 64,
            level_id: "default".into(),
            level_hash: 1,
            level: Default::default(),
            record: None,
            idle_kick: std::time::Duration::from_secs(30),
            instance: "test".into(),
            records: Default::default(),
            replays: Default::default(),
            max_spectators: 2,
            levels: crate::levels::LevelSet::load(&[], None, Default::default(), 32).unwrap(),
            rotation: Default::default(),
        };
        let (metrics, _registry) = Metrics::new();
        Rooms::new(game, template, max_rooms, metrics)
    }

    fn names(rooms: &Rooms) -> Vec<String> {
        rooms.list().into_iter().map(|r| r.name).collect()
    }

    #[tokio::test]
    async fn rooms_open_by_name_up_to_the_cap_and_are_listed_in_order() {
        let rooms = rooms(3);
        rooms.open_permanent("room-1".into(), None);
        let now = Instant::now();
        // Any room: the permanent one.
        let any = rooms.for_join(None, now).unwrap();
        assert_eq!(any.len(), 1);
        assert_eq!(any[0].name(), "room-1");
        // By name: opened once, then found.
        assert_eq!(rooms.for_join(Some("zeta"), now).unwrap()[0].name(), "zeta");
        assert_eq!(
            rooms.for_join(Some("alpha"), now).unwrap()[0].name(),
            "alpha"
        );
        assert_eq!(rooms.for_join(Some("zeta"), now).unwrap().len(), 1);
        assert_eq!(names(&rooms), ["alpha", "room-1", "zeta"]);
        let listed = rooms.list();
        assert!(listed
            .iter()
            .all(|r| r.capacity == 4 && r.players == 0 && r.level_id == "default"));
        ledge_shared::protocol::check_rooms(&listed).unwrap();
        // At the cap a new name is refused, saying why and what to do.
        let refused = rooms.for_join(Some("more"), now).unwrap_err().to_string();
        assert!(
            refused.contains("\"more\"") && refused.contains("--list-rooms"),
            "{refused}"
        );
        // An existing one still joins.
        assert_eq!(rooms.for_join(Some("alpha"), now).unwrap().len(), 1);
        assert_eq!(rooms.metrics.rooms.get(), 3);
    }

    #[tokio::test]
    async fn empty_rooms_opened_by_name_close_after_the_idle_time() {
        let rooms = rooms(2);
        rooms.open_permanent("room-1".into(), None);
        let t0 = Instant::now();
        rooms.for_join(Some("friends"), t0).unwrap();
        assert!(rooms.close_idle(t0 + IDLE_CLOSE / 2).is_empty());
        // Asked for again: the clock restarts.
        rooms
            .for_join(Some("friends"), t0 + IDLE_CLOSE / 2)
            .unwrap();
        assert!(rooms.close_idle(t0 + IDLE_CLOSE).is_empty());
        assert_eq!(
            rooms.close_idle(t0 + IDLE_CLOSE * 2),
            ["friends".to_owned()]
        );
        // The permanent room stays, and the freed place can be used again.
        assert_eq!(names(&rooms), ["room-1"]);
        assert_eq!(rooms.metrics.rooms.get(), 1);
        rooms.for_join(Some("others"), t0 + IDLE_CLOSE * 2).unwrap();
        assert_eq!(names(&rooms), ["others", "room-1"]);
        assert!(!rooms.close_all().is_empty());
        assert!(rooms.is_empty());
    }
}
