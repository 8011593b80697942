//! Server settings (what the command line sets).

use std::net::SocketAddr;
use std::path::PathBuf;

/// Default UDP address the server listens on.
pub const DEFAULT_BIND: &str = "0.0.0.0:4433";
/// Default directory of the certificate and key.
pub const DEFAULT_CERT_DIR: &str = "certs";
/// Default simulation rate in Hz.
pub const DEFAULT_TICK_RATE: u32 = 60;
/// Default bound on ticks run back to back after a stall (0.25 s at 60 Hz).
pub const DEFAULT_MAX_CATCH_UP: u32 = 15;

/// Everything [`crate::Server::bind`] needs.
#[derive(Debug, Clone)]
pub struct ServerConfig {
    /// UDP address to listen on; port 0 picks a free port (tests).
    pub bind: SocketAddr,
    /// Where the certificate and key are kept (created if missing).
    pub cert_dir: PathBuf,
    /// Simulation ticks per second.
    pub tick_rate: u32,
    /// Most ticks run back to back after a stall; older ones are skipped.
    pub max_catch_up: u32,
}

impl Default for ServerConfig {
    fn default() -> ServerConfig {
        ServerConfig {
            bind: SocketAddr::from(([0, 0, 0, 0], 4433)),
            cert_dir: PathBuf::from(DEFAULT_CERT_DIR),
            tick_rate: DEFAULT_TICK_RATE,
            max_catch_up: DEFAULT_MAX_CATCH_UP,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_bind_matches_the_documented_one() {
        assert_eq!(ServerConfig::default().bind, DEFAULT_BIND.parse().unwrap());
    }
}
