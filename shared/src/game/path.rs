//! Platform paths: the position of a moving platform as a pure function of
//! the tick.
//!
//! A path of nodes `n_0 .. n_m` is cut into legs (ping-pong: `n_0 -> n_1 ->
//! ... -> n_m -> n_{m-1} -> ... -> n_0`; looped: `n_0 -> ... -> n_m -> n_0`).
//! A leg from `a` to `b` lasts `k = max(1, ceil(|b - a| / speed))` ticks
//! (`|b - a|` the Euclidean length rounded up, an integer square root), and
//! `j` ticks into it the platform is at `a + floor((b - a) * j / k)` per axis:
//! exact integers, node to node, steps of at most `speed + 1` units per axis
//! (exactly `speed` on an axis-aligned leg whose length is a multiple of it).
//! The whole cycle repeats every `period` ticks, so the position at any tick
//! is computed directly (a binary search over the legs), never accumulated.

use glam::IVec2;

use crate::fixed::{check_coord, MAX_SPEED};
use crate::level::PlatformMotion;

/// One leg of a path.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Leg {
    from: IVec2,
    delta: IVec2,
    /// First tick of the leg within the cycle.
    start: u64,
    /// Its duration in ticks (at least 1).
    ticks: u64,
}

/// A platform's motion, ready to be evaluated at any tick.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PathSchedule {
    first: IVec2,
    legs: Vec<Leg>,
    period: u64,
}

impl PathSchedule {
    /// The schedule of `motion`; errors name the problem.
    pub fn new(motion: &PlatformMotion) -> Result<Self, String> {
        let path = &motion.path;
        let Some(&first) = path.first() else {
            return Err("platform path has no node".into());
        };
        if motion.speed <= 0 || motion.speed > MAX_SPEED / 2 {
            return Err(format!(
                "platform speed {} units/tick is not in (0, {}]",
                motion.speed,
                MAX_SPEED / 2
            ));
        }
        for p in path {
            for v in [p.x, p.y] {
                check_coord("platform path node", v as i64).map_err(|e| e.to_string())?;
            }
        }
        let mut order: Vec<usize> = (0..path.len()).collect();
        if path.len() > 1 {
            if motion.looped {
                order.push(0);
            } else {
                order.extend((0..path.len() - 1).rev());
            }
        }
        let mut legs = Vec::with_capacity(order.len().saturating_sub(1));
        let mut start = 0u64;
        for w in order.windows(2) {
            let (a, b) = (path[w[0]], path[w[1]]);
            let d = (b - a).as_i64vec2();
            let l2 = (d.x as i128 * d.x as i128 + d.y as i128 * d.y as i128) as u128;
            let mut len = l2.isqrt();
            if len * len < l2 {
                len += 1;
            }
            let ticks = (len.div_ceil(motion.speed as u128) as u64).max(1);
            legs.push(Leg {
                from: a,
                delta: b - a,
                start,
                ticks,
            });
            start += ticks;
        }
        Ok(Self {
            first,
            legs,
            period: start,
        })
    }

    /// Ticks in one full cycle (0 for a one-node path, which never moves).
    pub fn period(&self) -> u64 {
        self.period
    }

    /// The smallest box holding every position of the platform's centre:
    /// `(min, max)` per axis over the path's nodes (a leg runs straight
    /// between two nodes).
    pub fn bounds(&self) -> (IVec2, IVec2) {
        let ends = self.legs.iter().map(|l| l.from + l.delta);
        ends.fold((self.first, self.first), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        })
    }

    /// The platform's centre at `tick`.
    pub fn at(&self, tick: u64) -> IVec2 {
        if self.period == 0 {
            return self.first;
        }
        let t = tick % self.period;
        // The last leg starting at or before t.
        let i = self.legs.partition_point(|l| l.start <= t) - 1;
        let leg = &self.legs[i];
        let j = (t - leg.start) as i128;
        let k = leg.ticks as i128;
        let step = |d: i32| (d as i128 * j).div_euclid(k) as i32;
        leg.from + IVec2::new(step(leg.delta.x), step(leg.delta.y))
    }

    /// The index of the leg in progress at `tick` (0 for a one-node path).
    pub fn leg_at(&self, tick: u64) -> usize {
        if self.period == 0 {
            return 0;
        }
        let t = tick % self.period;
        self.legs.partition_point(|l| l.start <= t) - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn motion(path: &[(i32, i32)], speed: i32, looped: bool) -> PlatformMotion {
        PlatformMotion {
            path: path.iter().map(|&(x, y)| IVec2::new(x, y)).collect(),
            speed,
            looped,
        }
    }

    #[test]
    fn ping_pong_axis_leg_moves_exactly_speed() {
        let s = PathSchedule::new(&motion(&[(0, 0), (1000, 0)], 100, false)).unwrap();
        assert_eq!(s.period(), 20);
        for t in 0..=10 {
            assert_eq!(s.at(t), IVec2::new(100 * t as i32, 0));
        }
        for t in 10..=20 {
            assert_eq!(s.at(t), IVec2::new(1000 - 100 * (t as i32 - 10), 0));
        }
        assert_eq!(s.at(20), IVec2::ZERO);
        assert_eq!(s.at(20 * 1_000_000_007 + 3), IVec2::new(300, 0));
    }

    #[test]
    fn diagonal_and_looped_paths_hit_every_node() {
        let m = motion(&[(0, 0), (700, -700), (700, 300)], 90, true);
        let s = PathSchedule::new(&m).unwrap();
        let mut t = 0;
        let mut seen = Vec::new();
        while t <= s.period() {
            let p = s.at(t);
            if m.path.contains(&p) {
                seen.push(p);
            }
            let step = s.at(t + 1) - p;
            assert!(step.x.abs() <= 91 && step.y.abs() <= 91, "{step}");
            t += 1;
        }
        for n in &m.path {
            assert!(seen.contains(n), "{n}");
        }
        assert_eq!(s.at(s.period()), IVec2::ZERO);
    }

    #[test]
    fn one_node_never_moves_and_bad_speeds_are_refused() {
        let s = PathSchedule::new(&motion(&[(5, 6)], 10, false)).unwrap();
        assert_eq!(s.at(12345), IVec2::new(5, 6));
        assert!(PathSchedule::new(&motion(&[(0, 0), (1, 0)], 0, false)).is_err());
        assert!(PathSchedule::new(&motion(&[], 10, false)).is_err());
    }
}
