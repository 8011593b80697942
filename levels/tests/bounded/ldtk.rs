//! LDtk projects within the bounds, measured: counts and sizes are refused
//! before anything is built for them, at a small peak of heap memory.

use ledge_levels::limits::{MAX_JSON_VALUES, MAX_LDTK_ENTITIES, MAX_LEVEL_CELLS};
use ledge_levels::{ldtk, LevelError, LoadOptions};

use crate::peak::{measured, serial};

/// A project of one level `L` with these layer instances (JSON text).
fn project(layers: &str) -> String {
    format!(
        r#"{{"defs": {{"layers": [{{"uid": 1, "identifier": "Collisions", "intGridValues": [{{"value": 1, "identifier": "walls"}}]}}]}},
            "levels": [{{"identifier": "L", "pxWid": 64, "pxHei": 64, "layerInstances": [{layers}]}}]}}"#
    )
}

fn limit_of(r: Result<ledge_levels::LoadedLevel, LevelError>) -> (&'static str, String) {
    match r {
        Err(e @ LevelError::Limit { .. }) => {
            let LevelError::Limit { bound, .. } = &e else {
                unreachable!()
            };
            (bound, e.to_string())
        }
        other => panic!("expected a Limit error, got {other:?}"),
    }
}

#[test]
fn ldtk_cells_entities_and_values_are_bounded_before_building() {
    let _s = serial();
    let o = LoadOptions::default();
    // 4096 x 4096 cells claimed by a layer of four values: refused for
    // MAX_LEVEL_CELLS before its cells are built.
    let huge = project(
        r#"{"__identifier": "Collisions", "__type": "IntGrid", "__cWid": 4096, "__cHei": 4096, "__gridSize": 16, "layerDefUid": 1, "intGridCsv": [1, 1, 1, 1]}"#,
    );
    let (r, peak) = measured(|| ldtk::load_str("huge.ldtk", &huge, None, &o));
    let (bound, msg) = limit_of(r);
    assert_eq!(bound, "MAX_LEVEL_CELLS", "{msg}");
    assert!(msg.contains(&format!("16777216 IntGrid and collision cells in all layers is more than the limit of {MAX_LEVEL_CELLS}")), "{msg}");
    assert!(peak < 1 << 20, "refused before allocating: {peak}");
    // A tile layer of 4096 x 4096 cells drawn with one tile: the art's cell
    // bound, before the art layer's cells are allocated.
    let art = project(
        r#"{"__identifier": "T", "__type": "Tiles", "__cWid": 4096, "__cHei": 4096, "__gridSize": 16, "__tilesetDefUid": 9, "gridTiles": [{"px": [0, 0], "src": [0, 0]}]}"#,
    )
    .replacen(
        r#""defs": {"#,
        r#""defs": {"tilesets": [{"uid": 9, "identifier": "C", "relPath": "atlas/Cavernas_by_Adam_Saltsman.png", "tileGridSize": 8}], "#,
        1,
    );
    // Beside a copy of a sample's atlas, so that the layer is drawn.
    let atlas = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/testdata/levels/ldtk-samples/atlas/Cavernas_by_Adam_Saltsman.png"
    );
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(tmp.path().join("atlas")).unwrap();
    std::fs::copy(
        atlas,
        tmp.path().join("atlas/Cavernas_by_Adam_Saltsman.png"),
    )
    .unwrap();
    let p = tmp.path().join("art.ldtk");
    std::fs::write(&p, &art).unwrap();
    let (r, peak) = measured(|| ldtk::load_path(&p, None, &o));
    let msg = r.unwrap_err().to_string();
    assert!(msg.contains("(MAX_ART_CELLS)"), "{msg}");
    assert!(
        peak < 8 << 20,
        "refused before allocating the cells: {peak}"
    );
    // More entities than MAX_LDTK_ENTITIES: refused before any is placed.
    let one = r#"{"__identifier": "Coin", "width": 8, "height": 8, "px": [0, 0]}"#;
    let many = vec![one; MAX_LDTK_ENTITIES as usize + 1].join(",");
    let text = project(&format!(
        r#"{{"__identifier": "E", "__type": "Entities", "__gridSize": 16, "entityInstances": [{many}]}}"#
    ));
    let (r, _) = measured(|| ldtk::load_str("many.ldtk", &text, None, &o));
    assert_eq!(limit_of(r).0, "MAX_LDTK_ENTITIES");
    // More JSON values than MAX_JSON_VALUES: refused before parsing.
    let wide = format!(
        "{{\"levels\": [{}]}}",
        vec!["0"; MAX_JSON_VALUES as usize].join(",")
    );
    let (r, peak) = measured(|| ldtk::load_str("wide.ldtk", &wide, None, &o));
    assert_eq!(limit_of(r).0, "MAX_JSON_VALUES");
    assert!(
        peak < 1 << 20,
        "the count is checked before parsing: {peak}"
    );
}
