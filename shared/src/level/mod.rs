//! Levels: the data model every importer produces and the game is built
//! from.
//!
//! A [`Level`] is plain data: a tilemap plus a list of entity definitions in
//! world units; [`crate::game::Game::from_level`] turns it into a running
//! simulation. A level's bot route is a list of [`Waypoint`]s. The importers
//! (OGMO Editor 3, Tiled) and the embedded default level live in the
//! `ledge-levels` crate, so this crate stays free of file formats and I/O.

mod model;

use glam::IVec2;
use serde::{Deserialize, Serialize};

pub use model::{
    EntityDef, EntityKind, Level, PlatformMotion, PlayerScale, ScaleSource, Trigger,
    MAX_PLAYER_SCALE, MIN_PLAYER_SCALE,
};

use crate::tilemap::Tile;

/// What the runner bot does to reach a [`Waypoint`] from the previous one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum RouteAction {
    /// Walk along the ground (flat, slopes, one-way tiles) to the waypoint.
    Walk,
    /// Jump toward the waypoint (over a gap, a hazard or onto a higher or
    /// one-way surface) and land on it.
    Jump,
    /// Walk onto the springboard under the waypoint's x, get launched, and
    /// steer to land on the waypoint.
    Spring,
}

/// One stop of a level's bot route: where the player's foot (the
/// bottom-centre of its box) should stand, and how to get there from the
/// previous waypoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Waypoint {
    /// Foot position in units: the bottom-centre of the waypoint entity,
    /// which is placed standing on the ground.
    pub foot: IVec2,
    /// How to get here.
    pub action: RouteAction,
}

/// What a level uses, so the world can build only the passes it needs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct LevelFeatures {
    /// Some tile is [`Tile::Solid`].
    pub solid_tiles: bool,
    /// Some tile is [`Tile::OneWay`].
    pub one_way_tiles: bool,
    /// Some tile is a slope.
    pub slopes: bool,
    /// Some tile is [`Tile::Hazard`].
    pub hazard_tiles: bool,
    /// Some entity is a [`EntityKind::Block`] or [`EntityKind::PolygonBlock`].
    pub blocks: bool,
    /// Some entity is a moving platform.
    pub moving_platforms: bool,
    /// Some moving platform is one-way.
    pub one_way_platforms: bool,
    /// Some entity is a walker.
    pub walkers: bool,
    /// Some entity is a springboard.
    pub springboards: bool,
    /// Some entity is a trigger (coin, checkpoint, goal, hazard).
    pub triggers: bool,
    /// The fastest speed an entity gives (platform or walker speed,
    /// springboard strength), units per tick: a hint for swept collision.
    pub max_speed: i32,
}

impl Level {
    /// A stable 64-bit hash of the level's content (FNV-1a over its bincode
    /// encoding): server and client compare it to be sure they play the
    /// same level.
    pub fn content_hash(&self) -> u64 {
        let bytes = bincode::serde::encode_to_vec(self, bincode::config::standard())
            .expect("a level always encodes");
        bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        })
    }

    /// The box holding everything in the level (units, `(top-left,
    /// bottom-right)`): the tile grid and every entity's box, moving
    /// platforms over their whole path. `None` for a level with nothing in
    /// it. What the camera stays inside, and what a falling player falls
    /// out of.
    pub fn bounds(&self) -> Option<(IVec2, IVec2)> {
        let mut b: Option<(IVec2, IVec2)> = None;
        let mut add = |lo: IVec2, hi: IVec2| {
            b = Some(match b {
                None => (lo, hi),
                Some((a, c)) => (a.min(lo), c.max(hi)),
            });
        };
        let m = &self.tilemap;
        if m.width() > 0 && m.height() > 0 {
            let size = IVec2::new(m.width() as i32, m.height() as i32) * m.tile_size();
            add(m.origin(), m.origin() + size);
        }
        for e in &self.entities {
            let half = e.size / 2;
            add(e.pos - half, e.pos + half);
            if let EntityKind::MovingPlatform { motion, .. } = &e.kind {
                for &n in &motion.path {
                    add(n - half, n + half);
                }
            }
            if let EntityKind::PolygonBlock { vertices } = &e.kind {
                for &v in vertices {
                    add(e.pos + v, e.pos + v);
                }
            }
        }
        b
    }

    /// Which features the level uses.
    pub fn features(&self) -> LevelFeatures {
        let mut f = LevelFeatures::default();
        for t in self.tilemap.tiles() {
            match t {
                Tile::Empty => {}
                Tile::Solid => f.solid_tiles = true,
                Tile::OneWay => f.one_way_tiles = true,
                Tile::Hazard => f.hazard_tiles = true,
                Tile::Slope(_) => f.slopes = true,
            }
        }
        for e in &self.entities {
            match &e.kind {
                EntityKind::PlayerSpawn => {}
                EntityKind::Block | EntityKind::PolygonBlock { .. } => f.blocks = true,
                EntityKind::MovingPlatform { motion, one_way } => {
                    f.moving_platforms = true;
                    f.one_way_platforms |= *one_way;
                    f.max_speed = f.max_speed.max(motion.speed);
                }
                EntityKind::Walker { speed } => {
                    f.walkers = true;
                    f.max_speed = f.max_speed.max(*speed);
                }
                EntityKind::Springboard { strength } => {
                    f.springboards = true;
                    f.max_speed = f.max_speed.max(*strength);
                }
                EntityKind::Coin
                | EntityKind::Checkpoint
                | EntityKind::Goal
                | EntityKind::Hazard
                | EntityKind::Turned { .. } => f.triggers = true,
            }
        }
        f
    }
}
