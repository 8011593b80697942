//! False squishes: resting stacks that nothing crushes, under gravity; every
//! [`Event::Squished`] they report is false.
//!
//! One world: a tile floor with a solid border, and on it, 48 px apart,
//! straight stacks of 16 px boxes of every height from 1 to `max_height`,
//! then brick-bonded stacks of the same heights (each box shifted 6 px
//! sideways from the one below, alternately), then the same two kinds of
//! stack on a floor of static 16 px box colliders (whose seams are not
//! culled). Every box starts resting flush on the one below and gets one
//! tick of gravity every tick: a stack pressed down by its own weight, which
//! squished once deeper than the restitution pass budget (see "Propagating
//! passes are free" in `docs/ARCHITECTURE.md`).

use anyhow::Result;
use glam::IVec2;
use ledge_shared::fixed::px;
use ledge_shared::tilemap::{Tile, Tilemap};
use ledge_shared::world::{BodyDesc, BodyId, ColliderDesc, Event, SimConfig, World};

use super::{aabb, apply_gravity};

/// Tile and box size.
const TILE: i32 = px(16);
/// Distance between stacks.
const PITCH: i32 = px(48);

/// Squish events of the stacks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Squish {
    /// Boxes in the stacks.
    pub boxes: u64,
    /// [`Event::Squished`] events over the run (at most one per box per
    /// tick).
    pub squished: u64,
}

/// Runs `ticks` ticks of stacks up to `max_height` boxes with `config`.
pub fn run(config: SimConfig, max_height: u32, ticks: u32) -> Result<Squish> {
    anyhow::ensure!(max_height >= 1, "stacks need a height");
    let stacks = 2 * max_height as i32;
    // Tile floor under the first `stacks` stacks, box floor under the rest.
    let cols = (2 * stacks * PITCH / TILE + 8) as u32;
    let rows = max_height + 4;
    let floor_row = rows - 2;
    let floor_top = floor_row as i32 * TILE;
    let split = 2 + stacks * PITCH / TILE; // first column of the box floor
    let mut tiles = vec![Tile::Empty; (cols * rows) as usize];
    for c in 0..cols {
        tiles[((rows - 1) * cols + c) as usize] = Tile::Solid;
        if (c as i32) < split {
            tiles[(floor_row * cols + c) as usize] = Tile::Solid;
        }
    }
    for r in 0..rows {
        tiles[(r * cols) as usize] = Tile::Solid;
        tiles[(r * cols + cols - 1) as usize] = Tile::Solid;
    }
    let mut w = World::new(config)?;
    w.set_tilemap(Tilemap::new(IVec2::ZERO, TILE, cols, rows, tiles)?);
    let fixed = w.add_body(BodyDesc::fixed(IVec2::ZERO))?;
    for c in split..cols as i32 - 1 {
        let centre = IVec2::new(c * TILE + TILE / 2, floor_top + TILE / 2);
        w.add_collider(
            fixed,
            ColliderDesc::solid(aabb(IVec2::splat(TILE))?).at(centre),
        )?;
    }
    let mut ids: Vec<BodyId> = Vec::new();
    for floor in 0..2 {
        for s in 0..stacks {
            let height = (s % max_height as i32) + 1;
            let brick = s >= max_height as i32;
            let x = (2 + floor * split) * TILE + PITCH / 2 + s * PITCH;
            for k in 0..height {
                let shift = if brick && k % 2 == 1 { px(6) } else { 0 };
                let pos = IVec2::new(x + shift, floor_top - TILE / 2 - k * TILE);
                let body = w.add_body(BodyDesc::dynamic(pos))?;
                w.add_collider(body, ColliderDesc::solid(aabb(IVec2::splat(TILE))?))?;
                ids.push(body);
            }
        }
    }
    let mut out = Squish {
        boxes: ids.len() as u64,
        squished: 0,
    };
    for _ in 0..ticks {
        apply_gravity(&mut w, &ids)?;
        let events = w.step(&[]);
        out.squished += events
            .iter()
            .filter(|e| matches!(e, Event::Squished { .. }))
            .count() as u64;
    }
    Ok(out)
}
