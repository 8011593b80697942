//! A congestion window with a floor, for self-paced game traffic.
//!
//! # Why
//! ledge sends a few kilobytes per second each way, paced by the game (60
//! inputs and 30 snapshots a second), never a bulk transfer. During an
//! outage (a blackout of a few seconds), QUIC's loss recovery collapses the
//! congestion window to its minimum while both ends keep queueing
//! datagrams. When the link returns, quinn 0.11 does not send an ACK on its
//! own while datagrams wait behind a full window (the ACK would ride in the
//! same blocked packet), so an end answers the other's probes only when its
//! own probe timer fires: after an exponentially backed-off delay that
//! reached 3-5 s after a 5 s blackout in our end-to-end test
//! (`tests/tests/e2e/conditioned.rs`). With a window that never drops below
//! [`WINDOW_FLOOR`], both ends resume within one round trip (measured:
//! 40-60 ms after the link returned).
//!
//! The floor never lets a burst out in practice: the game's own rate is
//! what limits the traffic, far below a floor's worth per round trip. Above
//! the floor, Cubic governs as usual.

use std::any::Any;
use std::sync::Arc;
use std::time::Instant;

use quinn::congestion::{Controller, ControllerFactory, Cubic, CubicConfig};
use quinn_proto::RttEstimator;

/// The smallest congestion window, bytes (1 MiB: far above the game's
/// bytes per round trip, so loss never stalls it).
pub const WINDOW_FLOOR: u64 = 1 << 20;

/// Cubic with a window that never drops below [`WINDOW_FLOOR`].
#[derive(Debug, Clone)]
pub struct GameWindow {
    inner: Cubic,
}

impl Controller for GameWindow {
    fn on_sent(&mut self, now: Instant, bytes: u64, last_packet_number: u64) {
        self.inner.on_sent(now, bytes, last_packet_number)
    }

    fn on_ack(
        &mut self,
        now: Instant,
        sent: Instant,
        bytes: u64,
        app_limited: bool,
        rtt: &RttEstimator,
    ) {
        self.inner.on_ack(now, sent, bytes, app_limited, rtt)
    }

    fn on_end_acks(
        &mut self,
        now: Instant,
        in_flight: u64,
        app_limited: bool,
        largest_packet_num_acked: Option<u64>,
    ) {
        self.inner
            .on_end_acks(now, in_flight, app_limited, largest_packet_num_acked)
    }

    fn on_congestion_event(
        &mut self,
        now: Instant,
        sent: Instant,
        is_persistent_congestion: bool,
        lost_bytes: u64,
    ) {
        self.inner
            .on_congestion_event(now, sent, is_persistent_congestion, lost_bytes)
    }

    fn on_mtu_update(&mut self, new_mtu: u16) {
        self.inner.on_mtu_update(new_mtu)
    }

    fn window(&self) -> u64 {
        self.inner.window().max(WINDOW_FLOOR)
    }

    fn clone_box(&self) -> Box<dyn Controller> {
        Box::new(self.clone())
    }

    fn initial_window(&self) -> u64 {
        self.inner.initial_window().max(WINDOW_FLOOR)
    }

    fn into_any(self: Box<Self>) -> Box<dyn Any> {
        self
    }
}

/// Builds a [`GameWindow`] per connection.
#[derive(Debug, Default)]
pub struct GameWindowFactory {
    cubic: Arc<CubicConfig>,
}

impl ControllerFactory for GameWindowFactory {
    fn build(self: Arc<Self>, now: Instant, current_mtu: u16) -> Box<dyn Controller> {
        Box::new(GameWindow {
            inner: Cubic::new(self.cubic.clone(), now, current_mtu),
        })
    }
}

/// Installs [`GameWindow`] as `transport`'s congestion controller.
pub fn install(transport: &mut quinn::TransportConfig) -> &mut quinn::TransportConfig {
    transport.congestion_controller_factory(Arc::new(GameWindowFactory::default()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window() -> Box<dyn Controller> {
        Arc::new(GameWindowFactory::default()).build(Instant::now(), 1200)
    }

    #[test]
    fn losses_never_shrink_the_window_below_the_floor() {
        let mut w = window();
        assert_eq!(w.initial_window(), WINDOW_FLOOR);
        let t0 = Instant::now();
        for k in 0..20 {
            w.on_congestion_event(t0, t0, k % 2 == 0, 100_000);
        }
        assert_eq!(w.window(), WINDOW_FLOOR);
    }

    #[test]
    fn plain_cubic_collapses_under_the_same_losses() {
        // The reason for the floor: Cubic alone drops to a few packets.
        let mut c: Box<dyn Controller> =
            Arc::new(CubicConfig::default()).build(Instant::now(), 1200);
        let t0 = Instant::now();
        c.on_congestion_event(t0, t0, true, 100_000);
        assert!(c.window() < 10_000, "cubic window {}", c.window());
    }
}
