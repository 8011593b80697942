//! Drift-free fixed-step scheduling.
//!
//! Tick `n` is due at `start + n / rate` seconds, computed from the start in
//! integer nanoseconds, never by adding a rounded period to the previous
//! deadline, so rounding error does not accumulate. After a stall (a slow
//! tick, a suspended process) the loop catches up by running the missed
//! ticks back to back, at most `max_catch_up` of them; the rest are skipped
//! by moving the schedule forward, so a long stall cannot start a spiral of
//! ever-later ticks. Pure: the caller passes the current time.

use std::time::{Duration, Instant};

/// The absolute schedule of a fixed-rate loop.
#[derive(Debug, Clone)]
pub struct TickSchedule {
    start: Instant,
    rate: u32,
    /// Index of the next slot to run, counted from `start`.
    next_slot: u64,
    max_catch_up: u32,
}

/// What the loop should do now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Due {
    /// Ticks to run now, back to back (0 when it is not time yet).
    pub run: u32,
    /// Slots abandoned because the loop fell too far behind.
    pub skipped: u64,
}

impl TickSchedule {
    /// A schedule at `rate` Hz whose first tick is due at `start`.
    ///
    /// `rate` and `max_catch_up` are clamped to at least 1.
    pub fn new(start: Instant, rate: u32, max_catch_up: u32) -> TickSchedule {
        TickSchedule {
            start,
            rate: rate.max(1),
            next_slot: 0,
            max_catch_up: max_catch_up.max(1),
        }
    }

    /// The tick rate in Hz.
    pub fn rate(&self) -> u32 {
        self.rate
    }

    /// When slot `n` is due.
    fn slot_time(&self, n: u64) -> Instant {
        let nanos = u128::from(n) * 1_000_000_000 / u128::from(self.rate);
        // Saturates after ~584 years of uptime.
        self.start + Duration::from_nanos(u64::try_from(nanos).unwrap_or(u64::MAX))
    }

    /// When the next tick is due: the loop sleeps until then.
    pub fn next_deadline(&self) -> Instant {
        self.slot_time(self.next_slot)
    }

    /// Claims the ticks due at `now` and advances the schedule past them.
    pub fn poll(&mut self, now: Instant) -> Due {
        if now < self.next_deadline() {
            return Due { run: 0, skipped: 0 };
        }
        let elapsed = now.duration_since(self.start).as_nanos();
        // Slot n is due when floor(n * 1e9 / rate) <= elapsed, i.e. when
        // n * 1e9 < (elapsed + 1) * rate: the due slots are 0..=last_due.
        let last_due = u64::try_from(((elapsed + 1) * u128::from(self.rate) - 1) / 1_000_000_000)
            .unwrap_or(u64::MAX - 1);
        let due = (last_due + 1).saturating_sub(self.next_slot);
        if due == 0 {
            return Due { run: 0, skipped: 0 };
        }
        let run = due.min(u64::from(self.max_catch_up));
        self.next_slot = last_due + 1;
        Due {
            run: run as u32,
            skipped: due - run,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(n: u64) -> Duration {
        Duration::from_millis(n)
    }

    #[test]
    fn first_tick_is_due_at_start() {
        let t0 = Instant::now();
        let mut s = TickSchedule::new(t0, 60, 5);
        assert_eq!(s.next_deadline(), t0);
        assert_eq!(s.poll(t0), Due { run: 1, skipped: 0 });
        assert_eq!(s.poll(t0), Due { run: 0, skipped: 0 });
    }

    #[test]
    fn deadlines_do_not_drift() {
        let t0 = Instant::now();
        let mut s = TickSchedule::new(t0, 60, 5);
        // Poll exactly at each deadline for an hour of ticks: one tick each.
        for _ in 0..60 * 3600 {
            let at = s.next_deadline();
            assert_eq!(s.poll(at).run, 1);
        }
        // Exactly one hour later, to the nanosecond: no accumulated rounding.
        assert_eq!(s.next_deadline(), t0 + Duration::from_secs(3600));
    }

    #[test]
    fn a_tick_is_due_exactly_at_its_rounded_deadline() {
        let t0 = Instant::now();
        // 1/60 s is not a whole number of nanoseconds.
        let mut s = TickSchedule::new(t0, 60, 5);
        assert_eq!(s.poll(t0).run, 1);
        let deadline = s.next_deadline();
        assert_eq!(deadline, t0 + Duration::from_nanos(16_666_666));
        assert_eq!(s.poll(deadline - Duration::from_nanos(1)).run, 0);
        assert_eq!(s.poll(deadline).run, 1);
    }

    #[test]
    fn polling_late_catches_up_then_resumes_the_grid() {
        let t0 = Instant::now();
        let mut s = TickSchedule::new(t0, 100, 5);
        assert_eq!(s.poll(t0).run, 1);
        // 35 ms late: slots at 10, 20, 30 ms are due.
        assert_eq!(s.poll(t0 + ms(35)), Due { run: 3, skipped: 0 });
        assert_eq!(s.next_deadline(), t0 + ms(40));
    }

    #[test]
    fn a_long_stall_is_bounded_and_reports_skipped_ticks() {
        let t0 = Instant::now();
        let mut s = TickSchedule::new(t0, 100, 5);
        assert_eq!(s.poll(t0).run, 1);
        // 1 s stall: slots 1..=100 are due, only 5 run.
        assert_eq!(
            s.poll(t0 + ms(1000)),
            Due {
                run: 5,
                skipped: 95
            }
        );
        // The grid stays anchored at start.
        assert_eq!(s.next_deadline(), t0 + ms(1010));
    }
}
