//! The parts of an LDtk 1.5 project (`.ldtk`) and level (`.ldtkl`) the
//! importer reads, as `serde` structs (every other field is skipped), and
//! the small helpers its modules share: parsing a document within the
//! bounds, and errors naming the file and the field.

use serde::Deserialize;
use serde_json::Value;

use crate::error::LevelError;
use crate::limits::check_json;

/// A project: its definitions and its levels (top level and in worlds).
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct Project {
    /// Layer and tileset definitions.
    pub defs: Defs,
    /// The levels of a single-world project.
    pub levels: Vec<Level>,
    /// The worlds of a multi-world project, each with its levels.
    pub worlds: Vec<World>,
    /// The project's background colour (`#rrggbb`).
    #[serde(rename = "bgColor")]
    pub bg_color: Option<String>,
}

/// A world of a multi-world project.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct World {
    /// Its levels.
    pub levels: Vec<Level>,
}

/// Only the level identifiers of a project: what [`super::level_names`]
/// reads (the rest of the document is skipped, not built).
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct Names {
    /// The top-level levels.
    pub levels: Vec<NameOnly>,
    /// The worlds' levels.
    pub worlds: Vec<WorldNames>,
}

/// A world's level identifiers.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct WorldNames {
    /// Its levels.
    pub levels: Vec<NameOnly>,
}

/// A level's identifier.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct NameOnly {
    /// The identifier.
    pub identifier: String,
}

/// The project's definitions.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct Defs {
    /// Layer definitions (IntGrid values by layer).
    pub layers: Vec<LayerDef>,
    /// Tileset definitions.
    pub tilesets: Vec<TilesetDef>,
}

/// A layer definition.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct LayerDef {
    /// Its uid (layer instances name it in `layerDefUid`).
    pub uid: i64,
    /// Its name.
    pub identifier: String,
    /// Its IntGrid values (IntGrid layers).
    #[serde(rename = "intGridValues")]
    pub int_grid_values: Vec<IntGridValueDef>,
}

/// One IntGrid value of a layer definition.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct IntGridValueDef {
    /// The value (1 and up; 0 is an empty cell).
    pub value: i64,
    /// Its name, when it has one.
    pub identifier: Option<String>,
}

/// A tileset definition.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct TilesetDef {
    /// Its uid.
    pub uid: i64,
    /// Its name.
    pub identifier: String,
    /// Its image, relative to the project (none for LDtk's embedded icons).
    #[serde(rename = "relPath")]
    pub rel_path: Option<String>,
    /// Tile size, pixels.
    #[serde(rename = "tileGridSize")]
    pub tile_grid_size: i64,
    /// Pixels between tiles.
    pub spacing: i64,
    /// Pixels around the tiles.
    pub padding: i64,
}

/// A level (in the project, or the whole of an `.ldtkl` file).
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct Level {
    /// Its name (`Level_0`).
    pub identifier: String,
    /// Width, pixels.
    #[serde(rename = "pxWid")]
    pub px_wid: i64,
    /// Height, pixels.
    #[serde(rename = "pxHei")]
    pub px_hei: i64,
    /// Background colour (`#rrggbb`).
    #[serde(rename = "__bgColor")]
    pub bg_color: Option<String>,
    /// Background image, relative to the project.
    #[serde(rename = "bgRelPath")]
    pub bg_rel_path: Option<String>,
    /// Where the background image is drawn.
    #[serde(rename = "__bgPos")]
    pub bg_pos: Option<BgPos>,
    /// The level's own file, relative to the project (`null` when its
    /// layers are in the project).
    #[serde(rename = "externalRelPath")]
    pub external_rel_path: Option<String>,
    /// Its layers, top-most first (`null` in a project whose levels are
    /// in separate files).
    #[serde(rename = "layerInstances")]
    pub layer_instances: Option<Vec<LayerInstance>>,
}

/// How a level's background image is placed.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct BgPos {
    /// Top-left corner, pixels.
    #[serde(rename = "topLeftPx")]
    pub top_left_px: [f64; 2],
    /// Scale factors.
    pub scale: [f64; 2],
    /// The part of the image drawn: x, y, width, height.
    #[serde(rename = "cropRect")]
    pub crop_rect: [f64; 4],
}

/// A layer of a level.
#[derive(Debug, Deserialize)]
#[serde(default)]
pub(crate) struct LayerInstance {
    /// Its name.
    #[serde(rename = "__identifier")]
    pub identifier: String,
    /// `IntGrid`, `Entities`, `Tiles` or `AutoLayer`.
    #[serde(rename = "__type")]
    pub kind: String,
    /// Cells across.
    #[serde(rename = "__cWid")]
    pub c_wid: i64,
    /// Cells down.
    #[serde(rename = "__cHei")]
    pub c_hei: i64,
    /// Cell size, pixels.
    #[serde(rename = "__gridSize")]
    pub grid_size: i64,
    /// Opacity in `[0, 1]`.
    #[serde(rename = "__opacity")]
    pub opacity: f64,
    /// Offset from the level's corner (definition's and instance's), px.
    #[serde(rename = "__pxTotalOffsetX")]
    pub offset_x: i64,
    /// Offset down, px.
    #[serde(rename = "__pxTotalOffsetY")]
    pub offset_y: i64,
    /// The tileset its tiles are drawn from.
    #[serde(rename = "__tilesetDefUid")]
    pub tileset_uid: Option<i64>,
    /// Another tileset chosen for this level.
    #[serde(rename = "overrideTilesetUid")]
    pub override_tileset_uid: Option<i64>,
    /// Its definition.
    #[serde(rename = "layerDefUid")]
    pub layer_def_uid: Option<i64>,
    /// Shown in the editor.
    pub visible: bool,
    /// IntGrid values, row-major (0: empty).
    #[serde(rename = "intGridCsv")]
    pub int_grid_csv: Vec<i64>,
    /// Tiles the auto-layer rules placed, bottom first.
    #[serde(rename = "autoLayerTiles")]
    pub auto_layer_tiles: Vec<TileInstance>,
    /// Tiles placed by hand (tile layers), bottom first.
    #[serde(rename = "gridTiles")]
    pub grid_tiles: Vec<TileInstance>,
    /// Entities (entity layers).
    #[serde(rename = "entityInstances")]
    pub entity_instances: Vec<EntityInstance>,
}

impl Default for LayerInstance {
    fn default() -> Self {
        Self {
            identifier: String::new(),
            kind: String::new(),
            c_wid: 0,
            c_hei: 0,
            grid_size: 16,
            opacity: 1.0,
            offset_x: 0,
            offset_y: 0,
            tileset_uid: None,
            override_tileset_uid: None,
            layer_def_uid: None,
            visible: true,
            int_grid_csv: Vec::new(),
            auto_layer_tiles: Vec::new(),
            grid_tiles: Vec::new(),
            entity_instances: Vec::new(),
        }
    }
}

impl LayerInstance {
    /// Its tiles (auto-layer tiles, else hand-placed ones), bottom first,
    /// and the key they are under in the file.
    pub fn tiles(&self) -> (&[TileInstance], &'static str) {
        if self.auto_layer_tiles.is_empty() {
            (&self.grid_tiles, "gridTiles")
        } else {
            (&self.auto_layer_tiles, "autoLayerTiles")
        }
    }
}

/// A placed tile.
#[derive(Debug, Deserialize)]
#[serde(default)]
pub(crate) struct TileInstance {
    /// Top-left corner in the layer, pixels.
    pub px: [i64; 2],
    /// Top-left corner in the tileset image, pixels.
    pub src: [i64; 2],
    /// Flip bits: 1 mirrored across, 2 mirrored down.
    pub f: i64,
    /// Opacity in `[0, 1]`.
    pub a: f64,
}

impl Default for TileInstance {
    fn default() -> Self {
        Self {
            px: [0, 0],
            src: [0, 0],
            f: 0,
            a: 1.0,
        }
    }
}

/// A placed entity.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct EntityInstance {
    /// Its definition's name.
    #[serde(rename = "__identifier")]
    pub identifier: String,
    /// Where `px` is in its box: `[0, 0]` top-left, `[1, 1]` bottom-right.
    #[serde(rename = "__pivot")]
    pub pivot: [f64; 2],
    /// Width, pixels.
    pub width: f64,
    /// Height, pixels.
    pub height: f64,
    /// Its pivot's position in the layer, pixels.
    pub px: [f64; 2],
    /// Its fields.
    #[serde(rename = "fieldInstances")]
    pub field_instances: Vec<FieldInstance>,
}

/// One field of an entity.
#[derive(Debug, Default, Deserialize)]
#[serde(default)]
pub(crate) struct FieldInstance {
    /// Its name.
    #[serde(rename = "__identifier")]
    pub identifier: String,
    /// Its type: `Int`, `Float`, `Bool`, `String`, `Point`, `Array<Point>`,
    /// `LocalEnum.X`...
    #[serde(rename = "__type")]
    pub kind: String,
    /// Its value.
    #[serde(rename = "__value")]
    pub value: Value,
}

/// Parses an LDtk JSON document (`format` names it in errors) within
/// [`crate::limits::MAX_JSON_DEPTH`] and [`crate::limits::MAX_JSON_VALUES`],
/// checked before anything is built.
pub(crate) fn parse<T: serde::de::DeserializeOwned>(
    file: &str,
    text: &str,
    format: &'static str,
) -> Result<T, LevelError> {
    check_json(file, text)?;
    serde_json::from_str(text).map_err(|e| LevelError::Syntax {
        file: file.into(),
        field: format!("line {} column {}", e.line(), e.column()),
        format,
        message: e.to_string(),
    })
}

/// A value of the wrong kind or outside its range.
pub(crate) fn bad(file: &str, field: impl Into<String>, message: String) -> LevelError {
    LevelError::BadValue {
        file: file.into(),
        field: field.into(),
        message,
    }
}

/// A size beyond the level limits.
pub(crate) fn out_of_bounds(file: &str, field: impl Into<String>, message: String) -> LevelError {
    LevelError::OutOfBounds {
        file: file.into(),
        field: field.into(),
        message,
    }
}

/// A layer's cell size, checked: 1 to 4096 pixels.
pub(crate) fn grid_size(file: &str, field: &str, n: i64) -> Result<u32, LevelError> {
    if !(1..=4096).contains(&n) {
        return Err(out_of_bounds(
            file,
            format!("{field}.__gridSize"),
            format!("{n} px is not a cell size in [1, 4096] px"),
        ));
    }
    Ok(n as u32)
}

/// A layer's cell counts, checked: each in `[0, MAX_LEVEL_TILES]`.
pub(crate) fn cells(file: &str, field: &str, l: &LayerInstance) -> Result<(u32, u32), LevelError> {
    use crate::options::MAX_LEVEL_TILES;
    let mut out = [0u32; 2];
    for (i, (n, key)) in [(l.c_wid, "__cWid"), (l.c_hei, "__cHei")]
        .into_iter()
        .enumerate()
    {
        if !(0..=MAX_LEVEL_TILES as i64).contains(&n) {
            return Err(out_of_bounds(
                file,
                format!("{field}.{key}"),
                format!("{n} cells is outside [0, {MAX_LEVEL_TILES}]"),
            ));
        }
        out[i] = n as u32;
    }
    Ok((out[0], out[1]))
}

/// A layer's offset in pixels as units, within the world bound.
pub(crate) fn offset_units(
    file: &str,
    field: &str,
    l: &LayerInstance,
) -> Result<glam::IVec2, LevelError> {
    let x = crate::entities::px_to_units(
        file,
        &format!("{field}.__pxTotalOffsetX"),
        l.offset_x as f64,
    )?;
    let y = crate::entities::px_to_units(
        file,
        &format!("{field}.__pxTotalOffsetY"),
        l.offset_y as f64,
    )?;
    Ok(glam::IVec2::new(x as i32, y as i32))
}
