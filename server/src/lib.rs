//! `ledge-server`: the authoritative server of ledge.
//!
//! A QUIC endpoint (quinn, rustls with ring) serving rooms that each own a
//! deterministic [`ledge_shared::game::Game`] stepped on a drift-free
//! fixed-step loop. Clients send inputs in datagrams and receive
//! delta-compressed snapshots; the wire protocol is
//! [`ledge_shared::protocol`] (see `docs/PROTOCOL.md`, and `docs/SERVER.md`
//! for running and operating the server). The binary is a thin CLI around
//! [`Server`]; tests start the same server in-process on `127.0.0.1:0`.
//!
//! * [`config`]: settings, command line and TOML file ([`ServerConfig`]);
//! * [`quic_cert`] / [`fingerprint`]: the QUIC endpoint's self-signed
//!   identity, kept on disk, which clients pin;
//! * [`tls`]: QUIC/TLS endpoint configuration and buffer sizes;
//! * [`levels`]: the level played, its id and hash;
//! * [`clock`]: the absolute tick schedule;
//! * [`inputs`]: a client's bounded input buffer;
//! * [`snapshots`]: a room's snapshot history and per-client encoding;
//! * [`room_logic`]: a room's rules, sans-IO: its game, joins, resumes,
//!   ticks and what each client is sent, as actions;
//! * [`room`]: a room's task: its tick loop, the handle connections talk to
//!   it through, and its actions carried out over the clients' links;
//! * [`room_registry`]: the open rooms, opened by name up to the cap,
//!   closed when idle;
//! * [`sessions`]: players kept after a lost connection, for a resume;
//! * [`shutdown`]: the shutdown signal, its handle and the wait for it;
//! * [`shared`]: the state every connection task shares (rooms, sessions,
//!   metrics, admission, the shutdown flag);
//! * [`record`]: optional match recording (inputs, joins, hashes per tick);
//! * [`admission`]: which new connections are taken on (per address, the
//!   pending pool and its eviction, Retry under load);
//! * [`link`]: the transports (QUIC, WebTransport, WebSocket) behind one
//!   interface;
//! * [`connection`]: one client's handshake, control stream and datagrams,
//!   whatever its transport;
//! * [`web`]: browsers: the web port (page, `/web.json`, `/level`,
//!   WebSocket) and WebTransport with its rotating certificates;
//! * [`ratelimit`]: token buckets;
//! * [`metrics`]: Prometheus metrics and their HTTP endpoint;
//! * [`fleet`]: what a server in an Agones fleet reports, and when
//!   (sans-IO: counters, the rooms list, health, shutdown once allocated
//!   and empty);
//! * `agones` (cargo feature `agones`): the Agones SDK driver making the
//!   fleet logic's calls;
//! * [`server`]: the endpoint, accept loop and graceful shutdown.
#![deny(missing_docs)]

pub mod admission;
#[cfg(feature = "agones")]
pub mod agones;
pub mod clock;
pub mod config;
pub mod connection;
pub mod fingerprint;
pub mod fleet;
pub mod inputs;
pub mod levels;
pub mod link;
pub mod metrics;
pub mod quic_cert;
pub mod ratelimit;
pub mod record;
pub mod records;
pub mod replays;
pub mod room;
pub mod room_logic;
pub mod room_registry;
pub mod rotation;
pub mod server;
pub mod sessions;
pub mod shared;
pub mod shutdown;
pub mod snapshots;
pub mod tls;
pub mod web;

pub use config::ServerConfig;
pub use fingerprint::Fingerprint;
pub use server::{Server, ServerError};
pub use shutdown::ShutdownHandle;
