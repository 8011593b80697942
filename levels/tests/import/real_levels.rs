//! Real levels play as their authors made them (issue 33): spawns under
//! the names other games give them, the player scaled to the level, and
//! turned hazards and triggers. Small maps written here, one per editor.

use glam::IVec2;
use ledge_levels::{ldtk, ogmo, tmx, EntityKind, LoadOptions, LoadedLevel};
use ledge_shared::fixed::px;
use serde_json::json;

/// A Tiled map of `w` x `h` tiles of `tile` px, a solid floor on its last
/// row, and `objects` (XML) in an object layer.
fn tiled(tile: u32, w: u32, h: u32, objects: &str) -> String {
    let cells: Vec<&str> = (0..w * h)
        .map(|i| if i / w == h - 1 { "1" } else { "0" })
        .collect();
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<map version="1.10" orientation="orthogonal" renderorder="right-down" width="{w}" height="{h}" tilewidth="{tile}" tileheight="{tile}" infinite="0">
 <tileset firstgid="1" name="t" tilewidth="{tile}" tileheight="{tile}" tilecount="1" columns="1">
  <image source="t.png" width="{tile}" height="{tile}"/>
 </tileset>
 <layer id="1" name="ground" width="{w}" height="{h}">
  <properties><property name="solid" type="bool" value="true"/></properties>
  <data encoding="csv">{}</data>
 </layer>
 <objectgroup id="2" name="things">
{objects}
 </objectgroup>
</map>"#,
        cells.join(",")
    )
}

fn load_tiled(text: &str) -> LoadedLevel {
    tmx::load_str("t.tmx", text, &LoadOptions::default()).unwrap()
}

fn spawns(l: &LoadedLevel) -> Vec<(IVec2, IVec2)> {
    l.level
        .entities
        .iter()
        .filter(|e| e.kind == EntityKind::PlayerSpawn)
        .map(|e| (e.pos, e.size))
        .collect()
}

fn placed(l: &LoadedLevel) -> bool {
    l.warnings.iter().any(|w| w.contains("no player spawn"))
}

/// The names other games give their player start, as Tiled object names
/// and classes, OGMO entity names and LDtk identifiers.
const SPAWN_NAMES: &[&str] = &[
    "hero",
    "Hero",
    "player_start",
    "PlayerStart",
    "Start",
    "Start1",
    "Player1",
    "player_2",
    "spawn_point",
    "SpawnPoint",
    "Entrance",
    "player-start",
];

#[test]
fn spawns_under_other_names_are_where_the_author_put_them() {
    for name in SPAWN_NAMES {
        // Tiled: by name, and by class.
        for attr in ["name", "type"] {
            let obj =
                format!(r#"<object id="1" {attr}="{name}" x="64" y="32" width="16" height="16"/>"#);
            let l = load_tiled(&tiled(16, 10, 4, &obj));
            assert_eq!(
                spawns(&l),
                [(IVec2::new(px(72), px(40)), IVec2::new(px(16), px(16)))],
                "Tiled {attr} {name:?}: {:?}",
                l.warnings
            );
            assert!(!placed(&l), "Tiled {name:?}: {:?}", l.warnings);
        }
        // OGMO.
        let text = json!({"layers": [{"name": "e", "entities": [
            {"name": name, "x": 64, "y": 32, "width": 16, "height": 16}
        ]}]})
        .to_string();
        let l = ogmo::load_str("t.json", &text, None, &LoadOptions::default()).unwrap();
        assert_eq!(
            spawns(&l),
            [(IVec2::new(px(72), px(40)), IVec2::new(px(16), px(16)))],
            "OGMO {name:?}: {:?}",
            l.warnings
        );
        assert!(!placed(&l), "OGMO {name:?}: {:?}", l.warnings);
        // LDtk.
        let l = ldtk::load_str(
            "t.ldtk",
            &ldtk_project(name, 16, 16),
            None,
            &LoadOptions::default(),
        )
        .unwrap();
        assert_eq!(
            spawns(&l),
            [(IVec2::new(px(72), px(40)), IVec2::new(px(16), px(16)))],
            "LDtk {name:?}: {:?}",
            l.warnings
        );
        assert!(!placed(&l), "LDtk {name:?}: {:?}", l.warnings);
    }
}

#[test]
fn names_that_only_look_like_spawns_are_not_spawns() {
    for name in ["starter", "heroine_statue", "player_1x", "spawner"] {
        let obj = format!(r#"<object id="1" name="{name}" x="64" y="32" width="16" height="16"/>"#);
        let l = load_tiled(&tiled(16, 10, 4, &obj));
        assert!(placed(&l), "{name:?} is no spawn: {:?}", l.warnings);
    }
}

/// An LDtk project of one 10 x 4 level (16 px grid, floor on the last
/// row) with one entity `name` of `w` x `h` px whose top-left is at (64,
/// 32) px.
fn ldtk_project(name: &str, w: i64, h: i64) -> String {
    let csv: Vec<i64> = (0..40).map(|i| i64::from(i / 10 == 3)).collect();
    json!({
        "jsonVersion": "1.5.3",
        "defs": {
            "layers": [{"uid": 1, "identifier": "Collisions", "type": "IntGrid", "gridSize": 16,
                "intGridValues": [{"value": 1, "identifier": "walls", "color": "#000000"}]}],
            "tilesets": []
        },
        "levels": [{"identifier": "L", "pxWid": 160, "pxHei": 64, "layerInstances": [
            {"__identifier": "Entities", "__type": "Entities", "__cWid": 10, "__cHei": 4,
                "__gridSize": 16, "visible": true, "entityInstances": [
                    {"__identifier": name, "__pivot": [0, 0], "width": w, "height": h,
                        "px": [64, 32], "fieldInstances": []}
                ]},
            {"__identifier": "Collisions", "__type": "IntGrid", "__cWid": 10, "__cHei": 4,
                "__gridSize": 16, "__pxTotalOffsetX": 0, "__pxTotalOffsetY": 0, "layerDefUid": 1,
                "visible": true, "intGridCsv": csv, "autoLayerTiles": [], "gridTiles": [],
                "entityInstances": []}
        ]}],
        "worlds": []
    })
    .to_string()
}
