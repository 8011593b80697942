//! What a front end draws and shows, in floats: the only place floats
//! appear on the client (the simulation stays integer).
//!
//! A [`FrameView`] is built once per rendered frame by
//! [`crate::game::ClientGame::view`] (or [`crate::net::online::OnlineGame::view`])
//! from the predicted game (the local player, platforms, walkers, coins:
//! everything the client simulates itself), the interpolation buffer
//! (remote players, drawn a little in the past) and the correction
//! smoothing (the local player's visible offset after a misprediction).
//! [`NetStats`] is the network panel.
//!
//! Conventions: positions are the **centre** of the box, in **pixels**
//! (256 simulation units per pixel), y growing **down**; sizes are the full
//! width and height in pixels. The level's tiles are not in the view: draw
//! them once from [`crate::game::ClientGame::level`] (`level.tilemap`).
//!
//! This API is stable: fields may be added (the structs are
//! `#[non_exhaustive]`, so build them only through this crate), none
//! removed or renamed.

pub use glam::Vec2;
use ledge_shared::fixed::UNITS_PER_PX;
pub use ledge_shared::game::EntityType;
use ledge_shared::protocol::PlayerId;

/// Which way a player or walker faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Facing {
    /// Towards -x.
    Left,
    /// Towards +x.
    #[default]
    Right,
}

impl Facing {
    /// `Left` when `left`, else `Right`.
    pub fn from_left(left: bool) -> Facing {
        if left {
            Facing::Left
        } else {
            Facing::Right
        }
    }

    /// -1.0 for left, 1.0 for right (to flip a sprite).
    pub fn sign(self) -> f32 {
        match self {
            Facing::Left => -1.0,
            Facing::Right => 1.0,
        }
    }
}

/// A player to draw.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PlayerDraw {
    /// Its id.
    pub id: PlayerId,
    /// Its name, when known: ours, and remote players' from the server's
    /// roster (`None` until it arrived, or past [`ledge_shared::protocol::MAX_ROSTER`]
    /// players).
    pub name: Option<String>,
    /// Centre of its box, pixels.
    pub pos: Vec2,
    /// Full size of its box, pixels.
    pub size: Vec2,
    /// Velocity, pixels per second.
    pub vel: Vec2,
    /// Which way it faces.
    pub facing: Facing,
    /// Stood on the ground at the end of its last tick.
    pub grounded: bool,
    /// Reached the goal.
    pub won: bool,
    /// Dead, waiting to respawn (ours: the predicted game's
    /// `PlayerView::dead`; remote players: the `DEAD` flag of their
    /// interpolated state). Front ends draw no body then.
    pub dead: bool,
    /// Which side of its box touches a wall while airborne, for a
    /// wall-slide look: `Some(Left)` for a wall on its left. Only our
    /// player has it (from the predicted game's touched sides); remote
    /// players are always `None` because snapshots do not carry the sides.
    pub wall: Option<Facing>,
}

impl PlayerDraw {
    /// A player `id` with a box of `size` centred at `pos` (pixels):
    /// nameless, still, facing right, airborne, alive, not finished, no
    /// wall beside it. Set the other fields as needed (front ends' tests
    /// build their players so, the struct being `#[non_exhaustive]`).
    pub fn new(id: PlayerId, pos: Vec2, size: Vec2) -> PlayerDraw {
        PlayerDraw {
            id,
            name: None,
            pos,
            size,
            vel: Vec2::ZERO,
            facing: Facing::Right,
            grounded: false,
            won: false,
            dead: false,
            wall: None,
        }
    }

    /// Top-left corner of its box, pixels.
    pub fn top_left(&self) -> Vec2 {
        self.pos - self.size * 0.5
    }
}

/// A level entity to draw (blocks, platforms, walkers, springboards,
/// coins, checkpoints, goals, hazards, spawns), in level order.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct EntityDraw {
    /// Its id (`ENTITY_ID_BASE` + level index).
    pub id: u32,
    /// What it is.
    pub kind: EntityType,
    /// Centre of its box, pixels.
    pub pos: Vec2,
    /// Full size of its box, pixels.
    pub size: Vec2,
    /// Still in play: a walker not defeated, a coin not picked up (always
    /// true for the others).
    pub active: bool,
    /// A one-way platform (solid from above only).
    pub one_way: bool,
    /// A walker's direction (others: `Right`).
    pub facing: Facing,
}

impl EntityDraw {
    /// Level entity `e` drawn with its centre at `pos` (pixels).
    pub fn of(e: &ledge_shared::game::EntityView, pos: Vec2) -> EntityDraw {
        EntityDraw {
            id: e.id,
            kind: e.ty,
            pos,
            size: px2(e.half * 2),
            active: e.active,
            one_way: e.one_way,
            facing: if e.ty == EntityType::Walker {
                Facing::from_left(e.facing_left)
            } else {
                Facing::Right
            },
        }
    }

    /// Top-left corner of its box, pixels.
    pub fn top_left(&self) -> Vec2 {
        self.pos - self.size * 0.5
    }
}

/// Everything to draw this frame.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct FrameView {
    /// Our player, once the first snapshot arrived (`None` before, or when
    /// the server has no body for us).
    pub local: Option<PlayerDraw>,
    /// The other players, interpolated between two snapshots a little in
    /// the past, ascending by id.
    pub remotes: Vec<PlayerDraw>,
    /// The level's entities, predicted with the local player (walkers,
    /// coins, platforms move; blocks and the rest stand still).
    pub entities: Vec<EntityDraw>,
    /// The newest predicted tick (the local simulation's tick count).
    pub tick: u64,
    /// How far between the previous and the newest predicted tick this
    /// frame is drawn, in [0, 1] (the local player and entities are blended
    /// between the two ticks' states by it).
    pub alpha: f32,
    /// The server tick remote players are drawn at (fractional).
    pub remote_tick: f64,
}

impl FrameView {
    /// Where a camera should look: our player, else the first remote, else
    /// `None`.
    pub fn focus(&self) -> Option<Vec2> {
        self.local.as_ref().or(self.remotes.first()).map(|p| p.pos)
    }
}

/// The network panel: measured figures, all floats.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct NetStats {
    /// Round-trip time, milliseconds (QUIC's smoothed estimate or pings).
    pub rtt_ms: f32,
    /// Snapshot arrival jitter, milliseconds (RFC 3550 estimator).
    pub jitter_ms: f32,
    /// Fraction of snapshots lost over the last seconds, 0..=1.
    pub loss: f32,
    /// Snapshots received per second.
    pub snapshot_hz: f32,
    /// The server was quiet with us in the last second: nothing changed,
    /// so it sent snapshots a few times a second instead of every interval.
    pub quiet: bool,
    /// Bytes received per second (UDP payload, all channels).
    pub bytes_in_per_s: f32,
    /// Bytes sent per second.
    pub bytes_out_per_s: f32,
    /// Prediction corrections per second (snapshots that moved our
    /// predicted player).
    pub corrections_per_s: f32,
    /// Size of the last correction, pixels.
    pub last_correction_px: f32,
    /// How early our inputs reach the server, ticks (smoothed server
    /// feedback; below 0 they arrive late).
    pub input_margin_ticks: f32,
    /// The margin the clock steers towards, ticks (adapts to jitter).
    pub target_margin_ticks: f32,
    /// The local clock's speed adjustment, as a fraction (+0.02: 2% fast).
    pub clock_adjust: f32,
    /// How far in the past remote players are drawn, milliseconds.
    pub interp_delay_ms: f32,
    /// Corrections since the start.
    pub corrections: u64,
    /// Snapshots whose state of our player differed from our prediction of
    /// that tick, since the start (each one causes a correction unless the
    /// difference was invisible, e.g. a timer).
    pub mispredictions: u64,
}

/// Units to pixels.
pub fn px(units: i32) -> f32 {
    units as f32 / UNITS_PER_PX as f32
}

/// A unit vector to pixels.
pub fn px2(units: glam::IVec2) -> Vec2 {
    Vec2::new(px(units.x), px(units.y))
}

/// A move longer than this in one tick (pixels) is a teleport (a respawn,
/// a restart): drawn where it ends, not blended.
pub const TELEPORT_PX: f32 = 64.0;

/// Where something drawn between two ticks is (pixels): `alpha` of the
/// way from `before` to `now` (units), or at `now` when it has no
/// `before` or teleported.
pub fn blend(before: Option<glam::IVec2>, now: glam::IVec2, alpha: f32) -> Vec2 {
    let cur = px2(now);
    match before.map(px2) {
        Some(prev) if (cur - prev).abs().max_element() <= TELEPORT_PX => prev.lerp(cur, alpha),
        _ => cur,
    }
}
