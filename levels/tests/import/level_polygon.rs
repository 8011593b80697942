//! Polygon solids in level files: Tiled polygon objects and OGMO polygon
//! entities become [`EntityKind::PolygonBlock`]s; bad outlines (concave,
//! degenerate, too many vertices, out of bounds) are refused with an error
//! naming the file and the field; a player stands on and walks along a
//! polygon ramp.

use crate::platformer_kit;

use glam::IVec2;
use ledge_levels::{
    default_level, default_route, load_file, ogmo, tmx, EntityDef, EntityKind, Level, LevelError,
    LoadOptions, LoadedLevel,
};
use ledge_shared::fixed::px;
use ledge_shared::game::{EntityType, Game, GameError};
use ledge_shared::shape::ConvexPolygon;
use ledge_shared::world::AnyShape;
use platformer_kit::{Sim, LEFT, NONE, RIGHT};

const TILED_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/levels/tiled");
const RAMP_TMX: &str = include_str!("../fixtures/levels/tiled/ramp.tmx");
/// The ramp's points in `ramp.tmx`, which tests replace.
const RAMP_POINTS: &str = r#"<polygon points="0,0 64,-16 64,0"/>"#;

fn v(x: i32, y: i32) -> IVec2 {
    IVec2::new(px(x), px(y))
}

fn ramp_file() -> String {
    format!("{TILED_DIR}/ramp.tmx")
}

/// `ramp.tmx` with the ramp's `<polygon .../>` replaced by `polygon`.
fn tiled_with(polygon: &str) -> Result<LoadedLevel, LevelError> {
    assert!(RAMP_TMX.contains(RAMP_POINTS));
    let text = RAMP_TMX.replacen(RAMP_POINTS, polygon, 1);
    tmx::load_str(&ramp_file(), &text, &LoadOptions::default())
}

/// A 20 x 8 OGMO level (floor at row 6, as in `ramp.tmx`) with a spawn and
/// `entities_json` after it.
fn ogmo_level(entities_json: &str) -> String {
    let mut rows = Vec::new();
    for r in 0..8 {
        let row: Vec<&str> = (0..20)
            .map(|c| {
                if r == 0 || r >= 6 || c == 0 || c == 19 {
                    "1"
                } else {
                    "-1"
                }
            })
            .collect();
        rows.push(format!("[{}]", row.join(", ")));
    }
    format!(
        r#"{{"ogmoVersion": "3.3.0", "width": 320, "height": 128, "layers": [
            {{"name": "tiles", "gridCellWidth": 16, "gridCellHeight": 16,
              "gridCellsX": 20, "gridCellsY": 8, "tileset": "ledge",
              "data2D": [{}], "exportMode": 0, "arrayMode": 1}},
            {{"name": "things", "gridCellWidth": 8, "gridCellHeight": 8,
              "gridCellsX": 40, "gridCellsY": 16, "entities": [
                {{"name": "player", "x": 32, "y": 80, "width": 16, "height": 16}}{entities_json}
            ]}}
        ]}}"#,
        rows.join(", ")
    )
}

const OGMO_FILE: &str = "levels/ramp.json";

fn ogmo_with(entities_json: &str) -> Result<LoadedLevel, LevelError> {
    ogmo::load_str(
        OGMO_FILE,
        &ogmo_level(entities_json),
        None,
        &LoadOptions::default(),
    )
}

/// The OGMO twin of the ramp in `ramp.tmx`: position (96, 96) px, nodes
/// (160, 80) and (160, 96), in a layer offset by `offset` px.
fn ogmo_ramp(nodes: &str) -> String {
    format!(r#", {{"name": "ramp", "x": 96, "y": 96, "nodes": [{nodes}]}}"#)
}
const RAMP_NODES: &str = r#"{"x": 160, "y": 80}, {"x": 160, "y": 96}"#;

/// The error, after checking that its message starts with the file and
/// names `field` and contains `words`.
fn refused(r: Result<LoadedLevel, LevelError>, file: &str, field: &str, words: &str) -> LevelError {
    let e = r.expect_err("should be refused");
    let msg = e.to_string();
    assert!(msg.starts_with(&format!("{file}: ")), "{msg}");
    assert_eq!(e.file(), file);
    assert!(
        e.field().is_some_and(|f| f.contains(field)),
        "{msg}: field should name {field}"
    );
    assert!(msg.contains(words), "{msg}: should say {words:?}");
    e
}

/// The polygon blocks of a level: `(pos, size, vertices)`.
fn polygons(level: &Level) -> Vec<(IVec2, IVec2, Vec<IVec2>)> {
    level
        .entities
        .iter()
        .filter_map(|e| match &e.kind {
            EntityKind::PolygonBlock { vertices } => Some((e.pos, e.size, vertices.clone())),
            _ => None,
        })
        .collect()
}

/// The ramp as both loaders should give it: centred on its bounding box.
fn expected_ramp() -> (IVec2, IVec2, Vec<IVec2>) {
    (v(128, 88), v(64, 16), vec![v(-32, 8), v(32, -8), v(32, 8)])
}

#[test]
fn tiled_polygon_objects_become_polygon_blocks_and_rectangles_stay_boxes() {
    let level = load_file(ramp_file()).unwrap();
    let polys = polygons(&level);
    assert_eq!(polys.len(), 2, "{:?}", level.entities);
    assert_eq!(polys[0], expected_ramp());
    // The unnamed wedge, rotated 90 degrees clockwise about (240, 32):
    // (0, 0) (16, 0) (0, 16) -> (240, 32) (240, 48) (224, 32).
    assert_eq!(
        polys[1],
        (v(232, 40), v(16, 16), vec![v(8, -8), v(8, 8), v(-8, -8)])
    );
    assert!(level.entities.contains(&EntityDef {
        kind: EntityKind::Block,
        pos: v(264, 88),
        size: v(16, 16),
    }));
    assert!(level.features().blocks);
    // Every polygon the loader accepts is one the simulation accepts.
    for (_, size, vs) in &polys {
        assert!(ConvexPolygon::new(vs).is_ok());
        for p in vs {
            assert!(p.x.abs() <= size.x / 2 && p.y.abs() <= size.y / 2);
        }
    }
}

#[test]
fn ogmo_polygon_entities_take_their_position_and_nodes_as_vertices() {
    let l = ogmo_with(&ogmo_ramp(RAMP_NODES)).unwrap();
    assert_eq!(polygons(&l.level), vec![expected_ramp()]);
    // Both formats give the same level content.
    let t = load_file(ramp_file()).unwrap();
    assert_eq!(polygons(&l.level)[0], polygons(&t)[0]);
    // Layer offsets shift the vertices; size and origin do not matter.
    let text = ogmo_level(&format!(
        r#", {{"name": "Polygon", "x": 96, "y": 96, "width": 99, "originX": 7,
              "nodes": [{RAMP_NODES}]}}"#
    ))
    .replace(
        r#""name": "things","#,
        r#""name": "things", "offsetX": 8, "offsetY": -4,"#,
    );
    let l = ogmo::load_str(OGMO_FILE, &text, None, &LoadOptions::default()).unwrap();
    let (pos, size, vs) = &polygons(&l.level)[0];
    assert_eq!(
        (*pos, *size, vs),
        (v(136, 84), v(64, 16), &expected_ramp().2)
    );
}

#[test]
fn concave_polygons_are_refused_naming_the_vertex() {
    // Vertex 3 (128, 88) px points inwards.
    refused(
        tiled_with(r#"<polygon points="0,0 64,0 64,-32 32,-8"/>"#),
        &ramp_file(),
        r#"layers[1].objects[1].polygon[3] (object 7 "ramp")"#,
        "polygon is concave at vertex 3 (128, 88) px",
    );
    refused(
        ogmo_with(&ogmo_ramp(
            r#"{"x": 160, "y": 96}, {"x": 160, "y": 64}, {"x": 128, "y": 88}"#,
        )),
        OGMO_FILE,
        "layers[1].entities[1].nodes[2]",
        "polygon is concave at vertex 3 (128, 88) px",
    );
    // A bow tie (self-intersecting) is not convex either.
    refused(
        tiled_with(r#"<polygon points="0,0 64,-16 64,0 0,-16"/>"#),
        &ramp_file(),
        "polygon",
        "concave",
    );
}

#[test]
fn degenerate_polygons_are_refused_naming_the_vertex() {
    let f = ramp_file();
    // A repeated vertex.
    refused(
        tiled_with(r#"<polygon points="0,0 64,-16 64,-16 64,0"/>"#),
        &f,
        "polygon[2]",
        "degenerate: vertex 2 (160, 80) px repeats vertex 1",
    );
    refused(
        ogmo_with(&ogmo_ramp(r#"{"x": 96, "y": 96}, {"x": 160, "y": 96}"#)),
        OGMO_FILE,
        "layers[1].entities[1].nodes[0]",
        "degenerate: vertex 1 (96, 96) px repeats vertex 0",
    );
    // Three collinear vertices (a straight corner).
    refused(
        tiled_with(r#"<polygon points="0,0 32,-8 64,-16 64,0"/>"#),
        &f,
        "polygon[1]",
        "degenerate at vertex 1 (128, 88) px",
    );
    // Zero area: every vertex on one line.
    refused(
        tiled_with(r#"<polygon points="0,0 32,-8 64,-16"/>"#),
        &f,
        "polygon[1]",
        "zero area",
    );
    refused(
        ogmo_with(&ogmo_ramp(r#"{"x": 128, "y": 96}, {"x": 160, "y": 96}"#)),
        OGMO_FILE,
        "nodes[0]",
        "degenerate at vertex 1 (128, 96) px",
    );
    // Points closer than a unit apart round onto each other.
    refused(
        tiled_with(r#"<polygon points="0,0 64,-16 64.001,-16 64,0"/>"#),
        &f,
        "polygon[2]",
        "repeats vertex 1",
    );
}

#[test]
fn vertex_counts_outside_3_to_8_are_refused() {
    let f = ramp_file();
    // Nine vertices of a convex outline (more than a ConvexPolygon holds).
    let nine = "0,0 8,-6 20,-12 36,-16 52,-15 62,-10 66,-4 66,0 40,4";
    let e = refused(
        tiled_with(&format!(r#"<polygon points="{nine}"/>"#)),
        &f,
        r#"layers[1].objects[1].polygon (object 7 "ramp")"#,
        "polygon has 9 vertices; it needs 3 to 8",
    );
    assert!(matches!(e, LevelError::BadPolygon { .. }), "{e:?}");
    refused(
        tiled_with(r#"<polygon points="0,0 64,-16"/>"#),
        &f,
        "polygon (object 7",
        "polygon has 2 vertices",
    );
    let nodes: Vec<String> = (1..=8)
        .map(|i| format!(r#"{{"x": {}, "y": {}}}"#, 96 + 8 * i, 96 - i * i))
        .collect();
    refused(
        ogmo_with(&ogmo_ramp(&nodes.join(", "))),
        OGMO_FILE,
        "layers[1].entities[1].nodes",
        "polygon has 9 vertices",
    );
    // A polygon entity without nodes has one vertex.
    refused(
        ogmo_with(r#", {"name": "polygon", "x": 96, "y": 96}"#),
        OGMO_FILE,
        "layers[1].entities[1].nodes",
        "polygon has 1 vertices",
    );
    // A huge node list is refused without converting it all.
    let many = vec![r#"{"x": 1, "y": 1}"#; 100_000].join(", ");
    refused(
        ogmo_with(&ogmo_ramp(&many)),
        OGMO_FILE,
        "nodes",
        "polygon has 100001 vertices",
    );
}

#[test]
fn out_of_bounds_polygons_are_refused() {
    let f = ramp_file();
    // A vertex outside the world.
    let e = refused(
        tiled_with(r#"<polygon points="0,0 64,-16 90000000,0"/>"#),
        &f,
        r#"layers[1].objects[1].polygon[2] (object 7 "ramp").x"#,
        "outside the world bound",
    );
    assert!(matches!(e, LevelError::OutOfBounds { .. }), "{e:?}");
    refused(
        tiled_with(r#"<polygon points="0,0 64,-16 nan,0"/>"#),
        &f,
        "polygon",
        "",
    );
    refused(
        ogmo_with(&ogmo_ramp(r#"{"x": 160, "y": -1e12}, {"x": 160, "y": 96}"#)),
        OGMO_FILE,
        "layers[1].entities[1].nodes[0].y",
        "outside the world bound",
    );
    // Inside the world, but wider than a shape may be (each vertex within
    // 524288 px of the centre).
    let e = refused(
        tiled_with(r#"<polygon points="0,0 1100000,-16 1100000,0"/>"#),
        &f,
        r#"polygon (object 7 "ramp")"#,
        "polygon spans 1100000 x 16 px",
    );
    assert!(matches!(e, LevelError::OutOfBounds { .. }), "{e:?}");
}

#[test]
fn polygons_of_other_kinds_are_refused() {
    // A polygon object named as something that is not a solid.
    let text = RAMP_TMX.replacen(r#"name="ramp""#, r#"name="lift" class="platform""#, 1);
    refused(
        tmx::load_str(&ramp_file(), &text, &LoadOptions::default()),
        &ramp_file(),
        r#"polygon (object 7 "platform")"#,
        "moving polygon platforms are not supported",
    );
    // A rectangle named as a polygon has no vertices.
    let text = RAMP_TMX.replacen(r#"class="block""#, r#"class="polygon""#, 1);
    refused(
        tmx::load_str(&ramp_file(), &text, &LoadOptions::default()),
        &ramp_file(),
        "layers[1].objects[2]",
        "a polygon block needs vertices",
    );
}

#[test]
fn a_game_refuses_a_bad_polygon_instead_of_panicking() {
    let mut level = load_file(ramp_file()).unwrap();
    for e in &mut level.entities {
        if let EntityKind::PolygonBlock { vertices } = &mut e.kind {
            vertices.swap(0, 1);
            vertices.push(IVec2::ZERO);
        }
    }
    let e = Game::from_level(&level).unwrap_err();
    assert!(
        matches!(&e, GameError::BadLevel { message, .. } if message.contains("polygon")),
        "{e}"
    );
    let mut level = load_file(ramp_file()).unwrap();
    for e in &mut level.entities {
        if let EntityKind::PolygonBlock { vertices } = &mut e.kind {
            vertices.extend([IVec2::ONE; 20]);
        }
    }
    assert!(Game::from_level(&level).is_err());
}

#[test]
fn the_game_builds_polygon_blocks_as_static_polygon_colliders() {
    let level = load_file(ramp_file()).unwrap();
    let game = Game::from_level(&level).unwrap();
    let views: Vec<_> = game
        .entities()
        .filter(|e| e.ty == EntityType::PolygonBlock)
        .collect();
    assert_eq!(views.len(), 2);
    assert_eq!((views[0].pos, views[0].half), (v(128, 88), v(32, 8)));
    let (_, _, vs) = expected_ramp();
    let ramp = ConvexPolygon::new(&vs).unwrap();
    assert!(game
        .world()
        .colliders()
        .any(|c| c.shape == AnyShape::Polygon(ramp)));
}

/// Surface height of the ramp (units) at x (units): from (96, 96) px up
/// to (160, 80) px.
fn ramp_surface(x: i32) -> i32 {
    px(96) - (x - px(96)) / 4
}

#[test]
fn a_player_walks_up_a_polygon_ramp_and_stands_on_it() {
    for level in [
        load_file(ramp_file()).unwrap(),
        ogmo_with(&ogmo_ramp(RAMP_NODES)).unwrap().level,
    ] {
        let mut s = Sim::new(&level);
        s.land(60);
        let start = s.view();
        assert_eq!(start.pos.y + start.half.y, px(96), "on the floor");
        // Walk right until the box's leading corner is over the ramp.
        let mut on_ramp = 0;
        let mut last = start;
        for _ in 0..200 {
            s.step(RIGHT);
            let p = s.view();
            let corner = p.pos.x + p.half.x;
            if corner > px(100) && corner < px(136) {
                on_ramp += 1;
                // The box's bottom right corner rests on the slanted surface
                // (within the rounding of a slanted push), grounded, and the
                // player moves along the surface: right and up.
                assert!(p.grounded, "{p:?}");
                let gap = p.pos.y + p.half.y - ramp_surface(corner);
                assert!(gap.abs() <= 4, "gap {gap} at x {corner}: {p:?}");
                assert!(p.pos.x > last.pos.x && p.pos.y < last.pos.y, "{p:?}");
            }
            last = p;
            if corner >= px(136) {
                break;
            }
        }
        assert!(on_ramp > 10, "{on_ramp} ticks on the ramp");
        assert!(last.pos.y + last.half.y < px(87), "climbed: {last:?}");
        // Let go: it brakes and stays on the surface, grounded, and once
        // stopped stays put (a walkable face does not let it slide).
        let mut stopped = None;
        for t in 0..60 {
            s.step(NONE);
            let p = s.view();
            let corner = p.pos.x + p.half.x;
            assert!(corner < px(160), "still on the slope: {p:?}");
            assert!(p.grounded, "{p:?}");
            let gap = p.pos.y + p.half.y - ramp_surface(corner);
            assert!(gap.abs() <= 4, "gap {gap}: {p:?}");
            if t == 20 {
                stopped = Some(p.pos);
            } else if let Some(at) = stopped {
                assert_eq!(p.pos, at, "slid: {p:?}");
            }
        }
        // Walks back down it at full speed without leaving it, onto the
        // floor.
        let mut last = s.view();
        for _ in 0..40 {
            s.step(LEFT);
            let p = s.view();
            assert!(p.grounded, "{p:?}");
            assert!(p.pos.x < last.pos.x && p.pos.y >= last.pos.y, "{p:?}");
            last = p;
        }
        assert_eq!(last.pos.y + last.half.y, px(96), "{last:?}");
        assert!(last.pos.x + last.half.x < px(96), "{last:?}");
        // And walks up and on over the top, down onto the floor beyond it.
        s.run(RIGHT, 90);
        let p = s.view();
        assert!(p.pos.x - p.half.x > px(160), "{p:?}");
        assert!(p.grounded && p.pos.y + p.half.y == px(96), "{p:?}");
    }
}

#[test]
fn the_default_level_has_a_polygon_solid_off_the_route() {
    let level = default_level();
    let polys = polygons(&level);
    assert_eq!(polys.len(), 1, "one polygon solid");
    let (pos, size, vs) = &polys[0];
    assert!(ConvexPolygon::new(vs).is_ok());
    // No route waypoint is near it (the runner never touches it).
    for w in default_route() {
        let d = (w.foot - *pos).abs();
        assert!(
            d.x > size.x / 2 + px(32) || d.y > size.y / 2 + px(32),
            "waypoint {w:?} next to the polygon at {pos}"
        );
    }
    let game = Game::from_level(&level).unwrap();
    assert!(game
        .world()
        .colliders()
        .any(|c| matches!(c.shape, AnyShape::Polygon(_))));
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

    /// Any outline, in either format: the loader refuses it with an error
    /// naming the file and the polygon (never a panic), or accepts it, and
    /// then the shape is a valid convex polygon the game builds.
    #[test]
    fn any_outline_is_refused_by_name_or_accepted_and_built(
        pts in proptest::collection::vec((-40i32..=40, -40i32..=40), 0..11),
        scale in proptest::prop_oneof![proptest::strategy::Just(1i64), proptest::strategy::Just(300_000i64)],
        ogmo_format in proptest::bool::ANY,
    ) {
        let pts: Vec<(i64, i64)> = pts.iter().map(|&(x, y)| (x as i64 * scale, y as i64 * scale)).collect();
        let r = if ogmo_format {
            let mut e = String::from(r#", {"name": "polygon""#);
            if let Some((x, y)) = pts.first() {
                e += &format!(r#", "x": {}, "y": {}"#, 96 + x, 48 + y);
            } else {
                e += r#", "x": 96, "y": 48"#;
            }
            let nodes: Vec<String> = pts.iter().skip(1)
                .map(|(x, y)| format!(r#"{{"x": {}, "y": {}}}"#, 96 + x, 48 + y))
                .collect();
            e += &format!(r#", "nodes": [{}]}}"#, nodes.join(", "));
            ogmo_with(&e)
        } else {
            let p: Vec<String> = pts.iter().map(|(x, y)| format!("{x},{y}")).collect();
            tiled_with(&format!(r#"<polygon points="{}"/>"#, p.join(" ")))
        };
        match r {
            Ok(l) => {
                let polys = polygons(&l.level);
                let own = if ogmo_format { 1 } else { 2 };
                proptest::prop_assert_eq!(polys.len(), own);
                for (_, _, vs) in &polys {
                    proptest::prop_assert!(ConvexPolygon::new(vs).is_ok());
                }
                proptest::prop_assert!(Game::from_level(&l.level).is_ok());
            }
            // The tiled crate itself refuses an empty `points` attribute.
            Err(LevelError::Syntax { file, field, .. }) if !ogmo_format && pts.is_empty() => {
                proptest::prop_assert_eq!((file, field.as_str()), (ramp_file(), "map"));
            }
            Err(e) => {
                let file = if ogmo_format { OGMO_FILE.to_owned() } else { ramp_file() };
                proptest::prop_assert_eq!(e.file(), file.as_str());
                proptest::prop_assert!(
                    matches!(e, LevelError::BadPolygon { .. } | LevelError::OutOfBounds { .. }),
                    "{e}"
                );
                let field = e.field().unwrap_or_default().to_owned();
                proptest::prop_assert!(
                    field.contains("polygon") || field.contains("entities[1]"),
                    "{e}"
                );
            }
        }
    }
}
