//! Why a level file was refused: every error names the file and the field.

use thiserror::Error;

/// A level file the loaders refuse. Every variant names the file (as given
/// to the loader) and, where there is one, the field, as a path into the
/// document: `layers[2].data`, `layers[3].entities[1].values.speed`, or for
/// Tiled `layers[1].objects[4].properties.speed`.
///
/// The messages read like `levels/uno.json: layers[2].data: expected 300
/// entries, got 299`.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum LevelError {
    /// The file could not be read.
    #[error("{file}: cannot read the file: {message}")]
    Io {
        /// The file.
        file: String,
        /// What the operating system said.
        message: String,
    },
    /// An extension no loader handles.
    #[error(
        "{file}: unsupported level format (expected .json from OGMO Editor 3, .tmx from Tiled or .ldtk from LDtk)"
    )]
    UnsupportedFormat {
        /// The file.
        file: String,
    },
    /// Not well-formed JSON or XML, or a document the Tiled reader refuses.
    #[error("{file}: {field}: malformed {format}: {message}")]
    Syntax {
        /// The file.
        file: String,
        /// Where: a line and column when known, else the part of the document.
        field: String,
        /// "JSON", "OGMO project JSON", "TMX", "LDtk project JSON" or "LDtk
        /// level JSON".
        format: &'static str,
        /// What the parser said.
        message: String,
    },
    /// A required field is absent.
    #[error("{file}: {field}: missing{hint}")]
    Missing {
        /// The file.
        file: String,
        /// The missing field.
        field: String,
        /// Extra context (starts with a separator, may be empty).
        hint: String,
    },
    /// A layer whose kind no loader knows (neither tile, grid, entity nor
    /// decal for OGMO; an infinite or image layer where a grid is needed...).
    #[error("{file}: {field}: unknown layer kind {kind:?}")]
    UnknownLayer {
        /// The file.
        file: String,
        /// The layer.
        field: String,
        /// The kind found (or a description of the fields found).
        kind: String,
    },
    /// An array whose length does not match the layer's size.
    #[error("{file}: {field}: expected {expected} entries, got {got}")]
    Length {
        /// The file.
        file: String,
        /// The array.
        field: String,
        /// The length the layer's size implies.
        expected: u64,
        /// The length found.
        got: u64,
    },
    /// A size or position beyond the level limits ([`super::MAX_LEVEL_TILES`]
    /// per side) or the numeric bounds of [`ledge_shared::fixed`].
    #[error("{file}: {field}: {message}")]
    OutOfBounds {
        /// The file.
        file: String,
        /// The field.
        field: String,
        /// The value and the limit.
        message: String,
    },
    /// A value of the wrong type or outside its range.
    #[error("{file}: {field}: {message}")]
    BadValue {
        /// The file.
        file: String,
        /// The field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A tile id, grid value or `kind` property the [`super::TileMapping`]
    /// does not map.
    #[error("{file}: {field}: {tile} is not mapped to a tile kind (tileset {tileset:?})")]
    UnknownTile {
        /// The file.
        file: String,
        /// The cell.
        field: String,
        /// The id or value.
        tile: String,
        /// The tileset (or "grid" for grid layers).
        tileset: String,
    },
    /// An entity name (OGMO) or object type/class/name (Tiled) that is not in
    /// the entity table (see [`super::ENTITY_NAMES`]).
    #[error("{file}: {field}: unknown entity {name:?} in layer {layer:?} (known: {known})", known = super::ENTITY_NAMES.join(", "))]
    UnknownEntity {
        /// The file.
        file: String,
        /// The entity.
        field: String,
        /// The layer's name.
        layer: String,
        /// The entity's name.
        name: String,
    },
    /// A moving platform whose path cannot be followed.
    #[error("{file}: {field}: degenerate platform path: {message}")]
    DegeneratePath {
        /// The file.
        file: String,
        /// The platform (or its nodes).
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A polygon solid the simulation cannot use: too few or too many
    /// vertices, a duplicate vertex, three collinear vertices (zero area), a
    /// concave or self-intersecting outline. `field` is the vertex (or the
    /// polygon) and the message says which vertex, counted from 0 in file
    /// order.
    #[error("{file}: {field}: {message}")]
    BadPolygon {
        /// The file.
        file: String,
        /// The polygon or its offending vertex.
        field: String,
        /// What is wrong, e.g. `polygon is concave at vertex 3 (40, 16) px`.
        message: String,
    },
    /// A size, count, depth or decoded length beyond one of the bounds of
    /// `docs/LEVELS.md` ("Limits"), found before anything was allocated for
    /// it. `bound` names the constant (`MAX_TILESET_TILES`...).
    #[error("{file}: {field}: {found} {what} is more than the limit of {limit} ({bound})")]
    Limit {
        /// The file.
        file: String,
        /// The element or attribute, e.g. `map.tileset[0].tilecount`.
        field: String,
        /// What was counted, e.g. "tiles".
        what: String,
        /// The bound.
        limit: u64,
        /// The count found (for totals: the total so far).
        found: u64,
        /// The constant of the bound, e.g. `MAX_TILESET_TILES`.
        bound: &'static str,
    },
    /// A level name (`PROJECT.ldtk#NAME`) that is not one of the project's
    /// levels, or an empty one.
    #[error("{file}: {field}: {problem} (the project's levels: {known})")]
    UnknownLevel {
        /// The project file.
        file: String,
        /// Where the levels are listed (`levels`).
        field: String,
        /// What is wrong, naming the level asked for.
        problem: String,
        /// The project's level identifiers, in order, comma-separated.
        known: String,
    },
    /// No entity is a player spawn.
    #[error("{file}: {field}: no player spawn, and nothing in the level to place one on: nothing in it collides (add an entity named \"player\" or \"spawn\", and make something collide: see docs/LEVELS.md, \"What collides\", and the level's settings file)")]
    MissingSpawn {
        /// The file.
        file: String,
        /// The part of the document searched ("entities" or "layers").
        field: String,
    },
}

impl LevelError {
    /// The file the error is about.
    pub fn file(&self) -> &str {
        match self {
            LevelError::Io { file, .. }
            | LevelError::UnsupportedFormat { file }
            | LevelError::Syntax { file, .. }
            | LevelError::Missing { file, .. }
            | LevelError::UnknownLayer { file, .. }
            | LevelError::Length { file, .. }
            | LevelError::OutOfBounds { file, .. }
            | LevelError::BadValue { file, .. }
            | LevelError::UnknownTile { file, .. }
            | LevelError::UnknownEntity { file, .. }
            | LevelError::DegeneratePath { file, .. }
            | LevelError::BadPolygon { file, .. }
            | LevelError::MissingSpawn { file, .. }
            | LevelError::UnknownLevel { file, .. }
            | LevelError::Limit { file, .. } => file,
        }
    }

    /// The field the error is about, when there is one.
    pub fn field(&self) -> Option<&str> {
        match self {
            LevelError::Io { .. } | LevelError::UnsupportedFormat { .. } => None,
            LevelError::Syntax { field, .. }
            | LevelError::Missing { field, .. }
            | LevelError::UnknownLayer { field, .. }
            | LevelError::Length { field, .. }
            | LevelError::OutOfBounds { field, .. }
            | LevelError::BadValue { field, .. }
            | LevelError::UnknownTile { field, .. }
            | LevelError::UnknownEntity { field, .. }
            | LevelError::DegeneratePath { field, .. }
            | LevelError::BadPolygon { field, .. }
            | LevelError::MissingSpawn { field, .. }
            | LevelError::UnknownLevel { field, .. }
            | LevelError::Limit { field, .. } => Some(field),
        }
    }
}
