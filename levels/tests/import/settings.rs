//! The settings file beside a level (`LEVEL.ledge.toml`): every key, its
//! effect on a real load, and the errors for bad keys and values.

use std::path::{Path, PathBuf};

use ledge_levels::{
    load_level, ogmo, settings_path_for, EntityKind, LevelError, LevelSettings, LoadOptions,
    LoadedLevel,
};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::tilemap::Tile;

/// A 4 x 3 map of 16 px tiles: layer "A" (top row, tile id 0), layer "B"
/// (bottom row, tile ids 1 and 2, id 2 with a `water` property), and the
/// objects given. No collision data of its own.
fn write_map(dir: &Path, objects: &str) -> PathBuf {
    let map = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<map version="1.10" orientation="orthogonal" renderorder="right-down" width="4" height="3" tilewidth="16" tileheight="16" infinite="0">
 <tileset firstgid="1" name="Blocks" tilewidth="16" tileheight="16" tilecount="4" columns="2">
  <image source="blocks.png" width="32" height="32"/>
  <tile id="2"><properties><property name="water" type="bool" value="true"/></properties></tile>
 </tileset>
 <layer id="1" name="A" width="4" height="3">
  <data encoding="csv">1,0,0,0,
0,0,0,0,
0,0,0,0</data>
 </layer>
 <layer id="2" name="B" width="4" height="3">
  <data encoding="csv">0,0,0,0,
0,0,0,0,
2,2,3,2</data>
 </layer>
 <objectgroup id="3" name="things">{objects}</objectgroup>
</map>"#
    );
    let path = dir.join("level.tmx");
    std::fs::write(&path, map).unwrap();
    path
}

const SPAWN: &str = r#"<object id="1" name="spawn" x="24" y="8" width="16" height="16"/>"#;

/// Loads `map` with `settings` written beside it.
fn with_settings(map: &Path, settings: &str) -> Result<LoadedLevel, LevelError> {
    std::fs::write(settings_path_for(map), settings).unwrap();
    load_level(map, None)
}

fn tiles(l: &LoadedLevel) -> Vec<Tile> {
    l.level.tilemap.tiles().to_vec()
}

use Tile::{Empty as E, Hazard as H, OneWay as O, Solid as S};

#[test]
fn the_settings_file_is_found_beside_the_level_or_given() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path(), SPAWN);
    assert_eq!(settings_path_for(&map), dir.path().join("level.ledge.toml"));
    // Without settings: no collision data, so the collision-named layers
    // would collide; "A" and "B" are not, so every visible layer does.
    let plain = load_level(&map, None).unwrap();
    assert_eq!(tiles(&plain), [S, E, E, E, E, E, E, E, S, S, S, S]);
    // Beside the level.
    let l = with_settings(&map, r#"collision_layers = ["B"]"#).unwrap();
    assert_eq!(tiles(&l), [E, E, E, E, E, E, E, E, S, S, S, S]);
    // Given explicitly (wins over the one beside).
    let other = dir.path().join("other.toml");
    std::fs::write(&other, r#"collision_layers = ["A"]"#).unwrap();
    let l = load_level(&map, Some(&other)).unwrap();
    assert_eq!(tiles(&l), [S, E, E, E, E, E, E, E, E, E, E, E]);
}

#[test]
fn decoration_layers_never_collide() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path(), SPAWN);
    let l = with_settings(&map, r#"decoration_layers = ["A"]"#).unwrap();
    assert_eq!(tiles(&l), [E, E, E, E, E, E, E, E, S, S, S, S]);
}

#[test]
fn tiles_by_tileset_and_id_and_by_property() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path(), SPAWN);
    // Tile id 0 empty, id 1 one-way, id 2 (`water = true`) a hazard.
    let l = with_settings(
        &map,
        "[tiles.blocks]\n1 = \"one_way\"\n0 = \"empty\"\n[tile_properties]\nwater = \"hazard\"\n",
    )
    .unwrap();
    assert_eq!(tiles(&l), [E, E, E, E, E, E, E, E, O, O, H, O]);
    // A bad kind names the key and lists the kinds.
    let e = with_settings(&map, "[tiles.Blocks]\n1 = \"bouncy\"\n").unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("tiles.Blocks.1") && msg.contains("slope_45_right"),
        "{msg}"
    );
    let e = with_settings(&map, "[tiles.Blocks]\nx = \"solid\"\n").unwrap_err();
    assert!(e.to_string().contains("is not a tile id"), "{e}");
    let e = with_settings(&map, "[tile_properties]\nwater = \"wet\"\n").unwrap_err();
    assert!(e.to_string().contains("tile_properties.water"), "{e}");
}

#[test]
fn entity_aliases_speed_units_and_unknown_entities() {
    let dir = tempfile::tempdir().unwrap();
    let objects = r#"
  <object id="1" name="hero" x="24" y="8" width="16" height="16"/>
  <object id="2" name="crab" x="40" y="8" width="16" height="16"><properties><property name="speed" type="float" value="30"/></properties></object>"#;
    let map = write_map(dir.path(), objects);
    let l = with_settings(
        &map,
        "speed_unit = \"px_per_second\"\n[entities]\nhero = \"player\"\nCrab = \"walker\"\n",
    )
    .unwrap();
    let kinds: Vec<_> = l.level.entities.iter().map(|e| e.kind.clone()).collect();
    // 30 px/s at 60 ticks a second: 0.5 px a tick.
    assert_eq!(
        kinds,
        [
            EntityKind::PlayerSpawn,
            EntityKind::Walker {
                speed: UNITS_PER_PX / 2
            }
        ]
    );
    // px per tick (the default): 30 px a tick.
    let l = with_settings(&map, "[entities]\nhero = \"player\"\ncrab = \"walker\"\n").unwrap();
    assert_eq!(
        l.level.entities[1].kind,
        EntityKind::Walker {
            speed: 30 * UNITS_PER_PX
        }
    );
    // Unknown entities: skipped (default) or refused.
    let l = with_settings(&map, "[entities]\nhero = \"player\"\n").unwrap();
    assert_eq!(l.level.entities.len(), 1);
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("skipped objects named \"crab\"")),
        "{:?}",
        l.warnings
    );
    let e = with_settings(
        &map,
        "unknown_entities = \"error\"\n[entities]\nhero = \"player\"\n",
    )
    .unwrap_err();
    assert!(matches!(e, LevelError::UnknownEntity { .. }), "{e}");
    let e = with_settings(&map, "unknown_entities = \"maybe\"\n").unwrap_err();
    assert!(e.to_string().contains("unknown_entities"), "{e}");
    let e = with_settings(&map, "speed_unit = \"furlongs\"\n").unwrap_err();
    assert!(e.to_string().contains("speed_unit"), "{e}");
    // An alias must name a ledge entity.
    let e = with_settings(&map, "[entities]\nhero = \"wizard\"\n").unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("entities.hero") && msg.contains("player, spawn"),
        "{msg}"
    );
}

#[test]
fn require_spawn() {
    let dir = tempfile::tempdir().unwrap();
    // No spawn, and every visible tile solid with no room to stand: one is
    // placed on top by default, none when the settings say a spawn is not
    // required.
    let map = write_map(dir.path(), "");
    let full = std::fs::read_to_string(&map)
        .unwrap()
        .replace("0,0,0,0,\n0,0,0,0,\n2,2,3,2", "2,2,2,2,\n2,2,2,2,\n2,2,2,2");
    std::fs::write(&map, full).unwrap();
    let l = with_settings(&map, "").unwrap();
    assert_eq!(l.level.entities.len(), 1);
    assert!(
        l.warnings.iter().any(|w| w.contains("on top of the level")),
        "{:?}",
        l.warnings
    );
    let l = with_settings(&map, "require_spawn = false\n").unwrap();
    assert!(l.level.entities.is_empty());
}

#[test]
fn grid_values_for_ogmo() {
    let text = r#"{"layers": [
        {"name": "solids", "gridCellWidth": 16, "gridCellHeight": 16, "gridCellsX": 2, "gridCellsY": 1, "grid2D": [["1", "g"]]},
        {"name": "e", "entities": [{"name": "player", "x": 0, "y": 0, "width": 16, "height": 16}]}]}"#;
    let s = LevelSettings::parse("x.ledge.toml", "[grid]\ng = \"one_way\"\n").unwrap();
    let opts = s.options("x.ledge.toml", LoadOptions::default()).unwrap();
    let l = ogmo::load_str("x.json", text, None, &opts).unwrap();
    assert_eq!(l.level.tilemap.tiles(), &[S, O]);
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
}

#[test]
fn a_typo_lists_the_valid_keys() {
    let e = LevelSettings::parse("castle.ledge.toml", "colision_layers = [\"x\"]\n").unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("castle.ledge.toml: line 1: "), "{msg}");
    for key in [
        "collision_layers",
        "decoration_layers",
        "unknown_entities",
        "speed_unit",
        "require_spawn",
        "entities",
        "tiles",
        "tile_properties",
        "grid",
    ] {
        assert!(msg.contains(&format!("`{key}`")), "{key} not in {msg}");
    }
    // Wrong types and bad TOML are errors too, naming the line.
    let e = LevelSettings::parse("s.toml", "\n\nrequire_spawn = \"yes\"\n").unwrap_err();
    assert!(e.to_string().contains("s.toml: line 3"), "{e}");
    assert!(LevelSettings::parse("s.toml", "[entities\n").is_err());
    // A settings file that cannot be read names itself.
    let e = LevelSettings::load(Path::new("/no/such/level.ledge.toml")).unwrap_err();
    assert!(
        e.to_string().starts_with("/no/such/level.ledge.toml: "),
        "{e}"
    );
}
