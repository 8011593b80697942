//! LDtk edge cases on small projects written here: unknown, unnamed and
//! refused IntGrid values, one-way and hazard values, the settings file's
//! `[grid]`, external levels that leave the project's folder, a missing
//! level after `#`, platforms with and without a path, limits, and
//! `ledge-level check` on a project.

use std::path::{Path, PathBuf};

use glam::IVec2;
use ledge_levels::{ldtk, load_level, EntityKind, LevelError, LoadOptions, LoadedLevel};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::tilemap::Tile;
use serde_json::{json, Value};

/// An IntGrid layer definition (uid 1, "Collisions", 16 px) with `values`
/// (value, identifier).
fn defs(values: &[(i64, Option<&str>)]) -> Value {
    let values: Vec<Value> = values
        .iter()
        .map(|(v, id)| json!({"value": v, "identifier": id, "color": "#000000"}))
        .collect();
    json!({
        "layers": [{"uid": 1, "identifier": "Collisions", "type": "IntGrid", "gridSize": 16, "intGridValues": values}],
        "tilesets": []
    })
}

/// An IntGrid layer instance of `rows` (digits, one row each).
fn int_grid(name: &str, rows: &[&str]) -> Value {
    let csv: Vec<i64> = rows
        .iter()
        .flat_map(|r| r.chars().map(|c| c.to_digit(10).unwrap() as i64))
        .collect();
    json!({
        "__identifier": name, "__type": "IntGrid", "__cWid": rows[0].len(), "__cHei": rows.len(),
        "__gridSize": 16, "__pxTotalOffsetX": 0, "__pxTotalOffsetY": 0, "layerDefUid": 1,
        "visible": true, "intGridCsv": csv, "autoLayerTiles": [], "gridTiles": [], "entityInstances": []
    })
}

/// An entity layer of `entities`.
fn entity_layer(entities: Vec<Value>) -> Value {
    json!({
        "__identifier": "Entities", "__type": "Entities", "__cWid": 8, "__cHei": 6, "__gridSize": 16,
        "visible": true, "entityInstances": entities
    })
}

/// A 16 x 16 entity with its pivot at the bottom centre, at `px`.
fn entity(name: &str, px: [i64; 2], fields: Vec<Value>) -> Value {
    json!({"__identifier": name, "__pivot": [0.5, 1], "width": 16, "height": 16, "px": px, "fieldInstances": fields})
}

/// A project of one level per `(identifier, layers)`.
fn project(defs: Value, levels: Vec<(&str, Vec<Value>)>) -> Value {
    let levels: Vec<Value> = levels
        .into_iter()
        .map(|(id, layers)| json!({"identifier": id, "pxWid": 128, "pxHei": 96, "layerInstances": layers}))
        .collect();
    json!({"jsonVersion": "1.5.3", "defs": defs, "levels": levels, "worlds": []})
}

/// The rooms the tests use: 8 x 6 cells, floor on row 5.
const ROOM: &[&str] = &[
    "00000000", "00000000", "00000000", "00000000", "00000000", "11111111",
];

fn write(dir: &Path, name: &str, v: &Value) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string_pretty(v).unwrap()).unwrap();
    p
}

fn load_at(path: &Path, level: Option<&str>) -> Result<LoadedLevel, LevelError> {
    let p = match level {
        Some(l) => PathBuf::from(format!("{}#{l}", path.display())),
        None => path.to_path_buf(),
    };
    load_level(&p, None)
}

fn warned(l: &LoadedLevel, needle: &str) -> bool {
    l.warnings.iter().any(|w| w.contains(needle))
}

fn tile(l: &LoadedLevel, c: i32, r: i32) -> Tile {
    l.level.tilemap.tile(IVec2::new(c, r))
}

#[test]
fn values_by_identifier_unknown_unnamed_and_refused() {
    let dir = tempfile::tempdir().unwrap();
    let values = [
        (1, Some("walls")),
        (2, Some("one_way")),
        (3, Some("spikes")),
        (4, Some("ladder")),
        (5, Some("bouncy_goo")),
        (6, None),
    ];
    let rows = [
        "00000000", "02000000", "00400000", "00050000", "00006070", "11111131",
    ];
    let p = write(
        dir.path(),
        "v.ldtk",
        &project(
            defs(&values),
            vec![("Level_0", vec![int_grid("Collisions", &rows)])],
        ),
    );
    let l = load_at(&p, None).unwrap();
    assert_eq!(tile(&l, 0, 5), Tile::Solid);
    assert_eq!(tile(&l, 1, 1), Tile::OneWay);
    assert_eq!(tile(&l, 6, 5), Tile::Hazard);
    // A ladder is refused: empty, never silently solid, and said.
    assert_eq!(tile(&l, 2, 2), Tile::Empty);
    assert!(warned(&l, "layerInstances[0].intGridCsv[18] (column 2, row 2): IntGrid value 4 \"ladder\" of layer \"Collisions\" (1 cells) is not supported in ledge"), "{:?}", l.warnings);
    // An unknown name is solid, said with what to write.
    assert_eq!(tile(&l, 3, 3), Tile::Solid);
    assert!(warned(&l, "IntGrid value 5 \"bouncy_goo\" of layer \"Collisions\" (1 cells) is not a name ledge knows: read as solid"));
    assert!(warned(&l, "bouncy_goo = \"KIND\" under [grid]"));
    // An unnamed value: solid, said.
    assert_eq!(tile(&l, 4, 4), Tile::Solid);
    assert!(warned(
        &l,
        "IntGrid value 6 of layer \"Collisions\" (1 cells) has no identifier: read as solid"
    ));
    // A value the definition does not have: solid, said.
    assert_eq!(tile(&l, 6, 4), Tile::Solid);
    assert!(warned(&l, "IntGrid value 7 of layer \"Collisions\" (1 cells) is not one of the layer's IntGrid values"));
    // Known names give no warning.
    assert!(!warned(&l, "\"walls\""));
    assert!(!warned(&l, "\"spikes\""));

    // The settings file's [grid] maps an identifier.
    std::fs::write(
        dir.path().join("v.ledge.toml"),
        "[grid]\nladder = \"one_way\"\n",
    )
    .unwrap();
    let l = load_at(&p, None).unwrap();
    assert_eq!(tile(&l, 2, 2), Tile::OneWay);
    assert!(!warned(&l, "\"ladder\""));
}

#[test]
fn collision_named_layers_decide_and_the_upper_layer_wins() {
    let dir = tempfile::tempdir().unwrap();
    let d = json!({"layers": [
        {"uid": 1, "identifier": "Collisions", "intGridValues": [{"value": 1, "identifier": "walls"}, {"value": 2, "identifier": "one_way"}]},
        {"uid": 2, "identifier": "Water", "intGridValues": [{"value": 1, "identifier": "walls"}]}
    ]});
    let mut water = int_grid(
        "Water",
        &[
            "11111111", "00000000", "00000000", "00000000", "00000000", "00000000",
        ],
    );
    water["layerDefUid"] = json!(2);
    let upper = int_grid(
        "Solid",
        &[
            "00000000", "00000000", "00000000", "00000000", "00000000", "22000000",
        ],
    );
    let p = write(
        dir.path(),
        "d.ldtk",
        &project(
            d,
            vec![("L", vec![water, upper, int_grid("Collisions", ROOM)])],
        ),
    );
    let l = load_at(&p, Some("L")).unwrap();
    // "Water" is not named for collision: it does not collide, said.
    assert_eq!(tile(&l, 0, 0), Tile::Empty);
    assert!(warned(&l, "IntGrid layer \"Water\" does not collide: the IntGrid layers named for collision (Solid, Collisions) decide"), "{:?}", l.warnings);
    // "Solid" (above "Collisions") wins where both have a value.
    assert_eq!(tile(&l, 0, 5), Tile::OneWay);
    assert_eq!(tile(&l, 2, 5), Tile::Solid);
}

#[test]
fn external_levels_must_stay_in_the_projects_folder() {
    let dir = tempfile::tempdir().unwrap();
    let inner = dir.path().join("game");
    std::fs::create_dir_all(inner.join("levels")).unwrap();
    let level = json!({"identifier": "L", "pxWid": 128, "pxHei": 96, "layerInstances": [int_grid("Collisions", ROOM)]});
    write(&inner.join("levels"), "L.ldtkl", &level);
    write(dir.path(), "outside.ldtkl", &level);
    let with = |rel: &str| {
        let mut p = project(defs(&[(1, Some("walls"))]), vec![("L", vec![])]);
        p["levels"][0]["layerInstances"] = Value::Null;
        p["levels"][0]["externalRelPath"] = json!(rel);
        p["externalLevels"] = json!(true);
        write(&inner, "p.ldtk", &p)
    };
    let p = with("levels/L.ldtkl");
    let l = load_at(&p, Some("L")).unwrap();
    assert_eq!(tile(&l, 0, 5), Tile::Solid);
    for rel in [
        "../outside.ldtkl",
        "levels/../../outside.ldtkl",
        "/etc/passwd",
    ] {
        let p = with(rel);
        let e = load_at(&p, Some("L")).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("levels[0].externalRelPath"), "{msg}");
        assert!(
            msg.contains(&format!(
                "external level path {rel:?} leaves the project's folder"
            )),
            "{msg}"
        );
    }
    // Through a symbolic link: refused too.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.path(), inner.join("up")).unwrap();
        let p = with("up/outside.ldtkl");
        let msg = load_at(&p, Some("L")).unwrap_err().to_string();
        assert!(msg.contains("outside the project's folder"), "{msg}");
    }
    // A missing level file: a read error naming it.
    let p = with("levels/nope.ldtkl");
    let msg = load_at(&p, Some("L")).unwrap_err().to_string();
    assert!(msg.contains("nope.ldtkl: cannot read the file"), "{msg}");
    // Text has no folder to read it from.
    let text = std::fs::read_to_string(&p).unwrap();
    let msg = ldtk::load_str("p.ldtk", &text, None, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(msg.contains("the project was given as text"), "{msg}");
    // An .ldtkl given alone is refused, saying what to load.
    let msg = load_level(&inner.join("levels/L.ldtkl"), None)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("load the project instead (PROJECT.ldtk#LEVEL_IDENTIFIER)"),
        "{msg}"
    );
}

#[test]
fn a_missing_level_after_the_hash_is_refused_with_the_levels_named() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "two.ldtk",
        &project(
            defs(&[(1, Some("walls"))]),
            vec![
                ("First", vec![int_grid("Collisions", ROOM)]),
                ("Second", vec![int_grid("Collisions", ROOM)]),
            ],
        ),
    );
    assert_eq!(ldtk::level_names(&p).unwrap(), ["First", "Second"]);
    assert_eq!(load_at(&p, Some("Second")).unwrap().level.name, "Second");
    assert_eq!(load_at(&p, None).unwrap().level.name, "First");
    let e = load_at(&p, Some("Third")).unwrap_err();
    assert!(matches!(e, LevelError::UnknownLevel { .. }), "{e:?}");
    assert_eq!(e.file(), p.display().to_string());
    assert!(
        e.to_string().ends_with(
            "levels: no level \"Third\" in this LDtk project (the project's levels: First, Second)"
        ),
        "{e}"
    );
    let e = load_at(&p, Some("")).unwrap_err().to_string();
    assert!(e.contains("no level name after '#'"), "{e}");
    let paths = ldtk::level_paths(&p).unwrap();
    assert_eq!(paths[1], PathBuf::from(format!("{}#Second", p.display())));
    // A multi-world project: the worlds' levels, in order, after any
    // top-level ones.
    let mut multi = project(defs(&[(1, Some("walls"))]), vec![]);
    let world = |names: &[&str]| {
        let levels: Vec<Value> = names
            .iter()
            .map(|n| json!({"identifier": n, "pxWid": 128, "pxHei": 96, "layerInstances": [int_grid("Collisions", ROOM)]}))
            .collect();
        json!({"identifier": "W", "levels": levels})
    };
    multi["worlds"] = json!([world(&["A", "B"]), world(&["C"])]);
    let p = write(dir.path(), "multi.ldtk", &multi);
    assert_eq!(ldtk::level_names(&p).unwrap(), ["A", "B", "C"]);
    assert_eq!(load_at(&p, Some("C")).unwrap().level.name, "C");
    // No levels at all: refused, said.
    let p = write(dir.path(), "none.ldtk", &project(defs(&[]), vec![]));
    let e = load_at(&p, None).unwrap_err().to_string();
    assert!(
        e.ends_with("levels: the project has no levels (the project's levels: none)"),
        "{e}"
    );
}

#[test]
fn platforms_walkers_and_the_other_entities() {
    let dir = tempfile::tempdir().unwrap();
    let points = |pts: &[(i64, i64)]| {
        let v: Vec<Value> = pts.iter().map(|(x, y)| json!({"cx": x, "cy": y})).collect();
        json!({"__identifier": "path", "__type": "Array<Point>", "__value": v})
    };
    let speed = json!({"__identifier": "speed", "__type": "Float", "__value": 2.0});
    let ents = vec![
        entity("Hero", [24, 80], vec![]),
        entity(
            "MovingPlatform",
            [40, 48],
            vec![points(&[(2, 2), (6, 2)]), speed],
        ),
        entity("Platform", [40, 32], vec![]),
        entity("Mob", [88, 80], vec![points(&[(7, 4)])]),
        entity("Gem", [56, 64], vec![]),
        entity("Spikes", [72, 80], vec![]),
        entity("Door", [104, 80], vec![]),
        entity("Checkpoint", [8, 80], vec![]),
        entity("Chest", [8, 48], vec![]),
    ];
    let p = write(
        dir.path(),
        "e.ldtk",
        &project(
            defs(&[(1, Some("walls"))]),
            vec![("L", vec![entity_layer(ents), int_grid("Collisions", ROOM)])],
        ),
    );
    let l = load_at(&p, None).unwrap();
    let u = |x: i32, y: i32| IVec2::new(x, y) * UNITS_PER_PX;
    let find =
        |f: &dyn Fn(&EntityKind) -> bool| l.level.entities.iter().find(|e| f(&e.kind)).unwrap();
    // Hero: pivot (24, 80), 16 x 16: centre (24, 72).
    assert_eq!(find(&|k| *k == EntityKind::PlayerSpawn).pos, u(24, 72));
    // The platform stands at each point as if placed in that cell; the
    // first point is where it already is, so it is dropped.
    let pl = find(&|k| matches!(k, EntityKind::MovingPlatform { .. }));
    let EntityKind::MovingPlatform { motion, .. } = &pl.kind else {
        unreachable!()
    };
    assert_eq!(pl.pos, u(40, 40));
    assert_eq!(motion.path, vec![u(40, 40), u(104, 40)]);
    assert_eq!(motion.speed, 2 * UNITS_PER_PX);
    assert!(
        warned(
            &l,
            "skipped entity \"Platform\" in layer \"Entities\": a moving platform needs a path"
        ),
        "{:?}",
        l.warnings
    );
    assert!(matches!(
        find(&|k| matches!(k, EntityKind::Walker { .. })).kind,
        EntityKind::Walker { .. }
    ));
    assert!(warned(
        &l,
        "the patrol points of 1 \"Mob\" entities in layer \"Entities\" are not used"
    ));
    assert_eq!(find(&|k| *k == EntityKind::Coin).pos, u(56, 56));
    assert_eq!(find(&|k| *k == EntityKind::Hazard).pos, u(72, 72));
    assert_eq!(find(&|k| *k == EntityKind::Goal).pos, u(104, 72));
    assert_eq!(find(&|k| *k == EntityKind::Checkpoint).pos, u(8, 72));
    assert!(warned(
        &l,
        "skipped unknown entity \"Chest\" in layer \"Entities\""
    ));
    // With unknown entities refused by the settings, Chest refuses it.
    std::fs::write(
        dir.path().join("e.ledge.toml"),
        "unknown_entities = \"error\"\n",
    )
    .unwrap();
    let e = load_at(&p, None).unwrap_err().to_string();
    assert!(e.contains("unknown entity \"Chest\""), "{e}");
}

#[test]
fn counts_beyond_the_limits_are_refused_naming_the_bound() {
    let many: Vec<Value> = (0..=ledge_levels::limits::MAX_LDTK_LAYERS)
        .map(|_| json!({"__type": "Entities"}))
        .collect();
    let text = project(defs(&[]), vec![("L", many)]).to_string();
    let e = ldtk::load_str("many.ldtk", &text, None, &LoadOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            LevelError::Limit {
                bound: "MAX_LDTK_LAYERS",
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(
        e.to_string(),
        "many.ldtk#L: layerInstances: 1025 layers is more than the limit of 1024 (MAX_LDTK_LAYERS)"
    );
    // A layer larger than the level limits: refused before its cells.
    let mut big = int_grid("Collisions", ROOM);
    big["__cWid"] = json!(5000);
    let text = project(defs(&[(1, Some("walls"))]), vec![("L", vec![big])]).to_string();
    let e = ldtk::load_str("big.ldtk", &text, None, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "big.ldtk#L: layerInstances[0].__cWid: 5000 cells is outside [0, 4096]"
    );
    // 4096 x 4096 cells in two layers: past MAX_LEVEL_CELLS.
    let mut huge = int_grid("Collisions", ROOM);
    huge["__cWid"] = json!(4096);
    huge["__cHei"] = json!(1024);
    let text = project(
        defs(&[(1, Some("walls"))]),
        vec![("L", vec![huge.clone(), huge])],
    )
    .to_string();
    let e = ldtk::load_str("huge.ldtk", &text, None, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("(MAX_LEVEL_CELLS)"), "{e}");
    // A short intGridCsv: its length named.
    let mut short = int_grid("Collisions", ROOM);
    short["intGridCsv"].as_array_mut().unwrap().pop();
    let text = project(defs(&[(1, Some("walls"))]), vec![("L", vec![short])]).to_string();
    let e = ldtk::load_str("short.ldtk", &text, None, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "short.ldtk#L: layerInstances[0].intGridCsv: expected 48 entries, got 47"
    );
    // Deep JSON and malformed JSON: refused before or by the parser.
    let deep = format!("{}{}", "[".repeat(200), "]".repeat(200));
    let e = ldtk::load_str("deep.ldtk", &deep, None, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("(MAX_JSON_DEPTH)"), "{e}");
    let e = ldtk::load_str("bad.ldtk", "{\"levels\": [}", None, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("bad.ldtk: line 1 column 13: malformed LDtk project JSON"),
        "{e}"
    );
    let e = ldtk::load_str(
        "type.ldtk",
        "{\"levels\": 3}",
        None,
        &LoadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("malformed LDtk project JSON: invalid type"),
        "{e}"
    );
}

#[test]
fn no_input_panics() {
    // Every prefix of a real project, and a few mutations: Ok or a clean
    // error naming the file.
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/testdata/levels/ldtk-samples/AutoLayers_1_basic.ldtk"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let o = LoadOptions::default();
    for cut in (0..text.len()).step_by(997) {
        if let Err(e) = ldtk::load_str("cut.ldtk", &text[..cut], None, &o) {
            assert!(e.file().starts_with("cut.ldtk"), "{e}");
        }
    }
    for (from, to) in [
        ("\"__gridSize\": 8", "\"__gridSize\": 0"),
        ("\"__gridSize\": 8", "\"__gridSize\": -8"),
        ("\"__cWid\": 37", "\"__cWid\": -1"),
        ("\"tileGridSize\": 8", "\"tileGridSize\": 100000"),
        (
            "\"__pxTotalOffsetX\": 0",
            "\"__pxTotalOffsetX\": 9000000000",
        ),
        ("\"f\": 0", "\"f\": -7"),
        ("\"px\": [", "\"px\": [-99999999,"),
    ] {
        let mutated = text.replacen(from, to, 1);
        assert_ne!(mutated, text, "{from}");
        if let Err(e) = ldtk::load_str("m.ldtk", &mutated, None, &o) {
            assert!(e.file().starts_with("m.ldtk"), "{e}");
        }
    }
}

#[test]
fn ledge_level_check_reads_a_project_level_by_level() {
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_ledge-level"))
            .arg("check")
            .args(args)
            .output()
            .unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let project = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/testdata/levels/ldtk-samples/Typical_2D_platformer_example.ldtk"
    );
    let (ok, out, err) = run(&[&format!("{project}#Top")]);
    assert!(ok, "{out}\n{err}");
    for needle in [
        "Typical_2D_platformer_example.ldtk#Top: ok, level \"Top\"",
        "grid: 42 x 22 tiles of 16 px at (0, 0) px",
        "layer \"Collisions\" (layerInstances[2]), tiles: ",
        "IntGrid value 2 \"ladder\"",
        "settings: none (",
    ] {
        assert!(out.contains(needle), "{needle:?} not in:\n{out}");
    }
    // The whole project: every level.
    let (ok, out, _) = run(&[project]);
    assert!(ok);
    assert_eq!(out.matches(": ok, level ").count(), 4, "{out}");
    // A level that is not there: refused, the levels named, exit 1.
    let (ok, _, err) = run(&[&format!("{project}#Nope")]);
    assert!(!ok);
    assert!(err.contains("no level \"Nope\" in this LDtk project (the project's levels: Your_typical_2D_platformer, Top, Bottom, World_Level_3)"), "{err}");
}

/// A project with every part the importer reads: IntGrid values, a tile
/// layer and an auto-layer drawn from a real tileset image, entities with
/// fields and a platform path.
fn everything() -> Value {
    let mut d = defs(&[(1, Some("walls")), (2, Some("one_way")), (3, None)]);
    d["tilesets"] = json!([{"uid": 9, "identifier": "Cavernas", "relPath": "atlas.png", "tileGridSize": 8, "spacing": 0, "padding": 0}]);
    let mut grid = int_grid(
        "Collisions",
        &[
            "00000000", "00000000", "00300000", "02000000", "00000000", "11111111",
        ],
    );
    grid["__tilesetDefUid"] = json!(9);
    grid["autoLayerTiles"] = json!([{"px": [0, 80], "src": [8, 0], "f": 1, "a": 1}, {"px": [0, 80], "src": [16, 8], "f": 2, "a": 0.5}, {"px": [20, 84], "src": [0, 0], "f": 3, "a": 1}]);
    let tiles = json!({"__identifier": "Tiles", "__type": "Tiles", "__cWid": 16, "__cHei": 12, "__gridSize": 8,
        "__pxTotalOffsetX": 4, "__pxTotalOffsetY": -4, "__tilesetDefUid": 9, "__opacity": 0.5, "visible": true,
        "gridTiles": [{"px": [8, 8], "src": [24, 16], "f": 0}, {"px": [120, 88], "src": [0, 256], "f": 0}]});
    let path = json!({"__identifier": "points", "__type": "Array<Point>", "__value": [{"cx": 2, "cy": 2}, {"cx": 5, "cy": 2}]});
    let ents = entity_layer(vec![
        entity(
            "Player",
            [24, 80],
            vec![json!({"__identifier": "hp", "__type": "Int", "__value": 3})],
        ),
        entity(
            "Lift_platform",
            [40, 48],
            vec![
                path,
                json!({"__identifier": "loop", "__type": "Bool", "__value": true}),
            ],
        ),
        entity(
            "Enemy",
            [88, 80],
            vec![json!({"__identifier": "speed", "__type": "Float", "__value": 0.5})],
        ),
    ]);
    project(d, vec![("L", vec![ents, tiles, grid])])
}

#[test]
fn tiles_stacked_offset_and_flipped_are_drawn_as_ldtk_places_them() {
    let dir = tempfile::tempdir().unwrap();
    let atlas = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/testdata/levels/ldtk-samples/atlas/Cavernas_by_Adam_Saltsman.png"
    );
    std::fs::copy(atlas, dir.path().join("atlas.png")).unwrap();
    let p = write(dir.path(), "t.ldtk", &everything());
    let l = load_at(&p, None).unwrap();
    let art = &l.art;
    art.check().unwrap();
    assert_eq!(art.images.len(), 1);
    assert_eq!(art.images[0].name, "atlas.png");
    // 96 x 256 px of 8 px tiles: 12 columns.
    assert_eq!(
        (art.tilesets[0].columns, art.tilesets[0].tile_count),
        (12, 12 * 32)
    );
    let summary: Vec<(String, (f32, f32), f32, usize)> = art
        .layers
        .iter()
        .map(|a| {
            let ledge_levels::art::ArtContent::Tiles(g) = &a.content else {
                panic!()
            };
            (
                a.name.clone(),
                a.offset,
                a.opacity,
                g.cells.iter().flatten().count(),
            )
        })
        .collect();
    // Back to front: the IntGrid layer's tiles (two stacked in one cell,
    // the upper at half opacity; one 4 px off the grid), then the tile
    // layer (offset by its layer offset; the tile outside the atlas left
    // out, said).
    assert_eq!(
        summary,
        vec![
            ("Collisions".to_string(), (0.0, -8.0), 1.0, 1),
            ("Collisions".to_string(), (4.0, -4.0), 1.0, 1),
            ("Collisions".to_string(), (0.0, -8.0), 0.5, 1),
            ("Tiles".to_string(), (4.0, -4.0), 0.5, 1),
        ]
    );
    let cell = |i: usize, x, y| {
        let ledge_levels::art::ArtContent::Tiles(g) = &art.layers[i].content else {
            panic!()
        };
        *g.get(x, y).unwrap()
    };
    // The 16 px grid's cell (0, 5) holds two tiles; the 8 px tiles of
    // 16 px cells are lifted 8 px (the art draws a tile from its cell's
    // bottom-left corner, LDtk from its top-left), hence the y offsets.
    let c = cell(0, 0, 5);
    assert_eq!((c.tile, c.flip_h, c.flip_v), (1, true, false));
    let c = cell(2, 0, 5);
    assert_eq!((c.tile, c.flip_h, c.flip_v), (12 + 2, false, true));
    let c = cell(1, 1, 5);
    assert_eq!((c.tile, c.flip_h, c.flip_v), (0, true, true));
    assert_eq!(cell(3, 1, 1).tile, 2 * 12 + 3);
    assert!(art.warnings.iter().any(|w| w.contains("layerInstances[1].gridTiles: 1 tiles of layer \"Tiles\" are not on their tileset's grid or image")), "{:?}", art.warnings);
    // The unnamed value 3 is solid, value 2 one-way; the looping platform.
    assert_eq!(tile(&l, 2, 2), Tile::Solid);
    assert_eq!(tile(&l, 1, 3), Tile::OneWay);
    let pl = l.level.entities.iter().find_map(|e| match &e.kind {
        EntityKind::MovingPlatform { motion, .. } => Some(motion.clone()),
        _ => None,
    });
    assert!(pl.is_some_and(|m| m.looped && m.path.len() == 2));
    // Without a folder (text), the images are left out, said.
    let text = std::fs::read_to_string(&p).unwrap();
    let t = ldtk::load_str("t.ldtk", &text, None, &LoadOptions::default()).unwrap();
    assert!(t.art.layers.is_empty());
    assert!(t
        .art
        .warnings
        .iter()
        .any(|w| w.contains("no folder to read it from")));
}

/// The byte ranges of the numbers in `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            continue;
        }
        if b[i] == b'-' || b[i].is_ascii_digit() {
            let s = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_digit() || b"+-.eE".contains(&b[i])) {
                i += 1;
            }
            out.push((s, i));
            continue;
        }
        i += 1;
    }
    out
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 128, ..Default::default() })]

    /// Any bytes: a clean error, never a panic.
    #[test]
    fn ldtk_loader_never_panics_on_random_bytes(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..512)) {
        let text = String::from_utf8_lossy(&bytes);
        if let Err(e) = ldtk::load_str("fuzz.ldtk", &text, None, &LoadOptions::default()) {
            proptest::prop_assert!(e.file().starts_with("fuzz.ldtk"));
        }
    }

    /// Any numbers anywhere (extremes, negatives, fractions, huge sizes):
    /// a level or a clean error naming the project, never a panic, and art
    /// that passes its own check.
    #[test]
    fn ldtk_loader_never_panics_on_mutated_numbers(
        edits in proptest::collection::vec((proptest::prelude::any::<usize>(), 0..12usize), 1..6),
    ) {
        const VALUES: [&str; 12] = [
            "-9223372036854775808", "9223372036854775807", "-1", "0", "1", "4097",
            "1e300", "-0.5", "65536", "100000000", "3", "-4096",
        ];
        let dir = tempfile::tempdir().unwrap();
        let atlas = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/testdata/levels/ldtk-samples/atlas/Cavernas_by_Adam_Saltsman.png");
        std::fs::copy(atlas, dir.path().join("atlas.png")).unwrap();
        let mut text = serde_json::to_string(&everything()).unwrap();
        for (at, v) in edits {
            let spans = numbers(&text);
            let (s, e) = spans[at % spans.len()];
            text.replace_range(s..e, VALUES[v]);
        }
        let p = dir.path().join("m.ldtk");
        std::fs::write(&p, &text).unwrap();
        match load_at(&p, None) {
            Ok(l) => proptest::prop_assert!(l.art.check().is_ok()),
            Err(e) => proptest::prop_assert!(e.file().contains("m.ldtk"), "{}", e),
        }
    }
}

#[test]
fn settings_choose_the_collision_layers_and_hidden_layers_do_not_collide() {
    let dir = tempfile::tempdir().unwrap();
    let atlas = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/testdata/levels/ldtk-samples/atlas/Cavernas_by_Adam_Saltsman.png"
    );
    std::fs::copy(atlas, dir.path().join("atlas.png")).unwrap();
    let p = write(dir.path(), "s.ldtk", &everything());
    // A tile layer listed in collision_layers collides, every placed tile
    // solid, on its own grid and offset; the IntGrid layer, not listed,
    // does not.
    std::fs::write(
        dir.path().join("s.ledge.toml"),
        "collision_layers = [\"Tiles\"]\n",
    )
    .unwrap();
    let l = load_at(&p, None).unwrap();
    let map = &l.level.tilemap;
    assert_eq!(
        (map.width(), map.height(), map.tile_size()),
        (16, 12, 8 * UNITS_PER_PX)
    );
    assert_eq!(map.origin(), IVec2::new(4, -4) * UNITS_PER_PX);
    let solid: Vec<IVec2> = (0..12)
        .flat_map(|r| (0..16).map(move |c| IVec2::new(c, r)))
        .filter(|&c| map.tile(c) == Tile::Solid)
        .collect();
    assert_eq!(solid, vec![IVec2::new(1, 1), IVec2::new(15, 11)]);
    // Decoration: the IntGrid layer does not collide.
    std::fs::write(
        dir.path().join("s.ledge.toml"),
        "decoration_layers = [\"Collisions\"]\n",
    )
    .unwrap();
    let l = load_at(&p, None).unwrap();
    assert!(l.level.tilemap.tiles().iter().all(|t| *t == Tile::Empty));
    std::fs::remove_file(dir.path().join("s.ledge.toml")).unwrap();
    // Hidden layers neither collide nor draw, said.
    let hide = |k: usize| {
        let mut v = everything();
        v["levels"][0]["layerInstances"][k]["visible"] = json!(false);
        load_at(&write(dir.path(), "h.ldtk", &v), None).unwrap()
    };
    let l = hide(2);
    assert!(l.level.tilemap.tiles().iter().all(|t| *t == Tile::Empty));
    assert!(
        warned(
            &l,
            "layerInstances[2]: layer \"Collisions\" is hidden: it neither collides nor is drawn"
        ),
        "{:?}",
        l.warnings
    );
    assert!(l.art.layers.iter().all(|a| a.name == "Tiles"));
    let l = hide(0);
    assert!(warned(
        &l,
        "layerInstances[0]: entity layer \"Entities\" is hidden: its 3 entities are ignored"
    ));
    assert!(warned(&l, "no player spawn"));
}
