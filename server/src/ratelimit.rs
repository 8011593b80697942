//! Token buckets and a throttle: per-client rate limits, abuse thresholds,
//! and warnings at most so often.

use std::time::{Duration, Instant};

/// A token bucket: holds at most `capacity` tokens, refills at `rate` tokens
/// per second, starts full. Pure: the caller passes the time.
#[derive(Debug, Clone)]
pub struct TokenBucket {
    capacity: f64,
    rate: f64,
    tokens: f64,
    last: Instant,
}

impl TokenBucket {
    /// A full bucket of `capacity` tokens refilling at `rate` per second.
    pub fn new(capacity: f64, rate: f64, now: Instant) -> TokenBucket {
        let capacity = capacity.max(0.0);
        TokenBucket {
            capacity,
            rate: rate.max(0.0),
            tokens: capacity,
            last: now,
        }
    }

    fn refill(&mut self, now: Instant) {
        let elapsed = now.saturating_duration_since(self.last).as_secs_f64();
        self.tokens = (self.tokens + elapsed * self.rate).min(self.capacity);
        self.last = self.last.max(now);
    }

    /// Takes one token if there is one; `false` means over the limit.
    pub fn try_take(&mut self, now: Instant) -> bool {
        self.refill(now);
        if self.tokens >= 1.0 {
            self.tokens -= 1.0;
            true
        } else {
            false
        }
    }

    /// Tokens available now.
    pub fn available(&mut self, now: Instant) -> f64 {
        self.refill(now);
        self.tokens
    }
}

/// At most one message per `every`: [`Throttle::note`] says when one is
/// due and how many events it stands for. Pure, like [`TokenBucket`].
#[derive(Debug, Clone)]
pub struct Throttle {
    every: Duration,
    last: Option<Instant>,
    events: u64,
}

impl Throttle {
    /// One message at most every `every`.
    pub fn new(every: Duration) -> Throttle {
        Throttle {
            every,
            last: None,
            events: 0,
        }
    }

    /// Counts an event at `now`; `Some(n)` when a message is due, `n` the
    /// events since the last one (this one included).
    pub fn note(&mut self, now: Instant) -> Option<u64> {
        self.events += 1;
        let due = self
            .last
            .is_none_or(|t| now.saturating_duration_since(t) >= self.every);
        due.then(|| {
            self.last = Some(now);
            std::mem::take(&mut self.events)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn a_throttle_speaks_once_per_period_and_counts_the_rest() {
        let t0 = Instant::now();
        let mut t = Throttle::new(Duration::from_secs(10));
        assert_eq!(t.note(t0), Some(1));
        assert!((0..5).all(|i| t.note(t0 + Duration::from_secs(i)).is_none()));
        assert_eq!(t.note(t0 + Duration::from_secs(10)), Some(6));
        assert_eq!(t.note(t0 + Duration::from_secs(11)), None);
    }

    #[test]
    fn allows_the_burst_then_the_rate() {
        let t0 = Instant::now();
        let mut b = TokenBucket::new(3.0, 10.0, t0);
        assert!((0..3).all(|_| b.try_take(t0)));
        assert!(!b.try_take(t0));
        // 100 ms at 10/s: one more.
        let t1 = t0 + Duration::from_millis(100);
        assert!(b.try_take(t1));
        assert!(!b.try_take(t1));
        // A long pause refills to the capacity only.
        let t2 = t1 + Duration::from_secs(60);
        assert!((b.available(t2) - 3.0).abs() < 1e-9);
    }

    #[test]
    fn time_going_backwards_does_not_refill() {
        let t0 = Instant::now() + Duration::from_secs(1);
        let mut b = TokenBucket::new(1.0, 1.0, t0);
        assert!(b.try_take(t0));
        assert!(!b.try_take(t0 - Duration::from_millis(500)));
        assert!(!b.try_take(t0));
    }
}
