//! The level's entities at run time: [`EntityType`], what each is (public:
//! views and snapshots name it), and `Ent`, one entity's run-time state.
//! In a module of their own, below the [`Game`](super::Game) that holds them, so
//! that the parts reading them (`spawn`, the rules) need nothing from the
//! game's facade.

use glam::IVec2;

use super::path::PathSchedule;
use super::rect::Rect;
use super::state::kind;
use crate::level::EntityKind;
use crate::shape::Obb;
use crate::world::BodyId;

/// The type of a level entity, for drawing ([`super::EntityView`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EntityType {
    /// A player spawn point.
    Spawn,
    /// A static block.
    Block,
    /// A static convex polygon solid: its view's box holds the polygon (the
    /// level's [`EntityKind::PolygonBlock`] has the vertices). The walker
    /// ledge test and the drop-through test do not look at it.
    PolygonBlock,
    /// A moving platform.
    Platform,
    /// A walker enemy.
    Walker,
    /// A springboard.
    Springboard,
    /// A coin.
    Coin,
    /// A checkpoint.
    Checkpoint,
    /// A goal.
    Goal,
    /// A hazard volume.
    Hazard,
}

impl EntityType {
    /// The type of a level entity of kind `kind`.
    pub(super) fn of(kind: &EntityKind) -> Self {
        match kind {
            EntityKind::PlayerSpawn => EntityType::Spawn,
            EntityKind::Block => EntityType::Block,
            EntityKind::PolygonBlock { .. } => EntityType::PolygonBlock,
            EntityKind::MovingPlatform { .. } => EntityType::Platform,
            EntityKind::Walker { .. } => EntityType::Walker,
            EntityKind::Springboard { .. } => EntityType::Springboard,
            EntityKind::Coin => EntityType::Coin,
            EntityKind::Checkpoint => EntityType::Checkpoint,
            EntityKind::Goal => EntityType::Goal,
            EntityKind::Hazard => EntityType::Hazard,
            EntityKind::Turned { trigger, .. } => Self::of(&trigger.kind()),
        }
    }

    /// Its kind byte ([`super::kind`]).
    pub fn code(self) -> u8 {
        match self {
            EntityType::Spawn => kind::SPAWN,
            EntityType::Block | EntityType::PolygonBlock => kind::BLOCK,
            EntityType::Platform => kind::PLATFORM,
            EntityType::Walker => kind::WALKER,
            EntityType::Springboard => kind::SPRINGBOARD,
            EntityType::Coin => kind::COIN,
            EntityType::Checkpoint => kind::CHECKPOINT,
            EntityType::Goal => kind::GOAL,
            EntityType::Hazard => kind::HAZARD,
        }
    }
}

/// One level entity at run time.
#[derive(Debug, Clone)]
pub(super) struct Ent {
    pub(super) ty: EntityType,
    /// Centre in the level (a platform's first node).
    pub(super) pos: IVec2,
    pub(super) half: IVec2,
    pub(super) body: Option<BodyId>,
    /// Walker speed or springboard strength.
    pub(super) param: i32,
    pub(super) path: Option<PathSchedule>,
    pub(super) one_way: bool,
    /// Walker: not defeated.
    pub(super) alive: bool,
    /// Walker: walking direction, -1 or 1.
    pub(super) dir: i32,
    /// Coin: who picked it up.
    pub(super) collector: Option<u32>,
    /// A turned trigger's shape ([`EntityKind::Turned`]): what touches it
    /// (`half` is the even box around it).
    pub(super) turned: Option<Obb>,
}

impl Ent {
    /// Whether the interior of box `r` overlaps this entity's (its box at
    /// `pos`, or its turned shape).
    pub(super) fn touches(&self, pos: IVec2, r: &Rect) -> bool {
        match &self.turned {
            None => Rect::new(pos, self.half).overlaps(r),
            Some(obb) => r.overlaps_obb(pos, obb.u(), obb.v()),
        }
    }
}
