//! LDtk projects: LDtk 1.5.3's own samples in `shared/testdata` (every
//! level of every project loads, through `ldtk::level_names`), collision
//! checked cell by cell against the files read independently with
//! `serde_json::Value`, entities, art, and a player standing at each
//! platformer level's spawn for two seconds.

use std::path::{Path, PathBuf};

use crate::platformer_kit::{Sim, NONE};
use ledge_levels::art::ArtContent;
use ledge_levels::{ldtk, load_level, EntityKind, LoadedLevel};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::tilemap::Tile;
use serde_json::Value;

const SAMPLES: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../shared/testdata/levels/ldtk-samples"
);
const PLATFORMER: &str = "Typical_2D_platformer_example.ldtk";

fn sample(name: &str) -> PathBuf {
    Path::new(SAMPLES).join(name)
}

fn at(project: &str, level: &str) -> PathBuf {
    PathBuf::from(format!("{}#{level}", sample(project).display()))
}

fn load(project: &str, level: &str) -> LoadedLevel {
    load_level(&at(project, level), None).unwrap_or_else(|e| panic!("{project}#{level}: {e}"))
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn every_level_of_every_sample_loads() {
    let expected: &[(&str, &[&str])] = &[
        ("AutoLayers_1_basic.ldtk", &["AutoLayer"]),
        ("Entities.ldtk", &["Entities_demo"]),
        (
            "SeparateLevelFiles.ldtk",
            &["World_Level_0", "World_Level_1", "World_Level_2"],
        ),
        (
            "Test_file_for_API_showing_all_features.ldtk",
            &[
                "Everything",
                "Autolayer",
                "Tiles_and_intgrid",
                "Background_image",
            ],
        ),
        (
            PLATFORMER,
            &[
                "Your_typical_2D_platformer",
                "Top",
                "Bottom",
                "World_Level_3",
            ],
        ),
    ];
    for (project, levels) in expected {
        assert_eq!(&ldtk::level_names(sample(project)).unwrap(), levels);
    }
    // Every .ldtk in the folder is covered, GridVania's 21 levels too.
    let mut all = 0;
    for entry in std::fs::read_dir(SAMPLES).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "ldtk") {
            continue;
        }
        let paths = ldtk::level_paths(&path).unwrap();
        let names = ldtk::level_names(&path).unwrap();
        assert_eq!(paths.len(), names.len());
        for (p, name) in paths.iter().zip(&names) {
            let loaded = load_level(p, None).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            assert_eq!(&loaded.level.name, name);
            assert!(
                loaded
                    .level
                    .tilemap
                    .tiles()
                    .iter()
                    .any(|t| *t != Tile::Empty),
                "{name}"
            );
            let spawns = loaded
                .level
                .entities
                .iter()
                .filter(|e| e.kind == EntityKind::PlayerSpawn);
            assert_eq!(spawns.count(), 1, "{name}");
            loaded.art.check().unwrap();
            all += 1;
        }
    }
    assert_eq!(all, 1 + 1 + 3 + 4 + 4 + 21);
    assert_eq!(
        ldtk::level_names(sample("WorldMap_GridVania_layout.ldtk")).unwrap()[..3],
        ["Entrance", "Cross_roads", "Ossuary"]
    );
    // Without '#', the first level.
    let first = load_level(&sample(PLATFORMER), None).unwrap();
    assert_eq!(first.level.name, "Your_typical_2D_platformer");
}

#[test]
fn separate_level_files_are_read_from_their_ldtkl() {
    for (i, name) in ["World_Level_0", "World_Level_1", "World_Level_2"]
        .iter()
        .enumerate()
    {
        let loaded = load("SeparateLevelFiles.ldtk", name);
        // The project has no layers for them: they came from the .ldtkl.
        let project = json(&sample("SeparateLevelFiles.ldtk"));
        assert!(project["levels"][i]["layerInstances"].is_null());
        let file = sample(&format!("SeparateLevelFiles/{name}.ldtkl"));
        let csv = &json(&file)["layerInstances"][0]["intGridCsv"];
        let solid = csv
            .as_array()
            .unwrap()
            .iter()
            .filter(|v| v.as_i64() == Some(1))
            .count();
        let map = &loaded.level.tilemap;
        assert_eq!((map.width(), map.height()), (15, 15));
        assert_eq!(
            map.tiles().iter().filter(|t| **t == Tile::Solid).count(),
            solid
        );
        assert!(solid > 0);
        // Its warnings name the level's own file.
        assert!(
            loaded
                .warnings
                .iter()
                .any(|w| w.contains(&format!("{name}.ldtkl: no player spawn"))),
            "{:?}",
            loaded.warnings
        );
    }
}

/// The tile each IntGrid value of the sample files stands for, by its
/// identifier as the files name them.
fn expected_tile(identifier: Option<&str>) -> Tile {
    match identifier {
        Some("walls" | "dirt" | "stone") => Tile::Solid,
        Some("ladder" | "water") => Tile::Empty,
        other => panic!("no expectation for IntGrid value {other:?}"),
    }
}

/// Checks `level`'s collision grid against the IntGrid layer `layer` of
/// level `index` of `project`, read with `serde_json` (from the level's
/// own file when it has one).
fn check_cells(project: &str, index: usize, layer: &str) {
    let root = json(&sample(project));
    let entry = &root["levels"][index];
    let name = entry["identifier"].as_str().unwrap();
    let level = match entry["externalRelPath"].as_str() {
        Some(rel) => json(&sample(rel)),
        None => entry.clone(),
    };
    let li = level["layerInstances"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["__identifier"] == layer)
        .unwrap();
    let def = root["defs"]["layers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["uid"] == li["layerDefUid"])
        .unwrap();
    let (w, h) = (
        li["__cWid"].as_u64().unwrap(),
        li["__cHei"].as_u64().unwrap(),
    );
    let grid = li["__gridSize"].as_i64().unwrap() as i32;
    let csv = li["intGridCsv"].as_array().unwrap();
    assert_eq!(csv.len() as u64, w * h);
    let loaded = load(project, name);
    let map = &loaded.level.tilemap;
    assert_eq!((map.width() as u64, map.height() as u64), (w, h), "{name}");
    assert_eq!(map.tile_size(), grid * UNITS_PER_PX, "{name}");
    let mut counts = [0usize; 2];
    for (i, v) in csv.iter().enumerate() {
        let v = v.as_i64().unwrap();
        let want = if v == 0 {
            Tile::Empty
        } else {
            let ident = def["intGridValues"]
                .as_array()
                .unwrap()
                .iter()
                .find(|d| d["value"] == v)
                .and_then(|d| d["identifier"].as_str());
            expected_tile(ident)
        };
        let (c, r) = ((i as u64 % w) as i32, (i as u64 / w) as i32);
        assert_eq!(
            map.tile(glam::IVec2::new(c, r)),
            want,
            "{name}: cell ({c}, {r})"
        );
        counts[(want == Tile::Solid) as usize] += 1;
    }
    assert!(counts[0] > 0 && counts[1] > 0, "{name}: {counts:?}");
}

#[test]
fn collision_matches_the_files_cell_by_cell() {
    for i in 0..4 {
        check_cells(PLATFORMER, i, "Collisions");
    }
    for i in [0, 3, 5] {
        // Entrance, Water_supply (water), Sewers_trash.
        check_cells("WorldMap_GridVania_layout.ldtk", i, "Collisions");
    }
    check_cells("AutoLayers_1_basic.ldtk", 0, "IntGrid_layer");
    check_cells("Entities.ldtk", 0, "Collisions");
    check_cells("SeparateLevelFiles.ldtk", 1, "IntGrid");
}

#[test]
fn refused_values_are_warned_with_the_value_named() {
    let loaded = load(PLATFORMER, "Your_typical_2D_platformer");
    let w = loaded
        .warnings
        .iter()
        .find(|w| w.contains("IntGrid value 2 \"ladder\""))
        .unwrap_or_else(|| panic!("{:?}", loaded.warnings));
    assert!(
        w.contains("layer \"Collisions\" (21 cells) is not supported in ledge"),
        "{w}"
    );
    assert!(w.contains("read as empty"), "{w}");
    let water = load("WorldMap_GridVania_layout.ldtk", "Water_supply");
    assert!(
        water
            .warnings
            .iter()
            .any(|w| w.contains("IntGrid value 2 \"water\"") && w.contains("read as empty")),
        "{:?}",
        water.warnings
    );
    // An unnamed value is solid, said.
    let t = load("Test_file_for_API_showing_all_features.ldtk", "Everything");
    assert!(
        t.warnings.iter().any(|w| w.contains("IntGrid value 1 of layer \"IntGrid_8px_grid\" (60 cells) has no identifier: read as solid")),
        "{:?}",
        t.warnings
    );
    // The 16 px layers do not line up with that 8 px grid: skipped, said.
    assert!(t
        .warnings
        .iter()
        .any(|w| w
            .contains("layerInstances[4]: this collision layer of 43 x 36 cells of 16 x 16 px")));
    assert_eq!(t.level.tilemap.tile_size(), 8 * UNITS_PER_PX);
}

#[test]
fn platformer_entities_become_ledge_entities() {
    let loaded = load(PLATFORMER, "Your_typical_2D_platformer");
    let kinds =
        |k: fn(&EntityKind) -> bool| loaded.level.entities.iter().filter(|e| k(&e.kind)).count();
    assert_eq!(kinds(|k| *k == EntityKind::PlayerSpawn), 1);
    assert_eq!(kinds(|k| matches!(k, EntityKind::Walker { .. })), 3);
    assert_eq!(kinds(|k| *k == EntityKind::Goal), 2);
    // Player: px [184, 208], pivot (0.5, 1), 24 x 24: centre (184, 196).
    let spawn = loaded
        .level
        .entities
        .iter()
        .find(|e| e.kind == EntityKind::PlayerSpawn)
        .unwrap();
    assert_eq!(spawn.pos, glam::IVec2::new(184, 196) * UNITS_PER_PX);
    assert_eq!(spawn.size, glam::IVec2::splat(24 * UNITS_PER_PX));
    for needle in [
        "skipped unknown entity \"Chest\" in layer \"Entities\"",
        "the patrol points of 3 \"Mob\" entities in layer \"Entities\" are not used",
    ] {
        assert!(
            loaded.warnings.iter().any(|w| w.contains(needle)),
            "{needle}: {:?}",
            loaded.warnings
        );
    }
    // Entities.ldtk: PlayerStart, Enemy (walkers), Door and Exit (goals).
    let e = load("Entities.ldtk", "Entities_demo");
    let count = |k: &EntityKind| e.level.entities.iter().filter(|x| &x.kind == k).count();
    assert_eq!(count(&EntityKind::Goal), 5);
    assert_eq!(count(&EntityKind::PlayerSpawn), 1);
}

#[test]
fn tile_layers_and_auto_layers_are_drawn_with_their_tileset() {
    let loaded = load(PLATFORMER, "Your_typical_2D_platformer");
    let art = &loaded.art;
    art.check().unwrap();
    assert_eq!(art.images.len(), 1);
    assert_eq!(
        art.images[0].name,
        "atlas/SunnyLand_by_Ansimuz-extended.png"
    );
    assert_eq!((art.images[0].width, art.images[0].height), (368, 336));
    let root = json(&sample(PLATFORMER));
    let bg = root["levels"][0]["__bgColor"].as_str().unwrap();
    let byte = |i: usize| u8::from_str_radix(&bg[i..i + 2], 16).unwrap();
    assert_eq!(art.background, Some([byte(1), byte(3), byte(5), 255]));
    assert_eq!(art.size, (848.0, 336.0));
    // Back to front: Bg_textures, Collisions, Wall_shadows (LDtk lists the
    // top one first), a layer split where tiles stack in a cell.
    let names: Vec<&str> = art.layers.iter().map(|l| l.name.as_str()).collect();
    let first = |n: &str| names.iter().position(|x| *x == n).unwrap();
    assert!(first("Bg_textures") < first("Collisions"));
    assert!(first("Collisions") < first("Wall_shadows"));
    // Every tile the file places is drawn once, at its cell, with its
    // flips, from the tile its `src` names.
    let lis = root["levels"][0]["layerInstances"].as_array().unwrap();
    let mut want = 0;
    for li in lis {
        let tiles = li["autoLayerTiles"].as_array().unwrap();
        want += tiles.len();
        let layers: Vec<_> = art
            .layers
            .iter()
            .filter(|l| l.name == li["__identifier"])
            .collect();
        for t in tiles {
            let (px, py) = (t["px"][0].as_i64().unwrap(), t["px"][1].as_i64().unwrap());
            let (sx, sy) = (
                t["src"][0].as_u64().unwrap() as u32,
                t["src"][1].as_u64().unwrap() as u32,
            );
            let f = t["f"].as_i64().unwrap();
            let found = layers.iter().any(|l| {
                let ArtContent::Tiles(g) = &l.content else {
                    return false;
                };
                let (ox, oy) = (l.offset.0 as i64, l.offset.1 as i64);
                let (cx, cy) = ((px - ox) / 16, (py - oy) / 16);
                (px - ox) % 16 == 0
                    && (py - oy) % 16 == 0
                    && g.get(cx as u32, cy as u32).is_some_and(|c| {
                        let s = art.source(c.tileset, c.tile).unwrap();
                        (s.x, s.y) == (sx, sy)
                            && c.flip_h == (f & 1 != 0)
                            && c.flip_v == (f & 2 != 0)
                    })
            });
            assert!(found, "{}: tile at {px},{py}", li["__identifier"]);
        }
    }
    let drawn: usize = art
        .layers
        .iter()
        .map(|l| match &l.content {
            ArtContent::Tiles(g) => g.cells.iter().flatten().count(),
            _ => 0,
        })
        .sum();
    assert_eq!(drawn, want);
    // Layer opacity: Wall_shadows is drawn at 0.17.
    assert!(art
        .layers
        .iter()
        .filter(|l| l.name == "Wall_shadows")
        .all(|l| (l.opacity - 0.17).abs() < 1e-6));
}

#[test]
fn a_missing_background_image_is_a_warning() {
    let loaded = load(
        "Test_file_for_API_showing_all_features.ldtk",
        "Background_image",
    );
    assert!(
        loaded.art.warnings.iter().any(|w| w.contains("bgRelPath")
            && w.contains("Beach by deepnight.png: cannot read the file")),
        "{:?}",
        loaded.art.warnings
    );
    assert!(!loaded.art.layers.is_empty(), "the tiles are still drawn");
}

#[test]
fn a_player_stands_still_at_each_platformer_levels_spawn() {
    for name in ldtk::level_names(sample(PLATFORMER)).unwrap() {
        let loaded = load(PLATFORMER, &name);
        let spawn = loaded
            .level
            .entities
            .iter()
            .find(|e| e.kind == EntityKind::PlayerSpawn)
            .unwrap();
        let foot = spawn.pos.y + spawn.size.y / 2;
        let mut sim = Sim::new(&loaded.level);
        sim.run(NONE, 120);
        let v = sim.view();
        assert!(v.grounded, "{name}: {v:?}");
        assert_eq!(v.dead, None, "{name}: {v:?}");
        assert_eq!(v.pos.x, spawn.pos.x, "{name}: it stays where it was put");
        assert_eq!(sim.bottom(), foot, "{name}: on the ground under the spawn");
        // That ground is a solid tile of the file's grid.
        let map = &loaded.level.tilemap;
        let cell = (v.pos - map.origin()) / map.tile_size();
        let below = glam::IVec2::new(cell.x, (sim.bottom() - map.origin().y) / map.tile_size());
        assert_eq!(map.tile(below), Tile::Solid, "{name}");
    }
}
