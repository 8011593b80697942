//! Bounds on what a level file may ask for, checked before anything is
//! allocated for it.
//!
//! * Tiled: every TMX, TSX and template (`.tx`) document is scanned with a
//!   streaming XML reader (`check_tmx_resource`) before the `tiled` crate
//!   sees it: nesting depth, counts (layers, tilesets, tiles, objects,
//!   points, properties, elements, attributes), sizes (attributes, text,
//!   images) and every tile layer's `<data>`, decoded and inflated with the
//!   output bound enforced while inflating, whose cell count must be exactly
//!   the layer's (or chunk's) width x height. Totals are kept across the
//!   documents of one load (`Budget`). Old files that lack attributes the
//!   `tiled` crate requires (`tilecount`, `columns`, an image's `width` and
//!   `height`) are patched when the value can be derived. Tile data the
//!   `tiled` crate cannot read as built here (zstd-compressed base64, and the
//!   oldest format, one `<tile gid=".."/>` element per cell) is decoded here,
//!   under the same bounds, and handed to it rewritten as CSV.
//! * OGMO and LDtk: the JSON text is scanned (`check_json`) for its
//!   nesting depth and its number of values before `serde_json` builds a
//!   tree of it; the LDtk importer then checks its counts (`check_count`,
//!   the `MAX_LDTK_*` bounds) before building anything from them.
//!
//! Every refusal is a [`LevelError`] naming the file, the element path (like
//! `map.layers[3].data`) and the bound; see `docs/LEVELS.md` ("Limits").
//!
//! The counts an element kind adds to, and their bounds, are one table
//! (`LIMITS`, after `EVERY_ELEMENT`); the rewriting of a document for the
//! `tiled` crate is the `rewrite` module's.

mod rewrite;

use std::collections::BTreeMap;
use std::io::{self, Read};
use std::path::{Path, PathBuf};

use quick_xml::events::{BytesStart, Event};

use self::rewrite::Patch;
use crate::{LevelError, MAX_FILE_BYTES, MAX_LEVEL_TILES};

/// Deepest element nesting in a TMX, TSX or template document (the `tiled`
/// crate parses group layers and class properties recursively).
pub const MAX_XML_DEPTH: usize = 64;
/// Most attributes on one element.
pub const MAX_ATTRIBUTES: usize = 64;
/// Longest attribute value, in bytes (as written, before unescaping).
pub const MAX_ATTRIBUTE_BYTES: usize = 1 << 20;
/// Longest text between tags, other than a tile layer's `<data>`, in bytes.
pub const MAX_TEXT_BYTES: usize = 1 << 20;
/// Most elements in all the documents of one Tiled load.
pub const MAX_ELEMENTS: u64 = 1 << 20;
/// Most documents (the map, its external tilesets and templates) read for one
/// Tiled load.
pub const MAX_DOCUMENTS: u64 = 64;
/// Most layers (tile, object, image and group layers) in one Tiled load.
pub const MAX_LAYERS: u64 = 1024;
/// Most tilesets in one map.
pub const MAX_TILESETS: u64 = 256;
/// Largest `tilecount`, and most `<tile>` elements, of one tileset.
pub const MAX_TILESET_TILES: u64 = 65_536;
/// Most tiles (`tilecount` plus `<tile>` elements) of all the tilesets of one
/// Tiled load.
pub const MAX_TOTAL_TILESET_TILES: u64 = 1 << 18;
/// Most tile cells in all the tile layers (and chunks) of one level, Tiled
/// or OGMO. One layer is also at most [`MAX_LEVEL_TILES`] per side.
pub const MAX_LEVEL_CELLS: u64 = 1 << 22;
/// Most objects in one Tiled load (an object made from a template counts
/// the template's objects again).
pub const MAX_OBJECTS: u64 = 65_536;
/// Most points in one polygon or polyline.
pub const MAX_SHAPE_POINTS: u64 = 4096;
/// Most polygon and polyline points in one Tiled load.
pub const MAX_TOTAL_POINTS: u64 = 1 << 20;
/// Most properties in one Tiled load.
pub const MAX_PROPERTIES: u64 = 65_536;
/// Widest or tallest image, in pixels.
pub const MAX_IMAGE_SIDE: u64 = 16_384;
/// Most pixels in one image.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;
/// Largest chunk coordinate (either sign) in an infinite map, in tiles.
pub const MAX_CHUNK_COORD: i64 = 1 << 24;
/// Most bytes the objects made from templates may copy: a template's size
/// times the number of objects using it, added up.
pub const MAX_TEMPLATE_BYTES: u64 = 64 << 20;
/// Deepest nesting of arrays and objects in an OGMO or LDtk JSON document (the same
/// as `serde_json`'s own recursion limit).
pub const MAX_JSON_DEPTH: usize = 128;
/// Most values (numbers, strings, arrays, objects, keys included) in one
/// OGMO or LDtk JSON document.
pub const MAX_JSON_VALUES: u64 = 1 << 22;

/// Most levels in one LDtk project (all its worlds together).
pub const MAX_LDTK_LEVELS: u64 = 4096;
/// Most layer instances in one LDtk level.
pub const MAX_LDTK_LAYERS: u64 = 1024;
/// Most entity instances in one LDtk level (all its entity layers).
pub const MAX_LDTK_ENTITIES: u64 = 65_536;
/// Most placed tiles (`gridTiles` and `autoLayerTiles`) in all the layers
/// of one LDtk level.
pub const MAX_LDTK_TILES: u64 = 1 << 22;
/// Most definitions (layers, entities, tilesets, IntGrid values of each
/// layer) in one LDtk project's `defs`.
pub const MAX_LDTK_DEFS: u64 = 65_536;

/// Refuses a count `found` of `what` above `max` (named `bound`), before
/// anything is allocated for it: the LDtk importer's counts.
pub(crate) fn check_count(
    file: &str,
    field: impl Into<String>,
    what: &str,
    found: u64,
    max: u64,
    bound: &'static str,
) -> Result<(), LevelError> {
    if found > max {
        return Err(limit(file, field, what, max, found, bound));
    }
    Ok(())
}

/// Totals over the documents of one Tiled load.
#[derive(Debug, Default)]
pub(crate) struct Budget {
    documents: u64,
    elements: u64,
    layers: u64,
    tileset_tiles: u64,
    cells: u64,
    objects: u64,
    points: u64,
    properties: u64,
    template_bytes: u64,
    /// Objects using each template (path as the `tiled` crate resolves it).
    template_uses: BTreeMap<PathBuf, u64>,
}

/// A load-wide total of [`Budget`].
#[derive(Clone, Copy)]
enum Total {
    Elements,
    Layers,
    TilesetTiles,
    Cells,
    Objects,
    Points,
    Properties,
}

impl Total {
    /// Its counter in `budget`.
    fn of(self, budget: &mut Budget) -> &mut u64 {
        match self {
            Total::Elements => &mut budget.elements,
            Total::Layers => &mut budget.layers,
            Total::TilesetTiles => &mut budget.tileset_tiles,
            Total::Cells => &mut budget.cells,
            Total::Objects => &mut budget.objects,
            Total::Points => &mut budget.points,
            Total::Properties => &mut budget.properties,
        }
    }
}

/// Which elements of a kind a limit applies to, by where they are.
#[derive(Clone, Copy)]
enum Place {
    /// Anywhere.
    Any,
    /// The document's root.
    Root,
    /// Inside a tileset.
    InTileset,
    /// Inside a tile layer.
    InLayer,
    /// Inside an infinite map's layer data (its chunks).
    InChunkedData,
}

/// The number an element brings to a count.
#[derive(Clone, Copy)]
enum Amount {
    /// One.
    One,
    /// Its nesting depth, itself included.
    Depth,
    /// A whole-number attribute (none, or not a number: nothing counted),
    /// named in the error's field.
    Attr(&'static str),
    /// A signed attribute's distance from 0 (none: 0), named in the
    /// error's field.
    Coord(&'static str),
    /// The points of its `points` attribute, named in the error's field.
    Points,
    /// The cells of the tile layer its `<data>` holds (nothing for an
    /// infinite map's, or a layer without its size: its chunks count).
    LayerCells,
    /// The cells a chunk costs: its own, or the tiled crate's whole 16 x
    /// 16 blocks it touches, whichever is more.
    ChunkCells,
}

/// What an element's amount is added to before the bound is checked.
#[derive(Clone, Copy)]
enum Count {
    /// Nothing: the amount itself is bounded.
    Own,
    /// The tilesets of the map it is in (only when its parent is the map).
    MapTilesets,
    /// The `<tile>` elements of the tileset it is in.
    TilesOfTileset,
    /// A load-wide total, once for each object using the document (a
    /// template).
    PerUse(Total),
    /// A load-wide total, once.
    Once(Total),
}

/// One bound of the pre-scan: the elements it counts, what it counts, and
/// the error naming it (`what`, `max`, `bound`).
struct Limit {
    /// Element names (local) it applies to; empty: every element.
    names: &'static [&'static str],
    place: Place,
    amount: Amount,
    count: Count,
    max: u64,
    what: &'static str,
    bound: &'static str,
}

/// Checked on every element before its attributes are read.
const EVERY_ELEMENT: [Limit; 2] = [
    Limit {
        names: &[],
        place: Place::Any,
        amount: Amount::Depth,
        count: Count::Own,
        max: MAX_XML_DEPTH as u64,
        what: "levels of element nesting",
        bound: "MAX_XML_DEPTH",
    },
    Limit {
        names: &[],
        place: Place::Any,
        amount: Amount::One,
        count: Count::PerUse(Total::Elements),
        max: MAX_ELEMENTS,
        what: "elements in the map and its tilesets and templates",
        bound: "MAX_ELEMENTS",
    },
];

/// Element kinds that are layers.
const LAYER_KINDS: &[&str] = &["layer", "objectgroup", "imagelayer", "group"];

/// Checked on the elements of each kind, in this order, once their
/// attributes are read (an `<image>`'s size is [`Scan::image`]'s).
const LIMITS: [Limit; 20] = [
    Limit {
        names: &["map"],
        place: Place::Root,
        amount: Amount::Attr("width"),
        count: Count::Own,
        max: MAX_LEVEL_TILES as u64,
        what: "tiles",
        bound: "MAX_LEVEL_TILES",
    },
    Limit {
        names: &["map"],
        place: Place::Root,
        amount: Amount::Attr("height"),
        count: Count::Own,
        max: MAX_LEVEL_TILES as u64,
        what: "tiles",
        bound: "MAX_LEVEL_TILES",
    },
    Limit {
        names: &["tileset"],
        place: Place::Any,
        amount: Amount::One,
        count: Count::MapTilesets,
        max: MAX_TILESETS,
        what: "tilesets",
        bound: "MAX_TILESETS",
    },
    Limit {
        names: &["tileset"],
        place: Place::Any,
        amount: Amount::Attr("tilecount"),
        count: Count::Own,
        max: MAX_TILESET_TILES,
        what: "tiles",
        bound: "MAX_TILESET_TILES",
    },
    Limit {
        names: &["tileset"],
        place: Place::Any,
        amount: Amount::Attr("tilecount"),
        count: Count::PerUse(Total::TilesetTiles),
        max: MAX_TOTAL_TILESET_TILES,
        what: "tiles in all tilesets",
        bound: "MAX_TOTAL_TILESET_TILES",
    },
    Limit {
        names: &["tile"],
        place: Place::InTileset,
        amount: Amount::One,
        count: Count::TilesOfTileset,
        max: MAX_TILESET_TILES,
        what: "<tile> elements in one tileset",
        bound: "MAX_TILESET_TILES",
    },
    Limit {
        names: &["tile"],
        place: Place::InTileset,
        amount: Amount::One,
        count: Count::PerUse(Total::TilesetTiles),
        max: MAX_TOTAL_TILESET_TILES,
        what: "tiles in all tilesets",
        bound: "MAX_TOTAL_TILESET_TILES",
    },
    Limit {
        names: LAYER_KINDS,
        place: Place::Any,
        amount: Amount::One,
        count: Count::PerUse(Total::Layers),
        max: MAX_LAYERS,
        what: "layers",
        bound: "MAX_LAYERS",
    },
    Limit {
        names: &["layer"],
        place: Place::Any,
        amount: Amount::Attr("width"),
        count: Count::Own,
        max: MAX_LEVEL_TILES as u64,
        what: "tiles",
        bound: "MAX_LEVEL_TILES",
    },
    Limit {
        names: &["layer"],
        place: Place::Any,
        amount: Amount::Attr("height"),
        count: Count::Own,
        max: MAX_LEVEL_TILES as u64,
        what: "tiles",
        bound: "MAX_LEVEL_TILES",
    },
    Limit {
        names: &["data"],
        place: Place::InLayer,
        amount: Amount::LayerCells,
        count: Count::Once(Total::Cells),
        max: MAX_LEVEL_CELLS,
        what: "tile cells in all layers",
        bound: "MAX_LEVEL_CELLS",
    },
    Limit {
        names: &["chunk"],
        place: Place::InChunkedData,
        amount: Amount::Coord("x"),
        count: Count::Own,
        max: MAX_CHUNK_COORD as u64,
        what: "tiles from the origin",
        bound: "MAX_CHUNK_COORD",
    },
    Limit {
        names: &["chunk"],
        place: Place::InChunkedData,
        amount: Amount::Coord("y"),
        count: Count::Own,
        max: MAX_CHUNK_COORD as u64,
        what: "tiles from the origin",
        bound: "MAX_CHUNK_COORD",
    },
    Limit {
        names: &["chunk"],
        place: Place::InChunkedData,
        amount: Amount::Attr("width"),
        count: Count::Own,
        max: MAX_LEVEL_TILES as u64,
        what: "tiles",
        bound: "MAX_LEVEL_TILES",
    },
    Limit {
        names: &["chunk"],
        place: Place::InChunkedData,
        amount: Amount::Attr("height"),
        count: Count::Own,
        max: MAX_LEVEL_TILES as u64,
        what: "tiles",
        bound: "MAX_LEVEL_TILES",
    },
    Limit {
        names: &["chunk"],
        place: Place::InChunkedData,
        amount: Amount::ChunkCells,
        count: Count::Once(Total::Cells),
        max: MAX_LEVEL_CELLS,
        what: "tile cells in all layers (infinite maps count whole 16 x 16 blocks)",
        bound: "MAX_LEVEL_CELLS",
    },
    Limit {
        names: &["object"],
        place: Place::Any,
        amount: Amount::One,
        count: Count::PerUse(Total::Objects),
        max: MAX_OBJECTS,
        what: "objects",
        bound: "MAX_OBJECTS",
    },
    Limit {
        names: &["polygon", "polyline"],
        place: Place::Any,
        amount: Amount::Points,
        count: Count::Own,
        max: MAX_SHAPE_POINTS,
        what: "points",
        bound: "MAX_SHAPE_POINTS",
    },
    Limit {
        names: &["polygon", "polyline"],
        place: Place::Any,
        amount: Amount::Points,
        count: Count::PerUse(Total::Points),
        max: MAX_TOTAL_POINTS,
        what: "polygon and polyline points",
        bound: "MAX_TOTAL_POINTS",
    },
    Limit {
        names: &["property"],
        place: Place::Any,
        amount: Amount::One,
        count: Count::PerUse(Total::Properties),
        max: MAX_PROPERTIES,
        what: "properties",
        bound: "MAX_PROPERTIES",
    },
];

fn limit(
    file: &str,
    field: impl Into<String>,
    what: &str,
    limit: u64,
    found: u64,
    bound: &'static str,
) -> LevelError {
    LevelError::Limit {
        file: file.into(),
        field: field.into(),
        what: what.into(),
        limit,
        found,
        bound,
    }
}

/// Checks one TMX, TSX or template file's bytes before the Tiled reader
/// sees them, and returns the bytes to hand it (patched for old files).
pub(crate) fn check_tmx_resource(
    budget: &mut Budget,
    path: &Path,
    bytes: Vec<u8>,
) -> Result<Vec<u8>, LevelError> {
    let file = path.display().to_string();
    budget.documents += 1;
    if budget.documents > MAX_DOCUMENTS {
        return Err(limit(
            &file,
            "(document)",
            "documents read for one map (map, tilesets, templates)",
            MAX_DOCUMENTS,
            budget.documents,
            "MAX_DOCUMENTS",
        ));
    }
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(limit(
            &file,
            "(document)",
            "bytes",
            MAX_FILE_BYTES,
            bytes.len() as u64,
            "MAX_FILE_BYTES",
        ));
    }
    let uses = budget.template_uses.get(path).copied().unwrap_or(1).max(1);
    let mut scan = Scan {
        file,
        path,
        budget,
        uses,
        stack: Vec::new(),
        patches: Vec::new(),
        root_seen: false,
    };
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("tx"))
    {
        let cost = (bytes.len() as u64).saturating_mul(uses);
        scan.budget.template_bytes = scan.budget.template_bytes.saturating_add(cost);
        if scan.budget.template_bytes > MAX_TEMPLATE_BYTES {
            return Err(limit(
                &scan.file,
                "template",
                "bytes copied into objects from templates",
                MAX_TEMPLATE_BYTES,
                scan.budget.template_bytes,
                "MAX_TEMPLATE_BYTES",
            ));
        }
    }
    scan.run(&bytes)?;
    let patches = std::mem::take(&mut scan.patches);
    Ok(rewrite::apply(bytes, patches))
}

/// What an open element is, for the checks at its children and its end.
enum Ctx {
    Other,
    Map {
        infinite: bool,
        tilesets: u64,
    },
    Tileset(Box<TilesetScan>),
    /// A tile layer: its size, when given.
    Layer {
        size: Option<(u64, u64)>,
    },
    Data(DataScan),
}

struct TilesetScan {
    name: String,
    field: String,
    tilecount: Option<u64>,
    has_columns: bool,
    tile_size: (Option<u64>, Option<u64>),
    spacing: u64,
    margin: u64,
    /// Width and height of the tileset's own image (`Some(None)`: an image
    /// of unknown size).
    image: Option<Option<(u64, u64)>>,
    tiles: u64,
    /// Where attributes can be added to the start tag.
    insert_at: usize,
    external: bool,
}

struct DataScan {
    field: String,
    encoding: Option<String>,
    compression: Option<String>,
    /// Cells the layer (or chunk) must have; `None` when its size is not given.
    expected: Option<u64>,
    /// Decoded already (the `tiled` crate reads only the first text).
    done: bool,
    /// Whether this element's text is tile data (a chunk of an infinite map,
    /// or the data of a finite one).
    decodes: bool,
    chunks: u64,
    /// Where the element's content starts (just after its start tag), and
    /// whether it has any (`<data/>` has none).
    content_start: usize,
    empty: bool,
    /// XML tile data (no `encoding`): the `<tile>` children seen, and the
    /// gids of the first of them (at most the cells the layer may have).
    tiles: u64,
    gids: Vec<u32>,
}

impl DataScan {
    /// Tile data as `<tile gid=".."/>` children (the oldest TMX format).
    fn is_xml(&self) -> bool {
        self.encoding.is_none()
    }

    /// Tile data the `tiled` crate is handed rewritten as CSV.
    fn rewritten(&self) -> bool {
        rewrite::is_rewritten(self.encoding.as_deref(), self.compression.as_deref())
    }

    /// Most gids kept for the rewrite: the cells the layer has, or, when its
    /// size is not given, the cells the load may still have.
    fn keep(&self, remaining: u64) -> usize {
        self.expected
            .unwrap_or(remaining)
            .min(MAX_LEVEL_CELLS)
            .try_into()
            .unwrap_or(usize::MAX)
    }
}

struct Frame {
    path: String,
    ctx: Ctx,
    /// Children seen so far, by segment name.
    counts: Vec<(String, u64)>,
}

struct Scan<'a> {
    file: String,
    path: &'a Path,
    budget: &'a mut Budget,
    /// How many objects use this document (a template), else 1.
    uses: u64,
    stack: Vec<Frame>,
    /// Byte ranges of the document to replace (an empty range inserts).
    patches: Vec<Patch>,
    root_seen: bool,
}

/// The attributes of an element, by local name, unescaped.
struct Attrs(Vec<(String, String)>);

impl Attrs {
    fn get(&self, k: &str) -> Option<&str> {
        self.0.iter().find(|(n, _)| n == k).map(|(_, v)| v.as_str())
    }
    fn num(&self, k: &str) -> Option<u64> {
        self.get(k).and_then(|v| v.parse().ok())
    }
    fn int(&self, k: &str) -> Option<i64> {
        self.get(k).and_then(|v| v.parse().ok())
    }
}

/// Where an element's start tag is in the document, and whether it is an
/// empty-element tag (`<data/>`).
#[derive(Clone, Copy)]
struct Tag {
    start: usize,
    end: usize,
    empty: bool,
}

impl Tag {
    /// Where attributes can be added to it: before `>` or `/>`.
    fn insert_at(self) -> usize {
        self.end.saturating_sub(if self.empty { 2 } else { 1 })
    }
}

impl Scan<'_> {
    fn syntax(&self, field: &str, message: impl ToString) -> LevelError {
        LevelError::Syntax {
            file: self.file.clone(),
            field: field.into(),
            format: "TMX",
            message: message.to_string(),
        }
    }

    fn current_path(&self) -> String {
        self.stack
            .last()
            .map(|f| f.path.clone())
            .unwrap_or_else(|| "(document)".into())
    }

    fn run(&mut self, bytes: &[u8]) -> Result<(), LevelError> {
        let mut reader = quick_xml::Reader::from_reader(bytes);
        let mut buf = Vec::new();
        loop {
            buf.clear();
            // The event's bytes are `start..end` of the document.
            let start = reader.buffer_position();
            let ev = reader
                .read_event_into(&mut buf)
                .map_err(|e| self.syntax(&self.current_path(), e))?;
            let end = reader.buffer_position();
            match ev {
                Event::Start(e) => self.open(&e, false, start, end)?,
                Event::Empty(e) => {
                    self.open(&e, true, start, end)?;
                    self.close(end)?;
                }
                Event::End(_) => self.close(start)?,
                Event::Text(t) => {
                    let text = t
                        .unescape()
                        .map_err(|e| self.syntax(&self.current_path(), e))?;
                    self.text(text.as_bytes(), start, end)?;
                }
                Event::CData(t) => {
                    let text = t.into_inner();
                    self.text(&text, start, end)?;
                }
                Event::Eof => break,
                _ => {}
            }
        }
        Ok(())
    }

    /// The path segment of a child named `name` of the innermost element.
    fn segment(&mut self, name: &str) -> String {
        let (key, indexed) = match name {
            "layer" | "objectgroup" | "imagelayer" | "group" => ("layers", true),
            "object" => ("objects", true),
            "property" => ("properties", true),
            "tileset" | "tile" | "chunk" | "frame" | "wangset" | "wangcolor" | "wangtile"
            | "terrain" => (name, true),
            _ => (name, false),
        };
        let Some(top) = self.stack.last_mut() else {
            return name.to_owned();
        };
        let parent = &top.path;
        if !indexed {
            return format!("{parent}.{name}");
        }
        let n = match top.counts.iter_mut().find(|(k, _)| k == key) {
            Some((_, n)) => {
                *n += 1;
                *n - 1
            }
            None => {
                top.counts.push((key.to_owned(), 1));
                0
            }
        };
        format!("{parent}.{key}[{n}]")
    }

    fn attrs(&self, e: &BytesStart<'_>, field: &str) -> Result<Attrs, LevelError> {
        let mut out = Vec::new();
        let mut it = e.attributes();
        it.with_checks(false);
        for (i, a) in it.enumerate() {
            if i >= MAX_ATTRIBUTES {
                return Err(limit(
                    &self.file,
                    field,
                    "attributes on one element (or more)",
                    MAX_ATTRIBUTES as u64,
                    i as u64 + 1,
                    "MAX_ATTRIBUTES",
                ));
            }
            let a = a.map_err(|e| self.syntax(field, e))?;
            let key = String::from_utf8_lossy(a.key.local_name().as_ref()).into_owned();
            if a.value.len() > MAX_ATTRIBUTE_BYTES {
                return Err(limit(
                    &self.file,
                    format!("{field}.{key}"),
                    "bytes in an attribute value",
                    MAX_ATTRIBUTE_BYTES as u64,
                    a.value.len() as u64,
                    "MAX_ATTRIBUTE_BYTES",
                ));
            }
            let v = a.unescape_value().map_err(|e| self.syntax(field, e))?;
            out.push((key, v.into_owned()));
        }
        Ok(Attrs(out))
    }

    /// Adds `n` to a load-wide total and checks it.
    #[allow(clippy::too_many_arguments)]
    fn add(
        file: &str,
        total: &mut u64,
        n: u64,
        max: u64,
        field: &str,
        what: &str,
        bound: &'static str,
    ) -> Result<(), LevelError> {
        *total = total.saturating_add(n);
        if *total > max {
            return Err(limit(file, field, what, max, *total, bound));
        }
        Ok(())
    }

    /// Opens an element: checks the limits on it ([`EVERY_ELEMENT`], then
    /// [`LIMITS`] once its attributes are read), counting it, then notes
    /// what it is for its children and its end.
    fn open(
        &mut self,
        e: &BytesStart<'_>,
        empty: bool,
        start: usize,
        end: usize,
    ) -> Result<(), LevelError> {
        let name = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
        let field = self.segment(&name);
        let is_root = self.stack.is_empty();
        self.check_limits(&EVERY_ELEMENT, &name, &field, is_root, &Attrs(Vec::new()))?;
        let a = self.attrs(e, &field)?;
        if is_root {
            if self.root_seen {
                return Err(self.syntax(&field, "more than one root element"));
            }
            self.root_seen = true;
        }
        self.check_limits(&LIMITS, &name, &field, is_root, &a)?;
        let tag = Tag { start, end, empty };
        let ctx = self.context(&name, &field, is_root, &a, tag)?;
        self.stack.push(Frame {
            path: field,
            ctx,
            counts: Vec::new(),
        });
        Ok(())
    }

    /// Checks the `limits` that apply to element `name` (at `field`, with
    /// attributes `a`), in order, counting it in each.
    fn check_limits(
        &mut self,
        limits: &[Limit],
        name: &str,
        field: &str,
        is_root: bool,
        a: &Attrs,
    ) -> Result<(), LevelError> {
        for l in limits {
            if !(l.names.is_empty() || l.names.contains(&name)) || !self.is_at(l.place, is_root) {
                continue;
            }
            let Some(n) = self.amount(l.amount, a) else {
                continue;
            };
            let found = match l.count {
                Count::Own => n,
                Count::MapTilesets | Count::TilesOfTileset => match self.parent_count(l.count) {
                    Some(c) => {
                        *c += n;
                        *c
                    }
                    None => continue,
                },
                Count::PerUse(total) => {
                    let n = n.saturating_mul(self.uses);
                    let c = total.of(self.budget);
                    *c = c.saturating_add(n);
                    *c
                }
                Count::Once(total) => {
                    let c = total.of(self.budget);
                    *c = c.saturating_add(n);
                    *c
                }
            };
            if found > l.max {
                let field = match l.amount {
                    Amount::Attr(k) | Amount::Coord(k) => format!("{field}.{k}"),
                    Amount::Points => format!("{field}.points"),
                    _ => field.to_owned(),
                };
                return Err(limit(&self.file, field, l.what, l.max, found, l.bound));
            }
        }
        Ok(())
    }

    /// Whether the element being opened is at `place`.
    fn is_at(&self, place: Place, is_root: bool) -> bool {
        match place {
            Place::Any => true,
            Place::Root => is_root,
            Place::InTileset => self.parent_is(|c| matches!(c, Ctx::Tileset(_))),
            Place::InLayer => self.parent_is(|c| matches!(c, Ctx::Layer { .. })),
            Place::InChunkedData => self.parent_is(|c| matches!(c, Ctx::Data(d) if !d.decodes)),
        }
    }

    /// Whether the innermost open element (the parent of the one being
    /// opened) is `f`.
    fn parent_is(&self, f: impl Fn(&Ctx) -> bool) -> bool {
        self.stack.last().is_some_and(|p| f(&p.ctx))
    }

    /// The number the element being opened (attributes `a`) brings to a
    /// count; `None`: nothing to count.
    fn amount(&self, amount: Amount, a: &Attrs) -> Option<u64> {
        match amount {
            Amount::One => Some(1),
            Amount::Depth => Some(self.stack.len() as u64 + 1),
            Amount::Attr(k) => a.num(k),
            // The distance from 0, which i64::MIN has too (`abs` overflowed
            // on it: a panic in debug builds, a pass in release).
            Amount::Coord(k) => Some(a.int(k).unwrap_or(0).unsigned_abs()),
            Amount::Points => Some(
                a.get("points")
                    .map_or(0, |p| p.split_ascii_whitespace().count() as u64),
            ),
            Amount::LayerCells => self.layer_cells().1,
            Amount::ChunkCells => {
                let (x, y) = (a.int("x").unwrap_or(0), a.int("y").unwrap_or(0));
                let (w, h) = (a.num("width").unwrap_or(0), a.num("height").unwrap_or(0));
                // The tiled crate stores infinite layers in 16 x 16
                // blocks: count the blocks the chunk touches.
                let blocks = |p: i64, n: u64| {
                    if n == 0 {
                        0
                    } else {
                        ((p + n as i64 - 1).div_euclid(16) - p.div_euclid(16) + 1) as u64
                    }
                };
                Some((w * h).max(blocks(x, w) * blocks(y, h) * 256))
            }
        }
    }

    /// The parent's count of children like the one being opened (`count`
    /// is [`Count::MapTilesets`] or [`Count::TilesOfTileset`]), if the parent
    /// keeps one.
    fn parent_count(&mut self, count: Count) -> Option<&mut u64> {
        match (count, &mut self.stack.last_mut()?.ctx) {
            (Count::MapTilesets, Ctx::Map { tilesets, .. }) => Some(tilesets),
            (Count::TilesOfTileset, Ctx::Tileset(ts)) => Some(&mut ts.tiles),
            _ => None,
        }
    }

    /// Whether the map is infinite, and the cells the innermost tile
    /// layer's data must hold (`None`: an infinite map's, whose chunks are
    /// counted, or a layer without its size).
    fn layer_cells(&self) -> (bool, Option<u64>) {
        let infinite = self
            .stack
            .iter()
            .any(|f| matches!(f.ctx, Ctx::Map { infinite: true, .. }));
        let size = match self.stack.last().map(|f| &f.ctx) {
            Some(Ctx::Layer { size }) => *size,
            _ => None,
        };
        let expected = if infinite {
            None
        } else {
            size.map(|(w, h)| w * h)
        };
        (infinite, expected)
    }

    /// What the element being opened is, for its children and its end, and
    /// what its kind does besides being counted (gids kept, image sizes
    /// checked, templates' uses counted, start tags rewritten).
    fn context(
        &mut self,
        name: &str,
        field: &str,
        is_root: bool,
        a: &Attrs,
        tag: Tag,
    ) -> Result<Ctx, LevelError> {
        Ok(match name {
            "map" if is_root => Ctx::Map {
                infinite: a.get("infinite") == Some("1"),
                tilesets: 0,
            },
            "tileset" => Ctx::Tileset(Box::new(TilesetScan {
                name: a.get("name").unwrap_or_default().to_owned(),
                field: field.to_owned(),
                tilecount: a.num("tilecount"),
                has_columns: a.get("columns").is_some(),
                tile_size: (a.num("tilewidth"), a.num("tileheight")),
                spacing: a.num("spacing").unwrap_or(0),
                margin: a.num("margin").unwrap_or(0),
                image: None,
                tiles: 0,
                insert_at: tag.insert_at(),
                external: !is_root && a.get("source").is_some(),
            })),
            "tile" if self.parent_is(|c| matches!(c, Ctx::Data(d) if d.decodes && d.is_xml())) => {
                self.xml_tile(a, field)?;
                Ctx::Other
            }
            "image" => {
                let size = self.image(a, field, tag.insert_at())?;
                if let Some(Frame {
                    ctx: Ctx::Tileset(ts),
                    ..
                }) = self.stack.last_mut()
                {
                    ts.image = Some(size);
                }
                Ctx::Other
            }
            "layer" => Ctx::Layer {
                size: a.num("width").zip(a.num("height")),
            },
            "data" if self.parent_is(|c| matches!(c, Ctx::Layer { .. })) => {
                self.data(a, field, tag)
            }
            "chunk" => self.chunk(a, field, tag),
            "object" => {
                self.object_template(a, field)?;
                Ctx::Other
            }
            _ => Ctx::Other,
        })
    }

    /// A `<tile>` of XML tile data: counted, and its gid kept for the
    /// rewrite (at most the cells the layer may have).
    fn xml_tile(&mut self, a: &Attrs, field: &str) -> Result<(), LevelError> {
        let gid = match a.get("gid") {
            None => 0,
            Some(g) => g.trim().parse::<u32>().map_err(|e| LevelError::BadValue {
                file: self.file.clone(),
                field: format!("{field}.gid"),
                message: format!("{g:?} is not a tile gid: {e}"),
            })?,
        };
        let remaining = MAX_LEVEL_CELLS.saturating_sub(self.budget.cells);
        if let Some(Frame {
            ctx: Ctx::Data(d), ..
        }) = self.stack.last_mut()
        {
            d.tiles += 1;
            if d.gids.len() < d.keep(remaining) {
                d.gids.push(gid);
            }
        }
        Ok(())
    }

    /// A tile layer's `<data>`: the cells it must hold, and its start tag
    /// rewritten when its content (or each chunk's) becomes CSV.
    fn data(&mut self, a: &Attrs, field: &str, tag: Tag) -> Ctx {
        let (infinite, expected) = self.layer_cells();
        let d = DataScan {
            field: field.to_owned(),
            encoding: a.get("encoding").map(str::to_owned),
            compression: a.get("compression").map(str::to_owned),
            expected,
            done: false,
            decodes: !infinite,
            chunks: 0,
            content_start: tag.end,
            empty: tag.empty,
            tiles: 0,
            gids: Vec::new(),
        };
        if d.rewritten() {
            self.patches
                .push(Patch::csv_data_tag(tag.start, tag.end, tag.empty));
        }
        Ctx::Data(d)
    }

    /// A `<chunk>` of an infinite map's layer data: the cells it must hold,
    /// in its parent's encoding.
    fn chunk(&mut self, a: &Attrs, field: &str, tag: Tag) -> Ctx {
        let Some(Ctx::Data(d)) = self.stack.last_mut().map(|f| &mut f.ctx) else {
            return Ctx::Other;
        };
        if d.decodes {
            return Ctx::Other;
        }
        d.chunks += 1;
        let (w, h) = (a.num("width").unwrap_or(0), a.num("height").unwrap_or(0));
        Ctx::Data(DataScan {
            field: field.to_owned(),
            encoding: d.encoding.clone(),
            compression: d.compression.clone(),
            expected: Some(w * h),
            done: false,
            decodes: true,
            chunks: 0,
            content_start: tag.end,
            empty: tag.empty,
            tiles: 0,
            gids: Vec::new(),
        })
    }

    /// An `<object>` made from a template: one more use of the template
    /// (whose objects then count again); a tileset's or template's own
    /// objects cannot use one.
    fn object_template(&mut self, a: &Attrs, field: &str) -> Result<(), LevelError> {
        let Some(t) = a.get("template") else {
            return Ok(());
        };
        let in_template = self
            .path
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("tx") || x.eq_ignore_ascii_case("tsx"));
        if in_template {
            return Err(LevelError::BadValue {
                file: self.file.clone(),
                field: format!("{field}.template"),
                message: "an object in a tileset or template cannot use a template".into(),
            });
        }
        let dir = self.path.parent().unwrap_or(Path::new(""));
        *self
            .budget
            .template_uses
            .entry(dir.join(Path::new(t)))
            .or_insert(0) += 1;
        Ok(())
    }

    /// Checks an `<image>`'s size; when it is not given, reads it from the
    /// PNG's header and adds it (the `tiled` crate requires it). Returns the
    /// size when known.
    fn image(
        &mut self,
        a: &Attrs,
        field: &str,
        insert_at: usize,
    ) -> Result<Option<(u64, u64)>, LevelError> {
        let mut size = a.num("width").zip(a.num("height"));
        if size.is_none() && a.get("width").is_none() && a.get("height").is_none() {
            if let Some(src) = a.get("source") {
                let dir = self.path.parent().unwrap_or(Path::new(""));
                if let Some((w, h)) = png_size(&dir.join(src)) {
                    self.patches.push(Patch::image_size(insert_at, w, h));
                    size = Some((w as u64, h as u64));
                }
            }
        }
        if let Some((w, h)) = size {
            for (v, k) in [(w, "width"), (h, "height")] {
                if v > MAX_IMAGE_SIDE {
                    return Err(limit(
                        &self.file,
                        format!("{field}.{k}"),
                        "pixels",
                        MAX_IMAGE_SIDE,
                        v,
                        "MAX_IMAGE_SIDE",
                    ));
                }
            }
            if w * h > MAX_IMAGE_PIXELS {
                return Err(limit(
                    &self.file,
                    field,
                    "pixels in one image",
                    MAX_IMAGE_PIXELS,
                    w * h,
                    "MAX_IMAGE_PIXELS",
                ));
            }
        }
        Ok(size)
    }

    fn text(&mut self, text: &[u8], start: usize, end: usize) -> Result<(), LevelError> {
        let file = self.file.clone();
        let remaining = MAX_LEVEL_CELLS.saturating_sub(self.budget.cells);
        if let Some(Frame {
            ctx: Ctx::Data(d), ..
        }) = self.stack.last_mut()
        {
            // XML tile data: the text between the `<tile>` elements is
            // checked like any other.
            if d.decodes && !d.done && !d.is_xml() {
                d.done = true;
                if let Some(gids) = decode_data(&file, d, text, remaining)? {
                    self.patches.push(Patch::csv_data(start, end, &gids));
                }
                return Ok(());
            }
        }
        if text.len() > MAX_TEXT_BYTES {
            return Err(limit(
                &file,
                self.current_path(),
                "bytes of text",
                MAX_TEXT_BYTES as u64,
                text.len() as u64,
                "MAX_TEXT_BYTES",
            ));
        }
        Ok(())
    }

    /// Closes the innermost element; `content_end` is where its end tag
    /// starts (or where its empty tag ends).
    fn close(&mut self, content_end: usize) -> Result<(), LevelError> {
        let Some(frame) = self.stack.pop() else {
            return Ok(());
        };
        match frame.ctx {
            Ctx::Data(d) if d.decodes && d.is_xml() => {
                let remaining = MAX_LEVEL_CELLS.saturating_sub(self.budget.cells);
                check_cells(&self.file, &d, d.tiles, remaining)?;
                if !d.empty {
                    self.patches
                        .push(Patch::csv_data(d.content_start, content_end, &d.gids));
                }
            }
            Ctx::Data(d) if d.decodes && !d.done => {
                let remaining = MAX_LEVEL_CELLS.saturating_sub(self.budget.cells);
                decode_data(&self.file, &d, b"", remaining)?;
            }
            Ctx::Tileset(ts) => self.finish_tileset(&ts)?,
            _ => {}
        }
        Ok(())
    }

    /// Adds `tilecount` (and `columns`) to a tileset that lacks it.
    fn finish_tileset(&mut self, ts: &TilesetScan) -> Result<(), LevelError> {
        if ts.external || ts.tilecount.is_some() {
            return Ok(());
        }
        let missing = |what: &str| {
            LevelError::Missing {
            file: self.file.clone(),
            field: format!("{}.tilecount", ts.field),
            hint: format!(
                " (tileset {:?} has no tilecount, and it cannot be derived: {what}; save the tileset again with a recent Tiled)",
                ts.name
            ),
        }
        };
        let (count, columns) = match ts.image {
            None => (ts.tiles, 0),
            Some(None) => return Err(missing("its image's width and height are not known")),
            Some(Some((iw, ih))) => {
                let (Some(tw), Some(th)) = ts.tile_size else {
                    return Err(missing("no tilewidth or tileheight"));
                };
                let fit = |side: u64, tile: u64| {
                    (side + ts.spacing).saturating_sub(ts.margin) / (tile + ts.spacing).max(1)
                };
                let (c, r) = (fit(iw, tw), fit(ih, th));
                (c * r, c)
            }
        };
        if count > MAX_TILESET_TILES {
            return Err(limit(
                &self.file,
                format!("{}.tilecount", ts.field),
                "tiles (derived from the image size)",
                MAX_TILESET_TILES,
                count,
                "MAX_TILESET_TILES",
            ));
        }
        if ts.image.is_some() {
            let file = self.file.clone();
            Self::add(
                &file,
                &mut self.budget.tileset_tiles,
                count.saturating_mul(self.uses),
                MAX_TOTAL_TILESET_TILES,
                &format!("{}.tilecount", ts.field),
                "tiles in all tilesets",
                "MAX_TOTAL_TILESET_TILES",
            )?;
        }
        let columns = (!ts.has_columns).then_some(columns);
        self.patches
            .push(Patch::tileset_count(ts.insert_at, count, columns));
        Ok(())
    }
}

/// Counts the cells of one `<data>` (or `<chunk>`) text, never holding more
/// than a small buffer, and checks the count against the layer's size.
/// zstd-compressed data is decoded: its gids are returned, to be handed to
/// the `tiled` crate as CSV.
fn decode_data(
    file: &str,
    d: &DataScan,
    text: &[u8],
    remaining: u64,
) -> Result<Option<Vec<u32>>, LevelError> {
    let bad = |message: String| LevelError::Syntax {
        file: file.into(),
        field: d.field.clone(),
        format: "TMX",
        message,
    };
    // Cells counted at most: what the layer needs plus one, within the load's
    // remaining budget (the layer's own cells are already counted in it).
    let expected = d.expected;
    let cap = match expected {
        Some(n) => n.saturating_add(remaining).saturating_add(1),
        None => remaining.saturating_add(1),
    };
    let mut gids = None;
    let got = match (d.encoding.as_deref(), d.compression.as_deref()) {
        (Some("csv"), None) => {
            let n = memchr_count(b',', text) + 1;
            n.min(cap)
        }
        (Some("base64"), c) => {
            let trimmed = trim_ascii(text);
            let b64 = base64::read::DecoderReader::new(
                trimmed,
                &base64::engine::general_purpose::STANDARD,
            );
            let byte_cap = cap.saturating_mul(4);
            let bytes = match c {
                None => count_bytes(b64, byte_cap),
                Some("zlib") => count_bytes(flate2::read::ZlibDecoder::new(b64), byte_cap),
                Some("gzip") => count_bytes(flate2::read::GzDecoder::new(b64), byte_cap),
                Some("zstd") => {
                    let mut cells = Cells::new(d.keep(remaining));
                    zstd_cells(b64, byte_cap, &mut cells)
                        .map_err(|e| bad(format!("cannot decode the tile data: {e}")))?;
                    gids = Some(cells.gids);
                    Ok(cells.bytes)
                }
                Some(other) => {
                    return Err(LevelError::BadValue {
                        file: file.into(),
                        field: format!("{}.compression", d.field),
                        message: format!(
                            "unknown compression {other:?} (expected zlib, gzip or zstd)"
                        ),
                    })
                }
            }
            .map_err(|e| bad(format!("cannot decode the tile data: {e}")))?;
            if bytes % 4 != 0 && bytes < byte_cap {
                return Err(bad(format!(
                    "{bytes} bytes of tile data is not a whole number of 4-byte cells"
                )));
            }
            bytes / 4
        }
        (Some("csv"), Some(c)) => {
            return Err(LevelError::BadValue {
                file: file.into(),
                field: format!("{}.compression", d.field),
                message: format!("CSV tile data cannot be compressed, got {c:?}"),
            })
        }
        // XML tile data is counted as its `<tile>` elements come.
        (None, _) => return Ok(None),
        (Some(e), _) => {
            return Err(LevelError::BadValue {
                file: file.into(),
                field: format!("{}.encoding", d.field),
                message: format!("unknown tile data encoding {e:?} (expected csv or base64)"),
            })
        }
    };
    check_cells(file, d, got, remaining)?;
    Ok(gids)
}

/// Checks the `got` cells of one `<data>` (or `<chunk>`): within the load's
/// remaining cells, and exactly the layer's (or chunk's) width x height.
fn check_cells(file: &str, d: &DataScan, got: u64, remaining: u64) -> Result<(), LevelError> {
    let expected = d.expected;
    let over = match expected {
        Some(n) => got > n.saturating_add(remaining),
        None => got > remaining,
    };
    if over {
        return Err(LevelError::Limit {
            file: file.into(),
            field: d.field.clone(),
            what: "tile cells in all layers (decoding stopped there)".into(),
            limit: MAX_LEVEL_CELLS,
            found: MAX_LEVEL_CELLS.saturating_add(1),
            bound: "MAX_LEVEL_CELLS",
        });
    }
    if let Some(n) = expected {
        if got != n {
            return Err(LevelError::Length {
                file: file.into(),
                field: d.field.clone(),
                expected: n,
                got,
            });
        }
    }
    Ok(())
}

/// Tile data decoded to 4-byte little-endian gids: the first `keep` are kept,
/// the rest only counted.
struct Cells {
    keep: usize,
    gids: Vec<u32>,
    part: [u8; 4],
    filled: usize,
    bytes: u64,
}

impl Cells {
    fn new(keep: usize) -> Self {
        Cells {
            keep,
            gids: Vec::with_capacity(keep.min(1 << 16)),
            part: [0; 4],
            filled: 0,
            bytes: 0,
        }
    }
}

impl io::Write for Cells {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        for &b in buf {
            self.part[self.filled] = b;
            self.filled += 1;
            if self.filled == 4 {
                self.filled = 0;
                if self.gids.len() < self.keep {
                    self.gids.push(u32::from_le_bytes(self.part));
                }
            }
        }
        self.bytes += buf.len() as u64;
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Smallest zstd window accepted whatever the cap (a streaming encoder
/// that does not know the input's size announces its level's window, up to
/// 8 MiB at level 19); the decoder reserves the window up front.
const MIN_ZSTD_WINDOW: u64 = 8 << 20;

/// Decodes the zstd frames of base64 text `b64` into `cells`, stopping after
/// `cap + 1` bytes of output. The decoder's window (its memory) is at most
/// the larger of the cap and [`MIN_ZSTD_WINDOW`].
fn zstd_cells(b64: impl Read, cap: u64, cells: &mut Cells) -> io::Result<()> {
    // The compressed bytes are at most 3/4 of the text, already held.
    let mut data = Vec::new();
    b64.take(MAX_FILE_BYTES).read_to_end(&mut data)?;
    let max_window = cap.max(MIN_ZSTD_WINDOW);
    let mut src = data.as_slice();
    // A frame at least, then any frames concatenated after it.
    loop {
        let decoder =
            ruzstd::decoding::StreamingDecoder::new_with_max_window_size(&mut src, max_window)
                .map_err(io::Error::other)?;
        let left = cap.saturating_add(1).saturating_sub(cells.bytes);
        io::copy(&mut decoder.take(left), cells)?;
        if src.is_empty() || cells.bytes > cap {
            return Ok(());
        }
    }
}

/// Reads `r` to its end or to `cap + 1` bytes, whichever is first, into a
/// small buffer, and returns how many bytes there were.
fn count_bytes(r: impl Read, cap: u64) -> io::Result<u64> {
    io::copy(&mut r.take(cap.saturating_add(1)), &mut io::sink())
}

fn memchr_count(b: u8, s: &[u8]) -> u64 {
    s.iter().filter(|&&c| c == b).count() as u64
}

fn trim_ascii(s: &[u8]) -> &[u8] {
    let start = s
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(s.len());
    let end = s
        .iter()
        .rposition(|c| !c.is_ascii_whitespace())
        .map_or(start, |e| e + 1);
    &s[start..end]
}

/// The width and height of a PNG file, from its header (24 bytes read).
fn png_size(path: &Path) -> Option<(u32, u32)> {
    let f = std::fs::File::open(path).ok()?;
    let mut head = Vec::with_capacity(24);
    f.take(24).read_to_end(&mut head).ok()?;
    if head.len() < 24 || &head[..8] != b"\x89PNG\r\n\x1a\n" || &head[12..16] != b"IHDR" {
        return None;
    }
    let w = u32::from_be_bytes(head[16..20].try_into().ok()?);
    let h = u32::from_be_bytes(head[20..24].try_into().ok()?);
    Some((w, h))
}

/// Checks an OGMO or LDtk JSON document before `serde_json` parses it: its size,
/// nesting depth ([`MAX_JSON_DEPTH`]) and number of values
/// ([`MAX_JSON_VALUES`]), in one pass without allocating.
pub(crate) fn check_json(file: &str, text: &str) -> Result<(), LevelError> {
    let b = text.as_bytes();
    if b.len() as u64 > MAX_FILE_BYTES {
        return Err(limit(
            file,
            "(document)",
            "bytes",
            MAX_FILE_BYTES,
            b.len() as u64,
            "MAX_FILE_BYTES",
        ));
    }
    let (mut depth, mut values) = (0usize, 0u64);
    let mut i = 0;
    let mut prev_scalar = false;
    while i < b.len() {
        let c = b[i];
        let starts_value = match c {
            b'[' | b'{' => {
                depth += 1;
                if depth > MAX_JSON_DEPTH {
                    return Err(limit(
                        file,
                        format!("byte {i}"),
                        "levels of array and object nesting",
                        MAX_JSON_DEPTH as u64,
                        depth as u64,
                        "MAX_JSON_DEPTH",
                    ));
                }
                prev_scalar = false;
                true
            }
            b']' | b'}' => {
                depth = depth.saturating_sub(1);
                prev_scalar = false;
                false
            }
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                prev_scalar = false;
                true
            }
            b',' | b':' | b' ' | b'\t' | b'\n' | b'\r' => {
                prev_scalar = false;
                false
            }
            _ => {
                // A number or literal: count it once.
                let first = !prev_scalar;
                prev_scalar = true;
                first
            }
        };
        if starts_value {
            values += 1;
            if values > MAX_JSON_VALUES {
                return Err(limit(
                    file,
                    format!("byte {i}"),
                    "JSON values (numbers, strings, arrays, objects)",
                    MAX_JSON_VALUES,
                    values,
                    "MAX_JSON_VALUES",
                ));
            }
        }
        i += 1;
    }
    Ok(())
}
