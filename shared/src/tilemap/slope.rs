//! Slope shapes: the surface height of each slope kind inside its tile.

use serde::{Deserialize, Serialize};

/// The shape of a slope tile: solid below a straight surface.
///
/// "Right" slopes rise to the right (`/`), "left" slopes rise to the left
/// (`\`). The 22.5 degree ramps (rise 1 over run 2) span two tiles: a ramp
/// rising to the right is [`Slope::RightLow22`] then [`Slope::RightHigh22`];
/// one rising to the left is [`Slope::LeftHigh22`] then [`Slope::LeftLow22`]
/// (left to right).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[repr(u8)]
pub enum Slope {
    /// 45 degrees rising to the right (`/`): `h(x) = x`.
    Right45,
    /// 45 degrees rising to the left (`\`): `h(x) = T - x`.
    Left45,
    /// Lower half of a 22.5 degree ramp rising to the right: `h(x) = x/2`.
    RightLow22,
    /// Upper half of a 22.5 degree ramp rising to the right: `h(x) = T/2 + x/2`.
    RightHigh22,
    /// Upper half of a 22.5 degree ramp rising to the left: `h(x) = T - x/2`.
    LeftHigh22,
    /// Lower half of a 22.5 degree ramp rising to the left: `h(x) = T/2 - x/2`.
    LeftLow22,
}

impl Slope {
    /// Every slope kind, in code order.
    pub const ALL: [Slope; 6] = [
        Slope::Right45,
        Slope::Left45,
        Slope::RightLow22,
        Slope::RightHigh22,
        Slope::LeftHigh22,
        Slope::LeftLow22,
    ];

    /// Height of the surface above the tile's bottom edge, in units, over the
    /// unit column at offset `x` (`0 <= x < tile_size`) from the tile's left
    /// edge; the tile is solid from that height down.
    ///
    /// Exact integers: `x/2` is `floor(x / 2)` in every 22.5 degree formula,
    /// and `tile_size` is even, so the surface is continuous along a ramp in
    /// the discrete sense: over a whole ramp (flat, slope tiles, flat) the
    /// height changes by at most one unit between neighbouring unit columns
    /// and is `floor(X / 2)` (or `T - floor(X / 2)`) of the offset `X` from the
    /// ramp's start for 22.5 degree ramps. The one-unit steps are at the high
    /// end of a rising-right slope (`h(T - 1) = T - 1`, the next tile's top is
    /// `T`) and at the low end of a rising-left one (`h(T - 1) = 1`, the floor
    /// after it is `0`).
    #[inline]
    pub fn height(self, x: i32, tile_size: i32) -> i32 {
        debug_assert!((0..tile_size).contains(&x));
        let t = tile_size;
        match self {
            Slope::Right45 => x,
            Slope::Left45 => t - x,
            Slope::RightLow22 => x / 2,
            Slope::RightHigh22 => t / 2 + x / 2,
            Slope::LeftHigh22 => t - x / 2,
            Slope::LeftLow22 => t / 2 - x / 2,
        }
    }

    /// Whether the surface rises to the right (its highest column is the
    /// rightmost one).
    #[inline]
    pub fn rises_right(self) -> bool {
        matches!(
            self,
            Slope::Right45 | Slope::RightLow22 | Slope::RightHigh22
        )
    }

    /// Internal form of [`Slope::height`].
    #[inline]
    pub(crate) fn height64(self, x: i64, tile_size: i64) -> i64 {
        self.height(x as i32, tile_size as i32) as i64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: i32 = 4096;

    #[test]
    fn heights_at_the_ends() {
        assert_eq!(Slope::Right45.height(0, T), 0);
        assert_eq!(Slope::Right45.height(T - 1, T), T - 1);
        assert_eq!(Slope::Left45.height(0, T), T);
        assert_eq!(Slope::Left45.height(T - 1, T), 1);
        assert_eq!(Slope::RightLow22.height(0, T), 0);
        assert_eq!(Slope::RightLow22.height(T - 1, T), T / 2 - 1);
        assert_eq!(Slope::RightHigh22.height(0, T), T / 2);
        assert_eq!(Slope::RightHigh22.height(T - 1, T), T - 1);
        assert_eq!(Slope::LeftHigh22.height(0, T), T);
        assert_eq!(Slope::LeftHigh22.height(T - 1, T), T / 2 + 1);
        assert_eq!(Slope::LeftLow22.height(0, T), T / 2);
        assert_eq!(Slope::LeftLow22.height(T - 1, T), 1);
    }

    /// Tile sizes: powers of two and not (whole pixels, 18 to 70 px, and
    /// small even unit counts).
    const SIZES: [i32; 9] = [
        T,
        2,
        6,
        10,
        18 * 256,
        21 * 256,
        24 * 256,
        31 * 256,
        70 * 256,
    ];

    #[test]
    fn ramps_are_continuous() {
        for t in SIZES {
            ramps_are_continuous_at(t);
        }
    }

    fn ramps_are_continuous_at(t: i32) {
        // Flat (0) -> low -> high -> flat (T), rising to the right; and the
        // mirror. Height changes by at most one unit per unit column.
        let right = |x: i32| match x {
            x if x < 0 => 0,
            x if x < t => Slope::RightLow22.height(x, t),
            x if x < 2 * t => Slope::RightHigh22.height(x - t, t),
            _ => t,
        };
        let left = |x: i32| match x {
            x if x < 0 => t,
            x if x < t => Slope::LeftHigh22.height(x, t),
            x if x < 2 * t => Slope::LeftLow22.height(x - t, t),
            _ => 0,
        };
        let r45 = |x: i32| x.clamp(0, t);
        let l45 = |x: i32| {
            if x < 0 {
                t
            } else if x < t {
                Slope::Left45.height(x, t)
            } else {
                0
            }
        };
        for x in -2..2 * t + 2 {
            assert!(
                (right(x + 1) - right(x)).abs() <= 1,
                "right 22.5 at {x}, T {t}"
            );
            assert!(
                (left(x + 1) - left(x)).abs() <= 1,
                "left 22.5 at {x}, T {t}"
            );
            assert!((r45(x + 1) - r45(x)).abs() <= 1, "T {t}");
            assert!((l45(x + 1) - l45(x)).abs() <= 1, "T {t}");
            if (0..2 * t).contains(&x) {
                assert_eq!(right(x), x.div_euclid(2), "T {t}");
                assert_eq!(left(x), t - x.div_euclid(2), "T {t}");
            }
            if (0..t).contains(&x) {
                assert_eq!(r45(x), Slope::Right45.height(x, t), "T {t}");
            }
        }
    }

    #[test]
    fn rises_right_matches_heights() {
        // (At T = 2 a 22.5 degree half is flat: heights 0, 0.)
        for t in SIZES.into_iter().filter(|&t| t >= 4) {
            for s in Slope::ALL {
                assert_eq!(
                    s.rises_right(),
                    s.height(t - 1, t) > s.height(0, t),
                    "{s:?} T {t}"
                );
            }
        }
    }
}
