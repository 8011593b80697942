//! Ghosts in the world: the runs the server sent to race against
//! ([`ledge_client::ghost::Ghost`]: the level's record, our own best),
//! each drawn as a translucent player where its runner was at the tick our
//! own run timer shows; before our run starts at its start, once our run
//! is finished at its goal.

use glam::IVec2;
use ledge_client::ghost::Ghost;
use ledge_client::view::{px2, Facing, PlayerDraw};
use ledge_shared::game::PlayerView;
use ledge_shared::protocol::PlayerId;
use macroquad::prelude::*;

use crate::draw::anim::Pose;
use crate::draw::camera::View;
use crate::draw::render::{self, palette, PlayerSprite};

/// A ghost's opacity.
pub const ALPHA: f32 = 0.35;

/// A ghost as drawn this frame.
#[derive(Debug, Clone, PartialEq)]
pub struct GhostSprite {
    /// The level's record (else our own best).
    pub record: bool,
    /// Who ran it.
    pub player: String,
    /// The tick of its run drawn.
    pub run_tick: u32,
    /// Where its runner was then (centre, units).
    pub units: IVec2,
    /// The body drawn.
    pub sprite: PlayerSprite,
    /// Its label: "record: NAME m:ss.cc" or "your best m:ss.cc".
    pub label: String,
}

/// The tick of a ghost's run to draw while our player is `me`: our run
/// timer's while it runs, 0 before it starts, its last once ours finished.
pub fn ghost_tick(ghost: &Ghost, me: Option<&PlayerView>) -> u32 {
    match me {
        Some(m) if m.won || m.place.is_some() => ghost.ticks(),
        Some(m) if m.run_started => m.run_ticks,
        _ => 0,
    }
}

/// `millis` as `m:ss.cc` (hundredths rounded down).
pub fn millis_time(millis: u64) -> String {
    let cs = millis / 10;
    format!("{}:{:02}.{:02}", cs / 6000, cs / 100 % 60, cs % 100)
}

/// The label over a ghost.
pub fn label(ghost: &Ghost) -> String {
    let time = millis_time(ghost.millis);
    if ghost.record {
        format!("record: {} {time}", ghost.player)
    } else {
        format!("your best {time}")
    }
}

/// The ghosts to draw this frame, our player being `me` (`None`: not in
/// the game yet); `rate`: ticks a second.
pub fn place(ghosts: &[Ghost], me: Option<&PlayerView>, rate: u32) -> Vec<GhostSprite> {
    ghosts
        .iter()
        .filter_map(|ghost| {
            let run_tick = ghost_tick(ghost, me);
            let units = ghost.at(run_tick)?;
            Some(GhostSprite {
                record: ghost.record,
                player: ghost.player.clone(),
                run_tick,
                units,
                sprite: sprite(ghost, run_tick, rate),
                label: label(ghost),
            })
        })
        .collect()
}

/// The ghost's body at `run_tick`: posed from how it moved between that
/// tick and the next (the track holds positions only).
fn sprite(ghost: &Ghost, run_tick: u32, rate: u32) -> PlayerSprite {
    let at = |t: u32| ghost.at(t).map_or(Vec2::ZERO, px2);
    let pos = at(run_tick);
    let next = at(run_tick.saturating_add(1));
    let before = at(run_tick.saturating_sub(1));
    let mut draw = PlayerDraw::new(PlayerId(0), pos, px2(ghost.half * 2));
    draw.vel = (next - pos) * rate as f32;
    // Level with the tick before and after: on the ground.
    draw.grounded = next.y == pos.y && before.y == pos.y;
    draw.facing = if draw.vel.x.abs() > 0.0 {
        Facing::from_left(draw.vel.x < 0.0)
    } else {
        Facing::from_left(pos.x < before.x)
    };
    draw.won = run_tick >= ghost.ticks();
    PlayerSprite {
        id: 0,
        name: Some(ghost.player.clone()),
        pos,
        size: draw.size,
        facing: draw.facing,
        won: draw.won,
        dead: false,
        pose: Pose::still(&draw),
    }
}

/// A ghost's tint: the record's or our best's.
pub fn tint(record: bool) -> Color {
    if record {
        palette::GHOST_RECORD
    } else {
        palette::GHOST_BEST
    }
}

/// Draws `ghosts` (under the players).
pub fn draw(ghosts: &[GhostSprite], view: &View) {
    for g in ghosts {
        render::draw_ghost(&g.sprite, view, tint(g.record), ALPHA, &g.label);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ghost() -> Ghost {
        Ghost {
            record: true,
            player: "bob".into(),
            millis: 2_050,
            track: (0..=120)
                .map(|t| IVec2::new(1000 + t * 100, 5000))
                .collect(),
            half: IVec2::new(6 * 256, 8 * 256),
            splits: vec![(7, 60)],
        }
    }

    fn me(run_started: bool, run_ticks: u32, won: bool) -> PlayerView {
        let mut game = ledge_shared::game::Game::from_level(&ledge_levels::default_level())
            .expect("the default level plays");
        let id = PlayerId(1);
        game.add_player(id).expect("a player joins");
        let mut me = game.player(id).expect("in the game");
        me.run_started = run_started;
        me.run_ticks = run_ticks;
        me.won = won;
        me
    }

    #[test]
    fn a_ghost_runs_with_our_timer_waits_at_its_start_and_ends_at_its_goal() {
        let g = ghost();
        assert_eq!(ghost_tick(&g, None), 0);
        assert_eq!(ghost_tick(&g, Some(&me(false, 0, false))), 0);
        assert_eq!(ghost_tick(&g, Some(&me(true, 42, false))), 42);
        assert_eq!(ghost_tick(&g, Some(&me(true, 90, true))), 120);
        let placed = place(std::slice::from_ref(&g), Some(&me(true, 42, false)), 60);
        assert_eq!(placed.len(), 1);
        assert_eq!(placed[0].units, g.track[42]);
        assert_eq!(placed[0].sprite.pos, px2(g.track[42]));
        assert_eq!(placed[0].sprite.facing, Facing::Right);
        assert_eq!(placed[0].label, "record: bob 0:02.05");
        // Past its finish (our run slower): at its goal, crowned.
        let late = place(std::slice::from_ref(&g), Some(&me(true, 500, false)), 60);
        assert_eq!(late[0].units, g.track[120]);
        assert!(late[0].sprite.won);
        let best = Ghost { record: false, ..g };
        assert_eq!(label(&best), "your best 0:02.05");
    }
}
