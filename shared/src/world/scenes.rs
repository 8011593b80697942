//! Scenes for tests and benchmarks of the world pipeline (seeded, fully
//! deterministic, built through the public API only).
//!
//! * [`boxes`]: the broad-phase standard scene ([`crate::broad::standard`])
//!   as world bodies: `n` dynamic boxes driven by top-down movers inside four
//!   static walls. AABBs only, no tilemap: the fast path's scene.
//! * [`tile_room`]: a feature-poor level: a grid of solid tiles (border,
//!   pillars, shelves), a few static blocks and `n` dynamic boxes with
//!   movers. Tiles and boxes only: no slope, one-way, trigger, kinematic body
//!   or rider.
//! * [`mixed`]: everything at once: every shape kind moving, static segments
//!   and polygons, triggers, one-way colliders, kinematic platforms with
//!   riders, and a tilemap with slopes, one-way and hazard tiles.
//!
//! Every body with a mover takes one input slot, in body order; [`inputs`]
//! fills a tick's inputs for all of them.

use crate::broad::standard::{SplitMix64, StandardScene};
use crate::fixed::px;
use crate::input::Buttons;
use crate::scene::{scripted_inputs, MOVER};
use crate::shape::{Aabb, Circle, ConvexPolygon, Obb, Point, Segment};
use crate::tilemap::{Slope, Tile, Tilemap};
use glam::IVec2;

use super::{
    BodyDesc, BodyId, BuildError, ColliderDesc, Controller, Mover, OneWay, SimConfig, World,
};

/// Tile size of the tile scenes: 16 px.
pub const TILE: i32 = px(16);

/// The inputs of tick `tick` for every slot of `out`: slot `k` plays
/// [`scripted_inputs`] shifted by `k * 7919` ticks, so bodies wander
/// independently.
pub fn inputs(tick: u64, out: &mut [Buttons]) {
    for (k, b) in out.iter_mut().enumerate() {
        *b = scripted_inputs(tick.wrapping_add(7919 * k as u64));
    }
}

/// Adds a mover for `body` (next input slot).
fn drive(w: &mut World, body: BodyId) -> Result<(), BuildError> {
    w.add_controller(Controller::Mover(Mover {
        body,
        config: MOVER,
    }))?;
    Ok(())
}

/// A box shape of full size `size` (units, even).
fn aabb(size: IVec2) -> Aabb {
    Aabb::new(size / 2).expect("scene boxes are valid")
}

/// Four static walls, 64 px thick, around `[0, side]^2`, on one static body.
fn walls(w: &mut World, side: i32) -> Result<(), BuildError> {
    let t = px(64);
    let body = w.add_body(BodyDesc::fixed(IVec2::ZERO))?;
    let h = side / 2;
    for (centre, size) in [
        (IVec2::new(h, -t / 2), IVec2::new(side + 2 * t, t)),
        (IVec2::new(h, side + t / 2), IVec2::new(side + 2 * t, t)),
        (IVec2::new(-t / 2, h), IVec2::new(t, side)),
        (IVec2::new(side + t / 2, h), IVec2::new(t, side)),
    ] {
        w.add_collider(body, ColliderDesc::solid(aabb(size)).at(centre))?;
    }
    Ok(())
}

/// The broad-phase standard scene of `n` boxes (seed `seed`) as dynamic
/// bodies: each box keeps its size and position, starts with its velocity
/// and is driven by a [`MOVER`] (input slot = box index); four static walls
/// close the square. Overlapping boxes at the start are pushed apart by the
/// first ticks.
pub fn boxes(n: usize, seed: u64, config: SimConfig) -> Result<World, BuildError> {
    let scene = StandardScene::new(n, seed);
    let mut w = World::new(config)?;
    for ((_, b), v) in scene.boxes.iter().zip(&scene.vel) {
        let size = b.max - b.min;
        let body = w.add_body(BodyDesc::dynamic((b.min + b.max) / 2).with_vel(*v))?;
        w.add_collider(body, ColliderDesc::solid(aabb(size)))?;
        drive(&mut w, body)?;
    }
    walls(&mut w, scene.side)?;
    Ok(w)
}

/// The tile grid of the tile scenes: about `4000 n` px^2 of room, solid
/// border, 2 x 2 solid pillars every 8 tiles and a solid shelf every 12
/// rows; with `rich`, also 45 and 22.5 degree slopes, one-way shelves and
/// hazard tiles.
fn room_tiles(n: usize, rich: bool) -> Tilemap {
    let side = ((((n as f64) * 4000.0).sqrt() / 16.0).ceil() as u32).max(24);
    let (wd, ht) = (side, side);
    let mut tiles = vec![Tile::Empty; (wd * ht) as usize];
    let mut set = |c: u32, r: u32, t: Tile| {
        if c < wd && r < ht {
            tiles[(r * wd + c) as usize] = t;
        }
    };
    for c in 0..wd {
        set(c, 0, Tile::Solid);
        set(c, ht - 1, Tile::Solid);
    }
    for r in 0..ht {
        set(0, r, Tile::Solid);
        set(wd - 1, r, Tile::Solid);
    }
    for r in (6..ht - 2).step_by(8) {
        for c in (6..wd - 2).step_by(8) {
            for (dc, dr) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                set(c + dc, r + dr, Tile::Solid);
            }
        }
    }
    for r in (11..ht - 2).step_by(12) {
        for c in 2..6 {
            let t = if rich && r % 24 == 11 {
                Tile::OneWay
            } else {
                Tile::Solid
            };
            set(c, r, t);
        }
    }
    if rich {
        // A 45 degree hill and a 22.5 degree ramp on the floor, spikes
        // between them.
        let f = ht - 2;
        set(3, f, Tile::Slope(Slope::Right45));
        set(4, f, Tile::Solid);
        set(5, f, Tile::Slope(Slope::Left45));
        set(8, f, Tile::Slope(Slope::RightLow22));
        set(9, f, Tile::Slope(Slope::RightHigh22));
        set(10, f, Tile::Solid);
        set(11, f, Tile::Slope(Slope::LeftHigh22));
        set(12, f, Tile::Slope(Slope::LeftLow22));
        set(14, f, Tile::Hazard);
        set(15, f, Tile::Hazard);
    }
    Tilemap::new(IVec2::ZERO, TILE, wd, ht, tiles).expect("scene tilemap is valid")
}

/// A free spot for a box of full size `size` in `map`: no tile (of any
/// kind) under it; `None` after 64 tries.
fn free_spot(map: &Tilemap, rng: &mut SplitMix64, size: IVec2) -> Option<IVec2> {
    let (wd, ht) = (
        map.width() as i32 * map.tile_size(),
        map.height() as i32 * map.tile_size(),
    );
    for _ in 0..64 {
        let c = IVec2::new(
            rng.range(size.x / 2 + TILE, wd - size.x / 2 - TILE),
            rng.range(size.y / 2 + TILE, ht - size.y / 2 - TILE),
        );
        let (lo, hi) = (c - size / 2, c + size / 2 - 1);
        let (t0, t1) = (map.tile_of(lo), map.tile_of(hi));
        let clear =
            (t0.y..=t1.y).all(|r| (t0.x..=t1.x).all(|q| map.tile(IVec2::new(q, r)) == Tile::Empty));
        if clear {
            return Some(c);
        }
    }
    None
}

/// An even pixel size in `lo..=hi` px.
fn even_px(rng: &mut SplitMix64, lo: i32, hi: i32) -> i32 {
    px(rng.range(lo / 2, hi / 2) * 2)
}

/// The feature-poor level: a room of tiles (solid tiles only: about
/// `4000 n` px^2, solid border, pillars and shelves), one static
/// block (16..48 px) per 50 boxes on one static body, and `n` dynamic boxes
/// of 8..24 px with movers, placed on empty tiles.
pub fn tile_room(n: usize, seed: u64, config: SimConfig) -> Result<World, BuildError> {
    let map = room_tiles(n, false);
    let mut rng = SplitMix64(seed);
    let mut w = World::new(config)?;
    let fixed = w.add_body(BodyDesc::fixed(IVec2::ZERO))?;
    for _ in 0..n.div_ceil(50) {
        let size = IVec2::new(even_px(&mut rng, 16, 48), even_px(&mut rng, 16, 48));
        if let Some(c) = free_spot(&map, &mut rng, size) {
            w.add_collider(fixed, ColliderDesc::solid(aabb(size)).at(c))?;
        }
    }
    for _ in 0..n {
        let size = IVec2::new(even_px(&mut rng, 8, 24), even_px(&mut rng, 8, 24));
        if let Some(c) = free_spot(&map, &mut rng, size) {
            let body = w.add_body(BodyDesc::dynamic(c))?;
            w.add_collider(body, ColliderDesc::solid(aabb(size)))?;
            drive(&mut w, body)?;
        }
    }
    w.set_tilemap(map);
    Ok(w)
}

/// Everything at once, `n` moving bodies: the room of [`tile_room`] with
/// slopes, one-way shelves and hazards; static blocks, segments, polygons,
/// a one-way box and trigger pads; kinematic platforms (one in 20 bodies, some
/// one-way) and dynamic bodies of every shape kind, all driven by movers;
/// dynamic boxes are riders, one body in ten carries a trigger sensor, and
/// one in seven is on a layer that ignores itself.
pub fn mixed(n: usize, seed: u64, config: SimConfig) -> Result<World, BuildError> {
    let map = room_tiles(n, true);
    let mut rng = SplitMix64(seed);
    let mut w = World::new(config)?;
    let fixed = w.add_body(BodyDesc::fixed(IVec2::ZERO))?;
    for k in 0..n.div_ceil(20) {
        let size = IVec2::new(even_px(&mut rng, 16, 48), even_px(&mut rng, 8, 32));
        let Some(c) = free_spot(&map, &mut rng, size) else {
            continue;
        };
        let d = match k % 5 {
            0 => ColliderDesc::solid(aabb(size)),
            1 => ColliderDesc::solid(
                Segment::new(-size / 2, IVec2::new(size.x / 2, -size.y / 2 + px(4)))
                    .expect("segment"),
            ),
            2 => ColliderDesc::solid(hexagon(size.x / 2)),
            3 => ColliderDesc::solid(aabb(IVec2::new(size.x, px(8)))).one_way(OneWay::Up),
            _ => ColliderDesc::trigger(aabb(size)).tagged(9),
        };
        w.add_collider(fixed, d.at(c))?;
    }
    for k in 0..n {
        let size = IVec2::new(even_px(&mut rng, 8, 24), even_px(&mut rng, 8, 24));
        let Some(c) = free_spot(&map, &mut rng, size) else {
            continue;
        };
        if k % 20 == 19 {
            let body = w.add_body(BodyDesc::kinematic(c))?;
            let mut d = ColliderDesc::solid(aabb(IVec2::new(size.x * 2, px(8))));
            if k % 40 == 39 {
                d = d.one_way(OneWay::Up);
            }
            w.add_collider(body, d)?;
            drive(&mut w, body)?;
            continue;
        }
        let body = w.add_body(BodyDesc::dynamic(c).with_mass(1 + (k % 3) as u32))?;
        let h = size / 2;
        let d = match k % 6 {
            0 => ColliderDesc::solid(Point),
            1 => ColliderDesc::solid(Segment::new(-h, h).expect("segment")),
            2 => ColliderDesc::solid(Circle::new(h.x).expect("circle")),
            3 => ColliderDesc::solid(
                Obb::new(h, IVec2::new(rng.range(-100, 100), rng.range(1, 100))).expect("obb"),
            ),
            4 => ColliderDesc::solid(hexagon(h.x)),
            _ => ColliderDesc::solid(aabb(size)),
        };
        // One body in seven is on layer 2 and ignores that layer: those pass
        // through each other and meet everything else.
        let d = if k % 7 == 3 { d.layers(2, !2) } else { d };
        w.add_collider(body, d)?;
        if k % 6 == 5 {
            w.set_rider(body, true)?;
        }
        if k % 10 == 7 {
            w.add_collider(
                body,
                ColliderDesc::trigger(Circle::new(px(10)).expect("circle")),
            )?;
        }
        drive(&mut w, body)?;
    }
    w.set_tilemap(map);
    Ok(w)
}

/// A hexagon of radius about `r` units around the origin.
fn hexagon(r: i32) -> ConvexPolygon {
    const DIRS: [(i32, i32); 6] = [
        (256, 0),
        (128, 222),
        (-128, 222),
        (-256, 0),
        (-128, -222),
        (128, -222),
    ];
    let s = (r / 256).max(1);
    let pts: Vec<IVec2> = DIRS
        .iter()
        .map(|&(x, y)| IVec2::new(x * s, y * s))
        .collect();
    ConvexPolygon::new(&pts).expect("hexagon")
}
