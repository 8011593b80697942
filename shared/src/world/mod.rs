//! Bodies, colliders and the tick pipeline.
//!
//! ```text
//! step(inputs): controllers -> find carriers -> for each substep { carry riders
//!               -> move -> detect (colliders, then tiles) -> restitute
//!               (-> detect again after each pass that moved something) } -> events
//! ```
//!
//! * **Tilemap** ([`World::set_tilemap`]): detection asks the tilemap about
//!   every solid box collider of an enabled dynamic body
//!   ([`crate::tilemap::Tilemap::box_contacts`]); each tile contact becomes a
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
//! * **Removal** ([`World::remove_body`]) frees a body's slot (reused by the
//!   next [`World::add_body`]) and drops its colliders and controllers;
//!   [`World::set_enabled`] only suspends a body.
//! * [`body`]: static, kinematic and dynamic bodies, touched [`Sides`];
//! * [`collider`]: shapes attached to bodies, one `Vec` per shape kind;
//! * [`contact`]: the element of the single, reused contact buffer;
//! * `detect`: one monomorphised loop per pair of shape kinds;
//! * `restitute`: largest overlap first, no push-back, mass split;
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
mod restitute;

pub use body::{Body, BodyDesc, BodyId, BodyKind, Sides};
pub use collider::{AnyShape, ColliderDesc, ColliderId, ColliderMode, ColliderView, OneWay};
pub use config::SimConfig;
pub use contact::{ContactKind, ContactRecord};
pub use controller::{Controller, Mover, MoverConfig};
pub use detect::{TILEMAP_LAYER, TILEMAP_TAG};
pub use error::BuildError;
pub use event::Event;
pub use restitute::ONE_WAY_SLOP;

use crate::input::Buttons;
use crate::shape::ShapeKind;
use crate::tilemap::{TileContact, Tilemap};
use glam::IVec2;

use collider::{make_data, view, ColliderSet, Colliders, Stored};
use event::Logs;
use hash::Fnv1a;
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
    /// Where each collider lives, by id: its kind and index in that kind's set.
    collider_index: Vec<(ShapeKind, u32)>,
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
}

/// `collider_index` entry of a removed collider.
const GONE: u32 = u32::MAX;

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
            collider_index: Vec::new(),
            dynamic_colliders: 0,
            controllers: Vec::new(),
            contacts: Vec::new(),
            logs: Logs::default(),
            events: Vec::new(),
            tilemap: None,
            tilemap_digest: 0,
            tile_scratch: Vec::new(),
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
        if let Some(i) = self.bodies.iter().position(|b| b.removed) {
            self.bodies[i] = body;
            return Ok(BodyId(i as u32));
        }
        let id = BodyId(self.bodies.len() as u32);
        self.bodies.push(body);
        Ok(id)
    }

    /// Removes a body: drops its colliders (their ids are never reused) and
    /// the controllers driving it (later controllers move down one input
    /// slot each), and frees its slot for the next [`World::add_body`].
    pub fn remove_body(&mut self, id: BodyId) -> Result<(), BuildError> {
        let dynamic = self.live(id)?.is_dynamic();
        let c = &mut self.colliders;
        let ix = &mut self.collider_index;
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
        self.live_mut(body)?.enabled = enabled;
        Ok(())
    }

    /// Makes a body a rider (`true`): kinematic boxes it stands on carry it
    /// (see the module docs). Off by default.
    pub fn set_rider(&mut self, body: BodyId, rider: bool) -> Result<(), BuildError> {
        self.live_mut(body)?.rider = rider;
        Ok(())
    }

    /// While set, one-way colliders and one-way tiles never push the body,
    /// and one-way boxes do not carry it (a player dropping through a
    /// platform).
    pub fn set_drop_through(&mut self, body: BodyId, drop: bool) -> Result<(), BuildError> {
        self.live_mut(body)?.drop_through = drop;
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
        self.tilemap.replace(map)
    }

    /// Removes the world's tilemap and returns it.
    pub fn take_tilemap(&mut self) -> Option<Tilemap> {
        self.tilemap_digest = 0;
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
        let dynamic = self.live(body)?.is_dynamic();
        desc.validate()?;
        let id = self.collider_index.len() as u32;
        let c = &mut self.colliders;
        let (b, d) = (body.0, &desc);
        let entry = match desc.shape {
            AnyShape::Point(s) => (ShapeKind::Point, c.push(make_data(id, b, dynamic, s, d))),
            AnyShape::Segment(s) => (ShapeKind::Segment, c.push(make_data(id, b, dynamic, s, d))),
            AnyShape::Circle(s) => (ShapeKind::Circle, c.push(make_data(id, b, dynamic, s, d))),
            AnyShape::Aabb(s) => (ShapeKind::Aabb, c.push(make_data(id, b, dynamic, s, d))),
            AnyShape::Obb(s) => (ShapeKind::Obb, c.push(make_data(id, b, dynamic, s, d))),
            AnyShape::Polygon(s) => (ShapeKind::Polygon, c.push(make_data(id, b, dynamic, s, d))),
        };
        self.collider_index.push(entry);
        if dynamic {
            self.dynamic_colliders += 1;
        }
        // Grow the contact buffer now rather than during the first ticks.
        let want = (self.dynamic_colliders * self.colliders.len()).min(RESERVE_CAP);
        self.contacts
            .reserve(want.saturating_sub(self.contacts.len()));
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
        b.pos = pos;
        b.start = pos;
        Ok(())
    }

    /// Runs one fixed tick with one input per controller slot (missing
    /// inputs count as no button held); returns the tick's events.
    pub fn step(&mut self, inputs: &[Buttons]) -> &[Event] {
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
        let carried = self.find_carriers();
        let n = self.config.substeps;
        for k in 0..n {
            if carried {
                self.carry_riders(k, n);
            }
            self.move_bodies(k, n);
            self.resolve_substep();
        }
        self.logs.emit(&mut self.events);
        &self.events
    }

    /// Sets the carrier of every rider standing flush on a kinematic box
    /// (see the module docs); returns whether any rider is carried.
    fn find_carriers(&mut self) -> bool {
        let set = &self.colliders.aabbs.items;
        let mut any = false;
        for rc in set {
            let rb = &self.bodies[rc.body as usize];
            if !rc.dynamic || !rc.solid || !rb.rider || !rb.enabled || rb.carrier.is_some() {
                continue;
            }
            let bottom = rb.pos.y as i64 + rc.hi.y as i64;
            let (l, r) = (rb.pos.x + rc.lo.x, rb.pos.x + rc.hi.x);
            let found = set.iter().find(|kc| {
                let kb = &self.bodies[kc.body as usize];
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
            });
            if let Some(kc) = found {
                let body = kc.body;
                self.bodies[rc.body as usize].carrier = Some(body);
                any = true;
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
    /// velocity.
    fn move_bodies(&mut self, k: u32, n: u32) {
        for b in &mut self.bodies {
            if b.kind == BodyKind::Static || b.vel == IVec2::ZERO || !b.enabled {
                continue;
            }
            let d = substep_share(b.vel, k, n);
            b.translate(d);
        }
    }

    /// Detects and restitutes once per pass, up to the configured passes;
    /// reports what is still wedged.
    fn resolve_substep(&mut self) {
        self.detect();
        restitute::log_triggers(&self.contacts, &mut self.logs.triggers);
        let scene = Scene {
            cols: &self.colliders,
            tiles: self.tilemap.as_ref(),
        };
        for _ in 0..self.config.restitution_iterations {
            if !restitute::has_solid(&self.contacts) {
                return;
            }
            if !restitute::pass(
                &mut self.contacts,
                &mut self.bodies,
                scene,
                &mut self.logs.hits,
            ) {
                // Nothing moved: the buffer is current and nothing more can change.
                break;
            }
            detect::detect_all(scene.cols, &self.bodies, &mut self.contacts);
            if let Some(map) = scene.tiles {
                detect::detect_tiles(
                    map,
                    scene.cols,
                    &self.bodies,
                    &mut self.tile_scratch,
                    &mut self.contacts,
                );
            }
            restitute::log_triggers(&self.contacts, &mut self.logs.triggers);
        }
        restitute::log_squished(&self.contacts, &self.bodies, scene, &mut self.logs.squished);
    }

    /// Fills the contact buffer: collider pairs, then tiles.
    fn detect(&mut self) {
        detect::detect_all(&self.colliders, &self.bodies, &mut self.contacts);
        if let Some(map) = &self.tilemap {
            detect::detect_tiles(
                map,
                &self.colliders,
                &self.bodies,
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
        self.collider_index.len()
    }

    /// A collider, placed in the world, by id (`None` once removed).
    pub fn collider(&self, id: ColliderId) -> Option<ColliderView> {
        let &(kind, i) = self.collider_index.get(id.0 as usize)?;
        if i == GONE {
            return None;
        }
        Some(match kind {
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
        (0..self.collider_index.len() as u32).filter_map(|i| self.collider(ColliderId(i)))
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
        }
        h.u64(self.tilemap_digest);
        h.u32(self.collider_index.len() as u32);
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
    kind: ShapeKind,
    body: u32,
    index: &mut [(ShapeKind, u32)],
) -> usize {
    let before = set.items.len();
    for c in set.items.iter().filter(|c| c.body == body) {
        index[c.id as usize] = (kind, GONE);
    }
    set.items.retain(|c| c.body != body);
    for (i, c) in set.items.iter().enumerate() {
        index[c.id as usize] = (kind, i as u32);
    }
    before - set.items.len()
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
