//! A joined session: the handshake, then inputs out and snapshots and
//! control messages in.
//!
//! The protocol is sans IO, like `quinn-proto`: [`SessionState`] ([`state`])
//! turns bytes of the control stream and datagrams into [`SessionEvent`]s
//! and our inputs into datagrams, and [`Handshake`] reads the server's
//! first answer. Drivers own the sockets and the clock:
//!
//! * [`Session`] (native, [`quic`]): QUIC through quinn, driven by its
//!   caller (no task of its own): call [`Session::send_input`] once per
//!   tick, and [`Session::recv`] in a loop (or in a `select!`: it is
//!   cancel-safe);
//! * the browser's WebTransport or WebSocket, through the web front end's
//!   glue.
//!
//! Snapshots are decoded against the session's own
//! [`ledge_shared::protocol::SnapshotHistory`] and every input packet
//! acknowledges the newest one, so the server's next deltas are against
//! it. The room's roster (who is in it, by name) is kept, at most
//! [`ledge_shared::protocol::MAX_ROSTER`] names.

use std::time::Duration;

use ledge_shared::protocol::{
    ClientControl, GhostRun, LevelList, NoticeKind, PlayerId, SessionToken, Standing,
    StateSnapshot, Welcome, PROTOCOL_VERSION,
};

use crate::time::Instant;

#[cfg(not(target_arch = "wasm32"))]
pub mod quic;
pub mod state;

#[cfg(not(target_arch = "wasm32"))]
pub use quic::{connect, connect_with, handshake, list_rooms, Session};
pub use state::{Handshake, SessionState};

/// How long the server has to answer a hello or a ping.
pub const REPLY_TIMEOUT: Duration = Duration::from_secs(5);

/// Snapshots kept to decode deltas against: more than the server keeps as
/// baselines (64), so any delta it sends can be decoded.
pub const SNAPSHOT_HISTORY: usize = 128;

/// How to join.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct JoinOptions {
    /// Our player name (1..=32 bytes, no control characters).
    pub player_name: String,
    /// The room to join; `None`: the server picks the least full one.
    pub room: Option<String>,
    /// Resume the session this token names (a lost connection's player:
    /// same id, position, coins); an unknown or expired one joins as new.
    pub resume: Option<SessionToken>,
    /// Watch rather than play ([`ClientControl::Spectate`]): no body, no
    /// player's place; `room` is the room to watch.
    pub spectate: bool,
}

impl JoinOptions {
    /// Joins any room as `player_name`.
    pub fn new(player_name: &str) -> JoinOptions {
        JoinOptions {
            player_name: player_name.to_owned(),
            room: None,
            resume: None,
            spectate: false,
        }
    }

    /// The hello these options send.
    pub fn hello(&self) -> ClientControl {
        if self.spectate {
            return ClientControl::Spectate {
                version: PROTOCOL_VERSION,
                name: self.player_name.clone(),
                room: self.room.clone(),
            };
        }
        if let Some(token) = self.resume {
            return ClientControl::Resume {
                version: PROTOCOL_VERSION,
                name: self.player_name.clone(),
                room: self.room.clone(),
                token,
            };
        }
        match &self.room {
            None => ClientControl::Hello {
                version: PROTOCOL_VERSION,
                name: self.player_name.clone(),
            },
            Some(room) => ClientControl::HelloRoom {
                version: PROTOCOL_VERSION,
                name: self.player_name.clone(),
                room: room.clone(),
            },
        }
    }
}

/// A decoded snapshot and this client's bookkeeping from the server.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SnapshotUpdate {
    /// The authoritative state at `state.tick` (every replicated entity).
    pub state: StateSnapshot,
    /// The snapshot it was a delta against (`None`: it came in full).
    pub baseline_tick: Option<u64>,
    /// The snapshot the server sent us before it (`None`: the first); more
    /// than an interval back, the server skipped those between because
    /// nothing changed ([`ledge_shared::protocol::Snapshot::since_previous`]).
    pub previous_tick: Option<u64>,
    /// Newest tick of our input the server had applied (`None` before the
    /// first): inputs after it are not in `state` yet.
    pub last_input_tick: Option<u64>,
    /// How early (+) or late (-), in ticks, our inputs arrive at the server:
    /// the server's figure for a datagram's newest tick, less the ticks it
    /// brings that were due earlier ([`state::input_interval`] - 1), so
    /// that clocks steering by it keep every tick early.
    pub input_timing: i16,
    /// Whether it came on the control stream (too big for a datagram).
    pub via_stream: bool,
    /// Encoded size in bytes.
    pub wire_bytes: usize,
    /// When it was received and decoded (for jitter and interpolation).
    pub received: Instant,
}

/// Something the server sent.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SessionEvent {
    /// A new authoritative state (never older than the previous one).
    Snapshot(SnapshotUpdate),
    /// A chat line from a player in our room (ours included).
    Chat {
        /// Who said it.
        from: PlayerId,
        /// The line.
        text: String,
    },
    /// A server announcement: shutdown, kick, information.
    Notice(NoticeKind),
    /// The answer to a ping.
    Pong {
        /// The ping's nonce.
        nonce: u64,
        /// Round-trip time, if the ping was sent by this session recently.
        rtt: Option<Duration>,
    },
    /// A player is in our room: from the roster sent after the welcome
    /// (once per player, us included) or because it joined later.
    PlayerJoined {
        /// Its id.
        id: PlayerId,
        /// Its name.
        name: String,
    },
    /// A player left our room.
    PlayerLeft {
        /// Its id.
        id: PlayerId,
        /// Its name, if we knew it.
        name: Option<String>,
    },
    /// Our finished run is stored in the server's records: where it
    /// stands (`Ok`), or why it was not stored (`Err`).
    RunRecorded(Result<Standing, String>),
    /// A run to race against (the level's record or our best), as its
    /// replay ([`crate::ghost::Ghost::from_run`] plays it).
    Ghost(GhostRun),
    /// The room's levels, votes and when it moves on (after the roster on
    /// joining, then whenever any of it changes).
    Levels(LevelList),
    /// The room moved to another level: the session's welcome is now this
    /// one (the first `session_token` kept), snapshots of earlier ticks are
    /// dropped, and the new level must be had before predicting it
    /// ([`crate::net::bundle::fetch_level`] gets the latest level).
    LevelChange(Welcome),
}

/// Counters of what the session received and sent.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SessionStats {
    /// Snapshots decoded and newer than the previous one.
    pub snapshots: u64,
    /// Of those, sent in full.
    pub full_snapshots: u64,
    /// Snapshots on the control stream.
    pub stream_snapshots: u64,
    /// Snapshots older than the newest decoded (reordered), or of a level
    /// the room has left, ignored.
    pub stale_snapshots: u64,
    /// Deltas against a snapshot we no longer have, dropped.
    pub missing_baselines: u64,
    /// Datagrams or snapshots that failed to decode, dropped.
    pub malformed: u64,
    /// Roster entries ignored because
    /// [`MAX_ROSTER`](ledge_shared::protocol::MAX_ROSTER) names were known.
    pub roster_overflow: u64,
    /// Input packets sent.
    pub inputs_sent: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn join_options_choose_the_hello() {
        let any = JoinOptions::new("ada");
        assert!(matches!(any.hello(), ClientControl::Hello { .. }));
        let named = JoinOptions {
            room: Some("room-2".into()),
            ..any
        };
        assert_eq!(
            named.hello().as_hello(),
            Some((PROTOCOL_VERSION, "ada", Some("room-2")))
        );
    }
}
