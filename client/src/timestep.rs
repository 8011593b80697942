//! A fixed-step accumulator for the render loop.
//!
//! The window delivers frames at whatever rate it likes; the simulation
//! must advance in whole fixed ticks. Frame time is accumulated exactly (in
//! units of 1/(rate * 10^9) s, so 1/60 s has no rounding error) and turned
//! into whole ticks. A long frame (window dragged, debugger) runs at most
//! `max_steps` ticks and drops the rest instead of spiralling.

use std::time::Duration;

/// Turns frame durations into a number of fixed ticks to run.
#[derive(Debug, Clone)]
pub struct FixedStep {
    rate: u32,
    /// Accumulated time in nanoseconds × rate; one tick is 10^9 of these.
    acc: u128,
    max_steps: u32,
}

const UNITS_PER_TICK: u128 = 1_000_000_000;

impl FixedStep {
    /// An accumulator for `rate` Hz running at most `max_steps` ticks per
    /// frame (both clamped to at least 1).
    pub fn new(rate: u32, max_steps: u32) -> FixedStep {
        FixedStep {
            rate: rate.max(1),
            acc: 0,
            max_steps: max_steps.max(1),
        }
    }

    /// Adds one frame's duration; returns how many ticks to run now.
    pub fn advance(&mut self, frame: Duration) -> u32 {
        self.acc += frame.as_nanos() * u128::from(self.rate);
        let due = self.acc / UNITS_PER_TICK;
        let run = due.min(u128::from(self.max_steps));
        self.acc -= run * UNITS_PER_TICK;
        if due > run {
            // Too far behind: keep only the fraction of a tick.
            self.acc %= UNITS_PER_TICK;
        }
        run as u32
    }

    /// How far into the next tick the accumulated time is, in [0, 1): for
    /// interpolating what is drawn.
    pub fn alpha(&self) -> f32 {
        (self.acc as f64 / UNITS_PER_TICK as f64) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sixty_frames_of_a_sixtieth_make_sixty_ticks_exactly() {
        let mut step = FixedStep::new(60, 5);
        // 1/60 s rounded down to whole nanoseconds, plus the lost thirds:
        // a second in 60 uneven frames.
        let mut total = 0;
        for i in 0..60u64 {
            let ns = (i + 1) * 1_000_000_000 / 60 - i * 1_000_000_000 / 60;
            total += step.advance(Duration::from_nanos(ns));
        }
        assert_eq!(total, 60);
        assert_eq!(step.alpha(), 0.0);
    }

    #[test]
    fn short_frames_accumulate() {
        let mut step = FixedStep::new(100, 5);
        assert_eq!(step.advance(Duration::from_millis(4)), 0);
        assert_eq!(step.advance(Duration::from_millis(4)), 0);
        assert_eq!(step.advance(Duration::from_millis(4)), 1);
        assert!((step.alpha() - 0.2).abs() < 1e-6);
    }

    #[test]
    fn a_long_frame_is_capped_and_the_backlog_dropped() {
        let mut step = FixedStep::new(100, 5);
        assert_eq!(step.advance(Duration::from_millis(1005)), 5);
        assert_eq!(step.advance(Duration::ZERO), 0);
        assert!((step.alpha() - 0.5).abs() < 1e-6);
    }
}
