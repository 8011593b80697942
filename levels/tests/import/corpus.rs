//! Real levels made by others: Tiled 1.8.2's own examples as Debian ships
//! them (`scripts/fetch-level-corpus` unpacks them into
//! `target/level-corpus/tiled-examples`; licences in its `COPYRIGHT.debian`;
//! not committed). Every map loads with no settings file, or is refused
//! with a message that says why; several are checked cell by cell (or
//! object by object) against the file's own data, read independently with
//! the `tiled` crate.
//!
//! Without the corpus the tests print a loud SKIPPED notice and pass,
//! except when `CI=true`, where they fail (`.ci/run` fetches it).

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use glam::IVec2;
use ledge_levels::{load_level, EntityKind, LevelError, LoadOptions, LoadedLevel};
use ledge_shared::game::Game;
use ledge_shared::tilemap::Tile;

fn corpus() -> Option<PathBuf> {
    let dir = std::env::var_os("LEDGE_LEVEL_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/level-corpus/tiled-examples")
        });
    if dir.join(".complete").is_file() {
        return Some(dir);
    }
    let msg = format!(
        "SKIPPED: the real-level corpus is missing at {}; run scripts/fetch-level-corpus",
        dir.display()
    );
    if std::env::var("CI").as_deref() == Ok("true") {
        panic!("{msg} (required when CI=true)");
    }
    eprintln!("\n*** {msg} ***\n");
    None
}

/// What each map of the corpus becomes.
enum Expect {
    /// Loads (and builds a game).
    Loads,
    /// Refused; the message contains this.
    Refused(&'static str),
}

const NOT_ORTHOGONAL: Expect =
    Expect::Refused("maps are not supported: ledge levels are orthogonal (side view)");

const CORPUS: &[(&str, Expect)] = &[
    ("desert.tmx", Expect::Loads),
    ("hexagonal-mini.tmx", NOT_ORTHOGONAL),
    ("isometric_grass_and_water.tmx", NOT_ORTHOGONAL),
    ("isometric_staggered_grass_and_water.tmx", NOT_ORTHOGONAL),
    ("orthogonal-outside.tmx", Expect::Loads),
    ("perspective_walls.tmx", Expect::Loads),
    ("rpg/island.tmx", Expect::Loads),
    ("sewer_automap/rule_001.tmx", Expect::Loads),
    ("sewer_automap/rule_002.tmx", Expect::Loads),
    ("sewer_automap/rule_003.tmx", Expect::Loads),
    ("sewer_automap/rule_004.tmx", Expect::Loads),
    ("sewer_automap/rule_005.tmx", Expect::Loads),
    ("sewer_automap/rule_006.tmx", Expect::Loads),
    ("sewer_automap/rule_007.tmx", Expect::Loads),
    ("sewer_automap/rule_008.tmx", Expect::Loads),
    ("sewer_automap/rule_009.tmx", Expect::Loads),
    ("sewer_automap/sewers.tmx", Expect::Loads),
    ("sewers.tmx", Expect::Loads),
    ("sticker-knight/map/sandbox.tmx", Expect::Loads),
    ("sticker-knight/map/sandbox2.tmx", Expect::Loads),
    ("test_hexagonal_tile_60x60x30.tmx", NOT_ORTHOGONAL),
];

/// Runs `f` with a panic hook that records any panic (caught or not).
fn no_panics<T>(f: impl FnOnce() -> T) -> T {
    let seen = Arc::new(Mutex::new(Vec::<String>::new()));
    let s = seen.clone();
    let me = std::thread::current().id();
    let old = std::panic::take_hook();
    // The hook is global: record only this thread's panics (tests run in
    // parallel).
    std::panic::set_hook(Box::new(move |info| {
        if std::thread::current().id() == me {
            s.lock().unwrap().push(info.to_string());
        }
    }));
    let out = f();
    std::panic::set_hook(old);
    let seen = seen.lock().unwrap();
    assert!(seen.is_empty(), "panics while loading: {seen:?}");
    out
}

fn load(dir: &Path, name: &str) -> Result<LoadedLevel, LevelError> {
    load_level(&dir.join(name), None)
}

#[test]
fn every_map_loads_or_is_refused_with_a_reason() {
    let Some(dir) = corpus() else { return };
    // The table covers the whole corpus: a new file is noticed.
    let mut found: Vec<String> = walk(&dir)
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "tmx"))
        .map(|p| p.strip_prefix(&dir).unwrap().display().to_string())
        .collect();
    found.sort();
    let mut listed: Vec<String> = CORPUS.iter().map(|(n, _)| n.to_string()).collect();
    listed.sort();
    assert_eq!(found, listed);
    let mut loaded = 0;
    for (name, expect) in CORPUS {
        let r = no_panics(|| load(&dir, name));
        match (expect, r) {
            (Expect::Loads, Ok(l)) => {
                Game::from_level(&l.level).unwrap_or_else(|e| panic!("{name}: {e}"));
                // Every warning names the file and says something.
                for w in &l.warnings {
                    assert!(w.starts_with(&dir.join(name).display().to_string()), "{w}");
                }
                loaded += 1;
            }
            (Expect::Refused(why), Err(e)) => {
                let msg = e.to_string();
                assert!(msg.contains(why), "{name}: {msg}");
                assert!(
                    msg.starts_with(&dir.join(name).display().to_string()),
                    "{msg}"
                );
            }
            (Expect::Loads, Err(e)) => panic!("{name} should load: {e}"),
            (Expect::Refused(why), Ok(_)) => panic!("{name} should be refused ({why})"),
        }
    }
    assert_eq!(loaded, 17);
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

/// The map as the `tiled` crate reads it, for the checks: old tilesets
/// without `tilecount` and images without a size (which the crate
/// requires) get made-up ones, enough to tell which cells hold a tile.
fn oracle(path: &Path) -> tiled::Map {
    struct Reader;
    impl tiled::ResourceReader for Reader {
        type Resource = std::io::Cursor<Vec<u8>>;
        type Error = std::io::Error;
        fn read_from(&mut self, path: &Path) -> Result<Self::Resource, Self::Error> {
            let text = std::fs::read_to_string(path)?;
            let text = text
                .split("<image ")
                .enumerate()
                .map(|(i, part)| {
                    let head = part.split('>').next().unwrap_or("");
                    if i > 0 && !head.contains("width=") {
                        format!("width=\"64\" height=\"64\" {part}")
                    } else {
                        part.to_owned()
                    }
                })
                .collect::<Vec<_>>()
                .join("<image ");
            let patched = text
                .split("<tileset ")
                .enumerate()
                .map(|(i, part)| {
                    let head = part.split('>').next().unwrap_or("");
                    if i > 0 && !head.contains("tilecount") && !head.contains("source=") {
                        format!("tilecount=\"100000\" {part}")
                    } else {
                        part.to_owned()
                    }
                })
                .collect::<Vec<_>>()
                .join("<tileset ");
            Ok(std::io::Cursor::new(patched.into_bytes()))
        }
    }
    tiled::Loader::<tiled::DefaultResourceCache, _>::with_reader(Reader)
        .load_tmx_map(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Whether the level collides anywhere inside the cell `(c, r)` of `t`
/// pixel cells: its tile, or a static block or polygon overlapping the
/// cell's interior.
fn collides_in(l: &LoadedLevel, c: i32, r: i32, t: i32) -> bool {
    let u = 256;
    if l.level.tilemap.width() > 0 && l.level.tilemap.tile(IVec2::new(c, r)) != Tile::Empty {
        return true;
    }
    let (lo, hi) = (IVec2::new(c, r) * t * u, IVec2::new(c + 1, r + 1) * t * u);
    l.level.entities.iter().any(|e| match &e.kind {
        EntityKind::Block | EntityKind::PolygonBlock { .. } => {
            let (a, b) = (e.pos - e.size / 2, e.pos + e.size / 2);
            a.x < hi.x - u && b.x > lo.x + u && a.y < hi.y - u && b.y > lo.y + u
        }
        _ => false,
    })
}

/// The background tiles `(layer, tile id)` of the layers of `names` that
/// are painted edge to edge (at least 9 cells in 10 hold a tile): the most
/// common tile, and the tiles under the level's entities other than solid
/// ones and hazards (the importer's evidence, `collision::infer`).
fn painted_background(
    map: &tiled::Map,
    l: &LoadedLevel,
    names: &[&str],
) -> std::collections::BTreeSet<(String, u32)> {
    let mut out = std::collections::BTreeSet::new();
    let t = map.tile_width as i32 * 256;
    for layer in map.layers().filter(|x| names.contains(&x.name.as_str())) {
        let Some(tl) = layer.as_tile_layer() else {
            continue;
        };
        let mut counts = std::collections::BTreeMap::<u32, usize>::new();
        for r in 0..map.height as i32 {
            for c in 0..map.width as i32 {
                if let Some(tile) = tl.get_tile(c, r) {
                    *counts.entry(tile.id()).or_default() += 1;
                }
            }
        }
        let placed: usize = counts.values().sum();
        if placed * 10 < (map.width * map.height) as usize * 9 {
            continue;
        }
        let most = counts
            .iter()
            .max_by_key(|(id, n)| (**n, std::cmp::Reverse(**id)));
        out.insert((layer.name.clone(), *most.unwrap().0));
        for e in &l.level.entities {
            if matches!(
                e.kind,
                EntityKind::Block | EntityKind::PolygonBlock { .. } | EntityKind::Hazard
            ) {
                continue;
            }
            let (lo, hi) = ((e.pos - e.size / 2 + 1) / t, (e.pos + e.size / 2 - 1) / t);
            for r in lo.y..=hi.y {
                for c in lo.x..=hi.x {
                    if let Some(tile) = tl.get_tile(c, r) {
                        out.insert((layer.name.clone(), tile.id()));
                    }
                }
            }
        }
    }
    out
}

/// Maps with no collision data of their own: the layers named like
/// collision layers collide (every tile), the others are decoration (or,
/// with no such layer, every visible layer collides), and the importer
/// says so; a layer painted edge to edge has its background tiles empty
/// (the most common one and those under the spawn and entities), said.
/// Checked cell by cell against the layers' own cells.
#[test]
fn maps_without_collision_data_collide_their_collision_named_layers() {
    let Some(dir) = corpus() else { return };
    // The maps whose collision layer is painted edge to edge.
    let painted = ["rpg/island.tmx", "orthogonal-outside.tmx", "desert.tmx"];
    // (map, the layers that collide, whether by their names)
    for (name, solid_layers, by_name) in [
        ("rpg/island.tmx", &["Ground"][..], true),
        ("orthogonal-outside.tmx", &["Ground"][..], true),
        (
            "perspective_walls.tmx",
            &["Walls", "Walls level 2", "Walls level 3"][..],
            true,
        ),
        ("sewer_automap/rule_004.tmx", &["Output_Ground"][..], true),
        ("desert.tmx", &["Ground"][..], true),
    ] {
        let lenient = LoadOptions {
            require_spawn: false,
            ..LoadOptions::default()
        };
        let l = ledge_levels::load_file_with(dir.join(name), &lenient).unwrap();
        let said = if by_name {
            "named like collision layers"
        } else {
            "every tile of every visible tile layer is solid"
        };
        assert!(
            l.warnings
                .iter()
                .any(|w| w.contains("the map has no collision data") && w.contains(said)),
            "{name}: {:?}",
            l.warnings
        );
        let map = oracle(&dir.join(name));
        let t = map.tile_width as i32;
        let background = painted_background(&map, &l, solid_layers);
        assert_eq!(
            !background.is_empty(),
            painted.contains(&name),
            "{name}: painted edge to edge: {background:?}"
        );
        assert_eq!(
            l.warnings
                .iter()
                .any(|w| w.contains("painted edge to edge") && w.contains("[tiles.")),
            !background.is_empty(),
            "{name}: {:?}",
            l.warnings
        );
        let mut solid = 0;
        for r in 0..map.height as i32 {
            for c in 0..map.width as i32 {
                let want = map.layers().any(|layer| {
                    solid_layers.contains(&layer.name.as_str())
                        && layer.as_tile_layer().is_some_and(|tl| {
                            tl.get_tile(c, r).is_some_and(|tile| {
                                !background.contains(&(layer.name.clone(), tile.id()))
                            })
                        })
                });
                let got = collides_in(&l, c, r, t);
                assert_eq!(got, want, "{name}: cell ({c}, {r})");
                solid += want as usize;
            }
        }
        assert!(solid > 0, "{name}");
    }
}

/// Sticker Knight (a platformer example, public domain): its ground and
/// walls are tile objects and rectangles marked `bodyType = static`
/// (Box2D style), its crates objects named "block". Each visible one
/// becomes solid geometry over its box, nothing else is solid, and the
/// hidden `bounds` layer's objects are ignored and said so.
#[test]
fn sticker_knight_collides_where_its_static_bodies_are() {
    let Some(dir) = corpus() else { return };
    for name in [
        "sticker-knight/map/sandbox.tmx",
        "sticker-knight/map/sandbox2.tmx",
    ] {
        let l = load(&dir, name).unwrap();
        let map = oracle(&dir.join(name));
        // Every static body's box (tile objects stand on their bottom-left
        // corner), in units, and whether its layer is visible.
        let mut statics = Vec::new();
        for layer in map.layers() {
            let Some(ol) = layer.as_object_layer() else {
                continue;
            };
            for o in ol.objects() {
                // Static bodies, and the objects named "block" (Sticker
                // Knight's pushable crates: ledge's blocks are static).
                let body = o.properties.get("bodyType");
                if !matches!(body, Some(tiled::PropertyValue::StringValue(s)) if s == "static")
                    && o.name != "block"
                {
                    continue;
                }
                let tiled::ObjectShape::Rect { width, height } = o.shape else {
                    continue;
                };
                assert_eq!(
                    o.rotation, 0.0,
                    "{name}: the check assumes unrotated bodies"
                );
                let top = if o.get_tile().is_some() {
                    o.y - height
                } else {
                    o.y
                };
                let lo = IVec2::new((o.x * 256.0) as i32, (top * 256.0) as i32);
                let hi = lo + IVec2::new((width * 256.0) as i32, (height * 256.0) as i32);
                statics.push((lo, hi, layer.visible));
            }
        }
        let visible = statics.iter().filter(|s| s.2).count();
        assert!(visible >= 10, "{name}: {visible} static bodies");
        let blocks: Vec<_> = l
            .level
            .entities
            .iter()
            .filter(|e| matches!(e.kind, EntityKind::Block | EntityKind::PolygonBlock { .. }))
            .collect();
        let near = |a: IVec2, b: IVec2| (a - b).abs().max_element() <= 256;
        // Each visible static body is exactly one block over its box.
        for (lo, hi, _) in statics.iter().filter(|s| s.2) {
            let centre = (*lo + *hi) / 2;
            assert!(
                blocks.iter().any(|e| e.kind == EntityKind::Block
                    && near(e.pos, centre)
                    && near(e.size, *hi - *lo)),
                "{name}: no block over the static body at {lo} .. {hi} units"
            );
        }
        // Nothing else is solid; the hidden bounds are not.
        assert_eq!(blocks.len(), visible, "{name}");
        for (lo, hi, _) in statics.iter().filter(|s| !s.2) {
            let centre = (*lo + *hi) / 2;
            assert!(
                !blocks.iter().any(|e| {
                    let (a, b) = (e.pos - e.size / 2, e.pos + e.size / 2);
                    a.x <= centre.x && centre.x <= b.x && a.y <= centre.y && centre.y <= b.y
                }),
                "{name}: a hidden body at {centre} collides"
            );
        }
        assert!(
            l.warnings
                .iter()
                .any(|w| w.contains("layer \"bounds\"") && w.contains("hidden object layer")),
            "{name}: {:?}",
            l.warnings
        );
        // The art draws the static bodies' pictures, not the coins' or the
        // enemy's (the game draws them: a collected coin vanishes, a walker
        // walks): one art object per visible tile object of another kind.
        let coins = l
            .level
            .entities
            .iter()
            .filter(|e| e.kind == EntityKind::Coin)
            .count();
        assert!(coins > 0, "{name}");
        let drawn: usize = l
            .art
            .layers
            .iter()
            .map(|layer| match &layer.content {
                ledge_levels::art::ArtContent::Objects(o) => o.len(),
                _ => 0,
            })
            .sum();
        let mut tile_objects = 0;
        for layer in map.layers().filter(|l| l.visible) {
            if let Some(ol) = layer.as_object_layer() {
                tile_objects += ol
                    .objects()
                    .filter(|o| {
                        o.visible
                            && o.get_tile().is_some()
                            && !["coin", "enemy"].contains(&o.user_type.as_str())
                    })
                    .count();
            }
        }
        assert_eq!(drawn, tile_objects, "{name}");
    }
}

/// The OGMO Editor 3 projects of `shared/testdata/levels` (beside the
/// repository; real files from two other projects, licences there) load
/// with no settings file and say what they did not use or guessed: the
/// echo slopes level (one tile layer of a foreign tileset, no grid layer,
/// no entities) collides every tile, said (`levels/tests/import/level_ogmo.rs`
/// loads it with its tile table, slopes and all).
#[test]
fn ogmo_files_load_with_no_settings_and_say_what_they_skipped() {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/testdata/levels");
    let l = no_panics(|| load_level(&shared.join("echo-slopes/slopes.json"), None)).unwrap();
    assert!(
        l.warnings.iter().any(|w| w.contains("no collision data")
            && w.contains("every tile of every tile layer is solid")),
        "{:?}",
        l.warnings
    );
    // Solid exactly where the file has a tile.
    let text = std::fs::read_to_string(shared.join("echo-slopes/slopes.json")).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    let data = doc["layers"][0]["data"]
        .as_array()
        .expect("a 1D tile layer");
    let tiles = l.level.tilemap.tiles();
    assert_eq!(tiles.len(), data.len());
    for (i, (t, d)) in tiles.iter().zip(data).enumerate() {
        assert_eq!(*t == Tile::Solid, d.as_i64().unwrap() >= 0, "cell {i}");
    }
    let file = "ogmo3-sample/levels/uno.json";
    let l = no_panics(|| load_level(&shared.join(file), None))
        .unwrap_or_else(|e| panic!("{file}: {e}"));
    Game::from_level(&l.level).unwrap();
    for said in [
        "tile layer \"tile_1D\" does not collide",
        "no player spawn: players start at",
    ] {
        assert!(
            l.warnings.iter().any(|w| w.contains(said)),
            "{said:?} not in {:?}",
            l.warnings
        );
    }
}

/// Sticker Knight's `hero` (a 128 x 160 px tile object from a template) is
/// the spawn, and the player has its size: scale 10 (160 px over ledge's
/// 16 px), so its jump is ten times ledge's, as its blocks are.
#[test]
fn sticker_knights_player_is_its_hero() {
    let Some(dir) = corpus() else { return };
    for (map, foot) in [("sandbox.tmx", (109, 979)), ("sandbox2.tmx", (352, 448))] {
        let l = load(&dir, &format!("sticker-knight/map/{map}")).unwrap();
        let spawns: Vec<_> = l
            .level
            .entities
            .iter()
            .filter(|e| e.kind == EntityKind::PlayerSpawn)
            .collect();
        assert_eq!(spawns.len(), 1, "{map}");
        let s = spawns[0];
        let px = |u: i32| u / 256;
        assert_eq!(
            (px(s.pos.x), px(s.pos.y + s.size.y / 2)),
            foot,
            "{map}: the hero's bottom centre"
        );
        assert!(
            !l.warnings.iter().any(|w| w.contains("no player spawn")),
            "{map}"
        );
        assert_eq!(l.level.player.scale, 10 * 256, "{map}");
        let config = ledge_shared::game::GameConfig::default()
            .for_level(&l.level)
            .unwrap();
        assert_eq!(config.player.half, IVec2::new(64, 80) * 256, "{map}");
        let game = Game::from_level(&l.level).unwrap();
        assert_eq!(game.config().player.half, IVec2::new(64, 80) * 256);
    }
}
