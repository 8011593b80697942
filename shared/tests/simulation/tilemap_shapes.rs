//! Circles, segments, oriented boxes and polygons against the tilemap:
//! discrete contacts (resting, seams, slopes, walls, one-way tiles) and
//! exact sweeps (no tunnelling, agreement with a brute-force walk).

use glam::{I64Vec2, IVec2};
use ledge_shared::fixed::MAX_SPEED;
use ledge_shared::input::Buttons;
use ledge_shared::query::sweep::sweep_shape_tiles;
use ledge_shared::query::{contact, Proximity};
use ledge_shared::shape::{Aabb, Circle, ConvexPolygon, Obb, Segment};
use ledge_shared::tilemap::{ContactFlags, Slope, Tile, TileRegion, Tilemap};
use ledge_shared::world::{AnyShape, BodyDesc, BodyId, ColliderDesc, SimConfig, World};
use proptest::prelude::*;

use crate::platformer_kit;
use crate::tile_kit::shot;
use platformer_kit::{map, T};

/// Gravity per tick, in units per tick.
const G: i32 = 40;

/// The four non-box kinds the issue names, about one tile wide.
fn shapes() -> Vec<(&'static str, AnyShape)> {
    vec![
        ("circle", Circle::new(1500).unwrap().into()),
        // Slanted: a perfectly level segment lying on a tile line only
        // touches the tiles on both sides of it (see the tilemap docs).
        (
            "segment",
            Segment::new(IVec2::new(-1500, 200), IVec2::new(1500, -200))
                .unwrap()
                .into(),
        ),
        (
            "obb",
            Obb::new(IVec2::new(1500, 800), IVec2::new(3, 1))
                .unwrap()
                .into(),
        ),
        (
            "triangle",
            ConvexPolygon::new(&[
                IVec2::new(-1500, 1000),
                IVec2::new(1500, 1000),
                IVec2::new(0, -1000),
            ])
            .unwrap()
            .into(),
        ),
    ]
}

/// Deepest overlap (largest MTV component) of `shape` at `pos` with any
/// tile region of the map, culling ignored: how far it sank.
fn sink(m: &Tilemap, shape: &AnyShape, pos: IVec2) -> i32 {
    let mut deepest = 0;
    for r in 0..m.height() as i32 {
        for c in 0..m.width() as i32 {
            let tile = IVec2::new(c, r);
            let p = match m.tile_region(tile, m.tile(tile)) {
                Some(TileRegion::Square { shape: b, centre }) => prox(shape, pos, &b, centre),
                Some(TileRegion::Slope { shape: s, centre }) => prox(shape, pos, &s, centre),
                _ => Proximity::Apart,
            };
            if let Proximity::Overlapping(v) = p {
                deepest = deepest.max(v.x.abs()).max(v.y.abs());
            }
        }
    }
    deepest
}

fn prox<B>(a: &AnyShape, pos: IVec2, b: &B, bpos: IVec2) -> Proximity
where
    Circle: ledge_shared::query::Contact<B>,
    Segment: ledge_shared::query::Contact<B>,
    Obb: ledge_shared::query::Contact<B>,
    ConvexPolygon: ledge_shared::query::Contact<B>,
    Aabb: ledge_shared::query::Contact<B>,
{
    match a {
        AnyShape::Circle(s) => contact(s, pos, b, bpos),
        AnyShape::Segment(s) => contact(s, pos, b, bpos),
        AnyShape::Obb(s) => contact(s, pos, b, bpos),
        AnyShape::Polygon(s) => contact(s, pos, b, bpos),
        AnyShape::Aabb(s) => contact(s, pos, b, bpos),
        AnyShape::Point(_) => unreachable!("no points here"),
    }
}

/// A world with `m` and one dynamic body of `shape` at `pos`.
fn world(m: Tilemap, shape: AnyShape, pos: IVec2, vel: IVec2) -> (World, BodyId) {
    let mut w = World::new(SimConfig::default()).unwrap();
    w.set_tilemap(m);
    let b = w.add_body(BodyDesc::dynamic(pos).with_vel(vel)).unwrap();
    w.add_collider(b, ColliderDesc::solid(shape)).unwrap();
    (w, b)
}

/// Steps with gravity; calls `check` after every tick.
fn run(w: &mut World, b: BodyId, ticks: u32, vx: Option<i32>, mut check: impl FnMut(&World)) {
    for _ in 0..ticks {
        let v = w.body(b).unwrap().vel();
        let vx = vx.unwrap_or(v.x);
        w.set_velocity(b, IVec2::new(vx, v.y + G)).unwrap();
        w.step(&[Buttons::NONE; 0]);
        check(w);
    }
}

#[test]
fn shapes_fall_onto_a_tile_floor_and_rest_on_it() {
    for (name, shape) in shapes() {
        let m = map(&["....", "....", "....", "####"]);
        let (mut w, b) = world(
            m.clone(),
            shape,
            IVec2::new(2 * T - 300, T / 2),
            IVec2::ZERO,
        );
        let mut ys = Vec::new();
        run(&mut w, b, 240, Some(0), |w| {
            let p = w.body(b).unwrap().pos();
            assert!(sink(&m, &shape, p) <= G + 1, "{name} sank at {p}");
            ys.push(p.y);
        });
        let p = w.body(b).unwrap().pos();
        // At rest on the floor: the bottom of the shape on the floor's top.
        let bottom = p.y + shape.local_bounds().1.y;
        assert!((bottom - 3 * T).abs() <= G + 1, "{name}: bottom {bottom}");
        let last = &ys[ys.len() - 30..];
        let (lo, hi) = (last.iter().min().unwrap(), last.iter().max().unwrap());
        assert!(hi - lo <= G + 1, "{name} not at rest: {lo}..{hi}");
        assert!(sink(&m, &shape, p) <= 1, "{name} overlaps after resting");
    }
}

#[test]
fn a_circle_rolls_across_floor_seams_at_every_subpixel_offset() {
    let shape: AnyShape = Circle::new(1500).unwrap().into();
    for off in (0..256).step_by(7) {
        let m = map(&["................", "................", "################"]);
        let start = IVec2::new(T / 2 + off, 2 * T - 1500);
        let (mut w, b) = world(m, shape, start, IVec2::ZERO);
        let vx = 300 + off;
        run(&mut w, b, 60, Some(vx), |_| {});
        let body = w.body(b).unwrap();
        assert_eq!(body.pos().x, start.x + 60 * vx, "offset {off}: snagged");
        assert!(body.pos().y <= start.y + 1, "offset {off}: sank");
    }
}

#[test]
fn other_shapes_slide_across_floor_seams() {
    for (name, shape) in shapes() {
        let m = map(&["........", "........", "########"]);
        let bottom = shape.local_bounds().1.y;
        let start = IVec2::new(T, 2 * T - bottom);
        let (mut w, b) = world(m, shape, start, IVec2::ZERO);
        run(&mut w, b, 60, Some(333), |_| {});
        let p = w.body(b).unwrap().pos();
        assert_eq!(p.x, start.x + 60 * 333, "{name} snagged");
        assert!((p.y - start.y).abs() <= G + 1, "{name}: {p}");
    }
}

#[test]
fn shapes_on_a_45_degree_slope_never_sink_in() {
    for (name, shape) in shapes() {
        let m = map(&["#......#", "#......#", "#...../#", "#..../##", "########"]);
        let start = IVec2::new(5 * T + T / 2, T / 2);
        let (mut w, b) = world(m.clone(), shape, start, IVec2::ZERO);
        run(&mut w, b, 300, None, |w| {
            let p = w.body(b).unwrap().pos();
            assert!(
                sink(&m, &shape, p) <= 2 * G,
                "{name} sank into the slope at {p}"
            );
        });
        let p = w.body(b).unwrap().pos();
        assert!(
            sink(&m, &shape, p) <= 2 * G,
            "{name} ends in the slope at {p}"
        );
        // It slid down (frictionless) or rests, but is still above the floor.
        assert!(
            p.y + shape.local_bounds().1.y <= 4 * T + 1,
            "{name} fell through: {p}"
        );
        assert!(p.x > T && p.x < 7 * T, "{name} left the room: {p}");
    }
}

/// A one-tile wall standing on the floor stops every shape sliding into
/// it.
#[test]
fn a_one_tile_wall_stops_shapes() {
    let all = shapes();
    for (name, shape) in all {
        let m = map(&["....#...", "....#...", "....#...", "########"]);
        let bottom = shape.local_bounds().1.y;
        let start = IVec2::new(T, 3 * T - bottom);
        let (mut w, b) = world(m, shape, start, IVec2::ZERO);
        run(&mut w, b, 120, Some(600), |_| {});
        let p = w.body(b).unwrap().pos();
        let right = p.x + shape.local_bounds().1.x;
        assert!(right <= 4 * T + 1, "{name} went into the wall: {p}");
        assert!(right >= 4 * T - 700, "{name} stopped early: {p}");
    }
}

#[test]
fn one_way_tiles_hold_from_above_and_let_through_from_below() {
    for (name, shape) in shapes() {
        let m = map(&["....", "....", "====", "....", "...."]);
        let (mut w, b) = world(m.clone(), shape, IVec2::new(2 * T, T / 2), IVec2::ZERO);
        run(&mut w, b, 200, Some(0), |_| {});
        let p = w.body(b).unwrap().pos();
        let bottom = p.y + shape.local_bounds().1.y;
        assert!((bottom - 2 * T).abs() <= G + 1, "{name} not held: {p}");
        // From below, moving up: passes through.
        let (mut w, b) = world(m, shape, IVec2::new(2 * T, 4 * T), IVec2::new(0, -1200));
        for _ in 0..10 {
            w.step(&[]);
        }
        let p = w.body(b).unwrap().pos();
        assert!(p.y < 2 * T - 2000, "{name} blocked from below: {p}");
    }
}

fn projectile(kind: u8, size: i32) -> AnyShape {
    match kind {
        0 => Circle::new(size).unwrap().into(),
        _ => Segment::new(IVec2::new(-size, -size / 2), IVec2::new(size, size / 2))
            .unwrap()
            .into(),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn swept_shapes_never_tunnel_through_a_wall(
        kind in 0u8..2,
        size in 64i32..2000,
        y in 3 * T..13 * T,
        speed in 2_000i32..=MAX_SPEED,
        vy in -1000i32..1000,
        x in T..6 * T,
    ) {
        let shape = projectile(kind, size);
        let (mut w, b, m) = shot(shape, T, IVec2::new(x, y), IVec2::new(speed, vy), false);
        w.step(&[]);
        w.step(&[]);
        let p = w.body(b).unwrap().pos();
        let right = p.x + shape.local_bounds().1.x;
        prop_assert!(right <= 8 * T + 1, "tunnelled: {}", p);
        prop_assert!(sink(&m, &shape, p) == 0, "overlaps at {}", p);
        // Stopped touching the wall (within a unit or two), unless the path
        // was short of it.
        let reach = x as i64 + shape.local_bounds().1.x as i64 + 2 * speed as i64;
        if reach > 8 * T as i64 + 2 {
            prop_assert!(right >= 8 * T - 2, "stopped short: {}", p);
        }
    }

    #[test]
    fn swept_shapes_never_tunnel_through_a_one_way_row(
        kind in 0u8..2,
        size in 64i32..2000,
        x in 3 * T..13 * T,
        speed in 2_000i32..=MAX_SPEED,
        vx in -1000i32..1000,
        y in T..6 * T,
    ) {
        let shape = projectile(kind, size);
        let (mut w, b, _) = shot(shape, T, IVec2::new(x, y), IVec2::new(vx, speed), true);
        w.step(&[]);
        w.step(&[]);
        let p = w.body(b).unwrap().pos();
        let bottom = p.y + shape.local_bounds().1.y;
        prop_assert!(bottom <= 8 * T + 1, "fell through: {}", p);
        let reach = y as i64 + shape.local_bounds().1.y as i64 + 2 * speed as i64;
        if reach > 8 * T as i64 + 2 {
            prop_assert!(bottom >= 8 * T - 2, "stopped short: {}", p);
        }
    }

    #[test]
    fn tile_sweeps_agree_with_a_brute_force_walk(
        kind in 0u8..2,
        size in 200i32..3000,
        sx in 0..16 * T,
        sy in 0..16 * T,
        dx in -4 * T..4 * T,
        dy in -4 * T..4 * T,
        seed in any::<u64>(),
    ) {
        // A random map of solids and 45 degree slopes.
        let mut s = seed;
        let tiles: Vec<Tile> = (0..16 * 16)
            .map(|_| {
                s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                match s >> 60 {
                    0..=1 => Tile::Solid,
                    2 => Tile::Slope(Slope::Right45),
                    3 => Tile::Slope(Slope::Left45),
                    _ => Tile::Empty,
                }
            })
            .collect();
        let m = Tilemap::new(IVec2::ZERO, T, 16, 16, tiles).unwrap();
        let shape = projectile(kind, size);
        let start = IVec2::new(sx, sy);
        prop_assume!(sink(&m, &shape, start) == 0);
        let d = I64Vec2::new(dx as i64, dy as i64);
        let hit = match shape {
            AnyShape::Circle(c) => sweep_shape_tiles(&m, &c, start, d, ContactFlags::default()),
            AnyShape::Segment(g) => sweep_shape_tiles(&m, &g, start, d, ContactFlags::default()),
            _ => unreachable!(),
        };
        // The brute force: the first of 400 steps along the path that
        // overlaps a tile region.
        const STEPS: i64 = 400;
        let at = |k: i64| start + IVec2::new((d.x * k / STEPS) as i32, (d.y * k / STEPS) as i32);
        // The deepest push at `p` (a step position is rounded to whole
        // units, so a push of a unit or two is rounding, not a miss).
        let depth = |p: IVec2| {
            let mut out = Vec::new();
            let f = ContactFlags::default();
            match shape {
                AnyShape::Circle(c) => m.shape_contacts(&c, p, IVec2::ZERO, f, &mut out),
                AnyShape::Segment(g) => m.shape_contacts(&g, p, IVec2::ZERO, f, &mut out),
                _ => unreachable!(),
            }
            out.iter()
                .map(|c| c.mtv.x.abs().max(c.mtv.y.abs()) + 1)
                .max()
                .unwrap_or(0)
        };
        let pushes = |p: IVec2| depth(p) > 3;
        prop_assume!(depth(start) == 0);
        let first = (1..=STEPS).find(|&k| pushes(at(k)));
        match hit {
            Some(h) => {
                // The stop is clean, and the path is clean before it.
                prop_assert_eq!(depth(h.hit.stop), 0, "stop {} is pushed", h.hit.stop);
                let toi = h.hit.toi.num() as f64 / h.hit.toi.den() as f64;
                if let Some(k) = first {
                    prop_assert!(toi <= k as f64 / STEPS as f64 + 1e-9, "hit {} after step {}", toi, k);
                }
                // The surface is really there: a few units from the stop,
                // in the direction of the motion, the shape overlaps a tile
                // region.
                let (gx, gy) = (d.x.signum() as i32, d.y.signum() as i32);
                let beyond = (0..=4)
                    .flat_map(|i| (0..=4).map(move |k| IVec2::new(gx * i, gy * k)))
                    .any(|o| o != IVec2::ZERO && sink(&m, &shape, h.hit.stop + o) > 0);
                prop_assert!(beyond, "hit at {} but nothing past {}", toi, h.hit.stop);
            }
            None => {
                // No hit: the brute-force walk finds no overlap either
                // (a graze shorter than a step aside).
                prop_assert!(first.is_none(), "missed an overlap at step {:?}", first);
            }
        }
    }
}
