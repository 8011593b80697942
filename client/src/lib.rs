//! `ledge-client`: connecting to a ledge server, headless.
//!
//! Everything here runs without a window, so bots and tests use it
//! directly; the macroquad front end (the `ledge-client` binary, feature
//! `gui`) is a thin layer on top. The wire protocol is
//! [`ledge_shared::protocol`].
//!
//! * [`view`]: what a front end draws ([`view::FrameView`]) and shows
//!   ([`view::NetStats`]): the stable API of the front end;
//! * [`online`]: a networked game for a GUI ([`online::OnlineGame`]);
//! * [`game`]: the client's game, sans IO ([`game::ClientGame`]): clock,
//!   prediction, interpolation, statistics, views;
//! * [`predict`]: prediction and reconciliation ([`predict::Predictor`]);
//! * [`interp`]: remote players drawn in the past ([`interp::Interpolator`]);
//! * [`clock`]: the synchronised local clock ([`clock::SyncClock`]) and the
//!   simple [`InputClock`];
//! * [`netstats`]: RTT, jitter, loss, rates;
//! * [`bot`]: headless bots (idle, random walker, route runner,
//!   misbehaving);
//! * [`trust`]: pinned fingerprints and trust on first use (known hosts);
//! * [`verifier`]: the certificate verifier behind both;
//! * [`transport`]: resolve and dial a server over QUIC;
//! * [`session`]: the handshake, inputs out, snapshots and control messages
//!   in: the protocol sans IO ([`SessionState`]) and its QUIC driver
//!   ([`Session`]);
//! * [`time`]: the clock type, native or the browser's;
//! * [`levels`]: the server's level, checked by hash;
//! * [`bundle`]: the server's level downloaded, cached by hash;
//! * [`download`]: a level download checked, sans IO;
//! * [`link`]: a session over a transport driven from outside (the
//!   browser's WebTransport or WebSocket), sans IO ([`link::Link`]);
//! * [`net`]: the network as a front end sees it ([`net::Network`],
//!   [`net::NetEvent`], [`net::NetStatus`]), whatever carries it;
//! * [`background`]: the network on its own thread, for GUI front ends;
//! * [`rng`]: a seedable generator (bots, effects);
//! * [`audio`]: sound effects, synthesized at start, played through ALSA
//!   loaded at run time (off, never failing, without it);
//! * [`cues`]: which sound effects to play, from frame-to-frame changes of
//!   our player (so rollbacks never replay one);
//! * [`anim`]: how players look from frame to frame ([`anim::Animator`]:
//!   run, jump, fall, landing squash, wall slide), and stacked players
//!   fanned out ([`anim::spread`]);
//! * [`error`]: what can fail ([`ClientError`]).
//!
//! The modules with sockets, threads, files or ALSA (`background`, `bot`,
//! `bundle`, `online`, `transport`, `trust`, `verifier`, the QUIC session,
//! the ALSA player) are native only; the rest also builds for
//! `wasm32-unknown-unknown`, for the browser front end.
//!
//! `docs/CLIENT.md` describes the design and the figures.
#![deny(missing_docs)]

pub mod anim;
pub mod audio;
#[cfg(not(target_arch = "wasm32"))]
pub mod background;
#[cfg(not(target_arch = "wasm32"))]
pub mod bot;
#[cfg(not(target_arch = "wasm32"))]
pub mod bundle;
pub mod clock;
pub mod cues;
pub mod download;
pub mod error;
pub mod game;
pub mod interp;
pub mod levels;
pub mod link;
pub mod net;
pub mod netstats;
pub mod online;
pub mod predict;
pub mod rng;
pub mod session;
pub mod time;
#[cfg(not(target_arch = "wasm32"))]
pub mod transport;
#[cfg(not(target_arch = "wasm32"))]
pub mod trust;
#[cfg(not(target_arch = "wasm32"))]
pub mod verifier;
pub mod view;

pub use clock::{InputClock, SyncClock};
pub use error::ClientError;
pub use game::ClientGame;
pub use ledge_shared::protocol::Fingerprint;
pub use online::OnlineGame;
#[cfg(not(target_arch = "wasm32"))]
pub use online::OnlineRequest;
#[cfg(not(target_arch = "wasm32"))]
pub use session::{connect, connect_with, handshake, list_rooms, Session};
pub use session::{JoinOptions, SessionEvent, SessionState, SessionStats, SnapshotUpdate};
#[cfg(not(target_arch = "wasm32"))]
pub use trust::{connect_trusted, dial_trusted, list_rooms_trusted, Trust};
pub use view::{EntityDraw, Facing, FrameView, NetStats, PlayerDraw};
