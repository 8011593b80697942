//! A player spawn for a level that has none: the first free standing spot
//! from the left (then from the top), so a map made for another game still
//! starts somewhere sensible. The importer says where it put it.

use glam::IVec2;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::game::PlayerConfig;
use ledge_shared::level::{EntityDef, EntityKind, Level};
use ledge_shared::tilemap::Tile;

/// Most cells the search raster may have; a larger level is searched on
/// coarser cells.
const MAX_CELLS: i64 = 1 << 20;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Cell {
    Free,
    /// Solid: blocks the player, and a floor to stand on.
    Solid,
    /// A floor from above only (one-way tiles).
    Floor,
    /// Hurts: never a place to stand in.
    Hazard,
}

/// A spawn for `level` when [`find`] finds no free standing spot: standing
/// on top of everything in the level, at its left edge (the player lands on
/// whatever is below). `None` for a level with nothing in it.
pub(crate) fn above(level: &Level, player: &PlayerConfig) -> Option<EntityDef> {
    let (lo, _) = level.bounds()?;
    let half = player.half.max(IVec2::ONE);
    Some(EntityDef {
        kind: EntityKind::PlayerSpawn,
        pos: IVec2::new(lo.x.saturating_add(half.x), lo.y.saturating_sub(half.y)),
        size: half * 2,
    })
}

/// A spawn for `level` on the first spot (leftmost column, then topmost)
/// where a player of `player` size stands on a solid or one-way floor with
/// room above and no hazard; `None` when there is no such spot.
pub(crate) fn find(level: &Level, player: &PlayerConfig) -> Option<EntityDef> {
    let map = &level.tilemap;
    let solid = |k: &EntityKind| matches!(k, EntityKind::Block | EntityKind::PolygonBlock { .. });
    // Bounds of everything that collides or hurts, in units.
    let mut lo = map.origin().as_i64vec2();
    let mut hi =
        lo + glam::I64Vec2::new(map.width() as i64, map.height() as i64) * map.tile_size() as i64;
    let boxes: Vec<(glam::I64Vec2, glam::I64Vec2, Cell)> = level
        .entities
        .iter()
        .filter_map(|e| {
            let cell = if solid(&e.kind) {
                Cell::Solid
            } else if e.kind == EntityKind::Hazard {
                Cell::Hazard
            } else {
                return None;
            };
            let half = (e.size / 2).as_i64vec2();
            Some((e.pos.as_i64vec2() - half, e.pos.as_i64vec2() + half, cell))
        })
        .collect();
    for &(a, b, _) in &boxes {
        lo = lo.min(a);
        hi = hi.max(b);
    }
    let mut cell = if map.width() > 0 && map.height() > 0 {
        map.tile_size() as i64
    } else {
        16 * UNITS_PER_PX as i64
    };
    let span = hi - lo;
    if span.x <= 0 || span.y <= 0 {
        return None;
    }
    while (span.x / cell + 1) * (span.y / cell + 1) > MAX_CELLS {
        cell *= 2;
    }
    let (w, h) = ((span.x + cell - 1) / cell, (span.y + cell - 1) / cell);
    let mut grid = vec![Cell::Free; (w * h) as usize];
    let mut mark = |a: glam::I64Vec2, b: glam::I64Vec2, what: Cell| {
        // Cells the box [a, b) overlaps.
        let c0 = ((a.x - lo.x) / cell).clamp(0, w - 1);
        let c1 = ((b.x - 1 - lo.x) / cell).clamp(0, w - 1);
        let r0 = ((a.y - lo.y) / cell).clamp(0, h - 1);
        let r1 = ((b.y - 1 - lo.y) / cell).clamp(0, h - 1);
        for r in r0..=r1 {
            for c in c0..=c1 {
                let g = &mut grid[(r * w + c) as usize];
                // Hazards win, then solids, then floors.
                *g = match (*g, what) {
                    (Cell::Hazard, _) | (_, Cell::Hazard) => Cell::Hazard,
                    (Cell::Solid, _) | (_, Cell::Solid) => Cell::Solid,
                    _ => what,
                };
            }
        }
    };
    let t = map.tile_size() as i64;
    for r in 0..map.height() as i64 {
        for c in 0..map.width() as i64 {
            let what = match map.tile(IVec2::new(c as i32, r as i32)) {
                Tile::Empty => continue,
                Tile::Solid | Tile::Slope(_) => Cell::Solid,
                Tile::OneWay => Cell::Floor,
                Tile::Hazard => Cell::Hazard,
            };
            let a = map.origin().as_i64vec2() + glam::I64Vec2::new(c, r) * t;
            mark(a, a + glam::I64Vec2::splat(t), what);
        }
    }
    for &(a, b, what) in &boxes {
        mark(a, b, what);
    }
    let size = player.half.as_i64vec2() * 2;
    let (cw, ch) = ((size.x + cell - 1) / cell, (size.y + cell - 1) / cell);
    let at = |c: i64, r: i64| grid[(r * w + c) as usize];
    for c in 0..=(w - cw) {
        for r in ch..h {
            // Standing on row r (its top), occupying rows r - ch .. r.
            let floor = (c..c + cw).any(|x| matches!(at(x, r), Cell::Solid | Cell::Floor));
            let room = (r - ch..r).all(|y| (c..c + cw).all(|x| at(x, y) == Cell::Free));
            let safe = (c..c + cw).all(|x| at(x, r) != Cell::Hazard);
            if floor && room && safe {
                let foot = glam::I64Vec2::new(lo.x + c * cell + cw * cell / 2, lo.y + r * cell);
                let half = (size / 2).max(glam::I64Vec2::ONE);
                return Some(EntityDef {
                    kind: EntityKind::PlayerSpawn,
                    pos: IVec2::new(foot.x as i32, (foot.y - half.y) as i32),
                    size: (half * 2).as_ivec2(),
                });
            }
        }
    }
    None
}
