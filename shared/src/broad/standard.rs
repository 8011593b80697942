//! The standard broad-phase benchmark scene, shared by the criterion bench,
//! the comparison CLI (`bench/`) and the tests so that all of them measure
//! the same boxes.
//!
//! `n` axis-aligned boxes with integer sides uniform in 4..=40 px and integer
//! velocities uniform in -4..=4 px per tick per axis, in a square world of
//! side `sqrt(n * 4000)` px. Each tick every box moves `p += v`, first
//! reversing a velocity component that would take it out of the world. All
//! values are whole pixels expressed in units ([`UNITS_PER_PX`]).

use super::bounds::Bounds;
use crate::fixed::{px, UNITS_PER_PX};
use glam::IVec2;

/// A small deterministic generator (SplitMix64): no `rand` in the
/// simulation's dependency tree.
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `lo..=hi` (`lo <= hi`; the tiny modulo bias is irrelevant
    /// here).
    #[inline]
    pub fn range(&mut self, lo: i32, hi: i32) -> i32 {
        let span = (hi as i64 - lo as i64 + 1) as u64;
        (lo as i64 + (self.next_u64() % span) as i64) as i32
    }
}

/// The seed every published figure uses.
pub const SEED: u64 = 0x0001_ed9e_b0a5;

/// The scene: boxes (id = index) and their velocities, in units.
#[derive(Debug, Clone)]
pub struct StandardScene {
    /// `(id, box)` for every body; ids are `0..n`.
    pub boxes: Vec<(u32, Bounds)>,
    /// Velocity of each body, units per tick.
    pub vel: Vec<IVec2>,
    /// Side of the square world, in units; the world is `[0, side]` on both
    /// axes.
    pub side: i32,
}

impl StandardScene {
    /// `n` boxes from `seed`.
    pub fn new(n: usize, seed: u64) -> Self {
        let mut rng = SplitMix64(seed);
        let side_px = ((n as f64 * 4000.0).sqrt().round() as i32).max(200);
        let side = px(side_px);
        let mut boxes = Vec::with_capacity(n);
        let mut vel = Vec::with_capacity(n);
        for i in 0..n {
            let size = IVec2::new(rng.range(4, 40), rng.range(4, 40));
            let min = IVec2::new(
                rng.range(0, side_px - size.x),
                rng.range(0, side_px - size.y),
            );
            boxes.push((
                i as u32,
                Bounds::from_min_size(min * UNITS_PER_PX, size * UNITS_PER_PX),
            ));
            vel.push(IVec2::new(rng.range(-4, 4), rng.range(-4, 4)) * UNITS_PER_PX);
        }
        Self { boxes, vel, side }
    }

    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.boxes.len()
    }

    /// Whether the scene has no body.
    pub fn is_empty(&self) -> bool {
        self.boxes.is_empty()
    }

    /// One tick of motion: reverse each velocity component that would leave
    /// the world, then `p += v`.
    pub fn step(&mut self) {
        let side = self.side;
        for ((_, b), v) in self.boxes.iter_mut().zip(&mut self.vel) {
            if b.min.x + v.x < 0 || b.max.x + v.x > side {
                v.x = -v.x;
            }
            if b.min.y + v.y < 0 || b.max.y + v.y > side {
                v.y = -v.y;
            }
            b.min += *v;
            b.max += *v;
        }
    }
}
