//! Quantiles of a window from histogram bucket counts.
//!
//! The server's fine tick histograms are cumulative since start; the
//! difference of two scrapes is the histogram of the window between them,
//! and a quantile is read from it by finding the bucket that holds the rank
//! and interpolating inside it (geometrically: the buckets are log-spaced).
//! With the server's 16 buckets per doubling the result is within one
//! bucket, 4.4 %, of the exact quantile.

use anyhow::{bail, ensure};

/// Histogram buckets: upper bounds in increasing order (the last may be
/// `+Inf`) and the number of observations in each (not cumulative).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Buckets {
    bounds: Vec<f64>,
    counts: Vec<u64>,
}

impl Buckets {
    /// From `(upper bound, cumulative count)` pairs in increasing bound
    /// order, as served.
    pub fn from_cumulative(cumulative: &[(f64, f64)]) -> anyhow::Result<Buckets> {
        let mut bounds = Vec::with_capacity(cumulative.len());
        let mut counts = Vec::with_capacity(cumulative.len());
        let mut previous = 0u64;
        for &(bound, cum) in cumulative {
            ensure!(
                cum.is_finite() && cum >= 0.0,
                "bucket count {cum} at le={bound}"
            );
            let cum = cum.round() as u64;
            if let Some(&last) = bounds.last() {
                ensure!(bound > last, "bucket bounds not increasing at {bound}");
            }
            ensure!(cum >= previous, "cumulative count decreases at le={bound}");
            bounds.push(bound);
            counts.push(cum - previous);
            previous = cum;
        }
        Ok(Buckets { bounds, counts })
    }

    /// From upper bounds and per-bucket counts.
    pub fn new(bounds: Vec<f64>, counts: Vec<u64>) -> anyhow::Result<Buckets> {
        ensure!(bounds.len() == counts.len(), "bounds and counts differ");
        ensure!(
            bounds.windows(2).all(|w| w[0] < w[1]),
            "bucket bounds not increasing"
        );
        Ok(Buckets { bounds, counts })
    }

    /// Upper bounds.
    pub fn bounds(&self) -> &[f64] {
        &self.bounds
    }

    /// Observations per bucket.
    pub fn counts(&self) -> &[u64] {
        &self.counts
    }

    /// No buckets at all (the histogram was not served).
    pub fn is_empty(&self) -> bool {
        self.bounds.is_empty()
    }

    /// Observations in all buckets.
    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// The observations made after `earlier` (a scrape of the same
    /// histogram taken before this one).
    pub fn since(&self, earlier: &Buckets) -> anyhow::Result<Buckets> {
        if earlier.is_empty() {
            return Ok(self.clone());
        }
        ensure!(
            self.bounds == earlier.bounds,
            "the histogram's buckets changed between scrapes"
        );
        let mut counts = Vec::with_capacity(self.counts.len());
        for (now, before) in self.counts.iter().zip(&earlier.counts) {
            match now.checked_sub(*before) {
                Some(c) => counts.push(c),
                None => bail!("a bucket count went down (did the server restart?)"),
            }
        }
        Ok(Buckets {
            bounds: self.bounds.clone(),
            counts,
        })
    }

    /// The `q` quantile (0 < q <= 1), or `None` without observations. A
    /// quantile in the `+Inf` bucket is reported as the last finite bound
    /// (a lower bound of the true value).
    pub fn quantile(&self, q: f64) -> Option<f64> {
        let total = self.total();
        if total == 0 {
            return None;
        }
        let rank = (q.clamp(0.0, 1.0) * total as f64).max(1.0);
        let mut below = 0u64;
        for (i, &count) in self.counts.iter().enumerate() {
            if count == 0 || ((below + count) as f64) < rank {
                below += count;
                continue;
            }
            let upper = self.bounds[i];
            let lower = if i == 0 { 0.0 } else { self.bounds[i - 1] };
            if upper.is_infinite() {
                return Some(lower);
            }
            let frac = ((rank - below as f64) / count as f64).clamp(0.0, 1.0);
            return Some(if lower > 0.0 {
                lower * (upper / lower).powf(frac)
            } else {
                upper * frac
            });
        }
        self.bounds.last().copied()
    }

    /// Upper bound of the highest non-empty bucket (the largest observation
    /// is at most this), or `None` without observations.
    pub fn max_bound(&self) -> Option<f64> {
        let i = self.counts.iter().rposition(|&c| c > 0)?;
        Some(self.bounds[i])
    }

    /// Observations in the buckets entirely above `x` (every one of them is
    /// greater than `x`; the bucket straddling `x` is not counted).
    pub fn count_above(&self, x: f64) -> u64 {
        self.counts
            .iter()
            .enumerate()
            .filter(|&(i, _)| i > 0 && self.bounds[i - 1] >= x)
            .map(|(_, &c)| c)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Log-spaced bounds like the server's: 1 µs * 2^(i/16).
    fn fine() -> Vec<f64> {
        (0..320)
            .map(|i| 1e-6 * 2f64.powf(f64::from(i) / 16.0))
            .chain(std::iter::once(f64::INFINITY))
            .collect()
    }

    fn histogram_of(values: &[f64]) -> Buckets {
        let bounds = fine();
        let mut counts = vec![0; bounds.len()];
        for &v in values {
            let i = bounds.iter().position(|&b| v <= b).unwrap();
            counts[i] += 1;
        }
        Buckets::new(bounds, counts).unwrap()
    }

    #[test]
    fn quantiles_are_within_one_fine_bucket_of_the_exact_ones() {
        // 10,000 ticks spread from 80 µs to 2.5 ms, unevenly.
        let mut values: Vec<f64> = (0..10_000u32)
            .map(|i| {
                let x = f64::from((i * 7919) % 10_000) / 10_000.0;
                80e-6 + x * x * x * 2.4e-3
            })
            .collect();
        let h = histogram_of(&values);
        values.sort_by(f64::total_cmp);
        for q in [0.5, 0.9, 0.99, 0.999] {
            let exact = values[(q * values.len() as f64).ceil() as usize - 1];
            let got = h.quantile(q).unwrap();
            let ratio = got / exact;
            assert!(
                (1.0 / 1.045..1.045).contains(&ratio),
                "q {q}: {got} vs exact {exact}"
            );
        }
        let max = h.max_bound().unwrap();
        assert!(max >= values[values.len() - 1] && max < values[values.len() - 1] * 1.045);
    }

    #[test]
    fn window_is_the_difference_of_two_scrapes() {
        let before = histogram_of(&[1e-3; 100]);
        let after = histogram_of(&[[1e-3; 100].as_slice(), &[10e-6; 50]].concat());
        let window = after.since(&before).unwrap();
        assert_eq!(window.total(), 50);
        let p50 = window.quantile(0.5).unwrap();
        assert!((9.5e-6..10.5e-6).contains(&p50), "{p50}");
        // A counter going down is an error, not a negative count.
        assert!(before.since(&after).is_err());
        let coarse = Buckets::new(vec![1.0, f64::INFINITY], vec![0, 0]).unwrap();
        assert!(after.since(&coarse).is_err());
    }

    #[test]
    fn empty_infinite_and_counting_above() {
        assert_eq!(histogram_of(&[]).quantile(0.5), None);
        assert_eq!(histogram_of(&[]).max_bound(), None);
        let h = histogram_of(&[5.0, 5.0, 1e-3]);
        // Beyond the last finite bound (~1.05 s): reported as that bound.
        let last = fine()[319];
        assert_eq!(h.quantile(0.99), Some(last));
        assert_eq!(h.max_bound(), Some(f64::INFINITY));
        assert_eq!(h.count_above(0.5), 2);
        assert_eq!(h.count_above(1e-4), 3);
        assert_eq!(h.count_above(10.0), 0);
    }

    #[test]
    fn cumulative_counts_must_not_decrease() {
        let b = Buckets::from_cumulative(&[(1.0, 2.0), (2.0, 5.0), (f64::INFINITY, 5.0)]).unwrap();
        assert_eq!(b.counts(), &[2, 3, 0]);
        assert!(Buckets::from_cumulative(&[(1.0, 2.0), (2.0, 1.0)]).is_err());
        assert!(Buckets::from_cumulative(&[(2.0, 1.0), (1.0, 2.0)]).is_err());
    }
}
