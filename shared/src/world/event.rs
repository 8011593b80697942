//! Events: what happened during a tick, in a deterministic order.

use glam::IVec2;
use serde::{Deserialize, Serialize};

use super::body::Sides;
use super::id::{BodyId, ColliderId};

/// Something that happened during a tick.
///
/// [`super::World::step`] returns a tick's events in this order: all
/// `Contact`s sorted by `(body, collider, other_collider)`, then all
/// `Trigger`s sorted by `(trigger, collider)`, then all `Squished` sorted by
/// body, then all `SweptHit`s sorted by body (a body's own hits in the order
/// they happened). Each pair is reported at most once per tick, whatever the
/// number of substeps and restitution passes; a `SweptHit` once per impact
/// (at most once per body and substep).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Event {
    /// A solid contact pushed `body` (its `collider` out of `other_collider`).
    Contact {
        /// The body that was pushed.
        body: BodyId,
        /// Its collider in the contact.
        collider: ColliderId,
        /// The body it was pushed out of.
        other_body: BodyId,
        /// That body's collider.
        other_collider: ColliderId,
        /// That collider's tag (wall, floor, platform...).
        other_tag: u16,
        /// The sides of `body` that touched it.
        sides: Sides,
    },
    /// A solid collider overlapped a trigger.
    Trigger {
        /// The body whose solid collider is in the trigger.
        body: BodyId,
        /// That solid collider.
        collider: ColliderId,
        /// The body the trigger belongs to.
        trigger_body: BodyId,
        /// The trigger collider.
        trigger: ColliderId,
        /// The trigger's tag.
        tag: u16,
        /// The solid collider's tag.
        other_tag: u16,
    },
    /// A dynamic body still overlapped a solid after the last restitution
    /// pass of a substep: it is wedged and could not be resolved.
    Squished {
        /// The body.
        body: BodyId,
    },
    /// A swept body's motion was stopped by the first time of impact of its
    /// sweep ([`super::SweepMode`]): it stopped at the contact and its
    /// velocity was changed by its [`super::SweepResponse`]. Reported once
    /// per impact: a body resting against the same surface and pushing into
    /// it again (a hit at time 0 on the same collider, same normal) is not
    /// reported again until a sweep of it hits something else or nothing.
    SweptHit {
        /// The swept body.
        body: BodyId,
        /// Its collider that hit first.
        collider: ColliderId,
        /// The body hit ([`BodyId::TILEMAP`] for a tile).
        other_body: BodyId,
        /// The collider hit ([`ColliderId::TILEMAP`] for a tile).
        other_collider: ColliderId,
        /// That collider's tag ([`super::TILEMAP_TAG`] for a tile).
        other_tag: u16,
        /// Surface normal at the impact, out of the obstacle towards the
        /// body, reduced (gcd 1): `(-1, 0)` for the left face of a wall.
        normal: IVec2,
        /// Where the body stopped (its position, in units).
        pos: IVec2,
        /// The tile hit (tile coordinates) for a tile, else zero.
        tile: IVec2,
    },
}

/// A push, logged by restitution (possibly many times a tick per pair).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Hit {
    pub body: u32,
    pub collider: u32,
    pub other_body: u32,
    pub other_collider: u32,
    pub other_tag: u16,
    pub sides: Sides,
}

/// A trigger overlap, logged after each detection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct TriggerHit {
    pub body: u32,
    pub collider: u32,
    pub trigger_body: u32,
    pub trigger: u32,
    pub tag: u16,
    pub other_tag: u16,
}

/// The per-tick logs events are assembled from (reused, never shrunk).
#[derive(Debug, Clone, Default)]
pub(crate) struct Logs {
    pub hits: Vec<Hit>,
    pub triggers: Vec<TriggerHit>,
    pub squished: Vec<u32>,
    /// Swept hits (`Event::SweptHit` only) with their body and their rank
    /// in the order they happened.
    pub swept: Vec<(u32, u32, Event)>,
}

impl Logs {
    pub fn clear(&mut self) {
        self.hits.clear();
        self.triggers.clear();
        self.squished.clear();
        self.swept.clear();
    }

    /// Sorts, merges and appends the tick's events to `out` (no allocation
    /// once `out` has grown to the largest tick: unstable sorts only).
    pub fn emit(&mut self, out: &mut Vec<Event>) {
        self.hits
            .sort_unstable_by_key(|h| (h.body, h.collider, h.other_collider));
        let mut i = 0;
        while i < self.hits.len() {
            let h = self.hits[i];
            let mut sides = h.sides;
            let mut j = i + 1;
            while j < self.hits.len()
                && (
                    self.hits[j].body,
                    self.hits[j].collider,
                    self.hits[j].other_collider,
                ) == (h.body, h.collider, h.other_collider)
            {
                sides |= self.hits[j].sides;
                j += 1;
            }
            out.push(Event::Contact {
                body: BodyId(h.body),
                collider: ColliderId(h.collider),
                other_body: BodyId(h.other_body),
                other_collider: ColliderId(h.other_collider),
                other_tag: h.other_tag,
                sides,
            });
            i = j;
        }
        self.triggers
            .sort_unstable_by_key(|t| (t.trigger, t.collider));
        self.triggers.dedup_by_key(|t| (t.trigger, t.collider));
        for t in &self.triggers {
            out.push(Event::Trigger {
                body: BodyId(t.body),
                collider: ColliderId(t.collider),
                trigger_body: BodyId(t.trigger_body),
                trigger: ColliderId(t.trigger),
                tag: t.tag,
                other_tag: t.other_tag,
            });
        }
        self.squished.sort_unstable();
        self.squished.dedup();
        for &b in &self.squished {
            out.push(Event::Squished { body: BodyId(b) });
        }
        self.swept.sort_unstable_by_key(|s| (s.0, s.1));
        out.extend(self.swept.iter().map(|s| s.2));
    }

    /// Logs a swept hit of `body` (after those already logged this tick).
    pub fn swept_hit(&mut self, body: u32, e: Event) {
        let rank = self.swept.len() as u32;
        self.swept.push((body, rank, e));
    }
}
