//! The debug overlay (F1): collider shapes, contacts with their MTVs as
//! arrows, the tiles they touch, the sides each body touched, and the broad
//! phase's strips.
//!
//! The world's contact buffer holds the *last* detection of a tick, after
//! restitution resolved what it could (usually nothing is left). So the
//! overlay also re-runs the tile query of every dynamic box at its position
//! before this tick's pushes (`pos - pushed`, the first detection's
//! position): those contacts and their MTVs are what restitution resolved.
//! Collider-collider contacts show through the touched sides and each
//! body's total push.

use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::tilemap::ContactFlags;
use ledge_shared::world::{
    AnyShape, BodyKind, BroadPhaseKind, ColliderMode, ContactKind, Sides, World,
};
use macroquad::prelude::*;

use crate::draw::camera::View;

/// Pixels per unit.
const PX: f32 = 1.0 / UNITS_PER_PX as f32;
/// MTV arrows are drawn this many times their length (MTVs are often a
/// fraction of a pixel: gravity presses a standing body 96 units deep).
const MTV_SCALE: f32 = 8.0;
/// Shortest MTV arrow, screen pixels.
const MIN_ARROW: f32 = 10.0;

fn world_px(p: IVec2) -> Vec2 {
    vec2(p.x as f32, p.y as f32) * PX
}

fn seg(view: &View, a: Vec2, b: Vec2, thickness: f32, color: Color) {
    let (a, b) = (view.to_screen(a), view.to_screen(b));
    draw_line(a.x, a.y, b.x, b.y, thickness, color);
}

fn outline(view: &View, pts: &[Vec2], color: Color) {
    for (i, &a) in pts.iter().enumerate() {
        seg(view, a, pts[(i + 1) % pts.len()], 1.5, color);
    }
}

/// An arrow from `from` towards `dir` (screen px), `len` screen px long.
fn arrow(from: Vec2, dir: Vec2, len: f32, color: Color) {
    let d = dir.normalize_or_zero();
    if d == Vec2::ZERO {
        return;
    }
    let to = from + d * len;
    draw_line(from.x, from.y, to.x, to.y, 2.0, color);
    let side = vec2(-d.y, d.x) * 4.0;
    draw_triangle(to + d * 5.0, to + side, to - side, color);
}

/// Draws the overlay for `world` and a legend in the bottom-left corner.
pub fn draw(world: &World, view: &View) {
    draw_colliders(world, view);
    draw_touched_sides(world, view);
    // Broad phase: the strip boundaries of the two finest levels.
    let strips = strips(world, view);
    let tile_contacts = draw_tile_contacts(world, view);
    let count = draw_contacts(world, view);
    let lines = [
        format!(
            "debug (F1): {} bodies, {} colliders; {} tile contacts at the first detection; left unresolved: {} solid + {} trigger",
            world.bodies().count(),
            world.colliders().count(),
            tile_contacts,
            count.0,
            count.1
        ),
        format!(
            "shapes: yellow dynamic, blue kinematic, grey static, magenta trigger; red: touched sides; green: tile MTV x{MTV_SCALE} (units); blue: total push"
        ),
        strips,
    ];
    draw_legend(&lines);
}

/// Colliders, coloured by kind, and one-way platforms' directions.
fn draw_colliders(world: &World, view: &View) {
    let seen = view.visible();
    for c in world.colliders() {
        let (lo, hi) = c.world_bounds();
        let (lo, hi) = (world_px(lo), world_px(hi));
        if !Rect::new(lo.x, lo.y, hi.x - lo.x, hi.y - lo.y).overlaps(&seen) {
            continue;
        }
        let kind = world.body(c.body).map(|b| b.kind());
        let color = match (c.mode, kind) {
            (ColliderMode::Trigger, _) => MAGENTA,
            (_, Some(BodyKind::Dynamic)) => YELLOW,
            (_, Some(BodyKind::Kinematic)) => SKYBLUE,
            _ => LIGHTGRAY,
        };
        let o = world_px(c.pos);
        match c.shape {
            AnyShape::Point(_) => {
                let p = view.to_screen(o);
                draw_line(p.x - 4.0, p.y, p.x + 4.0, p.y, 1.5, color);
                draw_line(p.x, p.y - 4.0, p.x, p.y + 4.0, 1.5, color);
            }
            AnyShape::Segment(s) => seg(view, o + world_px(s.a()), o + world_px(s.b()), 1.5, color),
            AnyShape::Circle(s) => {
                let p = view.to_screen(o);
                draw_circle_lines(p.x, p.y, s.radius() as f32 * PX * view.zoom, 1.5, color);
            }
            AnyShape::Aabb(s) => {
                let h = world_px(s.half());
                outline(
                    view,
                    &[o - h, o + vec2(h.x, -h.y), o + h, o + vec2(-h.x, h.y)],
                    color,
                );
            }
            AnyShape::Obb(s) => {
                let (u, v) = (world_px(s.u()), world_px(s.v()));
                outline(view, &[o - u - v, o + u - v, o + u + v, o - u + v], color);
            }
            AnyShape::Polygon(s) => {
                let pts: Vec<Vec2> = s.vertices().iter().map(|&p| o + world_px(p)).collect();
                outline(view, &pts, color);
            }
        }
        if let Some(dir) = c.one_way {
            let n = dir.normal();
            let centre = view.to_screen((lo + hi) / 2.0);
            arrow(centre, vec2(n.x as f32, n.y as f32), 8.0, color);
        }
    }
}

/// Touched sides of every body (from the last step).
fn draw_touched_sides(world: &World, view: &View) {
    for (id, body) in world.bodies() {
        let sides = body.sides();
        if sides.is_empty() {
            continue;
        }
        let mut bounds: Option<(Vec2, Vec2)> = None;
        for c in world.colliders().filter(|c| c.body == id) {
            let (lo, hi) = c.world_bounds();
            let (lo, hi) = (world_px(lo), world_px(hi));
            bounds = Some(match bounds {
                None => (lo, hi),
                Some((a, b)) => (a.min(lo), b.max(hi)),
            });
        }
        let Some((lo, hi)) = bounds else { continue };
        let (lo, hi) = (view.to_screen(lo), view.to_screen(hi));
        let red = Color::new(1.0, 0.2, 0.2, 1.0);
        let side = |s: Sides, a: Vec2, b: Vec2| {
            if sides.contains(s) {
                draw_line(a.x, a.y, b.x, b.y, 4.0, red);
            }
        };
        side(Sides::LEFT, lo, vec2(lo.x, hi.y));
        side(Sides::RIGHT, vec2(hi.x, lo.y), hi);
        side(Sides::TOP, lo, vec2(hi.x, lo.y));
        side(Sides::BOTTOM, vec2(lo.x, hi.y), hi);
    }
}

/// Tile contacts at the start of restitution, and each body's push;
/// returns how many tile contacts.
fn draw_tile_contacts(world: &World, view: &View) -> usize {
    let mut tile_contacts = 0;
    if let Some(map) = world.tilemap() {
        let mut out = Vec::new();
        for c in world.colliders() {
            let AnyShape::Aabb(shape) = c.shape else {
                continue;
            };
            let Some(body) = world.body(c.body) else {
                continue;
            };
            if body.kind() != BodyKind::Dynamic || !body.is_enabled() {
                continue;
            }
            let push = body.pushed();
            out.clear();
            map.box_contacts(
                c.pos - push,
                shape.half(),
                body.displacement() - push,
                ContactFlags {
                    drop_through: body.drops_through(),
                },
                &mut out,
            );
            let from = view.to_screen(world_px(c.pos));
            for tc in &out {
                tile_contacts += 1;
                let t = map.tile_size() as f32 * PX;
                let p = world_px(map.origin()) + vec2(tc.tile.x as f32, tc.tile.y as f32) * t;
                let s = view.to_screen(p);
                draw_rectangle_lines(s.x, s.y, t * view.zoom, t * view.zoom, 2.0, ORANGE);
                if tc.is_trigger() {
                    draw_circle_lines(from.x, from.y, 6.0, 2.0, MAGENTA);
                    continue;
                }
                let mv = world_px(tc.mtv);
                let len = (mv.length() * MTV_SCALE * view.zoom).max(MIN_ARROW);
                arrow(from, mv, len, GREEN);
                let label = format!("{},{}", tc.mtv.x, tc.mtv.y);
                draw_text(&label, from.x + 6.0, from.y + 14.0, 14.0, GREEN);
            }
            if push != IVec2::ZERO {
                let pv = world_px(push);
                let len = (pv.length() * MTV_SCALE * view.zoom).max(MIN_ARROW);
                arrow(from + vec2(2.0, 0.0), pv, len * 0.8, SKYBLUE);
            }
        }
    }
    tile_contacts
}

/// Contacts left in the world's buffer: the tile touched, and the MTV
/// from A's centre; returns how many (solid, trigger).
fn draw_contacts(world: &World, view: &View) -> (usize, usize) {
    let mut count = (0, 0);
    for contact in world.contacts() {
        if let (Some(tile), Some(map)) = (contact.tile(), world.tilemap()) {
            let t = map.tile_size() as f32 * PX;
            let p = world_px(map.origin()) + vec2(tile.x as f32, tile.y as f32) * t;
            let s = view.to_screen(p);
            draw_rectangle_lines(
                s.x,
                s.y,
                t * view.zoom,
                t * view.zoom,
                2.0,
                Color::new(1.0, 0.6, 0.1, 0.9),
            );
        }
        let Some(a) = world.collider(contact.collider_a()) else {
            continue;
        };
        let (lo, hi) = a.world_bounds();
        let from = view.to_screen((world_px(lo) + world_px(hi)) / 2.0);
        let m = contact.mtv();
        let trigger = contact.kind() == ContactKind::Trigger;
        if trigger {
            count.1 += 1;
            draw_circle_lines(from.x, from.y, 6.0, 2.0, MAGENTA);
            continue;
        }
        count.0 += 1;
        let mv = world_px(m);
        let len = (mv.length() * MTV_SCALE * view.zoom).max(MIN_ARROW);
        arrow(from, mv, len, Color::new(0.1, 1.0, 0.4, 1.0));
        let label = format!("{},{}", m.x, m.y);
        draw_text(&label, from.x + 6.0, from.y - 6.0, 14.0, WHITE);
    }
    count
}

/// The legend's lines, bottom-left, on dark boxes.
fn draw_legend(lines: &[String]) {
    let h = screen_height();
    for (i, l) in lines.iter().enumerate() {
        let y = h - 34.0 - (lines.len() - 1 - i) as f32 * 18.0;
        let w = measure_text(l, None, 16, 1.0).width;
        draw_rectangle(6.0, y - 14.0, w + 8.0, 18.0, Color::new(0.0, 0.0, 0.0, 0.6));
        draw_text(l, 10.0, y, 16.0, WHITE);
    }
}

/// Draws the broad phase's strip boundaries (the finest level dim, the
/// next one brighter); returns a legend line with its statistics.
fn strips(world: &World, view: &View) -> String {
    let BroadPhaseKind::Strips {
        strip_shift,
        level_shift,
    } = world.config().broad_phase
    else {
        return "broad phase: brute force (no strips)".into();
    };
    let seen = view.visible();
    for (level, alpha) in [(0, 0.18), (1, 0.4)] {
        let shift = strip_shift + level * level_shift;
        if shift > 30 {
            break;
        }
        let h = (1u64 << shift) as f32 * PX;
        if h * view.zoom < 8.0 {
            continue;
        }
        let color = Color::new(0.6, 0.9, 1.0, alpha);
        let mut y = (seen.y / h).floor() * h;
        while y <= seen.bottom() {
            let s = view.to_screen(vec2(seen.x, y));
            draw_line(0.0, s.y, view.screen.x, s.y, 1.0, color);
            y += h;
        }
    }
    let st = world.broad_phase_stats();
    format!(
        "broad phase strips: {} px, x{} per level (lines); {} static + {} dynamic boxes, {} dynamic strips, {} movers",
        (1u64 << strip_shift) / UNITS_PER_PX as u64,
        1u64 << level_shift,
        st.statics,
        st.dynamics,
        st.dynamic_strips,
        st.movers
    )
}
