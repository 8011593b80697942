//! Tile test helpers shared by the tile suites of this binary (`tilemap.rs`,
//! `tilemap_shapes.rs`, `tilemap_sizes.rs`, `sweep.rs`,
//! `platformer_controller.rs`): the local box-contact loop (one restitution
//! pass as the world runs it, and runs of it), a flat slide across a seam,
//! random maps, a swept shot at a one-tile wall, and a player running over
//! hills. Each takes the tile size where a suite runs at more than one, so
//! the 16 px suites and the odd-size suite check the same properties with
//! the same code.

use glam::{I64Vec2, IVec2};
use ledge_shared::game::{GameConfig, PlayerConfig};
use ledge_shared::level::EntityKind;
use ledge_shared::tilemap::{ContactFlags, Slope, Tile, TileContact, Tilemap};
use ledge_shared::world::{
    AnyShape, BodyDesc, BodyId, ColliderDesc, SimConfig, SweepMode, SweepResponse, World,
};
use proptest::prelude::*;
use std::cmp::Reverse;

use crate::platformer_kit::{ent_sized, level_sized, map_at, Sim, LEFT, RIGHT};

/// Shorthand for a unit vector.
pub fn v(x: i32, y: i32) -> IVec2 {
    IVec2::new(x, y)
}

/// Shorthand for a wide vector.
pub fn w(x: i64, y: i64) -> I64Vec2 {
    I64Vec2::new(x, y)
}

/// World x of column `c`'s left edge.
pub fn col_x(m: &Tilemap, c: i32) -> i32 {
    m.origin().x + c * m.tile_size()
}

/// World y of row `r`'s top edge.
pub fn row_y(m: &Tilemap, r: i32) -> i32 {
    m.origin().y + r * m.tile_size()
}

// ------------------------------------------------------------ box contacts

/// One restitution pass, the way the world runs it: contacts sorted by
/// MTV length, largest first (stable), each re-checked at the current
/// position before it is applied, and no push against this tick's pushes on
/// an axis. `start` is the position at the start of the tick. Returns the
/// total push.
pub fn resolve(
    m: &Tilemap,
    pos: &mut IVec2,
    half: IVec2,
    start: IVec2,
    flags: ContactFlags,
    buf: &mut Vec<TileContact>,
) -> IVec2 {
    buf.clear();
    m.box_contacts(*pos, half, *pos - start, flags, buf);
    buf.sort_by_key(|c| Reverse(c.mtv.x.abs() + c.mtv.y.abs()));
    let mut pushed = IVec2::ZERO;
    for c in buf.iter() {
        if c.is_trigger() {
            continue;
        }
        let Some(now) = m.tile_contact(c.tile, *pos, half, *pos - start, flags) else {
            continue;
        };
        let mut d = now.mtv;
        if d.x.signum() * pushed.x.signum() < 0 {
            d.x = 0;
        }
        if d.y.signum() * pushed.y.signum() < 0 {
            d.y = 0;
        }
        *pos += d;
        pushed += d;
    }
    pushed
}

/// Whether no solid contact is left at `pos` (reusing `buf`): true after
/// every [`resolve`] in these scenes.
pub fn resolved(
    m: &Tilemap,
    pos: IVec2,
    half: IVec2,
    start: IVec2,
    flags: ContactFlags,
    buf: &mut Vec<TileContact>,
) -> bool {
    buf.clear();
    m.box_contacts(pos, half, pos - start, flags, buf);
    buf.iter().all(|c| c.is_trigger())
}

/// Runs `ticks` ticks of constant motion `v` with `flags` through
/// [`resolve`]; returns the positions after each tick.
pub fn run(
    m: &Tilemap,
    mut pos: IVec2,
    half: IVec2,
    v: IVec2,
    flags: ContactFlags,
    ticks: usize,
) -> Vec<IVec2> {
    let mut buf = Vec::new();
    (0..ticks)
        .map(|_| {
            let start = pos;
            pos += v;
            resolve(m, &mut pos, half, start, flags, &mut buf);
            assert!(resolved(m, pos, half, start, flags, &mut buf));
            pos
        })
        .collect()
}

/// Solid (non-trigger) contacts of a box at `pos` having moved by `moved`.
pub fn pushes(
    map: &Tilemap,
    pos: IVec2,
    half: IVec2,
    moved: IVec2,
    flags: ContactFlags,
) -> Vec<TileContact> {
    let mut out = Vec::new();
    map.box_contacts(pos, half, moved, flags, &mut out);
    out.retain(|c| !c.is_trigger());
    out
}

/// Whether contact `c` pushes back against a motion along `d0`.
pub fn against(c: &TileContact, d0: IVec2) -> bool {
    c.mtv.as_i64vec2().dot(d0.as_i64vec2()) < 0
}

/// The first lattice position `j` in `1..=k` at which a box of `half`
/// moved from `start` to `start + d0 * j` is pushed back against the motion
/// (the sweep oracles' reference hit). (The rules also push a box crossing a
/// slope's thin end down through its bottom, with the motion: not a
/// collision to stop at.)
pub fn first_pushed_back(
    map: &Tilemap,
    start: IVec2,
    half: IVec2,
    d0: IVec2,
    k: i32,
    flags: ContactFlags,
) -> Option<i32> {
    (1..=k).find(|&j| {
        pushes(map, start + d0 * j, half, d0 * j, flags)
            .iter()
            .any(|c| against(c, d0))
    })
}

/// Slides a box along a flat run of tiles: `along` is the unit direction of
/// travel, `into` the unit direction towards the surface (pressed by `press`
/// units each tick), `surface` the surface line's coordinate along `into`
/// (x for walls, y for floors and ceilings) and `seam` a tile seam crossed
/// along the way. At every subpixel offset and every speed of `speeds`, the
/// box must advance exactly `speed` each tick and stay exactly on the
/// surface line, with nothing left overlapping.
#[allow(clippy::too_many_arguments)]
pub fn slide(
    m: &Tilemap,
    half: IVec2,
    along: IVec2,
    into: IVec2,
    surface: i32,
    seam: i32,
    press: i32,
    speeds: &[i32],
) {
    let mut buf = Vec::new();
    let flags = ContactFlags::default();
    let t = m.tile_size();
    // Distance from the box centre to its leading edge and to the surface.
    let reach = (half * along.abs()).x + (half * along.abs()).y;
    let to_surface = (half * into.abs()).x + (half * into.abs()).y;
    let dot = |a: IVec2, b: IVec2| a.x * b.x + a.y * b.y;
    for &speed in speeds {
        // Offsets 0..min(speed, 256): runs from these cross the seam at every
        // relative position, so at every subpixel offset.
        for sub in 0..speed.min(256) {
            // The leading edge starts 2 * speed + sub before the seam, moving
            // towards it; run until the trailing edge is well past it.
            let lead =
                dot(IVec2::splat(seam), along.abs()) - dot(along, along.abs()) * (2 * speed + sub);
            let centre_along = lead - dot(along, along.abs()) * reach;
            let centre_into = surface - dot(into, into.abs()) * to_surface;
            let mut pos = along.abs() * centre_along + into.abs() * centre_into;
            let ticks = (2 * reach + 4 * speed + 256) / speed + 1;
            for tick in 0..ticks {
                let start = pos;
                pos += along * speed + into * press;
                // Every contact on its own already points straight out of the
                // surface: seams are culled, not merely outvoted by the
                // largest-first order.
                buf.clear();
                m.box_contacts(pos, half, pos - start, flags, &mut buf);
                // (Messages are formatted only on failure.)
                let what = || {
                    format!("T {t} speed {speed} sub {sub} tick {tick} half {half} along {along} into {into} press {press}")
                };
                assert!(
                    buf.iter().all(|c| c.mtv == -into * press) && buf.is_empty() == (press == 0),
                    "contacts {buf:?}: {}",
                    what()
                );
                let pushed = resolve(m, &mut pos, half, start, flags, &mut buf);
                assert_eq!(
                    pushed,
                    -into * press,
                    "pushed only out of the surface: {}",
                    what()
                );
                assert_eq!(
                    pos - start,
                    along * speed,
                    "advanced exactly the speed: {}",
                    what()
                );
                assert!(resolved(m, pos, half, start, flags, &mut buf), "{}", what());
            }
        }
    }
}

// ------------------------------------------------------------ random maps

/// A random 7 x 5 map with its tile size drawn from `size` (`Just(T)` for
/// one size: it draws nothing, so a fixed size sees the same maps).
pub fn random_map(size: impl Strategy<Value = i32>) -> impl Strategy<Value = Tilemap> {
    let tile = prop_oneof![
        6 => Just(Tile::Empty),
        4 => Just(Tile::Solid),
        1 => Just(Tile::OneWay),
        1 => Just(Tile::Hazard),
        2 => proptest::sample::select(Slope::ALL.to_vec()).prop_map(Tile::Slope),
    ];
    (
        proptest::collection::vec(tile, 7 * 5),
        -40i32..=40,
        -40i32..=40,
        size,
    )
        .prop_map(|(mut tiles, ox, oy, t)| {
            // Slopes stand on solid ground down to the bottom row, as in a
            // level. Under a floating slope the contact rules push a box whose
            // body crosses the slope's triangle (or the block under it) down
            // through an exposed bottom face, whatever its motion: no sweep
            // rule mirrors that (see the tilemap notes of `query::sweep`).
            for c in 0..7 {
                let mut grounded = false;
                for r in 0..5 {
                    let i = r * 7 + c;
                    if grounded {
                        tiles[i] = Tile::Solid;
                    } else if matches!(tiles[i], Tile::Slope(_)) {
                        grounded = true;
                        if r == 4 {
                            tiles[i] = Tile::Solid;
                        }
                    }
                }
            }
            Tilemap::new(v(ox, oy), t, 7, 5, tiles).unwrap()
        })
}

// ------------------------------------------------------------ swept shots

/// A world with a one-tile wall (column 8 of a 16 x 16 map of tiles `t`)
/// or a one-way row (row 8), and a swept body of `shape` that stops at a
/// hit; also the map.
pub fn shot(
    shape: AnyShape,
    t: i32,
    start: IVec2,
    vel: IVec2,
    one_way: bool,
) -> (World, BodyId, Tilemap) {
    let mut tiles = vec![Tile::Empty; 16 * 16];
    for i in 0..16 {
        if one_way {
            tiles[8 * 16 + i] = Tile::OneWay;
        } else {
            tiles[i * 16 + 8] = Tile::Solid;
        }
    }
    let m = Tilemap::new(IVec2::ZERO, t, 16, 16, tiles).unwrap();
    let mut w = World::new(SimConfig {
        sweep: SweepMode::Flagged,
        ..SimConfig::default()
    })
    .unwrap();
    w.set_tilemap(m.clone());
    let b = w.add_body(BodyDesc::dynamic(start).with_vel(vel)).unwrap();
    w.add_collider(b, ColliderDesc::solid(shape)).unwrap();
    w.set_swept(b, true).unwrap();
    w.set_sweep_response(b, SweepResponse::Stop).unwrap();
    (w, b, m)
}

// ------------------------------------------------------------ hills

/// Flat, a 45 degree hill two tiles high, flat, a 22.5 degree hill one tile
/// high, flat; floor top at row 11.
pub const HILLS: [&str; 12] = [
    "##############################",
    "#............................#",
    "#............................#",
    "#............................#",
    "#............................#",
    "#............................#",
    "#............................#",
    "#............................#",
    "#............................#",
    "#...../##\\...................#",
    "#..../####\\.....ab##cd.......#",
    "##############################",
];

/// A player lands for `land` ticks, then runs over the [`HILLS`] on tiles
/// of `t` at `speed` from column `from` to column `to`: grounded every tick
/// with its foot on the surface, and over the top of the 45 degree hill
/// (two tiles up).
pub fn run_hills(t: i32, land: usize, speed: i32, from: i32, to: i32) {
    let cfg = GameConfig {
        player: PlayerConfig {
            max_run_speed: speed,
            run_accel: speed.min(40),
            snap_distance: 1024.max(speed + 256),
            ..PlayerConfig::default()
        },
        ..GameConfig::default()
    };
    let lv = level_sized(
        t,
        &HILLS,
        vec![ent_sized(EntityKind::PlayerSpawn, t, from, 10)],
    );
    let mut s = Sim::with(&lv, cfg);
    s.land(land);
    let b = if to > from { RIGHT } else { LEFT };
    let map = s.game.tilemap().clone();
    let mut ticks = 0;
    let mut min_bottom = s.bottom();
    while (s.pos().x - (to * t + t / 2)) * (to - from).signum() < 0 {
        s.step(b);
        ticks += 1;
        let view = s.view();
        let foot = IVec2::new(view.pos.x, view.pos.y + view.half.y);
        assert!(
            view.grounded,
            "T {t} speed {speed}: airborne at {foot} after {ticks} ticks"
        );
        assert_eq!(
            map.ground_below(foot, 0),
            Some(foot.y),
            "T {t} speed {speed}: foot {foot} not on the surface after {ticks} ticks"
        );
        min_bottom = min_bottom.min(foot.y);
        assert!(ticks < 100_000);
    }
    assert_eq!(min_bottom, 9 * t, "T {t} speed {speed}");
}

/// A ramp: its row (row 5, solid ground under it), the column of its first
/// slope tile, and its standing height above the row's bottom line as a
/// function of the foot's offset from that column's left edge and the tile
/// size.
pub struct Ramp {
    pub name: &'static str,
    pub row: &'static str,
    pub col: i32,
    pub height: fn(i32, i32) -> i32,
}

pub const RAMPS: [Ramp; 4] = [
    Ramp {
        name: "45 rising right",
        row: "...../########",
        col: 5,
        height: |x, t| x.clamp(0, t),
    },
    Ramp {
        name: "45 rising left",
        row: "########\\.....",
        col: 8,
        height: |x, t| t - x.clamp(0, t),
    },
    Ramp {
        name: "22.5 rising right",
        row: ".....ab#######",
        col: 5,
        height: |x, t| x.clamp(0, 2 * t).div_euclid(2),
    },
    Ramp {
        name: "22.5 rising left",
        row: "#######cd.....",
        col: 7,
        height: |x, t| t - x.clamp(0, 2 * t).div_euclid(2),
    },
];

/// The ramp's map: five empty rows, its row, two solid rows; tiles of `t`
/// with the top-left corner at `origin`.
pub fn ramp_map(origin: IVec2, t: i32, ramp: &Ramp) -> Tilemap {
    let rows = [
        "..............",
        "..............",
        "..............",
        "..............",
        "..............",
        ramp.row,
        "##############",
        "##############",
    ];
    map_at(origin, t, &rows)
}
