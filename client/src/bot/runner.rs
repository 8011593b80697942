//! The runner: follows a level's bot route ([`Waypoint`]s) to the goal.
//!
//! Between waypoints it walks toward the next one's x. Where the route says
//! `Jump` or `Spring` (or when a wall blocks it), it plans with the
//! predicted game itself: it clones the [`Game`], tries a few dozen short
//! button sequences (jump held for 0 to 30 ticks, the direction held, or
//! released or reversed after a while) and keeps the one that lands on the
//! waypoint's floor soonest without getting hurt. The plan is then played
//! tick by tick; since the predicted game is the server's game when the
//! prediction is right, the plan lands exactly as simulated. When no plan
//! reaches the waypoint from here, it walks on and tries again a few ticks
//! later.

use std::collections::VecDeque;

use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::game::{Game, GameEvent, PlayerView};
use ledge_shared::input::Buttons;
use ledge_shared::level::{RouteAction, Waypoint};
use ledge_shared::protocol::PlayerId;
use ledge_shared::world::Sides;

use super::brain::Brain;

/// Within this many pixels of a waypoint (x and y, standing) it is reached.
const REACH_PX: i32 = 6;
/// A planned landing counts within this many pixels of the waypoint's x.
const LAND_TOLERANCE_PX: i32 = 24;
/// A planned landing must be within this many pixels of the waypoint's y.
const LAND_HEIGHT_PX: i32 = 4;
/// Longest plan simulated, ticks.
const HORIZON: u32 = 120;
/// Ticks between two searches that found nothing.
const SEARCH_EVERY: u32 = 3;
/// Jump hold lengths tried, ticks (0: no jump).
const HOLDS: [u32; 9] = [0, 3, 6, 9, 12, 16, 20, 25, 30];

/// How the direction is held during a planned jump.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Steer {
    /// Toward the waypoint all the way.
    Hold,
    /// Toward the waypoint, then nothing after this many ticks.
    Release(u32),
    /// Toward the waypoint, then away after this many ticks.
    Reverse(u32),
}

const STEERS: [Steer; 6] = [
    Steer::Hold,
    Steer::Release(6),
    Steer::Release(12),
    Steer::Release(20),
    Steer::Reverse(10),
    Steer::Reverse(18),
];

/// Progress report of a [`Runner`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RunnerProgress {
    /// Index of the waypoint it is heading for (`route.len()`: the goal).
    pub waypoint: usize,
    /// Plans searched.
    pub searches: u64,
    /// Plans adopted.
    pub plans: u64,
    /// Times it was hurt or respawned.
    pub respawns: u64,
    /// It reached the goal (the game says it won).
    pub won: bool,
}

/// Follows a route to the goal.
#[derive(Debug, Clone)]
pub struct Runner {
    route: Vec<Waypoint>,
    next: usize,
    plan: VecDeque<Buttons>,
    cooldown: u32,
    blocked: u32,
    progress: RunnerProgress,
}

impl Runner {
    /// A runner for `route` (e.g. [`ledge_shared::level::default_route`]).
    pub fn new(route: Vec<Waypoint>) -> Runner {
        Runner {
            route,
            next: 0,
            plan: VecDeque::new(),
            cooldown: 0,
            blocked: 0,
            progress: RunnerProgress::default(),
        }
    }

    /// How far it got.
    pub fn progress(&self) -> RunnerProgress {
        RunnerProgress {
            waypoint: self.next,
            ..self.progress
        }
    }

    /// The waypoint it is heading for, if any is left.
    pub fn target(&self) -> Option<&Waypoint> {
        self.route.get(self.next)
    }

    fn reached(&self, i: usize, p: &PlayerView) -> bool {
        let w = &self.route[i];
        let foot = foot(p);
        let dy = (foot.1 - w.foot.y).abs();
        if !p.grounded || dy > REACH_PX * UNITS_PER_PX {
            return false;
        }
        let dx = w.foot.x - foot.0;
        if dx.abs() <= REACH_PX * UNITS_PER_PX {
            return true;
        }
        // Passed it (standing at its height beyond it, seen from the
        // previous waypoint).
        let from = if i == 0 {
            foot.0
        } else {
            self.route[i - 1].foot.x
        };
        let travel = (w.foot.x - from).signum();
        travel != 0 && dx.signum() == -travel
    }

    /// After a respawn: the first waypoint not behind the player.
    fn resume_from(&mut self, p: &PlayerView) {
        let x = foot(p).0 - REACH_PX * UNITS_PER_PX;
        self.next = self
            .route
            .iter()
            .position(|w| w.foot.x >= x)
            .unwrap_or(self.route.len());
        self.plan.clear();
        self.cooldown = 0;
    }

    /// Simulates the candidate plans from `game`; returns the best one that
    /// lands on waypoint `i`'s floor.
    fn search(&mut self, game: &Game, me: PlayerId, i: usize) -> Option<VecDeque<Buttons>> {
        self.progress.searches += 1;
        let target = self.route[i].foot;
        let p = game.player(me)?;
        let dir = dir_bits(target.x - foot(&p).0);
        let away = dir_bits(foot(&p).0 - target.x);
        let mut best: Option<(i64, VecDeque<Buttons>)> = None;
        for &hold in &HOLDS {
            for &steer in &STEERS {
                if hold == 0 && steer != Steer::Hold {
                    continue;
                }
                let press = |t: u32| {
                    let d = match steer {
                        Steer::Hold => dir,
                        Steer::Release(m) if t >= m => 0,
                        Steer::Reverse(m) if t >= m => away,
                        _ => dir,
                    };
                    let j = if t < hold { Buttons::JUMP } else { 0 };
                    Buttons(d | j)
                };
                if let Some((ticks, score)) = simulate(game, me, target, hold == 0, press) {
                    if best.as_ref().is_none_or(|(s, _)| score < *s) {
                        best = Some((score, (0..ticks).map(press).collect()));
                    }
                }
            }
        }
        best.map(|(_, plan)| plan)
    }
}

/// The bottom-centre of a player's box, units.
fn foot(p: &PlayerView) -> (i32, i32) {
    (p.pos.x, p.pos.y + p.half.y)
}

fn dir_bits(dx: i32) -> u8 {
    match dx.signum() {
        1 => Buttons::RIGHT,
        -1 => Buttons::LEFT,
        _ => 0,
    }
}

/// Plays `press` on a copy of `game`; `Some((ticks, score))` when the
/// player stands on `target`'s floor near it after `ticks` ticks without
/// being hurt (score: ticks plus the distance to the target in ticks of
/// running), `None` when it lands elsewhere, is hurt or runs out of time.
fn simulate(
    game: &Game,
    me: PlayerId,
    target: glam::IVec2,
    walking: bool,
    press: impl Fn(u32) -> Buttons,
) -> Option<(u32, i64)> {
    let mut g = game.clone();
    let mut airborne = false;
    for t in 0..HORIZON {
        let events = g.step(&[(me, press(t))]);
        let hurt = events.iter().any(|e| {
            matches!(e,
                GameEvent::Hurt { player, .. } | GameEvent::Respawned { player, .. }
                    if *player == me)
                || matches!(e, GameEvent::Squished(p) if *p == me)
        });
        if hurt {
            return None;
        }
        let p = g.player(me)?;
        if !p.grounded {
            airborne = true;
            continue;
        }
        let (fx, fy) = foot(&p);
        let at_height = (fy - target.y).abs() <= LAND_HEIGHT_PX * UNITS_PER_PX;
        let dx = (fx - target.x).abs();
        if at_height && dx <= LAND_TOLERANCE_PX * UNITS_PER_PX && (airborne || walking) {
            let run = i64::from(dx) / 640;
            return Some((t + 1, i64::from(t + 1) + run));
        }
        if airborne {
            // Landed somewhere else.
            return None;
        }
    }
    None
}

impl Brain for Runner {
    fn name(&self) -> &'static str {
        "runner"
    }

    fn done(&self) -> bool {
        self.progress.won
    }

    fn on_correction(&mut self) {
        self.plan.clear();
        self.cooldown = 0;
    }

    fn progress(&self) -> String {
        let p = self.progress();
        format!(
            "waypoint {}/{}, {} plans, {} respawns",
            p.waypoint,
            self.route.len(),
            p.plans,
            p.respawns
        )
    }

    fn buttons(&mut self, game: &Game, me: PlayerId) -> Buttons {
        let Some(p) = game.player(me) else {
            return Buttons::NONE;
        };
        if p.won {
            self.progress.won = true;
            return Buttons::NONE;
        }
        let respawned = game
            .events()
            .iter()
            .any(|e| matches!(e, GameEvent::Respawned { player, .. } if *player == me));
        if respawned {
            self.progress.respawns += 1;
            self.resume_from(&p);
        }
        if let Some(b) = self.plan.pop_front() {
            return b;
        }
        while self.next < self.route.len() && self.reached(self.next, &p) {
            self.next += 1;
            self.cooldown = 0;
        }
        // The goal is the last waypoint: past it, keep walking to the goal.
        let i = self.next.min(self.route.len().saturating_sub(1));
        let Some(w) = self.route.get(i).copied() else {
            return Buttons::NONE;
        };
        let dx = w.foot.x - foot(&p).0;
        let dir = dir_bits(dx);
        let wall = if dir == Buttons::RIGHT {
            Sides::RIGHT
        } else {
            Sides::LEFT
        };
        if p.grounded && dir != 0 && p.sides.contains(wall) && p.vel.x == 0 {
            self.blocked += 1;
        } else {
            self.blocked = 0;
        }
        let wants_plan = match w.action {
            RouteAction::Jump | RouteAction::Spring => true,
            RouteAction::Walk => self.blocked > 2,
        };
        if wants_plan && p.grounded && self.next < self.route.len() {
            if self.cooldown == 0 {
                if let Some(plan) = self.search(game, me, i) {
                    self.progress.plans += 1;
                    self.plan = plan;
                    if let Some(b) = self.plan.pop_front() {
                        return b;
                    }
                }
                self.cooldown = SEARCH_EVERY;
            } else {
                self.cooldown -= 1;
            }
        }
        if self.blocked > 8 && p.grounded {
            // Nothing found: jump anyway.
            self.blocked = 0;
            self.plan = (0..20).map(|_| Buttons(dir | Buttons::JUMP)).collect();
            return Buttons(dir | Buttons::JUMP);
        }
        if dx.abs() <= REACH_PX * UNITS_PER_PX / 2 {
            return Buttons::NONE;
        }
        Buttons(dir)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ledge_shared::level::{default_level, default_route};

    #[test]
    fn a_runner_reaches_the_goal_of_the_default_level_offline() {
        let level = default_level();
        let mut game = Game::from_level(&level).unwrap();
        let me = PlayerId(1);
        game.add_player(me).unwrap();
        let mut runner = Runner::new(default_route());
        let start = std::time::Instant::now();
        let mut won_at = None;
        for _ in 0..60 * 60 {
            let b = runner.buttons(&game, me);
            let events = game.step(&[(me, b)]).to_vec();
            if events.contains(&GameEvent::Won(me)) {
                won_at = Some(game.tick());
                break;
            }
        }
        let p = game.player(me).unwrap();
        eprintln!(
            "won at {won_at:?}, {:?}, at ({}, {}) px, {:?}",
            runner.progress(),
            p.pos.x / 256,
            p.pos.y / 256,
            start.elapsed()
        );
        assert!(
            won_at.is_some(),
            "stuck before waypoint {:?}",
            runner.target()
        );
    }
}
