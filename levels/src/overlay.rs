//! The collision overlay as shapes: what collides (solid, one-way, slope and
//! hazard tiles, blocks and polygons), the entities' boxes, the spawn
//! entities and a player's box where the game spawns one, each a convex
//! polygon in world pixels with its [`palette::overlay`] colour.
//!
//! `ledge-level render` and the client's window (the C key) both draw these
//! shapes, in the same order, so the two pictures show the same thing:
//! first [`Overlay::fixed`] (tiles through [`tile_shapes`], then static
//! solids, hazards and spawns), then every other entity's box
//! ([`entity_shapes`]: the client takes them where the game has them this
//! frame), then [`Overlay::players`] on top.

use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::game::{EntityType, Game};
use ledge_shared::level::{EntityKind, Level};
use ledge_shared::protocol::PlayerId;
use ledge_shared::tilemap::{Slope, Tile, Tilemap};

use crate::palette::{overlay, Rgba};

/// Most corners of a [`Shape`] (a polygon block's most vertices).
pub const MAX_SHAPE_POINTS: usize = 8;

/// Thickness of outlines, world pixels.
pub const OUTLINE_PX: f32 = 1.0;

/// Height of the band on top of one-way tiles and platforms, world pixels.
pub const ONE_WAY_EDGE_PX: f32 = 2.0;

/// A convex polygon to fill, world pixels, with its colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape {
    points: [[f32; 2]; MAX_SHAPE_POINTS],
    len: u8,
    /// Its colour.
    pub color: Rgba,
}

impl Shape {
    /// A convex polygon of the first [`MAX_SHAPE_POINTS`] of `points`.
    pub fn polygon(points: &[[f32; 2]], color: Rgba) -> Shape {
        let mut s = Shape {
            points: [[0.0; 2]; MAX_SHAPE_POINTS],
            len: points.len().min(MAX_SHAPE_POINTS) as u8,
            color,
        };
        s.points[..s.len as usize].copy_from_slice(&points[..s.len as usize]);
        s
    }

    /// A rectangle: top-left `x, y`, size `w, h`.
    pub fn rect(x: f32, y: f32, w: f32, h: f32, color: Rgba) -> Shape {
        Shape::polygon(&[[x, y], [x + w, y], [x + w, y + h], [x, y + h]], color)
    }

    /// Its corners, in order.
    pub fn points(&self) -> &[[f32; 2]] {
        &self.points[..self.len as usize]
    }

    /// Its bounding box: `[left, top, right, bottom]`.
    pub fn bounds(&self) -> [f32; 4] {
        let mut b = [f32::MAX, f32::MAX, f32::MIN, f32::MIN];
        for p in self.points() {
            b = [
                b[0].min(p[0]),
                b[1].min(p[1]),
                b[2].max(p[0]),
                b[3].max(p[1]),
            ];
        }
        b
    }
}

/// The overlay's shapes that do not move: static solids, hazards and
/// spawns ([`Overlay::fixed`], drawn after the tiles), and a player's box
/// at each spawn ([`Overlay::players`], drawn last).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overlay {
    /// Blocks, polygon blocks, hazard entities and spawn entities' boxes.
    pub fixed: Vec<Shape>,
    /// A player's box (the game's player size) where the game spawns the
    /// first player of each spawn.
    pub players: Vec<Shape>,
}

fn px(u: i32) -> f32 {
    u as f32 / UNITS_PER_PX as f32
}

/// Whether entities of type `t` are part of [`Overlay::fixed`] (they never
/// move); the others are drawn with [`entity_shapes`].
pub fn is_fixed(t: EntityType) -> bool {
    matches!(
        t,
        EntityType::Spawn | EntityType::Block | EntityType::PolygonBlock | EntityType::Hazard
    )
}

/// The entity type of a level entity, and whether it is one-way.
pub fn entity_type(kind: &EntityKind) -> Option<(EntityType, bool)> {
    Some(match kind {
        EntityKind::PlayerSpawn => (EntityType::Spawn, false),
        EntityKind::Block => (EntityType::Block, false),
        EntityKind::PolygonBlock { .. } => (EntityType::PolygonBlock, false),
        EntityKind::MovingPlatform { one_way, .. } => (EntityType::Platform, *one_way),
        EntityKind::Walker { .. } => (EntityType::Walker, false),
        EntityKind::Springboard { .. } => (EntityType::Springboard, false),
        EntityKind::Coin => (EntityType::Coin, false),
        EntityKind::Checkpoint => (EntityType::Checkpoint, false),
        EntityKind::Goal => (EntityType::Goal, false),
        EntityKind::Hazard => (EntityType::Hazard, false),
        #[allow(unreachable_patterns)]
        _ => return None,
    })
}

impl Overlay {
    /// The fixed shapes and the players' boxes of `level`.
    pub fn of_level(level: &Level) -> Overlay {
        let mut fixed = Vec::new();
        for e in &level.entities {
            let (c, s) = ([px(e.pos.x), px(e.pos.y)], [px(e.size.x), px(e.size.y)]);
            match (&e.kind, entity_type(&e.kind)) {
                (EntityKind::PolygonBlock { vertices }, _) => {
                    let pts: Vec<[f32; 2]> = vertices
                        .iter()
                        .take(MAX_SHAPE_POINTS)
                        .map(|v| [c[0] + px(v.x), c[1] + px(v.y)])
                        .collect();
                    outlined(Shape::polygon(&pts, overlay::SOLID), &mut fixed);
                }
                (_, Some((t, one_way))) if is_fixed(t) => {
                    entity_shapes(t, one_way, c, s, &mut fixed)
                }
                _ => {}
            }
        }
        Overlay {
            fixed,
            players: player_boxes(level),
        }
    }
}

/// A player's box where the game spawns the first player of each spawn
/// (the game's own spots and player size), filled and outlined.
fn player_boxes(level: &Level) -> Vec<Shape> {
    let mut out = Vec::new();
    let spawns = level
        .entities
        .iter()
        .filter(|e| e.kind == EntityKind::PlayerSpawn)
        .count()
        .min(1024);
    let Ok(mut game) = Game::from_level(level) else {
        return out;
    };
    for id in 1..=spawns as u32 {
        let _ = game.add_player(PlayerId(id));
    }
    let half = game.config().player.half;
    let (w, h) = (px(half.x) * 2.0, px(half.y) * 2.0);
    for (_, pos) in game.players() {
        let (x, y) = (px(pos.x) - w / 2.0, px(pos.y) - h / 2.0);
        outlined(Shape::rect(x, y, w, h, overlay::PLAYER), &mut out);
    }
    out
}

/// The colour of an entity's box.
pub fn entity_color(t: EntityType, one_way: bool) -> Rgba {
    match t {
        EntityType::Spawn => overlay::SPAWN,
        EntityType::Block | EntityType::PolygonBlock => overlay::SOLID,
        EntityType::Platform if one_way => overlay::ONE_WAY,
        EntityType::Platform => overlay::PLATFORM,
        EntityType::Walker => overlay::WALKER,
        EntityType::Springboard => overlay::SPRING,
        EntityType::Coin => overlay::COIN,
        EntityType::Checkpoint => overlay::CHECKPOINT,
        EntityType::Goal => overlay::GOAL,
        EntityType::Hazard => overlay::HAZARD,
    }
}

/// Adds the shapes of an entity of type `t` whose box has centre `c` and
/// size `s` (world pixels): its box filled and outlined; a one-way
/// platform's top edge banded.
pub fn entity_shapes(t: EntityType, one_way: bool, c: [f32; 2], s: [f32; 2], out: &mut Vec<Shape>) {
    let (x, y) = (c[0] - s[0] / 2.0, c[1] - s[1] / 2.0);
    let color = entity_color(t, one_way);
    outlined(Shape::rect(x, y, s[0], s[1], color), out);
    if t == EntityType::Platform && one_way {
        let band = ONE_WAY_EDGE_PX.min(s[1]);
        out.push(Shape::rect(x, y, s[0], band, overlay::ONE_WAY_EDGE));
    }
}

/// Adds `shape`, then its outline ([`OUTLINE_PX`] thick, inside it, in
/// its colour at [`overlay::OUTLINE_ALPHA`]).
fn outlined(shape: Shape, out: &mut Vec<Shape>) {
    out.push(shape);
    let pts = shape.points();
    let n = pts.len();
    if n < 3 {
        return;
    }
    // Twice the signed area: its sign says which side is inside.
    let area: f32 = (0..n)
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum();
    let side = if area >= 0.0 { 1.0 } else { -1.0 };
    let color = overlay::outline(shape.color);
    for i in 0..n {
        let (a, b) = (pts[i], pts[(i + 1) % n]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = (dx * dx + dy * dy).sqrt();
        if len <= 0.0 {
            continue;
        }
        // The inward normal (y down: (-dy, dx) points inside a clockwise
        // polygon on screen, which has a positive area here).
        let k = side * OUTLINE_PX / len;
        let (nx, ny) = (-dy * k, dx * k);
        out.push(Shape::polygon(
            &[a, b, [b[0] + nx, b[1] + ny], [a[0] + nx, a[1] + ny]],
            color,
        ));
    }
}

/// Calls `f` with the shapes of the tiles in columns `cols` and rows
/// `rows` of `map` (clamped to it), row by row: solid and hazard cells
/// filled, one-way cells filled lightly with their top edge banded, slopes
/// the solid part under their surface.
pub fn tile_shapes(
    map: &Tilemap,
    cols: std::ops::Range<i64>,
    rows: std::ops::Range<i64>,
    mut f: impl FnMut(Shape),
) {
    let t = px(map.tile_size());
    let (ox, oy) = (px(map.origin().x), px(map.origin().y));
    let (c0, c1) = (cols.start.max(0), cols.end.min(map.width() as i64));
    let (r0, r1) = (rows.start.max(0), rows.end.min(map.height() as i64));
    for r in r0..r1 {
        for c in c0..c1 {
            let (x, y) = (ox + c as f32 * t, oy + r as f32 * t);
            match map.tile(glam::IVec2::new(c as i32, r as i32)) {
                Tile::Empty => {}
                Tile::Solid => f(Shape::rect(x, y, t, t, overlay::SOLID)),
                Tile::Hazard => f(Shape::rect(x, y, t, t, overlay::HAZARD)),
                Tile::OneWay => {
                    f(Shape::rect(x, y, t, t, overlay::ONE_WAY));
                    f(Shape::rect(x, y, t, ONE_WAY_EDGE_PX, overlay::ONE_WAY_EDGE));
                }
                Tile::Slope(s) => {
                    let (hl, hr) = slope_ends(s, t);
                    let b = y + t;
                    f(Shape::polygon(
                        &[[x, b], [x, b - hl], [x + t, b - hr], [x + t, b]],
                        overlay::SLOPE,
                    ));
                }
            }
        }
    }
}

/// A slope's surface heights at its left and right edges above the tile's
/// bottom, for a tile `t` pixels wide.
pub fn slope_ends(slope: Slope, t: f32) -> (f32, f32) {
    match slope {
        Slope::Right45 => (0.0, t),
        Slope::Left45 => (t, 0.0),
        Slope::RightLow22 => (0.0, t / 2.0),
        Slope::RightHigh22 => (t / 2.0, t),
        Slope::LeftHigh22 => (t, t / 2.0),
        Slope::LeftLow22 => (t / 2.0, 0.0),
    }
}

/// Every shape of `level`'s overlay with its entities where the level puts
/// them, in drawing order (what `ledge-level render` draws).
pub fn level_shapes(level: &Level, mut f: impl FnMut(Shape)) {
    let map = &level.tilemap;
    tile_shapes(map, 0..map.width() as i64, 0..map.height() as i64, &mut f);
    let o = Overlay::of_level(level);
    o.fixed.iter().copied().for_each(&mut f);
    let mut moving = Vec::new();
    for e in &level.entities {
        let Some((t, one_way)) = entity_type(&e.kind) else {
            continue;
        };
        if !is_fixed(t) {
            let (c, s) = ([px(e.pos.x), px(e.pos.y)], [px(e.size.x), px(e.size.y)]);
            entity_shapes(t, one_way, c, s, &mut moving);
        }
    }
    moving.into_iter().for_each(&mut f);
    o.players.into_iter().for_each(f);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_level_has_a_player_box_at_its_spawn() {
        let level = crate::default_level();
        let o = Overlay::of_level(&level);
        // One spawn: its box and four outline edges.
        assert_eq!(o.players.len(), 5);
        let b = o.players[0].bounds();
        assert_eq!((b[2] - b[0], b[3] - b[1]), (12.0, 16.0));
        let mut n = 0;
        level_shapes(&level, |_| n += 1);
        assert!(n > 500, "{n}");
    }

    #[test]
    fn outlines_lie_inside_their_shape() {
        for pts in [
            [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]],
            [[0.0, 0.0], [0.0, 10.0], [10.0, 10.0], [10.0, 0.0]],
        ] {
            let mut out = Vec::new();
            outlined(Shape::polygon(&pts, overlay::SOLID), &mut out);
            assert_eq!(out.len(), 5);
            for s in &out[1..] {
                let b = s.bounds();
                assert!(
                    b[0] >= 0.0 && b[1] >= 0.0 && b[2] <= 10.0 && b[3] <= 10.0,
                    "{b:?}"
                );
            }
        }
    }
}
