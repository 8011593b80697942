//! The collision overlay (the C key, `--collision`): what collides, drawn
//! translucent over the game, the same shapes in the same colours as
//! `ledge-level render` draws (`ledge_levels::overlay`, whose colours are
//! `ledge_levels::palette::overlay`): solid, one-way, slope and hazard
//! tiles, blocks and polygons, each entity's box where the game has it
//! this frame, the spawns and a player's box where the game spawns one.

use ledge_levels::overlay::{self, Overlay, Shape};
use ledge_levels::palette::Rgba;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::level::Level;
use macroquad::prelude::*;

use crate::draw::camera::View;
use crate::draw::render::EntitySprite;

/// The overlay's state: shown or not, and the shapes of the level that
/// do not move (made once per level).
#[derive(Default)]
pub struct CollisionOverlay {
    shown: bool,
    /// The fixed shapes and which level they are of (the caller's key).
    cached: Option<(u64, Overlay)>,
}

/// `c` as macroquad's colour.
pub fn color(c: Rgba) -> Color {
    Color::from_rgba(c[0], c[1], c[2], c[3])
}

impl CollisionOverlay {
    /// An overlay, shown from the start or not.
    pub fn new(shown: bool) -> CollisionOverlay {
        CollisionOverlay {
            shown,
            cached: None,
        }
    }

    /// Shows or hides it.
    pub fn toggle(&mut self) {
        self.shown = !self.shown;
    }

    /// Draws it over the world, when shown: the tiles `view` shows, the
    /// fixed shapes of `level` (remade when `key` changes: a new level),
    /// the entities as drawn this frame, the players' spawn boxes on top.
    pub fn draw(&mut self, level: &Level, key: u64, view: &View, entities: &[EntitySprite]) {
        if !self.shown {
            return;
        }
        if self.cached.as_ref().is_none_or(|(k, _)| *k != key) {
            self.cached = Some((key, Overlay::of_level(level)));
        }
        let Some((_, fixed)) = &self.cached else {
            return;
        };
        let seen = view.visible();
        let map = &level.tilemap;
        let t = map.tile_size() as f32 / UNITS_PER_PX as f32;
        let (ox, oy) = (
            map.origin().x as f32 / UNITS_PER_PX as f32,
            map.origin().y as f32 / UNITS_PER_PX as f32,
        );
        let cols = ((seen.x - ox) / t).floor() as i64..((seen.right() - ox) / t).ceil() as i64;
        let rows = ((seen.y - oy) / t).floor() as i64..((seen.bottom() - oy) / t).ceil() as i64;
        overlay::tile_shapes(map, cols, rows, |s| fill(view, &s));
        let visible = |s: &Shape| {
            let [l, t, r, b] = s.bounds();
            Rect::new(l, t, r - l, b - t).overlaps(&seen)
        };
        for s in fixed.fixed.iter().filter(|s| visible(s)) {
            fill(view, s);
        }
        let mut moving = Vec::new();
        for e in entities {
            if overlay::is_fixed(e.kind) || !e.active {
                continue;
            }
            let (c, s) = ([e.pos.x, e.pos.y], [e.size.x, e.size.y]);
            overlay::entity_shapes(e.kind, e.one_way, c, s, &mut moving);
        }
        for s in moving.iter().chain(&fixed.players).filter(|s| visible(s)) {
            fill(view, s);
        }
    }
}

/// Fills a convex shape (a fan of triangles from its first corner).
fn fill(view: &View, s: &Shape) {
    let pts = s.points();
    if pts.len() < 3 {
        return;
    }
    let c = color(s.color);
    let p = |i: usize| view.to_screen(vec2(pts[i][0], pts[i][1]));
    for i in 1..pts.len() - 1 {
        draw_triangle(p(0), p(i), p(i + 1), c);
    }
}
