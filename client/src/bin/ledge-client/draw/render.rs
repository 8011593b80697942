//! Drawing the world: the tilemap, the level's entities and the players,
//! through a [`View`] (world pixels to screen pixels). Plain shapes, no
//! textures: every colour is in [`palette`]. A level's own art (its tile
//! layers and tileset images) is drawn by `art.rs`; the tilemap's flat
//! colours only fill the cells the art does not draw.

use crate::draw::anim::{label_rows, Action, Label, Pose};
use ledge_client::view::{EntityType, Facing};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::level::{EntityKind, Level};
use ledge_shared::tilemap::{Slope, Tile, Tilemap};
use macroquad::prelude::*;

use crate::draw::camera::View;

/// The colours of the game. Those a level is drawn with are
/// `ledge_levels::palette::flat`'s (`ledge-level render` draws with them
/// too).
pub mod palette {
    use ledge_levels::palette;
    use macroquad::color::Color;

    const fn rgb(r: u8, g: u8, b: u8) -> Color {
        Color::new(r as f32 / 255.0, g as f32 / 255.0, b as f32 / 255.0, 1.0)
    }

    const fn flat(c: palette::Rgba) -> Color {
        Color::new(
            c[0] as f32 / 255.0,
            c[1] as f32 / 255.0,
            c[2] as f32 / 255.0,
            c[3] as f32 / 255.0,
        )
    }

    /// The sky behind everything.
    pub const SKY: Color = flat(palette::flat::SKY);
    /// Distant clouds.
    pub const CLOUD: Color = rgb(236, 242, 250);
    /// Solid ground (tiles and the body of slopes).
    pub const SOLID: Color = flat(palette::flat::SOLID);
    /// Pebbles in the ground.
    pub const SOLID_SPECK: Color = flat(palette::flat::SOLID_SPECK);
    /// Edges of the ground facing empty space.
    pub const SOLID_EDGE: Color = flat(palette::flat::SOLID_EDGE);
    /// Grass on exposed ground tops and slope surfaces.
    pub const GRASS: Color = flat(palette::flat::GRASS);
    /// The darker line under the grass.
    pub const GRASS_DARK: Color = flat(palette::flat::GRASS_DARK);
    /// One-way ledges (tiles).
    pub const PLANK: Color = flat(palette::flat::PLANK);
    /// Their shaded underside.
    pub const PLANK_DARK: Color = flat(palette::flat::PLANK_DARK);
    /// Spikes.
    pub const SPIKE: Color = flat(palette::flat::SPIKE);
    /// Spike outlines and bases.
    pub const SPIKE_DARK: Color = flat(palette::flat::SPIKE_DARK);
    /// Crates (blocks).
    pub const CRATE: Color = flat(palette::flat::CRATE);
    /// Crate boards.
    pub const CRATE_DARK: Color = flat(palette::flat::CRATE_DARK);
    /// Solid moving platforms.
    pub const STEEL: Color = flat(palette::flat::STEEL);
    /// Their outline.
    pub const STEEL_DARK: Color = flat(palette::flat::STEEL_DARK);
    /// Their lit top edge.
    pub const STEEL_LIGHT: Color = rgb(170, 184, 210);
    /// One-way moving platforms.
    pub const ONE_WAY: Color = flat(palette::flat::ONE_WAY);
    /// Their see-through underside.
    pub const ONE_WAY_GHOST: Color = Color::new(0.94, 0.77, 0.28, 0.35);
    /// Walkers.
    pub const WALKER: Color = flat(palette::flat::WALKER);
    /// Defeated walkers.
    pub const WALKER_DEAD: Color = Color::new(0.45, 0.45, 0.5, 0.7);
    /// Dust kicked up by feet.
    pub const DUST: Color = Color::new(0.93, 0.9, 0.84, 0.85);
    /// The goal's confetti.
    pub const CONFETTI: [Color; 5] = [
        rgb(255, 208, 32),
        rgb(255, 96, 96),
        rgb(96, 200, 255),
        rgb(120, 230, 110),
        rgb(250, 250, 250),
    ];
    /// Coins.
    pub const COIN: Color = flat(palette::flat::COIN);
    /// Coin shine.
    pub const COIN_LIGHT: Color = rgb(255, 240, 160);
    /// Coin rim.
    pub const COIN_DARK: Color = rgb(186, 132, 18);
    /// Springboard pads.
    pub const SPRING: Color = flat(palette::flat::SPRING);
    /// Springboard coils and bases.
    pub const METAL: Color = rgb(150, 156, 168);
    /// Poles of checkpoints and the goal.
    pub const POLE: Color = flat(palette::flat::POLE);
    /// A checkpoint that is the local player's respawn point.
    pub const FLAG_ACTIVE: Color = rgb(64, 224, 120);
    /// Other checkpoints.
    pub const FLAG_IDLE: Color = flat(palette::flat::FLAG_IDLE);
    /// The goal.
    pub const GOAL: Color = flat(palette::flat::GOAL);
    /// Outlines of dark things and eye pupils.
    pub const INK: Color = rgb(24, 20, 30);
    /// Eyes.
    pub const EYE: Color = rgb(255, 255, 255);
    /// The local player.
    pub const LOCAL_PLAYER: Color = rgb(255, 132, 24);
    /// The level record's ghost (drawn translucent).
    pub const GHOST_RECORD: Color = rgb(255, 255, 255);
    /// Our own best run's ghost (drawn translucent).
    pub const GHOST_BEST: Color = rgb(60, 200, 255);
    /// Other players, by id: each far from the others, from
    /// [`LOCAL_PLAYER`] and from the sky, ground and grass (a test checks
    /// the distances).
    pub const REMOTE_PLAYERS: [Color; 8] = [
        rgb(0, 220, 230),
        rgb(190, 120, 255),
        rgb(160, 245, 90),
        rgb(255, 110, 186),
        rgb(40, 80, 220),
        rgb(250, 240, 90),
        rgb(0, 150, 136),
        rgb(232, 40, 56),
    ];

    /// A colour as `[r, g, b]` bytes (for the screenshot JSON).
    pub fn bytes(c: Color) -> [u8; 3] {
        let b = |v: f32| (v * 255.0).round() as u8;
        [b(c.r), b(c.g), b(c.b)]
    }
}

/// A player to draw (world pixels: centre and full size).
#[derive(Debug, Clone, PartialEq)]
pub struct PlayerSprite {
    /// Its id.
    pub id: u32,
    /// Its name, when known.
    pub name: Option<String>,
    /// Centre of its box.
    pub pos: Vec2,
    /// Full size of its box.
    pub size: Vec2,
    /// Which way it looks.
    pub facing: Facing,
    /// Reached the goal (wears a crown).
    pub won: bool,
    /// Dead: nothing is drawn (the effects draw its death).
    pub dead: bool,
    /// How it is drawn this frame (the pose's facing wins over
    /// [`PlayerSprite::facing`]).
    pub pose: Pose,
}

/// A level entity to draw (world pixels: centre and full size).
#[derive(Debug, Clone, PartialEq)]
pub struct EntitySprite {
    /// Its id.
    pub id: u32,
    /// What it is.
    pub kind: EntityType,
    /// Centre of its box.
    pub pos: Vec2,
    /// Full size of its box.
    pub size: Vec2,
    /// A walker not defeated, a coin not picked up.
    pub active: bool,
    /// A one-way platform.
    pub one_way: bool,
    /// A walker's direction.
    pub facing: Facing,
}

impl EntitySprite {
    fn top_left(&self) -> Vec2 {
        self.pos - self.size * 0.5
    }
}

impl PlayerSprite {
    fn top_left(&self) -> Vec2 {
        self.pos - self.size * 0.5
    }
}

/// Pixels per unit.
const PX: f32 = 1.0 / UNITS_PER_PX as f32;

/// Draws a world-space rectangle (top-left `x, y`, size `w, h`, world px).
fn rect(view: &View, x: f32, y: f32, w: f32, h: f32, color: Color) {
    let p = view.to_screen(vec2(x, y));
    draw_rectangle(p.x, p.y, w * view.zoom, h * view.zoom, color);
}

/// Draws a world-space triangle.
fn tri(view: &View, a: Vec2, b: Vec2, c: Vec2, color: Color) {
    draw_triangle(
        view.to_screen(a),
        view.to_screen(b),
        view.to_screen(c),
        color,
    );
}

/// Draws a world-space line `thickness` world px thick.
fn line(view: &View, a: Vec2, b: Vec2, thickness: f32, color: Color) {
    let (a, b) = (view.to_screen(a), view.to_screen(b));
    draw_line(a.x, a.y, b.x, b.y, thickness * view.zoom, color);
}

/// Draws a world-space convex quad (corners in order).
fn quad(view: &View, p: [Vec2; 4], color: Color) {
    tri(view, p[0], p[1], p[2], color);
    tri(view, p[0], p[2], p[3], color);
}

/// Clouds: `(x, y, width)` in pixels of a far layer that scrolls at half
/// the camera's speed (so they seem far away).
const CLOUDS: [(f32, f32, f32); 7] = [
    (60.0, 40.0, 56.0),
    (260.0, 70.0, 40.0),
    (430.0, 30.0, 72.0),
    (640.0, 84.0, 48.0),
    (820.0, 44.0, 64.0),
    (1040.0, 76.0, 44.0),
    (1240.0, 36.0, 60.0),
];
/// Clouds move this fraction of the camera's motion.
const CLOUD_PARALLAX: f32 = 0.5;

/// Clears to the sky and draws distant clouds (high up, behind
/// everything).
pub fn draw_background(view: &View, time: f32) {
    clear_background(palette::SKY);
    // Horizontally at parallax; vertically almost fixed, in the upper part
    // of the screen.
    let far = View {
        offset: vec2(
            view.offset.x * CLOUD_PARALLAX,
            view.offset.y * 0.1 + 40.0 * view.zoom,
        ),
        ..*view
    };
    // The cloud band repeats every this many world pixels.
    let period = 1400.0;
    let drift = time * 2.0;
    let left = far.to_world(Vec2::ZERO).x;
    let right = far.to_world(view.screen).x;
    for &(x, y, w) in &CLOUDS {
        let mut cx = (x + drift - left).rem_euclid(period) + left - w;
        while cx < right + w {
            cloud(&far, cx, y, w);
            cx += period;
        }
    }
}

fn cloud(view: &View, x: f32, y: f32, w: f32) {
    let c = palette::CLOUD;
    for (dx, dy, r) in [(0.2, 0.1, 0.16), (0.45, -0.05, 0.22), (0.72, 0.08, 0.17)] {
        let p = view.to_screen(vec2(x + dx * w, y + dy * w));
        draw_circle(p.x, p.y, r * w * view.zoom, c);
    }
    rect(view, x + 0.12 * w, y + 0.1 * w, 0.72 * w, 0.14 * w, c);
}

/// Surface heights of a slope at its left and right tile edges, in units
/// above the tile's bottom: the ends of the straight line
/// [`Slope::height`] follows (`height(0)` and its value extended to
/// `x = T`).
pub fn slope_ends(slope: Slope, t: i32) -> (i32, i32) {
    match slope {
        Slope::Right45 => (0, t),
        Slope::Left45 => (t, 0),
        Slope::RightLow22 => (0, t / 2),
        Slope::RightHigh22 => (t / 2, t),
        Slope::LeftHigh22 => (t, t / 2),
        Slope::LeftLow22 => (t / 2, 0),
    }
}

/// Whether `tile` covers the top of the tile below it (no grass there).
fn covers_below(tile: Tile) -> bool {
    matches!(tile, Tile::Solid | Tile::Slope(_))
}

/// Draws the tiles of `map` that `view` shows, except those `covered`
/// (row-major, one per cell; shorter: not covered) says the level's art
/// draws.
pub fn draw_tilemap(map: &Tilemap, view: &View, covered: &[bool]) {
    let t = map.tile_size() as f32 * PX;
    let origin = vec2(map.origin().x as f32, map.origin().y as f32) * PX;
    let seen = view.visible();
    let col0 = (((seen.x - origin.x) / t).floor() as i64).max(0);
    let row0 = (((seen.y - origin.y) / t).floor() as i64).max(0);
    let col1 = (((seen.right() - origin.x) / t).ceil() as i64).min(map.width() as i64);
    let row1 = (((seen.bottom() - origin.y) / t).ceil() as i64).min(map.height() as i64);
    let at = |c: i64, r: i64| map.tile(IVec2::new(c as i32, r as i32));
    // Edge lines: one world pixel.
    let hair = 1.0;
    let mut grass = Vec::new();
    for r in row0..row1 {
        for c in col0..col1 {
            let (x, y) = (origin.x + c as f32 * t, origin.y + r as f32 * t);
            if covered
                .get((r * map.width() as i64 + c) as usize)
                .is_some_and(|&v| v)
            {
                continue;
            }
            match at(c, r) {
                Tile::Empty => {}
                Tile::Solid => {
                    rect(view, x, y, t, t, palette::SOLID);
                    // Pebbles, away from the tile's centre.
                    let h = (c * 7 + r * 13).rem_euclid(5);
                    if h == 0 {
                        rect(view, x + 2.0, y + 10.0, 3.0, 2.0, palette::SOLID_SPECK);
                    } else if h == 3 {
                        rect(view, x + 11.0, y + 3.0, 2.0, 2.0, palette::SOLID_SPECK);
                    }
                    // Slopes lean on their neighbours: no edge line there.
                    let exposed = |dc: i64, dr: i64| {
                        !matches!(at(c + dc, r + dr), Tile::Solid | Tile::Slope(_))
                    };
                    if exposed(-1, 0) {
                        rect(view, x, y, hair, t, palette::SOLID_EDGE);
                    }
                    if exposed(1, 0) {
                        rect(view, x + t - hair, y, hair, t, palette::SOLID_EDGE);
                    }
                    if exposed(0, 1) {
                        rect(view, x, y + t - hair, t, hair, palette::SOLID_EDGE);
                    }
                    if !covers_below(at(c, r - 1)) {
                        rect(view, x, y, t, 3.0, palette::GRASS);
                        rect(view, x, y + 3.0, t, 1.0, palette::GRASS_DARK);
                    }
                }
                Tile::Slope(s) => {
                    let (hl, hr) = slope_ends(s, map.tile_size());
                    let b = y + t;
                    let (l, rr) = (b - hl as f32 * PX, b - hr as f32 * PX);
                    quad(
                        view,
                        [vec2(x, b), vec2(x, l), vec2(x + t, rr), vec2(x + t, b)],
                        palette::SOLID,
                    );
                    // Grass below the exact surface line, drawn after the
                    // tiles below (it reaches into them at the low end).
                    grass.push([
                        vec2(x, l),
                        vec2(x + t, rr),
                        vec2(x + t, rr + 3.0),
                        vec2(x, l + 3.0),
                    ]);
                }
                Tile::OneWay => {
                    rect(view, x, y, t, 4.0, palette::PLANK);
                    rect(view, x, y + 3.0, t, 1.0, palette::PLANK_DARK);
                    // Little brackets under the ends of a run of ledges.
                    if !matches!(at(c - 1, r), Tile::OneWay) {
                        tri(
                            view,
                            vec2(x + 1.0, y + 4.0),
                            vec2(x + 5.0, y + 4.0),
                            vec2(x + 1.0, y + 8.0),
                            palette::PLANK_DARK,
                        );
                    }
                    if !matches!(at(c + 1, r), Tile::OneWay) {
                        tri(
                            view,
                            vec2(x + t - 5.0, y + 4.0),
                            vec2(x + t - 1.0, y + 4.0),
                            vec2(x + t - 1.0, y + 8.0),
                            palette::PLANK_DARK,
                        );
                    }
                }
                Tile::Hazard => spikes(view, Rect::new(x, y, t, t)),
            }
        }
    }
    for band in grass {
        quad(view, band, palette::GRASS);
    }
}

/// A row of spikes standing on the bottom of `area` (world px).
fn spikes(view: &View, area: Rect) {
    let n = (area.w / 4.0).round().max(1.0);
    let w = area.w / n;
    let h = (area.h * 0.7).min(11.0);
    let b = area.bottom();
    rect(view, area.x, b - 2.0, area.w, 2.0, palette::SPIKE_DARK);
    for i in 0..n as usize {
        let x = area.x + i as f32 * w;
        tri(
            view,
            vec2(x, b - 1.0),
            vec2(x + w / 2.0, b - h),
            vec2(x + w, b - 1.0),
            palette::SPIKE,
        );
        line(
            view,
            vec2(x + w / 2.0, b - h),
            vec2(x + w, b - 1.0),
            0.75,
            palette::SPIKE_DARK,
        );
    }
}

/// Draws the level's entities. `checkpoint`: the local player's respawn
/// checkpoint (drawn raised); `time`: seconds, for small animations;
/// `statics`: draw static blocks too (not when the level's own art draws
/// them).
pub fn draw_entities(
    entities: &[EntitySprite],
    view: &View,
    checkpoint: Option<u32>,
    time: f32,
    statics: bool,
) {
    let seen = view.visible();
    for e in entities {
        let tl = e.top_left();
        let area = Rect::new(tl.x, tl.y, e.size.x, e.size.y);
        // Poles and flags reach above their box.
        let margin = Rect::new(area.x - 16.0, area.y - 48.0, area.w + 32.0, area.h + 64.0);
        if !margin.overlaps(&seen) {
            continue;
        }
        match e.kind {
            EntityType::Spawn => {}
            EntityType::Block if statics => crate_box(view, area),
            EntityType::Block => {}
            // Drawn from the level's vertices by `draw_polygon_blocks`.
            EntityType::PolygonBlock => {}
            EntityType::Platform if e.one_way => {
                rect(view, area.x, area.y, area.w, area.h, palette::ONE_WAY_GHOST);
                rect(view, area.x, area.y, area.w, 4.0, palette::ONE_WAY);
                rect(view, area.x, area.y + 4.0, area.w, 1.0, palette::PLANK_DARK);
                // Chevrons: passable from below.
                let n = (area.w / 12.0).floor().max(1.0) as usize;
                for i in 0..n {
                    let cx = area.x + (i as f32 + 0.5) * area.w / n as f32;
                    let cy = area.y + area.h * 0.65;
                    line(
                        view,
                        vec2(cx - 3.0, cy + 2.0),
                        vec2(cx, cy - 1.0),
                        1.0,
                        palette::ONE_WAY,
                    );
                    line(
                        view,
                        vec2(cx, cy - 1.0),
                        vec2(cx + 3.0, cy + 2.0),
                        1.0,
                        palette::ONE_WAY,
                    );
                }
            }
            EntityType::Platform => {
                rect(view, area.x, area.y, area.w, area.h, palette::STEEL_DARK);
                rect(
                    view,
                    area.x + 1.0,
                    area.y + 1.0,
                    area.w - 2.0,
                    area.h - 2.0,
                    palette::STEEL,
                );
                rect(
                    view,
                    area.x + 1.0,
                    area.y + 1.0,
                    area.w - 2.0,
                    2.0,
                    palette::STEEL_LIGHT,
                );
                for x in [area.x + 4.0, area.right() - 4.0] {
                    let p = view.to_screen(vec2(x, area.y + area.h * 0.6));
                    draw_circle(p.x, p.y, view.zoom, palette::STEEL_DARK);
                }
            }
            EntityType::Walker => walker(view, area, e.active, e.facing, time),
            EntityType::Springboard => springboard(view, area),
            EntityType::Coin if e.active => coin(view, area, e.id, time),
            EntityType::Coin => {}
            EntityType::Checkpoint => {
                let raised = checkpoint == Some(e.id);
                flag(
                    view,
                    area,
                    if raised {
                        palette::FLAG_ACTIVE
                    } else {
                        palette::FLAG_IDLE
                    },
                    raised,
                );
            }
            EntityType::Goal => {
                // A golden pedestal, the flag, and a pulsing star above.
                rect(
                    view,
                    area.x,
                    area.bottom() - 4.0,
                    area.w,
                    4.0,
                    palette::COIN_DARK,
                );
                rect(
                    view,
                    area.x + 1.0,
                    area.bottom() - 4.0,
                    area.w - 2.0,
                    2.5,
                    palette::GOAL,
                );
                flag(view, area, palette::GOAL, true);
                let top = area.bottom() - area.h.max(24.0);
                let c = vec2(area.center().x, top - 7.0);
                let r = 4.5 + 0.8 * (time * 4.0).sin();
                let star = |k: f32| {
                    let a = std::f32::consts::FRAC_PI_2 + k * std::f32::consts::TAU / 3.0;
                    c - vec2(a.cos(), a.sin()) * r
                };
                let down = |k: f32| {
                    let a = -std::f32::consts::FRAC_PI_2 + k * std::f32::consts::TAU / 3.0;
                    c - vec2(a.cos(), a.sin()) * r
                };
                tri(view, star(0.0), star(1.0), star(2.0), palette::GOAL);
                tri(view, down(0.0), down(1.0), down(2.0), palette::GOAL);
            }
            EntityType::Hazard => spikes(view, area),
        }
    }
}

/// Draws the level's polygon solids ([`EntityKind::PolygonBlock`]: static,
/// so drawn from the level): filled like the ground, with an edge outline.
pub fn draw_polygon_blocks(level: &Level, view: &View) {
    let seen = view.visible();
    for e in &level.entities {
        let EntityKind::PolygonBlock { vertices } = &e.kind else {
            continue;
        };
        let (pos, size) = (e.pos.as_vec2() * PX, e.size.as_vec2() * PX);
        let tl = pos - size * 0.5;
        if vertices.len() < 3 || !Rect::new(tl.x, tl.y, size.x, size.y).overlaps(&seen) {
            continue;
        }
        let pts: Vec<Vec2> = vertices.iter().map(|v| pos + v.as_vec2() * PX).collect();
        // Convex: a fan from the first vertex covers it.
        for w in pts[1..].windows(2) {
            tri(view, pts[0], w[0], w[1], palette::SOLID);
        }
        for (i, a) in pts.iter().enumerate() {
            line(view, *a, pts[(i + 1) % pts.len()], 1.0, palette::SOLID_EDGE);
        }
    }
}

fn crate_box(view: &View, a: Rect) {
    rect(view, a.x, a.y, a.w, a.h, palette::CRATE_DARK);
    rect(
        view,
        a.x + 1.5,
        a.y + 1.5,
        a.w - 3.0,
        a.h - 3.0,
        palette::CRATE,
    );
    line(
        view,
        vec2(a.x + 2.0, a.y + 2.0),
        vec2(a.right() - 2.0, a.bottom() - 2.0),
        1.5,
        palette::CRATE_DARK,
    );
    line(
        view,
        vec2(a.right() - 2.0, a.y + 2.0),
        vec2(a.x + 2.0, a.bottom() - 2.0),
        1.5,
        palette::CRATE_DARK,
    );
}

fn walker(view: &View, a: Rect, alive: bool, facing: Facing, time: f32) {
    if !alive {
        let h = (a.h * 0.3).max(2.0);
        rect(view, a.x, a.bottom() - h, a.w, h, palette::WALKER_DEAD);
        return;
    }
    let bob = ((time * 10.0).sin() * 0.75).round();
    // Feet, body, eyes.
    for fx in [a.x + 1.0, a.right() - 4.0] {
        rect(view, fx, a.bottom() - 2.0, 3.0, 2.0, palette::INK);
    }
    let body = Rect::new(a.x, a.y + bob, a.w, a.h - 2.0 - bob);
    rect(view, body.x, body.y, body.w, body.h, palette::INK);
    rect(
        view,
        body.x + 1.0,
        body.y + 1.0,
        body.w - 2.0,
        body.h - 2.0,
        palette::WALKER,
    );
    eyes(view, body, facing, 1.0);
}

/// Two eyes in the upper part of `body`, looking towards `facing`.
fn eyes(view: &View, body: Rect, facing: Facing, alpha: f32) {
    let cx = body.center().x + facing.sign() * body.w * 0.15;
    let y = body.y + body.h * 0.22;
    for dx in [-0.2, 0.2] {
        let x = cx + dx * body.w - 1.25;
        rect(view, x, y, 2.5, 3.5, fade(palette::EYE, alpha));
        let px = x + if facing == Facing::Left { 0.0 } else { 1.25 };
        rect(view, px, y + 1.0, 1.25, 2.0, fade(palette::INK, alpha));
    }
}

fn springboard(view: &View, a: Rect) {
    let b = a.bottom();
    let plate = (a.h * 0.25).clamp(1.5, 3.0);
    rect(view, a.x + 1.0, b - plate, a.w - 2.0, plate, palette::METAL);
    // A zigzag coil from the base to the pad.
    let (low, high) = (b - plate, a.y + plate);
    let n = ((low - high) / 2.0).floor().max(2.0) as usize;
    let step = (low - high) / n as f32;
    for i in 0..n {
        let y0 = low - i as f32 * step;
        let (x0, x1) = if i % 2 == 0 {
            (a.x + 3.0, a.right() - 3.0)
        } else {
            (a.right() - 3.0, a.x + 3.0)
        };
        line(view, vec2(x0, y0), vec2(x1, y0 - step), 1.0, palette::METAL);
    }
    rect(view, a.x - 1.0, a.y, a.w + 2.0, plate, palette::SPRING);
    rect(
        view,
        a.x - 1.0,
        a.y + plate - 0.75,
        a.w + 2.0,
        0.75,
        palette::INK,
    );
}

fn coin(view: &View, a: Rect, id: u32, time: f32) {
    let c = a.center();
    let r = a.w.min(a.h) * 0.4;
    // Spin: the coin's width follows a cosine, each coin in its own phase.
    let phase = (id % 7) as f32 * 0.9;
    let squash = (time * 3.0 + phase).cos().abs().max(0.25);
    let p = view.to_screen(c);
    let (w, h) = (r * squash * view.zoom, r * view.zoom);
    draw_ellipse(p.x, p.y, w, h, 0.0, palette::COIN_DARK);
    draw_ellipse(p.x, p.y, w * 0.78, h * 0.85, 0.0, palette::COIN);
    draw_ellipse(
        p.x - w * 0.25,
        p.y - h * 0.3,
        w * 0.2,
        h * 0.25,
        0.0,
        palette::COIN_LIGHT,
    );
}

/// A flag on a pole standing on the bottom of `a`; `raised`: at the top.
fn flag(view: &View, a: Rect, color: Color, raised: bool) {
    let x = a.center().x - 0.5;
    let top = a.bottom() - a.h.max(24.0);
    rect(view, x, top, 1.5, a.bottom() - top, palette::POLE);
    rect(view, x - 2.0, a.bottom() - 2.0, 5.5, 2.0, palette::POLE);
    let fy = if raised {
        top
    } else {
        top + (a.bottom() - top) * 0.5
    };
    tri(
        view,
        vec2(x + 1.5, fy),
        vec2(x + 12.0, fy + 4.0),
        vec2(x + 1.5, fy + 8.0),
        color,
    );
}

/// The colour of player `id` (ours: [`palette::LOCAL_PLAYER`]).
pub fn player_color(id: u32, local: bool) -> Color {
    if local {
        palette::LOCAL_PLAYER
    } else {
        palette::REMOTE_PLAYERS[id as usize % palette::REMOTE_PLAYERS.len()]
    }
}

/// Height of a player's legs at rest, world px (the body is the rest of
/// its box).
const LEG: f32 = 3.0;

/// `c` darker (`f` < 1) or lighter, opaque.
fn shade(c: Color, f: f32) -> Color {
    Color::new(
        (c.r * f).min(1.0),
        (c.g * f).min(1.0),
        (c.b * f).min(1.0),
        1.0,
    )
}

/// Size of name labels' text, screen px.
const LABEL_SIZE: f32 = 16.0;
/// Height of one row of name labels, screen px (the text and its box,
/// and a little space).
const LABEL_ROW: f32 = 22.0;

/// Draws the players (ours over the others; `remotes` ascending by id),
/// then their name labels over all of them, each label stepped up where
/// it would overprint one before it (ours first, then by id). Dead players
/// are not drawn, nor their labels.
pub fn draw_players<'a>(
    view: &View,
    local: Option<(&'a PlayerSprite, &'a str)>,
    remotes: impl IntoIterator<Item = (&'a PlayerSprite, &'a str)>,
) {
    let remotes: Vec<_> = remotes.into_iter().filter(|(p, _)| !hidden(p)).collect();
    let local = local.filter(|(p, _)| !hidden(p));
    for (p, _) in &remotes {
        draw_body(p, view, player_color(p.id, false), 1.0);
    }
    if let Some((p, _)) = local {
        draw_body(p, view, player_color(p.id, true), 1.0);
    }
    let labelled: Vec<(&PlayerSprite, &str, Vec2, TextDimensions)> = local
        .into_iter()
        .chain(remotes)
        .filter(|(_, label)| !label.is_empty())
        .map(|(p, label)| {
            let dims = measure_text(label, None, LABEL_SIZE as u16, 1.0);
            (p, label, label_place(p, view, &dims), dims)
        })
        .collect();
    let boxes: Vec<Label> = labelled
        .iter()
        .map(|(_, _, at, dims)| Label {
            x: at.x + dims.width / 2.0,
            bottom: at.y - dims.offset_y + dims.height + 2.0,
            width: dims.width + 8.0,
        })
        .collect();
    let rows = label_rows(&boxes, LABEL_ROW);
    for ((_, label, at, dims), row) in labelled.iter().zip(rows) {
        let y = at.y - row as f32 * LABEL_ROW;
        draw_rectangle(
            at.x - 3.0,
            y - dims.offset_y - 2.0,
            dims.width + 6.0,
            dims.height + 4.0,
            Color::new(0.0, 0.0, 0.0, 0.45),
        );
        draw_text(label, at.x, y, LABEL_SIZE, WHITE);
    }
}

/// Whether `p` is not drawn at all (dead: the effects draw its death).
fn hidden(p: &PlayerSprite) -> bool {
    p.dead || p.pose.action == Action::Dead
}

/// Where `p`'s label text starts (left end of its baseline), screen px, in
/// the lowest row: steady above its box (not bouncing with the pose),
/// above its crown if it won.
fn label_place(p: &PlayerSprite, view: &View, dims: &TextDimensions) -> Vec2 {
    let top = view.to_screen(vec2(p.pos.x, p.pos.y - p.size.y / 2.0));
    let crown = if p.won { 4.0 * view.zoom } else { 0.0 };
    vec2(
        (top.x - dims.width / 2.0).round(),
        (top.y - 8.0 - crown).round(),
    )
}

/// Draws a ghost: `p`'s body in `color` at opacity `alpha` (the same
/// drawing as a player's), and its `label` above it, as faint.
pub fn draw_ghost(p: &PlayerSprite, view: &View, color: Color, alpha: f32, label: &str) {
    draw_body(p, view, color, alpha);
    if label.is_empty() {
        return;
    }
    let size = LABEL_SIZE - 2.0;
    let dims = measure_text(label, None, size as u16, 1.0);
    let at = label_place(p, view, &dims);
    draw_text(label, at.x, at.y, size, fade(WHITE, (alpha * 2.0).min(1.0)));
}

/// `c` at opacity `alpha` (times its own).
fn fade(c: Color, alpha: f32) -> Color {
    Color {
        a: c.a * alpha,
        ..c
    }
}

/// Draws a player's body in its pose (nothing while it is dead), at
/// opacity `alpha` (1: a player; less: a ghost). The
/// drawing stands on the bottom centre of its box: the body is scaled by
/// the pose from there and sheared by its lean, the legs follow the action
/// (a run cycle, tucked when rising, spread when falling, bent on landing,
/// one against the wall when sliding down it).
fn draw_body(p: &PlayerSprite, view: &View, color: Color, alpha: f32) {
    if hidden(p) {
        return;
    }
    let color = fade(color, alpha);
    let ink = fade(palette::INK, alpha);
    let pose = &p.pose;
    let tl = p.top_left();
    let a = Rect::new(tl.x, tl.y, p.size.x, p.size.y);
    let foot = vec2(a.center().x, a.bottom());
    let dir = pose.facing.sign();
    let (sx, sy) = (pose.scale.x, pose.scale.y);
    let leg = LEG * sy;
    let bw = a.w * sx;
    let bh = (a.h - LEG).max(1.0) * sy;
    let swing = (pose.phase * std::f32::consts::TAU).sin();
    let lift = (pose.phase * std::f32::consts::TAU).cos();
    // Where the wall is while sliding down it (-1 left, 1 right): the
    // player looks away from it.
    let wall = -dir;
    // Each leg: (x of its centre from the middle, how high its foot is
    // off the ground); then how far the body is raised and pushed sideways.
    let (legs, bob, push): ([(f32, f32); 2], f32, f32) = match pose.action {
        Action::Idle | Action::Dead => ([(-2.5, 0.0), (2.5, 0.0)], 0.0, 0.0),
        // Legs swing forward and back, the one swinging forward raised;
        // the body is highest when they pass each other.
        Action::Run => (
            [
                (3.0 * swing * dir, 1.5 * lift.max(0.0)),
                (-3.0 * swing * dir, 1.5 * (-lift).max(0.0)),
            ],
            0.75 * (1.0 - swing.abs()),
            0.0,
        ),
        // Tucked, one knee forward.
        Action::Jump => ([(1.5 * dir, 2.0), (-1.5 * dir, 1.0)], 0.0, 0.0),
        // Spread.
        Action::Fall => ([(-3.5, 0.0), (3.5, 0.0)], 0.0, 0.0),
        // Bent wide.
        Action::Land => (
            [(-3.5 * sx, 0.0), (3.5 * sx, 0.0)],
            -pose.landing * 0.4 * leg,
            0.0,
        ),
        // One foot up against the wall, the body pressed to it.
        Action::WallSlide => (
            [(wall * (bw / 2.0 - 2.0), 1.0), (-wall * 2.0, 0.0)],
            0.0,
            wall,
        ),
    };
    let cx = foot.x + push;
    let yb = foot.y - leg - bob;
    // A point of the body `u` px right of its middle and `z` px above its
    // bottom, leaning.
    let at = |u: f32, z: f32| vec2(cx + u + pose.lean * z, yb - z);
    // Legs (behind the body), with dark shoes pointing forward.
    for (dx, up) in legs {
        let x = foot.x + dx - 1.5;
        let top = yb - 0.5;
        let bottom = (foot.y - up).max(top + 1.0);
        rect(view, x, top, 3.0, bottom - 1.0 - top, color);
        let toe = if dir > 0.0 { 0.0 } else { -1.0 };
        rect(view, x + toe, bottom - 1.0, 4.0, 1.0, ink);
    }
    // The body: an outline, then the colour inside it.
    quad(
        view,
        [
            at(-bw / 2.0, 0.0),
            at(bw / 2.0, 0.0),
            at(bw / 2.0, bh),
            at(-bw / 2.0, bh),
        ],
        ink,
    );
    let (iw, ih) = (bw / 2.0 - 1.0, bh - 1.0);
    quad(
        view,
        [at(-iw, 1.0), at(iw, 1.0), at(iw, ih), at(-iw, ih)],
        color,
    );
    let head = at(0.0, bh);
    eyes(
        view,
        Rect::new(head.x - bw / 2.0 - pose.lean * 0.3 * bh, head.y, bw, bh),
        pose.facing,
        alpha,
    );
    // Arms: thrown up when jumping, flailing when falling, swinging
    // against the legs when running, one on the wall when sliding.
    let arm = fade(shade(color, 0.6), alpha);
    let shoulder = |k: f32| at(k * (bw / 2.0 - 0.5), bh * 0.45);
    let arms: Vec<(f32, Vec2)> = match pose.action {
        Action::Run => vec![
            (-1.0, vec2(-2.0, 1.5 * swing * dir)),
            (1.0, vec2(2.0, -1.5 * swing * dir)),
        ],
        Action::Jump => vec![(-1.0, vec2(-1.5, -4.0)), (1.0, vec2(1.5, -4.0))],
        Action::Fall => vec![(-1.0, vec2(-3.0, -2.5)), (1.0, vec2(3.0, -2.5))],
        Action::WallSlide => vec![
            (wall, vec2(wall * 0.5, -5.0)),
            (-wall, vec2(-wall * 2.5, 1.0)),
        ],
        Action::Idle | Action::Land | Action::Dead => Vec::new(),
    };
    for (k, reach) in arms {
        let from = shoulder(k);
        line(view, from, from + reach, 1.5, arm);
    }
    if p.won {
        let c = head.x;
        for dx in [-4.0, 0.0, 4.0] {
            tri(
                view,
                vec2(c + dx - 2.0, head.y - 1.0),
                vec2(c + dx, head.y - 5.0),
                vec2(c + dx + 2.0, head.y - 1.0),
                fade(palette::GOAL, alpha),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_ends_follow_the_surface() {
        let t = 4096;
        for s in Slope::ALL {
            let (l, r) = slope_ends(s, t);
            assert_eq!(l, s.height(0, t), "{s:?} left end");
            // The last unit column is within one unit of the line's end.
            let last = s.height(t - 1, t);
            assert!((r - last).abs() <= 1, "{s:?}: {r} vs {last}");
        }
    }

    /// Euclidean distance of two colours in RGB bytes (0 to 441).
    fn distance(a: Color, b: Color) -> f32 {
        let (a, b) = (palette::bytes(a), palette::bytes(b));
        (0..3)
            .map(|i| (a[i] as f32 - b[i] as f32).powi(2))
            .sum::<f32>()
            .sqrt()
    }

    #[test]
    fn colours_are_distinct_where_tests_look() {
        let all = [
            palette::SKY,
            palette::SOLID,
            palette::GRASS,
            palette::LOCAL_PLAYER,
        ];
        for (i, a) in all.iter().enumerate() {
            for b in &all[i + 1..] {
                assert_ne!(palette::bytes(*a), palette::bytes(*b));
            }
        }
    }

    #[test]
    fn players_are_told_apart_by_colour() {
        let remotes = palette::REMOTE_PLAYERS;
        assert!(remotes.len() >= 8, "at least 8 remote colours");
        // Far from each other, from us, and from what they stand in front
        // of (sky, clouds, ground, grass) and their own outline.
        let near = 80.0;
        for (i, a) in remotes.iter().enumerate() {
            for b in &remotes[i + 1..] {
                let d = distance(*a, *b);
                assert!(
                    d > near,
                    "{:?} {:?}: {d}",
                    palette::bytes(*a),
                    palette::bytes(*b)
                );
            }
            for b in [
                palette::LOCAL_PLAYER,
                palette::SKY,
                palette::CLOUD,
                palette::SOLID,
                palette::GRASS,
                palette::INK,
            ] {
                let d = distance(*a, b);
                assert!(
                    d > near,
                    "{:?} {:?}: {d}",
                    palette::bytes(*a),
                    palette::bytes(b)
                );
            }
        }
        // By id: consecutive ids differ; ours is ours whatever its id.
        for id in 0..16 {
            assert_ne!(
                palette::bytes(player_color(id, false)),
                palette::bytes(player_color(id + 1, false))
            );
            assert_eq!(
                palette::bytes(player_color(id, true)),
                palette::bytes(palette::LOCAL_PLAYER)
            );
        }
    }
}
