//! The platformer: players, moving platforms, enemies, pickups and the rules
//! that tie them to the physics world.
//!
//! [`Game`] is what the server runs authoritatively and the client predicts:
//! `step` is deterministic (integer only, players in id order, no hash map),
//! `snapshot`/`restore` carry the exact state, and `state_hash` identifies it.
//!
//! # How a level becomes a world
//! * The level's tilemap is the [`World`]'s tilemap: collision by lookup, no
//!   collider per tile ([`World::set_tilemap`]).
//! * Blocks are static boxes, polygon blocks static convex polygons
//!   ([`EntityKind::PolygonBlock`]); moving platforms kinematic boxes
//!   (one-way ones solid from above) whose centre is a pure function of the
//!   tick ([`PathSchedule`]); walkers and players dynamic boxes that ride
//!   platforms ([`World::set_rider`]). Players and walkers do not collide
//!   with each other (layers): stomping and hurting are rules, checked on
//!   the boxes after the physics step.
//! * Coins, checkpoints, goals, hazard volumes and springboards are plain
//!   boxes the rules test against player boxes (no collider).
//!
//! # One tick
//! ```text
//! platforms: velocity = path(t + 1) - path(t)
//! players (id order): buttons -> run, jump / drop-through, gravity
//! walkers: walk, gravity
//! world.step: carry riders, move, detect (colliders + tiles), restitute
//! walkers: squished -> defeated; turn at walls and ledges
//! players (id order): restart; run timer; dead -> count down, respawn;
//!   squished / hazard / fell -> die; polygon slopes;
//!   ceiling, wall, ground; ground snap; platform exit velocity;
//!   enemies (stomp or die); springboards; coins; checkpoints; goal
//! ```
//! Events come out in that order (join and leave events first). The rules
//! are described in `docs/PLATFORMER.md`.
//!
//! # Runs
//! Each player has a run: what a results card and a room's results table
//! show, decided here (server-authoritative, predicted like the rest).
//! * **Timer.** It starts on the first tick whose buttons hold one that
//!   plays ([`Buttons::PLAY`]; not restart) and counts every tick until it
//!   finishes, that first tick and the finishing tick included, deaths and
//!   dead time too: a finished run's ticks are the game tick after the
//!   goal was reached minus the game tick before the first press.
//! * **Death.** Hazard tiles and volumes, walkers, being squished and
//!   falling [`FALL_MARGIN`] below the level kill ([`GameEvent::Died`]):
//!   the death count goes up (not after finishing: a finished run's record
//!   stays as it was), the body stops where it died and is suspended (it
//!   neither moves, collides, collects nor is hurt) for
//!   [`PlayerConfig::respawn_delay_ticks`] ticks ([`PlayerView::dead`]
//!   counts them down), then it is put back at its respawn point at rest
//!   ([`GameEvent::Respawned`]). With a delay of 0 that happens in the tick
//!   it died.
//! * **Finishing.** Reaching a goal finishes the run once
//!   ([`GameEvent::Finished`]): the timer stops, and the run gets a
//!   finishing order, one more than the largest of the players in the game.
//!   A player's place ([`PlayerView::place`]) is 1 plus the number of
//!   finished players in the game with a smaller order: players ranked by
//!   finishing tick, ties (the same tick) by player id, because players are
//!   stepped in id order. Places are among the players present: when one
//!   ahead leaves or restarts, those behind move up. After finishing a
//!   player keeps playing (and can still die and respawn).
//! * **Restart.** A press of [`Buttons::RESTART`] (held now, not last tick),
//!   also while dead or after finishing, restarts the run at the end of the
//!   tick (the tick's movement is discarded; [`GameEvent::Restarted`], then
//!   [`GameEvent::Respawned`]): the player is put at its own spawn spot at
//!   rest, alive; its checkpoint is the spawn again; timer, deaths and
//!   finish are cleared (the timer starts again with the next press); and
//!   the coins it picked up are put back in the level for anyone to take,
//!   so the new run counts its own coins. Walkers it defeated stay
//!   defeated (they are the room's, like coins others took).
//!
//! # State
//! Everything that lasts from one tick to the next is in the snapshot:
//! players (position, velocity, flags and timers packed as in [`state`]),
//! walkers, coins and one run record per player ([`kind::RUN`], id
//! [`RUN_ID_BASE`] + player id); platforms are flagged
//! [`EntityState::CLIENT_SIMULATED`] and recomputed from the tick. The
//! world's per-tick scratch (touched sides, carriers, pushes) is rebuilt
//! every tick, and a player's outcome never depends on other players' body
//! ids, so restoring a snapshot into any game of the same level reproduces
//! the future exactly.

mod config;
mod entity;
mod path;
mod polygon_ground;
mod rect;
mod rules;
pub mod spawn;
pub mod state;

pub use config::{
    CarryMode, GameConfig, PlayerConfig, PlayerShape, FOOT_HEIGHT, FOOT_INSET,
    MAX_RESPAWN_DELAY_TICKS,
};
pub use entity::EntityType;
pub use path::PathSchedule;
pub use state::{kind, ENTITY_ID_BASE, RUN_ID_BASE};

use crate::fixed::{check_coord, check_speed};
use crate::input::Buttons;
use crate::level::{EntityDef, EntityKind, Level};
use crate::protocol::{is_replicated, EntityState, PlayerId, StateSnapshot};
use crate::shape::{Aabb, ConvexPolygon, Obb};
use crate::tilemap::Tilemap;
use crate::world::hash::Fnv1a;
use crate::world::{BodyDesc, BodyId, ColliderDesc, OneWay, Sides, World, TILEMAP_LAYER};
use entity::Ent;
use glam::IVec2;
use state::{coin_flags, platform_flags, walker_flags, PlayerState, RunState, RUN_MAX};
use thiserror::Error;

/// Collision layer of level geometry (blocks, platforms).
const LAYER_SOLID: u32 = 1;
/// Collision layer of players.
const LAYER_PLAYER: u32 = 2;
/// Collision layer of walkers.
const LAYER_WALKER: u32 = 4;

/// Why a game could not be built or changed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum GameError {
    /// The level has no player spawn.
    #[error("level {0:?} has no player spawn")]
    NoSpawn(String),
    /// A player with this id is already in the game.
    #[error("player {0} is already in the game")]
    DuplicatePlayer(PlayerId),
    /// A snapshot that does not describe this game.
    #[error("snapshot does not fit this game: {0}")]
    BadSnapshot(String),
    /// A level the game cannot run (names the entity and the problem).
    #[error("level {level:?}: {message}")]
    BadLevel {
        /// The level's name.
        level: String,
        /// What is wrong.
        message: String,
    },
    /// A configuration value out of range.
    #[error("bad game configuration: {0}")]
    BadConfig(String),
    /// A player id at or above [`ENTITY_ID_BASE`] (reserved for entities).
    #[error("player id {0} is reserved for level entities")]
    PlayerIdOutOfRange(PlayerId),
}

/// What killed a player ([`GameEvent::Died`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HurtCause {
    /// A walker's body (entity id).
    Enemy(u32),
    /// A hazard tile.
    HazardTile,
    /// A hazard volume (entity id).
    Hazard(u32),
    /// Fell out of the level: [`FALL_MARGIN`] below everything in it.
    Fell,
    /// Crushed: a platform pushed it into something solid.
    Squished,
}

/// How far below the lowest thing in a level ([`Level::bounds`]) a player
/// falls before it dies: 16 tiles of 16 px, in units.
pub const FALL_MARGIN: i32 = 256 * crate::fixed::UNITS_PER_PX;

/// Something that happened in a tick, for the server, the HUD and tests.
/// Entity ids are [`ENTITY_ID_BASE`] plus the entity's index in the level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GameEvent {
    /// A player entered the game (reported at the start of the next step).
    Joined(PlayerId),
    /// A player left the game (reported at the start of the next step).
    Left(PlayerId),
    /// A player jumped off the ground (or within coyote time).
    Jumped(PlayerId),
    /// A player pressed down + jump on a one-way surface and drops through.
    DroppedThrough(PlayerId),
    /// A player picked up a coin.
    CoinPicked {
        /// Who.
        player: PlayerId,
        /// The coin's entity id.
        coin: u32,
        /// Coins that player has picked up so far, this one included.
        total: u32,
    },
    /// A player touched a checkpoint that was not its respawn point: now it is.
    Checkpoint {
        /// Who.
        player: PlayerId,
        /// The checkpoint's entity id.
        checkpoint: u32,
    },
    /// A player reached a goal: its run finished (once per run).
    Finished {
        /// Who.
        player: PlayerId,
        /// The run's ticks, from the first press to the goal, both ticks
        /// included.
        ticks: u32,
        /// Its place in the room now (1: first).
        place: u32,
    },
    /// A player died; a [`GameEvent::Respawned`] follows after
    /// [`PlayerConfig::respawn_delay_ticks`] (in this tick when 0) unless it
    /// restarts first.
    Died {
        /// Who.
        player: PlayerId,
        /// Of what.
        cause: HurtCause,
    },
    /// A player restarted its run ([`Buttons::RESTART`]); a
    /// [`GameEvent::Respawned`] at its spawn follows in this tick.
    Restarted(PlayerId),
    /// A player landed on a walker's head: the walker is defeated and the
    /// player bounces.
    Stomped {
        /// Who.
        player: PlayerId,
        /// The walker's entity id.
        enemy: u32,
    },
    /// A springboard launched a player.
    Launched {
        /// Who.
        player: PlayerId,
        /// The springboard's entity id.
        springboard: u32,
    },
    /// A player was put back at its respawn point (after dying or
    /// restarting).
    Respawned {
        /// Who.
        player: PlayerId,
        /// Its new centre.
        pos: IVec2,
    },
    /// A walker was crushed and is defeated.
    EnemySquished {
        /// The walker's entity id.
        enemy: u32,
    },
}

/// A level entity as it is now, for drawing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EntityView {
    /// Its id ([`ENTITY_ID_BASE`] + level index).
    pub id: u32,
    /// What it is.
    pub ty: EntityType,
    /// Its centre now, in units.
    pub pos: IVec2,
    /// Its half extents, in units.
    pub half: IVec2,
    /// Still in play: a walker not defeated, a coin not picked up (always
    /// true for the others).
    pub active: bool,
    /// A one-way platform.
    pub one_way: bool,
    /// A walker walking left.
    pub facing_left: bool,
}

/// A player as it is now, for drawing and the HUD.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlayerView {
    /// Its id.
    pub id: PlayerId,
    /// Its centre, in units.
    pub pos: IVec2,
    /// Its velocity, in units per tick.
    pub vel: IVec2,
    /// Half extents of its box.
    pub half: IVec2,
    /// Stood on the ground at the end of the last tick.
    pub grounded: bool,
    /// Faces left.
    pub facing_left: bool,
    /// Coins picked up.
    pub coins: u32,
    /// Reached the goal: its run finished.
    pub won: bool,
    /// The checkpoint it respawns at (entity id), `None` for the level spawn.
    pub checkpoint: Option<u32>,
    /// Deaths in this run.
    pub deaths: u32,
    /// The run's timer started (a button that plays was pressed).
    pub run_started: bool,
    /// The run's ticks: running, or final once finished.
    pub run_ticks: u32,
    /// Its place among the finished players in the game (1: first), `None`
    /// until it finishes.
    pub place: Option<u32>,
    /// Dead: `Some(ticks until it respawns)`, at least 1; `None` alive.
    pub dead: Option<u16>,
    /// Sides its box touched during the last step (a view of the world's
    /// per-tick scratch: not part of the state, empty after a restore).
    pub sides: Sides,
}

/// One player at run time.
#[derive(Debug, Clone, Copy)]
struct Player {
    id: PlayerId,
    body: BodyId,
    st: PlayerState,
    run: RunState,
    /// Per-step scratch: restart was pressed this tick.
    restart: bool,
}

/// The running platformer.
#[derive(Debug, Clone)]
pub struct Game {
    config: GameConfig,
    name: String,
    world: World,
    tick: u64,
    ents: Vec<Ent>,
    spawns: Vec<usize>,
    /// Per spawn (as `spawns`), the player centres players take there
    /// ([`spawn`]); never empty.
    spawn_spots: Vec<Vec<IVec2>>,
    platforms: Vec<usize>,
    walkers: Vec<usize>,
    coins: Vec<usize>,
    springs: Vec<usize>,
    checkpoints: Vec<usize>,
    goals: Vec<usize>,
    hazards: Vec<usize>,
    /// Ascending by id.
    players: Vec<Player>,
    events: Vec<GameEvent>,
    /// Join and leave events waiting for the next step.
    pending: Vec<GameEvent>,
    /// Per-step scratch: bodies the world reported squished / in a hazard tile.
    squished: Vec<u32>,
    in_hazard_tile: Vec<u32>,
    tile_scratch: Vec<crate::tilemap::TileContact>,
    /// The polygon blocks, for the slope rules (`polygon_ground`).
    polygons: Vec<polygon_ground::PolygonSolid>,
    /// A player whose top passes below this y (units) fell out of the
    /// level ([`HurtCause::Fell`]); derived from the level.
    fall_y: i32,
}

impl Game {
    /// Builds the game for `level` with the default configuration, its
    /// player scaled for the level ([`GameConfig::for_level`]).
    pub fn from_level(level: &Level) -> Result<Self, GameError> {
        let config = GameConfig::default()
            .for_level(level)
            .map_err(GameError::BadConfig)?;
        Self::with_config(level, config)
    }

    /// Builds the game for `level` with `config`.
    pub fn with_config(level: &Level, config: GameConfig) -> Result<Self, GameError> {
        let mut g = Self::empty(level, config)?;
        for (i, def) in level.entities.iter().enumerate() {
            g.add_entity(level, i, def)?;
        }
        if g.spawns.is_empty() {
            return Err(GameError::NoSpawn(level.name.clone()));
        }
        g.find_spawn_spots();
        Ok(g)
    }

    /// The game for `level` with `config` before its entities: the world with
    /// the level's tilemap, no entity, no player.
    fn empty(level: &Level, config: GameConfig) -> Result<Self, GameError> {
        config.player.validate().map_err(GameError::BadConfig)?;
        let mut world = World::new(config.sim).map_err(|e| GameError::BadConfig(e.to_string()))?;
        world.set_tilemap(level.tilemap.clone());
        if level.entities.len() >= (1 << 15) - 1 {
            return Err(GameError::BadLevel {
                level: level.name.clone(),
                message: format!("{} entities; at most 32766", level.entities.len()),
            });
        }
        Ok(Game {
            config,
            name: level.name.clone(),
            world,
            tick: 0,
            ents: Vec::with_capacity(level.entities.len()),
            spawns: Vec::new(),
            spawn_spots: Vec::new(),
            platforms: Vec::new(),
            walkers: Vec::new(),
            coins: Vec::new(),
            springs: Vec::new(),
            checkpoints: Vec::new(),
            goals: Vec::new(),
            hazards: Vec::new(),
            players: Vec::new(),
            events: Vec::new(),
            pending: Vec::new(),
            squished: Vec::new(),
            in_hazard_tile: Vec::new(),
            tile_scratch: Vec::new(),
            polygons: Vec::new(),
            fall_y: level
                .bounds()
                .map_or(i32::MAX, |(_, hi)| hi.y.saturating_add(FALL_MARGIN)),
        })
    }

    /// Adds entity `i` of `level`, `def`: checks it, builds its body and
    /// collider if it has one, and files it in its type's list.
    fn add_entity(&mut self, level: &Level, i: usize, def: &EntityDef) -> Result<(), GameError> {
        let bad = |m: String| bad_entity(level, i, m);
        let half = def.size / 2;
        for v in [def.pos.x, def.pos.y] {
            check_coord("entity position", v as i64).map_err(|e| bad(e.to_string()))?;
        }
        let ty = EntityType::of(&def.kind);
        let needs_box = ty != EntityType::Spawn;
        let shape = if needs_box {
            Some(Aabb::new(half).map_err(|e| bad(format!("size {}: {e}", def.size)))?)
        } else {
            None
        };
        let mut e = Ent {
            ty,
            pos: def.pos,
            half,
            body: None,
            param: 0,
            path: None,
            one_way: false,
            alive: true,
            dir: -1,
            collector: None,
            turned: None,
        };
        self.build_entity(level, i, def, shape, &mut e)?;
        self.ents.push(e);
        Ok(())
    }

    /// The part of [`Game::add_entity`] that depends on the entity's kind:
    /// its body and collider (box `shape`, or its polygon), parameters, and
    /// the list it goes in.
    fn build_entity(
        &mut self,
        level: &Level,
        i: usize,
        def: &EntityDef,
        shape: Option<Aabb>,
        e: &mut Ent,
    ) -> Result<(), GameError> {
        let bad = |m: String| bad_entity(level, i, m);
        let build = |r: Result<BodyId, crate::world::BuildError>| r.map_err(|x| bad(x.to_string()));
        match &def.kind {
            EntityKind::PlayerSpawn => self.spawns.push(i),
            EntityKind::Block => {
                let b = build(self.world.add_body(BodyDesc::fixed(def.pos)))?;
                let c = ColliderDesc::solid(shape.expect("box")).layers(LAYER_SOLID, u32::MAX);
                self.world
                    .add_collider(b, c)
                    .map_err(|x| bad(x.to_string()))?;
                e.body = Some(b);
            }
            EntityKind::PolygonBlock { vertices } => {
                let poly =
                    ConvexPolygon::new(vertices).map_err(|x| bad(format!("polygon: {x}")))?;
                let b = build(self.world.add_body(BodyDesc::fixed(def.pos)))?;
                let c = ColliderDesc::solid(poly).layers(LAYER_SOLID, u32::MAX);
                self.world
                    .add_collider(b, c)
                    .map_err(|x| bad(x.to_string()))?;
                self.polygons
                    .push(polygon_ground::PolygonSolid::new(b, def.pos, &poly));
                e.body = Some(b);
            }
            EntityKind::MovingPlatform { motion, one_way } => {
                let path = PathSchedule::new(motion).map_err(bad)?;
                let b = build(self.world.add_body(BodyDesc::kinematic(path.at(0))))?;
                let mut c = ColliderDesc::solid(shape.expect("box")).layers(LAYER_SOLID, u32::MAX);
                if *one_way {
                    c = c.one_way(OneWay::Up);
                }
                self.world
                    .add_collider(b, c)
                    .map_err(|x| bad(x.to_string()))?;
                e.pos = path.at(0);
                e.body = Some(b);
                e.path = Some(path);
                e.one_way = *one_way;
                self.platforms.push(i);
            }
            EntityKind::Walker { speed } => {
                check_speed("walker speed", *speed as i64).map_err(|x| bad(x.to_string()))?;
                let b = build(self.world.add_body(BodyDesc::dynamic(def.pos)))?;
                let c = ColliderDesc::solid(shape.expect("box"))
                    .layers(LAYER_WALKER, LAYER_SOLID | TILEMAP_LAYER);
                self.world
                    .add_collider(b, c)
                    .map_err(|x| bad(x.to_string()))?;
                self.world
                    .set_rider(b, true)
                    .map_err(|x| bad(x.to_string()))?;
                e.body = Some(b);
                e.param = speed.abs();
                self.walkers.push(i);
            }
            EntityKind::Springboard { strength } => {
                check_speed("springboard strength", *strength as i64)
                    .map_err(|x| bad(x.to_string()))?;
                e.param = strength.abs();
                self.springs.push(i);
            }
            EntityKind::Coin => self.coins.push(i),
            EntityKind::Checkpoint => self.checkpoints.push(i),
            EntityKind::Goal => self.goals.push(i),
            EntityKind::Hazard => self.hazards.push(i),
            EntityKind::Turned { trigger, u, v } => {
                e.turned = Some(Obb::from_axes(*u, *v).map_err(|x| bad(format!("turned: {x}")))?);
                let def = EntityDef {
                    kind: trigger.kind(),
                    ..def.clone()
                };
                return self.build_entity(level, i, &def, shape, e);
            }
        }
        Ok(())
    }

    /// Where players stand at each spawn ([`spawn`]), once every entity is in.
    fn find_spawn_spots(&mut self) {
        let ground = spawn::Ground {
            map: self.tilemap(),
            ents: &self.ents,
            half: self.config.player.half,
        };
        self.spawn_spots = self
            .spawns
            .iter()
            .map(|&i| ground.spots(self.stand_in(&self.ents[i])))
            .collect();
    }

    /// The configuration.
    pub fn config(&self) -> &GameConfig {
        &self.config
    }

    /// The level's name.
    pub fn level_name(&self) -> &str {
        &self.name
    }

    /// The collision grid.
    pub fn tilemap(&self) -> &Tilemap {
        self.world
            .tilemap()
            .expect("a game's world always has a tilemap")
    }

    /// The physics world (for debug drawing and tools).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The pool the world's detection runs on when the configuration asks
    /// for threads (`config.sim.threads != 1`); see
    /// [`World::set_thread_pool`]. A server running many rooms shares one
    /// pool this way. Results never depend on it.
    pub fn set_thread_pool(&mut self, pool: Option<std::sync::Arc<rayon::ThreadPool>>) {
        self.world.set_thread_pool(pool);
    }

    /// Adds a player at its spawn point (spawn `id % spawn count` in level
    /// order, on its own spot there: [`spawn`]); a [`GameEvent::Joined`]
    /// opens the next step's events.
    pub fn add_player(&mut self, id: PlayerId) -> Result<(), GameError> {
        if id.0 >= ENTITY_ID_BASE {
            return Err(GameError::PlayerIdOutOfRange(id));
        }
        let at = match self.players.binary_search_by_key(&id, |p| p.id) {
            Ok(_) => return Err(GameError::DuplicatePlayer(id)),
            Err(at) => at,
        };
        let st = PlayerState::default();
        let pos = self.respawn_point(id, &st);
        let body = self.new_player_body(pos)?;
        self.players.insert(
            at,
            Player {
                id,
                body,
                st,
                run: RunState::default(),
                restart: false,
            },
        );
        self.pending.push(GameEvent::Joined(id));
        Ok(())
    }

    /// A player's body at `pos`: one box, or torso, feet and head boxes
    /// ([`config::PlayerShape`]).
    fn new_player_body(&mut self, pos: IVec2) -> Result<BodyId, GameError> {
        let cfg = &self.config.player;
        let (boxes, n) = cfg.shape.boxes(cfg.half);
        let err = |e: crate::world::BuildError| GameError::BadConfig(e.to_string());
        let body = self.world.add_body(BodyDesc::dynamic(pos)).map_err(err)?;
        for &(half, offset) in &boxes[..n] {
            let shape = Aabb::new(half).map_err(|e| GameError::BadConfig(e.to_string()))?;
            let c = ColliderDesc::solid(shape)
                .at(offset)
                .layers(LAYER_PLAYER, LAYER_SOLID | TILEMAP_LAYER);
            self.world.add_collider(body, c).map_err(err)?;
        }
        self.world.set_rider(body, true).map_err(err)?;
        Ok(body)
    }

    /// Removes a player and its body; returns whether it was there. A
    /// [`GameEvent::Left`] opens the next step's events. Coins it picked up
    /// stay picked up.
    pub fn remove_player(&mut self, id: PlayerId) -> bool {
        match self.players.binary_search_by_key(&id, |p| p.id) {
            Ok(i) => {
                let p = self.players.remove(i);
                self.world
                    .remove_body(p.body)
                    .expect("a player's body exists");
                self.pending.push(GameEvent::Left(id));
                true
            }
            Err(_) => false,
        }
    }

    /// Ticks run so far.
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// Sets the clock of a fresh game (no players, never stepped) to
    /// `tick`, platforms placed for it: a room moving to another level
    /// keeps counting its ticks, so no tick names two states. Refused
    /// (`false`, nothing changed) once the game has players or has run.
    pub fn start_at(&mut self, tick: u64) -> bool {
        if !self.players.is_empty() || self.tick != 0 {
            return false;
        }
        self.tick = tick;
        self.place_platforms();
        true
    }

    /// The last step's events.
    pub fn events(&self) -> &[GameEvent] {
        &self.events
    }

    /// The players and their centres (units), ascending by id.
    pub fn players(&self) -> impl Iterator<Item = (PlayerId, IVec2)> + '_ {
        self.players.iter().map(|p| (p.id, self.body_pos(p.body)))
    }

    /// One player's view.
    pub fn player(&self, id: PlayerId) -> Option<PlayerView> {
        let i = self.players.binary_search_by_key(&id, |p| p.id).ok()?;
        Some(self.view_of(&self.players[i]))
    }

    /// Every player's view, ascending by id.
    pub fn player_views(&self) -> impl Iterator<Item = PlayerView> + '_ {
        self.players.iter().map(|p| self.view_of(p))
    }

    /// The room's results table: the views of the players that finished
    /// their run, first place first.
    pub fn results(&self) -> Vec<PlayerView> {
        let mut v: Vec<PlayerView> = self
            .players
            .iter()
            .filter(|p| p.run.order != 0)
            .map(|p| self.view_of(p))
            .collect();
        v.sort_by_key(|p| (p.place, p.id));
        v
    }

    /// The place of a run finished with `order` among the players in the
    /// game: 1 plus the number of finished runs with a smaller order.
    fn place_of(&self, order: u32) -> u32 {
        let ahead = self
            .players
            .iter()
            .filter(|q| q.run.order != 0 && q.run.order < order)
            .count();
        1 + ahead as u32
    }

    /// The finishing order of a run finishing now: one more than the
    /// largest of the players in the game (at most [`RUN_MAX`]).
    fn next_order(&self) -> u32 {
        let top = self.players.iter().map(|q| q.run.order).max().unwrap_or(0);
        (top + 1).min(RUN_MAX)
    }

    fn view_of(&self, p: &Player) -> PlayerView {
        let b = self.world.body(p.body).expect("a player's body exists");
        PlayerView {
            id: p.id,
            pos: b.pos(),
            vel: b.vel(),
            half: self.config.player.half,
            grounded: p.st.grounded,
            facing_left: p.st.facing_left,
            coins: self.coins_of(p.id),
            won: p.st.won,
            checkpoint: (p.st.checkpoint != 0).then(|| ENTITY_ID_BASE + p.st.checkpoint as u32 - 1),
            deaths: p.run.deaths,
            run_started: p.run.started,
            run_ticks: p.run.ticks,
            place: (p.run.order != 0).then(|| self.place_of(p.run.order)),
            dead: (p.st.dead > 0).then_some(p.st.dead),
            sides: b.sides(),
        }
    }

    /// Coins player `id` has picked up.
    pub fn coins_of(&self, id: PlayerId) -> u32 {
        self.coins
            .iter()
            .filter(|&&i| self.ents[i].collector == Some(id.0))
            .count() as u32
    }

    /// Every level entity as it is now, in level order.
    pub fn entities(&self) -> impl Iterator<Item = EntityView> + '_ {
        self.ents.iter().enumerate().map(|(i, e)| EntityView {
            id: ENTITY_ID_BASE + i as u32,
            ty: e.ty,
            pos: e.body.map_or(e.pos, |b| self.body_pos(b)),
            half: e.half,
            active: match e.ty {
                EntityType::Walker => e.alive,
                EntityType::Coin => e.collector.is_none(),
                _ => true,
            },
            one_way: e.one_way,
            facing_left: e.dir < 0,
        })
    }

    fn body_pos(&self, b: BodyId) -> IVec2 {
        self.world.body(b).map_or(IVec2::ZERO, |b| b.pos())
    }

    fn body_vel(&self, b: BodyId) -> IVec2 {
        self.world.body(b).map_or(IVec2::ZERO, |b| b.vel())
    }

    /// Where player `id` with state `st` respawns: its checkpoint (the
    /// player's box standing on the bottom of the checkpoint's box, centred
    /// in x), else its own spot at its spawn ([`spawn`]: spawn
    /// `id % spawns`, spot `(id - 1) / spawns` of that spawn's spots).
    fn respawn_point(&self, id: PlayerId, st: &PlayerState) -> IVec2 {
        if st.checkpoint != 0 {
            return self.stand_in(&self.ents[st.checkpoint as usize - 1]);
        }
        // At most 32766 entities: the count fits u32.
        let n = self.spawns.len() as u32;
        let spots = &self.spawn_spots[(id.0 % n) as usize];
        let k = id.0.wrapping_sub(1) / n % spots.len() as u32;
        spots[k as usize]
    }

    /// The centre of a player standing on the bottom of entity `e`'s box,
    /// centred in x.
    fn stand_in(&self, e: &Ent) -> IVec2 {
        IVec2::new(e.pos.x, e.pos.y + e.half.y - self.config.player.half.y)
    }

    /// Calls `f` with every entity's state, ascending by id: players, then
    /// walkers, coins and platforms (client-simulated) in level order, then
    /// the players' run records.
    fn for_each_state(&self, mut f: impl FnMut(EntityState)) {
        for p in &self.players {
            f(EntityState {
                id: p.id.0,
                kind: kind::PLAYER,
                pos: self.body_pos(p.body),
                vel: self.body_vel(p.body),
                flags: p.st.flags(),
                aux: p.st.aux(),
            });
        }
        for (i, e) in self.ents.iter().enumerate() {
            let id = ENTITY_ID_BASE + i as u32;
            match e.ty {
                EntityType::Walker => {
                    let b = e.body.expect("walker body");
                    f(EntityState {
                        id,
                        kind: kind::WALKER,
                        pos: self.body_pos(b),
                        vel: self.body_vel(b),
                        flags: (e.alive as u32 * walker_flags::ALIVE)
                            | ((e.dir < 0) as u32 * walker_flags::FACING_LEFT),
                        aux: 0,
                    })
                }
                EntityType::Coin => f(EntityState {
                    id,
                    kind: kind::COIN,
                    pos: e.pos,
                    vel: IVec2::ZERO,
                    flags: e.collector.is_some() as u32 * coin_flags::COLLECTED,
                    aux: e.collector.unwrap_or(0) as i32,
                }),
                EntityType::Platform => {
                    let b = e.body.expect("platform body");
                    f(EntityState {
                        id,
                        kind: kind::PLATFORM,
                        pos: self.body_pos(b),
                        vel: self.platform_step(e),
                        flags: EntityState::CLIENT_SIMULATED
                            | (e.one_way as u32 * platform_flags::ONE_WAY),
                        aux: 0,
                    })
                }
                _ => {}
            }
        }
        for p in &self.players {
            f(p.run.to_entity(p.id.0));
        }
    }

    /// A platform's motion during the next step.
    fn platform_step(&self, e: &Ent) -> IVec2 {
        let p = e.path.as_ref().expect("platform path");
        p.at(self.tick + 1) - p.at(self.tick)
    }

    /// Every entity with state, ascending by id, platforms included (flagged
    /// [`EntityState::CLIENT_SIMULATED`]): what a renderer or a custom
    /// snapshot filter starts from.
    pub fn entity_states(&self) -> Vec<EntityState> {
        let mut v = Vec::new();
        self.for_each_state(|e| v.push(e));
        v
    }

    /// The exact state: every entity [`is_replicated`] keeps (players,
    /// walkers, coins, run records; platforms are recomputed from the
    /// tick).
    pub fn snapshot(&self) -> StateSnapshot {
        let mut entities =
            Vec::with_capacity(2 * self.players.len() + self.walkers.len() + self.coins.len());
        self.for_each_state(|e| {
            if is_replicated(&e) {
                entities.push(e)
            }
        });
        StateSnapshot {
            tick: self.tick,
            entities,
        }
    }

    /// Restores the exact state of a [`Game::snapshot`] of a game of the same
    /// level and configuration: afterwards `state_hash` and every future tick
    /// equal the original's. Client-simulated entities in the snapshot are
    /// ignored (platforms follow the tick). Join and leave events not yet
    /// reported are dropped. Nothing changes on error.
    pub fn restore(&mut self, snapshot: &StateSnapshot) -> Result<(), GameError> {
        snapshot
            .validate()
            .map_err(|e| bad_snapshot(e.to_string()))?;
        let read = self.read_snapshot(snapshot)?;
        // Valid: apply.
        self.restore_players(read.players, read.runs)?;
        self.restore_entities(&read.found);
        self.tick = snapshot.tick;
        self.place_platforms();
        self.events.clear();
        self.pending.clear();
        Ok(())
    }

    /// Reads every record of `snapshot` and checks it against this game (the
    /// first error in record order, then the checks across records);
    /// changes nothing.
    fn read_snapshot<'s>(&self, snapshot: &'s StateSnapshot) -> Result<Restored<'s>, GameError> {
        let mut read = Restored {
            players: Vec::new(),
            runs: Vec::new(),
            found: vec![None; self.ents.len()],
        };
        for e in &snapshot.entities {
            if e.id >= RUN_ID_BASE {
                read.runs.push((PlayerId(e.id - RUN_ID_BASE), read_run(e)?));
                continue;
            }
            check_motion(e)?;
            if e.id < ENTITY_ID_BASE {
                read.players.push((PlayerId(e.id), e, self.read_player(e)?));
                continue;
            }
            if let Some(i) = self.read_entity(e)? {
                read.found[i] = Some(e);
            }
        }
        self.check_complete(&read)?;
        Ok(read)
    }

    /// The state in player record `e`, checked against the configuration
    /// and the level's checkpoints.
    fn read_player(&self, e: &EntityState) -> Result<PlayerState, GameError> {
        if e.kind != kind::PLAYER {
            return Err(bad_snapshot(format!(
                "entity {} has kind {}, not a player",
                e.id, e.kind
            )));
        }
        let st = PlayerState::unpack(e.flags, e.aux).ok_or_else(|| {
            bad_snapshot(format!("player {}: unknown flag bits {:#x}", e.id, e.flags))
        })?;
        if st.dead > self.config.player.respawn_delay_ticks {
            return Err(bad_snapshot(format!(
                "player {}: dead for {} more ticks, the delay is {}",
                e.id, st.dead, self.config.player.respawn_delay_ticks
            )));
        }
        if st.checkpoint != 0 {
            let ok = self
                .ents
                .get(st.checkpoint as usize - 1)
                .is_some_and(|c| c.ty == EntityType::Checkpoint);
            if !ok {
                return Err(bad_snapshot(format!(
                    "player {}: no checkpoint {}",
                    e.id,
                    st.checkpoint - 1
                )));
            }
        }
        Ok(st)
    }

    /// Checks record `e` of a level entity against the level: the index of
    /// the entity whose state it holds (a walker or a coin), or `None` for
    /// a platform's (ignored: platforms follow the tick).
    fn read_entity(&self, e: &EntityState) -> Result<Option<usize>, GameError> {
        let i = (e.id - ENTITY_ID_BASE) as usize;
        let Some(ent) = self.ents.get(i) else {
            return Err(bad_snapshot(format!("no entity {}", e.id)));
        };
        if e.kind != ent.ty.code() {
            return Err(bad_snapshot(format!(
                "entity {} has kind {}, expected {}",
                e.id,
                e.kind,
                ent.ty.code()
            )));
        }
        match ent.ty {
            EntityType::Platform => Ok(None),
            EntityType::Walker | EntityType::Coin => Ok(Some(i)),
            _ => Err(bad_snapshot(format!("entity {} has no state", e.id))),
        }
    }

    /// The checks across records: every walker and coin has a record; one
    /// run record per player (both lists ascend by id), finished exactly
    /// when the player is.
    fn check_complete(&self, read: &Restored<'_>) -> Result<(), GameError> {
        for &i in self.walkers.iter().chain(&self.coins) {
            if read.found[i].is_none() {
                return Err(bad_snapshot(format!(
                    "entity {} is missing",
                    ENTITY_ID_BASE + i as u32
                )));
            }
        }
        let (players, runs) = (&read.players, &read.runs);
        if runs.len() != players.len() {
            return Err(bad_snapshot(format!(
                "{} run records for {} players",
                runs.len(),
                players.len()
            )));
        }
        for ((id, _, st), (rid, run)) in players.iter().zip(runs) {
            if id != rid {
                return Err(bad_snapshot(format!("player {id} has no run record")));
            }
            if st.won != (run.order != 0) {
                return Err(bad_snapshot(format!(
                    "player {id}: the won flag and the run's finishing order disagree"
                )));
            }
        }
        Ok(())
    }

    /// Applies the snapshot's players: drops those not in it, adds the new
    /// ones, then sets every state.
    fn restore_players(
        &mut self,
        players: Vec<(PlayerId, &EntityState, PlayerState)>,
        runs: Vec<(PlayerId, RunState)>,
    ) -> Result<(), GameError> {
        let old: Vec<Player> = std::mem::take(&mut self.players);
        let mut kept = Vec::with_capacity(players.len());
        for p in old {
            if players.iter().any(|(id, _, _)| *id == p.id) {
                kept.push(p);
            } else {
                self.world
                    .remove_body(p.body)
                    .expect("a player's body exists");
            }
        }
        for ((id, e, st), (_, run)) in players.into_iter().zip(runs) {
            let body = match kept.iter().find(|p| p.id == id) {
                Some(p) => p.body,
                None => self.new_player_body(e.pos)?,
            };
            self.set_body(body, e.pos, e.vel);
            self.world
                .set_drop_through(body, false)
                .expect("player body");
            self.world
                .set_enabled(body, st.dead == 0)
                .expect("player body");
            self.players.push(Player {
                id,
                body,
                st,
                run,
                restart: false,
            });
        }
        Ok(())
    }

    /// Applies the walker and coin records, `found[i]` for entity `i`.
    fn restore_entities(&mut self, found: &[Option<&EntityState>]) {
        for (i, e) in found.iter().enumerate() {
            let Some(e) = e else { continue };
            let body = self.ents[i].body;
            match self.ents[i].ty {
                EntityType::Walker => {
                    let body = body.expect("walker body");
                    let alive = e.flags & walker_flags::ALIVE != 0;
                    self.set_body(body, e.pos, e.vel);
                    self.world.set_enabled(body, alive).expect("walker body");
                    let ent = &mut self.ents[i];
                    ent.alive = alive;
                    ent.dir = if e.flags & walker_flags::FACING_LEFT != 0 {
                        -1
                    } else {
                        1
                    };
                }
                EntityType::Coin => {
                    self.ents[i].collector =
                        (e.flags & coin_flags::COLLECTED != 0).then_some(e.aux as u32);
                }
                _ => {}
            }
        }
    }

    /// Sets a body's position and velocity (both validated by the caller).
    fn set_body(&mut self, body: BodyId, pos: IVec2, vel: IVec2) {
        self.world
            .set_position(body, pos)
            .expect("position checked");
        self.world
            .set_velocity(body, vel)
            .expect("velocity checked");
    }

    /// Puts every platform where its path says it is at the current tick.
    fn place_platforms(&mut self) {
        for &i in &self.platforms {
            let e = &self.ents[i];
            let pos = e.path.as_ref().expect("platform path").at(self.tick);
            let body = e.body.expect("platform body");
            self.world
                .set_position(body, pos)
                .expect("path nodes are checked");
            self.world
                .set_velocity(body, IVec2::ZERO)
                .expect("zero velocity");
        }
    }

    /// A stable 64-bit hash of the whole state: FNV-1a over the tick and
    /// every entity state ([`Game::entity_states`], platforms included), each
    /// field little-endian. Equal after [`Game::restore`] of a
    /// [`Game::snapshot`].
    pub fn state_hash(&self) -> u64 {
        let mut h = Fnv1a::default();
        h.u64(self.tick);
        self.for_each_state(|e| {
            h.u32(e.id);
            h.u8(e.kind);
            h.ivec2(e.pos);
            h.ivec2(e.vel);
            h.u32(e.flags);
            h.i32(e.aux);
        });
        h.finish()
    }

    /// Runs one tick. `inputs` holds at most one entry per player, in any
    /// order (the first entry of a player counts); a player without an entry
    /// holds no button. Returns the tick's events (also [`Game::events`]).
    pub fn step(&mut self, inputs: &[(PlayerId, Buttons)]) -> &[GameEvent] {
        self.events.clear();
        self.events.append(&mut self.pending);
        self.step_rules(inputs);
        self.tick += 1;
        &self.events
    }
}

/// A snapshot's records, read and checked by [`Game::restore`] before it
/// changes anything.
struct Restored<'s> {
    /// Player records with their state, in snapshot order (ascending by id).
    players: Vec<(PlayerId, &'s EntityState, PlayerState)>,
    /// Run records, ascending by player id like `players`.
    runs: Vec<(PlayerId, RunState)>,
    /// The record of each walker and coin, by entity index.
    found: Vec<Option<&'s EntityState>>,
}

/// The error for a snapshot that does not describe the game.
fn bad_snapshot(m: String) -> GameError {
    GameError::BadSnapshot(m)
}

/// The error for entity `i` of `level`.
fn bad_entity(level: &Level, i: usize, m: String) -> GameError {
    GameError::BadLevel {
        level: level.name.clone(),
        message: format!("entity {i}: {m}"),
    }
}

/// The run in run record `e`.
fn read_run(e: &EntityState) -> Result<RunState, GameError> {
    if e.kind != kind::RUN {
        return Err(bad_snapshot(format!(
            "entity {} has kind {}, not a run record",
            e.id, e.kind
        )));
    }
    RunState::from_entity(e).map_err(|m| bad_snapshot(format!("run record {}: {m}", e.id)))
}

/// Checks the position and velocity of record `e` against the numeric
/// bounds.
fn check_motion(e: &EntityState) -> Result<(), GameError> {
    for (what, v) in [("x", e.pos.x), ("y", e.pos.y)] {
        check_coord("position", v as i64)
            .map_err(|x| bad_snapshot(format!("entity {}: {what}: {x}", e.id)))?;
    }
    for v in [e.vel.x, e.vel.y] {
        check_speed("velocity", v as i64)
            .map_err(|x| bad_snapshot(format!("entity {}: {x}", e.id)))?;
    }
    Ok(())
}
