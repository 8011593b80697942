//! `ledge-level check`, the real binary: what it prints for a level and
//! its exit status for good and refused files.

use std::process::Command;

const FIXTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/levels/tiled/level.tmx"
);

fn check(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ledge-level"))
        .arg("check")
        .args(args)
        .output()
        .expect("ledge-level runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_good_level_is_described_and_exits_zero() {
    let (ok, out, err) = check(&[FIXTURE]);
    assert!(ok, "{out}\n{err}");
    for needle in [
        "level.tmx: ok, level \"level\"",
        "grid: 20 x 10 tiles of 16 px at (0, 0) px",
        "tiles: ",
        "entities: ",
        "spawn: (",
        "layer \"ground\" (layers[0]), tiles: ",
        "settings: none (",
    ] {
        assert!(out.contains(needle), "{needle:?} not in:\n{out}");
    }
}

#[test]
fn a_refused_level_names_the_problem_and_exits_one() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"layers\": [}").unwrap();
    let missing = dir.path().join("missing.tmx");
    let (ok, out, err) = check(&[FIXTURE, bad.to_str().unwrap(), missing.to_str().unwrap()]);
    assert!(!ok);
    assert!(out.contains("level.tmx: ok"), "{out}");
    assert!(
        err.contains("bad.json: line 1 column 13: malformed JSON"),
        "{err}"
    );
    assert!(err.contains("missing.tmx: cannot read the file"), "{err}");
    assert!(err.contains("2 of 3 level file(s) refused"), "{err}");
    // A bad settings file refuses the level it is for.
    let settings = dir.path().join("s.toml");
    std::fs::write(&settings, "colision_layers = []\n").unwrap();
    let (ok, _, err) = check(&["--settings", settings.to_str().unwrap(), FIXTURE]);
    assert!(!ok);
    assert!(err.contains("unknown field `colision_layers`"), "{err}");
}

/// A level of Tiled's own examples (tiled-rs's test assets, in
/// `shared/testdata`) with no collision data: its collision is guessed.
const GUESSED: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../shared/testdata/levels/tiled-rs-tiled/assets/tiled_csv.tmx"
);

/// `check --json`: one document whose fields say what the level became,
/// checked against the same level loaded here.
#[test]
fn check_json_reports_the_level_as_loaded() {
    use ledge_levels::report::WarningKind;
    use ledge_shared::fixed::UNITS_PER_PX;
    use ledge_shared::tilemap::Tile;

    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"layers\": [}").unwrap();
    let mut files = vec![FIXTURE, bad.to_str().unwrap()];
    let guessed = std::path::Path::new(GUESSED).is_file();
    if guessed {
        files.push(GUESSED);
    }
    let mut args = vec!["--json"];
    args.extend(&files);
    let (ok, out, err) = check(&args);
    assert!(!ok, "a refused file exits 1 with --json too");
    let doc: serde_json::Value = serde_json::from_str(&out).expect("stdout is one JSON document");
    assert!(err.is_empty(), "nothing on stderr: {err}");
    let refused = doc["refused"].as_array().unwrap();
    assert_eq!(refused.len(), 1);
    assert_eq!(refused[0]["file"], bad.to_str().unwrap());
    assert!(refused[0]["error"]
        .as_str()
        .unwrap()
        .contains("malformed JSON"));
    let levels = doc["levels"].as_array().unwrap();
    assert_eq!(levels.len(), files.len() - 1);

    for (report, file) in levels.iter().zip([FIXTURE, GUESSED]) {
        let loaded = ledge_levels::load_level(std::path::Path::new(file), None).unwrap();
        let level = &loaded.level;
        let map = &level.tilemap;
        let px = |u: i32| u as f64 / UNITS_PER_PX as f64;
        assert_eq!(report["file"], file);
        assert_eq!(report["level"], level.name.as_str());
        let grid = &report["grid"];
        assert_eq!(grid["width"], map.width());
        assert_eq!(grid["height"], map.height());
        assert_eq!(grid["tile"], px(map.tile_size()));
        assert_eq!(
            grid["origin"],
            serde_json::json!([px(map.origin().x), px(map.origin().y)])
        );
        let (lo, hi) = level.bounds().unwrap();
        assert_eq!(
            report["bounds"],
            serde_json::json!([px(lo.x), px(lo.y), px(hi.x), px(hi.y)])
        );
        assert_eq!(
            report["size"],
            serde_json::json!([px(hi.x - lo.x), px(hi.y - lo.y)])
        );
        // Tiles and entities by kind add up to the level's.
        let count = |t: fn(&Tile) -> bool| map.tiles().iter().filter(|x| t(x)).count() as u64;
        let tiles = &report["tiles"];
        let n = |k: &str| tiles[k].as_u64().unwrap_or(0);
        assert_eq!(n("solid"), count(|t| *t == Tile::Solid));
        assert_eq!(n("one_way"), count(|t| *t == Tile::OneWay));
        assert_eq!(n("hazard"), count(|t| *t == Tile::Hazard));
        assert_eq!(n("slope"), count(|t| matches!(t, Tile::Slope(_))));
        let ents: u64 = report["entities"]
            .as_object()
            .unwrap()
            .values()
            .map(|v| v.as_u64().unwrap())
            .sum();
        assert_eq!(ents, level.entities.len() as u64);
        // Layers in file order, each saying what it became.
        let layers = report["layers"].as_array().unwrap();
        assert_eq!(layers.len(), loaded.layers.len());
        for (j, l) in layers.iter().zip(&loaded.layers) {
            assert_eq!(j["name"], l.name.as_str());
            let became = j["became"].as_str().unwrap();
            assert!(
                ["collision", "off_grid", "entities"].contains(&became),
                "{became}"
            );
            assert_eq!(became == "collision", !l.field.is_empty() && l.on_grid);
        }
        // Spawns: the spawn entities' boxes.
        let spawns: Vec<_> = level
            .entities
            .iter()
            .filter(|e| e.kind == ledge_levels::EntityKind::PlayerSpawn)
            .map(|e| serde_json::json!({"x": px(e.pos.x), "y": px(e.pos.y), "width": px(e.size.x), "height": px(e.size.y)}))
            .collect();
        assert_eq!(report["spawns"], serde_json::json!(spawns));
        // Every warning, with its kind.
        let warnings = report["warnings"].as_array().unwrap();
        assert_eq!(
            warnings.len(),
            loaded.warnings.len() + loaded.art.warnings.len()
        );
        for (w, text) in warnings.iter().zip(loaded.warnings.iter()) {
            assert_eq!(w["text"], text.as_str());
            assert_eq!(w["kind"], WarningKind::of(text).name());
        }
        let kinds: Vec<&str> = warnings
            .iter()
            .map(|w| w["kind"].as_str().unwrap())
            .collect();
        if file == GUESSED {
            assert_eq!(
                kinds[..2],
                ["guessed_collision", "spawn_placed"],
                "{report}"
            );
        } else {
            assert!(!kinds.contains(&"guessed_collision"), "{report}");
        }
    }
}

/// `ledge-level render`: writes the PNG it names, of the size and world box
/// it says; a refused level, or a scale past the bounds, exits 1 saying why.
#[test]
fn render_writes_the_picture_it_describes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("level.png");
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_ledge-level"))
            .arg("render")
            .args(args)
            .output()
            .expect("ledge-level runs");
        (
            o.status.success(),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (ok, stdout, err) = run(&[FIXTURE, "-o", out.to_str().unwrap(), "--scale", "2"]);
    assert!(ok, "{stdout}\n{err}");
    assert!(
        stdout.contains("level.png: 640 x 320 px at scale 2, world (0, 0) to (320, 160) px"),
        "{stdout}"
    );
    let decoder = png::Decoder::new(std::fs::File::open(&out).unwrap());
    let reader = decoder.read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (640, 320));

    let (ok, _, err) = run(&[FIXTURE, "-o", out.to_str().unwrap(), "--scale", "17"]);
    assert!(!ok);
    assert!(
        err.contains("scale 17 is not a number above 0 and at most 16"),
        "{err}"
    );
    let (ok, _, err) = run(&["missing.tmx"]);
    assert!(!ok);
    assert!(err.contains("missing.tmx: cannot read the file"), "{err}");
}
