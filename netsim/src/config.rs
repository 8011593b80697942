//! What one direction of a link does to its packets: [`LinkConfig`].

use std::time::Duration;

use crate::error::ConfigError;
use crate::loss::Loss;

/// One direction of a link: delay, loss, duplication, reordering.
///
/// A packet is delayed by `latency` plus a uniform jitter in
/// `[-jitter, +jitter]` (never below zero). Jitter alone never reorders:
/// a packet is never delivered before one sent earlier (it waits for it,
/// like a packet behind another in a router queue), which keeps each delay
/// within `latency ± jitter`. Unlike Linux netem, where jitter reorders,
/// reordering is its own knob: with probability `reorder` a packet is held
/// back `reorder_delay` longer and later packets may overtake it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinkConfig {
    /// Mean one-way delay.
    pub latency: Duration,
    /// Largest deviation from `latency`, either way (uniform).
    pub jitter: Duration,
    /// How packets are lost.
    pub loss: Loss,
    /// Probability that a delivered packet is delivered twice (the copy
    /// right after the original).
    pub duplicate: f64,
    /// Probability that a packet is held back by `reorder_delay`, letting
    /// later packets overtake it.
    pub reorder: f64,
    /// How much longer a reordered packet takes.
    pub reorder_delay: Duration,
}

impl LinkConfig {
    /// A perfect link: no delay, no loss.
    pub const PERFECT: LinkConfig = LinkConfig {
        latency: Duration::ZERO,
        jitter: Duration::ZERO,
        loss: Loss::None,
        duplicate: 0.0,
        reorder: 0.0,
        reorder_delay: Duration::ZERO,
    };

    /// A link with `latency` one way and nothing else.
    pub fn delay(latency: Duration) -> LinkConfig {
        LinkConfig {
            latency,
            ..LinkConfig::PERFECT
        }
    }

    /// The same link with `jitter`.
    pub fn with_jitter(self, jitter: Duration) -> LinkConfig {
        LinkConfig { jitter, ..self }
    }

    /// The same link with `loss`.
    pub fn with_loss(self, loss: Loss) -> LinkConfig {
        LinkConfig { loss, ..self }
    }

    /// The same link duplicating with probability `p`.
    pub fn with_duplicate(self, p: f64) -> LinkConfig {
        LinkConfig {
            duplicate: p,
            ..self
        }
    }

    /// The same link holding back packets by `delay` with probability `p`.
    pub fn with_reorder(self, p: f64, delay: Duration) -> LinkConfig {
        LinkConfig {
            reorder: p,
            reorder_delay: delay,
            ..self
        }
    }

    /// Checks every probability is a number in `0..=1`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let mut all = self.loss.probabilities();
        all.push(("duplicate", self.duplicate));
        all.push(("reorder", self.reorder));
        for (name, p) in all {
            if !(0.0..=1.0).contains(&p) {
                return Err(ConfigError::Probability { name, value: p });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probabilities_outside_zero_one_are_refused() {
        let bad = LinkConfig::PERFECT.with_duplicate(1.5);
        assert!(bad.validate().is_err());
        let nan = LinkConfig::PERFECT.with_loss(Loss::Bernoulli { p: f64::NAN });
        assert!(nan.validate().is_err());
        assert!(LinkConfig::PERFECT
            .with_loss(Loss::bursts(0.1, 3.0))
            .validate()
            .is_ok());
    }
}
