//! `ledge-client`: connecting to a ledge server, headless.
//!
//! Everything here runs without a window, so bots and tests use it
//! directly; the macroquad front end (the `ledge-client` binary, feature
//! `gui`) is a thin layer on top. The wire protocol is
//! [`ledge_shared::protocol`].
//!
//! * [`view`]: what a front end draws ([`view::FrameView`]) and shows
//!   ([`view::NetStats`]): the stable API of the front end;
//! * [`game`]: the client's game, sans IO ([`game::ClientGame`]), and its
//!   parts: prediction and reconciliation ([`game::predict`]), remote
//!   players drawn in the past ([`game::interp`]), the synchronised local
//!   clock ([`game::clock`]: [`SyncClock`], [`InputClock`]);
//! * [`net`]: talking to a server: the network as a front end sees it
//!   ([`net::Network`], [`net::NetEvent`], [`net::NetStatus`]), the
//!   session ([`net::session`]: the protocol sans IO, [`SessionState`],
//!   and its QUIC driver, [`Session`]), dialing ([`net::transport`]),
//!   trusting the certificate ([`net::trust`], [`net::verifier`]), the
//!   browser page's sans-IO session ([`net::page_session`]), the network
//!   thread ([`net::background`]), a networked game for a GUI
//!   ([`net::online`], [`OnlineGame`]), and the server's level
//!   ([`net::levels`], [`net::download`], [`net::bundle`]);
//! * [`ghost`]: a run to race against, played from its replay;
//! * [`follow`]: whom a watching camera follows, and cycling through the
//!   players (replays and spectators);
//! * [`netstats`]: RTT, jitter, loss, rates;
//! * [`replay`]: a replay as a front end shows it ([`replay::ReplayViewer`]:
//!   speeds, pauses, seeking, whom the camera follows; its frames as
//!   [`view::FrameView`]s);
//! * [`bot`]: headless bots (idle, random walker, route runner,
//!   misbehaving);
//! * [`time`]: the clock type, native or the browser's;
//! * [`rng`]: a seedable generator (bots, effects);
//! * [`error`]: what can fail ([`ClientError`]).
//!
//! Presentation only the window needs (how players look from frame to
//! frame, the sound effects and their player, which sounds a frame cues)
//! lives in the front end, not here.
//!
//! The modules with sockets, threads or files (`bot`, and in `net`
//! `background`, `bundle`, `transport`, `trust`, `verifier`, the QUIC
//! session) are native only; the rest also builds for
//! `wasm32-unknown-unknown`, for the browser front end.
//!
//! `docs/CLIENT.md` describes the design and the figures.
#![deny(missing_docs)]

#[cfg(not(target_arch = "wasm32"))]
pub mod bot;
pub mod error;
pub mod follow;
pub mod game;
pub mod ghost;
pub mod net;
pub mod netstats;
pub mod replay;
pub mod rng;
pub mod time;
pub mod view;

pub use error::ClientError;
pub use game::clock::{InputClock, SyncClock};
pub use game::ClientGame;
pub use ledge_shared::protocol::Fingerprint;
pub use net::online::OnlineGame;
#[cfg(not(target_arch = "wasm32"))]
pub use net::online::OnlineRequest;
#[cfg(not(target_arch = "wasm32"))]
pub use net::session::{connect, connect_with, handshake, list_rooms, Session};
pub use net::session::{JoinOptions, SessionEvent, SessionState, SessionStats, SnapshotUpdate};
#[cfg(not(target_arch = "wasm32"))]
pub use net::trust::{connect_trusted, dial_trusted, list_rooms_trusted, Trust};
pub use view::{EntityDraw, Facing, FrameView, NetStats, PlayerDraw};
