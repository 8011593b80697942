//! The standing-still check on real levels: a player put at the level's
//! spawn and left alone for two seconds is alive, on the ground, where it
//! was put. A level that fails it plays wrong from the first tick (the
//! player spawned inside a wall and was pushed out, or stands on nothing
//! and falls out), whatever its warnings say.
//!
//! Measured over every real level the tests have (Tiled's examples, the
//! files of `shared/testdata/levels`); the set that passes is pinned, so a
//! level that stops passing (or starts) is noticed.

use std::path::{Path, PathBuf};

use ledge_levels::{load_level, EntityKind, LoadedLevel};
use ledge_shared::level::Level;

use crate::platformer_kit::{Sim, NONE};

/// Two seconds at 60 ticks a second.
const TICKS: usize = 120;

/// Whether a player left alone at `level`'s spawn for two seconds stays
/// alive, grounded, and within a tile of where it was put; `Err` says what
/// happened instead.
pub(crate) fn stands_still(level: &Level) -> Result<(), String> {
    let spawn = level
        .entities
        .iter()
        .find(|e| e.kind == EntityKind::PlayerSpawn)
        .ok_or("no spawn")?;
    let mut sim = Sim::new(level);
    sim.run(NONE, TICKS);
    let v = sim.view();
    let tile = level.tilemap.tile_size().max(16 * 256);
    if v.deaths > 0 {
        return Err(format!("died {} times", v.deaths));
    }
    if !v.grounded {
        return Err(format!(
            "not on the ground at {} (spawn {})",
            v.pos, spawn.pos
        ));
    }
    // Pushed sideways or up (out of a wall) is wrong; settling down onto
    // a floor below a placed spawn is not.
    if (v.pos.x - spawn.pos.x).abs() > tile || v.pos.y < spawn.pos.y - tile {
        return Err(format!("moved from {} to {}", spawn.pos, v.pos));
    }
    Ok(())
}

fn shared() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/testdata/levels")
}

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/level-corpus/tiled-examples")
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out);
        } else if p
            .extension()
            .is_some_and(|x| x == "tmx" || x == "json" || x == "ldtk")
        {
            out.push(p);
        }
    }
}

/// Every real level: (its name for the table, the load path).
fn levels() -> Vec<(String, PathBuf)> {
    let mut files = Vec::new();
    for root in [corpus(), shared()] {
        walk(&root, &mut files);
    }
    files.sort();
    let mut out = Vec::new();
    for f in files {
        let name = f
            .strip_prefix(corpus())
            .or_else(|_| f.strip_prefix(shared()))
            .unwrap()
            .display()
            .to_string();
        if f.extension().is_some_and(|x| x == "ldtk") {
            let Ok(names) = ledge_levels::ldtk::level_names(&f) else {
                continue;
            };
            for n in names {
                let p = PathBuf::from(format!("{}#{n}", f.display()));
                out.push((format!("{name}#{n}"), p));
            }
        } else {
            out.push((name, f));
        }
    }
    out
}

fn check(path: &Path) -> Result<LoadedLevel, String> {
    let l = load_level(path, None).map_err(|e| format!("refused: {e}"))?;
    stands_still(&l.level)?;
    Ok(l)
}

/// The levels that pass (72 of 84; 70 before painted layers, resampled
/// grids and object collision: `ogmo3-sample/levels/uno.json` and
/// `orthogonal-outside.tmx` are new). The others are refused (not
/// orthogonal, not a level) or are not platformer levels (top-down maps,
/// the `tiled` crate's format samples).
const STANDING: &[&str] = &[
    "echo-slopes/slopes.json",
    "ldtk-samples/AutoLayers_1_basic.ldtk#AutoLayer",
    "ldtk-samples/Entities.ldtk#Entities_demo",
    "ldtk-samples/SeparateLevelFiles.ldtk#World_Level_0",
    "ldtk-samples/SeparateLevelFiles.ldtk#World_Level_1",
    "ldtk-samples/SeparateLevelFiles.ldtk#World_Level_2",
    "ldtk-samples/Test_file_for_API_showing_all_features.ldtk#Everything",
    "ldtk-samples/Test_file_for_API_showing_all_features.ldtk#Autolayer",
    "ldtk-samples/Test_file_for_API_showing_all_features.ldtk#Tiles_and_intgrid",
    "ldtk-samples/Test_file_for_API_showing_all_features.ldtk#Background_image",
    "ldtk-samples/Typical_2D_platformer_example.ldtk#Your_typical_2D_platformer",
    "ldtk-samples/Typical_2D_platformer_example.ldtk#Top",
    "ldtk-samples/Typical_2D_platformer_example.ldtk#Bottom",
    "ldtk-samples/Typical_2D_platformer_example.ldtk#World_Level_3",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Entrance",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Cross_roads",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Ossuary",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Water_supply",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Sewers2",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Sewers_trash",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Boss_room",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Large_water",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Shop",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Sewers1",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#The_ponds",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Pit",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#The_tower",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Garden",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#SaveRoom",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Flooded_rooms",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Long_hallway",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Exit",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Hidden_cave",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Shop_entrance",
    "ldtk-samples/WorldMap_GridVania_layout.ldtk#Shortcut_passage",
    "ogmo3-sample/levels/uno.json",
    "tiled-rs-tiled/assets/folder/tiled_relative_paths.tmx",
    "tiled-rs-tiled/assets/ldk_tiled_export.tmx",
    "tiled-rs-tiled/assets/tiled_base64.tmx",
    "tiled-rs-tiled/assets/tiled_base64_external.tmx",
    "tiled-rs-tiled/assets/tiled_base64_gzip.tmx",
    "tiled-rs-tiled/assets/tiled_base64_zlib.tmx",
    "tiled-rs-tiled/assets/tiled_base64_zlib_infinite.tmx",
    "tiled-rs-tiled/assets/tiled_base64_zstandard.tmx",
    "tiled-rs-tiled/assets/tiled_class_property.tmx",
    "tiled-rs-tiled/assets/tiled_csv.tmx",
    "tiled-rs-tiled/assets/tiled_csv_wangsets.tmx",
    "tiled-rs-tiled/assets/tiled_flipped.tmx",
    "tiled-rs-tiled/assets/tiled_group_layers.tmx",
    "tiled-rs-tiled/assets/tiled_object_list_property.tmx",
    "tiled-rs-tiled/assets/tiled_object_nested_list_property.tmx",
    "tiled-rs-tiled/assets/tiled_object_property.tmx",
    "tiled-rs-tiled/assets/tiled_object_template.tmx",
    "tiled-rs-tiled/assets/tiled_parallax.tmx",
    "tiled-rs-tiled/assets/tiled_repeat.tmx",
    "tiled-rs-tiled/assets/tiled_xml.tmx",
    "desert.tmx",
    "orthogonal-outside.tmx",
    "perspective_walls.tmx",
    "sewer_automap/rule_001.tmx",
    "sewer_automap/rule_002.tmx",
    "sewer_automap/rule_003.tmx",
    "sewer_automap/rule_004.tmx",
    "sewer_automap/rule_005.tmx",
    "sewer_automap/rule_006.tmx",
    "sewer_automap/rule_007.tmx",
    "sewer_automap/rule_008.tmx",
    "sewer_automap/rule_009.tmx",
    "sewer_automap/sewers.tmx",
    "sewers.tmx",
    "sticker-knight/map/sandbox.tmx",
    "sticker-knight/map/sandbox2.tmx",
];

#[test]
fn real_levels_that_stand_still() {
    if !corpus().join(".complete").is_file() {
        eprintln!(
            "\n*** SKIPPED: the real-level corpus is missing; run scripts/fetch-level-corpus ***\n"
        );
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("the corpus is required when CI=true");
        }
        return;
    }
    let mut passing = Vec::new();
    let mut report = String::new();
    let all = levels();
    for (name, path) in &all {
        match check(path) {
            Ok(_) => passing.push(name.clone()),
            Err(e) => report.push_str(&format!("  {name}: {e}\n")),
        }
    }
    eprintln!(
        "{} of {} real levels stand still; failing:\n{report}",
        passing.len(),
        all.len()
    );
    eprintln!("passing: {passing:#?}");
    assert_eq!(passing, STANDING);
}
