//! Tilemap collision: seams never snag, ramps follow their surface function
//! exactly, one-way platforms, hazards, bounds, outside the grid.
//!
//! The world integration comes later, so each test runs a tiny local loop:
//! `pos += v`, then [`resolve`] (largest MTV first, each contact re-checked
//! with `Tilemap::tile_contact` before it is applied, no push back against
//! this tick's pushes), then, on ramps, a ground snap with
//! `Tilemap::ground_below` when nothing pushed the box up.

use glam::IVec2;
use ledge_shared::fixed::{px, MAX_COORD};
use ledge_shared::tilemap::{ContactFlags, Slope, Tile, Tilemap, TilemapError};

use crate::platformer_kit;
use crate::tile_kit::{col_x, ramp_map, resolve, resolved, row_y, run, slide, RAMPS};
use platformer_kit::map_at;

/// 16 px tiles.
const T: i32 = px(16);

/// Box sizes: narrower than a tile and taller than one; wider than a tile.
const BOXES: [IVec2; 2] = [
    IVec2::new(px(5) + 37, px(11) + 3),
    IVec2::new(T + 301, px(3) + 5),
];

/// Grid origins: unaligned near the world's centre, and far out.
const ORIGINS: [IVec2; 2] = [
    IVec2::new(-5 * T + 77, -1234),
    IVec2::new(MAX_COORD - 40 * T - 5, -MAX_COORD + 3),
];

/// A tilemap with its top-left corner at `origin` and tiles of [`T`].
fn map(origin: IVec2, rows: &[&str]) -> Tilemap {
    map_at(origin, T, rows)
}

/// Speeds in units per tick, from 1 unit to 3 px.
const SPEEDS: [i32; 18] = [
    1, 2, 3, 7, 64, 127, 128, 129, 255, 256, 257, 300, 511, 512, 513, 640, 767, 768,
];

#[test]
fn floor_seams_never_snag() {
    for origin in ORIGINS {
        // A floor three tiles thick, long enough for every run.
        let m = map(
            origin,
            &[
                "..........",
                "..........",
                "..........",
                "##########",
                "##########",
                "##########",
            ],
        );
        let floor = row_y(&m, 3);
        let seam = col_x(&m, 5);
        for half in BOXES {
            for press in [0, 1, 150, 768] {
                slide(&m, half, IVec2::X, IVec2::Y, floor, seam, press, &SPEEDS);
                slide(&m, half, -IVec2::X, IVec2::Y, floor, seam, press, &SPEEDS);
            }
        }
    }
}

#[test]
fn ceiling_seams_never_snag() {
    for origin in ORIGINS {
        let m = map(
            origin,
            &[
                "##########",
                "##########",
                "..........",
                "..........",
                "..........",
                "..........",
            ],
        );
        let ceiling = row_y(&m, 2);
        let seam = col_x(&m, 5);
        for half in BOXES {
            for press in [0, 1, 150] {
                slide(&m, half, IVec2::X, -IVec2::Y, ceiling, seam, press, &SPEEDS);
                slide(
                    &m,
                    half,
                    -IVec2::X,
                    -IVec2::Y,
                    ceiling,
                    seam,
                    press,
                    &SPEEDS,
                );
            }
        }
    }
}

#[test]
fn wall_seams_never_snag() {
    for origin in ORIGINS {
        // Walls two tiles thick on both sides of a shaft.
        let rows = vec!["##.....##"; 10];
        let m = map(origin, &rows);
        let seam = row_y(&m, 5);
        let (left_wall, right_wall) = (col_x(&m, 2), col_x(&m, 7));
        for half in BOXES {
            for press in [0, 1, 150] {
                for dir in [IVec2::Y, -IVec2::Y] {
                    slide(&m, half, dir, IVec2::X, right_wall, seam, press, &SPEEDS);
                    slide(&m, half, dir, -IVec2::X, left_wall, seam, press, &SPEEDS);
                }
            }
        }
    }
}

/// Walks over each ramp, flat -> slope -> flat, in both directions: with
/// gravity and ground snap, the foot is exactly on the surface function every
/// tick, the x speed never changes, nothing is left overlapping.
#[test]
fn ramps_are_followed_exactly() {
    let mut buf = Vec::new();
    let flags = ContactFlags::default();
    for origin in ORIGINS {
        for ramp in &RAMPS {
            let m = ramp_map(origin, T, ramp);
            let base = row_y(&m, 6);
            let left = col_x(&m, ramp.col);
            let surface = |foot_x: i32| base - (ramp.height)(foot_x - left, T);
            for half in BOXES {
                for gravity in [0, 1, 90, 700] {
                    for speed in [1, 3, 16, 100, 255, 256, 257, 511, 768] {
                        for dir in [1, -1] {
                            // Offsets 0..min(speed, 256) visit every foot
                            // position (so every subpixel offset) of the run.
                            for sub in 0..speed.min(256) {
                                let x0 = left
                                    + if dir > 0 {
                                        -3 * T + sub
                                    } else {
                                        4 * T + 1 - sub
                                    };
                                let mut pos = IVec2::new(x0, surface(x0) - half.y);
                                while (dir > 0 && pos.x < left + 4 * T)
                                    || (dir < 0 && pos.x > left - 3 * T)
                                {
                                    let start = pos;
                                    pos += IVec2::new(dir * speed, gravity);
                                    let pushed =
                                        resolve(&m, &mut pos, half, start, flags, &mut buf);
                                    if pushed.y >= 0 {
                                        let foot = IVec2::new(pos.x, pos.y + half.y);
                                        if let Some(y) = m.ground_below(foot, speed) {
                                            pos.y = y - half.y;
                                        }
                                    }
                                    let v = dir * speed;
                                    let name = ramp.name;
                                    assert_eq!(pos.x - start.x, v, "x speed changed: {name} origin {origin} half {half} g {gravity} v {v} x {}", pos.x);
                                    assert_eq!(pos.y + half.y, surface(pos.x), "foot off the surface: {name} origin {origin} half {half} g {gravity} v {v} x {}", pos.x);
                                    assert!(resolved(&m, pos, half, start, flags, &mut buf), "left overlapping: {name} origin {origin} half {half} g {gravity} v {v} x {}", pos.x);
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Without the ground snap, walking down a ramp leaves the surface: the
/// snap in the test above is doing real work (and contacts alone never pull
/// a box down).
#[test]
fn walking_down_without_snap_leaves_the_ground() {
    let m = map(
        ORIGINS[0],
        &["........", "........", "##\\.....", "########"],
    );
    let half = BOXES[0];
    let base = row_y(&m, 3);
    let mut pos = IVec2::new(col_x(&m, 2) - 1, row_y(&m, 2) - half.y);
    let mut buf = Vec::new();
    let start = pos;
    pos += IVec2::new(600, 0);
    assert_eq!(
        resolve(&m, &mut pos, half, start, ContactFlags::default(), &mut buf),
        IVec2::ZERO
    );
    let foot = IVec2::new(pos.x, pos.y + half.y);
    let surface = base - (T - (pos.x - col_x(&m, 2)));
    assert!(foot.y < surface);
    assert_eq!(m.ground_below(foot, 599), Some(surface));
    assert_eq!(m.ground_below(foot, 598), None);
}

#[test]
fn slope_corner_dips_get_no_push_but_walls_and_bottoms_do() {
    let m = map(ORIGINS[0], &["......", "..../.", "......", "......"]);
    let half = IVec2::new(px(4), px(4));
    let (tl, tt) = (col_x(&m, 4), row_y(&m, 1));
    let tb = tt + T;
    let flags = ContactFlags::default();
    let contacts = |pos: IVec2| {
        let mut v = Vec::new();
        m.box_contacts(pos, half, IVec2::ZERO, flags, &mut v);
        v
    };
    // Foot left of the tile, bottom-right corner deep in the triangle.
    assert!(contacts(IVec2::new(tl - 1, tb - 2 * px(1) - half.y)).is_empty());
    // Foot right of the tile, box against its full high side: pushed right.
    let c = contacts(IVec2::new(tl + T + half.x - 100, tb - half.y - 10));
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].mtv, IVec2::new(100, 0));
    assert_eq!(c[0].tile, IVec2::new(4, 1));
    // But not above the surface at that side.
    // (the surface over the high column is one unit below the tile top).
    assert!(contacts(IVec2::new(tl + T + half.x - 100, tt + 1 - half.y)).is_empty());
    assert_eq!(
        contacts(IVec2::new(tl + T + half.x - 100, tt + 2 - half.y)).len(),
        1
    );
    // From below, foot under the tile: pushed down through the bottom.
    let c = contacts(IVec2::new(tl + 50, tb + half.y - 30));
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].mtv, IVec2::new(0, 30));
    // From below with the foot left of it: the bottom still pushes.
    let c = contacts(IVec2::new(tl - half.x + px(2), tb + half.y - 30));
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].mtv, IVec2::new(0, 30));
    // Foot over the tile, just below the surface: straight up onto it.
    let x = tl + 1000;
    let c = contacts(IVec2::new(x, tb - 1000 + 7 - half.y));
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].mtv, IVec2::new(0, -7));
    assert_eq!(c[0].kind, Tile::Slope(Slope::Right45));
}

#[test]
fn solid_corner_ties_push_up() {
    let m = map(ORIGINS[0], &["...", ".#.", "..."]);
    let half = IVec2::new(px(4), px(4));
    let (tl, tt) = (col_x(&m, 1), row_y(&m, 1));
    let mut v = Vec::new();
    // Overlapping the top-left corner by 10 units on both axes.
    m.box_contacts(
        IVec2::new(tl + 10 - half.x, tt + 10 - half.y),
        half,
        IVec2::ZERO,
        ContactFlags::default(),
        &mut v,
    );
    assert_eq!(v.len(), 1);
    assert_eq!(v[0].mtv, IVec2::new(0, -10));
    // One unit less deep in x: the side wins.
    v.clear();
    m.box_contacts(
        IVec2::new(tl + 9 - half.x, tt + 10 - half.y),
        half,
        IVec2::ZERO,
        ContactFlags::default(),
        &mut v,
    );
    assert_eq!(v[0].mtv, IVec2::new(-9, 0));
}

/// One-way platform scene: a platform in row 3, ground in row 7.
fn one_way_map() -> Tilemap {
    map(
        ORIGINS[0],
        &[
            "........", "........", "........", "..----..", "........", "........", "........",
            "########",
        ],
    )
}

#[test]
fn one_way_lands_from_above() {
    let m = one_way_map();
    let half = BOXES[0];
    let top = row_y(&m, 3);
    for fall in [1, 77, 300, 1000] {
        for sub in 0..64 {
            let start = IVec2::new(col_x(&m, 4) + sub * 13, top - half.y - 20 * fall - sub);
            let path = run(
                &m,
                start,
                half,
                IVec2::new(5, fall),
                ContactFlags::default(),
                100,
            );
            let last = *path.last().unwrap();
            assert_eq!(last.y + half.y, top, "fall {fall} sub {sub}");
            // Never below the top at any tick.
            assert!(path.iter().all(|p| p.y + half.y <= top));
        }
    }
}

#[test]
fn one_way_passes_from_below_and_side_and_drop_through() {
    let m = one_way_map();
    let half = BOXES[0];
    let top = row_y(&m, 3);
    let ground = row_y(&m, 7);
    let x = col_x(&m, 4);
    // From below: jump up through it unhindered, then land on it.
    let path = run(
        &m,
        IVec2::new(x, ground - half.y),
        half,
        IVec2::new(0, -300),
        ContactFlags::default(),
        90,
    );
    for (i, p) in path.iter().enumerate() {
        assert_eq!(p.y, ground - half.y - 300 * (i as i32 + 1));
    }
    let above = *path.last().unwrap();
    assert!(above.y + half.y < top);
    let back = run(
        &m,
        above,
        half,
        IVec2::new(0, 200),
        ContactFlags::default(),
        100,
    );
    assert_eq!(back.last().unwrap().y + half.y, top);
    // From the side, bottom below the top line: passes straight through.
    for depth in [1, 100, 2 * half.y - 1] {
        let p0 = IVec2::new(col_x(&m, 0), top + depth - half.y);
        let path = run(
            &m,
            p0,
            half,
            IVec2::new(250, 0),
            ContactFlags::default(),
            120,
        );
        for (i, p) in path.iter().enumerate() {
            assert_eq!(
                *p,
                p0 + IVec2::new(250 * (i as i32 + 1), 0),
                "depth {depth}"
            );
        }
    }
    // Resting on it and walking along it: stays.
    let rest = IVec2::new(col_x(&m, 2) + half.x, top - half.y);
    let path = run(
        &m,
        rest,
        half,
        IVec2::new(200, 90),
        ContactFlags::default(),
        60,
    );
    assert!(path.iter().all(|p| p.y == rest.y));
    // Drop through: falls off it, down to the ground.
    let drop = ContactFlags { drop_through: true };
    let path = run(&m, rest, half, IVec2::new(0, 90), drop, 200);
    assert_eq!(path[0].y, rest.y + 90);
    assert_eq!(path.last().unwrap().y + half.y, ground);
}

#[test]
fn hazards_are_reported_never_pushed() {
    let m = map(ORIGINS[0], &["....", ".^^.", "...."]);
    let half = IVec2::new(px(4), px(4));
    let mut v = Vec::new();
    // Overlapping both hazard tiles.
    let pos = IVec2::new(col_x(&m, 2), row_y(&m, 1) + 5 - half.y);
    m.box_contacts(pos, half, IVec2::ZERO, ContactFlags::default(), &mut v);
    assert_eq!(v.len(), 2);
    for (c, col) in v.iter().zip([1, 2]) {
        assert!(c.is_trigger());
        assert_eq!(c.kind, Tile::Hazard);
        assert_eq!(c.mtv, IVec2::ZERO);
        assert_eq!(c.tile, IVec2::new(col, 1));
    }
    // Touching is not overlapping.
    v.clear();
    m.box_contacts(
        pos - IVec2::new(0, 5),
        half,
        IVec2::ZERO,
        ContactFlags::default(),
        &mut v,
    );
    assert!(v.is_empty());
    // A falling box goes straight through.
    let path = run(
        &m,
        pos - IVec2::new(0, T),
        half,
        IVec2::new(0, 100),
        ContactFlags::default(),
        100,
    );
    assert!(path
        .iter()
        .enumerate()
        .all(|(i, p)| p.y == pos.y - T + 100 * (i as i32 + 1)));
}

#[test]
fn outside_the_grid_is_empty() {
    let m = map(ORIGINS[0], &["###"]);
    let half = IVec2::new(px(4), px(4));
    for t in [
        IVec2::new(-1, 0),
        IVec2::new(3, 0),
        IVec2::new(0, -1),
        IVec2::new(0, 1),
        IVec2::MIN,
        IVec2::MAX,
    ] {
        assert_eq!(m.tile(t), Tile::Empty);
    }
    assert!(!m.is_solid_at(m.origin() - IVec2::ONE));
    assert!(m.is_solid_at(m.origin()));
    let mut v = Vec::new();
    // Far away, and just beside the grid: nothing.
    m.box_contacts(
        IVec2::new(0, MAX_COORD),
        half,
        IVec2::ZERO,
        ContactFlags::default(),
        &mut v,
    );
    m.box_contacts(
        m.origin() - half,
        half,
        IVec2::ZERO,
        ContactFlags::default(),
        &mut v,
    );
    assert!(v.is_empty());
    // The grid's outer faces are exposed (no neighbour covers them).
    m.box_contacts(
        m.origin() + IVec2::new(5 - half.x, T / 2),
        half,
        IVec2::ZERO,
        ContactFlags::default(),
        &mut v,
    );
    assert_eq!(v.len(), 1);
    assert_eq!(v[0].mtv, IVec2::new(-5, 0));
    assert_eq!(m.ground_below(m.origin() - IVec2::new(1, 10), T), None);
    assert_eq!(
        m.ground_below(m.origin() + IVec2::new(0, -10), 10),
        Some(m.origin().y)
    );
    assert_eq!(m.ground_below(m.origin() + IVec2::new(0, -10), 9), None);
}

#[test]
fn bounds_errors_name_the_value() {
    let e = Tilemap::new(IVec2::new(MAX_COORD + 7, 0), T, 1, 1, vec![Tile::Solid]).unwrap_err();
    let s = e.to_string();
    assert!(
        s.contains("tilemap origin x") && s.contains(&(MAX_COORD + 7).to_string()),
        "{s}"
    );
    let e = Tilemap::new(IVec2::ZERO, T, 1, 2, vec![Tile::Solid]).unwrap_err();
    assert!(
        matches!(
            e,
            TilemapError::TileCount {
                expected: 2,
                got: 1,
                ..
            }
        ),
        "{e}"
    );
    // Odd: refused (any even size is fine, see `tilemap_sizes.rs`).
    let e = Tilemap::new(IVec2::ZERO, 1001, 1, 1, vec![Tile::Solid]).unwrap_err();
    assert!(e.to_string().contains("1001"), "{e}");
    let e = Tilemap::new(IVec2::new(0, MAX_COORD - T), T, 1, 2, vec![Tile::Solid; 2]).unwrap_err();
    assert!(e.to_string().contains("tilemap bottom edge y"), "{e}");
}

#[test]
fn contact_buffer_is_reused() {
    let m = map(ORIGINS[0], &["....", "#/##", "####"]);
    let half = BOXES[1];
    let mut v = Vec::with_capacity(64);
    let cap = v.capacity();
    for x in (0..4 * T).step_by(97) {
        v.clear();
        m.box_contacts(
            IVec2::new(m.origin().x + x, row_y(&m, 1) + 50 - half.y),
            half,
            IVec2::new(0, 50),
            ContactFlags::default(),
            &mut v,
        );
    }
    assert_eq!(v.capacity(), cap);
}

/// A short box falling fast onto the low end of a slope can end a tick
/// entirely inside the solid tile under the slope: the slope its foot stands
/// in still lifts it exactly onto the surface.
#[test]
fn fast_landing_sinks_no_further_than_the_slope() {
    let m = map(ORIGINS[0], &["......", "../#..", "######", "######"]);
    let half = IVec2::new(px(2), 100);
    let bottom = row_y(&m, 2);
    let mut buf = Vec::new();
    for x in [0, 1, 50, 99, 150] {
        for fall in [150, 400, 1000, T - 1] {
            let foot_x = col_x(&m, 2) + x;
            let surface = bottom - x;
            // One tick before: just above the surface.
            let start = IVec2::new(foot_x, surface - 1 - half.y);
            let mut pos = start + IVec2::new(0, fall);
            resolve(&m, &mut pos, half, start, ContactFlags::default(), &mut buf);
            assert_eq!(pos.y + half.y, surface, "x {x} fall {fall}");
            assert!(resolved(
                &m,
                pos,
                half,
                start,
                ContactFlags::default(),
                &mut buf
            ));
        }
    }
}
