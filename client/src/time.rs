//! The client's clock type: [`std::time::Instant`] natively; in a browser
//! (`wasm32-unknown-unknown`, where `std`'s clock panics) a monotonic
//! instant read from the page's `performance.now()` through the web glue
//! (`web/ledge.js`, import `ledge_now_ms`).
//!
//! Everything in the library that a browser build runs takes its time
//! from here, so one code path serves both.

#[cfg(not(target_arch = "wasm32"))]
pub use std::time::Instant;

#[cfg(target_arch = "wasm32")]
pub use web::Instant;

#[cfg(target_arch = "wasm32")]
mod web {
    use std::ops::{Add, AddAssign, Sub, SubAssign};
    use std::time::Duration;

    extern "C" {
        /// Milliseconds since the page loaded (`performance.now()`).
        fn ledge_now_ms() -> f64;
    }

    /// A point in time, in nanoseconds since the page loaded; monotonic
    /// like `performance.now()`, with its API the subset of
    /// [`std::time::Instant`]'s the client uses.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
    pub struct Instant(u64);

    impl Instant {
        /// Now.
        pub fn now() -> Instant {
            // SAFETY: an import without arguments or memory access.
            let ms = unsafe { ledge_now_ms() };
            let ns = (ms.max(0.0) * 1e6) as u64;
            Instant(ns)
        }

        /// Time from `earlier` to `self`, zero if `earlier` is later.
        pub fn duration_since(&self, earlier: Instant) -> Duration {
            self.saturating_duration_since(earlier)
        }

        /// Time from `earlier` to `self`, `None` if `earlier` is later.
        pub fn checked_duration_since(&self, earlier: Instant) -> Option<Duration> {
            self.0.checked_sub(earlier.0).map(Duration::from_nanos)
        }

        /// Time from `earlier` to `self`, zero if `earlier` is later.
        pub fn saturating_duration_since(&self, earlier: Instant) -> Duration {
            Duration::from_nanos(self.0.saturating_sub(earlier.0))
        }

        /// Time since `self`.
        pub fn elapsed(&self) -> Duration {
            Instant::now().saturating_duration_since(*self)
        }

        /// `self + d`, `None` on overflow.
        pub fn checked_add(&self, d: Duration) -> Option<Instant> {
            u64::try_from(d.as_nanos())
                .ok()
                .and_then(|n| self.0.checked_add(n))
                .map(Instant)
        }

        /// `self - d`, `None` before the page loaded.
        pub fn checked_sub(&self, d: Duration) -> Option<Instant> {
            u64::try_from(d.as_nanos())
                .ok()
                .and_then(|n| self.0.checked_sub(n))
                .map(Instant)
        }
    }

    impl Add<Duration> for Instant {
        type Output = Instant;
        fn add(self, d: Duration) -> Instant {
            // Saturates (584 years from the page's load) rather than panicking.
            self.checked_add(d).unwrap_or(Instant(u64::MAX))
        }
    }

    impl AddAssign<Duration> for Instant {
        fn add_assign(&mut self, d: Duration) {
            *self = *self + d;
        }
    }

    impl Sub<Duration> for Instant {
        type Output = Instant;
        fn sub(self, d: Duration) -> Instant {
            // Saturates at the page's load rather than panicking.
            self.checked_sub(d).unwrap_or(Instant(0))
        }
    }

    impl SubAssign<Duration> for Instant {
        fn sub_assign(&mut self, d: Duration) {
            *self = *self - d;
        }
    }

    impl Sub<Instant> for Instant {
        type Output = Duration;
        fn sub(self, earlier: Instant) -> Duration {
            self.saturating_duration_since(earlier)
        }
    }
}
