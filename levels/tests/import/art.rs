//! Level art: what a client draws, from Tiled maps (a map written here
//! with small generated PNGs; the Tiled examples corpus when fetched) and
//! OGMO levels (the embedded default level and its project).

use std::path::Path;

use ledge_levels::art::{png_size, ArtContent, LevelArt, MAX_ART_IMAGE_BYTES, MAX_ART_IMAGE_SIDE};
use ledge_levels::{load_file_with, ogmo, LevelError, LoadOptions, LoadedLevel};

/// A PNG of `w` x `h` pixels, every pixel `(x, y, 0, 255)`.
fn png(w: u32, h: u32) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc.write_header().unwrap();
        let data: Vec<u8> = (0..h)
            .flat_map(|y| (0..w).flat_map(move |x| [x as u8, y as u8, 0, 255]))
            .collect();
        wr.write_image_data(&data).unwrap();
    }
    out
}

/// Every tile of a tileset of `n` tiles is solid.
fn kinds(n: u32) -> String {
    (0..n)
        .map(|i| {
            format!(
                r#"<tile id="{i}"><properties><property name="kind" value="solid"/></properties></tile>"#
            )
        })
        .collect()
}

fn opts() -> LoadOptions {
    LoadOptions {
        collision_layers: Some(vec!["front".into()]),
        skip_unknown_entities: true,
        ..LoadOptions::default()
    }
}

const H: u32 = 0x8000_0000;
const V: u32 = 0x4000_0000;
const D: u32 = 0x2000_0000;

/// A 4 x 2 map of 16 px tiles: an image layer, a group (offset, opacity,
/// parallax) with a tile layer, a hidden tile layer, a tile layer with
/// flipped tiles, and tile objects (one hidden). The atlas (3 x 2 tiles,
/// margin 1, spacing 2) is in `img/`.
fn write_map(dir: &Path) -> std::path::PathBuf {
    std::fs::create_dir_all(dir.join("img")).unwrap();
    std::fs::write(dir.join("img/atlas.png"), png(54, 36)).unwrap();
    std::fs::write(dir.join("thing.png"), png(24, 40)).unwrap();
    std::fs::write(dir.join("other.png"), png(8, 8)).unwrap();
    std::fs::write(dir.join("sky.png"), png(8, 4)).unwrap();
    let front = [6 | H, 1 | V, 2 | D, 3 | H | V | D, 5, 0, 0, 1];
    let front: Vec<String> = front.iter().map(u32::to_string).collect();
    let map = format!(
        r##"<?xml version="1.0" encoding="UTF-8"?>
<map version="1.10" orientation="orthogonal" renderorder="right-down" width="4" height="2" tilewidth="16" tileheight="16" infinite="0" backgroundcolor="#102030" parallaxoriginx="8" parallaxoriginy="4" nextlayerid="7" nextobjectid="9">
 <tileset firstgid="1" name="atlas" tilewidth="16" tileheight="16" spacing="2" margin="1" tilecount="6" columns="3">
  <tileoffset x="1" y="-2"/>
  <image source="img/atlas.png" width="54" height="36"/>
  {atlas}
 </tileset>
 <tileset firstgid="7" name="things" tilewidth="24" tileheight="40" tilecount="2" columns="0">
  <grid orientation="orthogonal" width="1" height="1"/>
  <tile id="0"><image source="thing.png" width="24" height="40"/></tile>
  <tile id="1"><image source="other.png" width="8" height="8"/></tile>
 </tileset>
 <tileset firstgid="9" name="hiddenset" tilewidth="16" tileheight="16" tilecount="1" columns="1">
  <image source="missing.png" width="16" height="16"/>
  {hidden}
 </tileset>
 <imagelayer id="1" name="sky" offsetx="3" offsety="4" parallaxx="0.5" repeatx="1"><image source="sky.png" width="8" height="4"/></imagelayer>
 <group id="2" name="g" offsetx="5" offsety="7" opacity="0.5" parallaxx="0.5">
  <layer id="3" name="back" width="4" height="2" opacity="0.5"><data encoding="csv">1,0,0,2,0,0,0,0</data></layer>
 </group>
 <layer id="4" name="hidden" width="4" height="2" visible="0"><data encoding="csv">9,9,9,9,9,9,9,9</data></layer>
 <layer id="5" name="front" width="4" height="2"><data encoding="csv">{front}</data></layer>
 <objectgroup id="6" name="props">
  <object id="1" gid="7" x="10" y="30" width="24" height="40" rotation="90"/>
  <object id="2" gid="{flipped}" x="40" y="30" width="12" height="20"/>
  <object id="3" gid="8" x="0" y="0" width="8" height="8" visible="0"/>
  <object id="4" name="spawn" x="8" y="8"><point/></object>
 </objectgroup>
</map>
"##,
        atlas = kinds(6),
        hidden = kinds(1),
        front = front.join(","),
        flipped = 7 | H,
    );
    let path = dir.join("map.tmx");
    std::fs::write(&path, map).unwrap();
    path
}

#[test]
fn tiled_layers_in_draw_order_with_offsets_flips_and_objects() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_map(dir.path());
    let loaded = load_file_with(&path, &opts()).unwrap();
    // The hidden tile object is said to be ignored (drawn and collided
    // nowhere), nothing else.
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    assert!(
        loaded.warnings[0].contains("object 3")
            && loaded.warnings[0].contains("hidden objects are ignored")
    );
    let art = &loaded.art;
    assert!(art.warnings.is_empty(), "{:?}", art.warnings);
    assert_eq!(art.background, Some([0x10, 0x20, 0x30, 0xff]));
    assert_eq!(art.parallax_origin, (8.0, 4.0));
    assert_eq!(art.size, (64.0, 32.0));
    // Back to front; the hidden layer is left out, and so are its tileset
    // and image (never read: it does not exist).
    let names: Vec<&str> = art.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["sky", "g/back", "front", "props"]);
    let images: Vec<&str> = art.images.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(images, ["sky.png", "img/atlas.png", "thing.png"]);
    assert!(art.tilesets.iter().all(|t| t.name != "hiddenset"));

    let sky = &art.layers[0];
    assert_eq!((sky.offset, sky.parallax), ((3.0, 4.0), (0.5, 1.0)));
    assert_eq!(
        sky.content,
        ArtContent::Image {
            image: 0,
            repeat_x: true,
            repeat_y: false
        }
    );
    let back = &art.layers[1];
    assert_eq!(
        (back.offset, back.parallax, back.opacity),
        ((5.0, 7.0), (0.5, 1.0), 0.25)
    );

    // The atlas: margin and spacing in the source rectangles.
    let atlas = &art.tilesets[0];
    assert_eq!(
        (
            atlas.name.as_str(),
            atlas.columns,
            atlas.margin,
            atlas.spacing
        ),
        ("atlas", 3, 1, 2)
    );
    assert_eq!(atlas.offset, (1, -2));
    assert_eq!(art.images[1].bytes, png(54, 36), "the file's own bytes");
    assert_eq!((art.images[1].width, art.images[1].height), (54, 36));
    for (id, x, y) in [(0, 1, 1), (2, 37, 1), (4, 19, 19), (5, 37, 19)] {
        let s = art.source(0, id).unwrap();
        assert_eq!(
            (s.image, s.x, s.y, s.w, s.h),
            (1, x, y, 16, 16),
            "tile {id}"
        );
    }
    assert_eq!(art.source(0, 6), None);

    // Flips, cell by cell.
    let ArtContent::Tiles(front) = &art.layers[2].content else {
        panic!("front is a tile layer");
    };
    assert_eq!((front.width, front.height, front.cell_width), (4, 2, 16));
    let cell = |x, y| {
        front
            .get(x, y)
            .map(|c| (c.tile, c.flip_h, c.flip_v, c.flip_d))
    };
    assert_eq!(cell(0, 0), Some((5, true, false, false)));
    assert_eq!(cell(1, 0), Some((0, false, true, false)));
    assert_eq!(cell(2, 0), Some((1, false, false, true)));
    assert_eq!(cell(3, 0), Some((2, true, true, true)));
    assert_eq!(cell(0, 1), Some((4, false, false, false)));
    assert_eq!(cell(1, 1), None);
    assert_eq!(cell(3, 1), Some((0, false, false, false)));

    // Tile objects: the hidden one is left out; the collection keeps only
    // the tile used.
    let ArtContent::Objects(objs) = &art.layers[3].content else {
        panic!("props is an object layer");
    };
    assert_eq!(objs.len(), 2);
    let (a, b) = (&objs[0], &objs[1]);
    assert_eq!(
        (a.x, a.y, a.width, a.height, a.rotation, a.flip_h),
        (10.0, 30.0, 24.0, 40.0, 90.0, false)
    );
    assert_eq!(
        (b.x, b.y, b.width, b.height, b.rotation, b.flip_h),
        (40.0, 30.0, 12.0, 20.0, 0.0, true)
    );
    let things = &art.tilesets[a.tileset as usize];
    assert_eq!(things.image, None);
    assert_eq!(things.tiles.len(), 1);
    let s = art.source(a.tileset, 0).unwrap();
    assert_eq!(art.images[s.image as usize].name, "thing.png");
    assert_eq!((s.x, s.y, s.w, s.h), (0, 0, 24, 40));
}

#[test]
fn level_art_round_trips_through_serde() {
    let dir = tempfile::tempdir().unwrap();
    let art = load_file_with(write_map(dir.path()), &opts()).unwrap().art;
    let json = serde_json::to_string(&art).unwrap();
    let back: LevelArt = serde_json::from_str(&json).unwrap();
    assert_eq!(back, art);
}

fn load_with_image(
    name: &str,
    bytes: &[u8],
) -> (tempfile::TempDir, Result<LoadedLevel, LevelError>) {
    let dir = tempfile::tempdir().unwrap();
    let path = write_map(dir.path());
    std::fs::write(dir.path().join("img").join(name), bytes).unwrap();
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("img/atlas.png", &format!("img/{name}"));
    std::fs::write(&path, text).unwrap();
    let r = load_file_with(&path, &opts());
    (dir, r)
}

#[test]
fn images_too_wide_or_too_large_are_refused_naming_the_file_and_the_bound() {
    // The header says 9000 px wide: refused before any decoding.
    let mut wide = png(54, 36);
    wide[16..20].copy_from_slice(&9000u32.to_be_bytes());
    assert_eq!(png_size(&wide), Some((9000, 36)));
    let (_d, r) = load_with_image("wide.png", &wide);
    let e = r.unwrap_err();
    assert!(matches!(e, LevelError::OutOfBounds { .. }), "{e}");
    assert!(e.file().ends_with("map.tmx"), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("img/wide.png") && msg.contains("MAX_ART_IMAGE_SIDE"),
        "{msg}"
    );
    assert!(msg.contains(&MAX_ART_IMAGE_SIDE.to_string()), "{msg}");

    let mut big = png(54, 36);
    big.resize(MAX_ART_IMAGE_BYTES as usize + 1, 0);
    let (_d, r) = load_with_image("big.png", &big);
    let msg = r.unwrap_err().to_string();
    assert!(
        msg.contains("big.png") && msg.contains("MAX_ART_IMAGE_BYTES"),
        "{msg}"
    );
}

#[test]
fn tiles_outside_the_atlas_image_are_refused() {
    // An image of one row: the first cell, tile 5 (second row), is not in it.
    let (_d, r) = load_with_image("short.png", &png(54, 18));
    let e = r.unwrap_err();
    let msg = e.to_string();
    assert_eq!(e.field(), Some("layers[3].data[0]"), "{msg}");
    assert!(
        msg.contains("tile id 5 is outside tileset \"atlas\""),
        "{msg}"
    );
}

#[test]
fn missing_or_non_png_images_are_warnings_and_their_tiles_are_not_drawn() {
    let (_d, r) = load_with_image("atlas.gif", b"GIF89a....");
    let art = r.unwrap().art;
    assert_eq!(art.warnings.len(), 1, "{:?}", art.warnings);
    assert!(art.warnings[0].contains("not a PNG"), "{:?}", art.warnings);
    let ArtContent::Tiles(front) = &art.layers[2].content else {
        panic!()
    };
    assert!(front.cells.iter().all(Option::is_none));

    let dir = tempfile::tempdir().unwrap();
    let path = write_map(dir.path());
    std::fs::remove_file(dir.path().join("thing.png")).unwrap();
    let art = load_file_with(&path, &opts()).unwrap().art;
    assert_eq!(art.warnings.len(), 1, "{:?}", art.warnings);
    assert!(art.warnings[0].contains("thing.png"), "{:?}", art.warnings);
    // The props layer has nothing left to draw.
    let names: Vec<&str> = art.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["sky", "g/back", "front"]);
}

#[test]
fn ogmo_default_level_art_is_its_tile_layer_with_the_embedded_tileset() {
    let loaded = ledge_levels::load_default_level().unwrap();
    let art = &loaded.art;
    assert_eq!(art.background, Some([0x28, 0x2c, 0x34, 0xff]));
    assert_eq!(art.images.len(), 1);
    let img = &art.images[0];
    assert_eq!(
        (img.name.as_str(), img.width, img.height),
        ("ledge.png", 208, 32)
    );
    let file = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/default/ledge.png")).unwrap();
    assert_eq!(img.bytes, file, "the embedded PNG is the tileset file");
    let ts = &art.tilesets[0];
    assert_eq!((ts.columns, ts.tile_count, ts.tile_width), (13, 26, 16));
    assert_eq!(art.layers.len(), 1);
    let ArtContent::Tiles(grid) = &art.layers[0].content else {
        panic!()
    };
    assert_eq!((grid.width, grid.height, grid.cell_width), (100, 30, 16));
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/default/default.json"))
            .unwrap(),
    )
    .unwrap();
    let data = &json["layers"][0]["data2D"];
    for y in 0..30 {
        for x in 0..100 {
            let id = data[y][x].as_i64().unwrap();
            let cell = grid.get(x as u32, y as u32).map(|c| c.tile as i64);
            assert_eq!(cell.unwrap_or(-1), id, "cell ({x}, {y})");
        }
    }
    let s = art.source(0, 13).unwrap();
    assert_eq!((s.x, s.y), (0, 16));
}

#[test]
fn ogmo_layers_are_drawn_last_to_first() {
    let level = r#"{"ogmoVersion": "3.3.0", "width": 64, "height": 32, "offsetX": 0, "offsetY": 0,
      "layers": [
        {"name": "front", "offsetX": 0, "offsetY": 0, "gridCellWidth": 16, "gridCellHeight": 16,
         "gridCellsX": 4, "gridCellsY": 2, "tileset": "ledge", "data": [-1, 12, -1, -1, 1, 1, 1, 1]},
        {"name": "back", "offsetX": 8, "offsetY": 0, "gridCellWidth": 16, "gridCellHeight": 16,
         "gridCellsX": 4, "gridCellsY": 2, "tileset": "ledge", "data": [2, -1, -1, -1, -1, -1, -1, -1]},
        {"name": "entities", "entities": [{"name": "player", "x": 8, "y": 8, "width": 8, "height": 8}]}
      ]}"#;
    let project = include_str!("../../default/ledge.ogmo");
    let options = LoadOptions {
        collision_layers: Some(vec!["front".into()]),
        ..LoadOptions::default()
    };
    let loaded =
        ogmo::load_str("two.json", level, Some(("ledge.ogmo", project)), &options).unwrap();
    let names: Vec<&str> = loaded.art.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["back", "front"]);
    assert_eq!(loaded.art.layers[0].offset, (8.0, 0.0));
    assert_eq!(loaded.art.tilesets.len(), 1, "one tileset for both layers");
    // An id beyond the tileset is refused, naming the cell.
    let bad = level.replace("[2, -1,", "[26, -1,");
    let e = ogmo::load_str("two.json", &bad, Some(("ledge.ogmo", project)), &options).unwrap_err();
    assert_eq!(e.field(), Some("layers[1].data[0]"), "{e}");
}

/// The Tiled examples corpus (`scripts/fetch-level-corpus`), when fetched:
/// desert.tmx's art is its one layer on its margin-and-spacing tileset.
#[test]
fn corpus_desert_art() {
    let root = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../target/level-corpus/tiled-examples"
    );
    let path = Path::new(root).join("desert.tmx");
    if !path.is_file() {
        eprintln!("corpus_desert_art: no corpus at {root} (scripts/fetch-level-corpus); skipped");
        return;
    }
    let options = LoadOptions {
        collision_layers: Some(Vec::new()),
        require_spawn: false,
        ..LoadOptions::default()
    };
    let art = load_file_with(&path, &options).unwrap().art;
    assert_eq!(art.layers.len(), 1);
    assert_eq!(art.images.len(), 1);
    assert_eq!(art.images[0].name, "tmw_desert_spacing.png");
    assert_eq!((art.images[0].width, art.images[0].height), (265, 199));
    let ts = &art.tilesets[0];
    assert_eq!(
        (ts.margin, ts.spacing, ts.columns, ts.tile_count),
        (1, 1, 8, 48)
    );
    let ArtContent::Tiles(g) = &art.layers[0].content else {
        panic!()
    };
    assert_eq!((g.width, g.height), (40, 40));
    // The first cell is tile 29 (gid 30): column 5, row 3.
    let c = g.get(0, 0).unwrap();
    assert_eq!(c.tile, 29);
    let s = art.source(c.tileset, c.tile).unwrap();
    assert_eq!((s.x, s.y), (1 + 5 * 33, 1 + 3 * 33));
}
