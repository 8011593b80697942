//! The OGMO Editor 3 model the importer decodes into: the project's
//! definitions ([`Project`]) and a level's layers ([`OgmoLevel`]).
//!
//! Kept apart from the parser ([`super`]) so that the level's art
//! (`crate::art::ogmo`) reads these types without depending on the
//! importer that builds them: the importer sits on top of the art.

use glam::IVec2;

use crate::entities::PlacedEntity;

/// An OGMO project: only what the loader uses.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Project {
    /// The project's name.
    pub name: String,
    /// Layer definitions.
    pub layers: Vec<ProjectLayer>,
    /// Entity definitions.
    pub entities: Vec<ProjectEntity>,
    /// Tilesets.
    pub tilesets: Vec<ProjectTileset>,
    /// `backgroundColor` (`#rrggbbaa`), empty when absent.
    pub background_color: String,
}

/// A layer definition of a [`Project`].
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ProjectLayer {
    /// `name`.
    pub name: String,
    /// `definition`: `tile`, `grid`, `entity` or `decal`.
    pub definition: String,
    /// `exportID` (the level layer's `_eid`).
    pub export_id: String,
    /// `defaultTileset`, for tile layers.
    pub default_tileset: String,
}

/// An entity definition of a [`Project`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ProjectEntity {
    /// `name`.
    pub name: String,
    /// `exportID` (the level entity's `_eid`).
    pub export_id: String,
    /// Default size, pixels.
    pub size: (f64, f64),
    /// Default origin, pixels from the top-left corner.
    pub origin: (f64, f64),
}

/// A tileset of a [`Project`].
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ProjectTileset {
    /// `label` (what tile layers name).
    pub label: String,
    /// Tile width, pixels.
    pub tile_width: u32,
    /// Tile height, pixels.
    pub tile_height: u32,
    /// Tiles per row, when the embedded image's width could be read.
    pub columns: Option<u32>,
    /// `tileMarginX`, pixels.
    pub margin: u32,
    /// `tileSeparationX`, pixels.
    pub spacing: u32,
    /// `path`: the image file the tileset was made from.
    pub path: String,
    /// `image`: the embedded image, a `data:image/png;base64,` URI.
    pub image: String,
}

/// A decoded OGMO level: layers in file order, positions still per layer.
#[derive(Debug, Clone, PartialEq)]
pub struct OgmoLevel {
    /// Level `offsetX`, `offsetY`, pixels.
    pub offset: (f64, f64),
    /// Every layer, in file order.
    pub layers: Vec<OgmoLayer>,
    /// Tolerated irregularities, one line each (short 2D rows).
    pub warnings: Vec<String>,
}

/// One decoded layer.
#[derive(Debug, Clone, PartialEq)]
pub struct OgmoLayer {
    /// `name`.
    pub name: String,
    /// Path in the file: `layers[i]`.
    pub field: String,
    /// World position of the layer's top-left corner, in units (level and
    /// layer offsets).
    pub origin: IVec2,
    /// `gridCellWidth`, `gridCellHeight`, pixels.
    pub cell: (u32, u32),
    /// `gridCellsX`, `gridCellsY`.
    pub cells: (u32, u32),
    /// The layer's content.
    pub content: LayerContent,
}

/// What a layer holds.
#[derive(Debug, Clone, PartialEq)]
pub enum LayerContent {
    /// Tile ids, row-major, `-1` empty (coordinates already turned into ids).
    Tiles {
        /// The tileset's label.
        tileset: String,
        /// The field the ids came from (`data`, `data2D`, `dataCoords`,
        /// `dataCoords2D`).
        key: &'static str,
        /// One id per cell, row-major.
        ids: Vec<i32>,
    },
    /// Grid values, row-major.
    Grid {
        /// The field the values came from (`grid` or `grid2D`).
        key: &'static str,
        /// One value per cell, row-major.
        values: Vec<String>,
    },
    /// Entities, converted to centres and sizes in units.
    Entities(Vec<PlacedEntity>),
    /// A decal layer (ignored).
    Decals,
}
