//! Which tick to send inputs for: the server's tick, estimated from the
//! welcome and local time, plus a lead steered by the server's
//! `input_timing` feedback so inputs arrive slightly early.
//!
//! Two clocks:
//!
//! * [`InputClock`]: the simple first version (whole-tick lead, stepped by
//!   one tick per report), kept for tests that only send inputs;
//! * [`SyncClock`]: the smooth clock prediction runs on. Its tick advances
//!   at the server's rate scaled by a small adjustment (a few percent)
//!   steered by the server's `input_timing` feedback toward a target
//!   margin that grows with the measured jitter. It never moves backwards
//!   and never skips ticks, except forward when it is hopelessly late (the
//!   server is already past the ticks we would send).

use std::time::Duration;

use crate::time::Instant;

use ledge_shared::protocol::Welcome;

use crate::net::session::state::input_interval;

/// Ticks the oldest input of a datagram waits for it at `tick_rate`.
fn batch_wait(tick_rate: u32) -> u64 {
    input_interval(tick_rate) - 1
}

/// Default ticks the inputs are sent ahead of the estimated server tick
/// (besides the ticks they wait for their datagram).
pub const DEFAULT_LEAD: i64 = 2;
/// Input timing (ticks early) the clock steers towards.
pub const TARGET_TIMING: i16 = 2;

/// Estimates the server tick and the tick our next input is for.
#[derive(Debug, Clone)]
pub struct InputClock {
    start: Instant,
    start_tick: u64,
    tick_rate: u32,
    lead: i64,
}

impl InputClock {
    /// A clock for a session welcomed at `at` (the server was then at
    /// `welcome.server_tick`), leading by [`DEFAULT_LEAD`] plus the ticks
    /// an input waits for its datagram ([`input_interval`] - 1).
    pub fn new(welcome: &Welcome, at: Instant) -> InputClock {
        let rate = welcome.timing.tick_rate.max(1);
        InputClock {
            start: at,
            start_tick: welcome.server_tick,
            tick_rate: rate,
            lead: DEFAULT_LEAD + batch_wait(rate) as i64,
        }
    }

    /// The estimated server tick at `now`.
    pub fn server_tick(&self, now: Instant) -> u64 {
        let elapsed = now.saturating_duration_since(self.start);
        let ticks = elapsed.as_nanos() * u128::from(self.tick_rate) / 1_000_000_000;
        self.start_tick
            .saturating_add(u64::try_from(ticks).unwrap_or(u64::MAX))
    }

    /// The tick to send our input for at `now`: the server tick plus the
    /// lead.
    pub fn input_tick(&self, now: Instant) -> u64 {
        self.server_tick(now).saturating_add_signed(self.lead)
    }

    /// The current lead in ticks.
    pub fn lead(&self) -> i64 {
        self.lead
    }

    /// Steers the lead by one tick towards [`TARGET_TIMING`] given the
    /// server's report (late inputs: lead more; very early: lead less).
    pub fn observe(&mut self, input_timing: i16) {
        if input_timing < TARGET_TIMING - 1 {
            self.lead = (self.lead + 1).min(i64::from(self.tick_rate));
        } else if input_timing > TARGET_TIMING + 2 {
            self.lead = (self.lead - 1).max(0);
        }
    }

    /// How long until the next tick starts, from `now`.
    pub fn until_next_tick(&self, now: Instant) -> Duration {
        let elapsed = now.saturating_duration_since(self.start).as_nanos();
        let rate = u128::from(self.tick_rate);
        let next = (elapsed * rate / 1_000_000_000 + 1) * 1_000_000_000;
        let at = next.div_ceil(rate);
        Duration::from_nanos(u64::try_from(at - elapsed).unwrap_or(u64::MAX))
    }
}

/// Margin (ticks early) the [`SyncClock`] aims for with no jitter.
pub const BASE_MARGIN: f64 = 1.0;
/// Ticks of margin added per tick of measured jitter.
pub const JITTER_MARGIN: f64 = 2.0;
/// Most extra input datagrams of margin for loss (each worth the ticks
/// between two datagrams, [`input_interval`]).
pub const MAX_LOSS_MARGIN: f64 = 4.0;
/// Largest target margin, ticks.
pub const MAX_MARGIN: f64 = 12.0;
/// Speed adjustment per tick of error (0.015: 1.5% faster per tick late).
pub const CLOCK_GAIN: f64 = 0.015;
/// Largest speed adjustment while the error is small (5%).
pub const MAX_ADJUST: f64 = 0.05;
/// Largest speed adjustment when the error is over [`FAR_ERROR`] ticks.
pub const MAX_ADJUST_FAR: f64 = 0.2;
/// Error beyond which the clock may change speed by [`MAX_ADJUST_FAR`].
pub const FAR_ERROR: f64 = 6.0;
/// Late by more than this many ticks: catch up at once (forward).
pub const CATCH_UP: f64 = 15.0;
/// Weight of a new `input_timing` report in the smoothed margin.
const TIMING_SMOOTHING: f64 = 0.15;
/// Error (ticks) under which the speed stays nominal: the reports are
/// whole ticks, so smaller errors are quantisation noise.
const DEAD_BAND: f64 = 0.25;

/// The local simulation clock: a fractional tick that advances at the
/// server's rate times `1 + adjust`, with `adjust` steered so our inputs
/// reach the server [`SyncClock::target_margin`] ticks before it needs them.
///
/// Time is passed in (`now`), so it is deterministic under test.
#[derive(Debug, Clone)]
pub struct SyncClock {
    rate: f64,
    /// The local tick position (ticks, fractional).
    pos: f64,
    at: Instant,
    adjust: f64,
    /// Smoothed `input_timing` (ticks early), once reported.
    margin: Option<f64>,
    /// Measured jitter, ticks.
    jitter: f64,
    /// Margin with no jitter, ticks.
    base: f64,
    /// Extra margin for loss, ticks.
    loss_margin: f64,
    target: f64,
    /// After a catch-up jump: no other jump before this position (reports
    /// in flight still describe inputs sent before the jump).
    holdoff: f64,
}

impl SyncClock {
    /// A clock at tick `pos` at `now`, advancing at `tick_rate` Hz.
    pub fn new(pos: f64, tick_rate: u32, now: Instant) -> SyncClock {
        SyncClock {
            rate: f64::from(tick_rate.max(1)),
            pos,
            at: now,
            adjust: 0.0,
            margin: None,
            jitter: 0.0,
            base: BASE_MARGIN,
            loss_margin: 0.0,
            target: BASE_MARGIN,
            holdoff: f64::MIN,
        }
    }

    /// A clock for a session welcomed at `now`: the server was at
    /// `welcome.server_tick` about half a round trip ago, and our inputs
    /// need another half to arrive, plus the margin and the ticks an input
    /// waits for its datagram ([`input_interval`] - 1).
    pub fn for_welcome(welcome: &Welcome, rtt: Duration, now: Instant) -> SyncClock {
        let rate = welcome.timing.tick_rate.max(1);
        let lead =
            rtt.as_secs_f64() * f64::from(rate) + BASE_MARGIN + 1.0 + batch_wait(rate) as f64;
        SyncClock::new(welcome.server_tick as f64 + lead, rate, now)
    }

    /// Advances to `now` (earlier instants are ignored: never backwards)
    /// and returns the position.
    pub fn advance(&mut self, now: Instant) -> f64 {
        if now > self.at {
            let dt = (now - self.at).as_secs_f64();
            self.pos += dt * self.rate * (1.0 + self.adjust);
            self.at = now;
        }
        self.pos
    }

    /// The fractional tick position (as of the last [`SyncClock::advance`]).
    pub fn position(&self) -> f64 {
        self.pos
    }

    /// The tick whose input is due next: `floor(position)` ticks have
    /// started.
    pub fn tick(&self) -> u64 {
        self.pos.max(0.0) as u64
    }

    /// How far into the current tick, in [0, 1).
    pub fn alpha(&self) -> f32 {
        (self.pos - self.pos.floor()) as f32
    }

    /// Nominal ticks per second.
    pub fn rate(&self) -> f64 {
        self.rate
    }

    /// The speed adjustment in force (+0.03: 3% fast).
    pub fn adjust(&self) -> f64 {
        self.adjust
    }

    /// The smoothed input margin reported by the server, ticks.
    pub fn margin(&self) -> Option<f64> {
        self.margin
    }

    /// The margin steered towards, ticks.
    pub fn target_margin(&self) -> f64 {
        self.target
    }

    /// Sets the measured network jitter (ticks); the target margin follows.
    pub fn set_jitter(&mut self, jitter_ticks: f64) {
        self.jitter = jitter_ticks.max(0.0);
        self.retarget();
    }

    /// Sets the margin kept with no jitter (default [`BASE_MARGIN`]), ticks:
    /// more trades latency for tolerance of hiccups (a loaded machine).
    pub fn set_base_margin(&mut self, ticks: f64) {
        let base = ticks.clamp(0.0, MAX_MARGIN);
        if self.margin.is_none() && base > self.base {
            // No feedback yet: start with the larger lead right away.
            self.pos += base - self.base;
        }
        self.base = base;
        self.retarget();
    }

    /// Sets the measured loss (fraction). Each input datagram repeats the
    /// previous ticks, so a lost one is recovered by the next, one
    /// datagram interval later ([`input_interval`]: 2 ticks at 60 Hz): with
    /// loss `p`, the margin grows by `k` intervals such that `k + 1`
    /// datagrams in a row are lost with probability under 0.1% (1% loss:
    /// one interval, 10%: 2, 30%: 4), at most [`MAX_LOSS_MARGIN`]
    /// intervals. (Counted in ticks, as when every tick had its datagram,
    /// the margin at 60 Hz covered one lost datagram fewer than it meant
    /// to: through `tests/e2e/impaired.rs`'s relay, 10% loss each way, 11 of
    /// 7,200 ticks arrived late.)
    pub fn set_loss(&mut self, loss: f64) {
        let datagrams = if loss <= 0.001 {
            0.0
        } else if loss >= 0.5 {
            MAX_LOSS_MARGIN
        } else {
            ((0.001f64.ln() / loss.ln()).ceil() - 1.0).clamp(0.0, MAX_LOSS_MARGIN)
        };
        // `rate` is a whole number of ticks a second.
        self.loss_margin = datagrams * input_interval(self.rate as u32) as f64;
        self.retarget();
    }

    fn retarget(&mut self) {
        self.target = (self.base + JITTER_MARGIN * self.jitter + self.loss_margin).min(MAX_MARGIN);
    }

    /// Takes one `input_timing` report (ticks early, + or late, -) and
    /// steers the speed. Returns how many ticks the clock jumped forward
    /// (only when later than [`CATCH_UP`] ticks; 0 otherwise).
    pub fn observe(&mut self, input_timing: i16) -> f64 {
        let report = f64::from(input_timing);
        if report < -CATCH_UP {
            if self.pos < self.holdoff {
                // Sent before the last jump: already dealt with.
                return 0.0;
            }
            // Hopeless: the server starves on our inputs. Jump forward to
            // the target and restart the smoothing; reports arriving
            // during the next second describe inputs sent before the jump.
            let jump = self.target - report;
            self.pos += jump;
            self.holdoff = self.pos + self.rate;
            self.margin = None;
            self.adjust = 0.0;
            return jump;
        }
        let m = match self.margin {
            None => report,
            Some(m) => m + (report - m) * TIMING_SMOOTHING,
        };
        self.margin = Some(m);
        let error = m - self.target;
        let limit = if error.abs() > FAR_ERROR {
            MAX_ADJUST_FAR
        } else {
            MAX_ADJUST
        };
        self.adjust = if error.abs() < DEAD_BAND {
            0.0
        } else {
            (-CLOCK_GAIN * error).clamp(-limit, limit)
        };
        0.0
    }

    /// Moves forward to at least `tick` (never backwards); returns how far
    /// it moved.
    pub fn catch_up_to(&mut self, tick: f64) -> f64 {
        if tick > self.pos {
            let d = tick - self.pos;
            self.pos = tick;
            d
        } else {
            0.0
        }
    }

    /// When the next whole tick starts, from `now`.
    pub fn until_next_tick(&self, now: Instant) -> Duration {
        let pos = if now > self.at {
            self.pos + (now - self.at).as_secs_f64() * self.rate * (1.0 + self.adjust)
        } else {
            self.pos
        };
        let left = (pos.floor() + 1.0 - pos) / (self.rate * (1.0 + self.adjust));
        Duration::from_secs_f64(left.max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_shared::protocol::{NetTiming, PlayerId};

    fn welcome(tick: u64) -> Welcome {
        Welcome {
            player_id: PlayerId(1),
            room: "r".into(),
            level_id: "l".into(),
            level_hash: 0,
            level: Default::default(),
            session_token: Default::default(),
            server_tick: tick,
            timing: NetTiming {
                tick_rate: 60,
                snapshot_interval: 2,
                input_redundancy: 16,
            },
            sim_config: vec![],
        }
    }

    #[test]
    fn estimates_ticks_and_steers_the_lead() {
        let t0 = Instant::now();
        let mut c = InputClock::new(&welcome(100), t0);
        assert_eq!(c.server_tick(t0), 100);
        assert_eq!(c.server_tick(t0 + Duration::from_millis(1000)), 160);
        // At 60 Hz an input may wait a tick for its datagram: one more.
        let lead = DEFAULT_LEAD + 1;
        assert_eq!(c.input_tick(t0), 100 + lead as u64);
        c.observe(-3);
        assert_eq!(c.lead(), lead + 1);
        c.observe(TARGET_TIMING);
        assert_eq!(c.lead(), lead + 1);
        c.observe(10);
        c.observe(10);
        assert_eq!(c.lead(), lead - 1);
        let wait = c.until_next_tick(t0 + Duration::from_millis(10));
        assert!(
            wait > Duration::from_millis(6) && wait <= Duration::from_millis(7),
            "{wait:?}"
        );
    }

    /// A model of the server: ticks at exactly `rate` from `t0`; an input
    /// for tick `k` sent at local time `s` arrives at `s + delay(s)`; the
    /// server reports `k - next_tick` at arrival, the worst of each
    /// snapshot interval, one way later.
    fn run_sync(
        mut clock: SyncClock,
        t0: Instant,
        seconds: f64,
        delay: impl Fn(usize) -> f64,
        jitter_ticks: f64,
    ) -> (SyncClock, Vec<f64>, Vec<i16>) {
        let rate = 60.0;
        let mut positions = Vec::new();
        let mut reports = Vec::new();
        let mut pending: Vec<(f64, i16)> = Vec::new(); // (deliver at, timing)
        let mut worst: Option<i16> = None;
        let mut next_snapshot = 2.0 / rate;
        let mut sent = clock.tick();
        clock.set_jitter(jitter_ticks);
        let steps = (seconds * 1000.0) as usize;
        for i in 0..steps {
            let t = i as f64 / 1000.0;
            let now = t0 + Duration::from_secs_f64(t);
            let pos = clock.advance(now);
            positions.push(pos);
            while clock.tick() > sent {
                let d = delay(i);
                let server_next = ((t + d) * rate).floor() as u64 + 1000;
                let timing = input_timing(sent, server_next);
                worst = Some(worst.map_or(timing, |w| w.min(timing)));
                sent += 1;
            }
            if t >= next_snapshot {
                next_snapshot += 2.0 / rate;
                if let Some(w) = worst.take() {
                    pending.push((t + delay(i), w));
                }
            }
            pending.retain(|&(at, timing)| {
                if at <= t {
                    clock.observe(timing);
                    reports.push(timing);
                    false
                } else {
                    true
                }
            });
        }
        (clock, positions, reports)
    }

    use ledge_shared::protocol::input_timing;

    #[test]
    fn the_sync_clock_converges_from_early_and_late_and_never_goes_back() {
        let t0 = Instant::now();
        // Server tick 1000 at t0; one-way delay 25 ms (1.5 ticks).
        for start in [1000.0, 1003.0, 1030.0] {
            let clock = SyncClock::new(start, 60, t0);
            let (clock, positions, reports) = run_sync(clock, t0, 20.0, |_| 0.025, 0.0);
            assert!(
                positions.windows(2).all(|w| w[1] >= w[0]),
                "start {start}: never backwards"
            );
            let late: Vec<i16> = reports[reports.len() - 100..].to_vec();
            let mean = late.iter().map(|&r| f64::from(r)).sum::<f64>() / late.len() as f64;
            assert!(
                (mean - BASE_MARGIN).abs() <= 0.75,
                "start {start}: settled at {mean} ticks early, want {BASE_MARGIN} ({late:?})"
            );
            assert!(
                late.iter().all(|&r| r >= 0),
                "start {start}: late inputs {late:?}"
            );
            assert!(
                clock.adjust().abs() <= MAX_ADJUST,
                "start {start}: adjust {}",
                clock.adjust()
            );
            // The speed never changed by more than the far limit: the
            // position grows at 60 Hz within 20%.
            for w in positions.windows(1000) {
                let speed = (w[999] - w[0]) / 0.999;
                let (lo, hi) = (60.0 * (1.0 - MAX_ADJUST_FAR), 60.0 * (1.0 + MAX_ADJUST_FAR));
                assert!(
                    speed >= lo - 1e-6 && speed <= hi + 1e-6,
                    "start {start}: {speed} ticks a second"
                );
            }
        }
    }

    #[test]
    fn the_sync_clock_keeps_a_bigger_margin_under_jitter_and_catches_up_when_hopeless() {
        let t0 = Instant::now();
        let mut rng = 12345u64;
        let mut noise = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng % 1000) as f64 / 1000.0
        };
        let delays: Vec<f64> = (0..20_000).map(|_| 0.02 + 0.04 * noise()).collect();
        let clock = SyncClock::new(1000.0, 60, t0);
        // 40 ms of spread: about 1.2 ticks of jitter.
        let (clock, positions, reports) =
            run_sync(clock, t0, 20.0, |i| delays[i % delays.len()], 1.2);
        assert!(positions.windows(2).all(|w| w[1] >= w[0]));
        assert!((clock.target_margin() - (BASE_MARGIN + 2.4)).abs() < 1e-9);
        let late = &reports[reports.len() - 150..];
        let starved = late.iter().filter(|&&r| r < 0).count();
        assert_eq!(starved, 0, "inputs late under jitter: {late:?}");

        // The margin for loss is counted in input datagrams: at 60 Hz one
        // goes every 2 ticks, at 30 Hz every tick.
        for (rate, every) in [(60, 2.0), (30, 1.0)] {
            let mut c = SyncClock::new(100.0, rate, t0);
            for (loss, datagrams) in [(0.0, 0.0), (0.01, 1.0), (0.1, 2.0), (0.3, 4.0), (0.9, 4.0)] {
                c.set_loss(loss);
                let want = BASE_MARGIN + datagrams * every;
                assert_eq!(c.target_margin(), want, "{rate} Hz, loss {loss}");
            }
        }
        let mut c = SyncClock::new(100.0, 60, t0);
        assert_eq!(c.observe(-40), 40.0 + BASE_MARGIN);
        assert_eq!(c.position(), 141.0);
        assert_eq!(c.observe(-38), 0.0, "a report from before the jump");
        assert_eq!(c.position(), 141.0);
        assert_eq!(c.catch_up_to(120.0), 0.0, "never backwards");
    }
}
