//! What a scene uses, and the passes and index lists built from it.
//!
//! Computed when the world's content changes (a collider added, a body
//! removed, enabled or made a rider, a static body moved, the tilemap set),
//! never per tick: [`SceneFeatures`] says which features the scene has,
//! [`Layout`] keeps the lists the specialised passes walk instead of every
//! collider, and which passes run at all.

use crate::shape::ShapeKind;
use crate::tilemap::{Tile, Tilemap};
use glam::IVec2;

use super::body::{Body, BodyKind};
use super::collider::{Colliders, OneWay};
use super::config::Pipeline;
use super::id::TILEMAP_LAYER;

/// What a scene uses: shape kinds, tilemap features, one-way colliders,
/// triggers, moving platforms and riders. [`super::World::features`]
/// reports it; the specialised pipeline ([`super::Pipeline::Specialised`])
/// runs only the passes it implies.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct SceneFeatures {
    /// Shape kinds of the colliders, one bit per [`ShapeKind`] (bit
    /// `kind as u8`); see [`SceneFeatures::has_kind`].
    pub kinds: u8,
    /// The world has a tilemap with at least one non-empty tile.
    pub tilemap: bool,
    /// Some tile is a slope.
    pub slopes: bool,
    /// Some tile is one-way.
    pub one_way_tiles: bool,
    /// Some tile is a hazard (a trigger).
    pub hazard_tiles: bool,
    /// Some collider is one-way.
    pub one_way: bool,
    /// Some collider is a trigger.
    pub triggers: bool,
    /// Some kinematic body has a collider (moving platforms).
    pub kinematic: bool,
    /// Some body is a rider.
    pub riders: bool,
    /// Some collider is rotated: an oriented box or a polygon.
    pub rotated: bool,
    /// Some dynamic body is marked for swept collision
    /// ([`super::World::set_swept`]).
    pub swept: bool,
}

impl SceneFeatures {
    /// Whether some collider has shape kind `k`.
    #[inline]
    pub fn has_kind(&self, k: ShapeKind) -> bool {
        self.kinds & (1 << k as u8) != 0
    }

    /// Whether every collider is an axis-aligned box (or there is none): the
    /// scene detects through the broad phase's AABB fast path.
    #[inline]
    pub fn aabb_only(&self) -> bool {
        self.kinds & !(1 << ShapeKind::Aabb as u8) == 0
    }
}

/// A collider as detection sees it, by id: where it is stored and what the
/// pair filters and contact records need, without touching its shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Slot {
    pub kind: ShapeKind,
    /// Index in its kind's set ([`GONE`] once removed).
    pub index: u32,
    pub body: u32,
    /// Local bounding box around the body position.
    pub lo: IVec2,
    pub hi: IVec2,
    pub layer: u32,
    pub mask: u32,
    pub solid: bool,
    pub dynamic: bool,
    pub one_way: Option<OneWay>,
    pub tag: u16,
}

/// A non-box collider the tilemap is asked about: `(collider id, kind,
/// index in its kind's set)`.
pub(crate) type TileShapeRef = (u32, ShapeKind, u32);

/// [`Slot::index`] of a removed collider.
pub(crate) const GONE: u32 = u32::MAX;

/// The specialised pipeline tests pairs directly, without the broad phase,
/// while (moving colliders) x (all colliders) is at most this: below it the
/// broad phase's fixed cost per detection (update, batch plan, canonical
/// sort) exceeds the pair tests it saves. Measured on `scenes::boxes` and
/// `scenes::tile_room` with 2 to 128 bodies: direct tests win up to about
/// 16 moving boxes (products near 300: 3.5 vs 4.1 µs per tick), the broad
/// phase from 32 (products near 1,100: 6.7 vs 10.5 µs).
pub(crate) const SMALL_PAIRS: usize = 400;

/// The passes a tick runs and the lists they walk.
#[derive(Debug, Clone, Default)]
pub(crate) struct Layout {
    pub features: SceneFeatures,
    /// Collider ids of kinematic and dynamic bodies, in id order: the broad
    /// phase's dynamic set.
    pub moving: Vec<u32>,
    /// Collider ids of static bodies, in id order.
    pub statics: Vec<u32>,
    /// `moving` grouped by body: body `b`'s colliders are
    /// `by_body[by_body_start[b]..by_body_start[b + 1]]`, ascending.
    pub by_body: Vec<u32>,
    pub by_body_start: Vec<u32>,
    /// AABB-set indices of solid boxes of kinematic bodies (carriers), in
    /// set order.
    pub carriers: Vec<u32>,
    /// AABB-set indices of solid boxes of dynamic rider bodies, in set order.
    pub riders: Vec<u32>,
    /// AABB-set indices of the boxes the tilemap is asked about (solid, of a
    /// dynamic body, mask with [`TILEMAP_LAYER`]), in set order.
    pub tile_boxes: Vec<u32>,
    /// The other colliders the tilemap is asked about (same filters; any
    /// kind but a box, [`Tilemap::shape_contacts`]), in collider id order:
    /// empty in box-only scenes, which then pay nothing for them.
    pub tile_shapes: Vec<TileShapeRef>,
    /// Detect through the broad phase's AABB fast path.
    pub aabb_fast: bool,
    /// Detect by testing moving colliders against all, no broad phase.
    pub small: bool,
    /// Look for riders standing on carriers.
    pub carry: bool,
    /// Query the tilemap.
    pub tiles: bool,
    /// Log trigger contacts.
    pub triggers: bool,
    /// Re-detect after a restitution pass only around the bodies it moved.
    pub incremental: bool,
}

impl Layout {
    /// The moving colliders of body `b`.
    #[inline]
    pub fn colliders_of(&self, b: u32) -> &[u32] {
        let b = b as usize;
        &self.by_body[self.by_body_start[b] as usize..self.by_body_start[b + 1] as usize]
    }
}

impl Layout {
    /// Recomputes the features and the lists from the world's content.
    pub fn rebuild(
        &mut self,
        pipeline: Pipeline,
        slots: &[Slot],
        cols: &Colliders,
        bodies: &[Body],
        map: Option<&Tilemap>,
    ) {
        let f = features(slots, bodies, map);
        self.moving.clear();
        self.statics.clear();
        for (id, s) in slots.iter().enumerate() {
            if s.index == GONE {
                continue;
            }
            if bodies[s.body as usize].kind == BodyKind::Static {
                self.statics.push(id as u32);
            } else {
                self.moving.push(id as u32);
            }
        }
        self.carriers.clear();
        self.riders.clear();
        self.tile_boxes.clear();
        for (i, c) in cols.aabbs.items.iter().enumerate() {
            let b = &bodies[c.body as usize];
            if c.solid && b.kind == BodyKind::Kinematic {
                self.carriers.push(i as u32);
            }
            if c.solid && c.dynamic && b.rider {
                self.riders.push(i as u32);
            }
            if c.solid && c.dynamic && c.mask & TILEMAP_LAYER != 0 {
                self.tile_boxes.push(i as u32);
            }
        }
        self.tile_shapes.clear();
        for (id, s) in slots.iter().enumerate() {
            if s.index != GONE
                && s.kind != ShapeKind::Aabb
                && s.solid
                && s.dynamic
                && s.mask & TILEMAP_LAYER != 0
            {
                self.tile_shapes.push((id as u32, s.kind, s.index));
            }
        }
        self.features = f;
        let special = pipeline == Pipeline::Specialised;
        self.aabb_fast = special && f.aabb_only();
        // Counting sort of the moving colliders by body (ids stay ascending).
        self.by_body_start.clear();
        self.by_body_start.resize(bodies.len() + 1, 0);
        for &id in &self.moving {
            self.by_body_start[slots[id as usize].body as usize + 1] += 1;
        }
        for b in 0..bodies.len() {
            self.by_body_start[b + 1] += self.by_body_start[b];
        }
        self.by_body.clear();
        self.by_body.resize(self.moving.len(), 0);
        let mut at = self.by_body_start.clone();
        for &id in &self.moving {
            let b = slots[id as usize].body as usize;
            self.by_body[at[b] as usize] = id;
            at[b] += 1;
        }
        let live = self.moving.len() + self.statics.len();
        self.small = special && self.moving.len().saturating_mul(live) <= SMALL_PAIRS;
        self.carry = !special || (!self.riders.is_empty() && !self.carriers.is_empty());
        let askers = !self.tile_boxes.is_empty() || !self.tile_shapes.is_empty();
        self.tiles = map.is_some() && (!special || (f.tilemap && askers));
        self.triggers = !special || f.triggers || f.hazard_tiles;
        self.incremental = special && !self.small;
    }
}

/// What the colliders, bodies and tilemap use.
pub(crate) fn features(slots: &[Slot], bodies: &[Body], map: Option<&Tilemap>) -> SceneFeatures {
    let mut f = SceneFeatures::default();
    for s in slots {
        if s.index == GONE {
            continue;
        }
        f.kinds |= 1 << s.kind as u8;
        f.one_way |= s.one_way.is_some();
        f.triggers |= !s.solid;
        f.kinematic |= bodies[s.body as usize].kind == BodyKind::Kinematic;
    }
    f.rotated = f.has_kind(ShapeKind::Obb) || f.has_kind(ShapeKind::Polygon);
    f.riders = bodies.iter().any(|b| b.rider && !b.removed);
    f.swept = bodies
        .iter()
        .any(|b| b.swept && !b.removed && b.kind == BodyKind::Dynamic);
    if let Some(m) = map {
        for t in m.tiles() {
            match t {
                Tile::Empty => {}
                Tile::Solid => f.tilemap = true,
                Tile::OneWay => f.one_way_tiles = true,
                Tile::Hazard => f.hazard_tiles = true,
                Tile::Slope(_) => f.slopes = true,
            }
        }
        f.tilemap |= f.one_way_tiles || f.hazard_tiles || f.slopes;
    }
    f
}
