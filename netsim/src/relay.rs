//! The UDP relay: clients send to [`Relay::local_addr`] instead of the
//! server; each client gets its own upstream socket (so the server tells
//! clients apart, and several share one relay) and its own pair of
//! [`crate::Link`]s, configured and blacked out live from the [`Relay`]
//! handle.

use std::collections::HashMap;
use std::net::{Ipv4Addr, Ipv6Addr, SocketAddr};
use std::sync::Arc;
use std::time::Duration;

use tokio::net::UdpSocket;
use tokio::sync::{mpsc, watch};
use tokio::task::{JoinHandle, JoinSet};

use crate::config::LinkConfig;
use crate::counters::{Counters, Direction, RelayStats};
use crate::error::{ConfigError, RelayError};
use crate::flow::{Flow, Settings};
use crate::link::DEFAULT_CAPACITY;

/// How a relay starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelayConfig {
    /// Client to server.
    pub up: LinkConfig,
    /// Server to client.
    pub down: LinkConfig,
    /// Seed of the random draws (client `n`, counting from 0 in order of
    /// first packet, uses `seed + n`).
    pub seed: u64,
    /// Packets in flight per client and direction, at most; more are
    /// dropped and counted as overflow.
    pub queue: usize,
    /// Clients served at once, at most; packets from more are dropped.
    pub max_clients: usize,
    /// A client with no traffic either way for this long is forgotten
    /// (its upstream socket closed).
    pub idle: Duration,
}

impl Default for RelayConfig {
    fn default() -> RelayConfig {
        RelayConfig {
            up: LinkConfig::PERFECT,
            down: LinkConfig::PERFECT,
            seed: 1,
            queue: DEFAULT_CAPACITY,
            max_clients: 256,
            idle: Duration::from_secs(60),
        }
    }
}

impl RelayConfig {
    /// The same `link` both ways.
    pub fn symmetric(link: LinkConfig) -> RelayConfig {
        RelayConfig {
            up: link,
            down: link,
            ..RelayConfig::default()
        }
    }
}

/// Datagrams from one client waiting for its flow task, at most.
const CLIENT_CHANNEL: usize = 1024;

/// A running relay; stopped when dropped.
#[derive(Debug)]
pub struct Relay {
    addr: SocketAddr,
    server: SocketAddr,
    settings: watch::Sender<Settings>,
    counters: Arc<Counters>,
    task: JoinHandle<()>,
}

impl Relay {
    /// Binds `listen` and relays to `server` with `config`. Call inside a
    /// tokio runtime.
    pub async fn start(
        listen: SocketAddr,
        server: SocketAddr,
        config: RelayConfig,
    ) -> Result<Relay, RelayError> {
        config.up.validate()?;
        config.down.validate()?;
        let socket = Arc::new(UdpSocket::bind(listen).await?);
        let addr = socket.local_addr()?;
        let (settings, watching) = watch::channel(Settings {
            up: config.up,
            down: config.down,
            blackout_up: false,
            blackout_down: false,
        });
        let counters = Arc::new(Counters::default());
        let task = tokio::spawn(serve(socket, server, config, watching, counters.clone()));
        Ok(Relay {
            addr,
            server,
            settings,
            counters,
            task,
        })
    }

    /// Where clients send instead of the server.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// Where the relay sends.
    pub fn server_addr(&self) -> SocketAddr {
        self.server
    }

    /// Replaces one direction's configuration (packets in flight keep
    /// their times).
    pub fn set_link(&self, direction: Direction, config: LinkConfig) -> Result<(), ConfigError> {
        config.validate()?;
        self.settings.send_modify(|s| match direction {
            Direction::Up => s.up = config,
            Direction::Down => s.down = config,
        });
        Ok(())
    }

    /// Replaces both directions' configurations.
    pub fn set_links(&self, up: LinkConfig, down: LinkConfig) -> Result<(), ConfigError> {
        up.validate()?;
        down.validate()?;
        self.settings.send_modify(|s| {
            s.up = up;
            s.down = down;
        });
        Ok(())
    }

    /// The configuration of `direction` in force.
    pub fn link(&self, direction: Direction) -> LinkConfig {
        let s = self.settings.borrow();
        match direction {
            Direction::Up => s.up,
            Direction::Down => s.down,
        }
    }

    /// Starts (`true`) or ends a blackout of `direction`: every packet
    /// that way is dropped while it lasts.
    pub fn set_blackout(&self, direction: Direction, on: bool) {
        self.settings.send_modify(|s| match direction {
            Direction::Up => s.blackout_up = on,
            Direction::Down => s.blackout_down = on,
        });
    }

    /// Blacks out both directions (`true`) or restores them.
    pub fn set_blackout_both(&self, on: bool) {
        self.settings.send_modify(|s| {
            s.blackout_up = on;
            s.blackout_down = on;
        });
    }

    /// The counters so far.
    pub fn stats(&self) -> RelayStats {
        self.counters.read()
    }
}

impl Drop for Relay {
    fn drop(&mut self) {
        // The flows live in the task's JoinSet: they end with it.
        self.task.abort();
    }
}

/// An unbound address of the server's family, for upstream sockets.
fn any_port_for(server: SocketAddr) -> SocketAddr {
    match server {
        SocketAddr::V4(a) if a.ip().is_loopback() => (Ipv4Addr::LOCALHOST, 0).into(),
        SocketAddr::V4(_) => (Ipv4Addr::UNSPECIFIED, 0).into(),
        SocketAddr::V6(a) if a.ip().is_loopback() => (Ipv6Addr::LOCALHOST, 0).into(),
        SocketAddr::V6(_) => (Ipv6Addr::UNSPECIFIED, 0).into(),
    }
}

/// Receives from clients and hands each datagram to its client's flow,
/// opening flows as clients appear and forgetting them when they end.
async fn serve(
    socket: Arc<UdpSocket>,
    server: SocketAddr,
    config: RelayConfig,
    settings: watch::Receiver<Settings>,
    counters: Arc<Counters>,
) {
    let mut flows: HashMap<SocketAddr, mpsc::Sender<Vec<u8>>> = HashMap::new();
    let mut tasks: JoinSet<SocketAddr> = JoinSet::new();
    let mut opened: u64 = 0;
    let mut buf = vec![0u8; 65_536];
    loop {
        let (n, from) = tokio::select! {
            r = socket.recv_from(&mut buf) => match r {
                Ok(got) => got,
                // ICMP errors from a client that went away: keep serving.
                Err(e) => {
                    tracing::debug!("relay receive: {e}");
                    continue;
                }
            },
            Some(ended) = tasks.join_next() => {
                if let Ok(client) = ended {
                    // Unless a newer flow for the same client took its place.
                    if flows.get(&client).is_some_and(|tx| tx.is_closed()) {
                        flows.remove(&client);
                    }
                    tracing::debug!(%client, "client flow ended");
                }
                counters.set_clients(flows.len());
                continue;
            }
        };
        let packet = buf[..n].to_vec();
        if let Some(tx) = flows.get(&from) {
            match tx.try_send(packet) {
                Ok(()) => {}
                Err(mpsc::error::TrySendError::Full(_)) => counters.overflowed(Direction::Up),
                // The flow ended (idle): this packet is lost, the next one
                // opens a new flow.
                Err(mpsc::error::TrySendError::Closed(_)) => {
                    counters.overflowed(Direction::Up);
                    flows.remove(&from);
                    counters.set_clients(flows.len());
                }
            }
            continue;
        }
        if flows.len() >= config.max_clients {
            counters.overflowed(Direction::Up);
            continue;
        }
        let upstream = match open_upstream(server).await {
            Ok(u) => u,
            Err(e) => {
                tracing::warn!("relay upstream socket: {e}");
                counters.overflowed(Direction::Up);
                continue;
            }
        };
        let (tx, rx) = mpsc::channel(CLIENT_CHANNEL);
        // Cannot fail: the channel is new and open.
        let _ = tx.try_send(packet);
        flows.insert(from, tx);
        counters.set_clients(flows.len());
        tracing::debug!(client = %from, "client flow opened");
        let flow = Flow {
            client: from,
            upstream,
            listen: socket.clone(),
            from_client: rx,
            settings: settings.clone(),
            counters: counters.clone(),
            seed: config.seed.wrapping_add(opened),
            capacity: config.queue,
            idle: config.idle,
        };
        opened += 1;
        tasks.spawn(flow.run());
    }
}

async fn open_upstream(server: SocketAddr) -> std::io::Result<UdpSocket> {
    let upstream = UdpSocket::bind(any_port_for(server)).await?;
    upstream.connect(server).await?;
    Ok(upstream)
}
