//! Real levels play as their authors made them (issue 33): spawns under
//! the names other games give them, the player scaled to the level, and
//! turned hazards and triggers. Small maps written here, one per editor.

use glam::IVec2;
use ledge_levels::{ldtk, ogmo, tmx, EntityKind, LoadOptions, LoadedLevel};
use ledge_shared::fixed::px;
use ledge_shared::game::{GameConfig, GameEvent, HurtCause};
use serde_json::json;

use crate::platformer_kit::{Sim, JUMP, NONE, RIGHT};

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

/// A game of `level` with its player scaled, as a server plays it.
fn sim(level: &ledge_levels::Level) -> Sim {
    Sim::with(level, GameConfig::default().for_level(level).unwrap())
}

/// An OGMO level of 20 x 8 cells of 16 px, a floor on the last row (its
/// top at y = 112 px), and `entities` (JSON objects).
fn ogmo_room(entities: &str) -> LoadedLevel {
    let mut cells = vec!["0"; 160];
    cells[140..].fill("1");
    let text = format!(
        r#"{{"layers": [
            {{"name": "g", "gridCellWidth": 16, "gridCellHeight": 16, "gridCellsX": 20,
              "gridCellsY": 8, "grid": {cells:?}}},
            {{"name": "e", "entities": [{entities}]}}]}}"#
    );
    ogmo::load_str("t.json", &text, None, &LoadOptions::default()).unwrap()
}

/// Steps a game of `l` with `b` held for up to `n` ticks; the player's
/// centre (px) when it died of a hazard.
fn hazard_death(l: &LoadedLevel, b: ledge_shared::input::Buttons, n: usize) -> Option<IVec2> {
    let mut sim = sim(&l.level);
    for _ in 0..n {
        sim.step(b);
        let hazard = sim.saw(|e| {
            matches!(
                e,
                GameEvent::Died {
                    cause: HurtCause::Hazard(_),
                    ..
                }
            )
        });
        if hazard {
            return Some(sim.pos() / 256);
        }
    }
    None
}

/// A spike 16 x 8 px with its origin at its bottom-left corner, standing
/// on the floor at x = 160 px: upright it covers x 160..176; turned 270
/// degrees (a quarter anticlockwise) about that corner it is a wall spike
/// 8 x 16 px over x 152..160.
fn turned_spike(rotation: i32, spawn_x: i32) -> String {
    format!(
        r#"{{"name": "player", "x": {}, "y": 96, "width": 12, "height": 16}},
           {{"name": "spikes", "x": 160, "y": 112, "width": 16, "height": 8,
             "originX": 0, "originY": 8, "rotation": {rotation}}}"#,
        spawn_x - 6
    )
}

#[test]
fn an_ogmo_spike_turned_a_quarter_kills_where_it_is_turned_to() {
    let l = ogmo_room(&turned_spike(270, 168));
    let spike = &l.level.entities[1];
    assert_eq!(
        (spike.kind.clone(), spike.pos, spike.size),
        (
            EntityKind::Hazard,
            IVec2::new(px(156), px(104)),
            IVec2::new(px(8), px(16))
        ),
        "{:?}",
        l.warnings
    );
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    // Standing where the upright spike would be: safe.
    assert_eq!(hazard_death(&l, NONE, 120), None);
    // Walking right from x = 120 px: killed on touching x = 152 px.
    let l = ogmo_room(&turned_spike(270, 120));
    let at = hazard_death(&l, RIGHT, 240).expect("the turned spike kills");
    assert!((146..=150).contains(&at.x), "died at {at} px");
}

#[test]
fn a_tiled_hazard_turned_45_degrees_kills_on_its_turned_outline_only() {
    // A 32 x 8 px hazard bar turned 45 degrees clockwise about its top-left
    // corner (96, 80) px: a slanted bar reaching down-right to about
    // (118.6, 102.6) px, whose box corners (bottom-left of its bounding
    // box) are free.
    let objs = r#"<object id="1" name="spawn" x="20" y="96" width="12" height="16"/>
        <object id="2" type="hazard" x="96" y="80" width="32" height="8" rotation="45"/>"#;
    let l = load_tiled(&tiled(16, 12, 8, objs));
    let bar = &l.level.entities[1];
    let EntityKind::Turned { trigger, u, v } = bar.kind else {
        panic!("{bar:?}: {:?}", l.warnings);
    };
    assert_eq!(trigger, ledge_levels::Trigger::Hazard);
    // Half axes: 16 px along 45 degrees, 4 px across.
    let r = |a: f64| (a * 256.0).round() as i32;
    let s = std::f64::consts::FRAC_1_SQRT_2;
    assert_eq!(
        (u, v),
        (
            IVec2::new(r(16.0 * s), r(16.0 * s)),
            IVec2::new(r(-4.0 * s), r(4.0 * s))
        )
    );
    let game = |spawn: (i32, i32)| {
        let mut l = l.clone();
        l.level.entities[0].pos = IVec2::new(px(spawn.0), px(spawn.1));
        l
    };
    // A player whose box covers the bar's middle dies at once; one in the
    // bounding box's empty lower-left corner, clear of the bar, does not.
    let middle = (107, 91);
    assert!(hazard_death(&game(middle), NONE, 2).is_some());
    let corner = (88, 100);
    assert_eq!(hazard_death(&game(corner), NONE, 2), None);
}

/// How far (units) the player's bottom rises in a held jump from standing.
fn jump_rise(level: &ledge_levels::Level) -> i32 {
    let mut sim = sim(level);
    sim.land(600);
    sim.run(NONE, 10);
    let floor = sim.bottom();
    let mut top = floor;
    for _ in 0..120 {
        sim.step(JUMP);
        top = top.min(sim.bottom());
    }
    floor - top
}

/// The default level's jump, in tiles (its tiles are 16 px).
fn default_jump_tiles() -> f64 {
    f64::from(jump_rise(&ledge_levels::default_level())) / f64::from(px(16))
}

fn player_half(l: &LoadedLevel) -> IVec2 {
    sim(&l.level).view().half
}

#[test]
fn on_128_px_tiles_the_player_has_the_spawns_size_and_jumps_as_many_tiles() {
    // A hero 96 x 128 px standing on the floor of a map of 128 px tiles.
    let obj = r#"<object id="1" name="hero" x="256" y="512" width="96" height="128"/>"#;
    let l = load_tiled(&tiled(128, 10, 6, obj));
    assert_eq!(l.level.player.scale, 8 * 256, "{:?}", l.warnings);
    assert_eq!(player_half(&l), IVec2::new(px(48), px(64)));
    let tiles = f64::from(jump_rise(&l.level)) / f64::from(px(128));
    let default = default_jump_tiles();
    assert!(
        (tiles / default - 1.0).abs() < 0.02,
        "jumps {tiles:.2} tiles, the default level {default:.2}"
    );
    // The spawn stands where the author put it.
    assert_eq!(spawns(&l)[0].0, IVec2::new(px(304), px(576)));
}

#[test]
fn without_a_sized_spawn_the_tile_size_scales_the_player() {
    // A point spawn on 64 px tiles: 4 times ledge's player.
    let obj = r#"<object id="1" name="spawn" x="200" y="200"><point/></object>"#;
    let l = load_tiled(&tiled(64, 10, 6, obj));
    assert_eq!(l.level.player.scale, 4 * 256);
    assert_eq!(player_half(&l), IVec2::new(px(24), px(32)));
    let tiles = f64::from(jump_rise(&l.level)) / f64::from(px(64));
    assert!((tiles / default_jump_tiles() - 1.0).abs() < 0.02, "{tiles}");
    // An OGMO entity with its project's size (no width/height of its own)
    // does not size the player either: the 32 px grid does.
    let mut cells = vec!["0"; 40];
    cells[30..].fill("1");
    let project = r#"{"name": "p", "layers": [], "entities": [{"name": "player",
        "size": {"x": 16, "y": 16}, "origin": {"x": 0, "y": 0}, "exportID": "1"}],
        "tilesets": []}"#;
    let text = format!(
        r#"{{"layers": [
            {{"name": "g", "gridCellWidth": 32, "gridCellHeight": 32, "gridCellsX": 10,
              "gridCellsY": 4, "grid": {cells:?}}},
            {{"name": "e", "entities": [{{"name": "player", "x": 64, "y": 64}}]}}]}}"#
    );
    let l = ogmo::load_str(
        "t.json",
        &text,
        Some(("p.ogmo", project)),
        &LoadOptions::default(),
    )
    .unwrap();
    assert_eq!(
        (l.level.player.scale, player_half(&l)),
        (512, IVec2::new(px(12), px(16))),
        "{:?}",
        l.warnings
    );
}

#[test]
fn ogmo_and_ldtk_spawns_size_the_player_too() {
    let l = ogmo_room(r#"{"name": "Start1", "x": 64, "y": 64, "width": 24, "height": 48}"#);
    assert_eq!(l.level.player.scale, 3 * 256);
    assert_eq!(player_half(&l), IVec2::new(px(12), px(24)));
    let l = ldtk::load_str(
        "t.ldtk",
        &ldtk_project("Player", 24, 24),
        None,
        &LoadOptions::default(),
    )
    .unwrap();
    assert_eq!(l.level.player.scale, 384);
    assert_eq!(player_half(&l), IVec2::new(px(12), px(12)));
    // The default level keeps ledge's own player.
    let d = ledge_levels::default_level();
    assert_eq!(d.player, ledge_shared::level::PlayerScale::default());
}

fn with_settings(toml: &str, map: &str) -> Result<LoadedLevel, ledge_levels::LevelError> {
    let s = ledge_levels::LevelSettings::parse("t.ledge.toml", toml)?;
    let o = s.options("t.ledge.toml", LoadOptions::default())?;
    tmx::load_str("t.tmx", map, &o)
}

#[test]
fn the_settings_file_overrides_the_scale_and_size() {
    let obj = r#"<object id="1" name="hero" x="256" y="512" width="96" height="128"/>"#;
    let map = tiled(128, 10, 6, obj);
    let l = with_settings("scale = 4.0", &map).unwrap();
    assert_eq!(l.level.player.scale, 1024);
    assert_eq!(player_half(&l), IVec2::new(px(24), px(32)));
    let l = with_settings("[player]\nwidth = 40\nheight = 80", &map).unwrap();
    assert_eq!(l.level.player.scale, 5 * 256);
    assert_eq!(player_half(&l), IVec2::new(px(20), px(40)));
    let l = with_settings("scale = 2.5\n[player]\nheight = 64", &map).unwrap();
    assert_eq!(l.level.player.scale, 640);
    assert_eq!(player_half(&l), IVec2::new(px(24), px(32)));
    // A fraction of a 1/256 is rounded, once, at import.
    let l = with_settings("scale = 1.0001", &map).unwrap();
    assert_eq!(l.level.player.scale, 256);
    for (toml, field) in [
        ("scale = 1000.0", "scale"),
        ("scale = 0.01", "scale"),
        ("scale = nan", "scale"),
        ("[player]\nwidth = -1", "player.width"),
        ("[player]\nheight = 1e300", "player.height"),
        ("[player]", "player.width"),
    ] {
        let e = with_settings(toml, &map).unwrap_err();
        assert_eq!(e.field(), Some(field), "{toml}: {e}");
        assert!(e.to_string().starts_with("t.ledge.toml: "), "{e}");
    }
    let e = with_settings("[player]\nheight = 1\nwidth = 1", &map).unwrap_err();
    assert!(e.to_string().contains("player.height"), "{e}");
}

#[test]
fn a_spawn_too_small_to_scale_falls_back_to_the_tiles() {
    let obj = r#"<object id="1" name="spawn" x="64" y="32" width="1" height="1"/>"#;
    let l = load_tiled(&tiled(16, 10, 4, obj));
    assert_eq!(l.level.player, ledge_shared::level::PlayerScale::default());
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("outside ledge's scale range")),
        "{:?}",
        l.warnings
    );
}
