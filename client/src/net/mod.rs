//! The network as a game front end sees it, whatever carries it: the
//! events a driver reports ([`NetEvent`]), the status they add up to
//! ([`NetStatus`]), and what a driver offers ([`Network`]).
//!
//! Natively the driver is the background thread
//! ([`crate::net::background::NetThread`], QUIC); in a browser it is the
//! page's WebTransport or WebSocket, driven from the page's frames. Either
//! way [`crate::net::online::OnlineGame`] turns the events into the predicted
//! game.
//!
//! Everything about talking to a server lives in this directory, below the
//! game ([`crate::game`]) and the bots:
//!
//! * [`session`]: the handshake, inputs out, snapshots and control
//!   messages in: the protocol sans IO ([`session::SessionState`]) and its
//!   QUIC driver ([`session::Session`]);
//! * [`transport`]: resolve and dial a server over QUIC;
//! * [`trust`]: pinned fingerprints and trust on first use (known hosts);
//! * [`verifier`]: the certificate verifier behind both;
//! * [`page_session`]: the browser page's session, over a transport
//!   driven from outside (the browser's WebTransport or WebSocket), sans
//!   IO ([`page_session::PageSession`]);
//! * [`background`]: the network on its own thread, for GUI front ends;
//! * [`online`]: a networked game for a GUI ([`online::OnlineGame`]);
//! * [`levels`]: the server's level, checked by hash;
//! * [`download`]: a level download checked, sans IO;
//! * [`bundle`]: the server's level downloaded, cached by hash.
//!
//! The modules with sockets, threads or files (`background`, `bundle`,
//! `transport`, `trust`, `verifier`, the QUIC session) are native only.

#[cfg(not(target_arch = "wasm32"))]
pub mod background;
#[cfg(not(target_arch = "wasm32"))]
pub mod bundle;
pub mod download;
pub mod levels;
pub mod online;
pub mod page_session;
pub mod session;
#[cfg(not(target_arch = "wasm32"))]
pub mod transport;
#[cfg(not(target_arch = "wasm32"))]
pub mod trust;
#[cfg(not(target_arch = "wasm32"))]
pub mod verifier;

use std::collections::BTreeMap;
use std::fmt;
use std::time::Duration;

use ledge_levels::LevelBundle;
use ledge_shared::input::Buttons;
use ledge_shared::protocol::{GhostRun, LevelList, NoticeKind, PlayerId, Standing, Welcome};

use crate::net::download::Fetched;
use crate::net::session::{SessionEvent, SnapshotUpdate};
use crate::netstats::TransportSample;

/// A network driver, polled once per frame by
/// [`crate::net::online::OnlineGame`]. Nothing here blocks.
pub trait Network {
    /// The next event, if any.
    fn try_recv(&mut self) -> Option<NetEvent>;
    /// Sends our buttons for `tick` (once per simulated tick); `false` if
    /// it was dropped.
    fn send_input(&mut self, tick: u64, buttons: Buttons) -> bool;
    /// Says `text` in the room; `false` if it could not be queued.
    fn chat(&mut self, text: &str) -> bool;
    /// Votes for the level the room plays next (an index into the
    /// [`NetEvent::Levels`] list); `false` if it could not be queued.
    fn vote(&mut self, level: u32) -> bool;
    /// The transport's byte counters and round-trip time, when known.
    fn transport(&self) -> Option<TransportSample>;
    /// Who is in our room, by id (us included), as last heard.
    fn players(&self) -> BTreeMap<PlayerId, String>;
}

/// What a network driver reports (the background thread natively, the
/// page's transport in a browser).
#[derive(Debug, Clone, PartialEq)]
pub enum NetEvent {
    /// Downloading the server's level: `got` of `total` bytes.
    LevelProgress {
        /// Bytes so far (a resumed download starts above 0).
        got: u64,
        /// The level's size.
        total: u64,
    },
    /// The server's level (natively with
    /// `background::NetOptions::download_level`), just
    /// before [`NetEvent::Connected`]; or the room's next level, just
    /// before [`NetEvent::LevelChanged`].
    Level(Box<LevelBundle>, Fetched),
    /// The server welcomed us.
    Connected(Welcome),
    /// A fresh round-trip measurement.
    Rtt(Duration),
    /// A new authoritative snapshot, decoded.
    Snapshot(SnapshotUpdate),
    /// A chat line from a player in our room.
    Chat {
        /// Who said it.
        from: PlayerId,
        /// The line.
        text: String,
    },
    /// A server announcement (shutdown, kick, information).
    Notice(NoticeKind),
    /// A player is in our room (from the roster after the welcome, us
    /// included, or joining later).
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
    },
    /// Our finished run is in the server's records (`Ok`: where it stands),
    /// or why not (`Err`).
    RunRecorded(Result<Standing, String>),
    /// A run to race against, as its replay ([`crate::ghost::Ghost`]).
    Ghost(Box<GhostRun>),
    /// The room's levels, votes and when it moves on (after the roster,
    /// then whenever any of it changes).
    Levels(Box<LevelList>),
    /// The room moved to another level (or a resumed session found it on
    /// another than ours): this welcome replaces the one of
    /// [`NetEvent::Connected`] (same player, the new level, the tick the
    /// level started at, its config), and the new level's
    /// [`NetEvent::Level`] came just before. Snapshots after it are of the
    /// new level.
    LevelChanged(Box<Welcome>),
    /// Connecting failed; the thread has ended.
    Failed(String),
    /// Connecting failed because the server's certificate is not the one
    /// trusted (a wrong pin, or a known host whose certificate changed);
    /// the message says what to do. The thread has ended.
    Untrusted(String),
    /// The connection was lost; reconnecting (attempt 0: just lost). Then
    /// [`NetEvent::Connected`] (the same player, if the server still kept
    /// it) or [`NetEvent::Disconnected`].
    Reconnecting {
        /// Failed attempts so far.
        attempt: u32,
    },
    /// An established session ended; the thread has ended.
    Disconnected(String),
}

impl NetEvent {
    /// The event a session's event becomes (`None`: a pong without a
    /// round-trip time, which tells a front end nothing; and a level
    /// change, which the driver turns into [`NetEvent::Level`] and
    /// [`NetEvent::LevelChanged`] once it has the new level).
    pub fn from_session(event: SessionEvent) -> Option<NetEvent> {
        Some(match event {
            SessionEvent::Snapshot(update) => NetEvent::Snapshot(update),
            SessionEvent::Chat { from, text } => NetEvent::Chat { from, text },
            SessionEvent::Notice(kind) => NetEvent::Notice(kind),
            SessionEvent::Pong { rtt: Some(rtt), .. } => NetEvent::Rtt(rtt),
            SessionEvent::Pong { rtt: None, .. } => return None,
            SessionEvent::PlayerJoined { id, name } => NetEvent::PlayerJoined { id, name },
            SessionEvent::PlayerLeft { id, .. } => NetEvent::PlayerLeft { id },
            SessionEvent::RunRecorded(r) => NetEvent::RunRecorded(r),
            SessionEvent::Ghost(g) => NetEvent::Ghost(Box::new(g)),
            SessionEvent::Levels(list) => NetEvent::Levels(Box::new(list)),
            SessionEvent::LevelChange(_) => return None,
        })
    }
}

/// What a front end shows about the network.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum NetStatus {
    /// Playing locally, no server.
    #[default]
    Offline,
    /// Connecting to the named server.
    Connecting(String),
    /// The connection was lost; reconnecting.
    Reconnecting {
        /// Failed attempts so far.
        attempt: u32,
    },
    /// Joined; downloading the server's level.
    Downloading {
        /// Bytes so far.
        got: u64,
        /// The level's size.
        total: u64,
    },
    /// Joined.
    Connected {
        /// The server's welcome.
        welcome: Welcome,
        /// The latest round-trip time, once measured.
        rtt: Option<Duration>,
    },
    /// Connecting failed, with the reason.
    Failed(String),
    /// The session ended, with the reason.
    Disconnected(String),
}

impl NetStatus {
    /// Folds one event into the status.
    pub fn apply(&mut self, event: NetEvent) {
        *self = match (std::mem::take(self), event) {
            (_, NetEvent::Connected(welcome)) => NetStatus::Connected { welcome, rtt: None },
            // On the next level (its download, if any, is over).
            (NetStatus::Connected { rtt, .. }, NetEvent::LevelChanged(welcome)) => {
                NetStatus::Connected {
                    welcome: *welcome,
                    rtt,
                }
            }
            (_, NetEvent::LevelChanged(welcome)) => NetStatus::Connected {
                welcome: *welcome,
                rtt: None,
            },
            (NetStatus::Connected { welcome, .. }, NetEvent::Rtt(rtt)) => NetStatus::Connected {
                welcome,
                rtt: Some(rtt),
            },
            (_, NetEvent::LevelProgress { got, total }) => NetStatus::Downloading { got, total },
            (_, NetEvent::Reconnecting { attempt }) => NetStatus::Reconnecting { attempt },
            (
                status,
                NetEvent::Rtt(_)
                | NetEvent::Level(..)
                | NetEvent::Snapshot(_)
                | NetEvent::Chat { .. }
                | NetEvent::Notice(_)
                | NetEvent::PlayerJoined { .. }
                | NetEvent::PlayerLeft { .. }
                | NetEvent::RunRecorded(_)
                | NetEvent::Ghost(_)
                | NetEvent::Levels(_),
            ) => status,
            (_, NetEvent::Failed(reason) | NetEvent::Untrusted(reason)) => {
                NetStatus::Failed(reason)
            }
            (_, NetEvent::Disconnected(reason)) => NetStatus::Disconnected(reason),
        };
    }
}

impl fmt::Display for NetStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NetStatus::Offline => write!(f, "offline (local simulation)"),
            NetStatus::Connecting(server) => write!(f, "connecting to {server}..."),
            NetStatus::Reconnecting { attempt: 0 } => write!(f, "connection lost: reconnecting..."),
            NetStatus::Reconnecting { attempt } => {
                write!(
                    f,
                    "connection lost: reconnecting... (attempt {})",
                    attempt + 1
                )
            }
            NetStatus::Downloading { got, total } => write!(
                f,
                "downloading the level: {} of {} KiB",
                got / 1024,
                total.div_ceil(1024)
            ),
            NetStatus::Connected { welcome, rtt } => {
                write!(
                    f,
                    "welcome, player {} in {} on {} (joined at tick {}, {} Hz)",
                    welcome.player_id,
                    welcome.room,
                    welcome.level_id,
                    welcome.server_tick,
                    welcome.timing.tick_rate
                )?;
                if let Some(rtt) = rtt {
                    write!(f, ", rtt {:.1} ms", rtt.as_secs_f64() * 1000.0)?;
                }
                Ok(())
            }
            NetStatus::Failed(reason) => write!(f, "connection failed: {reason}"),
            NetStatus::Disconnected(reason) => write!(f, "disconnected: {reason}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_shared::protocol::NetTiming;

    fn welcome() -> Welcome {
        Welcome {
            player_id: PlayerId(3),
            room: "room-1".into(),
            level_id: "level".into(),
            level_hash: 0xabc,
            level: Default::default(),
            session_token: Default::default(),
            server_tick: 10,
            timing: NetTiming {
                tick_rate: 60,
                snapshot_interval: 2,
                input_redundancy: 16,
            },
            sim_config: vec![],
        }
    }

    #[test]
    fn status_follows_events() {
        let mut status = NetStatus::Connecting("x:1".into());
        status.apply(NetEvent::Rtt(Duration::from_millis(5)));
        assert_eq!(status, NetStatus::Connecting("x:1".into()));
        status.apply(NetEvent::Connected(welcome()));
        status.apply(NetEvent::Rtt(Duration::from_millis(5)));
        status.apply(NetEvent::Chat {
            from: PlayerId(1),
            text: "hi".into(),
        });
        status.apply(NetEvent::PlayerJoined {
            id: PlayerId(1),
            name: "bo".into(),
        });
        status.apply(NetEvent::PlayerLeft { id: PlayerId(1) });
        assert_eq!(
            status,
            NetStatus::Connected {
                welcome: welcome(),
                rtt: Some(Duration::from_millis(5))
            }
        );
        let text = status.to_string();
        assert!(
            text.contains("player #3") && text.contains("rtt 5.0 ms"),
            "{text}"
        );
        status.apply(NetEvent::Disconnected("gone".into()));
        assert_eq!(status, NetStatus::Disconnected("gone".into()));
        status.apply(NetEvent::Untrusted("changed".into()));
        assert_eq!(status, NetStatus::Failed("changed".into()));
    }
}
