//! OGMO Editor 3 loading: the real sample files in `shared/testdata` (every
//! tile export mode, grid layers, entities; the echo-slopes tileset) and the
//! embedded default level with its bot route.

use glam::IVec2;
use ledge_levels::ogmo::{self, LayerContent};
use ledge_levels::{
    default_level, default_route, load_default_level, load_file, load_file_with, EntityKind,
    LoadOptions, RouteAction, TileMapping, TileTable, ECHO_SLOPES,
};
use ledge_shared::fixed::px;
use ledge_shared::tilemap::{Slope, Tile};

const UNO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../shared/testdata/levels/ogmo3-sample/levels/uno.json"
);
const UNO_PROJECT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../shared/testdata/levels/ogmo3-sample/test.ogmo"
);
const SLOPES: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../shared/testdata/levels/echo-slopes/slopes.json"
);

fn read(p: &str) -> String {
    std::fs::read_to_string(p).unwrap()
}

fn uno() -> ogmo::OgmoLevel {
    let project = ogmo::parse_project("test.ogmo", &read(UNO_PROJECT)).unwrap();
    ogmo::parse_level("uno.json", &read(UNO), Some(&project)).unwrap()
}

/// Non-empty cells of a decoded tile layer as `(col, row, id)`.
fn tile_cells(l: &ogmo::OgmoLayer) -> Vec<(u32, u32, i32)> {
    let LayerContent::Tiles { ids, .. } = &l.content else {
        panic!("{} is not a tile layer", l.name)
    };
    assert_eq!(ids.len() as u32, l.cells.0 * l.cells.1);
    ids.iter()
        .enumerate()
        .filter(|(_, id)| **id != -1)
        .map(|(i, id)| (i as u32 % l.cells.0, i as u32 / l.cells.0, *id))
        .collect()
}

#[test]
fn uno_every_tile_export_mode_decodes_the_same_shape() {
    let level = uno();
    let names: Vec<_> = level.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "tile_1D",
            "tile_2D",
            "tileCoords_1D",
            "tileCoords_2D",
            "grid_1D",
            "grid_2D",
            "entity_layer",
            "decal_layer"
        ]
    );
    // Verified by hand in uno.json: each of the four tile layers holds the
    // same L of tile 1 (cells (x, y), (x + 1, y), (x, y + 1)), shifted one
    // cell down-right per layer; coordinates [1, 0] in the 64 px wide
    // tileset (4 columns) are id 1. tile_1D also has tile 0 at (12, 9) and
    // (13, 9).
    let keys = ["data", "data2D", "dataCoords", "dataCoords2D"];
    for (k, layer) in level.layers[..4].iter().enumerate() {
        let LayerContent::Tiles { tileset, key, .. } = &layer.content else {
            panic!()
        };
        assert_eq!(tileset, "New Tileset");
        assert_eq!(*key, keys[k]);
        assert_eq!((layer.cells, layer.cell), ((20, 15), (16, 16)));
        let k = k as u32;
        let mut expected = vec![(k, k, 1), (k + 1, k, 1), (k, k + 1, 1)];
        if k == 0 {
            expected.extend([(12, 9, 0), (13, 9, 0)]);
        }
        assert_eq!(tile_cells(layer), expected, "{}", layer.name);
    }
    // The same shape, whatever the mode: shifting back gives one grid.
    let shapes: Vec<Vec<_>> = level.layers[..4]
        .iter()
        .enumerate()
        .map(|(k, l)| {
            tile_cells(l)
                .into_iter()
                .filter(|c| c.2 == 1)
                .map(|(x, y, id)| (x - k as u32, y - k as u32, id))
                .collect()
        })
        .collect();
    assert!(shapes.windows(2).all(|w| w[0] == w[1]));
}

#[test]
fn uno_grid_layers_decode() {
    let level = uno();
    let grid = |i: usize| -> (&ogmo::OgmoLayer, Vec<(u32, u32, String)>) {
        let l = &level.layers[i];
        let LayerContent::Grid { values, .. } = &l.content else {
            panic!()
        };
        assert_eq!(values.len() as u32, l.cells.0 * l.cells.1);
        let cells = values
            .iter()
            .enumerate()
            .filter(|(_, v)| *v != "0")
            .map(|(i, v)| (i as u32 % l.cells.0, i as u32 / l.cells.0, v.clone()))
            .collect();
        (l, cells)
    };
    let (l, cells) = grid(4);
    assert_eq!((l.cells, l.cell), ((20, 15), (16, 16)));
    let three = |x, y| (x, y, "3".to_string());
    assert_eq!(
        cells,
        vec![three(18, 13), three(19, 13), three(18, 14), three(19, 14)]
    );
    let (l, cells) = grid(5);
    assert_eq!((l.cells, l.cell), ((40, 30), (8, 8)));
    assert_eq!(cells.len(), 56);
    assert!(cells.iter().all(|c| c.2 == "g"));
    assert_eq!(cells[0], (24, 9, "g".into()));
    assert_eq!(cells[55], (16, 23, "g".into()));
    assert!(cells.contains(&(11, 20, "g".into())));
    assert!(cells.contains(&(31, 15, "g".into())));
    assert!(matches!(level.layers[7].content, LayerContent::Decals));
    // Rows 20 to 29 of grid_2D have 37 of their 40 cells in the file: the
    // rest read as empty ("0"), said once for the whole layer.
    assert_eq!(
        level.warnings,
        ["uno.json: rows 20-29 of layers[5].grid2D: 37 of 40 entries, the rest read as empty"]
    );
}

#[test]
fn uno_entities_are_centres_in_units() {
    let level = uno();
    let LayerContent::Entities(es) = &level.layers[6].content else {
        panic!()
    };
    let got: Vec<_> = es
        .iter()
        .map(|e| (e.name.as_str(), e.centre, e.size))
        .collect();
    let v = |x, y| IVec2::new(x, y);
    assert_eq!(
        got,
        [
            // x, y 112, 96; 16 x 16; origin (0, 0): centre (120, 104) px.
            ("Dude", v(px(120), px(104)), v(px(16), px(16))),
            // No size or origin in the level: the project's 16 x 16 and
            // origin (8, 0): top-left (136, 80), centre (144, 88) px.
            ("Grom", v(px(144), px(88)), v(px(16), px(16))),
            // Origin (0, 0) in the level overrides the project's (16, 16).
            ("nsad", v(px(143), px(33)), v(px(16), px(16))),
            // The project's 24 x 24 size: centre (16 + 12, 112 + 12) px.
            ("anchor", v(px(28), px(124)), v(px(24), px(24))),
        ]
    );
    assert_eq!(es[0].field, "layers[6].entities[0]");
    assert_eq!(es[0].layer, "entity_layer");
    assert_eq!(es[0].values.len(), 1);
    assert!(es.iter().all(|e| e.nodes.is_empty()));
}

#[test]
fn uno_builds_a_level_with_chosen_layers() {
    let opts = LoadOptions {
        mapping: TileMapping::default().with_tileset("new tileset", TileTable::AllSolid),
        skip_unknown_entities: true,
        // grid_2D has 8 px cells: leave it out of the 16 px collision grid.
        collision_layers: Some(
            [
                "tile_1D",
                "tile_2D",
                "tileCoords_1D",
                "tileCoords_2D",
                "grid_1D",
            ]
            .map(String::from)
            .to_vec(),
        ),
        require_spawn: false,
        ..LoadOptions::default()
    };
    let loaded = load_file_with(UNO, &opts).unwrap();
    let m = &loaded.level.tilemap;
    assert_eq!((m.width(), m.height(), m.tile_size()), (20, 15, px(16)));
    let count = |t: Tile| m.tiles().iter().filter(|x| **x == t).count();
    assert_eq!(count(Tile::Solid), 4 * 3 + 2);
    assert_eq!(count(Tile::Hazard), 4); // grid "3" is the hazard code
    for k in 0..4 {
        assert_eq!(m.tile(IVec2::new(k, k)), Tile::Solid);
    }
    assert_eq!(m.tile(IVec2::new(19, 14)), Tile::Hazard);
    assert_eq!(loaded.level.name, "uno");
    assert!(loaded.level.entities.is_empty());
    let skipped: Vec<_> = loaded
        .warnings
        .iter()
        .filter(|w| w.contains("skipped unknown entity"))
        .collect();
    assert_eq!(skipped.len(), 4);
    assert!(skipped[0].contains("\"Dude\""), "{skipped:?}");
}

#[test]
fn echo_slopes_land_where_the_file_puts_them() {
    // The echo sample's tileset (named "tileset") is not ledge's own: say
    // which table reads it (a level's settings file does the same with
    // [tiles."tileset"]). Without, its tile layer does not collide.
    let plain = load_file_with(
        SLOPES,
        &LoadOptions {
            require_spawn: false,
            ..LoadOptions::default()
        },
    )
    .unwrap();
    // With no collision data at all, every placed tile is solid, said.
    assert!(plain
        .level
        .tilemap
        .tiles()
        .iter()
        .all(|t| matches!(t, Tile::Empty | Tile::Solid)));
    assert!(
        plain.warnings[0].contains("no collision data"),
        "{:?}",
        plain.warnings
    );
    let opts = LoadOptions {
        mapping: TileMapping::default()
            .with_tileset("tileset", TileTable::Ids(ECHO_SLOPES.to_vec())),
        require_spawn: false,
        ..LoadOptions::default()
    };
    // The project (project.ogmo) is found beside the level.
    let level = load_file_with(SLOPES, &opts).unwrap().level;
    let m = &level.tilemap;
    assert_eq!((m.width(), m.height(), m.tile_size()), (15, 11, px(16)));
    let at = |c, r| m.tile(IVec2::new(c, r));
    let s = Tile::Slope;
    // Verified by hand against slopes.json and the tileset image.
    let expected = [
        // A diamond: a 45 degree peak (ids 2, 3) over ceiling tiles (15, 16).
        ((2, 2), s(Slope::Right45)),
        ((3, 2), s(Slope::Left45)),
        ((2, 3), Tile::Solid),
        ((3, 3), Tile::Solid),
        // A 22.5 degree hill (ids 4, 5, 6, 7) over its ceiling (17..20).
        ((8, 4), s(Slope::RightLow22)),
        ((9, 4), s(Slope::RightHigh22)),
        ((10, 4), s(Slope::LeftHigh22)),
        ((11, 4), s(Slope::LeftLow22)),
        ((8, 5), Tile::Empty),
        ((9, 5), Tile::Solid),
        ((10, 5), Tile::Solid),
        ((11, 5), Tile::Empty),
        // The floor: a 45 then 22.5 degree descent from the left wall,
        // a 22.5 degree rise to a block, a 45 down, a gap, a 45 up.
        ((1, 8), s(Slope::Left45)),
        ((2, 9), s(Slope::LeftHigh22)),
        ((3, 9), s(Slope::LeftLow22)),
        ((8, 9), s(Slope::RightLow22)),
        ((9, 9), s(Slope::RightHigh22)),
        ((10, 9), Tile::Solid),
        ((11, 9), s(Slope::Left45)),
        ((12, 9), Tile::Empty),
        ((13, 9), s(Slope::Right45)),
        // Planks (id 12).
        ((7, 7), Tile::OneWay),
        ((12, 8), Tile::OneWay),
        // The blank tile (id 0) is empty; steep 63.4 degree tiles by area.
        ((4, 3), Tile::Empty),
        ((13, 4), Tile::Empty),
        ((13, 5), Tile::Solid),
        ((3, 6), Tile::Empty),
        ((4, 6), Tile::Empty),
    ];
    for ((c, r), t) in expected {
        assert_eq!(at(c, r), t, "tile ({c}, {r})");
    }
    let slopes: Vec<_> = Slope::ALL
        .map(|k| m.tiles().iter().filter(|t| **t == s(k)).count())
        .to_vec();
    assert_eq!(slopes, [2, 3, 2, 2, 2, 2]);
    assert_eq!(m.tiles().iter().filter(|t| **t == Tile::OneWay).count(), 2);
}

#[test]
fn default_level_loads_with_every_kind() {
    let loaded = load_default_level().expect("the embedded default level loads");
    assert!(loaded.warnings.is_empty());
    let level = default_level();
    assert_eq!(level.entities, loaded.level.entities);
    assert_eq!(level.tilemap, loaded.level.tilemap);
    let m = &level.tilemap;
    assert_eq!((m.width(), m.height(), m.tile_size()), (100, 30, px(16)));
    for code in 0..=9 {
        let t = Tile::from_code(code).unwrap();
        assert!(m.tiles().contains(&t), "no {t:?} tile");
    }
    let has =
        |f: &dyn Fn(&EntityKind) -> bool| level.entities.iter().filter(|e| f(&e.kind)).count();
    assert_eq!(has(&|k| *k == EntityKind::PlayerSpawn), 1);
    assert_eq!(has(&|k| *k == EntityKind::Goal), 1);
    assert!(has(&|k| *k == EntityKind::Block) >= 1);
    assert!(has(&|k| *k == EntityKind::Coin) >= 10);
    assert!(has(&|k| *k == EntityKind::Checkpoint) >= 2);
    assert!(has(&|k| *k == EntityKind::Hazard) >= 1);
    assert!(has(&|k| matches!(k, EntityKind::Walker { .. })) >= 2);
    assert!(has(&|k| matches!(k, EntityKind::Springboard { .. })) >= 1);
    // Moving platforms: up/down, sideways, diagonal, one-way; one loops.
    let platforms: Vec<_> = level
        .entities
        .iter()
        .filter_map(|e| match &e.kind {
            EntityKind::MovingPlatform { motion, one_way } => Some((motion, *one_way)),
            _ => None,
        })
        .collect();
    let leg = |m: &ledge_levels::PlatformMotion| m.path[1] - m.path[0];
    assert!(platforms
        .iter()
        .any(|(m, _)| leg(m).x == 0 && leg(m).y != 0));
    assert!(platforms
        .iter()
        .any(|(m, _)| leg(m).y == 0 && leg(m).x != 0));
    assert!(platforms
        .iter()
        .any(|(m, _)| leg(m).x.abs() == leg(m).y.abs()));
    assert!(platforms.iter().any(|(_, one_way)| *one_way));
    assert!(platforms.iter().any(|(m, _)| m.looped && m.path.len() == 3));
    let f = level.features();
    assert!(f.solid_tiles && f.one_way_tiles && f.slopes && f.hazard_tiles);
    assert!(f.blocks && f.moving_platforms && f.one_way_platforms);
    assert!(f.walkers && f.springboards && f.triggers);
    assert_eq!(f.max_speed, px(10));
}

#[test]
fn default_route_runs_from_spawn_to_goal_on_solid_footing() {
    let level = default_level();
    let route = default_route();
    let m = &level.tilemap;
    let t = m.tile_size();
    let find = |k: EntityKind| level.entities.iter().find(|e| e.kind == k).unwrap();
    let (spawn, goal) = (find(EntityKind::PlayerSpawn), find(EntityKind::Goal));
    assert!(route.len() >= 10);
    // Starts at the spawn's feet, ends at the goal's feet.
    assert_eq!(route[0].foot, spawn.pos + IVec2::new(0, spawn.size.y / 2));
    let last = route.last().unwrap().foot;
    assert_eq!(last, goal.pos + IVec2::new(0, goal.size.y / 2));
    for (i, w) in route.iter().enumerate() {
        // Every waypoint stands exactly on a floor, with 3 free tiles above.
        assert_eq!(
            m.ground_below(w.foot, 0),
            Some(w.foot.y),
            "waypoint {i} {w:?}"
        );
        let tile = m.tile_of(w.foot - IVec2::new(0, 1));
        for up in 0..3 {
            assert_eq!(
                m.tile(tile - IVec2::new(0, up)),
                Tile::Empty,
                "headroom at {i}"
            );
        }
        if i == 0 {
            continue;
        }
        let prev = route[i - 1].foot;
        let rise = prev.y - w.foot.y;
        assert!(w.foot.x > prev.x, "the route runs left to right ({i})");
        match w.action {
            RouteAction::Walk => {
                // No hazard tile between (walking never crosses spikes).
                let (a, b) = (m.tile_of(prev), m.tile_of(w.foot));
                for c in a.x..=b.x {
                    for r in a.y.min(b.y) - 1..=a.y.max(b.y) {
                        assert_ne!(m.tile(IVec2::new(c, r)), Tile::Hazard, "walk {i}");
                    }
                }
            }
            RouteAction::Jump => {
                assert!(rise <= 2 * t, "jump {i} rises {rise}");
                assert!(w.foot.x - prev.x <= 6 * t, "jump {i} too long");
            }
            RouteAction::Spring => {
                assert_eq!(rise, 6 * t);
                // A springboard lies between.
                assert!(level
                    .entities
                    .iter()
                    .any(|e| matches!(e.kind, EntityKind::Springboard { .. })
                        && (prev.x..w.foot.x).contains(&e.pos.x)));
            }
        }
    }
    // Every action is used.
    for a in [RouteAction::Walk, RouteAction::Jump, RouteAction::Spring] {
        assert!(route.iter().any(|w| w.action == a));
    }
    // The route passes both checkpoints.
    for c in level
        .entities
        .iter()
        .filter(|e| e.kind == EntityKind::Checkpoint)
    {
        let feet = c.pos + IVec2::new(0, c.size.y / 2);
        assert!(
            route
                .iter()
                .any(|w| (w.foot - feet).abs().max_element() <= t && w.foot.y == feet.y),
            "no waypoint at checkpoint {feet}"
        );
    }
}

#[test]
fn default_level_file_loads_from_disk_like_the_embedded_one() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/default/default.json");
    let from_disk = load_file(path).unwrap();
    let embedded = default_level();
    assert_eq!(from_disk.tilemap, embedded.tilemap);
    assert_eq!(from_disk.entities, embedded.entities);
}

#[test]
fn a_turned_block_is_a_polygon_and_a_turned_walker_is_said() {
    let text = r#"{"layers": [{"name": "e", "entities": [
        {"name": "player", "x": 0, "y": 0, "width": 16, "height": 16},
        {"name": "block", "x": 100, "y": 100, "width": 20, "height": 10, "originX": 10, "originY": 5, "rotation": 90},
        {"name": "walker", "x": 50, "y": 50, "width": 8, "height": 8, "rotation": 45}
    ]}]}"#;
    let l = ogmo::load_str("t.json", text, None, &LoadOptions::default()).unwrap();
    let block = &l.level.entities[1];
    let EntityKind::PolygonBlock { vertices } = &block.kind else {
        panic!("{block:?}");
    };
    // Turned a quarter about its centre (its origin): 10 wide, 20 tall.
    let mut abs: Vec<IVec2> = vertices.iter().map(|v| *v + block.pos).collect();
    abs.sort_by_key(|p| (p.x, p.y));
    let p = |x: i32, y: i32| IVec2::new(x, y) * 256;
    assert_eq!(abs, [p(95, 90), p(95, 110), p(105, 90), p(105, 110)]);
    assert!(matches!(
        l.level.entities[2].kind,
        EntityKind::Walker { .. }
    ));
    assert_eq!(
        l.warnings,
        ["t.json: layers[0].entities[2].rotation: entity \"walker\" is turned by 45 degrees: only blocks, hazards, coins, checkpoints and goals turn in ledge; it stands upright"]
    );
}
