//! Tiled collision from the map's own data: tile collision outlines (full
//! squares, slopes, partial boxes, ellipses, concave outlines, flips),
//! tile and layer properties, hidden layers, and infinite maps. The maps
//! are written by the tests in Tiled's format (tileset tiles with
//! `<objectgroup>` outlines, as Tiled's collision editor saves them).

use glam::IVec2;
use ledge_levels::{tmx, EntityKind, LoadOptions, LoadedLevel};
use ledge_shared::tilemap::{Slope, Tile};

const H: u32 = 0x8000_0000;
const V: u32 = 0x4000_0000;

/// A map of 16 px tiles: `layers` are `(name, attributes, csv)`, the
/// tileset's tiles (id → inner XML) as given; a spawn object at the top
/// left. `infinite` writes the layers' CSV as one chunk at `chunk`.
fn map(
    w: u32,
    h: u32,
    tiles: &[(u32, &str)],
    layers: &[(&str, &str, String)],
    chunk: Option<(i32, i32)>,
) -> String {
    let tiles: String = tiles
        .iter()
        .map(|(id, inner)| format!("<tile id=\"{id}\">{inner}</tile>\n"))
        .collect();
    let layers: String = layers
        .iter()
        .enumerate()
        .map(|(i, (name, attrs, csv))| match chunk {
            None => format!(
                "<layer id=\"{}\" name=\"{name}\" width=\"{w}\" height=\"{h}\" {attrs}><data encoding=\"csv\">{csv}</data></layer>\n",
                i + 1
            ),
            Some((cx, cy)) => format!(
                "<layer id=\"{}\" name=\"{name}\" width=\"{w}\" height=\"{h}\" {attrs}><data encoding=\"csv\"><chunk x=\"{cx}\" y=\"{cy}\" width=\"{w}\" height=\"{h}\">{csv}</chunk></data></layer>\n",
                i + 1
            ),
        })
        .collect();
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<map version="1.10" orientation="orthogonal" renderorder="right-down" width="{w}" height="{h}" tilewidth="16" tileheight="16" infinite="{inf}">
 <tileset firstgid="1" name="shapes" tilewidth="16" tileheight="16" tilecount="16" columns="4">
  <image source="shapes.png" width="64" height="64"/>
{tiles} </tileset>
{layers} <objectgroup id="99" name="things"><object id="1" name="spawn" x="0" y="0" width="16" height="16"/></objectgroup>
</map>"#,
        inf = chunk.is_some() as u8
    )
}

fn csv(gids: &[u32]) -> String {
    gids.iter()
        .map(|g| g.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

fn load(text: &str) -> LoadedLevel {
    tmx::load_str("maps/test.tmx", text, &LoadOptions::default()).unwrap()
}

fn rect(x: f32, y: f32, w: f32, h: f32) -> String {
    format!(
        "<objectgroup draworder=\"index\"><object id=\"1\" x=\"{x}\" y=\"{y}\" width=\"{w}\" height=\"{h}\"/></objectgroup>"
    )
}

fn polygon(points: &str) -> String {
    format!(
        "<objectgroup draworder=\"index\"><object id=\"1\" x=\"0\" y=\"0\"><polygon points=\"{points}\"/></object></objectgroup>"
    )
}

/// Blocks and polygons as absolute vertex lists (units), sorted.
fn solids(l: &LoadedLevel) -> Vec<Vec<IVec2>> {
    let mut out: Vec<Vec<IVec2>> = l
        .level
        .entities
        .iter()
        .filter_map(|e| match &e.kind {
            EntityKind::Block => {
                let (a, b) = (e.pos - e.size / 2, e.pos + e.size / 2);
                Some(vec![a, IVec2::new(b.x, a.y), b, IVec2::new(a.x, b.y)])
            }
            EntityKind::PolygonBlock { vertices } => {
                Some(vertices.iter().map(|v| *v + e.pos).collect())
            }
            _ => None,
        })
        .map(|mut v: Vec<IVec2>| {
            v.sort_by_key(|p| (p.x, p.y));
            v
        })
        .collect();
    out.sort_by_key(|v| (v[0].x, v[0].y));
    out
}

const PX: i32 = 256;

#[test]
fn tile_outlines_become_tiles_slopes_or_geometry() {
    let tiles = [
        (0, rect(0.0, 0.0, 16.0, 16.0)),             // full square
        (1, polygon("0,16 16,0 16,16")),             // `/` slope
        (2, rect(0.0, 8.0, 16.0, 8.0)),              // bottom half
        (3, polygon("0,16 16,8 16,16")),             // 22.5 degrees, low half
        (4, String::new()),                          // no collision
        (5, polygon("0,0 16,0 16,16 8,16 8,8 0,8")), // concave (an L)
    ];
    let tiles: Vec<(u32, &str)> = tiles.iter().map(|(i, s)| (*i, s.as_str())).collect();
    // Row 1: square, slope, slope flipped horizontally, half, 22.5, empty
    // tile, L, slope flipped vertically (a ceiling).
    let row = [1, 2, 2 | H, 3, 4, 5, 6, 2 | V];
    let mut gids = vec![0; 8];
    gids.extend(row);
    let l = load(&map(8, 2, &tiles, &[("Ground", "", csv(&gids))], None));
    let m = &l.level.tilemap;
    let at = |c| m.tile(IVec2::new(c, 1));
    assert_eq!(at(0), Tile::Solid);
    assert_eq!(at(1), Tile::Slope(Slope::Right45));
    assert_eq!(at(2), Tile::Slope(Slope::Left45));
    assert_eq!(at(3), Tile::Empty);
    assert_eq!(at(4), Tile::Slope(Slope::RightLow22));
    assert_eq!(at(5), Tile::Empty);
    assert_eq!(at(6), Tile::Empty);
    assert_eq!(at(7), Tile::Empty);
    assert!(m.tiles()[..8].iter().all(|t| *t == Tile::Empty));
    let p = |x: i32, y: i32| IVec2::new(x, y) * PX;
    let sorted = |mut v: Vec<IVec2>| {
        v.sort_by_key(|p| (p.x, p.y));
        v
    };
    let s = solids(&l);
    // The half box on cell 3, the L in two convex pieces on cell 6, the
    // ceiling triangle on cell 7.
    assert_eq!(s.len(), 4, "{s:?}");
    assert!(s.contains(&sorted(vec![p(48, 24), p(64, 24), p(64, 32), p(48, 32)])));
    assert!(
        s.contains(&sorted(vec![p(112, 16), p(128, 16), p(128, 32)])),
        "{s:?}"
    );
    let l_area: i64 = s
        .iter()
        .filter(|v| v.iter().all(|q| (96 * PX..=112 * PX).contains(&q.x)))
        .map(|v| area(v))
        .sum();
    assert_eq!(
        l_area,
        3 * 64 * (PX as i64).pow(2),
        "the L's pieces cover it"
    );
}

/// Twice the area of a convex outline given in any order (sorted by
/// angle about its centre first).
fn area(v: &[IVec2]) -> i64 {
    let c = v.iter().fold(glam::DVec2::ZERO, |a, p| a + p.as_dvec2()) / v.len() as f64;
    let mut v = v.to_vec();
    v.sort_by(|a, b| {
        let (da, db) = (a.as_dvec2() - c, b.as_dvec2() - c);
        da.y.atan2(da.x).partial_cmp(&db.y.atan2(db.x)).unwrap()
    });
    let twice: i64 = (0..v.len())
        .map(|i| {
            let (a, b) = (v[i].as_i64vec2(), v[(i + 1) % v.len()].as_i64vec2());
            a.x * b.y - b.x * a.y
        })
        .sum();
    twice.abs() / 2
}

#[test]
fn properties_and_layers_say_what_collides() {
    let tiles = [
        (
            0,
            "<properties><property name=\"collides\" type=\"bool\" value=\"true\"/></properties>",
        ),
        (
            1,
            "<properties><property name=\"one-way\" type=\"bool\" value=\"true\"/></properties>",
        ),
        (
            2,
            "<properties><property name=\"deadly\" type=\"bool\" value=\"true\"/></properties>",
        ),
        (3, ""),
    ];
    // Layer "deco" has only silent tiles; layer "blocks" says it collides;
    // a hidden layer with the colliding tile collides nowhere.
    let a = csv(&[1, 2, 3, 4, 0, 0]);
    let b = csv(&[0, 0, 0, 0, 4, 0]);
    let hidden = csv(&[0, 0, 0, 0, 0, 1]);
    let l = load(&map(
        6,
        1,
        &tiles,
        &[
            ("deco", "", a),
            ("blocks", "", b),
            ("secret", "visible=\"0\"", hidden),
        ],
        None,
    ));
    let t = l.level.tilemap.tiles();
    // "blocks" has no property yet: its silent tile 4 is empty (the map
    // has collision data, so silent tiles are empty).
    assert_eq!(
        t,
        &[
            Tile::Solid,
            Tile::OneWay,
            Tile::Hazard,
            Tile::Empty,
            Tile::Empty,
            Tile::Empty
        ]
    );
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("layer \"secret\"") && w.contains("hidden tile layer")),
        "{:?}",
        l.warnings
    );
    // With `collision = true` on the layer, its silent tiles are solid.
    let text = map(
        6,
        1,
        &tiles,
        &[(
            "blocks",
            "",
            csv(&[0, 0, 0, 0, 4, 0]),
        )],
        None,
    )
    .replace(
        "name=\"blocks\" width=\"6\" height=\"1\" >",
        "name=\"blocks\" width=\"6\" height=\"1\" ><properties><property name=\"collision\" type=\"bool\" value=\"true\"/></properties>",
    );
    let l = load(&text);
    assert_eq!(l.level.tilemap.tiles()[4], Tile::Solid, "{text}");
}

#[test]
fn infinite_maps_take_the_chunks_extent() {
    let tiles = [(
        0,
        "<properties><property name=\"solid\" type=\"bool\" value=\"true\"/></properties>",
    )];
    // One 16 x 16 chunk at (-16, 32) tiles with a solid tile in its
    // top-left and bottom-right cells.
    let mut gids = vec![0u32; 256];
    gids[0] = 1;
    gids[255] = 1;
    let text = map(
        16,
        16,
        &tiles,
        &[("Ground", "", csv(&gids))],
        Some((-16, 32)),
    );
    let l = load(&text);
    let m = &l.level.tilemap;
    assert_eq!((m.width(), m.height()), (16, 16));
    assert_eq!(m.origin(), IVec2::new(-16 * 16 * PX, 32 * 16 * PX));
    assert_eq!(m.tile(IVec2::new(0, 0)), Tile::Solid);
    assert_eq!(m.tile(IVec2::new(15, 15)), Tile::Solid);
    assert_eq!(m.tiles().iter().filter(|t| **t != Tile::Empty).count(), 2);
}

#[test]
fn unnamed_shapes_are_solid_and_markers_are_said() {
    // An unnamed polyline (a chain over the ground, drawn left to right),
    // an unnamed ellipse, and an unnamed point.
    let objects = r#"<object id="2" x="0" y="32"><polyline points="0,0 32,0 48,-16"/></object>
  <object id="3" x="64" y="0" width="16" height="16"><ellipse/></object>
  <object id="4" x="100" y="10"><point/></object>"#;
    let text = map(8, 4, &[], &[("Ground", "", csv(&[0; 32]))], None).replace(
        "</objectgroup>\n</map>",
        &format!("{objects}</objectgroup>\n</map>"),
    );
    let l = load(&text);
    let s = solids(&l);
    // Two legs, each a quad 2 px thick below the line; the ellipse an
    // octagon (one convex polygon of 8 points).
    assert_eq!(s.len(), 3, "{s:?}");
    let p = |x: i32, y: i32| IVec2::new(x, y) * PX;
    assert!(
        s.contains(&vec![p(0, 32), p(0, 34), p(32, 32), p(32, 34)]),
        "{s:?}"
    );
    assert!(s.iter().any(|v| v.len() == 8
        && v.iter()
            .all(|q| (64 * PX..=80 * PX).contains(&q.x) && (0..=16 * PX).contains(&q.y))));
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("object 4") && w.contains("markers and labels")),
        "{:?}",
        l.warnings
    );
}
