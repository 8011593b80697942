//! Bodies, colliders and the tick pipeline.
//!
//! ```text
//! step(inputs): [refresh features, passes and the static index if the content
//!               changed] -> controllers -> find carriers -> for each substep {
//!               carry riders -> move (swept bodies last, to their first
//!               impact) -> detect (colliders, then tiles) ->
//!               restitute (-> detect again after each pass that moved
//!               something) } -> events
//! ```
//!
//! * **Tilemap** ([`World::set_tilemap`]): detection asks the tilemap about
//!   every solid collider of an enabled dynamic body, boxes by the tile
//!   rules ([`crate::tilemap::Tilemap::box_contacts`]), other shapes against
//!   each tile's own region ([`crate::tilemap::Tilemap::shape_contacts`]);
//!   each tile contact becomes a
//!   record against one static end, [`BodyId::TILEMAP`] (solid, or trigger
//!   for a hazard tile), re-checked through
//!   [`crate::tilemap::Tilemap::tile_contact`]. Restitution treats it like any
//!   static collider: whole push to the body, no push-back, velocity
//!   removal, touched sides, squish. No collider exists per tile. One rule
//!   is the world's: a solid tile never pushes a box towards its far side
//!   (`detect::tile_push_ok`), so a box resting against a thin floor and
//!   wall is never thrown through them by a culled corner tile.
//! * **Riders** ([`World::set_rider`]): at the start of a tick, a rider whose
//!   box collider's bottom lies exactly on the top of a kinematic body's
//!   solid box collider (a one-unit probe: flush, overlapping in x; one-way
//!   boxes count only when solid from above and the rider is not dropping
//!   through) is carried: in each substep it first moves by the kinematic
//!   body's share of the tick's motion, then by its own velocity. Standing
//!   on a platform moving any way thus keeps the rider's offset exact.
//! * **Swept collision** ([`SweepMode`], [`World::set_swept`]): a swept
//!   dynamic body moves to the first time of impact of its colliders against
//!   the solid static and kinematic colliders it can collide with and the
//!   tilemap, then slides, stops or reflects ([`SweepResponse`]) and reports
//!   one [`Event::SweptHit`]; nothing up to [`crate::fixed::MAX_SPEED`] per
//!   tick tunnels through a 1 px wall. Bodies not swept move first, so
//!   kinematic obstacles are where the substep leaves them. See `sweep`;
//!   a scene without swept bodies runs none of it.
//! * **Removal** ([`World::remove_body`]) frees a body's slot (reused by the
//!   next [`World::add_body`]) and drops its colliders and controllers;
//!   [`World::set_enabled`] only suspends a body.
//! * **Detection** goes through the broad phase ([`crate::broad`]) by
//!   default ([`BroadPhaseKind`]): colliders of static bodies are indexed
//!   once (again only when statics change: a static body added, moved,
//!   enabled, disabled or removed), those of kinematic and dynamic bodies
//!   are updated at each detection (one reused buffer, collider id order),
//!   and every overlapping pair runs the monomorphised narrow phase of its
//!   two kinds through a static dispatch table. Contacts come out in
//!   canonical order (pairs by collider ids, then tiles by collider and
//!   tile), identical for brute force, either pipeline and any thread count
//!   ([`SimConfig::threads`], [`World::set_thread_pool`]); restitution walks
//!   them in its own order through a sorted index, so the buffer stays
//!   canonical.
//! * **Only what the scene needs** ([`Pipeline::Specialised`]): whenever the
//!   content changes the world recomputes its [`SceneFeatures`] and runs
//!   only what they imply: direct pair tests without the broad phase for a
//!   tiny scene, the AABB fast path for a scene of boxes, no rider search
//!   without riders and kinematic boxes (and then only riders against
//!   platforms), tile queries only for the colliders that can touch tiles, no
//!   trigger logging without triggers, and re-detection after a
//!   restitution pass only around the bodies the pass moved. Same results,
//!   bit for bit, as [`Pipeline::General`].
//! * `id`: [`BodyId`], [`ColliderId`] and the tilemap's stand-ins for them
//!   ([`TILEMAP_LAYER`], [`TILEMAP_TAG`]), the bottom layer every part
//!   names;
//! * [`body`]: static, kinematic and dynamic bodies, touched [`Sides`];
//! * [`collider`]: shapes attached to bodies, one `Vec` per shape kind;
//! * [`contact`]: the element of the single, reused contact buffer;
//! * `detect`: broad phase + dispatch table, or brute force (one
//!   monomorphised loop per pair of shape kinds);
//! * `layout`: scene features and the specialised passes' lists;
//! * [`scenes`]: seeded scenes for tests and benchmarks;
//! * `sweep`: the swept move (candidates, choice, response, events);
//! * `restitute`: support first, largest overlap first, pins, no push-back,
//!   mass split;
//! * [`event`]: what a tick reports;
//! * [`controller`]: input to velocity;
//! * [`config`]: the speed/accuracy knobs;
//! * [`hash`]: the stable state hash.
//!
//! Nothing here allocates per tick once the buffers have grown to the
//! scene's needs (sorts are unstable, buffers are cleared, not dropped), and
//! nothing depends on hashing order or floating point: the same inputs give
//! the same state, bit for bit, in every build.

pub mod body;
pub mod collider;
pub mod config;
pub mod contact;
pub mod controller;
mod detect;
mod error;
pub mod event;
pub mod hash;
mod id;
mod layout;
mod presets;
mod restitute;
pub mod scenes;
mod sweep;

pub use body::{Body, BodyDesc, BodyKind, Sides, SweepResponse};
pub use collider::{AnyShape, ColliderDesc, ColliderMode, ColliderView, OneWay};
pub use config::{BroadPhaseKind, Pipeline, SimConfig, SweepMode, MAX_THREADS};
pub use contact::{ContactKind, ContactRecord};
pub use controller::{Controller, Mover, MoverConfig};
pub use error::BuildError;
pub use event::Event;
pub use id::{BodyId, ColliderId, TILEMAP_LAYER, TILEMAP_TAG};
pub use layout::SceneFeatures;
pub use restitute::ONE_WAY_SLOP;

use crate::input::Buttons;
use crate::shape::ShapeKind;
use crate::tilemap::{TileContact, Tilemap};
use glam::IVec2;
use std::sync::Arc;

use collider::{make_data, view, ColliderData, ColliderSet, Colliders, Stored};
use detect::Detector;
use event::Logs;
use hash::Fnv1a;
use layout::{Layout, Slot, GONE};
use restitute::Scene;

/// Contacts reserved up front: the most a scene could produce in one
/// detection (colliders of dynamic bodies times all colliders), up to this.
const RESERVE_CAP: usize = 4096;

/// The simulation state: bodies, colliders, controllers, and the reused
/// per-tick buffers.
#[derive(Debug, Clone)]
pub struct World {
    config: SimConfig,
    tick: u64,
    bodies: Vec<Body>,
    colliders: Colliders,
    /// Each collider by id: its kind, index in that kind's set (or [`GONE`])
    /// and what the pair filters need.
    slots: Vec<Slot>,
    /// Colliders attached to dynamic bodies.
    dynamic_colliders: usize,
    controllers: Vec<Controller>,
    contacts: Vec<ContactRecord>,
    logs: Logs,
    events: Vec<Event>,
    tilemap: Option<Tilemap>,
    /// Hash of the tilemap (computed once when it is set).
    tilemap_digest: u64,
    tile_scratch: Vec<TileContact>,
    /// Features, passes and the lists they walk.
    layout: Layout,
    /// Removed bodies whose slots are free.
    free_bodies: usize,
    /// Restitution's order scratch, pins and covered box faces.
    solver: restitute::Solver,
    /// Bodies the last restitution pass moved.
    pushed: Vec<u32>,
    /// How detections ran.
    stats: DetectionStats,
    /// Rider search scratch: carriers' top edges and set indices.
    carrier_tops: Vec<(i64, u32)>,
    /// The content changed since `layout` was built.
    layout_dirty: bool,
    /// The static colliders changed since the broad phase indexed them.
    statics_dirty: bool,
    /// The broad phase and its buffers.
    detector: Detector,
    /// The pool detection runs on (attached, or built for `threads >= 2`).
    pool: Option<Arc<rayon::ThreadPool>>,
    /// `pool` was given by [`World::set_thread_pool`] (else the world built it).
    pool_attached: bool,
    /// Building the world's own pool failed: run on one thread.
    pool_failed: bool,
    /// The swept move phase's static index and scratch (built at the first
    /// sweep).
    sweep_index: sweep::SweepIndex,
}

/// Fewer moving colliders than this are detected on the calling thread
/// whatever [`SimConfig::threads`] says: the broad phase would make at most
/// two parallel batches of them, and the hand-over to a pool costs more
/// than it saves (`benches/world.rs`).
const PAR_MIN_MOVING: usize = 2048;

/// Above this many (riders x carriers) the specialised rider search sorts
/// the carriers by top edge instead of testing every pair.
const SORTED_CARRIERS: usize = 256;

impl Default for World {
    fn default() -> Self {
        Self::with_config(SimConfig::default())
    }
}

impl World {
    /// An empty world with configuration `config`.
    pub fn new(config: SimConfig) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(Self::with_config(config))
    }

    fn with_config(config: SimConfig) -> Self {
        Self {
            config,
            tick: 0,
            bodies: Vec::new(),
            colliders: Colliders::default(),
            slots: Vec::new(),
            dynamic_colliders: 0,
            controllers: Vec::new(),
            contacts: Vec::new(),
            logs: Logs::default(),
            events: Vec::new(),
            tilemap: None,
            tilemap_digest: 0,
            tile_scratch: Vec::new(),
            layout: Layout::default(),
            free_bodies: 0,
            solver: restitute::Solver::default(),
            pushed: Vec::new(),
            stats: DetectionStats::default(),
            carrier_tops: Vec::new(),
            layout_dirty: true,
            statics_dirty: true,
            detector: Detector::new(config.broad_phase),
            pool: None,
            pool_attached: false,
            pool_failed: false,
            sweep_index: sweep::SweepIndex::default(),
        }
    }

    /// Detection runs on `pool` (`Some`) whenever [`SimConfig::threads`] is
    /// not 1, whatever its value; `None` detaches it (then `threads >= 2`
    /// builds the world's own pool at the next step, and `threads == 0` uses
    /// the pool `step` is called from). The server shares one pool among
    /// its rooms this way. Results never depend on the pool.
    ///
    /// The world's own pool is not pinned to cores (a library pinning its
    /// pools would pile every pool of a process onto the same cores). Linux
    /// can leave two unpinned workers on one core for tens of milliseconds,
    /// which made whole stretches of two-thread ticks no faster than one
    /// (docs/PERFORMANCE.md, "Issue 19, fourth round"); a host that wants
    /// the steady speed-up builds a pool whose workers pin themselves
    /// (rayon's `ThreadPoolBuilder::start_handler`) and attaches it here.
    pub fn set_thread_pool(&mut self, pool: Option<Arc<rayon::ThreadPool>>) {
        self.pool_attached = pool.is_some();
        self.pool = pool;
        self.pool_failed = false;
    }

    /// What the scene uses (recomputed when the content changes; see
    /// [`Pipeline::Specialised`]).
    pub fn features(&self) -> SceneFeatures {
        if self.layout_dirty {
            layout::features(&self.slots, &self.bodies, self.tilemap.as_ref())
        } else {
            self.layout.features
        }
    }

    /// Statistics of the broad phase's sets after the last detection (all
    /// zero in brute-force mode).
    pub fn broad_phase_stats(&self) -> crate::broad::BroadPhaseStats {
        self.detector.stats()
    }

    /// How this world's detections ran so far (cumulative, for tuning and
    /// tests; not part of the state).
    pub fn detection_stats(&self) -> DetectionStats {
        self.stats
    }

    /// Marks the content changed: features, passes and (with `statics`) the
    /// broad phase's static set are rebuilt before the next tick.
    fn touch(&mut self, statics: bool) {
        self.layout_dirty = true;
        self.statics_dirty |= statics;
        self.sweep_index.touch();
    }

    /// Rebuilds what [`World::touch`] marked stale.
    fn refresh(&mut self) {
        self.detector.fit(self.bodies.len());
        if self.layout_dirty {
            self.layout.rebuild(
                self.config.pipeline,
                &self.slots,
                &self.colliders,
                &self.bodies,
                self.tilemap.as_ref(),
            );
            self.layout_dirty = false;
        }
        if self.statics_dirty {
            if self.config.broad_phase != BroadPhaseKind::BruteForce {
                self.detector.set_static(&self.slots, &self.bodies);
            }
            self.solver.cover(&self.slots, &self.bodies);
            self.statics_dirty = false;
        }
    }

    /// The configuration.
    pub fn config(&self) -> &SimConfig {
        &self.config
    }

    /// Adds a body after checking its position, velocity and mass. It takes
    /// the lowest slot freed by [`World::remove_body`], else a new one.
    pub fn add_body(&mut self, desc: BodyDesc) -> Result<BodyId, BuildError> {
        desc.validate()?;
        let body = Body::new(&desc);
        if self.free_bodies > 0 {
            if let Some(i) = self.bodies.iter().position(|b| b.removed) {
                self.bodies[i] = body;
                self.free_bodies -= 1;
                return Ok(BodyId(i as u32));
            }
        }
        let id = BodyId(self.bodies.len() as u32);
        self.bodies.push(body);
        Ok(id)
    }

    /// Removes a body: drops its colliders (their ids are never reused) and
    /// the controllers driving it (later controllers move down one input
    /// slot each), and frees its slot for the next [`World::add_body`].
    pub fn remove_body(&mut self, id: BodyId) -> Result<(), BuildError> {
        let body = self.live(id)?;
        let dynamic = body.is_dynamic();
        let is_static = body.kind == BodyKind::Static;
        let c = &mut self.colliders;
        let ix = &mut self.slots;
        let n = remove_colliders(&mut c.points, ShapeKind::Point, id.0, ix)
            + remove_colliders(&mut c.segments, ShapeKind::Segment, id.0, ix)
            + remove_colliders(&mut c.circles, ShapeKind::Circle, id.0, ix)
            + remove_colliders(&mut c.aabbs, ShapeKind::Aabb, id.0, ix)
            + remove_colliders(&mut c.obbs, ShapeKind::Obb, id.0, ix)
            + remove_colliders(&mut c.polygons, ShapeKind::Polygon, id.0, ix);
        if dynamic {
            self.dynamic_colliders -= n;
        }
        self.controllers.retain(|c| c.body() != id);
        let b = &mut self.bodies[id.0 as usize];
        *b = Body::new(&BodyDesc::fixed(IVec2::ZERO));
        b.enabled = false;
        b.removed = true;
        self.free_bodies += 1;
        self.touch(is_static);
        Ok(())
    }

    /// A body that exists (not removed), for changes.
    fn live(&self, id: BodyId) -> Result<&Body, BuildError> {
        self.bodies
            .get(id.0 as usize)
            .filter(|b| !b.removed)
            .ok_or(BuildError::NoBody(id))
    }

    fn live_mut(&mut self, id: BodyId) -> Result<&mut Body, BuildError> {
        self.bodies
            .get_mut(id.0 as usize)
            .filter(|b| !b.removed)
            .ok_or(BuildError::NoBody(id))
    }

    /// Suspends (`false`) or resumes a body: a disabled body keeps its state
    /// but neither moves, collides, carries nor is carried.
    pub fn set_enabled(&mut self, body: BodyId, enabled: bool) -> Result<(), BuildError> {
        let b = self.live_mut(body)?;
        let changed = b.enabled != enabled;
        b.enabled = enabled;
        if changed && b.kind == BodyKind::Static {
            self.touch(true);
        }
        Ok(())
    }

    /// Makes a body a rider (`true`): kinematic boxes it stands on carry it
    /// (see the module docs). Off by default.
    pub fn set_rider(&mut self, body: BodyId, rider: bool) -> Result<(), BuildError> {
        let b = self.live_mut(body)?;
        if b.rider != rider {
            b.rider = rider;
            self.touch(false);
        }
        Ok(())
    }

    /// While set, one-way colliders and one-way tiles never push the body,
    /// and one-way boxes do not carry it (a player dropping through a
    /// platform).
    pub fn set_drop_through(&mut self, body: BodyId, drop: bool) -> Result<(), BuildError> {
        self.live_mut(body)?.drop_through = drop;
        Ok(())
    }

    /// Marks a body for swept collision (`true`): with
    /// [`SweepMode::Flagged`] or [`SweepMode::Auto`], a dynamic body so
    /// marked moves each substep to the first time of impact of its sweep
    /// against the solid static and kinematic colliders and tiles it can
    /// collide with, whatever its speed, then responds as
    /// [`World::set_sweep_response`] says (see [`SweepMode`] and "Swept
    /// collision in the world" in `docs/ARCHITECTURE.md`). Off by default;
    /// ignored for static and kinematic bodies.
    pub fn set_swept(&mut self, body: BodyId, swept: bool) -> Result<(), BuildError> {
        let b = self.live_mut(body)?;
        if b.swept != swept {
            b.swept = swept;
            self.touch(false);
        }
        Ok(())
    }

    /// What a sweep hit does to the body: slide (the default), stop or
    /// reflect ([`SweepResponse`]).
    pub fn set_sweep_response(
        &mut self,
        body: BodyId,
        response: SweepResponse,
    ) -> Result<(), BuildError> {
        self.live_mut(body)?.sweep_response = response;
        Ok(())
    }

    /// Moves a body by `d` now (checked against the world bound). Unlike
    /// [`World::set_position`] the move counts as motion: the body's
    /// displacement this tick includes it (a controller snapping a body to
    /// the ground after a step).
    pub fn shift(&mut self, body: BodyId, d: IVec2) -> Result<(), BuildError> {
        let b = self.live_mut(body)?;
        let p = b.pos.as_i64vec2() + d.as_i64vec2();
        crate::fixed::check_coord("body position x", p.x)?;
        crate::fixed::check_coord("body position y", p.y)?;
        b.pos = p.as_ivec2();
        if b.kind == BodyKind::Static && d != IVec2::ZERO {
            self.touch(true);
        }
        Ok(())
    }

    /// Sets the world's tilemap (replacing any); returns the previous one.
    pub fn set_tilemap(&mut self, map: Tilemap) -> Option<Tilemap> {
        let mut h = Fnv1a::default();
        h.ivec2(map.origin());
        h.i32(map.tile_size());
        h.u32(map.width());
        h.u32(map.height());
        for t in map.tiles() {
            h.u8(t.code());
        }
        self.tilemap_digest = h.finish();
        self.touch(false);
        self.tilemap.replace(map)
    }

    /// Removes the world's tilemap and returns it.
    pub fn take_tilemap(&mut self) -> Option<Tilemap> {
        self.tilemap_digest = 0;
        self.touch(false);
        self.tilemap.take()
    }

    /// The world's tilemap, if any.
    pub fn tilemap(&self) -> Option<&Tilemap> {
        self.tilemap.as_ref()
    }

    /// Attaches a collider to `body` after checking its offset.
    pub fn add_collider(
        &mut self,
        body: BodyId,
        desc: ColliderDesc,
    ) -> Result<ColliderId, BuildError> {
        let owner = self.live(body)?;
        let dynamic = owner.is_dynamic();
        let is_static = owner.kind == BodyKind::Static;
        desc.validate()?;
        let id = self.slots.len() as u32;
        let c = &mut self.colliders;
        let (b, d) = (body.0, &desc);
        let slot = match desc.shape {
            AnyShape::Point(s) => slot_of(c, make_data(id, b, dynamic, s, d)),
            AnyShape::Segment(s) => slot_of(c, make_data(id, b, dynamic, s, d)),
            AnyShape::Circle(s) => slot_of(c, make_data(id, b, dynamic, s, d)),
            AnyShape::Aabb(s) => slot_of(c, make_data(id, b, dynamic, s, d)),
            AnyShape::Obb(s) => slot_of(c, make_data(id, b, dynamic, s, d)),
            AnyShape::Polygon(s) => slot_of(c, make_data(id, b, dynamic, s, d)),
        };
        self.slots.push(slot);
        if dynamic {
            self.dynamic_colliders += 1;
        }
        self.touch(is_static);
        // Grow the contact buffer now rather than during the first ticks.
        let want = (self.dynamic_colliders * self.colliders.len()).min(RESERVE_CAP);
        self.contacts
            .reserve(want.saturating_sub(self.contacts.len()));
        let logged = self.logs.triggers.len();
        self.logs.triggers.reserve(want.saturating_sub(logged));
        Ok(ColliderId(id))
    }

    /// Adds a controller; returns its input slot (inputs are given to
    /// [`World::step`] in slot order).
    pub fn add_controller(&mut self, controller: Controller) -> Result<usize, BuildError> {
        let body = controller.body();
        if self.live(body)?.kind() == BodyKind::Static {
            return Err(BuildError::StaticController(body));
        }
        controller.validate()?;
        self.controllers.push(controller);
        Ok(self.controllers.len() - 1)
    }

    /// Sets a body's velocity (checked against the speed bound; static
    /// bodies cannot move).
    pub fn set_velocity(&mut self, body: BodyId, vel: IVec2) -> Result<(), BuildError> {
        let b = self.live_mut(body)?;
        body::validate_velocity(b.kind, vel)?;
        b.vel = vel;
        Ok(())
    }

    /// Teleports a body (checked against the world bound). Its displacement
    /// for the one-way rule restarts from there: it did not "come from"
    /// anywhere.
    pub fn set_position(&mut self, body: BodyId, pos: IVec2) -> Result<(), BuildError> {
        crate::fixed::check_coord("body position x", pos.x as i64)?;
        crate::fixed::check_coord("body position y", pos.y as i64)?;
        let b = self.live_mut(body)?;
        let moved = b.pos != pos;
        b.pos = pos;
        b.start = pos;
        if moved && b.kind == BodyKind::Static {
            self.touch(true);
        }
        Ok(())
    }

    /// Runs one fixed tick with one input per controller slot (missing
    /// inputs count as no button held); returns the tick's events.
    pub fn step(&mut self, inputs: &[Buttons]) -> &[Event] {
        self.refresh();
        match self.parallelism() {
            None => self.run_tick(inputs, false),
            Some(None) => self.run_tick(inputs, true),
            Some(Some(pool)) => pool.install(|| self.run_tick(inputs, true)),
        }
        &self.events
    }

    /// How detection runs this tick: `None` on this thread only,
    /// `Some(None)` on the current rayon pool, `Some(Some(pool))` on `pool`.
    fn parallelism(&mut self) -> Option<Option<Arc<rayon::ThreadPool>>> {
        let n = self.config.threads;
        if n == 1
            || self.config.broad_phase == BroadPhaseKind::BruteForce
            || self.layout.small
            || self.layout.moving.len() < PAR_MIN_MOVING
        {
            return None;
        }
        if self.pool.is_none() && n >= 2 && !self.pool_failed {
            match rayon::ThreadPoolBuilder::new()
                .num_threads(n as usize)
                .thread_name(|i| format!("ledge-world-{i}"))
                .build()
            {
                Ok(p) => self.pool = Some(Arc::new(p)),
                // Results never depend on threads: carry on with one.
                Err(_) => self.pool_failed = true,
            }
        }
        match &self.pool {
            Some(p) => Some(Some(p.clone())),
            None if n == 0 => Some(None),
            None => None,
        }
    }

    /// The tick itself (on whichever thread or pool `step` chose).
    fn run_tick(&mut self, inputs: &[Buttons], par: bool) {
        self.tick += 1;
        self.events.clear();
        self.logs.clear();
        for b in &mut self.bodies {
            b.start = b.pos;
            b.push = IVec2::ZERO;
            b.sides = Sides::NONE;
            b.carrier = None;
        }
        for (i, c) in self.controllers.iter().enumerate() {
            c.apply(inputs.get(i).copied().unwrap_or_default(), &mut self.bodies);
        }
        let carried = self.layout.carry && self.find_carriers();
        let n = self.config.substeps;
        for k in 0..n {
            if carried {
                self.carry_riders(k, n);
            }
            self.move_bodies(k, n);
            self.resolve_substep(par);
        }
        self.logs.emit(&mut self.events);
    }

    /// Sets the carrier of every rider standing flush on a kinematic box
    /// (see the module docs); returns whether any rider is carried. The
    /// specialised pipeline walks only the riders' and the carriers' boxes
    /// (same order, same answer); the general one every box against every
    /// box.
    fn find_carriers(&mut self) -> bool {
        let set = &self.colliders.aabbs.items;
        let bodies = &mut self.bodies;
        let mut any = false;
        let (riders, carriers) = (&self.layout.riders, &self.layout.carriers);
        if self.config.pipeline == Pipeline::Specialised
            && riders.len() * carriers.len() > SORTED_CARRIERS
        {
            // Many of both: carriers sorted by top edge (then set index), each
            // rider looks at those whose top is its bottom, in set order.
            let tops = &mut self.carrier_tops;
            tops.clear();
            tops.extend(carriers.iter().map(|&k| {
                let kc = &set[k as usize];
                (bodies[kc.body as usize].pos.y as i64 + kc.lo.y as i64, k)
            }));
            tops.sort_unstable();
            for &i in riders {
                let rc = &set[i as usize];
                let rb = &bodies[rc.body as usize];
                let bottom = rb.pos.y as i64 + rc.hi.y as i64;
                let from = tops.partition_point(|t| t.0 < bottom);
                let level = tops[from..]
                    .iter()
                    .take_while(|t| t.0 == bottom)
                    .map(|t| &set[t.1 as usize]);
                if let Some(c) = carrier_of(rc, bodies, level) {
                    bodies[rc.body as usize].carrier = Some(c);
                    any = true;
                }
            }
        } else if self.config.pipeline == Pipeline::Specialised {
            for &i in riders {
                let rc = &set[i as usize];
                let found = carrier_of(rc, bodies, carriers.iter().map(|&k| &set[k as usize]));
                if let Some(c) = found {
                    bodies[rc.body as usize].carrier = Some(c);
                    any = true;
                }
            }
        } else {
            for rc in set {
                if let Some(c) = carrier_of(rc, bodies, set.iter()) {
                    bodies[rc.body as usize].carrier = Some(c);
                    any = true;
                }
            }
        }
        any
    }

    /// Moves every carried rider by substep `k`'s share of its carrier's
    /// velocity (which is exactly the carrier's motion in that substep).
    fn carry_riders(&mut self, k: u32, n: u32) {
        for i in 0..self.bodies.len() {
            if let Some(c) = self.bodies[i].carrier {
                let d = substep_share(self.bodies[c as usize].vel, k, n);
                self.bodies[i].translate(d);
            }
        }
    }

    /// Moves every enabled non-static body by substep `k`'s share of its
    /// velocity. When the configuration and the scene call for sweeps
    /// ([`SweepMode`]), the bodies that are not swept move first (kinematic
    /// obstacles are where this substep leaves them), then each swept body,
    /// in id order, moves to its first impact (`sweep`).
    fn move_bodies(&mut self, k: u32, n: u32) {
        let mode = self.config.sweep;
        let sweeping = match mode {
            SweepMode::Off => false,
            SweepMode::Flagged => self.layout.features.swept,
            SweepMode::Auto { .. } => true,
        };
        let mut any = false;
        for b in &mut self.bodies {
            if b.kind == BodyKind::Static || b.vel == IVec2::ZERO || !b.enabled {
                continue;
            }
            let d = substep_share(b.vel, k, n);
            if sweeping && sweep::is_swept(mode, b, d) {
                any = true;
                continue;
            }
            b.translate(d);
        }
        if !any {
            return;
        }
        let scene = sweep::Scene {
            slots: &self.slots,
            cols: &self.colliders,
            layout: &self.layout,
            tiles: self.tilemap.as_ref(),
        };
        for i in 0..self.bodies.len() {
            let b = &self.bodies[i];
            if b.kind == BodyKind::Static || b.vel == IVec2::ZERO || !b.enabled {
                continue;
            }
            let d = substep_share(b.vel, k, n);
            if sweep::is_swept(mode, b, d) {
                sweep::move_swept(
                    &mut self.sweep_index,
                    self.config.broad_phase,
                    &scene,
                    &mut self.bodies,
                    i as u32,
                    d,
                    &mut self.logs,
                );
            }
        }
    }

    /// Detects and restitutes once per pass, up to the configured passes
    /// (passes that only propagate pushes are not counted); reports what is
    /// still wedged.
    fn resolve_substep(&mut self, par: bool) {
        self.detect(par);
        let triggers = self.layout.triggers;
        if triggers {
            restitute::log_triggers(&self.contacts, &mut self.logs.triggers);
        }
        self.solver.begin(self.bodies.len());
        // Passes that only propagate pushes to bodies not moved yet this
        // substep are free (at most one per dynamic body).
        let mut budget = self.config.restitution_iterations;
        while budget > 0 {
            if !restitute::has_solid(&self.contacts) {
                return;
            }
            let scene = Scene {
                cols: &self.colliders,
                slots: &self.slots,
                tiles: self.tilemap.as_ref(),
            };
            self.pushed.clear();
            let pass = self.solver.pass(
                &self.contacts,
                &mut self.bodies,
                scene,
                &mut self.logs.hits,
                &mut self.pushed,
            );
            if !pass.moved {
                // Nothing moved: the buffer is current and nothing more can change.
                break;
            }
            budget -= !pass.propagating as u32;
            self.redetect(par);
            if triggers {
                restitute::log_triggers(&self.contacts, &mut self.logs.triggers);
            }
        }
        let scene = Scene {
            cols: &self.colliders,
            slots: &self.slots,
            tiles: self.tilemap.as_ref(),
        };
        self.solver
            .log_squished(&self.contacts, &self.bodies, scene, &mut self.logs.squished);
    }

    /// Detection again after a restitution pass: only around the bodies it
    /// moved when the specialised pipeline allows (same result), else in
    /// full.
    fn redetect(&mut self, par: bool) {
        if self.layout.incremental && self.config.broad_phase != BroadPhaseKind::BruteForce {
            self.pushed.sort_unstable();
            self.pushed.dedup();
            let inp = detect::Input {
                slots: &self.slots,
                moving: &self.layout.moving,
                cols: &self.colliders,
                bodies: &self.bodies,
            };
            let tiles = if self.layout.tiles {
                self.tilemap.as_ref()
            } else {
                None
            };
            if detect::redetect(
                &mut self.detector,
                inp,
                &self.layout,
                &self.pushed,
                tiles,
                &mut self.tile_scratch,
                &mut self.contacts,
            ) {
                self.stats.incremental += 1;
                return;
            }
        }
        self.detect(par);
    }

    /// Fills the contact buffer: collider pairs (broad phase or brute
    /// force), then tiles.
    fn detect(&mut self, par: bool) {
        self.stats.full += 1;
        self.stats.parallel += par as u64;
        let inp = detect::Input {
            slots: &self.slots,
            moving: &self.layout.moving,
            cols: &self.colliders,
            bodies: &self.bodies,
        };
        if self.config.broad_phase == BroadPhaseKind::BruteForce {
            detect::detect_all(&self.colliders, &self.bodies, &mut self.contacts);
        } else if self.layout.small {
            detect::detect_small(inp, &self.layout.statics, &mut self.contacts);
        } else {
            detect::detect_broad(
                &mut self.detector,
                inp,
                self.layout.aabb_fast,
                par,
                &mut self.contacts,
            );
        }
        if !self.layout.tiles {
            return;
        }
        if let Some(map) = &self.tilemap {
            let boxes = (self.config.pipeline == Pipeline::Specialised).then_some(&self.layout);
            detect::detect_tiles(
                map,
                &self.colliders,
                &self.bodies,
                boxes,
                &mut self.tile_scratch,
                &mut self.contacts,
            );
        }
    }

    /// Ticks run so far.
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// The last tick's events (what [`World::step`] returned).
    pub fn events(&self) -> &[Event] {
        &self.events
    }

    /// The contact buffer as the last detection of the last tick left it.
    pub fn contacts(&self) -> &[ContactRecord] {
        &self.contacts
    }

    /// Runs detection now, at the bodies' current positions, without
    /// stepping (displacements for one-way rules are those since the start
    /// of the last tick): replaces the contact buffer with every contact,
    /// in canonical order, and returns it. Nothing else changes. For tools
    /// and tests (the tick detects by itself).
    pub fn detect_contacts(&mut self) -> &[ContactRecord] {
        self.refresh();
        match self.parallelism() {
            None => self.detect(false),
            Some(None) => self.detect(true),
            Some(Some(pool)) => pool.install(|| self.detect(true)),
        }
        &self.contacts
    }

    /// A body by id (`None` for a removed one).
    pub fn body(&self, id: BodyId) -> Option<&Body> {
        self.bodies.get(id.0 as usize).filter(|b| !b.removed)
    }

    /// Every body with its id, in id order (removed ones left out).
    pub fn bodies(&self) -> impl Iterator<Item = (BodyId, &Body)> + '_ {
        self.bodies
            .iter()
            .enumerate()
            .filter(|(_, b)| !b.removed)
            .map(|(i, b)| (BodyId(i as u32), b))
    }

    /// Number of collider ids issued (removed colliders included).
    pub fn collider_count(&self) -> usize {
        self.slots.len()
    }

    /// A collider, placed in the world, by id (`None` once removed).
    pub fn collider(&self, id: ColliderId) -> Option<ColliderView> {
        let s = self.slots.get(id.0 as usize)?;
        let i = s.index;
        if i == GONE {
            return None;
        }
        Some(match s.kind {
            ShapeKind::Point => self.view_of::<crate::shape::Point>(i),
            ShapeKind::Segment => self.view_of::<crate::shape::Segment>(i),
            ShapeKind::Circle => self.view_of::<crate::shape::Circle>(i),
            ShapeKind::Aabb => self.view_of::<crate::shape::Aabb>(i),
            ShapeKind::Obb => self.view_of::<crate::shape::Obb>(i),
            ShapeKind::Polygon => self.view_of::<crate::shape::ConvexPolygon>(i),
        })
    }

    /// Every collider, placed in the world, in id order (for rendering and
    /// tools; the simulation never uses this view).
    pub fn colliders(&self) -> impl Iterator<Item = ColliderView> + '_ {
        (0..self.slots.len() as u32).filter_map(|i| self.collider(ColliderId(i)))
    }

    fn view_of<S: Stored>(&self, i: u32) -> ColliderView {
        let d = &S::set(&self.colliders).items[i as usize];
        view(d, self.bodies[d.body as usize].pos)
    }

    /// The controllers, in input-slot order.
    pub fn controllers(&self) -> &[Controller] {
        &self.controllers
    }

    /// A stable 64-bit hash of the whole simulation state: FNV-1a over an
    /// explicit little-endian encoding of the tick, the configuration, every
    /// body (all fields), every collider and every controller, in id order,
    /// and the tilemap (hashed once when set). Equal on every platform and
    /// build for equal states.
    pub fn state_hash(&self) -> u64 {
        let mut h = Fnv1a::default();
        h.u64(self.tick);
        h.u32(self.config.substeps);
        h.u32(self.config.restitution_iterations);
        h.u32(self.bodies.len() as u32);
        for b in &self.bodies {
            h.u8(b.kind.code());
            h.ivec2(b.pos);
            h.ivec2(b.vel);
            h.u32(b.mass);
            h.u8(b.sides.0);
            h.ivec2(b.start);
            h.ivec2(b.push);
            h.u8(b.flag_bits());
            h.u32(b.carrier.unwrap_or(u32::MAX));
            for r in b.swept_rest {
                let (c, n) = r.unwrap_or((u32::MAX, IVec2::ZERO));
                h.u32(c);
                h.ivec2(n);
            }
        }
        h.u64(self.tilemap_digest);
        h.u32(self.slots.len() as u32);
        for c in self.colliders() {
            h.u32(c.id.0);
            h.u32(c.body.0);
            h.ivec2(c.offset);
            hash_shape(&mut h, &c.shape);
            h.u8(matches!(c.mode, ColliderMode::Trigger) as u8);
            h.u32(c.layer);
            h.u32(c.mask);
            h.u8(OneWay::code(c.one_way));
            h.u16(c.tag);
        }
        h.u32(self.controllers.len() as u32);
        for c in &self.controllers {
            c.hash(&mut h);
        }
        h.finish()
    }
}

/// The body of the first of `carriers` that rider box `rc` stands flush on
/// (see the module docs), if `rc` is a solid box of an enabled, not yet
/// carried dynamic rider.
#[inline]
fn carrier_of<'a>(
    rc: &ColliderData<crate::shape::Aabb>,
    bodies: &[Body],
    mut carriers: impl Iterator<Item = &'a ColliderData<crate::shape::Aabb>>,
) -> Option<u32> {
    let rb = &bodies[rc.body as usize];
    if !rc.dynamic || !rc.solid || !rb.rider || !rb.enabled || rb.carrier.is_some() {
        return None;
    }
    let bottom = rb.pos.y as i64 + rc.hi.y as i64;
    let (l, r) = (rb.pos.x + rc.lo.x, rb.pos.x + rc.hi.x);
    carriers
        .find(|kc| {
            let kb = &bodies[kc.body as usize];
            kb.kind == BodyKind::Kinematic
                && kb.enabled
                && kc.solid
                && rc.layer & kc.mask != 0
                && kc.layer & rc.mask != 0
                && match kc.one_way {
                    None => true,
                    Some(OneWay::Up) => !rb.drop_through,
                    Some(_) => false,
                }
                && kb.pos.y as i64 + kc.lo.y as i64 == bottom
                && kb.pos.x + kc.lo.x < r
                && kb.pos.x + kc.hi.x > l
        })
        .map(|kc| kc.body)
}

/// How a world's detections ran ([`World::detection_stats`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct DetectionStats {
    /// Full detections: every pair (brute force, direct pairs of a small
    /// scene, or the broad phase).
    pub full: u64,
    /// Re-detections after a restitution pass done only around the bodies
    /// the pass moved ([`Pipeline::Specialised`]).
    pub incremental: u64,
    /// Full detections split over threads ([`SimConfig::threads`]).
    pub parallel: u64,
}

/// Substep `k` of `n`'s share of velocity `v`: `floor(v (k+1) / n) -
/// floor(v k / n)` per axis. The shares of `n` substeps sum to `v` exactly and
/// differ by at most one unit.
#[inline]
pub fn substep_share(v: IVec2, k: u32, n: u32) -> IVec2 {
    let f = |v: i32| {
        let (v, k, n) = (v as i64, k as i64, n as i64);
        ((v * (k + 1)).div_euclid(n) - (v * k).div_euclid(n)) as i32
    };
    IVec2::new(f(v.x), f(v.y))
}

/// Removes the colliders of body `body` from `set` (order kept), marks their
/// ids gone and re-points the ids of those that moved; returns how many went.
fn remove_colliders<S>(
    set: &mut ColliderSet<S>,
    _kind: ShapeKind,
    body: u32,
    slots: &mut [Slot],
) -> usize {
    let before = set.items.len();
    for c in set.items.iter().filter(|c| c.body == body) {
        slots[c.id as usize].index = GONE;
    }
    set.items.retain(|c| c.body != body);
    for (i, c) in set.items.iter().enumerate() {
        slots[c.id as usize].index = i as u32;
    }
    before - set.items.len()
}

/// Stores a new collider in its kind's set; returns its [`Slot`].
fn slot_of<S: Stored>(cols: &mut Colliders, d: ColliderData<S>) -> Slot {
    let slot = Slot {
        kind: S::KIND,
        index: 0,
        body: d.body,
        lo: d.lo,
        hi: d.hi,
        layer: d.layer,
        mask: d.mask,
        solid: d.solid,
        dynamic: d.dynamic,
        one_way: d.one_way,
        tag: d.tag,
    };
    Slot {
        index: cols.push(d),
        ..slot
    }
}

/// Feeds a shape's kind and parameters to the hash.
fn hash_shape(h: &mut Fnv1a, s: &AnyShape) {
    match s {
        AnyShape::Point(_) => h.u8(0),
        AnyShape::Segment(s) => {
            h.u8(1);
            h.ivec2(s.a());
            h.ivec2(s.b());
        }
        AnyShape::Circle(s) => {
            h.u8(2);
            h.i32(s.radius());
        }
        AnyShape::Aabb(s) => {
            h.u8(3);
            h.ivec2(s.half());
        }
        AnyShape::Obb(s) => {
            h.u8(4);
            h.ivec2(s.u());
            h.ivec2(s.v());
        }
        AnyShape::Polygon(s) => {
            h.u8(5);
            h.u8(s.vertices().len() as u8);
            for &v in s.vertices() {
                h.ivec2(v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn substep_shares_sum_to_the_velocity() {
        for n in 1..=7u32 {
            for v in [
                -1000,
                -7,
                -1,
                0,
                1,
                5,
                13,
                999,
                crate::fixed::MAX_SPEED,
                -crate::fixed::MAX_SPEED,
            ] {
                let v = IVec2::new(v, -v);
                let parts: Vec<IVec2> = (0..n).map(|k| substep_share(v, k, n)).collect();
                assert_eq!(parts.iter().copied().sum::<IVec2>(), v);
                let lo = parts.iter().map(|p| p.x).min().unwrap();
                let hi = parts.iter().map(|p| p.x).max().unwrap();
                assert!(hi - lo <= 1);
            }
        }
    }
}
