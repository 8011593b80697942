//! Which tick to send inputs for: the server's tick, estimated from the
//! welcome and local time, plus a lead steered by the server's
//! `input_timing` feedback so inputs arrive slightly early.
//!
//! A simple first version for bots and tests; prediction (issue 6) can
//! replace it with a smoothed clock.

use std::time::{Duration, Instant};

use ledge_shared::protocol::Welcome;

/// Default ticks the inputs are sent ahead of the estimated server tick.
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
    /// `welcome.server_tick`).
    pub fn new(welcome: &Welcome, at: Instant) -> InputClock {
        InputClock {
            start: at,
            start_tick: welcome.server_tick,
            tick_rate: welcome.timing.tick_rate.max(1),
            lead: DEFAULT_LEAD,
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
        assert_eq!(c.input_tick(t0), 100 + DEFAULT_LEAD as u64);
        c.observe(-3);
        assert_eq!(c.lead(), DEFAULT_LEAD + 1);
        c.observe(TARGET_TIMING);
        assert_eq!(c.lead(), DEFAULT_LEAD + 1);
        c.observe(10);
        c.observe(10);
        assert_eq!(c.lead(), DEFAULT_LEAD - 1);
        let wait = c.until_next_tick(t0 + Duration::from_millis(10));
        assert!(
            wait > Duration::from_millis(6) && wait <= Duration::from_millis(7),
            "{wait:?}"
        );
    }
}
