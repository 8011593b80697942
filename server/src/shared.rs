//! The state every connection task shares ([`Shared`]): the rooms, the
//! sessions kept for a resume, the level bundle, metrics, per-client
//! limits, player ids, admission and the shutdown flag.
//!
//! Separate from [`crate::connection`] because the server, the web port and
//! the Agones driver use it too: here it depends only on the low-level
//! modules it holds, and none of its users has to import another.

use std::sync::atomic::AtomicU32;
use std::sync::Arc;

use tokio::sync::watch;

use crate::admission::Admission;
use crate::config::Limits;
use crate::levels::LevelSet;
use crate::metrics::Metrics;
use crate::records::RecordsHandle;
use crate::room_registry::Rooms;
use crate::sessions::Sessions;

/// What every connection task shares.
#[derive(Debug)]
pub struct Shared {
    /// The open rooms.
    pub rooms: Rooms,
    /// Sessions, for resuming a lost connection's player.
    pub sessions: Sessions,
    /// The levels played, whose bundles clients download
    /// ([`ClientControl::GetLevel`](ledge_shared::protocol::ClientControl::GetLevel)).
    pub levels: LevelSet,
    /// Metrics.
    pub metrics: Arc<Metrics>,
    /// Per-client limits.
    pub limits: Limits,
    /// The next player id.
    pub next_player: AtomicU32,
    /// Who may connect, and the pending pool ([`crate::admission`]).
    pub admission: Arc<Admission>,
    /// Turns true when the server shuts down.
    pub shutdown: watch::Receiver<bool>,
    /// The records: where rooms send finished runs, and what the web port
    /// reads.
    pub records: RecordsHandle,
    /// The replays folder the web port serves (`None`: replays are off).
    pub replays_dir: Option<std::path::PathBuf>,
}
