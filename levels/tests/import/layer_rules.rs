//! Levels made for other games whose layers say what they are only by
//! their names and contents (issue 33): collision drawn as rectangles and
//! polygons in object layers, object layers named for things (`Coins`,
//! `Goombas`, `Camera`), tile layers painted edge to edge, and layers of
//! several grid sizes. Small files written here, each one of a failure
//! class the importers used to get wrong; the player must stand still at
//! the spawn for two seconds ([`stands_still`]).

use glam::IVec2;
use ledge_levels::{ogmo, tmx, EntityKind, LoadOptions, LoadedLevel};
use ledge_shared::tilemap::Tile;

use crate::stands_still::stands_still;

/// A Tiled map of `w` x `h` tiles of 16 px, one tileset `art` of 16 tiles
/// with no collision data, and `layers` (XML).
fn tiled(w: u32, h: u32, layers: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<map version="1.10" orientation="orthogonal" renderorder="right-down" width="{w}" height="{h}" tilewidth="16" tileheight="16" infinite="0">
 <tileset firstgid="1" name="art" tilewidth="16" tileheight="16" tilecount="16" columns="4">
  <image source="art.png" width="64" height="64"/>
 </tileset>
{layers}
</map>"#
    )
}

/// A tile layer `name` of `w` x `h` whose cell (x, y) holds gid `cell(x, y)`
/// (0: empty).
fn tile_layer(name: &str, w: u32, h: u32, cell: impl Fn(u32, u32) -> u32) -> String {
    let cells: Vec<String> = (0..w * h).map(|i| cell(i % w, i / w).to_string()).collect();
    format!(
        r#" <layer id="1" name="{name}" width="{w}" height="{h}"><data encoding="csv">{}</data></layer>"#,
        cells.join(",")
    )
}

fn object_layer(name: &str, objects: &str) -> String {
    format!(" <objectgroup id=\"9\" name=\"{name}\">\n{objects}\n </objectgroup>")
}

fn load(text: &str) -> LoadedLevel {
    tmx::load_str("t.tmx", text, &LoadOptions::default()).unwrap()
}

fn count(l: &LoadedLevel, f: impl Fn(&EntityKind) -> bool) -> usize {
    l.level.entities.iter().filter(|e| f(&e.kind)).count()
}

fn spawn(l: &LoadedLevel) -> IVec2 {
    l.level
        .entities
        .iter()
        .find(|e| e.kind == EntityKind::PlayerSpawn)
        .unwrap()
        .pos
}

/// A block whose box is `(x, y, w, h)` px.
fn has_block(l: &LoadedLevel, (x, y, w, h): (i32, i32, i32, i32)) -> bool {
    let u = 256;
    l.level.entities.iter().any(|e| {
        e.kind == EntityKind::Block
            && e.pos == IVec2::new((x + w / 2) * u, (y + h / 2) * u)
            && e.size == IVec2::new(w * u, h * u)
    })
}

/// Mario style: the ground, pipes and bricks are rectangles (and a
/// polygon) in object layers, the tile layer is the picture. It used to be
/// read as "no collision data" with every tile solid: the spawn was inside
/// the painted hills and the player was pushed out.
fn mario_map() -> String {
    let (w, h) = (20, 12);
    // Hills and ground painted over rows 7..12, the spawn's cells included.
    let tiles = tile_layer("Tiles", w, h, |_, y| if y >= 7 { 1 + y % 3 } else { 0 });
    let ground = object_layer(
        "Ground",
        r#"  <object id="1" x="0" y="160" width="320" height="32"/>
  <object id="2" x="240" y="144">
   <polygon points="0,16 32,0 32,16"/>
  </object>"#,
    );
    let pipes = object_layer(
        "Pipes",
        r#"  <object id="3" name="pipe" x="160" y="128" width="32" height="32"/>"#,
    );
    let bricks = object_layer(
        "Bricks",
        r#"  <object id="4" name="brick" x="96" y="96" width="16" height="16"/>"#,
    );
    let game = object_layer(
        "game",
        r#"  <object id="5" name="player" x="40" y="144" width="16" height="16"/>"#,
    );
    tiled(w, h, &[tiles, ground, pipes, bricks, game].join("\n"))
}

#[test]
fn rectangles_in_object_layers_are_the_collision_and_tile_layers_decoration() {
    let l = load(&mario_map());
    stands_still(&l.level).unwrap();
    // The painted tiles do not collide, the shapes do.
    assert!(l.level.tilemap.tiles().iter().all(|t| *t == Tile::Empty));
    assert!(has_block(&l, (0, 160, 320, 32)), "ground");
    assert!(has_block(&l, (160, 128, 32, 32)), "the named pipe");
    assert!(has_block(&l, (96, 96, 16, 16)), "the named brick");
    assert_eq!(
        count(&l, |k| matches!(k, EntityKind::PolygonBlock { .. })),
        1,
        "the slope"
    );
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("collision is drawn as objects")
                && w.contains("has no collision data")
                && w.contains("\"Ground\"")
                && w.contains("collision_layers")),
        "{:?}",
        l.warnings
    );
    // The settings say otherwise: the tile layer collides again.
    let opts = LoadOptions {
        collision_layers: Some(vec!["Tiles".into()]),
        ..LoadOptions::default()
    };
    let l = tmx::load_str("t.tmx", &mario_map(), &opts).unwrap();
    assert_eq!(
        l.level.tilemap.tile(IVec2::new(2, 8)),
        Tile::Solid,
        "collision_layers wins"
    );
}

/// Objects without a ledge name in layers named for things: coins, enemies
/// (Goombas, Turtles), spikes; a camera zone over the spawn. They used to
/// be solid blocks (unnamed shapes) or skipped (named ones).
fn named_layers_map() -> String {
    let (w, h) = (20, 10);
    let floor = tile_layer("Ground", w, h, |_, y| u32::from(y == h - 1));
    let floor = floor.replace(
        "><data",
        "><properties><property name=\"solid\" type=\"bool\" value=\"true\"/></properties><data",
    );
    let layers = [
        floor,
        object_layer(
            "Coins",
            r#"  <object id="1" x="96" y="96" width="16" height="16"/>
  <object id="2" x="112" y="96" width="16" height="16"/>
  <object id="3" x="128" y="104"><point/></object>
  <object id="4" gid="2" x="144" y="112" width="16" height="16"/>"#,
        ),
        object_layer(
            "Goombas",
            r#"  <object id="5" x="200" y="128" width="16" height="16"/>"#,
        ),
        object_layer(
            "Turtles",
            r#"  <object id="6" name="koopa_red" x="240" y="128" width="16" height="24"/>"#,
        ),
        object_layer(
            "Spikes",
            r#"  <object id="7" x="280" y="136" width="16" height="8"/>"#,
        ),
        object_layer(
            "Camera",
            r#"  <object id="8" x="0" y="0" width="320" height="160"/>"#,
        ),
        object_layer(
            "Enemies",
            r#"  <object id="9" name="coin" x="60" y="80" width="16" height="16"/>
  <object id="10" name="player" x="40" y="128" width="16" height="16"/>"#,
        ),
    ];
    tiled(w, h, &layers.join("\n"))
}

#[test]
fn objects_in_layers_named_for_things_become_those_things() {
    let l = load(&named_layers_map());
    assert_eq!(count(&l, |k| *k == EntityKind::Coin), 5);
    assert_eq!(count(&l, |k| matches!(k, EntityKind::Walker { .. })), 2);
    assert_eq!(count(&l, |k| *k == EntityKind::Hazard), 1);
    // Nothing became a solid block: not the coins, not the camera zone.
    assert_eq!(count(&l, |k| *k == EntityKind::Block), 0);
    stands_still(&l.level).unwrap();
    for said in [
        "read as \"coin\" by layer \"Coins\"",
        "read as \"walker\" by layer \"Goombas\"",
        "read as \"walker\" by its name \"koopa_red\"",
        "read as \"hazard\" by layer \"Spikes\"",
        "neither collision nor entities by layer \"Camera\"",
    ] {
        assert!(
            l.warnings
                .iter()
                .any(|w| w.contains(said) && w.contains("[entities]")),
            "{said:?} not in {:?}",
            l.warnings
        );
    }
    // The settings choose: the goombas are coins, the spikes skipped.
    let mut opts = LoadOptions::default();
    opts.entity_aliases.insert("goombas".into(), "coin".into());
    opts.decoration_layers.push("Spikes".into());
    let l = tmx::load_str("t.tmx", &named_layers_map(), &opts).unwrap();
    assert_eq!(count(&l, |k| *k == EntityKind::Coin), 6);
    assert_eq!(count(&l, |k| *k == EntityKind::Hazard), 0);
}

#[test]
fn ogmo_entities_in_layers_named_for_things_become_those_things() {
    let mut cells = vec!["0"; 160];
    cells[140..].fill("1");
    let text = format!(
        r#"{{"layers": [
            {{"name": "g", "gridCellWidth": 16, "gridCellHeight": 16, "gridCellsX": 20,
              "gridCellsY": 8, "grid": {cells:?}}},
            {{"name": "Enemies", "entities": [
                {{"name": "Goomba", "x": 100, "y": 96, "width": 16, "height": 16}},
                {{"name": "player", "x": 20, "y": 96, "width": 12, "height": 16}}]}},
            {{"name": "Coins", "entities": [
                {{"name": "Gold", "x": 150, "y": 80, "width": 8, "height": 8}}]}}]}}"#
    );
    let l = ogmo::load_str("t.json", &text, None, &LoadOptions::default()).unwrap();
    assert_eq!(count(&l, |k| matches!(k, EntityKind::Walker { .. })), 1);
    assert_eq!(count(&l, |k| *k == EntityKind::Coin), 1);
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("\"Goomba\"") && w.contains("read as \"walker\"")),
        "{:?}",
        l.warnings
    );
    stands_still(&l.level).unwrap();
}

/// One tile layer painted edge to edge: sky (gid 1, the most common),
/// walls (gid 2) round the edges and a floor, a platform (gid 3), clouds
/// (gid 5) where the player spawns and up in the sky. No collision data.
/// It used to be all walls: the spawn inside one.
fn painted_map() -> String {
    let (w, h) = (20, 12);
    let tiles = tile_layer("Tiles", w, h, |x, y| match (x, y) {
        (_, 10..) | (0 | 19, _) => 2,
        (8..=12, 7) => 3,
        (2, 8..=9) | (10..=11, 3) => 5,
        _ => 1,
    });
    let game = object_layer(
        "game",
        r#"  <object id="5" name="player" x="36" y="144" width="12" height="16"/>"#,
    );
    tiled(w, h, &[tiles, game].join("\n"))
}

#[test]
fn a_tile_layer_painted_edge_to_edge_has_its_background_passable() {
    let l = load(&painted_map());
    stands_still(&l.level).unwrap();
    let map = &l.level.tilemap;
    let at = |x, y| map.tile(IVec2::new(x, y));
    let s = spawn(&l) / (16 * 256);
    assert_eq!(s, IVec2::new(2, 9));
    assert_eq!(at(s.x, s.y), Tile::Empty, "the cloud under the spawn");
    assert_eq!(at(10, 3), Tile::Empty, "the same cloud elsewhere");
    assert_eq!(at(5, 5), Tile::Empty, "the sky");
    assert_eq!(at(2, 10), Tile::Solid, "the floor");
    assert_eq!(at(0, 5), Tile::Solid, "the wall");
    assert_eq!(at(9, 7), Tile::Solid, "the platform");
    assert!(
        l.warnings.iter().any(|w| w.contains("painted edge to edge")
            && w.contains("[tiles.\"art\"]")
            && w.contains("0 = \"empty\"")
            && w.contains("1 = \"solid\"")),
        "{:?}",
        l.warnings
    );
    // The settings decide instead: the sky is solid, so is everything.
    let mut opts = LoadOptions::default();
    opts.tile_kinds.insert(("art".into(), 4), Tile::Empty);
    opts.tile_kinds.insert(("art".into(), 0), Tile::Solid);
    let l = tmx::load_str("t.tmx", &painted_map(), &opts).unwrap();
    assert_eq!(l.level.tilemap.tile(IVec2::new(5, 5)), Tile::Solid);
}

/// An OGMO level (no project) of one foreign tile layer painted edge to
/// edge: id 0 the background, 7 the walls, a floor and a ledge.
fn ogmo_painted(extra_layers: &str) -> String {
    let (w, h) = (16, 10);
    let ids: Vec<i32> = (0..w * h)
        .map(|i| match (i % w, i / w) {
            (_, 8..) | (0 | 15, _) => 7,
            (6..=9, 5) => 7,
            _ => 0,
        })
        .collect();
    format!(
        r#"{{"layers": [{extra_layers}
            {{"name": "Tiles", "gridCellWidth": 16, "gridCellHeight": 16, "gridCellsX": {w},
              "gridCellsY": {h}, "tileset": "jungle", "data": {ids:?}}},
            {{"name": "Entities", "entities": [
                {{"name": "player", "x": 40, "y": 112, "width": 12, "height": 16}}]}}]}}"#
    )
}

#[test]
fn an_ogmo_tile_layer_painted_edge_to_edge_has_its_background_passable() {
    let l = ogmo::load_str("t.json", &ogmo_painted(""), None, &LoadOptions::default()).unwrap();
    stands_still(&l.level).unwrap();
    let map = &l.level.tilemap;
    assert_eq!(map.tile(IVec2::new(2, 6)), Tile::Empty);
    assert_eq!(map.tile(IVec2::new(2, 8)), Tile::Solid);
    assert_eq!(map.tile(IVec2::new(7, 5)), Tile::Solid);
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("painted edge to edge") && w.contains("[tiles.\"jungle\"]")),
        "{:?}",
        l.warnings
    );
}

/// An OGMO level whose first layer is a 64 px camera-zone tile layer
/// (painted everywhere), then the real 32 px tile layer, a 64 px ledge
/// layer and a 16 px layer of bumps. It used to take the camera layer's
/// grid and make it all solid, the real layer "not colliding".
fn ogmo_mixed() -> String {
    let layer = |name: &str, cell: u32, w: u32, h: u32, ids: Vec<i32>| {
        format!(
            r#"{{"name": "{name}", "gridCellWidth": {cell}, "gridCellHeight": {cell}, "gridCellsX": {w},
              "gridCellsY": {h}, "tileset": "set{cell}", "data": {ids:?}}},"#
        )
    };
    let camera = layer("Camera", 64, 5, 2, vec![0; 10]);
    // 10 x 4 cells of 32 px: the floor on the last row.
    let tiles = layer(
        "Tiles",
        32,
        10,
        4,
        (0..40).map(|i| if i / 10 == 3 { 1 } else { -1 }).collect(),
    );
    // A 64 px ledge over 32 px cells (6..8, 0..2).
    let ledges = layer(
        "Ledges",
        64,
        5,
        2,
        (0..10).map(|i| if i == 3 { 2 } else { -1 }).collect(),
    );
    // Two 16 px bumps side by side at 16 px cells (8, 5) and (9, 5): the
    // lower half of the 32 px cell (4, 2).
    let bumps = layer(
        "Bumps",
        16,
        20,
        8,
        (0..160)
            .map(|i| {
                if i == 5 * 20 + 8 || i == 5 * 20 + 9 {
                    3
                } else {
                    -1
                }
            })
            .collect(),
    );
    format!(
        r#"{{"layers": [{camera}{tiles}{ledges}{bumps}
            {{"name": "Entities", "entities": [
                {{"name": "player", "x": 40, "y": 80, "width": 12, "height": 16}}]}}]}}"#
    )
}

#[test]
fn the_collision_layer_decides_the_grid_and_other_sizes_are_resampled() {
    let l = ogmo::load_str("t.json", &ogmo_mixed(), None, &LoadOptions::default()).unwrap();
    let map = &l.level.tilemap;
    assert_eq!(map.tile_size(), 32 * 256, "the real layer's grid");
    assert_eq!((map.width(), map.height()), (10, 4));
    stands_still(&l.level).unwrap();
    let at = |x, y| map.tile(IVec2::new(x, y));
    assert_eq!(at(1, 2), Tile::Empty, "the camera zone does not collide");
    assert_eq!(at(3, 3), Tile::Solid, "the floor");
    for (x, y) in [(6, 0), (7, 0), (6, 1), (7, 1)] {
        assert_eq!(at(x, y), Tile::Solid, "the 64 px ledge at ({x}, {y})");
    }
    assert_eq!(at(4, 2), Tile::Solid, "the 16 px bumps");
    for said in ["layer \"Camera\"", "resampled"] {
        assert!(
            l.warnings.iter().any(|w| w.contains(said)),
            "{said:?} not in {:?}",
            l.warnings
        );
    }
    assert!(
        !l.warnings.iter().any(|w| w.contains("does not line up")),
        "{:?}",
        l.warnings
    );
}

/// A Tiled map without collision data whose layers are a background
/// ("BG", painted round the spawn, not edge to edge) and the level's tiles:
/// the background used to be solid with the rest.
#[test]
fn a_tiled_layer_named_for_the_background_does_not_collide() {
    let (w, h) = (20, 10);
    let bg = tile_layer("BG", w, h, |x, y| {
        u32::from((1..6).contains(&x) && y >= 4) * 4
    });
    let tiles = tile_layer("Tiles", w, h, |_, y| u32::from(y == h - 1));
    let game = object_layer(
        "game",
        r#"  <object id="5" name="player" x="36" y="128" width="12" height="16"/>"#,
    );
    let l = load(&tiled(w, h, &[bg, tiles, game].join("\n")));
    stands_still(&l.level).unwrap();
    assert_eq!(l.level.tilemap.tile(IVec2::new(2, 7)), Tile::Empty);
    assert_eq!(l.level.tilemap.tile(IVec2::new(2, 9)), Tile::Solid);
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("but those named for decoration")),
        "{:?}",
        l.warnings
    );
}

/// A tile object made a coin by its layer's name is the game's to draw (a
/// collected coin vanishes): the level's art leaves it out, and draws the
/// tile objects of other layers.
#[test]
fn coins_by_their_layer_are_not_drawn_as_art() {
    let png = concat!(env!("CARGO_MANIFEST_DIR"), "/default/ledge.png");
    let layers = [
        object_layer(
            "Coins",
            r#"  <object id="1" gid="2" x="96" y="112" width="16" height="16"/>"#,
        ),
        object_layer(
            "Props",
            r#"  <object id="2" gid="2" x="128" y="112" width="16" height="16"/>"#,
        ),
        object_layer(
            "game",
            r#"  <object id="3" name="player" x="40" y="128" width="16" height="16"/>"#,
        ),
    ];
    let text = tiled(10, 10, &layers.join("\n"))
        .replace(
            "art.png\" width=\"64\" height=\"64\"",
            &format!("{png}\" width=\"208\" height=\"32\""),
        )
        .replace(
            "tilecount=\"16\" columns=\"4\"",
            "tilecount=\"26\" columns=\"13\"",
        );
    let l = tmx::load_str("t.tmx", &text, &LoadOptions::default()).unwrap();
    assert_eq!(count(&l, |k| *k == EntityKind::Coin), 1);
    let drawn: Vec<_> = l
        .art
        .layers
        .iter()
        .filter_map(|a| match &a.content {
            ledge_levels::art::ArtContent::Objects(o) if !o.is_empty() => Some(a.name.clone()),
            _ => None,
        })
        .collect();
    assert_eq!(drawn, ["Props"], "{:?}", l.art.warnings);
}
