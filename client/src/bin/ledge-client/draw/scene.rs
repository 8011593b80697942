//! The world as a frame shows it, back to front: the sky (or the level
//! art's background colour), the level's art, its tiles and polygon
//! blocks, the entities, the ghosts, the players with their name labels, the effects
//! and, when asked, the debug overlay. The game loop and the replay window
//! draw with it alike.

use ledge_client::view::px2;
use ledge_shared::level::Level;
use macroquad::prelude::*;

use crate::draw::art::ArtView;
use crate::draw::camera::View;
use crate::draw::debug;
use crate::draw::fx::Fx;
use crate::draw::ghost::{self, GhostSprite};
use crate::draw::render::{self, EntitySprite, PlayerSprite};

/// What one frame draws of the world.
pub struct WorldFrame<'a> {
    /// The level played.
    pub level: &'a Level,
    /// Its own art (empty: ledge's flat colours).
    pub art: &'a ArtView,
    /// The camera.
    pub view: &'a View,
    /// The entities as drawn this frame.
    pub entities: &'a [EntitySprite],
    /// The checkpoint our (or the followed) player respawns at: drawn
    /// raised.
    pub checkpoint: Option<u32>,
    /// The ghosts to race (drawn under the players).
    pub ghosts: &'a [GhostSprite],
    /// Our (or the followed) player and its label, drawn over the others.
    pub local: Option<(&'a PlayerSprite, &'a str)>,
    /// The other players and their labels, ascending by id.
    pub remotes: Vec<(&'a PlayerSprite, &'a str)>,
    /// The particles and the flash.
    pub effects: &'a Fx,
    /// The simulation's world, for the debug overlay (F1) when shown.
    pub debug: Option<&'a ledge_shared::world::World>,
    /// Seconds since the start, for small animations.
    pub time: f32,
}

/// Draws the world of `frame`.
pub fn draw(frame: WorldFrame) {
    let WorldFrame {
        level, art, view, ..
    } = frame;
    match art.background() {
        Some(colour) => clear_background(colour),
        None => render::draw_background(view, frame.time),
    }
    art.draw(view);
    render::draw_tilemap(&level.tilemap, view, art.covered());
    // A level's own art draws its solids; ledge draws them otherwise.
    let statics = art.is_empty();
    if statics {
        render::draw_polygon_blocks(level, view);
    }
    render::draw_entities(frame.entities, view, frame.checkpoint, frame.time, statics);
    ghost::draw(frame.ghosts, view);
    render::draw_players(view, frame.local, frame.remotes);
    frame.effects.draw(view);
    frame.effects.draw_flash();
    if let Some(world) = frame.debug {
        debug::draw(world, view);
    }
}

/// The world the camera stays inside: everything in the level (grid,
/// entities, platform paths) and everything its art draws, world pixels.
pub fn level_extent(level: &Level, art: &ArtView) -> Rect {
    let things = level.bounds().map(|(lo, hi)| {
        let (lo, hi) = (px2(lo), px2(hi));
        Rect::new(lo.x, lo.y, hi.x - lo.x, hi.y - lo.y)
    });
    match (things, art.extent()) {
        (Some(a), Some(e)) => a.combine_with(e),
        (Some(a), None) => a,
        (None, Some(e)) => e,
        (None, None) => Rect::new(0.0, 0.0, 1.0, 1.0),
    }
}
