//! The renderer on the default level (its art and overlay where the level
//! puts them) and on a level too large for the picture's bounds.

use super::*;
use crate::palette::overlay;
use ledge_shared::level::{EntityDef, EntityKind};
use ledge_shared::tilemap::{Tile, Tilemap};

fn default_loaded() -> LoadedLevel {
    crate::load_default_level().expect("the default level loads")
}

/// `top` over `under`, straight alpha.
fn over(top: [u8; 4], under: [u8; 4]) -> [u8; 3] {
    let a = top[3] as f32 / 255.0;
    [0, 1, 2].map(|i| (top[i] as f32 * a + under[i] as f32 * (1.0 - a)).round() as u8)
}

fn close(a: [u8; 3], b: [u8; 3]) -> bool {
    a.iter().zip(b).all(|(&x, y)| x.abs_diff(y) <= 2)
}

#[test]
fn the_overlay_is_the_plain_picture_with_each_kind_in_its_colour() {
    let loaded = default_loaded();
    let plain = render(
        &loaded,
        &RenderOptions {
            scale: Some(1.0),
            overlay: false,
            region: None,
        },
    )
    .unwrap();
    let shown = render(&loaded, &RenderOptions::default()).unwrap();
    assert_eq!((shown.width(), shown.height()), (1600, 480));
    assert_eq!(shown.origin, [0.0, 0.0]);
    let map = &loaded.level.tilemap;
    let t = map.tile_size() / UNITS_PER_PX;
    // A cell of each kind: its centre is the plain picture under the
    // kind's colour.
    for (kind, colour) in [
        (Tile::Solid, overlay::SOLID),
        (Tile::Hazard, overlay::HAZARD),
        (Tile::OneWay, overlay::ONE_WAY_EDGE),
    ] {
        let i = map.tiles().iter().position(|&x| x == kind).unwrap();
        let (c, r) = (i as u32 % map.width(), i as u32 / map.width());
        // One-way: inside the edge band at the top of the cell.
        let dy = if kind == Tile::OneWay {
            1
        } else {
            t as u32 / 2
        };
        let (x, y) = (c * t as u32 + t as u32 / 2, r * t as u32 + dy);
        let mut under = plain.pixel(x, y);
        if kind == Tile::OneWay {
            // The band lies over the cell's own fill.
            let [r, g, b] = over(overlay::ONE_WAY, under);
            under = [r, g, b, 255];
        }
        let want = over(colour, under);
        let got = shown.pixel(x, y);
        assert!(
            close([got[0], got[1], got[2]], want),
            "{kind:?} at ({x}, {y}): {got:?}, want {want:?}"
        );
    }
    // The player's box where the game spawns the first player: 12 x 16 px
    // standing at the spawn.
    let spawn = loaded
        .level
        .entities
        .iter()
        .find(|e| e.kind == EntityKind::PlayerSpawn)
        .unwrap();
    let (x, y) = (
        (spawn.pos.x / UNITS_PER_PX) as u32,
        (spawn.pos.y / UNITS_PER_PX) as u32,
    );
    let got = shown.pixel(x, y);
    // Over the spawn entity's own box.
    let [r, g, b] = over(overlay::SPAWN, plain.pixel(x, y));
    let want = over(overlay::PLAYER, [r, g, b, 255]);
    assert!(
        close([got[0], got[1], got[2]], want),
        "spawn ({x}, {y}): {got:?}, want {want:?}"
    );
    // Empty sky is left alone.
    assert_eq!(shown.pixel(400, 100), plain.pixel(400, 100));
}

#[test]
fn a_level_without_art_is_drawn_in_the_games_plain_colours() {
    let mut loaded = default_loaded();
    loaded.art = Default::default();
    let plain = render(
        &loaded,
        &RenderOptions {
            scale: Some(2.0),
            overlay: false,
            region: None,
        },
    )
    .unwrap();
    assert_eq!((plain.width(), plain.height()), (3200, 960));
    // Deep in the ground (row 28, column 50): ground colour; the sky above.
    let ground = plain.pixel(50 * 32 + 16, 28 * 32 + 16);
    assert!(
        ground == crate::palette::flat::SOLID || ground == crate::palette::flat::SOLID_SPECK,
        "{ground:?}"
    );
    assert_eq!(plain.pixel(800, 200), crate::palette::flat::SKY);
    let png = plain.encode_png().unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

/// A level whose two blocks are `apart` pixels apart.
fn wide(apart: i32) -> LoadedLevel {
    let block = |x: i32| EntityDef {
        kind: EntityKind::Block,
        pos: glam::IVec2::new(x * UNITS_PER_PX, 0),
        size: glam::IVec2::splat(16 * UNITS_PER_PX),
    };
    // The default level's settings, none of its contents.
    let mut level = crate::default_level();
    level.name = "wide".into();
    level.tilemap = Tilemap::new(glam::IVec2::ZERO, 16 * UNITS_PER_PX, 0, 0, Vec::new()).unwrap();
    level.entities = vec![block(0), block(apart)];
    LoadedLevel {
        level,
        route: Vec::new(),
        warnings: Vec::new(),
        art: Default::default(),
        layers: Vec::new(),
    }
}

#[test]
fn a_level_too_large_is_drawn_smaller_or_refused_naming_the_limit() {
    let loaded = wide(100_000);
    let e = render(
        &loaded,
        &RenderOptions {
            scale: Some(1.0),
            overlay: true,
            region: None,
        },
    )
    .err()
    .expect("100016 px is wider than the limit");
    let text = e.to_string();
    assert!(
        text.contains("MAX_RENDER_SIDE") && text.contains("--scale 0.16"),
        "{text}"
    );
    let auto = render(&loaded, &RenderOptions::default()).unwrap();
    assert!(auto.width() <= MAX_RENDER_SIDE, "{}", auto.width());
    assert!(auto.scale < 0.17 && auto.scale > 0.15, "{}", auto.scale);
    assert!(auto.notes[0].contains("--scale"), "{:?}", auto.notes);
    // A region of it: drawn at scale 1.
    let region = RenderOptions {
        region: Some([99_990.0, -8.0, 40.0, 16.0]),
        ..RenderOptions::default()
    };
    let part = render(&loaded, &region).unwrap();
    assert_eq!((part.width(), part.height(), part.scale), (40, 16, 1.0));
    assert_eq!(part.origin, [99_990.0, -8.0]);
    assert!(matches!(
        render(
            &loaded,
            &RenderOptions {
                scale: Some(f32::NAN),
                ..RenderOptions::default()
            }
        ),
        Err(RenderError::BadScale(_))
    ));
}
