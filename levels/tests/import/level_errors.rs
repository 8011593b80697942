//! Bad level files: one test per error class, each asserting that the
//! message names the file and the field; and a property test feeding random
//! and mutated bytes to the loaders (never a panic).

use glam::IVec2;
use ledge_levels::{
    load_default_level, load_file, load_file_with, ogmo, tmx, EntityKind, LevelError, LoadOptions,
};
use ledge_shared::tilemap::Tile;
use proptest::prelude::*;

const UNO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../shared/testdata/levels/ogmo3-sample/levels/uno.json"
);
const TILED_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/levels/tiled");
const DEFAULT_JSON: &str = include_str!("../../default/default.json");
const DEFAULT_PROJECT: &str = include_str!("../../default/ledge.ogmo");

/// A one-layer OGMO level: a 4 x 2 tile layer (`tiles_json` is its data
/// field), and an entity layer with `entities_json`.
fn level(tiles_json: &str, entities_json: &str) -> String {
    format!(
        r#"{{"ogmoVersion": "3.3.0", "width": 64, "height": 32, "layers": [
            {{"name": "tiles", "gridCellWidth": 16, "gridCellHeight": 16,
              "gridCellsX": 4, "gridCellsY": 2, "tileset": "ledge", {tiles_json}}},
            {{"name": "things", "gridCellWidth": 8, "gridCellHeight": 8,
              "gridCellsX": 8, "gridCellsY": 4, "entities": [{entities_json}]}}
        ]}}"#
    )
}

const TILES: &str = r#""data": [1, 1, 1, 1, -1, 12, 13, 2], "exportMode": 0, "arrayMode": 0"#;
const SPAWN: &str = r#"{"name": "player", "x": 8, "y": 8, "width": 16, "height": 16}"#;

fn load(text: &str) -> Result<ledge_levels::LoadedLevel, LevelError> {
    ogmo::load_str("levels/test.json", text, None, &LoadOptions::default())
}

/// The error's message, after checking it names the file and the field.
fn check(r: Result<ledge_levels::LoadedLevel, LevelError>, file: &str, field: &str) -> String {
    let e = r.expect_err("should be refused");
    let msg = e.to_string();
    assert!(msg.starts_with(&format!("{file}: ")), "{msg}");
    assert!(msg.contains(field), "{msg} should name {field}");
    assert_eq!(e.file(), file);
    msg
}

#[test]
fn a_good_small_level_loads() {
    let l = load(&level(TILES, SPAWN)).unwrap();
    assert_eq!(l.level.tilemap.width(), 4);
    assert_eq!(l.level.entities.len(), 1);
}

#[test]
fn io_and_unsupported_format() {
    let e = load_file("no/such/level.json").unwrap_err();
    assert!(matches!(e, LevelError::Io { .. }), "{e}");
    assert!(
        e.to_string().starts_with("no/such/level.json: cannot read"),
        "{e}"
    );
    let e = load_file("no/such/level.tmx").unwrap_err();
    assert!(matches!(e, LevelError::Io { .. }), "{e}");
    assert!(e.to_string().starts_with("no/such/level.tmx: "), "{e}");
    let e = load_file("levels/level.png").unwrap_err();
    assert_eq!(
        e,
        LevelError::UnsupportedFormat {
            file: "levels/level.png".into()
        }
    );
    assert!(e.to_string().contains(".json") && e.to_string().contains(".tmx"));
}

#[test]
fn malformed_json_names_the_line() {
    let msg = check(
        load("{\"layers\": [\n  {\"name\": }"),
        "levels/test.json",
        "line 2 column",
    );
    assert!(msg.contains("malformed JSON"), "{msg}");
    let msg = check(load("[1, 2]"), "levels/test.json", "(document)");
    assert!(msg.contains("expected an object, got an array"), "{msg}");
    let r = ogmo::load_str(
        "a.json",
        &level(TILES, SPAWN),
        Some(("p.ogmo", "{oops")),
        &LoadOptions::default(),
    );
    let msg = check(r, "p.ogmo", "line 1 column 2");
    assert!(msg.contains("malformed OGMO project JSON"), "{msg}");
}

#[test]
fn malformed_xml_names_the_file() {
    let file = format!("{TILED_DIR}/broken.tmx");
    let r = tmx::load_str(
        &file,
        "<map version=\"1.10\" width=\"4\"><layer",
        &LoadOptions::default(),
    );
    let msg = check(r, &file, "map");
    assert!(msg.contains("malformed TMX"), "{msg}");
    let r = tmx::load_str(&file, "not xml at all", &LoadOptions::default());
    check(r, &file, "map");
}

#[test]
fn missing_fields() {
    let text = level(TILES, SPAWN).replace(r#""gridCellsX": 4, "#, "");
    let msg = check(
        load(&text),
        "levels/test.json",
        "layers[0].gridCellsX: missing",
    );
    assert!(!msg.is_empty());
    // arrayMode 1 needs data2D.
    let tiles = TILES.replace(r#""arrayMode": 0"#, r#""arrayMode": 1"#);
    let msg = check(
        load(&level(&tiles, SPAWN)),
        "levels/test.json",
        "layers[0].data2D: missing",
    );
    assert!(msg.contains("arrayMode 1"), "{msg}");
    // An entity with no size and no project to give one.
    let e = r#"{"name": "coin", "x": 1, "y": 2}"#;
    let msg = check(
        load(&level(TILES, &format!("{SPAWN}, {e}"))),
        "levels/test.json",
        "layers[1].entities[1].width: missing",
    );
    assert!(msg.contains("\"coin\""), "{msg}");
}

#[test]
fn unknown_layer_kinds() {
    let text = r#"{"layers": [{"name": "mystery", "stuff": [1, 2, 3]}]}"#;
    let msg = check(
        load(text),
        "levels/test.json",
        "layers[0]: unknown layer kind",
    );
    assert!(!msg.is_empty());
    let project = r#"{"layers": [{"name": "tiles", "definition": "hologram"}]}"#;
    let r = ogmo::load_str(
        "l.json",
        &level(TILES, SPAWN),
        Some(("p.ogmo", project)),
        &LoadOptions::default(),
    );
    let msg = check(r, "l.json", "layers[0]: unknown layer kind \"hologram\"");
    assert!(!msg.is_empty());
    // Tiled: a map that is not orthogonal.
    let file = format!("{TILED_DIR}/iso.tmx");
    let r = tmx::load_str(
        &file,
        r#"<map version="1.10" orientation="isometric" width="4" height="4" tilewidth="16" tileheight="16" infinite="0"></map>"#,
        &LoadOptions::default(),
    );
    let msg = check(r, &file, "map.orientation");
    assert!(msg.contains("Isometric maps are not supported"), "{msg}");
}

#[test]
fn inconsistent_data_lengths() {
    // The brief's example, on the real uno.json with one id removed.
    let uno = std::fs::read_to_string(UNO).unwrap();
    let cut = uno.replacen("\"data\": [1, 1, -1,", "\"data\": [1, 1,", 1);
    assert_ne!(cut, uno);
    let r = ogmo::load_str("levels/uno.json", &cut, None, &LoadOptions::default());
    let e = r.unwrap_err();
    assert_eq!(
        e.to_string(),
        "levels/uno.json: layers[0].data: expected 300 entries, got 299"
    );
    // 2D rows.
    let tiles = r#""data2D": [[1, 1, 1, 1], [1, 1, 1, 1, 1]]"#;
    check(
        load(&level(tiles, SPAWN)),
        "levels/test.json",
        "layers[0].data2D[1]: expected 4 entries, got 5",
    );
    // A short 2D row (OGMO 3.2 writes them, see uno.json) reads as empty,
    // with a warning.
    let tiles = r#""data2D": [[1, 1, 1, 1], [1, 1, 1]]"#;
    let l = load(&level(tiles, SPAWN)).unwrap();
    assert_eq!(
        l.level.tilemap.tile(glam::IVec2::new(3, 1)),
        ledge_shared::tilemap::Tile::Empty
    );
    assert_eq!(
        l.warnings,
        ["levels/test.json: layers[0].data2D[1]: 3 of 4 entries, the rest read as empty"]
    );
    // Several short rows: one warning, the rows as runs.
    let tiles = r#""data2D": [[1, 1], [1, 1, 1, 1], [1], [1, 1], [1, 1, 1]]"#;
    let five_rows = level(tiles, SPAWN)
        .replace(r#""height": 32"#, r#""height": 80"#)
        .replace(r#""gridCellsY": 2"#, r#""gridCellsY": 5"#);
    let l = load(&five_rows).unwrap();
    assert_eq!(
        l.warnings,
        ["levels/test.json: rows 0, 2-4 of layers[0].data2D: 1 to 3 of 4 entries, the rest read as empty"]
    );
    let tiles = r#""data2D": [[1, 1, 1, 1]]"#;
    check(
        load(&level(tiles, SPAWN)),
        "levels/test.json",
        "layers[0].data2D: expected 2 entries, got 1",
    );
    // Tiled: CSV data shorter than the layer (the tiled crate would index past it).
    let file = format!("{TILED_DIR}/short.tmx");
    let text = std::fs::read_to_string(format!("{TILED_DIR}/level.tmx"))
        .unwrap()
        .replacen("2,2,2,2,2,2,2,2,2,2,2,2,2,2,2,2,2,2,2,2\n", "2\n", 1);
    let r = tmx::load_str(&file, &text, &LoadOptions::default());
    let msg = check(r, &file, "layers[0].data");
    // Refused by the pre-scan before the Tiled reader sees it.
    assert!(msg.contains("expected 200 entries, got 181"), "{msg}");
}

#[test]
fn sizes_and_positions_out_of_bounds() {
    let text = level(TILES, SPAWN).replace(r#""gridCellsX": 4"#, r#""gridCellsX": 5000"#);
    let msg = check(load(&text), "levels/test.json", "layers[0].gridCellsX");
    assert!(msg.contains("5000 cells is outside [0, 4096]"), "{msg}");
    let far = r#"{"name": "coin", "x": 1e12, "y": 0, "width": 8, "height": 8}"#;
    let msg = check(
        load(&level(TILES, &format!("{SPAWN}, {far}"))),
        "levels/test.json",
        "layers[1].entities[1].x",
    );
    assert!(msg.contains("outside the world bound"), "{msg}");
    let huge = r#"{"name": "block", "x": 0, "y": 0, "width": 1e9, "height": 8}"#;
    check(
        load(&level(TILES, &format!("{SPAWN}, {huge}"))),
        "levels/test.json",
        "layers[1].entities[1].width",
    );
    // The grid's far edge beyond the world bound.
    let text = level(TILES, SPAWN).replace(
        r#""name": "tiles","#,
        r#""name": "tiles", "offsetX": 6291400,"#,
    );
    check(load(&text), "levels/test.json", "layers[0]");
    // Tiled: a map wider than 4096 tiles.
    let file = format!("{TILED_DIR}/wide.tmx");
    let r = tmx::load_str(
        &file,
        r#"<map version="1.10" orientation="orthogonal" width="5000" height="4" tilewidth="16" tileheight="16" infinite="0"></map>"#,
        &LoadOptions::default(),
    );
    check(r, &file, "map.width: 5000 tiles");
}

#[test]
fn bad_values() {
    let platform = |values: &str, nodes: &str| {
        format!(
            r#"{SPAWN}, {{"name": "platform", "x": 0, "y": 0, "width": 32, "height": 8, "values": {values}, "nodes": {nodes}}}"#
        )
    };
    let text = level(
        TILES,
        &platform(r#"{"speed": "fast"}"#, r#"[{"x": 32, "y": 0}]"#),
    );
    let msg = check(
        load(&text),
        "levels/test.json",
        "layers[1].entities[1].values.speed",
    );
    assert!(msg.contains("\"fast\""), "{msg}");
    let text = level(
        TILES,
        &platform(r#"{"speed": -1}"#, r#"[{"x": 32, "y": 0}]"#),
    );
    check(
        load(&text),
        "levels/test.json",
        "layers[1].entities[1].values.speed: -1 px/tick",
    );
    let text = level(
        TILES,
        &platform(r#"{"one_way": "maybe"}"#, r#"[{"x": 32, "y": 0}]"#),
    );
    check(
        load(&text),
        "levels/test.json",
        "layers[1].entities[1].values.one_way: expected a boolean",
    );
    let tiles = TILES.replace("-1, 12", "-5, 12");
    check(
        load(&level(&tiles, SPAWN)),
        "levels/test.json",
        "layers[0].data[4]: tile id -5",
    );
    let tiles = TILES.replace(r#""exportMode": 0"#, r#""exportMode": 2"#);
    check(
        load(&level(&tiles, SPAWN)),
        "levels/test.json",
        "layers[0].exportMode: expected 0 or 1, got 2",
    );
    let tiles = TILES.replace("-1, 12", "\"x\", 12");
    check(
        load(&level(&tiles, SPAWN)),
        "levels/test.json",
        "layers[0].data[4]: expected an integer, got a string",
    );
    let way = r#"{"name": "waypoint", "x": 0, "y": 0, "width": 8, "height": 8, "values": {"action": "fly"}}"#;
    check(
        load(&level(TILES, &format!("{SPAWN}, {way}"))),
        "levels/test.json",
        "layers[1].entities[1].values.action",
    );
    // Tile coordinates without a project to count the tileset's columns.
    let tiles = r#""dataCoords": [[0, 0], [-1], [-1], [-1], [-1], [-1], [-1], [-1]]"#;
    let msg = check(
        load(&level(tiles, SPAWN)),
        "levels/test.json",
        "layers[0].dataCoords[0]",
    );
    assert!(msg.contains("column count"), "{msg}");
    // Tiled: a slope flipped vertically is a ceiling: no tile kind, so a
    // static polygon over its cell (cell 165 = (5, 8) of 16 px tiles).
    let file = format!("{TILED_DIR}/flipped.tmx");
    let text = std::fs::read_to_string(format!("{TILED_DIR}/level.tmx"))
        .unwrap()
        .replacen("2147483651", "1073741827", 1);
    let l = tmx::load_str(&file, &text, &LoadOptions::default()).unwrap();
    assert_eq!(l.level.tilemap.tile(IVec2::new(5, 8)), Tile::Empty);
    let cell = |x: i32, y: i32| IVec2::new(x, y) * 16 * 256;
    let ceiling = l
        .level
        .entities
        .iter()
        .find_map(|e| match &e.kind {
            EntityKind::PolygonBlock { vertices } => {
                let abs: Vec<_> = vertices.iter().map(|v| *v + e.pos).collect();
                abs.iter()
                    .all(|p| {
                        (cell(5, 8).x..=cell(6, 8).x).contains(&p.x)
                            && (cell(5, 8).y..=cell(5, 9).y).contains(&p.y)
                    })
                    .then_some(abs)
            }
            _ => None,
        })
        .expect("a polygon in cell (5, 8)");
    // The `/` slope upside down: solid above the line, top-left to
    // bottom-right corners... mirrored vertically: (0,0), (16,0), (16,16).
    let mut want = vec![cell(5, 8), cell(6, 8), cell(6, 9)];
    let mut got = ceiling.clone();
    want.sort_by_key(|p| (p.x, p.y));
    got.sort_by_key(|p| (p.x, p.y));
    assert_eq!(got, want);
}

#[test]
fn unknown_tiles() {
    let tiles = TILES.replace("13, 2]", "13, 99]");
    let msg = check(
        load(&level(&tiles, SPAWN)),
        "levels/test.json",
        "layers[0].data[7]: tile id 99",
    );
    assert!(msg.contains("\"ledge\""), "{msg}");
    // A grid value ledge does not know is solid, with a warning.
    let grid = r#"{"name": "solids", "gridCellWidth": 16, "gridCellHeight": 16, "gridCellsX": 2, "gridCellsY": 1, "grid2D": [["1", "z"]]}"#;
    let text = format!(r#"{{"layers": [{grid}, {{"name": "e", "entities": [{SPAWN}]}}]}}"#);
    let l = load(&text).unwrap();
    assert_eq!(l.level.tilemap.tiles(), &[Tile::Solid, Tile::Solid]);
    assert_eq!(l.warnings.len(), 1, "{:?}", l.warnings);
    assert!(
        l.warnings[0].contains("layers[0].grid2D[0][1]: grid value \"z\" (1 cells)")
            && l.warnings[0].contains("read as solid"),
        "{:?}",
        l.warnings
    );
    let file = format!("{TILED_DIR}/kind.tmx");
    let text = std::fs::read_to_string(format!("{TILED_DIR}/level.tmx"))
        .unwrap()
        .replacen("value=\"one_way\"", "value=\"bouncy\"", 1);
    let msg = check(
        tmx::load_str(&file, &text, &LoadOptions::default()),
        &file,
        "layers[1].data[",
    );
    assert!(msg.contains("kind \"bouncy\""), "{msg}");
}

#[test]
fn unknown_entities_name_file_layer_and_entity() {
    // uno.json (a format sample, not a game) loads, and says what it did
    // not use: its tile layers (a foreign tileset), the unknown entity
    // "Dude"; its 16 px grid layer is resampled onto the 8 px one (which
    // covers more), so its spawn is placed on the 8 px layer's "g" cells.
    let l = load_file_with(UNO, &LoadOptions::default()).unwrap();
    let all = l.warnings.join("\n");
    for needle in [
        "the first free standing spot from the left",
        "tile layer \"tile_1D\" does not collide",
        "layers[4]: layer \"grid_1D\" of 16 px cells is resampled onto the level's grid of 8 px cells",
        "skipped unknown entity \"Dude\" in layer \"entity_layer\"",
    ] {
        assert!(all.contains(needle), "{needle:?} not in:\n{all}");
    }
    let opts = LoadOptions {
        collision_layers: Some(Vec::new()),
        skip_unknown_entities: false,
        ..LoadOptions::default()
    };
    let e = load_file_with(UNO, &opts).unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with(UNO), "{msg}");
    assert!(
        msg.contains(
            "layers[6].entities[0].name: unknown entity \"Dude\" in layer \"entity_layer\""
        ),
        "{msg}"
    );
    assert!(msg.contains("player, spawn"), "{msg}");
    // Or skipped, with a warning each.
    let text = level(
        TILES,
        &format!(r#"{SPAWN}, {{"name": "Ghost", "x": 0, "y": 0, "width": 8, "height": 8}}"#),
    );
    let opts = LoadOptions {
        skip_unknown_entities: true,
        ..LoadOptions::default()
    };
    let l = ogmo::load_str("t.json", &text, None, &opts).unwrap();
    assert_eq!(
        l.warnings,
        ["t.json: layers[1].entities[1]: skipped unknown entity \"Ghost\" in layer \"things\""]
    );
    // Tiled: objects by class, else name.
    let file = format!("{TILED_DIR}/ghost.tmx");
    let text = std::fs::read_to_string(format!("{TILED_DIR}/level.tmx"))
        .unwrap()
        .replacen("name=\"coin\"", "name=\"ghost\"", 1);
    let strict = LoadOptions {
        skip_unknown_entities: false,
        ..LoadOptions::default()
    };
    let msg = check(
        tmx::load_str(&file, &text, &strict),
        &file,
        "layers[2].objects[8].name",
    );
    assert!(msg.contains("\"ghost\" in layer \"objects\""), "{msg}");
    // By default: skipped, and said where.
    let l = tmx::load_str(&file, &text, &LoadOptions::default()).unwrap();
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("layer \"objects\" (layers[2]) object")
                && w.contains("skipped objects named \"ghost\"")),
        "{:?}",
        l.warnings
    );
}

#[test]
fn degenerate_platform_paths() {
    let p = |nodes: &str, values: &str| {
        level(
            TILES,
            &format!(
                r#"{SPAWN}, {{"name": "moving_platform", "x": 16, "y": 8, "width": 32, "height": 8, "nodes": {nodes}, "values": {values}}}"#
            ),
        )
    };
    let msg = check(
        load(&p("[]", "{}")),
        "levels/test.json",
        "layers[1].entities[1].nodes: degenerate platform path",
    );
    assert!(msg.contains("at least one node"), "{msg}");
    let msg = check(
        load(&p(r#"[{"x": 48, "y": 8}, {"x": 48, "y": 8}]"#, "{}")),
        "levels/test.json",
        "layers[1].entities[1].nodes[1]",
    );
    assert!(msg.contains("zero-length leg"), "{msg}");
    check(
        load(&p(r#"[{"x": 16, "y": 8}]"#, "{}")),
        "levels/test.json",
        "layers[1].entities[1].nodes[0]",
    );
    // A loop closed back on its start is fine (the closing node is dropped).
    let l = load(&p(
        r#"[{"x": 48, "y": 8}, {"x": 48, "y": 24}, {"x": 16, "y": 8}]"#,
        r#"{"loop": true}"#,
    ))
    .unwrap();
    let ledge_levels::EntityKind::MovingPlatform { motion, .. } = &l.level.entities[1].kind else {
        panic!()
    };
    assert_eq!(motion.path.len(), 3);
    assert!(motion.looped);
    // Tiled: a path property naming a non-path object.
    let file = format!("{TILED_DIR}/path.tmx");
    let text = std::fs::read_to_string(format!("{TILED_DIR}/level.tmx"))
        .unwrap()
        .replacen(
            "name=\"path\" type=\"object\" value=\"4\"",
            "name=\"path\" type=\"object\" value=\"2\"",
            1,
        );
    let msg = check(
        tmx::load_str(&file, &text, &LoadOptions::default()),
        &file,
        "layers[2].objects[",
    );
    assert!(
        msg.contains(".properties.path: object 2 is not a polyline"),
        "{msg}"
    );
}

#[test]
fn missing_spawn() {
    // Nothing in the level at all: nowhere to place one.
    let e = load(r#"{"layers": []}"#).unwrap_err();
    assert_eq!(
        e.to_string(),
        "levels/test.json: entities: no player spawn, and nothing in the level to place one on: nothing in it collides (add an entity named \"player\" or \"spawn\", and make something collide: see docs/LEVELS.md, \"What collides\", and the level's settings file)"
    );
    // No free spot to stand on inside (the floor row is at the top): on
    // top of the level at its left edge, and said.
    let l = load(&level(TILES, "")).unwrap();
    let spawn = l.level.entities.last().unwrap();
    assert_eq!(spawn.kind, EntityKind::PlayerSpawn);
    assert_eq!(spawn.pos.y + spawn.size.y / 2, 0);
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("on top of the level at its left edge")),
        "{:?}",
        l.warnings
    );
    // With a floor and room above it, one is placed on the first free
    // spot from the left, and said.
    let floor = r#""data": [-1, -1, -1, -1, 1, 1, 1, 1], "exportMode": 0, "arrayMode": 0"#;
    let l = load(&level(floor, "")).unwrap();
    let spawn = l
        .level
        .entities
        .iter()
        .find(|e| e.kind == EntityKind::PlayerSpawn)
        .expect("a spawn");
    // Standing on row 1's top (y = 16 px), in column 0.
    assert_eq!(spawn.pos.y + spawn.size.y / 2, 16 * 256);
    assert!((0..16 * 256).contains(&spawn.pos.x), "{spawn:?}");
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("no player spawn: players start at (")),
        "{:?}",
        l.warnings
    );
    let opts = LoadOptions {
        require_spawn: false,
        ..LoadOptions::default()
    };
    assert!(ogmo::load_str("x.json", &level(TILES, ""), None, &opts).is_ok());
    // The echo sample has no spawn: one is placed on its first free spot.
    let slopes = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/testdata/levels/echo-slopes/slopes.json"
    );
    let l = load_file_with(slopes, &LoadOptions::default()).unwrap();
    assert_eq!(l.level.entities.len(), 1);
    assert_eq!(l.level.entities[0].kind, EntityKind::PlayerSpawn);
}

/// A byte-level mutation of a valid file.
fn mutate(base: &[u8], edits: &[(usize, u8, u8)]) -> Vec<u8> {
    let mut b = base.to_vec();
    for &(pos, op, byte) in edits {
        if b.is_empty() {
            break;
        }
        let i = pos % b.len();
        match op % 4 {
            0 => b[i] = byte,
            1 => {
                b.remove(i);
            }
            2 => b.insert(i, byte),
            _ => b.truncate(i),
        }
    }
    b
}

/// Structure-aware bytes: JSON punctuation, digits, keys OGMO uses.
fn json_ish() -> impl Strategy<Value = u8> {
    prop::sample::select(b"{}[],:\"-0123456789.eE truefalsnul\n-1xy".to_vec())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 192, ..ProptestConfig::default() })]

    #[test]
    fn ogmo_loader_never_panics_on_random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = ogmo::load_str("fuzz.json", &text, None, &LoadOptions::default());
        let _ = ogmo::parse_project("fuzz.ogmo", &text);
    }

    #[test]
    fn ogmo_loader_never_panics_on_mutated_levels(
        edits in prop::collection::vec((any::<usize>(), any::<u8>(), json_ish()), 1..8),
        which in 0..3u8,
    ) {
        let uno = std::fs::read_to_string(UNO).unwrap();
        let base = match which {
            0 => DEFAULT_JSON,
            1 => uno.as_str(),
            _ => DEFAULT_PROJECT,
        };
        let text = String::from_utf8_lossy(&mutate(base.as_bytes(), &edits)).into_owned();
        let r = ogmo::load_str("fuzz.json", &text, Some(("ledge.ogmo", DEFAULT_PROJECT)), &LoadOptions::default());
        if let Err(e) = r {
            prop_assert!(e.to_string().starts_with("fuzz.json: ") || e.to_string().starts_with("ledge.ogmo: "));
        }
        let _ = ogmo::load_str("fuzz.json", DEFAULT_JSON, Some(("fuzz.ogmo", &text)), &LoadOptions::default());
    }

    #[test]
    fn tiled_loader_never_panics_on_mutated_maps(
        edits in prop::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6),
    ) {
        let base = std::fs::read(format!("{TILED_DIR}/level.tmx")).unwrap();
        let text = String::from_utf8_lossy(&mutate(&base, &edits)).into_owned();
        let file = format!("{TILED_DIR}/fuzz.tmx");
        if let Err(e) = tmx::load_str(&file, &text, &LoadOptions::default()) {
            // The map, or the external tileset or image it names.
            prop_assert!(e.to_string().starts_with(TILED_DIR), "{}", e);
        }
    }
}

#[test]
fn the_default_level_never_fails() {
    load_default_level().unwrap();
}
