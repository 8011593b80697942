//! Seams: boxes the size of a player (12 x 16 px) sliding along a flat floor
//! while pressed into it, as a running player is; the motion the floor's
//! seams take from them.
//!
//! Two floors, in two worlds: a row of solid tiles (the tilemap culls the
//! faces between tiles) and a row of 16 px static box colliders side by side
//! (nothing culls their inner faces). On each floor one box per (speed,
//! start offset): speeds 100, 640 (the player's run) and 1,280 units per
//! tick, start offsets from the seams every `offset_step` units of the
//! 256 subpixel offsets of a pixel, so seams are crossed at every subpixel
//! phase. Boxes ignore each other (layers). Every tick sets each box's
//! horizontal velocity to its speed and adds gravity to its vertical one
//! (the world removes it when the floor stops the box); every
//! [`HOP_PERIOD`] ticks a box on the floor hops (as a running player jumps),
//! so boxes also land on seams, at up to 5 px per tick. The motion lost in a
//! tick is the speed minus the box's actual displacement.
//!
//! Two more floors run the platformer itself, so the player's shape
//! ([`ledge_shared::game::PlayerShape`]) and rules count: a level whose
//! ground is a row of solid tiles, and one whose ground is a row of 16 px
//! `Block` entities (static boxes). One player per start offset (a spawn
//! point per offset; players never collide with each other) holds right;
//! in each tick it starts at full run speed, the motion lost is that speed
//! minus its displacement.
//!
//! The result is the lost motion per seam that the intended paths cross.

use anyhow::Result;
use glam::IVec2;
use ledge_shared::fixed::px;
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::level::{EntityDef, EntityKind, Level};
use ledge_shared::protocol::PlayerId;
use ledge_shared::tilemap::{Tile, Tilemap};
use ledge_shared::world::{BodyDesc, BodyId, ColliderDesc, SimConfig, World, TILEMAP_LAYER};

use super::{aabb, GRAVITY, MAX_FALL};

/// Ticks between hops of a box (each box hops at its own phase).
pub const HOP_PERIOD: u32 = 48;
/// Upward speed of a hop, units per tick (the player's jump).
const HOP_SPEED: i32 = 1280;

/// Tile (and floor box) width.
const TILE: i32 = px(16);
/// Sliding speeds, units per tick.
pub const SPEEDS: [i32; 3] = [100, 640, 1280];
/// The sliding box.
const BOX: IVec2 = IVec2::new(px(12), px(16));
/// Row of the floor (its top is at `FLOOR_ROW * TILE`).
const FLOOR_ROW: i32 = 2;
/// Layers: the floor boxes, the sliders (meet floors and tiles only).
const FLOOR_LAYER: u32 = 1;
const SLIDER_LAYER: u32 = 2;

/// Motion lost at seams, per floor.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Seams {
    /// Seams crossed by the boxes' intended paths (the same on both
    /// floors).
    pub crossings: u64,
    /// Units of motion lost on the tile floor.
    pub lost_tiles: u64,
    /// Units of motion lost on the floor of box colliders.
    pub lost_boxes: u64,
    /// Seams crossed by the players' intended paths on the tile ground.
    pub game_crossings_tiles: u64,
    /// Units of motion the players lost there.
    pub game_lost_tiles: u64,
    /// Seams crossed by the players' intended paths on the block ground.
    pub game_crossings_blocks: u64,
    /// Units of motion the players lost there.
    pub game_lost_blocks: u64,
}

impl Seams {
    /// Units lost per seam crossed on the tile floor.
    pub fn per_seam_tiles(&self) -> f64 {
        self.lost_tiles as f64 / self.crossings.max(1) as f64
    }

    /// Units lost per seam crossed on the floor of boxes.
    pub fn per_seam_boxes(&self) -> f64 {
        self.lost_boxes as f64 / self.crossings.max(1) as f64
    }

    /// Units the players lost per seam crossed, both grounds together.
    pub fn per_seam_game(&self) -> f64 {
        (self.game_lost_tiles + self.game_lost_blocks) as f64
            / (self.game_crossings_tiles + self.game_crossings_blocks).max(1) as f64
    }

    /// Units lost per seam crossed, all four floors together.
    pub fn per_seam(&self) -> f64 {
        let lost = self.lost_tiles + self.lost_boxes + self.game_lost_tiles + self.game_lost_blocks;
        let crossed = 2 * self.crossings + self.game_crossings_tiles + self.game_crossings_blocks;
        lost as f64 / crossed.max(1) as f64
    }
}

/// Slides for `ticks` ticks with start offsets every `offset_step` units
/// (1 = all 256).
pub fn run(config: GameConfig, ticks: u32, offset_step: i32) -> Result<Seams> {
    anyhow::ensure!((1..=256).contains(&offset_step), "offset step in 1..=256");
    let cols = ((3 * TILE + SPEEDS[2] * ticks as i32) / TILE + 8) as u32;
    let sim = config.sim;
    let (crossings, lost_tiles) = slide(sim, ticks, offset_step, Floor::Tiles(cols))?;
    let (_, lost_boxes) = slide(sim, ticks, offset_step, Floor::Boxes(cols, 0))?;
    let (game_crossings_tiles, game_lost_tiles) = run_players(config, ticks, offset_step, false)?;
    let (game_crossings_blocks, game_lost_blocks) = run_players(config, ticks, offset_step, true)?;
    Ok(Seams {
        crossings,
        lost_tiles,
        lost_boxes,
        game_crossings_tiles,
        game_lost_tiles,
        game_crossings_blocks,
        game_lost_blocks,
    })
}

/// The players' run: a level `cols` tiles long whose ground (row
/// [`FLOOR_ROW`] + 2) is solid tiles, or `Block` entities with `blocks`; a
/// spawn per start offset. Returns (seams crossed at full speed, units lost).
fn run_players(config: GameConfig, ticks: u32, step: i32, blocks: bool) -> Result<(u64, u64)> {
    let run = config.player.max_run_speed;
    let cols = ((4 * TILE + run * ticks as i32) / TILE + 8) as u32;
    let rows = 8u32;
    let ground = rows - 2;
    let top = ground as i32 * TILE;
    let mut tiles = vec![Tile::Empty; (cols * rows) as usize];
    for c in 0..cols {
        tiles[((rows - 1) * cols + c) as usize] = Tile::Solid;
        if !blocks {
            tiles[(ground * cols + c) as usize] = Tile::Solid;
        }
    }
    let mut entities = Vec::new();
    if blocks {
        for c in 0..cols as i32 {
            entities.push(EntityDef {
                kind: EntityKind::Block,
                pos: IVec2::new(c * TILE + TILE / 2, top + TILE / 2),
                size: IVec2::splat(TILE),
            });
        }
    }
    let half = config.player.half;
    let offsets: Vec<i32> = (0..256).step_by(step as usize).collect();
    for &o in &offsets {
        // The player stands on the spawn box's bottom, centred in x.
        entities.push(EntityDef {
            kind: EntityKind::PlayerSpawn,
            pos: IVec2::new(2 * TILE + half.x + o, top - TILE / 2),
            size: IVec2::splat(TILE),
        });
    }
    let level = Level {
        name: "seams".to_owned(),
        tilemap: Tilemap::new(IVec2::ZERO, TILE, cols, rows, tiles)?,
        entities,
        player: Default::default(),
    };
    let mut game = Game::with_config(&level, config)?;
    let n = offsets.len() as u32;
    for id in 0..n {
        game.add_player(PlayerId(id))?;
    }
    let inputs: Vec<(PlayerId, Buttons)> = (0..n)
        .map(|id| (PlayerId(id), Buttons(Buttons::RIGHT)))
        .collect();
    let mut before: Vec<(i32, i32)> = Vec::with_capacity(n as usize);
    let (mut crossings, mut lost) = (0u64, 0u64);
    for _ in 0..ticks {
        before.clear();
        before.extend(game.player_views().map(|p| (p.pos.x, p.vel.x)));
        game.step(&inputs);
        for (p, &(x0, v0)) in game.player_views().zip(&before) {
            if v0 != run {
                continue;
            }
            let front = x0 + half.x;
            crossings += ((front + run).div_euclid(TILE) - front.div_euclid(TILE)) as u64;
            lost += (run - (p.pos.x - x0)).max(0) as u64;
        }
    }
    Ok((crossings, lost))
}

/// Which floor a world has, `n` tiles long: tiles, or boxes with every
/// fourth one raised by the second field (units; 0 in the scene, a step
/// in the tests).
#[derive(Debug, Clone, Copy)]
enum Floor {
    Tiles(u32),
    Boxes(u32, i32),
}

/// One world: returns (seams crossed by the intended paths, units lost).
fn slide(config: SimConfig, ticks: u32, step: i32, floor: Floor) -> Result<(u64, u64)> {
    let mut w = World::new(config)?;
    match floor {
        Floor::Tiles(cols) => {
            let rows = FLOOR_ROW as u32 + 2;
            let mut tiles = vec![Tile::Empty; (cols * rows) as usize];
            for c in 0..cols {
                tiles[(FLOOR_ROW as u32 * cols + c) as usize] = Tile::Solid;
            }
            w.set_tilemap(Tilemap::new(IVec2::ZERO, TILE, cols, rows, tiles)?);
        }
        Floor::Boxes(cols, raise) => {
            let fixed = w.add_body(BodyDesc::fixed(IVec2::ZERO))?;
            for c in 0..cols as i32 {
                let up = if c % 4 == 3 { raise } else { 0 };
                let centre = IVec2::new(c * TILE + TILE / 2, FLOOR_ROW * TILE + TILE / 2 - up);
                let d = ColliderDesc::solid(aabb(IVec2::splat(TILE))?)
                    .at(centre)
                    .layers(FLOOR_LAYER, u32::MAX);
                w.add_collider(fixed, d)?;
            }
        }
    }
    let mut sliders: Vec<(BodyId, i32)> = Vec::new();
    let mut crossings = 0u64;
    for &speed in &SPEEDS {
        for offset in (0..256).step_by(step as usize) {
            let left = 2 * TILE + offset;
            let pos = IVec2::new(left + BOX.x / 2, FLOOR_ROW * TILE - BOX.y / 2);
            let body = w.add_body(BodyDesc::dynamic(pos))?;
            let d =
                ColliderDesc::solid(aabb(BOX)?).layers(SLIDER_LAYER, FLOOR_LAYER | TILEMAP_LAYER);
            w.add_collider(body, d)?;
            sliders.push((body, speed));
            let front = left + BOX.x;
            let end = front + speed * ticks as i32;
            crossings += (end.div_euclid(TILE) - front.div_euclid(TILE)) as u64;
        }
    }
    let mut before = Vec::with_capacity(sliders.len());
    let mut lost = 0u64;
    for t in 0..ticks {
        before.clear();
        for (i, &(b, speed)) in sliders.iter().enumerate() {
            let (pos, vel) = w
                .body(b)
                .map_or((IVec2::ZERO, IVec2::ZERO), |b| (b.pos(), b.vel()));
            let hop = (t + i as u32) % HOP_PERIOD == 0 && vel.y == 0;
            let vy = if hop {
                -HOP_SPEED
            } else {
                (vel.y + GRAVITY).min(MAX_FALL)
            };
            w.set_velocity(b, IVec2::new(speed, vy))?;
            before.push(pos.x);
        }
        w.step(&[]);
        for (&(b, speed), &x0) in sliders.iter().zip(&before) {
            let dx = w.body(b).map_or(0, |b| b.pos().x) - x0;
            lost += (speed - dx).max(0) as u64;
        }
    }
    Ok((crossings, lost))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_floor_loses_nothing_and_a_step_is_counted() {
        let sim = SimConfig::default();
        let (crossed, flat) = slide(sim, 60, 64, Floor::Boxes(40, 0)).unwrap();
        assert!(crossed > 0);
        assert_eq!(flat, 0);
        // A 4 px step every fourth box stops every slider that reaches it
        // on the ground (a 12 px box cannot climb it).
        let (_, stepped) = slide(sim, 60, 64, Floor::Boxes(40, px(4))).unwrap();
        assert!(stepped > 0);
    }

    #[test]
    fn players_cross_seams_at_full_speed() {
        let s = run(GameConfig::default(), 60, 128).unwrap();
        assert!(s.game_crossings_tiles > 0 && s.game_crossings_blocks > 0);
        assert_eq!(s.game_crossings_tiles, s.game_crossings_blocks);
    }
}
