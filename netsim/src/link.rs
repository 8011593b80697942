//! One direction of an impaired link, sans IO: [`Link`] decides each
//! packet's fate and holds it until it is due. Time is passed in, so the
//! model runs as fast as a test wants and the same seed and the same calls
//! always give the same result.
//!
//! Drive it like `quinn-proto`: [`Link::push`] each packet as it arrives,
//! sleep until [`Link::poll_timeout`], then [`Link::poll`] the due packets
//! out and send them.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;
use std::time::{Duration, Instant};

use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::config::LinkConfig;
use crate::error::ConfigError;
use crate::loss::LossProcess;

/// What [`Link::push`] did with a packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// It will be delivered at `at` (`copies` times: 2 when duplicated).
    Queued {
        /// When it is due.
        at: Instant,
        /// How many copies will be delivered (1 or 2).
        copies: u8,
        /// Held back so that later packets may overtake it.
        reordered: bool,
    },
    /// Lost by the loss model.
    Lost,
    /// Dropped because the direction is blacked out.
    Blackout,
    /// Dropped because the queue was full.
    Overflow,
}

/// Counters of one direction, from its creation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// Packets pushed.
    pub pushed: u64,
    /// Copies handed out by [`Link::poll`] (duplicates count twice).
    pub delivered: u64,
    /// Packets lost by the loss model.
    pub lost: u64,
    /// Packets dropped by a blackout.
    pub blackout: u64,
    /// Packets dropped because the queue was full.
    pub overflow: u64,
    /// Packets delivered twice.
    pub duplicated: u64,
    /// Packets held back to be reordered.
    pub reordered: u64,
}

impl LinkStats {
    /// Every packet dropped, for any reason.
    pub fn dropped(&self) -> u64 {
        self.lost + self.blackout + self.overflow
    }
}

/// A packet waiting for its delivery time; ordered by time, then by the
/// order it was queued in (so equal times stay first in, first out).
#[derive(Debug)]
struct InFlight<T> {
    at: Instant,
    seq: u64,
    packet: T,
}

impl<T> PartialEq for InFlight<T> {
    fn eq(&self, other: &Self) -> bool {
        (self.at, self.seq) == (other.at, other.seq)
    }
}
impl<T> Eq for InFlight<T> {}
impl<T> PartialOrd for InFlight<T> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl<T> Ord for InFlight<T> {
    fn cmp(&self, other: &Self) -> Ordering {
        (self.at, self.seq).cmp(&(other.at, other.seq))
    }
}

/// One direction of an impaired link carrying packets of type `T`.
///
/// Each pushed packet is, in this order: dropped if the direction is
/// blacked out, lost by the [`crate::Loss`] model, dropped if `capacity`
/// packets are already in flight, or else given a delivery time (see
/// [`LinkConfig`] for the delay, jitter and reordering rules) and
/// duplicated with the configured probability. A blackout drops what is
/// pushed while it lasts; packets already in flight still arrive.
#[derive(Debug)]
pub struct Link<T> {
    config: LinkConfig,
    rng: Pcg64Mcg,
    loss: LossProcess,
    blackout: bool,
    capacity: usize,
    queue: BinaryHeap<Reverse<InFlight<T>>>,
    seq: u64,
    /// The latest delivery time of an in-order packet: later in-order
    /// packets never arrive before it.
    last_at: Option<Instant>,
    stats: LinkStats,
}

/// The default bound on packets in flight in one direction.
pub const DEFAULT_CAPACITY: usize = 4096;

impl<T: Clone> Link<T> {
    /// A link with `config`, its random draws seeded by `seed`, holding at
    /// most [`DEFAULT_CAPACITY`] packets in flight.
    pub fn new(config: LinkConfig, seed: u64) -> Result<Link<T>, ConfigError> {
        config.validate()?;
        Ok(Link {
            config,
            rng: Pcg64Mcg::seed_from_u64(seed),
            loss: LossProcess::new(),
            blackout: false,
            capacity: DEFAULT_CAPACITY,
            queue: BinaryHeap::new(),
            seq: 0,
            last_at: None,
            stats: LinkStats::default(),
        })
    }

    /// The same link holding at most `capacity` packets in flight (at
    /// least 1).
    pub fn with_capacity(mut self, capacity: usize) -> Link<T> {
        self.capacity = capacity.max(1);
        self
    }

    /// The configuration in force.
    pub fn config(&self) -> &LinkConfig {
        &self.config
    }

    /// Replaces the configuration from the next packet on (packets in
    /// flight keep their times). The loss model's state is kept.
    pub fn set_config(&mut self, config: LinkConfig) -> Result<(), ConfigError> {
        config.validate()?;
        self.config = config;
        Ok(())
    }

    /// Starts (`true`) or ends a blackout: while on, every packet pushed is
    /// dropped.
    pub fn set_blackout(&mut self, on: bool) {
        self.blackout = on;
    }

    /// Whether the direction is blacked out.
    pub fn blackout(&self) -> bool {
        self.blackout
    }

    /// The counters so far.
    pub fn stats(&self) -> LinkStats {
        self.stats
    }

    /// Packets in flight (copies count separately).
    pub fn len(&self) -> usize {
        self.queue.len()
    }

    /// Whether nothing is in flight.
    pub fn is_empty(&self) -> bool {
        self.queue.is_empty()
    }

    /// A packet arrives at the link at `now` (which must not go backwards
    /// between calls); returns its fate.
    pub fn push(&mut self, now: Instant, packet: T) -> Verdict {
        self.stats.pushed += 1;
        if self.blackout {
            self.stats.blackout += 1;
            return Verdict::Blackout;
        }
        let c = self.config;
        if self.loss.lose(&c.loss, &mut self.rng) {
            self.stats.lost += 1;
            return Verdict::Lost;
        }
        // Draw everything before the capacity check, so a full queue does
        // not shift the random sequence of later packets.
        let (jitter, duplicate, reorder) = (
            self.rng.random::<f64>(),
            self.rng.random::<f64>(),
            self.rng.random::<f64>(),
        );
        let copies: u8 = if duplicate < c.duplicate { 2 } else { 1 };
        if self.queue.len() + usize::from(copies) > self.capacity {
            self.stats.overflow += 1;
            return Verdict::Overflow;
        }
        let delay = jittered(c.latency, c.jitter, jitter);
        let reordered = reorder < c.reorder;
        let at = if reordered {
            now + delay + c.reorder_delay
        } else {
            let at = self
                .last_at
                .map_or(now + delay, |last| (now + delay).max(last));
            self.last_at = Some(at);
            at
        };
        self.stats.reordered += u64::from(reordered);
        self.stats.duplicated += u64::from(copies == 2);
        for _ in 1..copies {
            self.enqueue(at, packet.clone());
        }
        self.enqueue(at, packet);
        Verdict::Queued {
            at,
            copies,
            reordered,
        }
    }

    fn enqueue(&mut self, at: Instant, packet: T) {
        self.seq += 1;
        self.queue.push(Reverse(InFlight {
            at,
            seq: self.seq,
            packet,
        }));
    }

    /// When the next packet is due (`None`: nothing in flight).
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.queue.peek().map(|Reverse(p)| p.at)
    }

    /// The next packet due at or before `now`, if any.
    pub fn poll(&mut self, now: Instant) -> Option<T> {
        if self.poll_timeout()? > now {
            return None;
        }
        let Reverse(p) = self.queue.pop()?;
        self.stats.delivered += 1;
        Some(p.packet)
    }
}

/// `latency` moved by `u` (uniform in `[0, 1)`) across `[-jitter,
/// +jitter]`, never below zero.
fn jittered(latency: Duration, jitter: Duration, u: f64) -> Duration {
    let secs = latency.as_secs_f64() + (2.0 * u - 1.0) * jitter.as_secs_f64();
    Duration::from_secs_f64(secs.max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loss::Loss;

    const N: u64 = 200_000;
    const EVERY: Duration = Duration::from_millis(10);

    /// Pushes `n` numbered packets 10 ms apart; returns the verdicts and
    /// the delivery order (packet numbers, copies included).
    fn run(config: LinkConfig, seed: u64, n: u64) -> (Vec<Verdict>, Vec<u64>) {
        run_from(Instant::now(), config, seed, n)
    }

    fn run_from(t0: Instant, config: LinkConfig, seed: u64, n: u64) -> (Vec<Verdict>, Vec<u64>) {
        let mut link = Link::new(config, seed).unwrap();
        let mut verdicts = Vec::new();
        let mut order = Vec::new();
        for i in 0..n {
            let now = t0 + EVERY * i as u32;
            while let Some(p) = link.poll(now) {
                order.push(p);
            }
            verdicts.push(link.push(now, i));
        }
        while let Some(at) = link.poll_timeout() {
            order.push(link.poll(at).unwrap());
        }
        assert!(link.is_empty());
        let s = link.stats();
        assert_eq!(s.pushed, n);
        assert_eq!(s.delivered, order.len() as u64);
        (verdicts, order)
    }

    fn lost_fraction(verdicts: &[Verdict]) -> f64 {
        let lost = verdicts.iter().filter(|v| **v == Verdict::Lost).count();
        lost as f64 / verdicts.len() as f64
    }

    #[test]
    fn the_same_seed_gives_the_same_fates() {
        let c = LinkConfig::delay(Duration::from_millis(50))
            .with_jitter(Duration::from_millis(20))
            .with_loss(Loss::bursts(0.1, 3.0))
            .with_duplicate(0.05)
            .with_reorder(0.05, Duration::from_millis(30));
        let t0 = Instant::now();
        assert_eq!(run_from(t0, c, 7, 5000), run_from(t0, c, 7, 5000));
        assert_ne!(run_from(t0, c, 7, 5000).0, run_from(t0, c, 8, 5000).0);
    }

    #[test]
    fn bernoulli_loss_matches_its_probability() {
        for p in [0.01, 0.05, 0.3] {
            let c = LinkConfig::PERFECT.with_loss(Loss::Bernoulli { p });
            let (verdicts, order) = run(c, 1, N);
            let rate = lost_fraction(&verdicts);
            // Binomial standard deviation is at most 0.0011 here: 5 sigma.
            assert!((rate - p).abs() < 0.005, "p {p}: lost {rate}");
            assert_eq!(order.len() as f64, N as f64 * (1.0 - rate));
        }
    }

    #[test]
    fn gilbert_elliott_loss_matches_the_stationary_rate() {
        let models = [
            Loss::bursts(0.05, 4.0),
            Loss::GilbertElliott {
                p_good_to_bad: 0.02,
                p_bad_to_good: 0.25,
                loss_in_good: 0.01,
                loss_in_bad: 0.6,
            },
        ];
        for loss in models {
            let (verdicts, _) = run(LinkConfig::PERFECT.with_loss(loss), 2, N);
            let rate = lost_fraction(&verdicts);
            let expected = loss.expected_rate();
            // Bursts are correlated: allow 10% relative error.
            assert!(
                (rate - expected).abs() < expected * 0.1,
                "{loss:?}: lost {rate}, expected {expected}"
            );
        }
    }

    /// Lengths of the runs of consecutive losses.
    fn bursts(verdicts: &[Verdict]) -> Vec<usize> {
        let mut runs = Vec::new();
        let mut current = 0;
        for v in verdicts {
            if *v == Verdict::Lost {
                current += 1;
            } else if current > 0 {
                runs.push(current);
                current = 0;
            }
        }
        runs
    }

    fn mean(xs: &[usize]) -> f64 {
        xs.iter().sum::<usize>() as f64 / xs.len() as f64
    }

    #[test]
    fn gilbert_elliott_loss_is_bursty() {
        for burst in [2.0, 5.0] {
            let loss = Loss::bursts(0.05, burst);
            let (verdicts, _) = run(LinkConfig::PERFECT.with_loss(loss), 3, N);
            let runs = bursts(&verdicts);
            let m = mean(&runs);
            assert!(
                (m - burst).abs() < burst * 0.1,
                "mean burst {m}, expected {burst}"
            );
        }
        // Random loss at the same rate: bursts of about 1 / (1 - p).
        let c = LinkConfig::PERFECT.with_loss(Loss::Bernoulli { p: 0.05 });
        let m = mean(&bursts(&run(c, 3, N).0));
        assert!((m - 1.0 / 0.95).abs() < 0.03, "random loss bursts {m}");
    }

    #[test]
    fn delay_stays_within_latency_plus_or_minus_jitter() {
        let (latency, jitter) = (Duration::from_millis(75), Duration::from_millis(25));
        let c = LinkConfig::delay(latency).with_jitter(jitter);
        let mut link = Link::new(c, 4).unwrap();
        let t0 = Instant::now();
        let (mut lo, mut hi) = (Duration::MAX, Duration::ZERO);
        for i in 0..N as u32 {
            // Packets 1 to 20 ms apart: some closer than the jitter.
            let now = t0 + Duration::from_millis(u64::from(i) * 10 + u64::from(i % 3) * 5);
            let Verdict::Queued { at, copies: 1, .. } = link.push(now, ()) else {
                panic!("nothing else is configured");
            };
            let delay = at - now;
            assert!(
                delay >= latency - jitter && delay <= latency + jitter,
                "{delay:?}"
            );
            lo = lo.min(delay);
            hi = hi.max(delay);
            while link.poll(now).is_some() {}
        }
        // The whole range is used.
        assert!(lo < latency - jitter + Duration::from_millis(1), "{lo:?}");
        assert!(hi > latency + jitter - Duration::from_millis(1), "{hi:?}");
    }

    #[test]
    fn jitter_alone_never_reorders() {
        let c = LinkConfig::delay(Duration::from_millis(20))
            .with_jitter(Duration::from_millis(20))
            .with_loss(Loss::Bernoulli { p: 0.1 });
        let (_, order) = run(c, 5, N);
        assert!(order.windows(2).all(|w| w[0] < w[1]), "out of order");
    }

    #[test]
    fn duplication_matches_its_probability() {
        let c = LinkConfig::delay(Duration::from_millis(5)).with_duplicate(0.02);
        let (verdicts, order) = run(c, 6, N);
        let dup = verdicts
            .iter()
            .filter(|v| matches!(v, Verdict::Queued { copies: 2, .. }))
            .count() as u64;
        let rate = dup as f64 / N as f64;
        assert!((rate - 0.02).abs() < 0.002, "duplicated {rate}");
        assert_eq!(order.len() as u64, N + dup);
        // Copies arrive together, in order.
        assert!(order.windows(2).all(|w| w[0] <= w[1]));
    }

    #[test]
    fn reordering_matches_its_probability() {
        // Held back 25 ms while packets come every 10 ms: each reordered
        // packet is overtaken by the next two.
        let c = LinkConfig::delay(Duration::from_millis(30))
            .with_reorder(0.03, Duration::from_millis(25));
        let mut link = Link::new(c, 7).unwrap();
        let t0 = Instant::now();
        let mut held = 0u64;
        let mut order = Vec::new();
        for i in 0..N {
            let now = t0 + EVERY * i as u32;
            while let Some(p) = link.poll(now) {
                order.push(p);
            }
            if let Verdict::Queued {
                reordered: true, ..
            } = link.push(now, i)
            {
                held += 1;
            }
        }
        while let Some(at) = link.poll_timeout() {
            order.push(link.poll(at).unwrap());
        }
        let rate = held as f64 / N as f64;
        assert!((rate - 0.03).abs() < 0.003, "reordered {rate}");
        assert_eq!(link.stats().reordered, held);
        // A packet arrives after one sent later exactly when it was held
        // back (or is the last of a run of held back ones).
        let late = order.windows(2).filter(|w| w[0] > w[1]).count() as u64;
        assert!(late > 0 && late <= held, "{late} inversions, {held} held");
        assert!(late as f64 > held as f64 * 0.9, "{late} of {held}");
        assert_eq!(order.len() as u64, N);
    }

    #[test]
    fn a_blackout_drops_everything_until_it_ends() {
        let mut link = Link::new(LinkConfig::delay(Duration::from_millis(10)), 8).unwrap();
        let t0 = Instant::now();
        assert!(matches!(link.push(t0, 1), Verdict::Queued { .. }));
        link.set_blackout(true);
        assert_eq!(link.push(t0, 2), Verdict::Blackout);
        // What was in flight still arrives.
        assert_eq!(link.poll(t0 + Duration::from_millis(10)), Some(1));
        link.set_blackout(false);
        assert!(matches!(link.push(t0, 3), Verdict::Queued { .. }));
        let s = link.stats();
        assert_eq!((s.pushed, s.blackout, s.delivered), (3, 1, 1));
    }

    #[test]
    fn a_full_queue_drops_and_counts() {
        let mut link = Link::new(LinkConfig::delay(Duration::from_secs(1)), 9)
            .unwrap()
            .with_capacity(3);
        let t0 = Instant::now();
        for i in 0..5 {
            link.push(t0, i);
        }
        assert_eq!(link.len(), 3);
        assert_eq!(link.stats().overflow, 2);
        assert_eq!(link.poll(t0), None, "not due yet");
        assert_eq!(link.poll(t0 + Duration::from_secs(1)), Some(0));
    }

    #[test]
    fn a_bad_config_is_refused() {
        let bad = LinkConfig::PERFECT.with_reorder(-0.1, Duration::ZERO);
        assert!(Link::<()>::new(bad, 0).is_err());
        let mut link = Link::<()>::new(LinkConfig::PERFECT, 0).unwrap();
        assert!(link.set_config(bad).is_err());
        assert_eq!(*link.config(), LinkConfig::PERFECT);
    }
}
