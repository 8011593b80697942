//! The relay's counters: shared atomics the flows add to
//! (`Counters`) and the plain figures read from them ([`RelayStats`]).

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::link::Verdict;

/// Which way a packet goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// Client to server.
    Up,
    /// Server to client.
    Down,
}

/// What happened to the packets of one direction, all clients together.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DirectionStats {
    /// Packets received from the sender.
    pub received: u64,
    /// Copies sent on (duplicates count twice).
    pub forwarded: u64,
    /// Lost by the loss model.
    pub lost: u64,
    /// Dropped by a blackout.
    pub blackout: u64,
    /// Dropped because a queue was full (or too many clients).
    pub overflow: u64,
    /// Packets sent twice.
    pub duplicated: u64,
    /// Packets held back to be reordered.
    pub reordered: u64,
    /// Sends the socket refused.
    pub send_errors: u64,
}

impl DirectionStats {
    /// Every packet dropped, for any reason.
    pub fn dropped(&self) -> u64 {
        self.lost + self.blackout + self.overflow
    }
}

impl fmt::Display for DirectionStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "received {} forwarded {} dropped {} (lost {}, blackout {}, overflow {}) \
             duplicated {} reordered {} send errors {}",
            self.received,
            self.forwarded,
            self.dropped(),
            self.lost,
            self.blackout,
            self.overflow,
            self.duplicated,
            self.reordered,
            self.send_errors
        )
    }
}

/// Both directions, and how many clients the relay serves.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RelayStats {
    /// Client to server.
    pub up: DirectionStats,
    /// Server to client.
    pub down: DirectionStats,
    /// Clients with a flow open now.
    pub clients: u64,
}

impl RelayStats {
    /// One direction's figures.
    pub fn direction(&self, d: Direction) -> DirectionStats {
        match d {
            Direction::Up => self.up,
            Direction::Down => self.down,
        }
    }
}

/// One direction's atomics.
#[derive(Debug, Default)]
struct Atomics {
    received: AtomicU64,
    forwarded: AtomicU64,
    lost: AtomicU64,
    blackout: AtomicU64,
    overflow: AtomicU64,
    duplicated: AtomicU64,
    reordered: AtomicU64,
    send_errors: AtomicU64,
}

impl Atomics {
    fn read(&self) -> DirectionStats {
        let get = |a: &AtomicU64| a.load(Ordering::Relaxed);
        DirectionStats {
            received: get(&self.received),
            forwarded: get(&self.forwarded),
            lost: get(&self.lost),
            blackout: get(&self.blackout),
            overflow: get(&self.overflow),
            duplicated: get(&self.duplicated),
            reordered: get(&self.reordered),
            send_errors: get(&self.send_errors),
        }
    }
}

/// The counters every flow of a relay adds to.
#[derive(Debug, Default)]
pub(crate) struct Counters {
    up: Atomics,
    down: Atomics,
    clients: AtomicU64,
}

fn inc(a: &AtomicU64) {
    a.fetch_add(1, Ordering::Relaxed);
}

impl Counters {
    fn of(&self, d: Direction) -> &Atomics {
        match d {
            Direction::Up => &self.up,
            Direction::Down => &self.down,
        }
    }

    /// A packet arrived and the link judged it.
    pub(crate) fn judged(&self, d: Direction, verdict: Verdict) {
        let a = self.of(d);
        inc(&a.received);
        match verdict {
            Verdict::Queued {
                copies, reordered, ..
            } => {
                if copies > 1 {
                    inc(&a.duplicated);
                }
                if reordered {
                    inc(&a.reordered);
                }
            }
            Verdict::Lost => inc(&a.lost),
            Verdict::Blackout => inc(&a.blackout),
            Verdict::Overflow => inc(&a.overflow),
        }
    }

    /// A packet arrived and was dropped before reaching a link (its
    /// client's queue was full, or there were too many clients).
    pub(crate) fn overflowed(&self, d: Direction) {
        let a = self.of(d);
        inc(&a.received);
        inc(&a.overflow);
    }

    /// A copy was sent on (`ok`) or the socket refused it.
    pub(crate) fn sent(&self, d: Direction, ok: bool) {
        let a = self.of(d);
        inc(if ok { &a.forwarded } else { &a.send_errors });
    }

    /// How many clients have a flow now.
    pub(crate) fn set_clients(&self, n: usize) {
        self.clients.store(n as u64, Ordering::Relaxed);
    }

    /// The figures now.
    pub(crate) fn read(&self) -> RelayStats {
        RelayStats {
            up: self.up.read(),
            down: self.down.read(),
            clients: self.clients.load(Ordering::Relaxed),
        }
    }
}
