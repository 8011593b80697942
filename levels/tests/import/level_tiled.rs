//! Tiled loading: the hand-made fixture `tests/fixtures/levels/tiled/level.tmx`
//! (external and embedded tilesets, CSV and zlib layers, `kind` properties,
//! a flipped slope, every entity kind as objects of every supported shape,
//! platform paths, group offsets, an image layer).

use glam::IVec2;
use ledge_levels::{
    load_file, load_file_with, tmx, EntityDef, EntityKind, LoadOptions, PlatformMotion,
    RouteAction, Waypoint,
};
use ledge_shared::fixed::px;
use ledge_shared::tilemap::{Slope, Tile};

const FIXTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/levels/tiled/level.tmx"
);

fn v(x: i32, y: i32) -> IVec2 {
    IVec2::new(px(x), px(y))
}

#[test]
fn tiles_come_from_kind_properties_the_mapping_and_flips() {
    let level = load_file(FIXTURE).unwrap();
    assert_eq!(level.name, "level");
    let m = &level.tilemap;
    assert_eq!(
        (m.width(), m.height(), m.tile_size(), m.origin()),
        (20, 10, px(16), IVec2::ZERO)
    );
    let at = |c, r| m.tile(IVec2::new(c, r));
    // Walls and floor (ledge tileset id 1, mapped by LEDGE_TILESET).
    for c in 0..20 {
        assert_eq!(at(c, 9), Tile::Solid);
    }
    for r in 0..10 {
        assert_eq!(at(0, r), Tile::Solid);
        assert_eq!(at(19, r), Tile::Solid);
    }
    let expected = [
        ((3, 8), Tile::Slope(Slope::Right45)), // id 2
        ((4, 8), Tile::Solid),
        ((5, 8), Tile::Slope(Slope::Left45)), // id 2 flipped horizontally
        ((8, 8), Tile::Slope(Slope::RightLow22)), // zlib layer, kind property
        ((9, 8), Tile::Slope(Slope::RightHigh22)), // kind "Slope-22 Right High"
        ((12, 8), Tile::Hazard),              // id 13
        ((13, 8), Tile::Hazard),
        ((10, 5), Tile::OneWay), // id 12
        ((11, 5), Tile::OneWay),
        ((12, 5), Tile::OneWay),
        ((15, 6), Tile::OneWay), // kind one_way
        ((16, 8), Tile::Solid),  // kind solid, over an empty cell
        ((6, 8), Tile::Empty),
    ];
    for ((c, r), t) in expected {
        assert_eq!(at(c, r), t, "tile ({c}, {r})");
    }
    let solid = m.tiles().iter().filter(|t| **t == Tile::Solid).count();
    assert_eq!(solid, 20 + 2 * 9 + 2);
}

#[test]
fn objects_become_entities_and_waypoints() {
    let loaded = load_file_with(FIXTURE, &LoadOptions::default()).unwrap();
    let e = |kind, pos, size| EntityDef { kind, pos, size };
    let expected = vec![
        // A point object: one tile centred on the point.
        e(EntityKind::PlayerSpawn, v(40, 136), v(16, 16)),
        // `type` (pre-1.9 Tiled) works like `class`.
        e(EntityKind::Block, v(104, 120), v(16, 16)),
        // The polyline's first point is the platform's centre (dropped).
        e(
            EntityKind::MovingPlatform {
                motion: PlatformMotion {
                    path: vec![v(184, 72), v(184, 24), v(248, 24)],
                    speed: px(1) * 3 / 2,
                    looped: false,
                },
                one_way: true,
            },
            v(184, 72),
            v(48, 16),
        ),
        // A polygon path loops.
        e(
            EntityKind::MovingPlatform {
                motion: PlatformMotion {
                    path: vec![v(48, 40), v(80, 40), v(80, 72)],
                    speed: px(1),
                    looped: true,
                },
                one_way: false,
            },
            v(48, 40),
            v(32, 16),
        ),
        e(EntityKind::Walker { speed: px(1) }, v(232, 136), v(16, 16)),
        e(
            EntityKind::Springboard { strength: px(12) },
            v(264, 140),
            v(16, 8),
        ),
        // Named only.
        e(EntityKind::Coin, v(70, 70), v(12, 12)),
        // An ellipse: its bounds.
        e(EntityKind::Checkpoint, v(136, 112), v(16, 32)),
        // A tile object is anchored at its bottom-left corner.
        e(EntityKind::Goal, v(296, 128), v(16, 32)),
        e(EntityKind::Hazard, v(208, 140), v(32, 8)),
    ];
    assert_eq!(loaded.level.entities, expected);
    // Waypoints in a group (offset 8, -4) in a layer (offset 8, 0).
    assert_eq!(
        loaded.route,
        vec![
            Waypoint {
                foot: v(48, 140),
                action: RouteAction::Walk
            },
            Waypoint {
                foot: v(124, 112),
                action: RouteAction::Jump
            },
        ]
    );
    assert!(loaded.warnings.is_empty());
}

#[test]
fn loads_from_text_like_from_the_file() {
    let text = std::fs::read_to_string(FIXTURE).unwrap();
    let from_text = tmx::load_str(FIXTURE, &text, &LoadOptions::default()).unwrap();
    assert_eq!(from_text.level, load_file(FIXTURE).unwrap());
    // Only the chosen tile layers make the grid.
    let opts = LoadOptions {
        collision_layers: Some(vec!["decor".into()]),
        ..LoadOptions::default()
    };
    let decor = tmx::load_str(FIXTURE, &text, &opts).unwrap().level.tilemap;
    assert_eq!(
        decor.tiles().iter().filter(|t| **t != Tile::Empty).count(),
        4
    );
    assert_eq!(decor.tile(IVec2::new(0, 9)), Tile::Empty);
}
