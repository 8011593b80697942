//! Built-in scenes: the warm-up room, the wall-and-door corner, and a
//! deterministic input script for long runs.

use crate::fixed::px;
use crate::input::Buttons;
use crate::shape::Aabb;
use crate::world::{
    BodyDesc, BodyId, BuildError, ColliderDesc, ColliderMode, Controller, Mover, MoverConfig,
    OneWay, SimConfig, World,
};
use glam::IVec2;

/// Collider tags used by the built-in scenes (reported in events).
pub mod tag {
    /// A side wall.
    pub const WALL: u16 = 1;
    /// The floor (bottom edge of the room).
    pub const FLOOR: u16 = 2;
    /// The ceiling (top edge of the room).
    pub const CEILING: u16 = 3;
    /// The block in the middle of the room.
    pub const BLOCK: u16 = 4;
    /// The raised one-way platform.
    pub const PLATFORM: u16 = 5;
    /// The player's square.
    pub const PLAYER: u16 = 6;
    /// A trigger pad (never blocks).
    pub const PAD: u16 = 7;
    /// A closed door.
    pub const DOOR: u16 = 8;
}

/// One tile: 16 px.
pub const TILE: i32 = px(16);
/// Warm-up room width in tiles (walls included).
pub const ROOM_W: i32 = 40;
/// Warm-up room height in tiles (floor and ceiling included).
pub const ROOM_H: i32 = 24;
/// Half size of the player's square (16 x 16 px).
pub const PLAYER_HALF: i32 = px(8);
/// The top-down mover of the built-in scenes: 2.5 px/tick at most.
pub const MOVER: MoverConfig = MoverConfig {
    accel: 48,
    brake: 96,
    max_speed: 640,
};

/// A box covering tiles `[x, x + w) x [y, y + h)`, as a collider description
/// around a body at the origin.
fn tiles(x: i32, y: i32, w: i32, h: i32) -> ColliderDesc {
    let half = IVec2::new(w * TILE / 2, h * TILE / 2);
    let centre = IVec2::new(x * TILE, y * TILE) + half;
    ColliderDesc::solid(Aabb::new(half).expect("scene boxes are valid")).at(centre)
}

/// Adds the player's square at `pos` with a mover at the next input slot.
fn add_player(w: &mut World, pos: IVec2) -> BodyId {
    let body = w
        .add_body(BodyDesc::dynamic(pos))
        .expect("player position in bounds");
    let shape = Aabb::new(IVec2::splat(PLAYER_HALF)).expect("player box");
    w.add_collider(body, ColliderDesc::solid(shape).tagged(tag::PLAYER))
        .expect("player collider");
    w.add_controller(Controller::Mover(Mover {
        body,
        config: MOVER,
    }))
    .expect("player controller");
    body
}

/// The warm-up room: [`ROOM_W`] x [`ROOM_H`] tiles with its top-left corner
/// at the origin.
///
/// * ceiling (row 0) and floor (last row) of four boxes each, side walls
///   (first and last columns, between them) of three boxes each: every
///   surface has seams, at different places on opposite sides;
/// * a 4 x 4 tile block in the middle ([`tag::BLOCK`]);
/// * a raised one-way platform, solid from above ([`tag::PLATFORM`]);
/// * a 3 x 3 tile trigger pad near the bottom right ([`tag::PAD`]);
/// * the player: a dynamic 16 x 16 px square ([`tag::PLAYER`]) driven by
///   the top-down [`MOVER`] at input slot 0.
///
/// All fixed geometry belongs to one static body at the origin (colliders at
/// offsets).
pub fn warmup_room() -> World {
    warmup_room_with(SimConfig::default()).expect("the default configuration is valid")
}

/// [`warmup_room`] with another simulation configuration (to measure the
/// knobs, or to test at several substep counts).
pub fn warmup_room_with(config: SimConfig) -> Result<World, BuildError> {
    let mut w = World::new(config)?;
    let room = w.add_body(BodyDesc::fixed(IVec2::ZERO)).expect("room body");
    let mut add = |d: ColliderDesc| {
        w.add_collider(room, d).expect("room collider");
    };
    let (right, bottom) = (ROOM_W - 1, ROOM_H - 1);
    for (x0, x1) in [(0, 9), (9, 21), (21, 30), (30, ROOM_W)] {
        add(tiles(x0, 0, x1 - x0, 1).tagged(tag::CEILING));
    }
    for (x0, x1) in [(0, 12), (12, 19), (19, 31), (31, ROOM_W)] {
        add(tiles(x0, bottom, x1 - x0, 1).tagged(tag::FLOOR));
    }
    for (y0, y1) in [(1, 8), (8, 16), (16, bottom)] {
        add(tiles(0, y0, 1, y1 - y0).tagged(tag::WALL));
    }
    for (y0, y1) in [(1, 6), (6, 13), (13, bottom)] {
        add(tiles(right, y0, 1, y1 - y0).tagged(tag::WALL));
    }
    add(tiles(18, 10, 4, 4).tagged(tag::BLOCK));
    add(tiles(6, 17, 8, 1).tagged(tag::PLATFORM).one_way(OneWay::Up));
    add(ColliderDesc {
        mode: ColliderMode::Trigger,
        ..tiles(30, 18, 3, 3).tagged(tag::PAD)
    });
    add_player(&mut w, IVec2::new(5 * TILE + TILE / 2, 5 * TILE + TILE / 2));
    Ok(w)
}

/// x of the wall's left face in [`wall_and_door`].
pub const CORNER_WALL_X: i32 = 20 * TILE;
/// y of the door's bottom face in [`wall_and_door`].
pub const CORNER_DOOR_Y: i32 = 8 * TILE;

/// A wall on the right (left face at [`CORNER_WALL_X`], [`tag::WALL`]) and a
/// closed door above, a separate solid box whose right end is flush against
/// the wall (bottom face at [`CORNER_DOOR_Y`], [`tag::DOOR`]); the player's
/// square with a mover at slot 0 starts below-left of the corner, 20 px from
/// the wall and 20 px below the door, so moving diagonally it reaches both in
/// the same tick.
pub fn wall_and_door() -> World {
    let mut w = World::default();
    let fixed = w
        .add_body(BodyDesc::fixed(IVec2::ZERO))
        .expect("fixed body");
    w.add_collider(fixed, tiles(20, 0, 1, 20).tagged(tag::WALL))
        .expect("wall");
    w.add_collider(fixed, tiles(14, 7, 6, 1).tagged(tag::DOOR))
        .expect("door");
    add_player(
        &mut w,
        IVec2::new(
            CORNER_WALL_X - PLAYER_HALF - px(20),
            CORNER_DOOR_Y + PLAYER_HALF + px(20),
        ),
    );
    w
}

/// The input of the deterministic script at `tick`: ticks are grouped in
/// runs of 40, and each run holds a pseudo-random set of buttons drawn from
/// an integer LCG seeded by the run number (no `rand`: the script must never
/// change with a dependency).
pub fn scripted_inputs(tick: u64) -> Buttons {
    let mut s = (tick / 40) ^ 0x1ed9_e5ee_d000_0001;
    for _ in 0..3 {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
    }
    Buttons(
        (s >> 59) as u8
            & (Buttons::LEFT | Buttons::RIGHT | Buttons::UP | Buttons::DOWN | Buttons::JUMP),
    )
}

/// Steps `world` for `ticks` ticks with [`scripted_inputs`] in slot 0 (the
/// tick number given to the script is [`World::tick`] before each step).
pub fn run_scripted(world: &mut World, ticks: u64) {
    for _ in 0..ticks {
        let input = scripted_inputs(world.tick());
        world.step(&[input]);
    }
}
