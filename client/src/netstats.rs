//! Measuring the connection: round-trip time, jitter, loss, snapshot rate,
//! bytes per second, corrections.
//!
//! Sans-IO: everything is fed with the instant it happened
//! ([`StatsTracker::snapshot`], [`StatsTracker::transport`],
//! [`StatsTracker::correction`]) and its getters read the figures over the
//! last second or two ([`crate::game::ClientGame::net_stats`] gathers them).

use std::collections::VecDeque;
use std::time::Duration;

use crate::time::Instant;

/// Window of the rate figures.
const RATE_WINDOW: Duration = Duration::from_secs(1);
/// Window of the loss figure.
const LOSS_WINDOW: Duration = Duration::from_secs(3);

/// Totals of the transport, read from QUIC (quinn's connection stats).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TransportSample {
    /// UDP payload bytes received so far.
    pub bytes_in: u64,
    /// UDP payload bytes sent so far.
    pub bytes_out: u64,
    /// QUIC's smoothed round-trip time.
    pub rtt: Duration,
}

impl TransportSample {
    #[cfg(not(target_arch = "wasm32"))]
    /// Reads a quinn connection's totals.
    pub fn of(connection: &quinn::Connection) -> TransportSample {
        let s = connection.stats();
        TransportSample {
            bytes_in: s.udp_rx.bytes,
            bytes_out: s.udp_tx.bytes,
            rtt: connection.rtt(),
        }
    }
}

/// Folds events into the figures of [`crate::view::NetStats`].
#[derive(Debug, Clone)]
pub struct StatsTracker {
    rate: f64,
    interval: u64,
    /// (arrival, tick, the tick the server sent before it) of recent
    /// snapshots.
    snapshots: VecDeque<(Instant, u64, Option<u64>)>,
    /// Transit time of the previous snapshot, ticks (RFC 3550).
    last_transit: Option<f64>,
    epoch: Option<Instant>,
    /// Jitter estimate, ticks.
    jitter: f64,
    transport: VecDeque<(Instant, TransportSample)>,
    rtt: Option<Duration>,
    corrections: VecDeque<Instant>,
    last_correction_px: f32,
}

impl StatsTracker {
    /// A tracker for snapshots every `interval` ticks at `tick_rate` Hz.
    pub fn new(tick_rate: u32, interval: u32) -> StatsTracker {
        StatsTracker {
            rate: f64::from(tick_rate.max(1)),
            interval: u64::from(interval.max(1)),
            snapshots: VecDeque::new(),
            last_transit: None,
            epoch: None,
            jitter: 0.0,
            transport: VecDeque::new(),
            rtt: None,
            corrections: VecDeque::new(),
            last_correction_px: 0.0,
        }
    }

    /// A snapshot of `tick` arrived at `at`; the server had sent
    /// `previous` before it ([`crate::net::session::SnapshotUpdate::previous_tick`]).
    pub fn snapshot(&mut self, tick: u64, previous: Option<u64>, at: Instant) {
        let epoch = *self.epoch.get_or_insert(at);
        let transit = at.saturating_duration_since(epoch).as_secs_f64() * self.rate - tick as f64;
        if let Some(last) = self.last_transit {
            let d = (transit - last).abs();
            self.jitter += (d - self.jitter) / 16.0;
        }
        self.last_transit = Some(transit);
        self.snapshots.push_back((at, tick, previous));
        while self
            .snapshots
            .front()
            .is_some_and(|&(t, _, _)| at.saturating_duration_since(t) > LOSS_WINDOW)
        {
            self.snapshots.pop_front();
        }
    }

    /// The transport's totals at `at`.
    pub fn transport(&mut self, sample: TransportSample, at: Instant) {
        self.rtt = Some(sample.rtt);
        self.transport.push_back((at, sample));
        while self.transport.len() > 2
            && self
                .transport
                .get(1)
                .is_some_and(|&(t, _)| at.saturating_duration_since(t) >= RATE_WINDOW)
        {
            self.transport.pop_front();
        }
    }

    /// A measured round-trip time (a ping).
    pub fn rtt(&mut self, rtt: Duration) {
        self.rtt = Some(rtt);
    }

    /// A correction of `px` pixels at `at`.
    pub fn correction(&mut self, px: f32, at: Instant) {
        self.last_correction_px = px;
        self.corrections.push_back(at);
        while self
            .corrections
            .front()
            .is_some_and(|&t| at.saturating_duration_since(t) > RATE_WINDOW)
        {
            self.corrections.pop_front();
        }
    }

    /// Whether a snapshot of the last second came after snapshots the
    /// server skipped because nothing changed for us (a quiet connection:
    /// a few a second).
    pub fn quiet(&self, now: Instant) -> bool {
        self.snapshots.iter().any(|&(at, tick, previous)| {
            now.saturating_duration_since(at) <= RATE_WINDOW
                && previous.is_some_and(|p| tick.saturating_sub(p) > self.interval)
        })
    }

    /// Snapshot arrival jitter, ticks (RFC 3550 estimator).
    pub fn jitter_ticks(&self) -> f64 {
        self.jitter
    }

    /// The latest round-trip time.
    pub fn latest_rtt(&self) -> Option<Duration> {
        self.rtt
    }

    /// Snapshots received over the last second.
    pub fn snapshot_hz(&self, now: Instant) -> f64 {
        self.snapshots
            .iter()
            .filter(|&&(t, _, _)| now.saturating_duration_since(t) <= RATE_WINDOW)
            .count() as f64
            / RATE_WINDOW.as_secs_f64()
    }

    /// Fraction of the snapshots the server sent over the last seconds that
    /// did not arrive (or arrived too late to be used). Each snapshot names
    /// the one sent before it: one that never came was lost, and so were
    /// the snapshot intervals between it and the last one received before
    /// it (a server sending every interval). Gaps the server left on
    /// purpose (nothing changed) are not loss.
    pub fn loss(&self) -> f64 {
        let mut ticks: Vec<u64> = self.snapshots.iter().map(|&(_, t, _)| t).collect();
        ticks.sort_unstable();
        ticks.dedup();
        let Some(&first) = ticks.first() else {
            return 0.0;
        };
        let mut lost = 0;
        for &(_, tick, previous) in &self.snapshots {
            let Some(p) = previous.filter(|&p| p > first && p < tick) else {
                continue;
            };
            if let Err(i) = ticks.binary_search(&p) {
                // `p > first`, so a received tick lies before it.
                lost += (p - ticks[i - 1]).div_ceil(self.interval);
            }
        }
        let expected = (ticks.len() as u64 + lost) as f64;
        (lost as f64 / expected).clamp(0.0, 1.0)
    }

    /// (in, out) bytes per second over the last second.
    pub fn bytes_per_s(&self) -> (f64, f64) {
        let (Some((t0, a)), Some((t1, b))) = (self.transport.front(), self.transport.back()) else {
            return (0.0, 0.0);
        };
        let dt = t1.saturating_duration_since(*t0).as_secs_f64();
        if dt <= 0.0 {
            return (0.0, 0.0);
        }
        (
            b.bytes_in.saturating_sub(a.bytes_in) as f64 / dt,
            b.bytes_out.saturating_sub(a.bytes_out) as f64 / dt,
        )
    }

    /// Corrections over the last second.
    pub fn corrections_per_s(&self, now: Instant) -> f64 {
        self.corrections
            .iter()
            .filter(|&&t| now.saturating_duration_since(t) <= RATE_WINDOW)
            .count() as f64
            / RATE_WINDOW.as_secs_f64()
    }

    /// The size of the last correction, pixels.
    pub fn last_correction_px(&self) -> f32 {
        self.last_correction_px
    }

    /// Milliseconds per tick.
    pub fn tick_ms(&self) -> f64 {
        1000.0 / self.rate
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_loss_and_jitter() {
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        let mut s = StatsTracker::new(60, 2);
        // 30 Hz snapshots for 2 s, every fifth lost, arrivals regular.
        for i in 0..60u64 {
            if i % 5 != 4 {
                s.snapshot(2 * i, (2 * i).checked_sub(2), at(i * 100 / 3));
            }
            s.transport(
                TransportSample {
                    bytes_in: i * 100,
                    bytes_out: i * 50,
                    rtt: Duration::from_millis(20),
                },
                at(i * 100 / 3),
            );
        }
        let now = at(59 * 100 / 3);
        assert!((s.loss() - 0.2).abs() < 0.03, "{}", s.loss());
        assert!(
            (s.snapshot_hz(now) - 24.0).abs() <= 1.0,
            "{}",
            s.snapshot_hz(now)
        );
        let (i, o) = s.bytes_per_s();
        assert!(
            (i - 3000.0).abs() < 150.0 && (o - 1500.0).abs() < 75.0,
            "{i} {o}"
        );
        assert!(s.jitter_ticks() < 0.1, "{}", s.jitter_ticks());
        s.correction(3.0, now);
        s.correction(5.0, now);
        assert_eq!(s.corrections_per_s(now), 2.0);
        assert_eq!(s.corrections_per_s(now + Duration::from_secs(2)), 0.0);
        assert_eq!(s.last_correction_px(), 5.0);

        // Snapshots the server skipped (their successor names the one before
        // them) are not lost; two in a row lost are two.
        let mut q = StatsTracker::new(60, 2);
        q.snapshot(10, Some(8), at(0));
        q.snapshot(34, Some(10), at(400));
        q.snapshot(58, Some(34), at(800));
        assert_eq!(q.loss(), 0.0, "skipped, not lost");
        assert!(q.quiet(at(800)));
        assert!(!q.quiet(at(2000)), "only the last second counts");
        q.snapshot(64, Some(62), at(900));
        assert!(
            (q.loss() - 2.0 / 6.0).abs() < 1e-9,
            "60 and 62: {}",
            q.loss()
        );
        assert!(q.quiet(at(900)), "58 came after a gap");
        assert!(!q.quiet(at(1900)), "64 came an interval after 62");

        // Arrivals alternating 0 and 20 ms late: |D| = 1.2 ticks each time.
        let mut j = StatsTracker::new(60, 2);
        for i in 0..200u64 {
            let late = if i % 2 == 0 { 0 } else { 20 };
            j.snapshot(2 * i, None, at(i * 100 / 3 + late));
        }
        assert!(
            (j.jitter_ticks() - 1.2).abs() < 0.15,
            "{}",
            j.jitter_ticks()
        );
    }
}
