//! The rules of one tick (see the module docs of [`super`] for the order and
//! `docs/PLATFORMER.md` for each rule).

use glam::IVec2;

use super::config::{CarryMode, PlayerConfig};
use super::entity::EntityType;
use super::polygon_ground::{PolygonSolid, SLOPE_RUN, TOUCH};
use super::rect::Rect;
use super::state::{PlayerState, RunState, RUN_MAX};
use super::{Game, GameEvent, HurtCause, Player, ENTITY_ID_BASE};
use crate::fixed::MAX_SPEED;
use crate::input::Buttons;
use crate::protocol::PlayerId;
use crate::tilemap::{ContactFlags, Tile, TileContact, Tilemap};
use crate::world::{BodyId, Event, Sides};

/// Horizontal speed after one tick of `dir` (-1, 0, 1) from `vx`.
fn run(vx: i32, dir: i32, accel: i32, brake: i32, max: i32) -> i32 {
    let v = vx as i64;
    if dir == 0 {
        return if v > 0 {
            (v - brake as i64).max(0) as i32
        } else {
            (v + brake as i64).min(0) as i32
        };
    }
    let (d, accel, brake, max) = (dir as i64, accel as i64, brake as i64, max as i64);
    let s = v * d;
    let s = if s < 0 {
        (s + brake + accel).min(max)
    } else if s < max {
        (s + accel).min(max)
    } else {
        (s - brake).max(max)
    };
    (s * d) as i32
}

impl Game {
    pub(super) fn step_rules(&mut self, inputs: &[(PlayerId, Buttons)]) {
        // Platforms: this tick's motion, from the path.
        for k in 0..self.platforms.len() {
            let e = &self.ents[self.platforms[k]];
            let v = self.platform_step(e);
            let body = e.body.expect("platform body");
            self.world
                .set_velocity(body, v)
                .expect("path steps are bounded");
        }
        for i in 0..self.players.len() {
            let id = self.players[i].id;
            let b = inputs
                .iter()
                .find(|(p, _)| *p == id)
                .map_or(Buttons::NONE, |(_, b)| *b);
            self.player_before(i, b);
        }
        for k in 0..self.walkers.len() {
            let e = &self.ents[self.walkers[k]];
            if !e.alive {
                continue;
            }
            let body = e.body.expect("walker body");
            let cfg = &self.config.player;
            let v = self.body_vel(body);
            let v = IVec2::new(
                e.dir * e.param,
                (v.y as i64 + cfg.gravity as i64).min(cfg.max_fall_speed as i64) as i32,
            );
            self.world
                .set_velocity(body, v)
                .expect("bounded walker speed");
        }

        self.world.step(&[]);
        self.squished.clear();
        self.in_hazard_tile.clear();
        for e in self.world.events() {
            match *e {
                Event::Squished { body } => self.squished.push(body.0),
                Event::Trigger {
                    body, trigger_body, ..
                } if trigger_body == BodyId::TILEMAP => self.in_hazard_tile.push(body.0),
                _ => {}
            }
        }

        for k in 0..self.walkers.len() {
            self.walker_after(self.walkers[k]);
        }
        for i in 0..self.players.len() {
            self.player_after(i);
        }
    }

    /// Buttons to velocity, before the physics step; the run's input
    /// (restart press, timer start) also while dead.
    fn player_before(&mut self, i: usize, b: Buttons) {
        let cfg = self.config.player;
        let mut p = self.players[i];
        let restart = b.held(Buttons::RESTART);
        p.restart = restart && !p.st.restart_held;
        p.st.restart_held = restart;
        if b.plays() {
            p.run.started = true;
        }
        if p.st.dead > 0 {
            // Suspended: no control, no timers; only the jump hold is
            // tracked, so a jump held through the respawn is no new press.
            p.st.jump_held = b.held(Buttons::JUMP);
            self.players[i] = p;
            return;
        }
        let mut v = self.body_vel(p.body);
        let s = &mut p.st;

        let held = b.held(Buttons::JUMP);
        if held && !s.jump_held {
            s.buffer = cfg.jump_buffer_ticks + 1;
        }
        s.jump_held = held;

        let dir = b.dir_x();
        if dir != 0 {
            s.facing_left = dir < 0;
        }
        v.x = if s.grounded {
            run(v.x, dir, cfg.run_accel, cfg.run_brake, cfg.max_run_speed)
        } else {
            run(v.x, dir, cfg.air_accel, cfg.air_brake, cfg.max_run_speed)
        };

        let can_jump = s.grounded || s.coyote > 0;
        if !s.grounded && s.coyote > 0 {
            s.coyote -= 1;
        }
        if s.buffer > 0 && can_jump {
            let pos = self.body_pos(p.body);
            if b.held(Buttons::DOWN) && s.grounded && self.drop_allowed(pos, &cfg) {
                s.drop = cfg.drop_through_ticks;
                self.events.push(GameEvent::DroppedThrough(p.id));
            } else {
                v.y = -cfg.jump_speed;
                s.hold = cfg.jump_hold_ticks;
                self.events.push(GameEvent::Jumped(p.id));
            }
            s.buffer = 0;
            s.coyote = 0;
            s.grounded = false;
        }
        s.buffer = s.buffer.saturating_sub(1);

        if !held {
            s.hold = 0;
        }
        let g = if v.y < 0 && s.hold > 0 {
            s.hold -= 1;
            cfg.jump_gravity
        } else {
            cfg.gravity
        };
        v.y = (v.y as i64 + g as i64).min(cfg.max_fall_speed as i64) as i32;

        self.world
            .set_drop_through(p.body, s.drop > 0)
            .expect("player body");
        s.drop = s.drop.saturating_sub(1);
        self.world
            .set_velocity(p.body, clamp_speed(v))
            .expect("clamped player speed");
        self.players[i] = p;
    }

    /// Whether a player standing at `pos` stands on a one-way surface (tile
    /// or platform) and on nothing solid, so down + jump drops through.
    fn drop_allowed(&self, pos: IVec2, cfg: &PlayerConfig) -> bool {
        let r = Rect::new(pos, cfg.half);
        let (mut one_way, mut solid) = (false, false);
        let map = self.tilemap();
        let t = map.tile_size() as i64;
        let origin = map.origin().as_i64vec2();
        let row = (r.b - origin.y).div_euclid(t);
        if origin.y + row * t == r.b {
            let c0 = (r.l - origin.x).div_euclid(t);
            let c1 = (r.r - 1 - origin.x).div_euclid(t);
            for c in c0..=c1 {
                match map.tile(IVec2::new(c as i32, row as i32)) {
                    Tile::OneWay => one_way = true,
                    Tile::Solid | Tile::Slope(_) => solid = true,
                    Tile::Empty | Tile::Hazard => {}
                }
            }
        }
        // A slope under the foot also holds the player up.
        if map.is_solid_at(IVec2::new(pos.x, r.b as i32)) {
            solid = true;
        }
        for (i, e) in self.ents.iter().enumerate() {
            if !matches!(e.ty, EntityType::Platform | EntityType::Block) {
                continue;
            }
            let er = Rect::new(self.entity_pos(i), e.half);
            if er.t == r.b && er.l < r.r && r.l < er.r {
                if e.one_way {
                    one_way = true;
                } else {
                    solid = true;
                }
            }
        }
        one_way && !solid
    }

    /// An entity's centre now.
    fn entity_pos(&self, i: usize) -> IVec2 {
        let e = &self.ents[i];
        e.body.map_or(e.pos, |b| self.body_pos(b))
    }

    /// A walker after the physics step: squished walkers are defeated; the
    /// others turn at walls and ledges.
    fn walker_after(&mut self, i: usize) {
        let e = &self.ents[i];
        if !e.alive {
            return;
        }
        let body = e.body.expect("walker body");
        if self.squished.contains(&body.0) {
            self.defeat(i);
            self.events.push(GameEvent::EnemySquished {
                enemy: ENTITY_ID_BASE + i as u32,
            });
            return;
        }
        let b = self.world.body(body).expect("walker body");
        let (sides, pos, dir) = (b.sides(), b.pos(), e.dir);
        let wall =
            (dir > 0 && sides.contains(Sides::RIGHT)) || (dir < 0 && sides.contains(Sides::LEFT));
        let ledge = sides.contains(Sides::BOTTOM) && !self.ground_ahead(i, pos);
        if wall || ledge {
            self.ents[i].dir = -dir;
        }
    }

    /// Whether there is ground under the walker's leading bottom corner after
    /// its next step: solid material there (or just above: the foot of an
    /// uphill slope), a floor surface at most `half.x + speed` below it (a
    /// downhill slope), or the top of a block or platform.
    fn ground_ahead(&self, i: usize, pos: IVec2) -> bool {
        let e = &self.ents[i];
        let r = Rect::new(pos, e.half);
        let x = if e.dir > 0 { r.r - 1 } else { r.l } + (e.dir * e.param) as i64;
        let (x, y) = (x as i32, r.b as i32);
        let map = self.tilemap();
        let reach = e.half.x + e.param;
        if map.is_solid_at(IVec2::new(x, y))
            || map.is_solid_at(IVec2::new(x, y - 1))
            || map.ground_below(IVec2::new(x, y), reach).is_some()
        {
            return true;
        }
        self.ents.iter().enumerate().any(|(k, o)| {
            matches!(o.ty, EntityType::Platform | EntityType::Block) && {
                let or = Rect::new(self.entity_pos(k), o.half);
                or.l <= x as i64
                    && (x as i64) < or.r
                    && or.t >= y as i64
                    && or.t <= (y + reach) as i64
            }
        })
    }

    /// Defeats walker `i`: it stops and stops colliding.
    fn defeat(&mut self, i: usize) {
        let e = &mut self.ents[i];
        e.alive = false;
        let body = e.body.expect("walker body");
        self.world.set_enabled(body, false).expect("walker body");
        self.world
            .set_velocity(body, IVec2::ZERO)
            .expect("zero velocity");
    }

    /// Puts player `p` back at its respawn point, at rest and alive.
    fn respawn(&mut self, p: &mut Player) {
        let pos = self.respawn_point(p.id, &p.st);
        self.world
            .set_position(p.body, pos)
            .expect("respawn point in bounds");
        self.still(p, true);
        p.st.dead = 0;
        self.events.push(GameEvent::Respawned { player: p.id, pos });
    }

    /// Stops player `p`'s body (no velocity, not dropping through, its
    /// controller cleared) and enables it (alive) or suspends it (dead).
    fn still(&mut self, p: &mut Player, enabled: bool) {
        self.world
            .set_velocity(p.body, IVec2::ZERO)
            .expect("zero velocity");
        self.world
            .set_drop_through(p.body, false)
            .expect("player body");
        self.world
            .set_enabled(p.body, enabled)
            .expect("player body");
        clear_controller(&mut p.st);
    }

    /// Player `p` dies of `cause`: counted (unless its run finished), then
    /// suspended where it is for the respawn delay, or respawned now when
    /// the delay is 0.
    fn die(&mut self, p: &mut Player, cause: HurtCause) {
        self.events.push(GameEvent::Died {
            player: p.id,
            cause,
        });
        if p.run.order == 0 {
            p.run.deaths = (p.run.deaths + 1).min(RUN_MAX);
        }
        let delay = self.config.player.respawn_delay_ticks;
        if delay == 0 {
            self.respawn(p);
            return;
        }
        self.still(p, false);
        p.st.dead = delay;
    }

    /// Player `p` restarts its run: its coins go back to the level, its
    /// checkpoint, timer, deaths and finish are cleared, and it respawns at
    /// its spawn spot (see "Runs" in the module docs of [`super`]).
    fn restart(&mut self, p: &mut Player) {
        self.events.push(GameEvent::Restarted(p.id));
        for k in 0..self.coins.len() {
            let c = self.coins[k];
            if self.ents[c].collector == Some(p.id.0) {
                self.ents[c].collector = None;
            }
        }
        p.st.checkpoint = 0;
        p.st.won = false;
        p.run = RunState::default();
        self.respawn(p);
    }

    /// The rules after the physics step, for player `i`: a restart; the
    /// run's timer; a dead player's countdown; the rules of a live one.
    fn player_after(&mut self, i: usize) {
        let mut p = self.players[i];
        if p.restart {
            p.restart = false;
            self.restart(&mut p);
            self.players[i] = p;
            return;
        }
        p.run.tick();
        if p.st.dead > 0 {
            p.st.dead -= 1;
            if p.st.dead == 0 {
                self.respawn(&mut p);
            }
            self.players[i] = p;
            return;
        }
        self.players[i] = p;
        self.live_player_after(i);
    }

    /// The rules after the physics step, for live player `i`.
    fn live_player_after(&mut self, i: usize) {
        let mut p = self.players[i];
        let mut m = self.moved(p.body);
        if let Some(cause) = self.fatal_touch(p.body, m.pos) {
            self.die(&mut p, cause);
            self.players[i] = p;
            return;
        }
        self.polygon_faces(p.body, &mut m);
        stop_at_surfaces(&mut p.st, &mut m);
        self.ground_snap(&p, &mut m);
        self.carry_off(&mut m);
        let r = Rect::new(m.pos, self.config.player.half);
        if !self.stomp_or_hurt(&mut p, &r, &mut m) {
            self.players[i] = p;
            return;
        }
        self.springboards(&mut p, &r, &mut m);
        self.collect(&mut p, &r);
        self.settle(&mut p, &m);
        self.players[i] = p;
    }

    /// Reads the player body `body` as the physics step left it.
    fn moved(&self, body: BodyId) -> Moved {
        let b = self.world.body(body).expect("player body");
        Moved {
            pos: b.pos(),
            vel: b.vel(),
            sides: b.sides(),
            disp: b.displacement(),
            pushed: b.pushed(),
            carrier: b.carrier(),
            dropping: b.drops_through(),
            grounded: false,
        }
    }

    /// What kills player body `body` at `pos` before any other rule: being
    /// squished, then a hazard tile, falling out, a hazard entity.
    fn fatal_touch(&self, body: BodyId, pos: IVec2) -> Option<HurtCause> {
        let cfg = self.config.player;
        if self.squished.contains(&body.0) {
            Some(HurtCause::Squished)
        } else if self.in_hazard_tile.contains(&body.0) {
            Some(HurtCause::HazardTile)
        } else if pos.y - cfg.half.y > self.fall_y {
            Some(HurtCause::Fell)
        } else {
            let r = Rect::new(pos, cfg.half);
            self.hazards
                .iter()
                .find(|&&h| self.ents[h].touches(self.ents[h].pos, &r))
                .map(|&h| HurtCause::Hazard(ENTITY_ID_BASE + h as u32))
        }
    }

    /// Polygon faces: a walkable one holds the player like a tile slope
    /// (ground, no slide), a steeper one is a wall.
    fn polygon_faces(&mut self, body: BodyId, m: &mut Moved) {
        if self.polygons.is_empty() || m.carrier.is_some() {
            return;
        }
        let Some(pc) = self.polygon_contacts(body, m.pos, m.disp, m.pushed, m.sides) else {
            return;
        };
        m.sides = pc.sides;
        if let Some((shift, v)) = pc.unslide {
            let half = self.config.player.half;
            if self.tiles_clear(m.pos + shift, half, m.disp + shift, m.dropping) {
                self.world
                    .shift(body, shift)
                    .expect("unslide within bounds");
                m.pos += shift;
                m.vel = v;
            }
        }
    }

    /// Ground snap: walking down a slope (or off a small step) keeps a
    /// grounded player on the ground instead of launching it.
    fn ground_snap(&mut self, p: &Player, m: &mut Moved) {
        if m.grounded || !p.st.grounded || m.vel.y < 0 || m.dropping || m.carrier.is_some() {
            return;
        }
        let cfg = self.config.player;
        let map = self.world.tilemap().expect("a game's world has a tilemap");
        let mut drop = snap_drop(
            map,
            m.pos,
            cfg.half,
            cfg.snap_distance,
            &mut self.tile_scratch,
        );
        if !self.polygons.is_empty() {
            drop = self.polygon_snap(m.pos, drop);
        }
        if let Some(d) = drop {
            if d != 0 {
                self.world
                    .shift(p.body, IVec2::new(0, d))
                    .expect("snap within bounds");
            }
            m.pos.y += d;
            m.vel.y = 0;
            m.grounded = true;
        }
    }

    /// Leaving a platform keeps (some of) its velocity.
    fn carry_off(&self, m: &mut Moved) {
        if let (Some(c), false) = (m.carrier, m.grounded) {
            let pv = self.body_vel(c);
            match self.config.player.carry_mode {
                CarryMode::Add => m.vel += pv,
                CarryMode::AddUpOnly => m.vel.y += pv.y.min(0),
                CarryMode::None => {}
            }
        }
    }

    /// Enemies: land on the head from above to stomp, else get hurt; false
    /// when the player (box `r`) died of it.
    fn stomp_or_hurt(&mut self, p: &mut Player, r: &Rect, m: &mut Moved) -> bool {
        let cfg = self.config.player;
        for k in 0..self.walkers.len() {
            let w = self.walkers[k];
            let e = &self.ents[w];
            if !e.alive {
                continue;
            }
            let wb = self
                .world
                .body(e.body.expect("walker body"))
                .expect("walker body");
            let wr = Rect::new(wb.pos(), e.half);
            if !wr.overlaps(r) {
                continue;
            }
            let start_bottom = r.b - m.disp.y as i64;
            let start_top = wr.t - wb.displacement().y as i64;
            let falling = m.disp.y > wb.displacement().y;
            let enemy = ENTITY_ID_BASE + w as u32;
            if falling && start_bottom <= start_top + cfg.stomp_tolerance as i64 {
                self.defeat(w);
                let s = &mut p.st;
                if s.jump_held {
                    m.vel.y = -cfg.jump_speed;
                    s.hold = cfg.jump_hold_ticks;
                } else {
                    m.vel.y = -cfg.stomp_bounce_speed;
                    s.hold = 0;
                }
                s.coyote = 0;
                m.grounded = false;
                self.events.push(GameEvent::Stomped {
                    player: p.id,
                    enemy,
                });
            } else {
                self.die(p, HurtCause::Enemy(enemy));
                return false;
            }
        }
        true
    }

    /// Springboards launch once per touch (of the player's box `r`).
    fn springboards(&mut self, p: &mut Player, r: &Rect, m: &mut Moved) {
        let spring = self
            .springs
            .iter()
            .copied()
            .find(|&k| Rect::new(self.ents[k].pos, self.ents[k].half).overlaps(r));
        if let Some(k) = spring {
            if !p.st.on_spring {
                m.vel.y = -self.ents[k].param;
                p.st.hold = 0;
                p.st.coyote = 0;
                m.grounded = false;
                self.events.push(GameEvent::Launched {
                    player: p.id,
                    springboard: ENTITY_ID_BASE + k as u32,
                });
            }
        }
        p.st.on_spring = spring.is_some();
    }

    /// Coins, checkpoints and goals the player's box `r` touches, in that
    /// order.
    fn collect(&mut self, p: &mut Player, r: &Rect) {
        let id = p.id;
        for k in 0..self.coins.len() {
            let c = self.coins[k];
            let e = &self.ents[c];
            if e.collector.is_none() && e.touches(e.pos, r) {
                self.ents[c].collector = Some(id.0);
                let total = self.coins_of(id);
                self.events.push(GameEvent::CoinPicked {
                    player: id,
                    coin: ENTITY_ID_BASE + c as u32,
                    total,
                });
            }
        }
        for k in 0..self.checkpoints.len() {
            let c = self.checkpoints[k];
            let e = &self.ents[c];
            if p.st.checkpoint as usize != c + 1 && e.touches(e.pos, r) {
                p.st.checkpoint = (c + 1) as u16;
                self.events.push(GameEvent::Checkpoint {
                    player: id,
                    checkpoint: ENTITY_ID_BASE + c as u32,
                });
            }
        }
        if !p.st.won
            && self
                .goals
                .iter()
                .any(|&k| self.ents[k].touches(self.ents[k].pos, r))
        {
            p.st.won = true;
            p.run.order = self.next_order();
            self.events.push(GameEvent::Finished {
                player: id,
                ticks: p.run.ticks,
                place: self.place_of(p.run.order),
            });
        }
    }

    /// Coyote time and the grounded flag from this tick, and the velocity
    /// the rules leave on the body.
    fn settle(&mut self, p: &mut Player, m: &Moved) {
        let s = &mut p.st;
        if m.grounded {
            s.coyote = self.config.player.coyote_ticks;
        }
        s.grounded = m.grounded;
        self.world
            .set_velocity(p.body, clamp_speed(m.vel))
            .expect("clamped player speed");
    }
}

/// A live player's body after the physics step, as the rules after it read
/// and change it ([`Game::live_player_after`]).
struct Moved {
    pos: IVec2,
    vel: IVec2,
    sides: Sides,
    disp: IVec2,
    pushed: IVec2,
    carrier: Option<BodyId>,
    dropping: bool,
    /// Standing on something this tick (set by [`stop_at_surfaces`], then
    /// by the snap, stomps and springboards).
    grounded: bool,
}

/// A ceiling stops the rise; a wall stops the run; a floor grounds.
fn stop_at_surfaces(s: &mut PlayerState, m: &mut Moved) {
    if m.sides.contains(Sides::TOP) {
        m.vel.y = m.vel.y.max(0);
        s.hold = 0;
    }
    if (m.sides.contains(Sides::LEFT) && m.vel.x < 0)
        || (m.sides.contains(Sides::RIGHT) && m.vel.x > 0)
    {
        m.vel.x = 0;
    }
    m.grounded = m.sides.contains(Sides::BOTTOM);
}

/// What this tick's polygon contacts change for a player
/// ([`Game::polygon_contacts`]).
struct PolygonContacts {
    /// The body's sides with each polygon contact reread: a walkable face
    /// the player rests on touched only its bottom; a steeper face (a wall)
    /// never its bottom.
    sides: Sides,
    /// When the player rests on walkable faces and nothing else pushed it
    /// sideways: the shift that undoes the faces' sideways push (along the
    /// surface, back out of it), and the velocity a straight-up push would
    /// have left.
    unslide: Option<(IVec2, IVec2)>,
}

impl Game {
    /// The polygon block of body `b`, if it is one.
    fn polygon_of(&self, b: BodyId) -> Option<&PolygonSolid> {
        // Built in level order: ascending body ids.
        let i = self.polygons.binary_search_by_key(&b, |p| p.body).ok()?;
        Some(&self.polygons[i])
    }

    /// Rereads the polygon contacts of player body `body` (now at `pos`,
    /// moved by `disp`, of which `pushed` by restitution, with `sides`
    /// touched), or `None` when no polygon pushed it this tick.
    ///
    /// The world pushes a box out of a slanted face along the face's normal,
    /// so a standing player slides down and a walking one is slowed and
    /// lifted off the surface. On a walkable face the rules make that push
    /// straight up instead, like a tile slope's: the sideways part is undone
    /// by moving along the surface and back out of it, and the velocity
    /// keeps its horizontal part (only a downward part is stopped).
    fn polygon_contacts(
        &self,
        body: BodyId,
        pos: IVec2,
        disp: IVec2,
        pushed: IVec2,
        sides: Sides,
    ) -> Option<PolygonContacts> {
        let cfg = &self.config.player;
        let (boxes, n) = cfg.shape.boxes(cfg.half);
        let boxes = &boxes[..n];
        let slope = cfg.max_walkable_slope;
        // Each pushed event of this body, with its polygon when it is one
        // and whether the player rests on a walkable face of it.
        let contacts = self.world.events().iter().filter_map(|e| match *e {
            Event::Contact {
                body: b,
                other_body,
                sides,
                ..
            } if b == body => {
                let poly = self.polygon_of(other_body);
                let walk = poly
                    .and_then(|p| p.gap(pos, boxes, slope))
                    .is_some_and(|g| g.touching() && g.walkable);
                Some((sides, poly, walk))
            }
            _ => None,
        });
        let (mut any, mut walk_any) = (false, false);
        let (mut poly_bits, mut other, mut from_poly) = (Sides::NONE, Sides::NONE, Sides::NONE);
        for (s, poly, walk) in contacts.clone() {
            if poly.is_none() {
                other |= s;
                continue;
            }
            any = true;
            poly_bits |= s;
            if walk {
                walk_any = true;
                from_poly |= Sides::BOTTOM;
            } else {
                from_poly |= Sides(s.0 & !Sides::BOTTOM.0);
            }
        }
        if !any {
            return None;
        }
        // Sides no polygon contact explains came from the other contacts
        // (logged or not).
        let sides = Sides(sides.0 & !poly_bits.0) | other | from_poly;
        let mut out = PolygonContacts {
            sides,
            unslide: None,
        };
        // The motion before any push: the velocity the rules set.
        let v0 = disp - pushed;
        let walls = sides.contains(Sides::LEFT) || sides.contains(Sides::RIGHT);
        if !walk_any || walls || pushed.x == 0 || v0.y < 0 {
            return Some(out);
        }
        // Undo the sideways push, then lift the boxes back out of the
        // walkable faces they rest on: at most the faces' rise over that
        // run (plus rounding), so a face the new position would bury the
        // player in is not one it rests on.
        let back = IVec2::new(-pushed.x, 0);
        let mut lift = 0i64;
        for (_, poly, walk) in contacts {
            if let (Some(p), true) = (poly, walk) {
                if let Some(g) = p.gap(pos + back, boxes, slope) {
                    lift = lift.min(g.gap);
                }
            }
        }
        let bound = pushed.x.unsigned_abs() as i64 * slope as i64 / SLOPE_RUN as i64 + 2 * TOUCH;
        if -lift > bound {
            return Some(out);
        }
        out.unslide = Some((back + IVec2::new(0, lift as i32), IVec2::new(v0.x, 0)));
        Some(out)
    }

    /// The ground snap with polygon solids: the drop onto the nearest floor
    /// under the player at `pos`, `tile` (the tile snap's answer) or the
    /// nearest polygon face at most `snap_distance` below, whichever is
    /// higher. A polygon face only when it is walkable (walking off onto a
    /// steeper face falls) and nothing in the tilemap pushes the box there.
    fn polygon_snap(&mut self, pos: IVec2, tile: Option<i32>) -> Option<i32> {
        let cfg = self.config.player;
        let (boxes, n) = cfg.shape.boxes(cfg.half);
        let max = cfg.snap_distance as i64;
        let mut near: Option<(i64, bool)> = None;
        for p in &self.polygons {
            let Some(g) = p.gap(pos, &boxes[..n], cfg.max_walkable_slope) else {
                continue;
            };
            if g.gap < 0 || g.gap > max {
                continue;
            }
            near = Some(match near {
                Some((d, w)) if d < g.gap => (d, w),
                Some((d, w)) if d == g.gap => (d, w || g.walkable),
                _ => (g.gap, g.walkable),
            });
        }
        let Some((d, walkable)) = near else {
            return tile;
        };
        if tile.is_some_and(|t| t as i64 <= d) {
            return tile;
        }
        let d = d as i32;
        let shift = IVec2::new(0, d);
        (walkable && self.tiles_clear(pos + shift, cfg.half, shift, false)).then_some(d)
    }

    /// Whether no tile pushes a box of half extents `half` at `pos` that
    /// moved by `moved` (hazards aside).
    fn tiles_clear(&mut self, pos: IVec2, half: IVec2, moved: IVec2, dropping: bool) -> bool {
        let map = self.world.tilemap().expect("a game's world has a tilemap");
        let out = &mut self.tile_scratch;
        out.clear();
        let flags = ContactFlags {
            drop_through: dropping,
        };
        map.box_contacts(pos, half, moved, flags, out);
        out.iter().all(|c| c.is_trigger())
    }
}

/// Clears what a respawn or a death ends: ground, springboard contact and
/// the four controller timers (facing and held buttons are kept).
fn clear_controller(s: &mut PlayerState) {
    s.grounded = false;
    s.on_spring = false;
    s.coyote = 0;
    s.buffer = 0;
    s.hold = 0;
    s.drop = 0;
}

/// `v` with each component clamped to the speed bound.
fn clamp_speed(v: IVec2) -> IVec2 {
    v.clamp(IVec2::splat(-MAX_SPEED), IVec2::splat(MAX_SPEED))
}

/// How far down a box at `pos` with half extents `half` can be snapped onto
/// the floor under its foot: the surface [`Tilemap::ground_below`] finds
/// within `max` (0: it already rests exactly on it), provided nothing in the
/// tilemap pushes the box there.
fn snap_drop(
    map: &Tilemap,
    pos: IVec2,
    half: IVec2,
    max: i32,
    out: &mut Vec<TileContact>,
) -> Option<i32> {
    let foot = IVec2::new(pos.x, pos.y + half.y);
    let y = map.ground_below(foot, max)?;
    let d = y - foot.y;
    if d < 0 {
        return None;
    }
    out.clear();
    map.box_contacts(
        pos + IVec2::new(0, d),
        half,
        IVec2::new(0, d),
        ContactFlags::default(),
        out,
    );
    out.iter().all(|c| c.is_trigger()).then_some(d)
}

#[cfg(test)]
mod tests {
    use super::run;

    #[test]
    fn run_accelerates_brakes_and_caps() {
        assert_eq!(run(0, 1, 10, 20, 25), 10);
        assert_eq!(run(20, 1, 10, 20, 25), 25);
        assert_eq!(run(40, 1, 10, 20, 25), 25);
        assert_eq!(run(60, 1, 10, 20, 25), 40);
        assert_eq!(run(-5, 1, 10, 20, 25), 25);
        assert_eq!(run(-40, 1, 10, 20, 25), -10);
        assert_eq!(run(15, 0, 10, 20, 25), 0);
        assert_eq!(run(-35, 0, 10, 20, 25), -15);
        assert_eq!(run(-20, -1, 10, 20, 25), -25);
    }
}
