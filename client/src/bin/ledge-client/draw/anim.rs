//! How players look from frame to frame: an action (idle, run, jump, ...),
//! squash and stretch, a run cycle and a lean, from the simulation's state
//! in each [`PlayerDraw`] plus a little memory (when it landed, how fast
//! it fell). Cosmetic only: nothing here feeds back into the simulation,
//! and the box it collides with stays the box in [`PlayerDraw`].
//!
//! Only the window shows it, so it is part of the front end, not of the
//! headless library; pure (no drawing here), so it is tested without a
//! window, and [`crate::draw::render`] draws the [`Pose`]s. Everything is driven
//! by the frame's `dt` in seconds (exponential easing, timers), so the
//! result does not depend on the frame rate.
//!
//! [`spread`] fans out players drawn on top of each other (eight bots at
//! the goal) so that each stays visible, and [`label_rows`] steps their
//! name labels upwards so that none overprints another.

use std::collections::BTreeMap;

use ledge_shared::protocol::PlayerId;

use ledge_client::view::{Facing, PlayerDraw, Vec2};

/// Horizontal speed below which a grounded player stands (px/s).
pub const RUN_MIN_SPEED: f32 = 8.0;
/// Vertical speed below which an airborne player counts as rising (px/s,
/// y down: moving up faster than this is [`Action::Jump`]).
pub const RISE_MIN_SPEED: f32 = 10.0;
/// A landing after falling slower than this shows no squash and no
/// [`Action::Land`] (px/s; a step down a few pixels lands at about 100).
pub const LAND_MIN_SPEED: f32 = 120.0;
/// A landing this fast or faster shows the full squash (px/s: the default
/// maximum fall speed).
pub const LAND_FULL_SPEED: f32 = 360.0;
/// How long a landing's squash (and [`Action::Land`]) lasts, seconds.
pub const LAND_SECONDS: f32 = 0.13;
/// Widening at the full landing squash (0.3: 30% wider, 23% shorter).
pub const LAND_SQUASH: f32 = 0.3;
/// Stretch while rising at [`STRETCH_FULL_SPEED`] or faster (0.2: 20%
/// taller, 17% thinner).
pub const RISE_STRETCH: f32 = 0.2;
/// Stretch while falling at [`STRETCH_FULL_SPEED`] or faster.
pub const FALL_STRETCH: f32 = 0.08;
/// The vertical speed of full stretch (px/s: the default jump speed).
pub const STRETCH_FULL_SPEED: f32 = 300.0;
/// Scale factors stay within `[1 / MAX_SCALE, MAX_SCALE]`.
pub const MAX_SCALE: f32 = 1.4;
/// Pixels run per full run cycle (two steps).
pub const STRIDE_PX: f32 = 32.0;
/// Lean (shear, see [`Pose::lean`]) when running at [`LEAN_FULL_SPEED`].
pub const RUN_LEAN: f32 = 0.15;
/// Lean in the air at [`LEAN_FULL_SPEED`].
pub const AIR_LEAN: f32 = 0.06;
/// Horizontal speed of the full lean (px/s: the default run speed).
pub const LEAN_FULL_SPEED: f32 = 150.0;
/// How fast the stretch follows the speed, per second (1/time constant).
const STRETCH_RATE: f32 = 20.0;
/// How fast the lean follows the speed, per second.
const LEAN_RATE: f32 = 12.0;
/// A frame longer than this is animated as this long (a stall, the first
/// frame), seconds.
const MAX_DT: f32 = 0.25;
/// A player moving farther than this in one frame was teleported (a
/// respawn, a restart): no landing from what came before (px).
const TELEPORT_PX: f32 = 64.0;
/// Updates a player may be missing before its memory is forgotten.
const FORGET_AFTER: u32 = 2;

/// What a player is doing, for drawing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Action {
    /// Standing on the ground.
    #[default]
    Idle,
    /// Moving on the ground.
    Run,
    /// Airborne, going up.
    Jump,
    /// Airborne, going down (or at the top of a jump).
    Fall,
    /// Just landed after a fast fall, for [`LAND_SECONDS`].
    Land,
    /// Airborne, pressed against a wall and not rising (our player only:
    /// see [`PlayerDraw::wall`]).
    WallSlide,
    /// Dead, waiting to respawn: draw no body.
    Dead,
}

impl Action {
    /// The action `p`'s state alone shows (no memory, so never
    /// [`Action::Land`]).
    pub fn of(p: &PlayerDraw) -> Action {
        if p.dead {
            Action::Dead
        } else if p.grounded {
            if p.vel.x.abs() > RUN_MIN_SPEED {
                Action::Run
            } else {
                Action::Idle
            }
        } else if p.vel.y < -RISE_MIN_SPEED {
            Action::Jump
        } else if p.wall.is_some() {
            Action::WallSlide
        } else {
            Action::Fall
        }
    }
}

/// How to draw one player this frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// What it is doing.
    pub action: Action,
    /// Squash and stretch of the drawing, anchored at the feet (bottom
    /// centre of the box): `(1, 1)` at rest, `y > 1` tall and thin
    /// (rising), `x > 1` wide and short (landing). Roughly area-preserving
    /// (`x * y` near 1), each within `[1 / MAX_SCALE, MAX_SCALE]`.
    pub scale: Vec2,
    /// Which way it looks (away from the wall while wall sliding).
    pub facing: Facing,
    /// Run cycle in `[0, 1)`: advances with the distance run, so faster
    /// runs move the legs faster. Legs alternate at 0 and 0.5.
    pub phase: f32,
    /// Lean into the motion as a shear: how far the top of the body is
    /// shifted sideways per pixel of height (+x to the right; within
    /// `[-RUN_LEAN, RUN_LEAN]`).
    pub lean: f32,
    /// What is left of the landing squash, `[0, 1]` (1: just landed, 0:
    /// none, or over), for bending the legs with it.
    pub landing: f32,
}

impl Pose {
    /// `p`'s pose with no history: [`Action::of`], unscaled, unleaned.
    pub fn still(p: &PlayerDraw) -> Pose {
        let action = Action::of(p);
        Pose {
            action,
            scale: Vec2::ONE,
            facing: facing_for(action, p),
            phase: 0.0,
            lean: 0.0,
            landing: 0.0,
        }
    }
}

/// The way to look: away from the wall while sliding down it.
fn facing_for(action: Action, p: &PlayerDraw) -> Facing {
    match (action, p.wall) {
        (Action::WallSlide, Some(Facing::Left)) => Facing::Right,
        (Action::WallSlide, Some(Facing::Right)) => Facing::Left,
        _ => p.facing,
    }
}

/// What the animator remembers of one player.
///
/// Each update first advances the eased values over the frame's `dt`
/// towards the targets of the state shown during that time (the previous
/// one), then takes the new state's targets: so a change of state has the
/// same effect at any frame rate.
#[derive(Debug, Clone, Copy)]
struct Memory {
    /// Position at the last update (teleport detection).
    pos: Vec2,
    /// Airborne at the last update.
    airborne: bool,
    /// Fastest downward speed since it left the ground (px/s).
    fall_speed: f32,
    /// Seconds since the last landing squash began (`None`: none running).
    land_age: Option<f32>,
    /// Strength of that landing, `(0, 1]`.
    land_strength: f32,
    /// Eased stretch (tall when positive; squash comes from landing).
    stretch: f32,
    /// What the stretch eases towards.
    target_stretch: f32,
    /// Eased lean.
    lean: f32,
    /// What the lean eases towards.
    target_lean: f32,
    /// Run cycle.
    phase: f32,
    /// Run cycles per second.
    phase_rate: f32,
    /// Updates since it was last seen.
    missed: u32,
}

impl Memory {
    fn new(p: &PlayerDraw) -> Memory {
        Memory {
            pos: p.pos,
            airborne: !p.grounded && !p.dead,
            fall_speed: 0.0,
            land_age: None,
            land_strength: 0.0,
            stretch: 0.0,
            target_stretch: 0.0,
            lean: 0.0,
            target_lean: 0.0,
            phase: 0.0,
            phase_rate: 0.0,
            missed: 0,
        }
    }

    /// Advances by `dt` seconds to `p`'s state and gives its pose.
    fn step(&mut self, dt: f32, p: &PlayerDraw) -> Pose {
        self.missed = 0;
        // The frame that went by.
        self.stretch = ease(self.stretch, self.target_stretch, STRETCH_RATE, dt);
        self.lean = ease(self.lean, self.target_lean, LEAN_RATE, dt);
        self.phase = (self.phase + self.phase_rate * dt).fract();
        if let Some(age) = &mut self.land_age {
            *age += dt;
        }

        // The new state.
        let teleported = (p.pos - self.pos).length() > TELEPORT_PX;
        self.pos = p.pos;
        if p.dead || teleported {
            // Start over: a respawn neither lands nor keeps the old motion.
            *self = Memory::new(p);
            if p.dead {
                return Pose::still(p);
            }
        }
        // Landing: the first grounded update after being airborne.
        if p.grounded {
            if self.airborne {
                // The impact ends the stretch at once.
                self.stretch = 0.0;
            }
            if self.airborne && self.fall_speed > LAND_MIN_SPEED {
                self.land_age = Some(0.0);
                self.land_strength = ((self.fall_speed - LAND_MIN_SPEED)
                    / (LAND_FULL_SPEED - LAND_MIN_SPEED))
                    .clamp(0.05, 1.0);
            }
            self.airborne = false;
            self.fall_speed = 0.0;
        } else {
            self.airborne = true;
            self.fall_speed = self.fall_speed.max(p.vel.y);
            // Leaving the ground ends a landing at once.
            self.land_age = None;
        }
        let landing = match self.land_age {
            Some(age) if age < LAND_SECONDS => {
                let left = 1.0 - age / LAND_SECONDS;
                // Eased out: most of the squash goes back quickly.
                left * left
            }
            _ => {
                self.land_age = None;
                0.0
            }
        };

        let mut action = Action::of(p);
        if landing > 0.0 && p.grounded {
            action = Action::Land;
        }
        // Stretch with vertical speed in the air.
        self.target_stretch = if p.grounded {
            0.0
        } else if p.vel.y < 0.0 {
            RISE_STRETCH * (-p.vel.y / STRETCH_FULL_SPEED).min(1.0)
        } else {
            FALL_STRETCH * (p.vel.y / STRETCH_FULL_SPEED).min(1.0)
        };
        // The run cycle follows the distance run; standing resets it so
        // that the next run starts with the same step.
        self.phase_rate = match action {
            Action::Run | Action::Land => p.vel.x.abs() / STRIDE_PX,
            _ => 0.0,
        };
        if action == Action::Idle {
            self.phase = 0.0;
        }
        let lean_full = match action {
            Action::Run => RUN_LEAN,
            Action::Jump | Action::Fall => AIR_LEAN,
            _ => 0.0,
        };
        self.target_lean = lean_full * (p.vel.x / LEAN_FULL_SPEED).clamp(-1.0, 1.0);

        // Area-preserving: y by the stretch over the squash, x its inverse.
        let squash = LAND_SQUASH * self.land_strength * landing;
        let sy = ((1.0 + self.stretch) / (1.0 + squash)).clamp(1.0 / MAX_SCALE, MAX_SCALE);
        Pose {
            action,
            scale: Vec2::new(1.0 / sy, sy),
            facing: facing_for(action, p),
            phase: self.phase,
            lean: self.lean,
            landing: if squash > 0.0 { landing } else { 0.0 },
        }
    }
}

/// Moves `from` towards `to` as an exponential decay at `rate` per second
/// over `dt` seconds (the same result in one step or many).
fn ease(from: f32, to: f32, rate: f32, dt: f32) -> f32 {
    to + (from - to) * (-rate * dt).exp()
}

/// Per-player animation memory: call [`Animator::update`] once per drawn
/// frame with every player drawn.
#[derive(Debug, Clone, Default)]
pub struct Animator {
    players: BTreeMap<PlayerId, Memory>,
}

impl Animator {
    /// An animator that has seen no one.
    pub fn new() -> Animator {
        Animator::default()
    }

    /// Advances every player in `players` by `dt` seconds (the frame's
    /// duration; a long stall counts as a quarter second) and returns
    /// their poses in the same order. Players missing from
    /// `FORGET_AFTER` updates in a row are forgotten (a player seen
    /// again later starts afresh).
    pub fn update<'a>(
        &mut self,
        dt: f32,
        players: impl IntoIterator<Item = &'a PlayerDraw>,
    ) -> Vec<Pose> {
        let dt = if dt.is_finite() {
            dt.clamp(0.0, MAX_DT)
        } else {
            0.0
        };
        for m in self.players.values_mut() {
            m.missed += 1;
        }
        let poses = players
            .into_iter()
            .map(|p| {
                self.players
                    .entry(p.id)
                    .or_insert_with(|| Memory::new(p))
                    .step(dt, p)
            })
            .collect();
        self.players.retain(|_, m| m.missed < FORGET_AFTER);
        poses
    }

    /// How many players it remembers.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.players.len()
    }

    /// Whether it remembers no one.
    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.players.is_empty()
    }
}

/// Players whose centres are within this distance of each other (px) are
/// a stack for [`spread`].
pub const STACK_RADIUS: f32 = 4.0;
/// Sideways distance between the players of a spread stack (px).
pub const SPREAD_GAP: f32 = 8.0;
/// [`label_rows`] stacks labels at most this many rows high (more crowded
/// labels share rows).
pub const MAX_LABEL_ROWS: u32 = 16;

/// Drawing positions for `players` (`(id, centre)`, any order) such that
/// players nearly on top of each other stay visible: each stack (centres
/// within [`STACK_RADIUS`], chained) is fanned out sideways
/// [`SPREAD_GAP`] apart, left to right as they stand (by whole pixels,
/// then by id: players on one pixel in id order). `ours` (our player's
/// id) is never moved: the others of its stack go to its left and right
/// as they stand. A stack without it is centred on its members' mean.
/// Players not in a stack keep their position. Cosmetic only (the
/// simulation never sees it); deterministic; the result is in `players`'
/// order.
pub fn spread(players: &[(PlayerId, Vec2)], ours: Option<PlayerId>) -> Vec<Vec2> {
    let n = players.len();
    let mut drawn: Vec<Vec2> = players.iter().map(|&(_, pos)| pos).collect();
    // Stacks: connected components of "within the radius" (union-find).
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for i in 0..n {
        for j in i + 1..n {
            if (players[i].1 - players[j].1).length() <= STACK_RADIUS {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut stacks: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for i in 0..n {
        let r = root(&mut parent, i);
        stacks.entry(r).or_default().push(i);
    }
    for mut members in stacks.into_values().filter(|m| m.len() > 1) {
        // Left to right (whole pixels, so that jitter does not reorder),
        // then by id, then as given (repeated ids).
        members.sort_by(|&i, &j| {
            let key = |k: usize| (players[k].1.x.round(), players[k].0, k);
            let (a, b) = (key(i), key(j));
            a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2))
        });
        // Ours stays where it is; else the stack is centred on its mean.
        let (anchor, anchor_x) = match members.iter().position(|&i| Some(players[i].0) == ours) {
            Some(a) => (a as f32, players[members[a]].1.x),
            None => (
                (members.len() - 1) as f32 / 2.0,
                members.iter().map(|&i| players[i].1.x).sum::<f32>() / members.len() as f32,
            ),
        };
        for (k, &i) in members.iter().enumerate() {
            drawn[i].x = anchor_x + (k as f32 - anchor) * SPREAD_GAP;
        }
    }
    drawn
}

/// A name label to place with [`label_rows`], in any one unit (screen
/// pixels, say).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Label {
    /// Horizontal centre.
    pub x: f32,
    /// Bottom edge in its lowest row (y down: rows go up from there).
    pub bottom: f32,
    /// Full width.
    pub width: f32,
}

/// Rows for name labels so that none overprints another: label `i` is
/// drawn `rows[i] * row_height` above its place. Labels are placed in the
/// order given (put ours first, then by id), each in the lowest row where
/// it overlaps no label placed before it (rows `row_height` tall), at most
/// [`MAX_LABEL_ROWS`] high (beyond that, the lowest row). Labels of
/// players far apart all stay in row 0.
pub fn label_rows(labels: &[Label], row_height: f32) -> Vec<u32> {
    let mut rows: Vec<u32> = Vec::with_capacity(labels.len());
    for (i, a) in labels.iter().enumerate() {
        // Labels placed before that this one could overlap sideways.
        let near: Vec<(f32, u32)> = labels[..i]
            .iter()
            .zip(&rows)
            .filter(|(b, _)| (a.x - b.x).abs() < (a.width + b.width) / 2.0)
            .map(|(b, &r)| (b.bottom - r as f32 * row_height, r))
            .collect();
        let free = |r: u32| {
            let bottom = a.bottom - r as f32 * row_height;
            near.iter().all(|&(b, _)| (bottom - b).abs() >= row_height)
        };
        rows.push((0..MAX_LABEL_ROWS).find(|&r| free(r)).unwrap_or(0));
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 12x16 player at `pos` moving at `vel`.
    fn player(id: u32, pos: Vec2, vel: Vec2, grounded: bool) -> PlayerDraw {
        let mut p = PlayerDraw::new(PlayerId(id), pos, Vec2::new(12.0, 16.0));
        p.vel = vel;
        p.grounded = grounded;
        p
    }

    fn on_ground(vx: f32) -> PlayerDraw {
        player(1, Vec2::new(100.0, 200.0), Vec2::new(vx, 0.0), true)
    }

    fn in_air(vy: f32) -> PlayerDraw {
        player(1, Vec2::new(100.0, 150.0), Vec2::new(0.0, vy), false)
    }

    /// Runs `frames` updates of `dt` with the same state; the last pose.
    fn hold(a: &mut Animator, p: &PlayerDraw, dt: f32, frames: usize) -> Pose {
        let mut pose = None;
        for _ in 0..frames {
            pose = Some(a.update(dt, [p])[0]);
        }
        pose.expect("at least one frame")
    }

    /// Falls at `speed` for a while, then lands; the animator and the
    /// landing frame's pose.
    fn land_after_falling(speed: f32, dt: f32) -> (Animator, Pose) {
        let mut a = Animator::new();
        hold(&mut a, &in_air(speed), dt, 10);
        let pose = a.update(dt, [&on_ground(0.0)])[0];
        (a, pose)
    }

    fn close(a: f32, b: f32, eps: f32) -> bool {
        (a - b).abs() <= eps
    }

    #[test]
    fn idle_on_the_ground_stands_still() {
        let mut a = Animator::new();
        let pose = hold(&mut a, &on_ground(0.0), 1.0 / 60.0, 30);
        assert_eq!(pose.action, Action::Idle);
        assert_eq!(pose.scale, Vec2::ONE);
        assert_eq!(pose.lean, 0.0);
        assert_eq!(pose.phase, 0.0);
        assert_eq!(pose.landing, 0.0);
        assert_eq!(pose.facing, Facing::Right);
        // Barely moving is still standing.
        let pose = hold(&mut a, &on_ground(RUN_MIN_SPEED * 0.5), 1.0 / 60.0, 5);
        assert_eq!(pose.action, Action::Idle);
    }

    #[test]
    fn moving_on_the_ground_runs_and_leans_into_it() {
        let mut a = Animator::new();
        let pose = hold(&mut a, &on_ground(150.0), 1.0 / 60.0, 60);
        assert_eq!(pose.action, Action::Run);
        assert!(pose.lean > RUN_LEAN * 0.9, "{pose:?}");
        assert!(pose.lean <= RUN_LEAN);
        let mut left = on_ground(-150.0);
        left.facing = Facing::Left;
        let pose = hold(&mut a, &left, 1.0 / 60.0, 60);
        assert_eq!(pose.action, Action::Run);
        assert_eq!(pose.facing, Facing::Left);
        assert!(pose.lean < -RUN_LEAN * 0.9, "{pose:?}");
        // Stopping straightens up again.
        let pose = hold(&mut a, &on_ground(0.0), 1.0 / 60.0, 60);
        assert_eq!(pose.action, Action::Idle);
        assert!(pose.lean.abs() < 0.001, "{pose:?}");
    }

    #[test]
    fn jump_and_fall_follow_the_vertical_velocity() {
        let mut a = Animator::new();
        let up = hold(&mut a, &in_air(-300.0), 1.0 / 60.0, 20);
        assert_eq!(up.action, Action::Jump);
        // Tall and thin while rising fast.
        assert!(up.scale.y > 1.15 && up.scale.x < 0.9, "{up:?}");
        let top = hold(&mut a, &in_air(0.0), 1.0 / 60.0, 1);
        assert_eq!(top.action, Action::Fall, "the top of a jump");
        let down = hold(&mut a, &in_air(300.0), 1.0 / 60.0, 20);
        assert_eq!(down.action, Action::Fall);
        // Falling stretches less than rising.
        assert!(down.scale.y > 1.0 && down.scale.y < up.scale.y, "{down:?}");
    }

    #[test]
    fn a_fast_fall_lands_with_a_squash_that_goes_away() {
        let dt = 1.0 / 60.0;
        let (mut a, pose) = land_after_falling(LAND_FULL_SPEED, dt);
        assert_eq!(pose.action, Action::Land);
        // Wide and short, by the full squash.
        assert!(pose.scale.x > 1.25 && pose.scale.y < 0.8, "{pose:?}");
        assert!(close(pose.landing, 1.0, 1e-6));
        // Over within its duration (and back to idle).
        let frames = (LAND_SECONDS / dt).ceil() as usize + 1;
        let mut previous = pose.scale.x;
        for _ in 0..frames {
            let p = a.update(dt, [&on_ground(0.0)])[0];
            assert!(p.scale.x <= previous + 1e-6, "eased back: {p:?}");
            previous = p.scale.x;
        }
        let after = a.update(dt, [&on_ground(0.0)])[0];
        assert_eq!(after.action, Action::Idle);
        assert!(close(after.scale.x, 1.0, 1e-3), "{after:?}");
        assert_eq!(after.landing, 0.0);
    }

    #[test]
    fn the_squash_grows_with_the_impact_speed() {
        let (_, soft) = land_after_falling(200.0, 1.0 / 60.0);
        let (_, hard) = land_after_falling(340.0, 1.0 / 60.0);
        assert_eq!(soft.action, Action::Land);
        assert!(soft.scale.x > 1.0, "{soft:?}");
        assert!(hard.scale.x > soft.scale.x + 0.05, "{soft:?} {hard:?}");
    }

    #[test]
    fn a_tiny_step_down_does_not_squash() {
        // Stepping off a few pixels lands at about 100 px/s.
        let (_, pose) = land_after_falling(100.0, 1.0 / 60.0);
        assert_eq!(pose.action, Action::Idle);
        assert!(close(pose.scale.x, 1.0, 0.02), "{pose:?}");
        assert_eq!(pose.landing, 0.0);
    }

    #[test]
    fn a_respawn_does_not_land() {
        let mut a = Animator::new();
        hold(&mut a, &in_air(360.0), 1.0 / 60.0, 10);
        // Far away on the ground the next frame: teleported.
        let mut p = on_ground(0.0);
        p.pos.x += 500.0;
        let pose = a.update(1.0 / 60.0, [&p])[0];
        assert_eq!(pose.action, Action::Idle);
        assert_eq!(pose.scale, Vec2::ONE);
    }

    #[test]
    fn dead_players_are_dead_and_come_back_unsquashed() {
        let mut a = Animator::new();
        hold(&mut a, &in_air(360.0), 1.0 / 60.0, 10);
        let mut dead = in_air(360.0);
        dead.dead = true;
        let pose = hold(&mut a, &dead, 1.0 / 60.0, 3);
        assert_eq!(pose.action, Action::Dead);
        assert_eq!(pose.scale, Vec2::ONE);
        // Alive again on the ground (near where it died): no landing.
        let pose = a.update(1.0 / 60.0, [&on_ground(0.0)])[0];
        assert_eq!(pose.action, Action::Idle);
        assert_eq!(pose.scale, Vec2::ONE);
    }

    #[test]
    fn against_a_wall_in_the_air_slides_facing_away() {
        let mut a = Animator::new();
        let mut p = in_air(120.0);
        p.wall = Some(Facing::Right);
        let pose = hold(&mut a, &p, 1.0 / 60.0, 5);
        assert_eq!(pose.action, Action::WallSlide);
        assert_eq!(pose.facing, Facing::Left);
        p.wall = Some(Facing::Left);
        p.facing = Facing::Left;
        let pose = hold(&mut a, &p, 1.0 / 60.0, 1);
        assert_eq!(pose.action, Action::WallSlide);
        assert_eq!(pose.facing, Facing::Right);
        // Rising along the wall is a jump; on the ground, no slide.
        p.vel.y = -200.0;
        assert_eq!(hold(&mut a, &p, 1.0 / 60.0, 1).action, Action::Jump);
        let mut g = on_ground(0.0);
        g.wall = Some(Facing::Left);
        assert_eq!(hold(&mut a, &g, 1.0 / 60.0, 1).action, Action::Idle);
    }

    #[test]
    fn scale_is_bounded_and_roughly_area_preserving() {
        let mut a = Animator::new();
        let dt = 1.0 / 60.0;
        let mut check = |p: &PlayerDraw| {
            let pose = a.update(dt, [p])[0];
            let s = pose.scale;
            assert!(s.min_element() >= 0.6 && s.max_element() <= 1.4, "{pose:?}");
            assert!(close(s.x * s.y, 1.0, 0.05), "area {}: {pose:?}", s.x * s.y);
        };
        for vy in [-2000.0, -300.0, -50.0, 0.0, 100.0, 360.0, 5000.0] {
            for _ in 0..20 {
                check(&in_air(vy));
            }
            for _ in 0..3 {
                check(&on_ground(150.0));
            }
        }
    }

    #[test]
    fn faster_runs_cycle_faster() {
        let phase_after = |vx: f32| {
            let mut a = Animator::new();
            hold(&mut a, &on_ground(vx), 1.0 / 60.0, 6).phase
        };
        let (slow, fast) = (phase_after(60.0), phase_after(150.0));
        assert!(slow > 0.0 && fast > slow * 2.0, "{slow} {fast}");
        // In [0, 1) however long it runs.
        let mut a = Animator::new();
        for _ in 0..600 {
            let pose = a.update(1.0 / 60.0, [&on_ground(150.0)])[0];
            assert!((0.0..1.0).contains(&pose.phase), "{pose:?}");
        }
    }

    #[test]
    fn the_frame_rate_does_not_change_the_look() {
        // Rise, fall (up to the fall speed limit), land at t = 0.5 s, run
        // from t = 0.6 s; sampled at 30, 60 and 120 frames per second,
        // compared at the same times.
        let state = |t: f32| {
            if t < 0.4999 {
                in_air((-300.0 + 1500.0 * t).min(LAND_FULL_SPEED))
            } else if t < 0.5999 {
                on_ground(0.0)
            } else {
                on_ground(150.0)
            }
        };
        let run = |fps: u32| {
            let dt = 1.0 / fps as f32;
            let mut a = Animator::new();
            let mut at = BTreeMap::new();
            for frame in 0..=fps {
                let t = frame as f32 * dt;
                let pose = a.update(dt, [&state(t)])[0];
                // Every 1/30 s: 0, 1/30, 2/30, ...
                if frame % (fps / 30) == 0 {
                    at.insert(frame / (fps / 30), pose);
                }
            }
            at
        };
        let (slow, mid, fast) = (run(30), run(60), run(120));
        let mut landed = false;
        for (k, s) in &slow {
            landed |= s.action == Action::Land;
            for other in [&mid[k], &fast[k]] {
                assert_eq!(s.action, other.action, "at {k}/30 s");
                assert!(
                    (s.scale - other.scale).abs().max_element() < 0.02,
                    "at {k}/30 s: {s:?} vs {other:?}"
                );
                assert!(close(s.lean, other.lean, 0.005), "{s:?} vs {other:?}");
                assert!(close(s.phase, other.phase, 0.005), "{s:?} vs {other:?}");
                assert!(close(s.landing, other.landing, 0.005), "{s:?} vs {other:?}");
            }
        }
        assert!(landed, "the landing was seen");
        assert!(slow[&30].phase > 0.5, "ran: {:?}", slow[&30]);
    }

    #[test]
    fn players_not_seen_are_forgotten() {
        let mut a = Animator::new();
        let (p1, p2) = (on_ground(0.0), player(2, Vec2::ZERO, Vec2::ZERO, true));
        a.update(0.016, [&p1, &p2]);
        assert_eq!(a.len(), 2);
        // One frame missing is tolerated.
        a.update(0.016, [&p1]);
        assert_eq!(a.len(), 2);
        a.update(0.016, [&p1]);
        assert_eq!(a.len(), 1);
        a.update(0.016, []);
        a.update(0.016, []);
        assert!(a.is_empty());
        // Poses come back in the order given.
        let mut left = on_ground(0.0);
        left.facing = Facing::Left;
        let poses = a.update(0.016, [&p2, &left]);
        assert_eq!(poses.len(), 2);
        assert_eq!(poses[1].facing, Facing::Left);
    }

    #[test]
    fn a_stack_of_eight_fans_out() {
        let at = Vec2::new(300.0, 100.0);
        // On one pixel (but not quite the same point), given in no order.
        let players: Vec<(PlayerId, Vec2)> = [5, 1, 8, 3, 2, 7, 4, 6]
            .map(|i| (PlayerId(i), at + Vec2::new(i as f32 * 0.05, 0.0)))
            .to_vec();
        let drawn = spread(&players, None);
        for (i, a) in drawn.iter().enumerate() {
            assert_eq!(a.y, players[i].1.y, "sideways only");
            for b in &drawn[i + 1..] {
                assert!((a.x - b.x).abs() >= SPREAD_GAP - 0.01, "{a:?} {b:?}");
            }
        }
        // Centred where they were, in id order left to right.
        let mean = |v: &[Vec2]| v.iter().map(|p| p.x).sum::<f32>() / v.len() as f32;
        let given: Vec<Vec2> = players.iter().map(|p| p.1).collect();
        assert!(close(mean(&drawn), mean(&given), 0.01));
        let mut by_id: Vec<(PlayerId, f32)> = players
            .iter()
            .zip(&drawn)
            .map(|(p, d)| (p.0, d.x))
            .collect();
        by_id.sort_by_key(|p| p.0);
        assert!(by_id.windows(2).all(|w| w[0].1 < w[1].1), "{by_id:?}");
        // Deterministic whatever the order given.
        let mut reversed = players.clone();
        reversed.reverse();
        let mut again = spread(&reversed, None);
        again.reverse();
        assert_eq!(drawn, again);
    }

    #[test]
    fn ours_stays_and_the_others_go_around_it() {
        let at = Vec2::new(50.0, 80.0);
        let players: Vec<(PlayerId, Vec2)> = [5, 2, 9, 3].map(|i| (PlayerId(i), at)).to_vec();
        let drawn = spread(&players, Some(PlayerId(9)));
        assert_eq!(drawn[2], at, "ours never moves");
        // Id order on one pixel: 2, 3, 5, ours (9) last: all to its left.
        assert_eq!(drawn[1].x, at.x - 3.0 * SPREAD_GAP);
        assert_eq!(drawn[3].x, at.x - 2.0 * SPREAD_GAP);
        assert_eq!(drawn[0].x, at.x - SPREAD_GAP);
        // Standing a little to one side of ours: fanned out on that side.
        let players = [
            (PlayerId(1), at + Vec2::new(2.0, 0.0)),
            (PlayerId(9), at),
            (PlayerId(4), at + Vec2::new(-3.0, 1.0)),
        ];
        let drawn = spread(&players, Some(PlayerId(9)));
        assert_eq!(drawn[1], at);
        assert_eq!(drawn[0], Vec2::new(at.x + SPREAD_GAP, at.y));
        assert_eq!(drawn[2], Vec2::new(at.x - SPREAD_GAP, at.y + 1.0));
    }

    #[test]
    fn players_apart_are_not_moved() {
        let players = [
            (PlayerId(1), Vec2::new(0.0, 0.0)),
            (PlayerId(2), Vec2::new(STACK_RADIUS + 1.0, 0.0)),
            (PlayerId(3), Vec2::new(0.0, 20.0)),
            (PlayerId(4), Vec2::new(100.0, 0.0)),
        ];
        let drawn = spread(&players, Some(PlayerId(4)));
        for (d, (_, p)) in drawn.iter().zip(&players) {
            assert_eq!(d, p);
        }
        assert!(spread(&[], None).is_empty());
    }

    /// Whether two placed labels overlap.
    fn overprint(a: &Label, ra: u32, b: &Label, rb: u32, h: f32) -> bool {
        let (ya, yb) = (a.bottom - ra as f32 * h, b.bottom - rb as f32 * h);
        (a.x - b.x).abs() < (a.width + b.width) / 2.0 && (ya - yb).abs() < h
    }

    #[test]
    fn labels_of_a_stack_do_not_overprint() {
        // Eight players on one spot, fanned out, each with a 50 px label
        // (2 screen px per world px): each label in a row of its own.
        let players: Vec<(PlayerId, Vec2)> = (1..=8)
            .map(|i| (PlayerId(i), Vec2::new(300.0, 100.0)))
            .collect();
        let drawn = spread(&players, Some(PlayerId(3)));
        let labels: Vec<Label> = drawn
            .iter()
            .map(|p| Label {
                x: p.x * 2.0,
                bottom: (p.y - 8.0) * 2.0 - 8.0,
                width: 50.0,
            })
            .collect();
        // Ours first.
        let mut order: Vec<usize> = (0..8).collect();
        order.sort_by_key(|&i| (players[i].0 != PlayerId(3), players[i].0));
        let ordered: Vec<Label> = order.iter().map(|&i| labels[i]).collect();
        let h = 20.0;
        let rows = label_rows(&ordered, h);
        assert_eq!(rows[0], 0, "ours keeps its place");
        for i in 0..8 {
            for j in i + 1..8 {
                assert!(!overprint(&ordered[i], rows[i], &ordered[j], rows[j], h));
            }
        }
        // Stepped up, but labels far enough apart share a row.
        let top = *rows.iter().max().unwrap();
        assert!((2..8).contains(&top), "{rows:?}");
    }

    #[test]
    fn labels_apart_stay_low_and_crowds_are_bounded() {
        let h = 20.0;
        let far: Vec<Label> = (0..5)
            .map(|i| Label {
                x: i as f32 * 100.0,
                bottom: 50.0,
                width: 60.0,
            })
            .collect();
        assert_eq!(label_rows(&far, h), [0; 5]);
        // One above the other already (a player on another's head): no
        // need to move either.
        let stacked = [
            Label {
                x: 0.0,
                bottom: 100.0,
                width: 60.0,
            },
            Label {
                x: 10.0,
                bottom: 100.0 - h,
                width: 60.0,
            },
        ];
        assert_eq!(label_rows(&stacked, h), [0, 0]);
        // A crowd never climbs past the limit.
        let crowd = vec![
            Label {
                x: 0.0,
                bottom: 0.0,
                width: 60.0,
            };
            40
        ];
        let rows = label_rows(&crowd, h);
        assert!(rows.iter().all(|&r| r < MAX_LABEL_ROWS));
        assert_eq!(
            rows[..MAX_LABEL_ROWS as usize],
            (0..MAX_LABEL_ROWS).collect::<Vec<_>>()
        );
    }
}
