//! The game's plain colours ([`palette::flat`]) where a level has no art:
//! the tiles as the client's window draws them (ground with grass on
//! exposed tops, edges and pebbles, slopes, one-way planks with brackets,
//! spikes), polygon blocks, and the entities as simple shapes in their
//! colours (the window animates and details them).

use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::level::{EntityKind, Level};
use ledge_shared::tilemap::{Tile, Tilemap};

use crate::overlay::slope_ends;
use crate::palette::flat as colour;

use super::canvas::Canvas;

fn px(u: i32) -> f32 {
    u as f32 / UNITS_PER_PX as f32
}

/// Whether `tile` covers the top of the tile below it (no grass there).
fn covers_below(tile: Tile) -> bool {
    matches!(tile, Tile::Solid | Tile::Slope(_))
}

/// Draws the tiles of `map` except those `covered` (row-major) says the
/// level's art draws.
pub(crate) fn tiles(canvas: &mut Canvas, map: &Tilemap, covered: &[bool]) {
    let t = px(map.tile_size());
    let (ox, oy) = (px(map.origin().x), px(map.origin().y));
    let at = |c: i64, r: i64| map.tile(glam::IVec2::new(c as i32, r as i32));
    let mut grass = Vec::new();
    for r in 0..map.height() as i64 {
        for c in 0..map.width() as i64 {
            if covered
                .get((r * map.width() as i64 + c) as usize)
                .is_some_and(|&v| v)
            {
                continue;
            }
            let (x, y) = (ox + c as f32 * t, oy + r as f32 * t);
            match at(c, r) {
                Tile::Empty => {}
                Tile::Solid => {
                    canvas.rect(x, y, t, t, colour::SOLID);
                    // Pebbles, away from the tile's centre.
                    match (c * 7 + r * 13).rem_euclid(5) {
                        0 => canvas.rect(x + 2.0, y + 10.0, 3.0, 2.0, colour::SOLID_SPECK),
                        3 => canvas.rect(x + 11.0, y + 3.0, 2.0, 2.0, colour::SOLID_SPECK),
                        _ => {}
                    }
                    let exposed = |dc: i64, dr: i64| {
                        !matches!(at(c + dc, r + dr), Tile::Solid | Tile::Slope(_))
                    };
                    if exposed(-1, 0) {
                        canvas.rect(x, y, 1.0, t, colour::SOLID_EDGE);
                    }
                    if exposed(1, 0) {
                        canvas.rect(x + t - 1.0, y, 1.0, t, colour::SOLID_EDGE);
                    }
                    if exposed(0, 1) {
                        canvas.rect(x, y + t - 1.0, t, 1.0, colour::SOLID_EDGE);
                    }
                    if !covers_below(at(c, r - 1)) {
                        canvas.rect(x, y, t, 3.0, colour::GRASS);
                        canvas.rect(x, y + 3.0, t, 1.0, colour::GRASS_DARK);
                    }
                }
                Tile::Slope(s) => {
                    let (hl, hr) = slope_ends(s, t);
                    let b = y + t;
                    let (l, rr) = (b - hl, b - hr);
                    canvas.polygon(&[[x, b], [x, l], [x + t, rr], [x + t, b]], colour::SOLID);
                    grass.push([[x, l], [x + t, rr], [x + t, rr + 3.0], [x, l + 3.0]]);
                }
                Tile::OneWay => {
                    canvas.rect(x, y, t, 4.0, colour::PLANK);
                    canvas.rect(x, y + 3.0, t, 1.0, colour::PLANK_DARK);
                    if !matches!(at(c - 1, r), Tile::OneWay) {
                        let p = [[x + 1.0, y + 4.0], [x + 5.0, y + 4.0], [x + 1.0, y + 8.0]];
                        canvas.polygon(&p, colour::PLANK_DARK);
                    }
                    if !matches!(at(c + 1, r), Tile::OneWay) {
                        let p = [
                            [x + t - 5.0, y + 4.0],
                            [x + t - 1.0, y + 4.0],
                            [x + t - 1.0, y + 8.0],
                        ];
                        canvas.polygon(&p, colour::PLANK_DARK);
                    }
                }
                Tile::Hazard => spikes(canvas, [x, y, t, t]),
            }
        }
    }
    for band in grass {
        canvas.polygon(&band, colour::GRASS);
    }
}

/// A row of spikes standing on the bottom of the box `[x, y, w, h]`.
fn spikes(canvas: &mut Canvas, [x0, y0, w0, h0]: [f32; 4]) {
    let n = (w0 / 4.0).round().clamp(1.0, 4096.0);
    let w = w0 / n;
    let h = (h0 * 0.7).min(11.0);
    let b = y0 + h0;
    canvas.rect(x0, b - 2.0, w0, 2.0, colour::SPIKE_DARK);
    for i in 0..n as usize {
        let x = x0 + i as f32 * w;
        canvas.tri(
            [x, b - 1.0],
            [x + w / 2.0, b - h],
            [x + w, b - 1.0],
            colour::SPIKE,
        );
        let edge = [[x + w / 2.0, b - h], [x + w, b - 1.0]];
        canvas.line(edge[0], edge[1], 0.75, colour::SPIKE_DARK);
    }
}

/// Draws the level's polygon blocks and entities in plain colours;
/// `statics`: blocks and polygon blocks too (not when the art draws them).
pub(crate) fn entities(canvas: &mut Canvas, level: &Level, statics: bool) {
    for e in &level.entities {
        let (c, s) = ([px(e.pos.x), px(e.pos.y)], [px(e.size.x), px(e.size.y)]);
        let (x, y, w, h) = (c[0] - s[0] / 2.0, c[1] - s[1] / 2.0, s[0], s[1]);
        match &e.kind {
            EntityKind::PolygonBlock { vertices } if statics => {
                let pts: Vec<[f32; 2]> = vertices
                    .iter()
                    .map(|v| [c[0] + px(v.x), c[1] + px(v.y)])
                    .collect();
                canvas.polygon(&pts, colour::SOLID);
            }
            EntityKind::Block if statics => {
                canvas.rect(x, y, w, h, colour::CRATE_DARK);
                canvas.rect(x + 1.5, y + 1.5, w - 3.0, h - 3.0, colour::CRATE);
            }
            EntityKind::MovingPlatform { one_way: true, .. } => {
                canvas.rect(x, y, w, 4.0, colour::ONE_WAY);
                canvas.rect(x, y + 4.0, w, 1.0, colour::PLANK_DARK);
            }
            EntityKind::MovingPlatform { .. } => {
                canvas.rect(x, y, w, h, colour::STEEL_DARK);
                canvas.rect(x + 1.0, y + 1.0, w - 2.0, h - 2.0, colour::STEEL);
            }
            EntityKind::Walker { .. } => canvas.rect(x, y, w, h - 2.0, colour::WALKER),
            EntityKind::Springboard { .. } => {
                let plate = (h * 0.25).clamp(1.5, 3.0);
                canvas.rect(x - 1.0, y, w + 2.0, plate, colour::SPRING);
                canvas.rect(x + 1.0, y + h - plate, w - 2.0, plate, colour::STEEL);
            }
            EntityKind::Coin => {
                let r = w.min(h) * 0.4;
                canvas.ellipse(c, r * 0.8, r, colour::COIN);
            }
            EntityKind::Checkpoint => flag(canvas, [x, y, w, h], colour::FLAG_IDLE, false),
            EntityKind::Goal => flag(canvas, [x, y, w, h], colour::GOAL, true),
            EntityKind::Hazard => spikes(canvas, [x, y, w, h]),
            _ => {}
        }
    }
}

/// A flag on a pole standing on the bottom of the box; `raised`: at the
/// top.
fn flag(canvas: &mut Canvas, [x0, y0, w, h]: [f32; 4], c: crate::palette::Rgba, raised: bool) {
    let x = x0 + w / 2.0 - 0.5;
    let bottom = y0 + h;
    let top = bottom - h.max(24.0);
    canvas.rect(x, top, 1.5, bottom - top, colour::POLE);
    canvas.rect(x - 2.0, bottom - 2.0, 5.5, 2.0, colour::POLE);
    let fy = if raised {
        top
    } else {
        top + (bottom - top) * 0.5
    };
    canvas.tri([x + 1.5, fy], [x + 12.0, fy + 4.0], [x + 1.5, fy + 8.0], c);
}
