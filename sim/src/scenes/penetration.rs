//! Penetration: boxes of several sizes and masses dropped into a tiled bin
//! with shelves, landing on the floor, the shelves and each other under
//! gravity; after every tick, the deepest overlap between two solids that
//! the tick left (every contact at the bodies' final positions, through
//! [`World::detect_contacts`]). The pile also counts squish events: nothing
//! crushes it, so every one is false (added to [`super::squish`]'s).

use anyhow::Result;
use glam::IVec2;
use ledge_shared::broad::standard::SplitMix64;
use ledge_shared::fixed::px;
use ledge_shared::tilemap::{Tile, Tilemap};
use ledge_shared::world::{BodyDesc, BodyId, ColliderDesc, ContactKind, Event, SimConfig, World};

use super::{aabb, apply_gravity, MAX_FALL};

/// Tile size of the bin.
const TILE: i32 = px(16);
/// Bin size in tiles.
const COLS: u32 = 40;
const ROWS: u32 = 48;

/// The deepest overlaps seen.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Penetration {
    /// Largest MTV length left after any tick, units.
    pub max: i64,
    /// Mean over ticks of the largest MTV length left after the tick, units.
    pub mean_of_max: f64,
    /// Squish events over the run: all false (nothing crushes the pile).
    pub squished: u64,
}

/// The bin (640 x 768 px): solid border, two solid shelves a third of the
/// way up.
fn bin() -> Result<Tilemap> {
    let mut tiles = vec![Tile::Empty; (COLS * ROWS) as usize];
    for r in 0..ROWS {
        for c in 0..COLS {
            let border = r == ROWS - 1 || c == 0 || c == COLS - 1;
            let shelf = r == 2 * ROWS / 3 && ((4..12).contains(&c) || (28..36).contains(&c));
            if border || shelf {
                tiles[(r * COLS + c) as usize] = Tile::Solid;
            }
        }
    }
    Ok(Tilemap::new(IVec2::ZERO, TILE, COLS, ROWS, tiles)?)
}

/// The landing pile: its world and its boxes.
#[derive(Debug, Clone)]
pub struct Pile {
    world: World,
    ids: Vec<BodyId>,
}

impl Pile {
    /// `bodies` boxes (seed `seed`) above the bin, in a world configured
    /// with `config`.
    pub fn new(config: SimConfig, bodies: usize, seed: u64) -> Result<Self> {
        let mut rng = SplitMix64(seed);
        let mut w = World::new(config)?;
        w.set_tilemap(bin()?);
        // Spawn on a grid of 28 px cells over the upper part of the bin,
        // high ones first, each with a random sideways and downward
        // velocity.
        let cell = px(28);
        let per_row = ((COLS as i32 - 2) * TILE / cell) as usize;
        // 16 rows of cells end above the shelves (row 32).
        anyhow::ensure!(
            bodies <= 16 * per_row,
            "the landing pile holds at most {} boxes",
            16 * per_row
        );
        let mut ids = Vec::with_capacity(bodies);
        for k in 0..bodies {
            let (col, row) = ((k % per_row) as i32, (k / per_row) as i32);
            let size = IVec2::new(px(2 * rng.range(4, 12)), px(2 * rng.range(4, 12)));
            let pos = IVec2::new(TILE + cell / 2 + col * cell, TILE + cell / 2 + row * cell);
            let vel = IVec2::new(rng.range(-640, 640), rng.range(0, MAX_FALL));
            let body = w.add_body(
                BodyDesc::dynamic(pos)
                    .with_vel(vel)
                    .with_mass(1 + (k % 3) as u32),
            )?;
            w.add_collider(body, ColliderDesc::solid(aabb(size)?))?;
            ids.push(body);
        }
        Ok(Self { world: w, ids })
    }

    /// One tick: gravity, then the world's step; returns the squish events
    /// of the tick.
    pub fn tick(&mut self) -> Result<u64> {
        apply_gravity(&mut self.world, &self.ids)?;
        Ok(self
            .world
            .step(&[])
            .iter()
            .filter(|e| matches!(e, Event::Squished { .. }))
            .count() as u64)
    }

    /// The deepest solid overlap now (MTV length, units).
    pub fn deepest(&mut self) -> i64 {
        self.world
            .detect_contacts()
            .iter()
            .filter(|c| c.kind() == ContactKind::Solid)
            .map(|c| length(c.mtv()))
            .max()
            .unwrap_or(0)
    }
}

/// Drops `bodies` boxes (seed `seed`) and runs `ticks` ticks with `config`.
pub fn run(config: SimConfig, bodies: usize, ticks: u32, seed: u64) -> Result<Penetration> {
    let mut pile = Pile::new(config, bodies, seed)?;
    let mut out = Penetration::default();
    let mut sum = 0i64;
    for _ in 0..ticks {
        out.squished += pile.tick()?;
        let deepest = pile.deepest();
        out.max = out.max.max(deepest);
        sum += deepest;
    }
    out.mean_of_max = sum as f64 / ticks.max(1) as f64;
    Ok(out)
}

/// Euclidean length of `v` in units, rounded up.
fn length(v: IVec2) -> i64 {
    let sq = (v.x as i64).pow(2) + (v.y as i64).pow(2);
    let mut r = (sq as f64).sqrt() as i64;
    while r * r < sq {
        r += 1;
    }
    while r > 0 && (r - 1) * (r - 1) >= sq {
        r -= 1;
    }
    r
}
