//! The tilemap at tile sizes that are not powers of two: 24, 18, 70, 21 and
//! 31 px (real Tiled maps), plus small even unit counts for the brute-force
//! sweep check. The same properties the 16 px suites (`tilemap.rs`,
//! `sweep.rs`, `tilemap_shapes.rs`, `platformer_*.rs`) check, at each size:
//!
//! * lookups: every whole pixel size from 1 to 1024 px is accepted and tile
//!   lookups are floor divisions at every seam; odd sizes are refused;
//! * flat floor, ceiling and wall seams never snag a sliding box, at every
//!   subpixel offset;
//! * 45 and 22.5 degree ramps are continuous (the floor under a foot
//!   changes by at most one unit between neighbouring unit columns, and is
//!   the ramp's surface function), and a box walking over them with gravity
//!   and the ground snap follows them exactly;
//! * one-way tiles hold from above, let through from below, from the side
//!   and when dropping through;
//! * swept boxes, circles and segments crossing the world in one tick never
//!   tunnel through a one-tile floor or wall, and tile sweeps agree with a
//!   brute-force walk of the contact rules;
//! * a player (the whole game: controller, world, tile rules) runs over a
//!   row of tiles and up and down 45 and 22.5 degree hills staying
//!   grounded, and drops through one-way tiles.
//!
//! The helpers (the local contact loop, slides, random maps, shots, the
//! hills run) are the 16 px suites' own, from `tile_kit`, given the size.

use crate::platformer_kit;
use crate::tile_kit::{
    against, col_x, first_pushed_back, pushes, ramp_map, random_map, resolve, resolved, row_y, run,
    run_hills, shot, slide, v, w, RAMPS,
};

use glam::IVec2;
use ledge_shared::fixed::{px, MAX_COORD, MAX_EXTENT, MAX_SPEED};
use ledge_shared::game::GameEvent;
use ledge_shared::level::EntityKind;
use ledge_shared::query::ray::Toi;
use ledge_shared::query::sweep::sweep_tiles;
use ledge_shared::shape::{Aabb, Circle, Segment};
use ledge_shared::tilemap::{ContactFlags, Tile, Tilemap, TilemapError};
use ledge_shared::world::{AnyShape, BodyDesc, ColliderDesc, SimConfig, World};
use platformer_kit::{ent_sized, jumped, level_sized, map_at, Sim, DOWN_JUMP, JUMP, NONE};
use proptest::prelude::*;

/// Tile sizes of real maps, none a power of two (21 and 31 px: an odd
/// number of pixels, still an even number of units).
const SIZES: [i32; 5] = [px(24), px(18), px(70), px(21), px(31)];

/// A grid origin that is not aligned to anything.
const ORIGIN: IVec2 = IVec2::new(-5 * 4096 + 77, -1234);

// ------------------------------------------------------------------ lookups

#[test]
fn every_whole_pixel_size_is_accepted_and_looked_up_by_floor_division() {
    for n in 1..=1024 {
        let t = px(n);
        let m = map_at(ORIGIN, t, &["#.#.", "./.#"]);
        assert_eq!(m.tile_size(), t);
        for c in -2..6 {
            for r in -2..4 {
                let corner = ORIGIN + IVec2::new(c, r) * t;
                // The tile's top-left unit and its bottom-right unit are in
                // it; the units just outside are in the neighbours.
                assert_eq!(m.tile_of(corner), IVec2::new(c, r), "{n} px");
                assert_eq!(m.tile_of(corner + IVec2::splat(t - 1)), IVec2::new(c, r));
                assert_eq!(m.tile_of(corner - IVec2::ONE), IVec2::new(c - 1, r - 1));
            }
        }
        // The '/' at (1, 1): solid from its surface `tb - x` down.
        let (tl, tb) = (col_x(&m, 1), row_y(&m, 2));
        for x in [1, 2, t / 3, t / 2, t - 1] {
            assert!(m.is_solid_at(IVec2::new(tl + x, tb - x)), "{n} px at {x}");
            assert!(!m.is_solid_at(IVec2::new(tl + x, tb - x - 1)), "{n} px");
        }
    }
    // Even unit counts that are no whole number of pixels are fine too.
    for t in [2, 6, 10, 258, 3000, MAX_EXTENT - 2, MAX_EXTENT] {
        assert!(Tilemap::new(IVec2::ZERO, t, 1, 1, vec![Tile::Solid]).is_ok());
    }
}

#[test]
fn odd_and_tiny_sizes_are_refused_and_named() {
    for t in [1, 3, 255, 257, px(21) + 1, px(1024) - 1, 0, -2, -px(24)] {
        let e = Tilemap::new(IVec2::ZERO, t, 1, 1, vec![Tile::Solid]).unwrap_err();
        assert_eq!(e, TilemapError::TileSize { value: t as i64 });
        let s = e.to_string();
        assert!(s.contains(&t.to_string()) && s.contains("even"), "{s}");
    }
    // Too large: the bounds error, naming the value.
    let e = Tilemap::new(IVec2::ZERO, MAX_EXTENT + 2, 1, 1, vec![Tile::Solid]).unwrap_err();
    assert!(matches!(e, TilemapError::Bounds(_)), "{e}");
    assert!(e.to_string().contains(&(MAX_EXTENT + 2).to_string()), "{e}");
}

// ------------------------------------------------------------ box contacts

/// A box narrower than every tile size here and taller than the smaller
/// ones; and one wider than a tile of size `t`.
fn boxes(t: i32) -> [IVec2; 2] {
    [
        IVec2::new(px(5) + 37, px(11) + 3),
        IVec2::new(t + 301, px(3) + 5),
    ]
}

/// Speeds in units per tick, from 1 unit to 3 px.
const SPEEDS: [i32; 10] = [1, 2, 7, 64, 255, 256, 257, 511, 513, 768];

#[test]
fn floor_and_ceiling_seams_never_snag_at_every_subpixel_offset() {
    for t in SIZES {
        let m = map_at(
            ORIGIN,
            t,
            &[
                "##########",
                "##########",
                "..........",
                "..........",
                "..........",
                "..........",
                "##########",
                "##########",
            ],
        );
        let (ceiling, floor, seam) = (row_y(&m, 2), row_y(&m, 6), col_x(&m, 5));
        let [narrow, wide] = boxes(t);
        for dir in [IVec2::X, -IVec2::X] {
            for press in [0, 1, 150, 768] {
                slide(&m, narrow, dir, IVec2::Y, floor, seam, press, &SPEEDS);
                slide(&m, wide, dir, IVec2::Y, floor, seam, press, &[1, 256, 257]);
            }
            for press in [0, 1, 150] {
                slide(
                    &m,
                    narrow,
                    dir,
                    -IVec2::Y,
                    ceiling,
                    seam,
                    press,
                    &[1, 255, 256, 513],
                );
                slide(&m, wide, dir, -IVec2::Y, ceiling, seam, press, &[257]);
            }
        }
    }
}

#[test]
fn wall_seams_never_snag_at_every_subpixel_offset() {
    for t in SIZES {
        let rows = vec!["##.....##"; 10];
        let m = map_at(ORIGIN, t, &rows);
        let seam = row_y(&m, 5);
        let (left_wall, right_wall) = (col_x(&m, 2), col_x(&m, 7));
        for half in boxes(t) {
            for dir in [IVec2::Y, -IVec2::Y] {
                for press in [0, 1, 150] {
                    slide(
                        &m,
                        half,
                        dir,
                        IVec2::X,
                        right_wall,
                        seam,
                        press,
                        &[1, 256, 257],
                    );
                    slide(
                        &m,
                        half,
                        dir,
                        -IVec2::X,
                        left_wall,
                        seam,
                        press,
                        &[1, 255, 513],
                    );
                }
            }
        }
    }
}

/// Over every unit column of each ramp, flat -> slope -> flat, the floor
/// under a foot is the ramp's surface function (so it changes by at most
/// one unit between neighbouring columns), a box of any width resting there
/// is pushed by nothing, and one unit lower it is pushed straight up by one.
#[test]
fn ramps_are_continuous_at_every_unit_column() {
    let mut buf = Vec::new();
    let flags = ContactFlags::default();
    for t in SIZES {
        for ramp in &RAMPS {
            let m = ramp_map(ORIGIN, t, ramp);
            let (base, left) = (row_y(&m, 6), col_x(&m, ramp.col));
            let half = boxes(t)[0];
            let mut last: Option<i32> = None;
            for x in left - t..left + 3 * t {
                let name = ramp.name;
                let y = m
                    .ground_below(IVec2::new(x, row_y(&m, 3)), 4 * t)
                    .unwrap_or_else(|| panic!("{name} T {t}: no floor at {x}"));
                assert_eq!(y, base - (ramp.height)(x - left, t), "{name} T {t} x {x}");
                if let Some(l) = last {
                    assert!((y - l).abs() <= 1, "{name} T {t}: step at {x}");
                }
                last = Some(y);
                // Every 7th column (cheaper, still every offset class of
                // the box's corners over a seam across the sizes).
                if (x - left) % 7 == 0 {
                    let pos = IVec2::new(x, y - half.y);
                    let down = IVec2::new(0, 1);
                    assert!(
                        resolved(&m, pos, half, pos - down, flags, &mut buf),
                        "{name} T {t} x {x}: {buf:?}"
                    );
                    buf.clear();
                    m.box_contacts(pos + down, half, down, flags, &mut buf);
                    assert!(
                        buf.iter().any(|c| c.mtv == -down)
                            && buf.iter().all(|c| c.mtv.x == 0 && c.mtv.y >= -1),
                        "{name} T {t} x {x}: {buf:?}"
                    );
                }
            }
        }
    }
}

/// Walks over each ramp both ways with gravity and the ground snap: the
/// foot is on the surface function every tick, the x speed never changes,
/// nothing is left overlapping (`ramps_are_followed_exactly` in
/// `tilemap.rs`, with fewer speeds and offsets).
#[test]
fn ramps_are_followed_exactly() {
    let mut buf = Vec::new();
    let flags = ContactFlags::default();
    for t in SIZES {
        for ramp in &RAMPS {
            let m = ramp_map(ORIGIN, t, ramp);
            let (base, left) = (row_y(&m, 6), col_x(&m, ramp.col));
            let surface = |foot_x: i32| base - (ramp.height)(foot_x - left, t);
            for half in boxes(t) {
                for (gravity, speed) in [
                    (0, 16),
                    (90, 97),
                    (1, 255),
                    (700, 256),
                    (90, 257),
                    (0, 511),
                    (90, 768),
                ] {
                    for dir in [1, -1] {
                        for sub in (0..speed).step_by(1 + speed as usize / 16) {
                            let x0 = left + if dir > 0 { -t + sub } else { 3 * t + 1 - sub };
                            let mut pos = IVec2::new(x0, surface(x0) - half.y);
                            while (dir > 0 && pos.x < left + 3 * t) || (dir < 0 && pos.x > left - t)
                            {
                                let start = pos;
                                pos += IVec2::new(dir * speed, gravity);
                                let pushed = resolve(&m, &mut pos, half, start, flags, &mut buf);
                                if pushed.y >= 0 {
                                    let foot = IVec2::new(pos.x, pos.y + half.y);
                                    if let Some(y) = m.ground_below(foot, speed) {
                                        pos.y = y - half.y;
                                    }
                                }
                                let what = format!(
                                    "{} T {t} half {half} g {gravity} v {} x {}",
                                    ramp.name,
                                    dir * speed,
                                    pos.x
                                );
                                assert_eq!(pos.x - start.x, dir * speed, "x speed: {what}");
                                assert_eq!(pos.y + half.y, surface(pos.x), "foot: {what}");
                                assert!(
                                    resolved(&m, pos, half, start, flags, &mut buf),
                                    "overlap: {what}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn one_way_tiles_at_every_size() {
    for t in SIZES {
        let m = map_at(
            ORIGIN,
            t,
            &[
                "........", "........", "........", "..----..", "........", "........", "........",
                "########",
            ],
        );
        let half = boxes(t)[0];
        let (top, ground) = (row_y(&m, 3), row_y(&m, 7));
        let flags = ContactFlags::default();
        // Lands from above, across the seams between the platform's tiles,
        // at many offsets; never below the top at any tick.
        for fall in [1, 300, 1000] {
            for sub in 0..32 {
                let x = col_x(&m, 3) + sub * (t / 16);
                let start = IVec2::new(x, top - half.y - 20 * fall - sub);
                let path = run(&m, start, half, IVec2::new(5, fall), flags, 60);
                assert_eq!(path.last().unwrap().y + half.y, top, "T {t} fall {fall}");
                assert!(path.iter().all(|p| p.y + half.y <= top), "T {t}");
            }
        }
        // From below: straight up through it.
        let x = col_x(&m, 4);
        let rise = -300;
        let n = ((ground - top + 2 * half.y) / 300 + 2) as usize;
        let path = run(
            &m,
            IVec2::new(x, ground - half.y),
            half,
            IVec2::new(0, rise),
            flags,
            n,
        );
        for (i, p) in path.iter().enumerate() {
            assert_eq!(p.y, ground - half.y + rise * (i as i32 + 1), "T {t}");
        }
        // From the side, bottom below the top line: straight through.
        for depth in [1, 100, 2 * half.y - 1] {
            let p0 = IVec2::new(col_x(&m, 0), top + depth - half.y);
            let n = (7 * t / 250) as usize;
            let path = run(&m, p0, half, IVec2::new(250, 0), flags, n);
            for (i, p) in path.iter().enumerate() {
                assert_eq!(*p, p0 + IVec2::new(250 * (i as i32 + 1), 0), "T {t}");
            }
        }
        // Resting on it and walking along it: stays; dropping through: falls
        // to the ground.
        let rest = IVec2::new(col_x(&m, 2) + half.x, top - half.y);
        let path = run(
            &m,
            rest,
            half,
            IVec2::new(200, 90),
            flags,
            (3 * t / 200) as usize,
        );
        assert!(path.iter().all(|p| p.y == rest.y), "T {t}");
        let drop = ContactFlags { drop_through: true };
        let n = ((ground - top) / 90 + 5) as usize;
        let path = run(&m, rest, half, IVec2::new(0, 90), drop, n);
        assert_eq!(path[0].y, rest.y + 90, "T {t}");
        assert_eq!(path.last().unwrap().y + half.y, ground, "T {t}");
    }
}

// ------------------------------------------------------------------ sweeps

/// A tile size: one of [`SIZES`] or any even number of units up to 2048 px.
fn any_size() -> impl Strategy<Value = i32> {
    prop_oneof![
        proptest::sample::select(SIZES.to_vec()),
        (1i32..=px(1024)).prop_map(|n| 2 * n),
    ]
}

/// Small even sizes, mostly not powers of two, for lattice walks.
fn small_size() -> impl Strategy<Value = i32> {
    proptest::sample::select(vec![6, 10, 12, 14, 18, 20, 22, 24, 30, 34])
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// A box crossing the whole world in one tick never passes a one-tile
    /// floor (solid or one-way, from above), ceiling or wall, and stops
    /// exactly on it (`boxes_never_tunnel_through_tile_rows` in `sweep.rs`).
    #[test]
    fn boxes_never_tunnel_through_tile_rows(
        t in any_size(),
        half in (1i32..=1 << 14, 1i32..=1 << 14),
        ox in -(MAX_COORD / 2)..=MAX_COORD / 2,
        x in 0.0f64..1.0,
        kind in proptest::sample::select(vec!['#', '-']),
        down in any::<bool>(),
        drift in -(1i64 << 7)..=1 << 7,
    ) {
        let half = v(half.0, half.1);
        let b = Aabb::new(half).unwrap();
        let x = t + (x * (2 * t) as f64) as i32;
        let row: String = std::iter::repeat_n(kind, 4).collect();
        let m = map_at(v(ox, 0), t, &["....", &row, "...."]);
        let flags = ContactFlags::default();
        if down || kind == '-' {
            let start = v(ox + x, -MAX_COORD + (1 << 16));
            let d = w(drift, 2 * MAX_COORD as i64 - (1 << 17));
            let h = sweep_tiles(&m, &b, start, d, flags).expect("stopped by the floor");
            prop_assert_eq!(h.hit.normal, w(0, -1));
            prop_assert_eq!(h.hit.stop.y + half.y, t);
        } else {
            let start = v(ox + x, MAX_COORD - (1 << 16));
            let d = w(drift, -(2 * MAX_COORD as i64) + (1 << 17));
            let h = sweep_tiles(&m, &b, start, d, flags).expect("stopped by the ceiling");
            prop_assert_eq!(h.hit.normal, w(0, 1));
            prop_assert_eq!(h.hit.stop.y - half.y, 2 * t);
        }
        let m = map_at(v(ox, 0), t, &[".#..", ".#..", ".#.."]);
        let y = (x / 2).max(1).min(3 * t - 1);
        let start = v(-MAX_COORD + (1 << 16), y);
        let h = sweep_tiles(&m, &b, start, w(2 * MAX_COORD as i64 - (1 << 17), 0), flags)
            .expect("stopped by the wall");
        prop_assert_eq!((h.hit.normal, h.hit.stop.x + half.x), (w(-1, 0), ox + t));
    }

    /// Swept circles and segments in a world never tunnel through a
    /// one-tile wall or one-way row (`swept_shapes_never_tunnel_*` in
    /// `tilemap_shapes.rs`).
    #[test]
    fn swept_shapes_never_tunnel_through_a_wall_or_one_way_row(
        t in proptest::sample::select(SIZES.to_vec()),
        circle in any::<bool>(),
        size in 64i32..2000,
        across in 0.0f64..1.0,
        along in 0.0f64..1.0,
        speed in 2_000i32..=MAX_SPEED,
        drift in -1000i32..1000,
        one_way in any::<bool>(),
    ) {
        let shape: AnyShape = if circle {
            Circle::new(size).unwrap().into()
        } else {
            Segment::new(v(-size, -size / 2), v(size, size / 2)).unwrap().into()
        };
        // `a` along the wall (3 to 13 tiles), `b` towards it (1 to 6).
        let a = 3 * t + (along * (10 * t) as f64) as i32;
        let b = t + (across * (5 * t) as f64) as i32;
        let (start, vel) = if one_way {
            (v(a, b), v(drift, speed))
        } else {
            (v(b, a), v(speed, drift))
        };
        let (mut w, body, _) = shot(shape, t, start, vel, one_way);
        w.step(&[]);
        w.step(&[]);
        let p = w.body(body).unwrap().pos();
        let (lead, reach) = if one_way {
            (p.y + shape.local_bounds().1.y, b as i64 + shape.local_bounds().1.y as i64)
        } else {
            (p.x + shape.local_bounds().1.x, b as i64 + shape.local_bounds().1.x as i64)
        };
        prop_assert!(lead <= 8 * t + 1, "T {}: tunnelled to {}", t, p);
        if reach + 2 * speed as i64 > 8 * t as i64 + 2 {
            prop_assert!(lead >= 8 * t - 2, "T {}: stopped short at {}", t, p);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, max_global_rejects: 100_000, ..ProptestConfig::default() })]

    /// `tiles_agree_with_box_contacts` of `sweep.rs` at small even tile
    /// sizes that are not powers of two: along unit lattice paths the box
    /// sweep stops no later than the first position the contact rules push
    /// back against the motion, at a clean position, and reports nothing
    /// when no position is pushed back; it moves with the map.
    #[test]
    fn tile_sweeps_agree_with_box_contacts(
        m in random_map(small_size()),
        half in (1i32..=14, 1i32..=14),
        start in (-30i32..=250, -30i32..=180),
        d0 in proptest::sample::select(vec![v(1, 0), v(-1, 0), v(0, 1), v(0, -1), v(1, 1), v(-1, 1), v(1, -1), v(-1, -1)]),
        k in 1i32..=90,
        drop in any::<bool>(),
    ) {
        let t = m.tile_size();
        let half = v(half.0, half.1);
        let start = v(start.0, start.1) * t / 16;
        let flags = ContactFlags { drop_through: drop };
        prop_assume!(pushes(&m, start, half, IVec2::ZERO, flags).is_empty());
        let b = Aabb::new(half).unwrap();
        let d = d0 * k;
        let hit = sweep_tiles(&m, &b, start, d.as_i64vec2(), flags);
        let first = first_pushed_back(&m, start, half, d0, k, flags);
        match (hit, first) {
            (None, None) => {}
            (None, Some(j)) => prop_assert!(false, "T {}: no hit, but lattice {} of {} is pushed", t, j, k),
            (Some(h), first) => {
                let h = h.hit;
                prop_assert!(!h.started_inside());
                if let Some(j) = first {
                    prop_assert!(h.toi <= Toi::new(j as u64, k as u64).unwrap(), "T {}: toi {:?} after {}", t, h.toi, j);
                }
                let moved = h.stop - start;
                let p = pushes(&m, h.stop, half, moved, flags);
                let back = p.iter().any(|c| against(c, d0));
                prop_assert!(!back, "T {}: stop {} pushed back: {:?}", t, h.stop, p);
                let shift = v(7 * t, -3 * t);
                let moved_map = Tilemap::new(m.origin() + shift, t, 7, 5, m.tiles().to_vec()).unwrap();
                let h2 = sweep_tiles(&moved_map, &b, start + shift, d.as_i64vec2(), flags).unwrap();
                prop_assert_eq!(h2.hit.toi, h.toi);
                prop_assert_eq!(h2.hit.normal, h.normal);
                prop_assert_eq!(h2.hit.stop, h.stop + shift);
            }
        }
    }
}

/// A circle rolling (sliding: frictionless) over a floor of tiles crosses
/// every seam without a snag, from many subpixel offsets (the tiles'
/// regions: `a_circle_rolls_across_floor_seams_at_every_subpixel_offset` in
/// `tilemap_shapes.rs`).
#[test]
fn a_circle_slides_across_floor_seams() {
    for t in SIZES {
        let rows = ["................", "................", "################"];
        for off in (0..256).step_by(17) {
            let m = map_at(IVec2::ZERO, t, &rows);
            let start = v(t / 2 + off, 2 * t - 1500);
            let mut w = World::new(SimConfig::default()).unwrap();
            w.set_tilemap(m);
            let b = w.add_body(BodyDesc::dynamic(start)).unwrap();
            w.add_collider(b, ColliderDesc::solid(Circle::new(1500).unwrap()))
                .unwrap();
            let vx = 300 + off;
            let ticks = 12 * t / vx;
            for _ in 0..ticks {
                let vy = w.body(b).unwrap().vel().y;
                w.set_velocity(b, v(vx, vy + 40)).unwrap();
                w.step(&[]);
            }
            let p = w.body(b).unwrap().pos();
            assert_eq!(p.x, start.x + ticks * vx, "T {t} offset {off}: snagged");
            assert!((p.y - start.y).abs() <= 41, "T {t} offset {off}: {p}");
        }
    }
}

// ---------------------------------------------------------------- the game

#[test]
fn a_player_runs_over_tiles_and_hills_staying_grounded() {
    for t in SIZES {
        for speed in [256, 640, 1536] {
            run_hills(t, 20, speed, 2, 26);
            run_hills(t, 20, speed, 26, 2);
        }
    }
}

#[test]
fn a_player_stands_on_and_drops_through_one_way_tiles() {
    for t in SIZES {
        let rows = [
            "##########",
            "#........#",
            "#........#",
            "#........#",
            "#===.....#",
            "#........#",
            "#........#",
            "##########",
        ];
        let lv = level_sized(t, &rows, vec![ent_sized(EntityKind::PlayerSpawn, t, 2, 3)]);
        let mut s = Sim::new(&lv);
        s.land(100);
        assert_eq!(s.bottom(), 4 * t, "T {t}: stands on the one-way tiles");
        s.step(JUMP);
        assert!(s.saw(jumped), "T {t}");
        s.land(200);
        assert_eq!(s.bottom(), 4 * t, "T {t}");
        s.step(NONE);
        s.step(DOWN_JUMP);
        assert!(
            s.saw(|e| matches!(e, GameEvent::DroppedThrough(_))),
            "T {t}: {:?}",
            s.events
        );
        assert!(!s.saw(jumped), "T {t}");
        s.land(200);
        assert_eq!(s.bottom(), 7 * t, "T {t}: on the floor below");
    }
}
