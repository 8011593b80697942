//! What a server in an Agones fleet tells the orchestrator, and when:
//! a sans-IO state machine (like `quinn-proto`) that the SDK driver
//! (`crate::agones`, cargo feature `agones`) feeds with the rooms' load
//! and the GameServer's state, and whose [`Call`]s it makes.
//!
//! Following Agones' "high density game servers" pattern, one process
//! hosts many rooms:
//!
//! * Counter [`ROOMS`]: count = open rooms (those open from the start, and
//!   those opened by name until they close), capacity = the room cap: the
//!   same numbers the server refuses a new room by, so an allocation that
//!   finds a free room here can open one there;
//! * Counter [`PLAYERS`]: count = players in the rooms, capacity = room
//!   cap × places per room;
//! * List [`ROOMS`]: the names of the open rooms, so an allocation can find
//!   the server holding a named room;
//! * label [`FULL_LABEL`]: `"true"` while no room can open (the count is
//!   at the cap);
//! * annotation [`CERT_ANNOTATION`]: the certificate's SHA-256 fingerprint,
//!   which clients pin (`--cert-hash`);
//! * health pings every [`FleetConfig::health_every`] while **every** room's
//!   tick loop advances: a stuck tick loop stops them, and Agones restarts
//!   the server;
//! * once Allocated, `Shutdown` after the last player has been gone for
//!   [`FleetConfig::shutdown_after`].
//!
//! Agones prefixes the keys of labels and annotations set through the SDK
//! with `agones.dev/sdk-`: the GameServer carries
//! `agones.dev/sdk-ledge-full` and `agones.dev/sdk-ledge-cert-sha256`.
//!
//! Values are sent only when they change; a call that failed is forgotten
//! with [`Fleet::failed`], so the next [`Fleet::poll`] sends it again.

use std::collections::{BTreeMap, BTreeSet};
use std::time::{Duration, Instant};

/// The Counter of rooms in use, and the List of room names.
pub const ROOMS: &str = "rooms";
/// The Counter of players.
pub const PLAYERS: &str = "players";
/// The label saying every room is in use (Agones makes it
/// `agones.dev/sdk-ledge-full`).
pub const FULL_LABEL: &str = "ledge-full";
/// The annotation holding the certificate's fingerprint (Agones makes it
/// `agones.dev/sdk-ledge-cert-sha256`).
pub const CERT_ANNOTATION: &str = "ledge-cert-sha256";

/// Default time between health pings.
pub const DEFAULT_HEALTH_EVERY: Duration = Duration::from_secs(2);
/// Default time an Allocated server stays up with no players.
pub const DEFAULT_SHUTDOWN_AFTER: Duration = Duration::from_secs(60);
/// Default time the server waits for the SDK sidecar at start (as long as
/// the SDK itself tries).
pub const DEFAULT_CONNECT_TIMEOUT: Duration = Duration::from_secs(30);

/// How the fleet logic behaves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FleetConfig {
    /// Time between health pings (while every tick loop advances).
    pub health_every: Duration,
    /// Once Allocated, shut down after no player has been in any room this
    /// long.
    pub shutdown_after: Duration,
    /// How long the server waits for the SDK sidecar at start.
    pub connect_timeout: Duration,
    /// The sidecar's gRPC port; `None`: `AGONES_SDK_GRPC_PORT`, else 9357
    /// (as Agones sets it in the pod).
    pub sdk_port: Option<u16>,
}

impl Default for FleetConfig {
    fn default() -> FleetConfig {
        FleetConfig {
            health_every: DEFAULT_HEALTH_EVERY,
            shutdown_after: DEFAULT_SHUTDOWN_AFTER,
            connect_timeout: DEFAULT_CONNECT_TIMEOUT,
            sdk_port: None,
        }
    }
}

/// One open room, as the fleet logic sees it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RoomLoad {
    /// Its name.
    pub name: String,
    /// Players in it.
    pub players: u32,
    /// Ticks it has simulated (its tick loop advances it).
    pub tick: u64,
}

/// The server's load: its open rooms and its caps.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Load {
    /// The open rooms, in name order.
    pub rooms: Vec<RoomLoad>,
    /// Most rooms open at once (`--max-rooms`).
    pub room_cap: u32,
    /// Places per room (`--max-players`).
    pub players_per_room: u32,
}

impl Load {
    fn open(&self) -> u32 {
        u32::try_from(self.rooms.len()).unwrap_or(u32::MAX)
    }

    fn players(&self) -> u32 {
        self.rooms.iter().map(|r| r.players).sum()
    }
}

/// One SDK call to make.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Call {
    /// The server listens and its level is loaded.
    Ready,
    /// A health ping.
    Health,
    /// Set a Counter's count and capacity.
    Counter {
        /// [`ROOMS`] or [`PLAYERS`].
        name: &'static str,
        /// The count.
        count: i64,
        /// The capacity.
        capacity: i64,
    },
    /// Set the [`ROOMS`] List's capacity.
    ListCapacity(i64),
    /// Add a room name to the [`ROOMS`] List.
    ListAdd(String),
    /// Remove a room name from the [`ROOMS`] List.
    ListRemove(String),
    /// Set a label (Agones prefixes the key with `agones.dev/sdk-`).
    Label {
        /// The key.
        key: &'static str,
        /// The value.
        value: String,
    },
    /// Set an annotation (Agones prefixes the key with `agones.dev/sdk-`).
    Annotation {
        /// The key.
        key: &'static str,
        /// The value.
        value: String,
    },
    /// The server is done: Agones deletes it.
    Shutdown,
}

/// The fleet logic's state (see the module documentation).
#[derive(Debug, Clone)]
pub struct Fleet {
    config: FleetConfig,
    fingerprint: String,
    /// `Ready` and the annotation were acknowledged (else sent again).
    ready: bool,
    annotated: bool,
    list_capacity: Option<i64>,
    last_health: Option<Instant>,
    /// Each room's tick at the last health ping.
    ticks: BTreeMap<String, u64>,
    /// Rooms whose tick did not advance since the last ping, and since
    /// when they have been seen so.
    stuck: BTreeMap<String, Instant>,
    counters: BTreeMap<&'static str, (i64, i64)>,
    listed: BTreeSet<String>,
    full: Option<bool>,
    allocated: bool,
    empty_since: Option<Instant>,
    shutdown: bool,
}

impl Fleet {
    /// A server about to say it is ready; `fingerprint` is its
    /// certificate's, in hex.
    pub fn new(config: FleetConfig, fingerprint: &str) -> Fleet {
        Fleet {
            config,
            fingerprint: fingerprint.to_owned(),
            ready: false,
            annotated: false,
            list_capacity: None,
            last_health: None,
            ticks: BTreeMap::new(),
            stuck: BTreeMap::new(),
            counters: BTreeMap::new(),
            listed: BTreeSet::new(),
            full: None,
            allocated: false,
            empty_since: None,
            shutdown: false,
        }
    }

    /// The calls due at `now` for `load`: first the annotation, counters,
    /// list and label, then `Ready` (so an allocation never sees a ready
    /// server without its fingerprint), then changes, health pings and the
    /// shutdown as they come due.
    pub fn poll(&mut self, load: &Load, now: Instant) -> Vec<Call> {
        let mut calls = Vec::new();
        if !self.annotated {
            self.annotated = true;
            calls.push(Call::Annotation {
                key: CERT_ANNOTATION,
                value: self.fingerprint.clone(),
            });
        }
        let list_capacity = i64::from(load.room_cap);
        if self.list_capacity != Some(list_capacity) {
            self.list_capacity = Some(list_capacity);
            calls.push(Call::ListCapacity(list_capacity));
        }
        let players = load.players();
        self.counter(&mut calls, ROOMS, load.open(), load.room_cap);
        self.counter(
            &mut calls,
            PLAYERS,
            players,
            load.room_cap.saturating_mul(load.players_per_room),
        );
        let open: BTreeSet<String> = load.rooms.iter().map(|r| r.name.clone()).collect();
        for gone in self.listed.difference(&open) {
            calls.push(Call::ListRemove(gone.clone()));
        }
        for new in open.difference(&self.listed) {
            calls.push(Call::ListAdd(new.clone()));
        }
        self.listed = open;
        let full = load.open() >= load.room_cap;
        if self.full != Some(full) {
            self.full = Some(full);
            calls.push(Call::Label {
                key: FULL_LABEL,
                value: full.to_string(),
            });
        }
        if !self.ready {
            self.ready = true;
            calls.push(Call::Ready);
        }
        if self.health_due(load, now) {
            calls.push(Call::Health);
        }
        if self.allocated && !self.shutdown {
            if players > 0 {
                self.empty_since = None;
            } else {
                let since = *self.empty_since.get_or_insert(now);
                if now.saturating_duration_since(since) >= self.config.shutdown_after {
                    self.shutdown = true;
                    calls.push(Call::Shutdown);
                }
            }
        }
        calls
    }

    /// Whether a ping is due: the period passed and every room's tick
    /// advanced since the last ping (a new room counts as advanced).
    fn health_due(&mut self, load: &Load, now: Instant) -> bool {
        let period_over = self
            .last_health
            .is_none_or(|t| now.saturating_duration_since(t) >= self.config.health_every);
        if !period_over {
            return false;
        }
        let mut all = true;
        for room in &load.rooms {
            let advanced = self.ticks.get(&room.name).is_none_or(|&t| room.tick > t);
            if advanced {
                self.stuck.remove(&room.name);
            } else {
                all = false;
                self.stuck.entry(room.name.clone()).or_insert(now);
            }
        }
        self.stuck
            .retain(|name, _| load.rooms.iter().any(|r| &r.name == name));
        if all {
            self.last_health = Some(now);
            self.ticks = load
                .rooms
                .iter()
                .map(|r| (r.name.clone(), r.tick))
                .collect();
        }
        all
    }

    fn counter(&mut self, calls: &mut Vec<Call>, name: &'static str, count: u32, capacity: u32) {
        let value = (i64::from(count), i64::from(capacity));
        if self.counters.get(name) != Some(&value) {
            self.counters.insert(name, value);
            calls.push(Call::Counter {
                name,
                count: value.0,
                capacity: value.1,
            });
        }
    }

    /// The GameServer's state changed (from the SDK's watch): `Allocated`
    /// starts the shutdown clock.
    pub fn on_state(&mut self, state: &str) {
        if state == "Allocated" && !self.allocated {
            self.allocated = true;
            self.empty_since = None;
        }
    }

    /// Whether the GameServer was Allocated.
    pub fn allocated(&self) -> bool {
        self.allocated
    }

    /// `call` failed: forget it was made, so the next poll makes it again
    /// (a health ping is simply lost; the next one is due as usual).
    pub fn failed(&mut self, call: &Call) {
        match call {
            Call::Ready => self.ready = false,
            Call::Health => {}
            Call::Counter { name, .. } => {
                self.counters.remove(name);
            }
            Call::ListCapacity(_) => self.list_capacity = None,
            Call::ListAdd(name) => {
                self.listed.remove(name);
            }
            Call::ListRemove(name) => {
                self.listed.insert(name.clone());
            }
            Call::Label { .. } => self.full = None,
            Call::Annotation { .. } => self.annotated = false,
            Call::Shutdown => self.shutdown = false,
        }
    }

    /// Rooms whose tick loop has not advanced since the last health ping,
    /// with how long, at `now` (pings are withheld while any is listed).
    pub fn stuck(&self, now: Instant) -> Vec<(String, Duration)> {
        self.stuck
            .iter()
            .map(|(name, since)| (name.clone(), now.saturating_duration_since(*since)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn room(name: &str, players: u32, tick: u64) -> RoomLoad {
        RoomLoad {
            name: name.to_owned(),
            players,
            tick,
        }
    }

    fn load(rooms: Vec<RoomLoad>) -> Load {
        Load {
            rooms,
            room_cap: 3,
            players_per_room: 4,
        }
    }

    fn config() -> FleetConfig {
        FleetConfig {
            health_every: Duration::from_secs(2),
            shutdown_after: Duration::from_secs(10),
            connect_timeout: Duration::from_secs(1),
            sdk_port: None,
        }
    }

    fn secs(t0: Instant, s: f64) -> Instant {
        t0 + Duration::from_secs_f64(s)
    }

    #[test]
    fn the_first_poll_publishes_everything_then_says_ready() {
        let t0 = Instant::now();
        let mut fleet = Fleet::new(config(), "ab12");
        let calls = fleet.poll(&load(vec![room("room-1", 0, 5)]), t0);
        assert_eq!(
            calls,
            [
                Call::Annotation {
                    key: CERT_ANNOTATION,
                    value: "ab12".into()
                },
                Call::ListCapacity(3),
                // room-1, open from the start, takes a place of the cap.
                Call::Counter {
                    name: ROOMS,
                    count: 1,
                    capacity: 3
                },
                Call::Counter {
                    name: PLAYERS,
                    count: 0,
                    capacity: 12
                },
                Call::ListAdd("room-1".into()),
                Call::Label {
                    key: FULL_LABEL,
                    value: "false".into()
                },
                Call::Ready,
                Call::Health,
            ]
        );
        // Nothing changed, no time passed: nothing to say.
        assert!(fleet.poll(&load(vec![room("room-1", 0, 6)]), t0).is_empty());
    }

    #[test]
    fn counters_list_and_label_follow_the_rooms() {
        let t0 = Instant::now();
        let mut fleet = Fleet::new(config(), "ab12");
        fleet.poll(&load(vec![room("room-1", 0, 1)]), t0);
        // A player joins room-1; another opens "friends" by name.
        let calls = fleet.poll(
            &load(vec![room("friends", 1, 1), room("room-1", 1, 2)]),
            secs(t0, 0.5),
        );
        assert_eq!(
            calls,
            [
                Call::Counter {
                    name: ROOMS,
                    count: 2,
                    capacity: 3
                },
                Call::Counter {
                    name: PLAYERS,
                    count: 2,
                    capacity: 12
                },
                Call::ListAdd("friends".into()),
            ]
        );
        // A third room: the cap is reached, the server is full.
        let calls = fleet.poll(
            &load(vec![
                room("duel", 2, 1),
                room("friends", 1, 2),
                room("room-1", 1, 3),
            ]),
            secs(t0, 1.0),
        );
        assert!(calls.contains(&Call::Label {
            key: FULL_LABEL,
            value: "true".into()
        }));
        assert!(calls.contains(&Call::ListAdd("duel".into())));
        // "friends" closes, room-1 empties: 2 open, not full.
        let calls = fleet.poll(
            &load(vec![room("duel", 2, 5), room("room-1", 0, 6)]),
            secs(t0, 1.5),
        );
        assert_eq!(
            calls,
            [
                Call::Counter {
                    name: ROOMS,
                    count: 2,
                    capacity: 3
                },
                Call::Counter {
                    name: PLAYERS,
                    count: 2,
                    capacity: 12
                },
                Call::ListRemove("friends".into()),
                Call::Label {
                    key: FULL_LABEL,
                    value: "false".into()
                },
            ]
        );
    }

    #[test]
    fn health_pings_only_while_every_tick_loop_advances() {
        let t0 = Instant::now();
        let mut fleet = Fleet::new(config(), "ab12");
        let pinged = |calls: Vec<Call>| calls.contains(&Call::Health);
        let two = |a: u64, b: u64| load(vec![room("a", 1, a), room("b", 1, b)]);
        assert!(pinged(fleet.poll(&two(1, 1), t0)));
        // Within the period: no ping even though ticks advance.
        assert!(!pinged(fleet.poll(&two(60, 60), secs(t0, 1.0))));
        assert!(pinged(fleet.poll(&two(120, 120), secs(t0, 2.0))));
        // Room b stops ticking: no ping, and it is named.
        assert!(!pinged(fleet.poll(&two(240, 120), secs(t0, 4.0))));
        assert!(!pinged(fleet.poll(&two(300, 120), secs(t0, 5.0))));
        let stuck = fleet.stuck(secs(t0, 5.0));
        assert_eq!(stuck, [("b".to_owned(), Duration::from_secs(1))]);
        // It ticks again: the ping comes at once, nothing is stuck.
        assert!(pinged(fleet.poll(&two(310, 121), secs(t0, 5.5))));
        assert!(fleet.stuck(secs(t0, 5.5)).is_empty());
        // A stuck room that closes no longer holds pings back.
        assert!(!pinged(fleet.poll(&two(400, 121), secs(t0, 8.0))));
        assert!(pinged(
            fleet.poll(&load(vec![room("a", 1, 401)]), secs(t0, 8.1))
        ));
    }

    #[test]
    fn an_allocated_server_shuts_down_once_empty_long_enough() {
        let t0 = Instant::now();
        let mut fleet = Fleet::new(config(), "ab12");
        let with = |players: u32, tick: u64| load(vec![room("room-1", players, tick)]);
        let shuts = |calls: &[Call]| calls.contains(&Call::Shutdown);
        // Not allocated: empty forever, never shut down.
        fleet.poll(&with(0, 1), t0);
        assert!(!shuts(&fleet.poll(&with(0, 2), secs(t0, 100.0))));
        fleet.on_state("Allocated");
        assert!(fleet.allocated());
        // Players come and go: the clock restarts when the last one leaves.
        assert!(!shuts(&fleet.poll(&with(0, 3), secs(t0, 101.0))));
        assert!(!shuts(&fleet.poll(&with(2, 4), secs(t0, 105.0))));
        assert!(!shuts(&fleet.poll(&with(0, 5), secs(t0, 106.0))));
        assert!(!shuts(&fleet.poll(&with(0, 6), secs(t0, 115.9))));
        assert!(shuts(&fleet.poll(&with(0, 7), secs(t0, 116.0))));
        // Once.
        assert!(!shuts(&fleet.poll(&with(0, 8), secs(t0, 200.0))));
    }

    #[test]
    fn a_failed_call_is_made_again() {
        let t0 = Instant::now();
        let mut fleet = Fleet::new(config(), "ab12");
        let one = load(vec![room("room-1", 1, 1)]);
        let calls = fleet.poll(&one, t0);
        for call in &calls {
            fleet.failed(call);
        }
        let again = fleet.poll(&one, secs(t0, 0.1));
        let without_health: Vec<&Call> = calls.iter().filter(|c| **c != Call::Health).collect();
        let again: Vec<&Call> = again.iter().collect();
        assert_eq!(again, without_health);
        // A failed removal is retried too.
        let calls = fleet.poll(&load(vec![]), secs(t0, 0.2));
        assert!(calls.contains(&Call::ListRemove("room-1".into())));
        fleet.failed(&Call::ListRemove("room-1".into()));
        let calls = fleet.poll(&load(vec![]), secs(t0, 0.3));
        assert_eq!(calls, [Call::ListRemove("room-1".into())]);
    }
}
