//! Sound cues from the game's state: which [`Effect`]s to play this frame.
//!
//! The window does not hear the simulation's events: the predicted game is
//! rolled back and replayed whenever a snapshot arrives, so its events of a
//! tick can be seen twice (or a predicted one never confirmed). Instead,
//! [`Cues`] keeps our player's previous [`PlayerView`] (and the walkers and
//! springboards around) and compares each frame's with it:
//!
//! | cue | when |
//! |---|---|
//! | [`Effect::Coin`] | `coins` went up |
//! | [`Effect::Hurt`] | `deaths` went up, or `dead` became `Some` (a death after finishing does not count) |
//! | [`Effect::Respawn`] | `dead` became `None` again, or the run restarted |
//! | [`Effect::Land`] | `grounded` became true after falling faster than a quarter of a jump's speed (not when put back at a respawn point) |
//! | [`Effect::Jump`] | a sudden upward velocity (at least half a jump's) that is not one of the next two |
//! | [`Effect::Spring`] | the same beside a springboard, or stronger than a jump by a quarter |
//! | [`Effect::Stomp`] | a walker within [`STOMP_REACH_PX`] of us became inactive while we go up |
//! | [`Effect::Checkpoint`] | `checkpoint` changed to another checkpoint (not back to the spawn) |
//! | [`Effect::Goal`] | `place` became `Some` |
//!
//! A restart (the timer back to 0 and not started, from a started run or
//! with deaths, coins or the place cleared) plays [`Effect::Respawn`] alone:
//! nothing is "lost" or "landed".
//!
//! **Rollbacks.** A correction can take a predicted change back and the
//! replay make it again (a coin picked up, un-picked by the server's
//! snapshot, picked up again a tick later). Each cue remembers the value it
//! was played for and the tick; the same cue for the same value within
//! [`REPEAT_TICKS`] ([`MOVE_REPEAT_TICKS`] for jump, land, spring and
//! stomp) is not played again. A replay that does not change what we see
//! changes nothing here: cues come from differences only. A state seen for the first time
//! (joining, a new game) plays nothing.
//!
//! The window's sound ([`crate::sound::audio`]) and effects ([`crate::draw::fx`]) are
//! its only listeners, so it is part of the front end, not of the headless
//! library.

use glam::IVec2;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::game::{EntityType, EntityView, Game, PlayerConfig, PlayerView};
use ledge_shared::protocol::PlayerId;

use crate::sound::audio::Effect;

/// The same cue for the same value within this many ticks is a replay, not
/// a new event (half a second at 60 ticks a second).
pub const REPEAT_TICKS: u64 = 30;

/// The same for the movement cues (jump, land, spring, stomp): two real
/// jumps are further apart.
pub const MOVE_REPEAT_TICKS: u64 = 8;

/// A walker defeated this close to us (centre to centre, pixels) while we
/// go up was stomped by us.
pub const STOMP_REACH_PX: i32 = 40;

/// A move of more than this many pixels in one frame is a teleport
/// (respawn, restart): no landing.
pub const TELEPORT_PX: i32 = 64;

/// How close (pixels, between boxes) a springboard must be for a launch to
/// be its.
const SPRING_REACH_PX: i32 = 8;

/// Number of [`Effect`] variants.
const EFFECTS: usize = Effect::ALL.len();

/// What was last cued, per effect: `(value, tick)`.
type Played = [Option<(u64, u64)>; EFFECTS];

/// Turns frame-to-frame changes of our player into sound effects.
#[derive(Debug, Clone)]
pub struct Cues {
    jump_speed: i32,
    prev: Option<PlayerView>,
    /// Walkers and springboards last frame: `(id, kind, centre, half, active)`.
    things: Vec<(u32, EntityType, IVec2, IVec2, bool)>,
    /// Scratch for this frame's.
    scratch: Vec<(u32, EntityType, IVec2, IVec2, bool)>,
    played: Played,
}

impl Default for Cues {
    fn default() -> Cues {
        Cues::new(&PlayerConfig::default())
    }
}

impl Cues {
    /// Cues for players moving as `config` says (its jump speed tells a
    /// jump from a springboard's launch).
    pub fn new(config: &PlayerConfig) -> Cues {
        Cues {
            jump_speed: config.jump_speed.max(1),
            prev: None,
            things: Vec::new(),
            scratch: Vec::new(),
            played: [None; EFFECTS],
        }
    }

    /// This frame's effects for player `me` of `game` (none if it is not in
    /// the game).
    pub fn observe(&mut self, game: &Game, me: PlayerId) -> Vec<Effect> {
        let player = game.player(me);
        let entities: Vec<EntityView> = game
            .entities()
            .filter(|e| matches!(e.ty, EntityType::Walker | EntityType::Springboard))
            .collect();
        self.update(game.tick(), player.as_ref(), &entities)
    }

    /// This frame's effects, from our player `me` now (at game tick `tick`)
    /// and the level's `entities` now (only walkers and springboards are
    /// looked at).
    pub fn update(
        &mut self,
        tick: u64,
        me: Option<&PlayerView>,
        entities: &[EntityView],
    ) -> Vec<Effect> {
        self.scratch.clear();
        self.scratch.extend(
            entities
                .iter()
                .filter(|e| matches!(e.ty, EntityType::Walker | EntityType::Springboard))
                .map(|e| (e.id, e.ty, e.pos, e.half, e.active)),
        );
        let mut out = Vec::new();
        if let (Some(prev), Some(now)) = (self.prev, me) {
            self.diff(tick, &prev, now, &mut out);
        }
        self.prev = me.copied();
        std::mem::swap(&mut self.things, &mut self.scratch);
        out
    }

    /// Plays `effect` for `value` unless it was just played for it.
    fn cue(&mut self, out: &mut Vec<Effect>, tick: u64, effect: Effect, value: u64) {
        // Movement cues come often; a replay of one is at most a frame or
        // two late.
        let window = match effect {
            Effect::Jump | Effect::Land | Effect::Spring | Effect::Stomp => MOVE_REPEAT_TICKS,
            _ => REPEAT_TICKS,
        };
        let slot = &mut self.played[effect as usize];
        if let Some((v, t)) = *slot {
            if v == value && tick >= t && tick - t < window {
                return;
            }
        }
        *slot = Some((value, tick));
        if !out.contains(&effect) {
            out.push(effect);
        }
    }

    fn diff(&mut self, tick: u64, prev: &PlayerView, now: &PlayerView, out: &mut Vec<Effect>) {
        // A restart clears the timer (it starts again with the next press)
        // and whatever the run had; a snapshot taking back a predicted
        // death or coin leaves the timer running.
        let restarted = !now.run_started
            && now.run_ticks == 0
            && (prev.run_started
                || now.deaths < prev.deaths
                || now.coins < prev.coins
                || (prev.place.is_some() && now.place.is_none()));
        let moved = (now.pos - prev.pos).abs();
        let teleported = moved.x.max(moved.y) > TELEPORT_PX * UNITS_PER_PX;
        if restarted {
            // A fresh run: forget what the old one cued (its coins, its
            // deaths), and only say we are back at the start.
            self.played = [None; EFFECTS];
            self.cue(out, tick, Effect::Respawn, u64::MAX);
            return;
        }
        if now.coins > prev.coins {
            self.cue(out, tick, Effect::Coin, now.coins.into());
        }
        let died = now.deaths > prev.deaths || (prev.dead.is_none() && now.dead.is_some());
        if died {
            self.cue(out, tick, Effect::Hurt, now.deaths.into());
        }
        // (Not a predicted death taken back by a snapshot.)
        let respawned = prev.dead.is_some() && now.dead.is_none() && now.deaths >= prev.deaths;
        // With no respawn delay the body is back in the tick it died.
        let instant_respawn = died && now.dead.is_none() && teleported;
        if respawned || instant_respawn {
            self.cue(out, tick, Effect::Respawn, now.deaths.into());
        }
        if now.checkpoint != prev.checkpoint {
            if let Some(c) = now.checkpoint {
                self.cue(out, tick, Effect::Checkpoint, c.into());
            }
        }
        if prev.place.is_none() && now.place.is_some() {
            self.cue(out, tick, Effect::Goal, now.run_ticks.into());
        }
        if died || now.dead.is_some() || respawned || teleported {
            return;
        }
        // Going up suddenly: a jump, a springboard or a stomp.
        let kick = now.vel.y - prev.vel.y;
        if now.vel.y < 0 && kick <= -self.jump_speed / 2 {
            let effect = if self.stomped_near(now.pos) {
                Effect::Stomp
            } else if now.vel.y < -(self.jump_speed + self.jump_speed / 4) || self.spring_near(now)
            {
                Effect::Spring
            } else {
                Effect::Jump
            };
            self.cue(out, tick, effect, 0);
        } else if !prev.grounded && now.grounded && prev.vel.y > self.jump_speed / 4 {
            self.cue(out, tick, Effect::Land, 0);
        }
    }

    /// A walker near `pos` was active last frame and is not now.
    fn stomped_near(&self, pos: IVec2) -> bool {
        let reach = STOMP_REACH_PX * UNITS_PER_PX;
        self.scratch.iter().any(|&(id, ty, at, _, active)| {
            ty == EntityType::Walker
                && !active
                && (at - pos).abs().max_element() <= reach
                && self
                    .things
                    .iter()
                    .any(|&(old, _, _, _, was)| old == id && was)
        })
    }

    /// A springboard touches (or nearly) our box.
    fn spring_near(&self, me: &PlayerView) -> bool {
        let reach = SPRING_REACH_PX * UNITS_PER_PX;
        self.scratch.iter().any(|&(_, ty, at, half, _)| {
            let gap = (at - me.pos).abs() - half - me.half;
            ty == EntityType::Springboard && gap.x <= reach && gap.y <= reach
        })
    }
}

#[cfg(test)]
mod tests;
