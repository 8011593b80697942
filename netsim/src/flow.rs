//! One client's traffic through the relay: its own upstream socket and a
//! [`Link`] each way, driven by a tokio task.

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use tokio::net::UdpSocket;
use tokio::sync::{mpsc, watch};
use tokio::time::Instant;

use crate::config::LinkConfig;
use crate::counters::{Counters, Direction};
use crate::link::Link;

/// What the relay's owner controls, shared with every flow.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Settings {
    /// Client to server.
    pub up: LinkConfig,
    /// Server to client.
    pub down: LinkConfig,
    /// Client to server blacked out.
    pub blackout_up: bool,
    /// Server to client blacked out.
    pub blackout_down: bool,
}

/// Everything a flow task needs.
#[derive(Debug)]
pub(crate) struct Flow {
    /// The client's address (the relay answers it from `listen`).
    pub client: SocketAddr,
    /// Connected to the server; the server sees the client as this.
    pub upstream: UdpSocket,
    /// The relay's listening socket.
    pub listen: Arc<UdpSocket>,
    /// Datagrams from the client.
    pub from_client: mpsc::Receiver<Vec<u8>>,
    /// The settings in force.
    pub settings: watch::Receiver<Settings>,
    /// Shared counters.
    pub counters: Arc<Counters>,
    /// Seed of this flow's links.
    pub seed: u64,
    /// Packets in flight each way, at most.
    pub capacity: usize,
    /// A flow with no traffic either way for this long ends.
    pub idle: Duration,
}

/// Packets larger than this (beyond the UDP maximum) cannot arrive.
const MAX_DATAGRAM: usize = 65_536;

/// A different stream for the downward link of a flow.
const DOWN_SEED: u64 = 0x9e37_79b9_7f4a_7c15;

impl Flow {
    /// Relays until the flow has been idle for `idle`, or the relay is
    /// gone; returns the client's address.
    pub(crate) async fn run(mut self) -> SocketAddr {
        let s = *self.settings.borrow_and_update();
        let capacity = self.capacity;
        let link = |config: LinkConfig, seed: u64, blackout: bool| {
            // Settings are validated before they are published.
            let mut link = Link::<Vec<u8>>::new(config, seed)
                .ok()?
                .with_capacity(capacity);
            link.set_blackout(blackout);
            Some(link)
        };
        let (Some(mut up), Some(mut down)) = (
            link(s.up, self.seed, s.blackout_up),
            link(s.down, self.seed ^ DOWN_SEED, s.blackout_down),
        ) else {
            return self.client;
        };
        let mut buf = vec![0u8; MAX_DATAGRAM];
        let mut active = Instant::now();
        loop {
            let idle_at = active + self.idle;
            // The next delivery, or the idle deadline when nothing is in
            // flight (a flow with packets in flight is never idle).
            let next = [up.poll_timeout(), down.poll_timeout()]
                .into_iter()
                .flatten()
                .map(Instant::from_std)
                .min()
                .unwrap_or(idle_at);
            tokio::select! {
                packet = self.from_client.recv() => {
                    let Some(packet) = packet else { break };
                    active = Instant::now();
                    let verdict = up.push(active.into_std(), packet);
                    self.counters.judged(Direction::Up, verdict);
                }
                r = self.upstream.recv(&mut buf) => {
                    // An ICMP error from the server's side: nothing arrived.
                    if let Ok(n) = r {
                        active = Instant::now();
                        let verdict = down.push(active.into_std(), buf[..n].to_vec());
                        self.counters.judged(Direction::Down, verdict);
                    }
                }
                changed = self.settings.changed() => {
                    if changed.is_err() {
                        break;
                    }
                    let s = *self.settings.borrow_and_update();
                    apply(&mut up, s.up, s.blackout_up);
                    apply(&mut down, s.down, s.blackout_down);
                }
                () = tokio::time::sleep_until(next) => {
                    if Instant::now() >= idle_at && up.is_empty() && down.is_empty() {
                        break;
                    }
                }
            }
            let now = Instant::now().into_std();
            while let Some(p) = up.poll(now) {
                let ok = self.upstream.send(&p).await.is_ok();
                self.counters.sent(Direction::Up, ok);
            }
            while let Some(p) = down.poll(now) {
                let ok = self.listen.send_to(&p, self.client).await.is_ok();
                self.counters.sent(Direction::Down, ok);
            }
        }
        self.client
    }
}

fn apply(link: &mut Link<Vec<u8>>, config: LinkConfig, blackout: bool) {
    // Settings are validated before they are published.
    if link.set_config(config).is_err() {
        tracing::warn!("invalid link settings ignored");
    }
    link.set_blackout(blackout);
}
