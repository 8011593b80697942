//! How packets are lost: the model ([`Loss`]) and its running state
//! ([`LossProcess`]).

use rand::RngExt;
use rand_pcg::Pcg64Mcg;

/// How packets are lost.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Loss {
    /// Nothing is lost.
    #[default]
    None,
    /// Each packet is lost independently with probability `p` (random
    /// loss).
    Bernoulli {
        /// Loss probability, `0..=1`.
        p: f64,
    },
    /// The Gilbert-Elliott two-state model (burst loss): the link is either
    /// good or bad, each packet is lost with its state's probability, then
    /// the state may change. The stationary loss rate is
    /// [`Loss::expected_rate`]; with `loss_in_good = 0` and `loss_in_bad = 1`
    /// losses come in bursts of mean length `1 / p_bad_to_good`.
    GilbertElliott {
        /// Per packet, the probability that a good link turns bad.
        p_good_to_bad: f64,
        /// Per packet, the probability that a bad link turns good.
        p_bad_to_good: f64,
        /// Loss probability while good.
        loss_in_good: f64,
        /// Loss probability while bad.
        loss_in_bad: f64,
    },
}

impl Loss {
    /// Bursts: a Gilbert-Elliott model that loses everything while bad and
    /// nothing while good, with a long-run loss `rate` in bursts of
    /// `mean_burst` packets on average (`mean_burst >= 1`). A rate of 0 is
    /// [`Loss::None`], of 1 (or more) losing everything.
    pub fn bursts(rate: f64, mean_burst: f64) -> Loss {
        let rate = if rate.is_nan() { 0.0 } else { rate };
        if rate <= 0.0 {
            return Loss::None;
        }
        if rate >= 1.0 {
            return Loss::Bernoulli { p: 1.0 };
        }
        let p_bad_to_good = 1.0 / mean_burst.max(1.0);
        // Stationary P(bad) = p_gb / (p_gb + p_bg) = rate.
        let p_good_to_bad = (rate * p_bad_to_good / (1.0 - rate)).min(1.0);
        Loss::GilbertElliott {
            p_good_to_bad,
            p_bad_to_good,
            loss_in_good: 0.0,
            loss_in_bad: 1.0,
        }
    }

    /// The long-run fraction of packets lost.
    pub fn expected_rate(&self) -> f64 {
        match *self {
            Loss::None => 0.0,
            Loss::Bernoulli { p } => p,
            Loss::GilbertElliott {
                p_good_to_bad,
                p_bad_to_good,
                loss_in_good,
                loss_in_bad,
            } => {
                let moving = p_good_to_bad + p_bad_to_good;
                // A chain that never moves stays good (it starts good).
                let bad = if moving > 0.0 {
                    p_good_to_bad / moving
                } else {
                    0.0
                };
                (1.0 - bad) * loss_in_good + bad * loss_in_bad
            }
        }
    }

    pub(crate) fn probabilities(&self) -> Vec<(&'static str, f64)> {
        match *self {
            Loss::None => Vec::new(),
            Loss::Bernoulli { p } => vec![("loss", p)],
            Loss::GilbertElliott {
                p_good_to_bad,
                p_bad_to_good,
                loss_in_good,
                loss_in_bad,
            } => vec![
                ("p_good_to_bad", p_good_to_bad),
                ("p_bad_to_good", p_bad_to_good),
                ("loss_in_good", loss_in_good),
                ("loss_in_bad", loss_in_bad),
            ],
        }
    }
}

/// A [`Loss`] model running over a sequence of packets: remembers the
/// Gilbert-Elliott state between packets.
#[derive(Debug, Clone, Default)]
pub struct LossProcess {
    bad: bool,
}

impl LossProcess {
    /// A process in the good state.
    pub fn new() -> LossProcess {
        LossProcess::default()
    }

    /// Whether the Gilbert-Elliott chain is in its bad state.
    pub fn is_bad(&self) -> bool {
        self.bad
    }

    /// Decides whether the next packet is lost under `loss`, drawing from
    /// `rng` (the same draws for every packet, whatever the outcome).
    pub fn lose(&mut self, loss: &Loss, rng: &mut Pcg64Mcg) -> bool {
        let (lose, turn) = (rng.random::<f64>(), rng.random::<f64>());
        match *loss {
            Loss::None => false,
            Loss::Bernoulli { p } => lose < p,
            Loss::GilbertElliott {
                p_good_to_bad,
                p_bad_to_good,
                loss_in_good,
                loss_in_bad,
            } => {
                let lost = lose < if self.bad { loss_in_bad } else { loss_in_good };
                let change = if self.bad {
                    p_bad_to_good
                } else {
                    p_good_to_bad
                };
                if turn < change {
                    self.bad = !self.bad;
                }
                lost
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bursts_have_the_asked_rate() {
        let loss = Loss::bursts(0.05, 4.0);
        assert!((loss.expected_rate() - 0.05).abs() < 1e-12);
        assert_eq!(Loss::bursts(1.0, 2.0).expected_rate(), 1.0);
        assert_eq!(Loss::bursts(0.0, 2.0).expected_rate(), 0.0);
    }
}
