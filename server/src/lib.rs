//! `ledge-server`: the authoritative server of ledge.
//!
//! A QUIC endpoint (quinn, rustls with ring) serving one room that owns the
//! deterministic world from `ledge-shared` and steps it on a drift-free
//! fixed-step loop. The binary is a thin CLI around [`Server`]; tests start
//! the same server in-process on `127.0.0.1:0`.
//!
//! * [`config`]: settings ([`ServerConfig`]);
//! * [`cert`] / [`fingerprint`]: the self-signed identity clients pin;
//! * [`tls`]: QUIC/TLS endpoint configuration;
//! * [`protocol`] / [`framing`]: control messages and their frames (shared
//!   with the client library until the protocol moves into `ledge-shared`);
//! * [`clock`]: the absolute tick schedule;
//! * [`room`]: the world and its tick loop;
//! * [`connection`]: one client's handshake and control stream;
//! * [`server`]: the endpoint, accept loop and graceful shutdown.
#![deny(missing_docs)]

pub mod cert;
pub mod clock;
pub mod config;
pub mod connection;
pub mod fingerprint;
pub mod framing;
pub mod protocol;
pub mod room;
pub mod server;
pub mod tls;

pub use config::ServerConfig;
pub use fingerprint::Fingerprint;
pub use server::{Server, ServerError, ShutdownHandle};
