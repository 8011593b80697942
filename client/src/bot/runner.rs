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
//!
//! Plans never count on stomping a walker: the walker may be gone on the
//! server (another player stomped it a few ticks ago, which the prediction
//! learns from the next snapshot only), and a plan that bounces off it then
//! drops the runner somewhere else.
//!
//! Plans are simulated on a copy of the game holding our player only, so a
//! search costs the same in a crowded room as alone: players never touch
//! each other, and the others' buttons are unknown anyway. (Simulating the
//! whole room made a search up to 13 times dearer with 12 idle players
//! beside us; the stall delayed our inputs past the server's tick, the
//! server repeated the previous buttons, and the prediction was corrected:
//! see `docs/ARCHITECTURE.md`, "Prediction in a crowd".) A candidate is
//! also dropped as soon as it can no longer beat the best plan found, which
//! never changes the plan chosen.
//!
//! Like a player, the runner notices when it is off its route and
//! recovers: standing lower than both ends of the route segment it is on
//! (it fell, e.g. into the walker trench) or not getting closer to its
//! waypoint for [`STALL_TICKS`] (jumping at a wall), it heads
//! back to the latest earlier waypoint it can climb to (a floor at most
//! [`CLIMB_PX`] above its feet), walks all the way there for a running
//! start, and takes the route again from there. A stall while recovering
//! steps one more waypoint back; after [`MAX_RETRIES`] recoveries in a row
//! on the way to the same waypoint it gives that waypoint up. Everything it
//! decides is a pure function of the games it is shown, so it is
//! deterministic.

use std::collections::VecDeque;

use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::game::{Game, GameEvent, PlayerView};
use ledge_shared::input::Buttons;
use ledge_shared::level::{Level, RouteAction, Waypoint};
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
/// Standing more than this many pixels lower than both ends of its route
/// segment, the runner is off its route.
const BELOW_ROUTE_PX: i32 = 8;
/// Ticks without getting at least a pixel closer to its waypoint before the
/// runner counts as stuck (2.5 s).
pub const STALL_TICKS: u32 = 150;
/// Highest floor above its feet a recovering runner heads back to, pixels:
/// what every jump of the route asks (2 tiles), well below a full jump.
pub const CLIMB_PX: i32 = 32;
/// Recoveries in a row on the way to one waypoint before the runner gives
/// it up and heads for the next one.
pub const MAX_RETRIES: u32 = 2;
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
    /// Times it noticed it was off its route or stuck, and headed back.
    pub recoveries: u64,
    /// Player-ticks simulated while planning (each simulated tick counts
    /// the players in the simulated game): the planning cost, which does
    /// not grow with the players in the room.
    pub simulated: u64,
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
    /// Heading back to an earlier waypoint after leaving the route: it must
    /// be reached exactly (a running start), not just passed.
    recovering: bool,
    /// The waypoint `closest` and `stall` are about.
    watched: usize,
    /// Closest distance (|dx| + |dy|, units) to waypoint `watched` so far.
    closest: i32,
    /// Ticks since `closest` last shrank by a pixel or more.
    stall: u32,
    /// The waypoint it was heading for when it last left its route.
    origin: usize,
    /// Recoveries in a row on the way to waypoint `origin`.
    retries: u32,
    /// A new level began: take the route from where the player stands,
    /// at its first sight.
    restart: bool,
    progress: RunnerProgress,
}

impl Runner {
    /// A runner for `route` (e.g. [`ledge_levels::default_route`]).
    pub fn new(route: Vec<Waypoint>) -> Runner {
        Runner {
            route,
            next: 0,
            plan: VecDeque::new(),
            cooldown: 0,
            blocked: 0,
            recovering: false,
            watched: usize::MAX,
            closest: i32::MAX,
            stall: 0,
            origin: usize::MAX,
            retries: 0,
            restart: false,
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

    /// Whether the runner is recovering: heading back to an earlier
    /// waypoint after it left its route or got stuck.
    pub fn recovering(&self) -> bool {
        self.recovering
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
        if self.recovering {
            // Recovering: all the way there, for a running start.
            return false;
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
        self.recovering = false;
    }

    /// Counts the ticks since the runner last got closer to waypoint `i`.
    fn watch(&mut self, i: usize, p: &PlayerView) {
        let (fx, fy) = foot(p);
        let w = self.route[i].foot;
        let d = (w.x - fx).abs().saturating_add((w.y - fy).abs());
        if i != self.watched {
            self.watched = i;
            self.closest = d;
            self.stall = 0;
        } else if d <= self.closest.saturating_sub(UNITS_PER_PX) {
            self.closest = d;
            self.stall = 0;
        } else {
            self.stall = self.stall.saturating_add(1);
        }
    }

    /// Standing lower than both ends of the route segment to waypoint `i`
    /// (it fell off the route).
    fn below_route(&self, i: usize, p: &PlayerView) -> bool {
        let low = match i.checked_sub(1) {
            Some(h) => self.route[h].foot.y.max(self.route[i].foot.y),
            None => self.route[i].foot.y,
        };
        p.grounded && foot(p).1 > low + BELOW_ROUTE_PX * UNITS_PER_PX
    }

    /// Off the route or stuck: heads back to the latest waypoint before the
    /// current one whose floor is at most [`CLIMB_PX`] above the feet (the
    /// one just before when none is), to take the route again from there.
    /// After [`MAX_RETRIES`] recoveries in a row on the way to the same
    /// waypoint, it gives that one up and heads for the next.
    fn recover(&mut self, p: &PlayerView) {
        let origin = if self.recovering {
            self.origin
        } else {
            self.next
        };
        if origin == self.origin {
            self.retries += 1;
        } else {
            self.origin = origin;
            self.retries = 1;
        }
        self.progress.recoveries += 1;
        self.plan.clear();
        self.cooldown = 0;
        self.blocked = 0;
        self.stall = 0;
        if self.retries > MAX_RETRIES && origin + 1 < self.route.len() {
            self.next = origin + 1;
            self.recovering = false;
            self.retries = 0;
            return;
        }
        let Some(before) = self.next.checked_sub(1) else {
            // Stuck on the way to the first waypoint: try again.
            return;
        };
        let top = foot(p).1 - CLIMB_PX * UNITS_PER_PX;
        self.next = (0..=before)
            .rev()
            .find(|&j| self.route[j].foot.y >= top)
            .unwrap_or(before);
        self.recovering = true;
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
        let solo = alone(game, me);
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
                let bound = best.as_ref().map(|(s, _)| *s);
                let sim = Candidate {
                    me,
                    target,
                    walking: hold == 0,
                    bound,
                };
                let found = sim.simulate(&solo, press, &mut self.progress.simulated);
                if let Some((ticks, score)) = found {
                    if bound.is_none_or(|s| score < s) {
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

/// A copy of `game` with our player `me` only (the others removed): what
/// plans are simulated on.
fn alone(game: &Game, me: PlayerId) -> Game {
    let mut solo = game.clone();
    let others: Vec<PlayerId> = solo
        .players()
        .map(|(id, _)| id)
        .filter(|&id| id != me)
        .collect();
    for id in others {
        solo.remove_player(id);
    }
    solo
}

/// One candidate plan to simulate.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    /// Our player.
    me: PlayerId,
    /// The waypoint's foot position to land on.
    target: glam::IVec2,
    /// A walking plan (no jump): it may reach the target without leaving
    /// the ground.
    walking: bool,
    /// The best score so far: a plan scoring this or more is not wanted.
    bound: Option<i64>,
}

impl Candidate {
    /// Plays `press` on a copy of `game`; `Some((ticks, score))` when the
    /// player stands on the target's floor near it after `ticks` ticks
    /// without being hurt (score: ticks plus the distance to the target in
    /// ticks of running), `None` when it lands elsewhere, is hurt, runs out
    /// of time or can no longer score below the bound (a landing at tick
    /// `t` scores at least `t`). Adds the player-ticks simulated to
    /// `simulated`.
    fn simulate(
        &self,
        game: &Game,
        press: impl Fn(u32) -> Buttons,
        simulated: &mut u64,
    ) -> Option<(u32, i64)> {
        let (me, target) = (self.me, self.target);
        let mut g = game.clone();
        let players = g.players().count() as u64;
        let mut airborne = false;
        for t in 0..HORIZON {
            if self.bound.is_some_and(|b| i64::from(t + 1) >= b) {
                return None;
            }
            *simulated += players;
            let events = g.step(&[(me, press(t))]);
            let hurt = events.iter().any(|e| {
                matches!(e,
                    GameEvent::Died { player, .. } | GameEvent::Respawned { player, .. }
                        if *player == me)
            });
            // A plan must not count on a walker: it may be gone on the server.
            let stomped = events
                .iter()
                .any(|e| matches!(e, GameEvent::Stomped { player, .. } if *player == me));
            if hurt || stomped {
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
            if at_height && dx <= LAND_TOLERANCE_PX * UNITS_PER_PX && (airborne || self.walking) {
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

    /// The route starts over (the same route: a level bundle carries none,
    /// so the rotation's levels share the runner's), from the player's
    /// spawn; the counters go on.
    fn on_level(&mut self, _level: &Level) {
        self.next = 0;
        self.plan.clear();
        self.cooldown = 0;
        self.blocked = 0;
        self.recovering = false;
        self.watched = usize::MAX;
        self.closest = i32::MAX;
        self.stall = 0;
        self.origin = usize::MAX;
        self.retries = 0;
        self.restart = true;
        self.progress.won = false;
    }

    fn progress(&self) -> String {
        let p = self.progress();
        format!(
            "waypoint {}/{}, {} plans, {} respawns, {} recoveries",
            p.waypoint,
            self.route.len(),
            p.plans,
            p.respawns,
            p.recoveries
        )
    }

    fn buttons(&mut self, game: &Game, me: PlayerId) -> Buttons {
        let Some(p) = game.player(me) else {
            return Buttons::NONE;
        };
        if std::mem::take(&mut self.restart) {
            self.resume_from(&p);
        }
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
        if self.next < self.route.len() {
            self.watch(self.next, &p);
        }
        while self.next < self.route.len() && self.reached(self.next, &p) {
            self.next += 1;
            self.cooldown = 0;
            self.recovering = false;
        }
        if self.next < self.route.len() {
            let fell = !self.recovering && self.below_route(self.next, &p);
            if fell || (self.stall >= STALL_TICKS && p.grounded) {
                self.recover(&p);
            }
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
    use ledge_levels::{default_level, default_route};
    use ledge_shared::level::{EntityKind, Level};

    const PX: i32 = UNITS_PER_PX;

    /// Whether `events` hold our player finishing its run.
    fn finished(events: &[GameEvent], me: PlayerId) -> bool {
        events
            .iter()
            .any(|e| matches!(e, GameEvent::Finished { player, .. } if *player == me))
    }
    /// The walker trench of the default level: x from col 36 to col 44,
    /// floor at the top of row 27, route height (ground) at row 26.
    const TRENCH: (i32, i32) = (36 * 16 * PX, 44 * 16 * PX);
    const TRENCH_FLOOR: i32 = 27 * 16 * PX;

    /// Plays `runner` alone on `game` for at most `ticks`; the tick it won.
    fn play(game: &mut Game, me: PlayerId, runner: &mut Runner, ticks: u32) -> Option<u64> {
        for _ in 0..ticks {
            let b = runner.buttons(game, me);
            if finished(game.step(&[(me, b)]), me) {
                return Some(game.tick());
            }
        }
        None
    }

    /// The default level without the walker in the trench (as when another
    /// player stomped it).
    fn level_without_trench_walker() -> Level {
        let mut level = default_level();
        let before = level.entities.len();
        level.entities.retain(|e| {
            !(matches!(e.kind, EntityKind::Walker { .. })
                && (TRENCH.0..TRENCH.1).contains(&e.pos.x))
        });
        assert_eq!(level.entities.len(), before - 1, "one walker in the trench");
        level
    }

    #[test]
    fn a_runner_reaches_the_goal_of_the_default_level_offline() {
        let level = default_level();
        let mut game = Game::from_level(&level).unwrap();
        let me = PlayerId(1);
        game.add_player(me).unwrap();
        let mut runner = Runner::new(default_route());
        let won_at = play(&mut game, me, &mut runner, 60 * 60);
        let p = game.player(me).unwrap();
        eprintln!(
            "won at {won_at:?}, {:?}, at ({}, {}) px",
            runner.progress(),
            p.pos.x / PX,
            p.pos.y / PX,
        );
        assert!(
            won_at.is_some(),
            "stuck before waypoint {:?}",
            runner.target()
        );
        assert_eq!(runner.progress().recoveries, 0, "it never left its route");
    }

    /// A runner that finished one level runs the next from its spawn
    /// (here the same level again, a fresh game from a later tick, as a
    /// room moving on starts it).
    #[test]
    fn a_runner_runs_the_next_level_after_finishing_one() {
        let level = default_level();
        let me = PlayerId(1);
        let mut game = Game::from_level(&level).unwrap();
        game.add_player(me).unwrap();
        let mut runner = Runner::new(default_route());
        let first = play(&mut game, me, &mut runner, 60 * 60).expect("the first level");
        // Standing at the goal a while: done.
        for _ in 0..30 {
            let b = runner.buttons(&game, me);
            game.step(&[(me, b)]);
        }
        assert!(runner.done());
        let searched = runner.progress().searches;

        let mut next = Game::from_level(&level).unwrap();
        assert!(next.start_at(first + 600));
        next.add_player(me).unwrap();
        runner.on_level(&level);
        assert!(!runner.done(), "a new run to make");
        assert_eq!(runner.progress().waypoint, 0);
        let second = play(&mut next, me, &mut runner, 60 * 60);
        assert!(
            second.is_some(),
            "stuck before waypoint {:?}",
            runner.target()
        );
        assert!(runner.progress().searches > searched, "the counters go on");
    }

    #[test]
    fn a_runner_in_the_walker_trench_climbs_out_and_reaches_the_goal() {
        let route = default_route();
        // The waypoint on the plateau beyond the trench, and the one on the
        // ground before the trench.
        let plateau = route
            .iter()
            .position(|w| w.foot.x > TRENCH.1 && w.foot.y < TRENCH_FLOOR - 64 * PX)
            .expect("a waypoint on the plateau");
        let low_side = route
            .iter()
            .rposition(|w| w.foot.x < TRENCH.0)
            .expect("a waypoint before the trench");
        let mut game = Game::from_level(&level_without_trench_walker()).unwrap();
        let me = PlayerId(1);
        game.add_player(me).unwrap();
        // Up to the low side of the trench, then right into it and against
        // its high wall: where runners got stuck, jumping at the wall.
        let mut runner = Runner::new(route.clone());
        let mut ticks = 0;
        while runner.progress().waypoint <= low_side {
            let b = runner.buttons(&game, me);
            game.step(&[(me, b)]);
            ticks += 1;
            assert!(
                ticks < 60 * 60,
                "reaches the trench: {:?}",
                runner.progress()
            );
        }
        let at_wall = |p: &PlayerView| p.grounded && p.sides.contains(Sides::RIGHT);
        while !game.player(me).is_some_and(|p| at_wall(&p)) {
            game.step(&[(me, Buttons(Buttons::RIGHT))]);
            ticks += 1;
            assert!(ticks < 60 * 60, "walks to the wall");
        }
        let p = game.player(me).unwrap();
        assert_eq!(foot(&p).1, TRENCH_FLOOR, "in the trench");
        assert!(foot(&p).0 > TRENCH.1 - 16 * PX, "at its high wall");
        // A runner that was heading for the plateau (its plan failed).
        let mut runner = Runner::new(route.clone());
        runner.next = plateau;
        let won_at = play(&mut game, me, &mut runner, 60 * 60);
        let progress = runner.progress();
        eprintln!("won at {won_at:?}, {progress:?}");
        assert!(won_at.is_some(), "stuck: {progress:?}");
        assert!(progress.recoveries >= 1, "it noticed: {progress:?}");
        assert_eq!(progress.respawns, 0, "it climbed out: {progress:?}");
    }

    #[test]
    fn a_runner_stuck_under_an_unreachable_waypoint_steps_back_then_gives_it_up() {
        // A waypoint on the bonus shelf, 16 tiles above the ground: no jump
        // gets there. The runner stalls under it, notices, heads back for a
        // running start, stalls again, and after MAX_RETRIES recoveries
        // gives that waypoint up and still reaches the goal.
        let mut route = default_route();
        let shelf = Waypoint {
            foot: glam::IVec2::new(10 * 16 * PX, 10 * 16 * PX),
            action: RouteAction::Jump,
        };
        route.insert(2, shelf);
        let mut game = Game::from_level(&default_level()).unwrap();
        let me = PlayerId(1);
        game.add_player(me).unwrap();
        let mut runner = Runner::new(route);
        let mut went_back = false;
        let mut won_at = None;
        for _ in 0..60 * 60 {
            let b = runner.buttons(&game, me);
            went_back |= runner.recovering() && runner.next == 1;
            if finished(game.step(&[(me, b)]), me) {
                won_at = Some(game.tick());
                break;
            }
        }
        let progress = runner.progress();
        eprintln!("won at {won_at:?}, {progress:?}");
        assert!(went_back, "it headed back to the waypoint before");
        assert_eq!(
            progress.recoveries,
            u64::from(MAX_RETRIES) + 1,
            "it gave the shelf up after {MAX_RETRIES} tries: {progress:?}"
        );
        let won_at = won_at.expect("it reached the goal");
        assert!(
            won_at > u64::from(STALL_TICKS * (MAX_RETRIES + 1)),
            "it stalled {} times first",
            MAX_RETRIES + 1
        );
    }

    #[test]
    fn plans_never_count_on_stomping_a_walker() {
        // The runner crosses the whole level, the trench walker included,
        // without ever bouncing off a walker.
        let level = default_level();
        let mut game = Game::from_level(&level).unwrap();
        let me = PlayerId(1);
        game.add_player(me).unwrap();
        let mut runner = Runner::new(default_route());
        let mut stomps = 0;
        let mut won = false;
        for _ in 0..60 * 60 {
            let b = runner.buttons(&game, me);
            let events = game.step(&[(me, b)]);
            stomps += events
                .iter()
                .filter(|e| matches!(e, GameEvent::Stomped { player, .. } if *player == me))
                .count();
            if finished(events, me) {
                won = true;
                break;
            }
        }
        assert!(won, "{:?}", runner.progress());
        assert_eq!(stomps, 0);
    }

    /// The runner's buttons, tick by tick, until it wins (at most a minute),
    /// in a game holding `idle` idle players besides it (on their own spots
    /// around the spawn; ours, player 1's, is the spawn itself).
    fn run_beside(idle: u32) -> (Vec<Buttons>, RunnerProgress, bool) {
        let level = default_level();
        let mut game = Game::from_level(&level).unwrap();
        let me = PlayerId(1);
        for id in 1..=idle + 1 {
            game.add_player(PlayerId(id)).unwrap();
        }
        let mut runner = Runner::new(default_route());
        let mut pressed = Vec::new();
        for _ in 0..60 * 60 {
            let b = runner.buttons(&game, me);
            pressed.push(b);
            if finished(game.step(&[(me, b)]), me) {
                return (pressed, runner.progress(), true);
            }
        }
        (pressed, runner.progress(), false)
    }

    #[test]
    fn planning_costs_the_same_beside_idle_players() {
        let (alone, solo, won) = run_beside(0);
        let (crowded, crowd, won_too) = run_beside(12);
        assert!(won && won_too, "{solo:?} {crowd:?}");
        // Players never touch: the same run, tick for tick...
        assert_eq!(alone, crowded);
        assert_eq!(solo.plans, crowd.plans);
        // ...planned at the same cost: the others are not simulated.
        assert!(solo.simulated > 0);
        assert_eq!(solo.simulated, crowd.simulated, "{solo:?} {crowd:?}");
    }
}
