//! Bodies, colliders and the tick pipeline.
//!
//! ```text
//! step(inputs): controllers -> for each substep { move -> detect -> restitute
//!               (-> detect again after each pass that moved something) } -> events
//! ```
//!
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
pub use error::BuildError;
pub use event::Event;
pub use restitute::ONE_WAY_SLOP;

use crate::input::Buttons;
use crate::shape::ShapeKind;
use glam::IVec2;

use collider::{make_data, view, Colliders, Stored};
use event::Logs;
use hash::Fnv1a;

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
}

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
        }
    }

    /// The configuration.
    pub fn config(&self) -> &SimConfig {
        &self.config
    }

    /// Adds a body after checking its position, velocity and mass.
    pub fn add_body(&mut self, desc: BodyDesc) -> Result<BodyId, BuildError> {
        desc.validate()?;
        let id = BodyId(self.bodies.len() as u32);
        self.bodies.push(Body::new(&desc));
        Ok(id)
    }

    /// Attaches a collider to `body` after checking its offset.
    pub fn add_collider(
        &mut self,
        body: BodyId,
        desc: ColliderDesc,
    ) -> Result<ColliderId, BuildError> {
        let dynamic = self
            .body(body)
            .ok_or(BuildError::NoBody(body))?
            .is_dynamic();
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
        if self.body(body).ok_or(BuildError::NoBody(body))?.kind() == BodyKind::Static {
            return Err(BuildError::StaticController(body));
        }
        controller.validate()?;
        self.controllers.push(controller);
        Ok(self.controllers.len() - 1)
    }

    /// Sets a body's velocity (checked against the speed bound; static
    /// bodies cannot move).
    pub fn set_velocity(&mut self, body: BodyId, vel: IVec2) -> Result<(), BuildError> {
        let b = self
            .bodies
            .get_mut(body.0 as usize)
            .ok_or(BuildError::NoBody(body))?;
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
        let b = self
            .bodies
            .get_mut(body.0 as usize)
            .ok_or(BuildError::NoBody(body))?;
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
        }
        for (i, c) in self.controllers.iter().enumerate() {
            c.apply(inputs.get(i).copied().unwrap_or_default(), &mut self.bodies);
        }
        let n = self.config.substeps;
        for k in 0..n {
            self.move_bodies(k, n);
            self.resolve_substep();
        }
        self.logs.emit(&mut self.events);
        &self.events
    }

    /// Moves every non-static body by substep `k`'s share of its velocity.
    fn move_bodies(&mut self, k: u32, n: u32) {
        for b in &mut self.bodies {
            if b.kind == BodyKind::Static || b.vel == IVec2::ZERO {
                continue;
            }
            let d = substep_share(b.vel, k, n);
            b.translate(d);
        }
    }

    /// Detects and restitutes once per pass, up to the configured passes;
    /// reports what is still wedged.
    fn resolve_substep(&mut self) {
        detect::detect_all(&self.colliders, &self.bodies, &mut self.contacts);
        restitute::log_triggers(&self.contacts, &mut self.logs.triggers);
        for _ in 0..self.config.restitution_iterations {
            if !restitute::has_solid(&self.contacts) {
                return;
            }
            if !restitute::pass(
                &mut self.contacts,
                &mut self.bodies,
                &self.colliders,
                &mut self.logs.hits,
            ) {
                // Nothing moved: the buffer is current and nothing more can change.
                break;
            }
            detect::detect_all(&self.colliders, &self.bodies, &mut self.contacts);
            restitute::log_triggers(&self.contacts, &mut self.logs.triggers);
        }
        restitute::log_squished(
            &self.contacts,
            &self.bodies,
            &self.colliders,
            &mut self.logs.squished,
        );
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

    /// A body by id.
    pub fn body(&self, id: BodyId) -> Option<&Body> {
        self.bodies.get(id.0 as usize)
    }

    /// Every body with its id, in id order.
    pub fn bodies(&self) -> impl Iterator<Item = (BodyId, &Body)> + '_ {
        self.bodies
            .iter()
            .enumerate()
            .map(|(i, b)| (BodyId(i as u32), b))
    }

    /// Number of colliders.
    pub fn collider_count(&self) -> usize {
        self.collider_index.len()
    }

    /// A collider, placed in the world, by id.
    pub fn collider(&self, id: ColliderId) -> Option<ColliderView> {
        let &(kind, i) = self.collider_index.get(id.0 as usize)?;
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
    /// body (all fields), every collider and every controller, in id order.
    /// Equal on every platform and build for equal states.
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
        }
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
