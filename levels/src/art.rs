//! What a client draws for a level: the editor's own tile layers, tile
//! objects, image layers and tileset images.
//!
//! [`LevelArt`] is plain data, meant to travel to clients with the level
//! (a level bundle): images are kept as their encoded file bytes (PNG) under
//! their path relative to the level file, never decoded here. Only the PNG
//! header is read, for the image's size, and every size is bounded before
//! anything is allocated for it ([`MAX_ART_IMAGE_BYTES`],
//! [`MAX_ART_BYTES`], [`MAX_ART_IMAGES`], [`MAX_ART_IMAGE_SIDE`],
//! [`MAX_ART_TILES`], [`MAX_ART_CELLS`], [`MAX_ART_OBJECTS`]).
//!
//! * Layers are listed back to front (the order to draw them), groups
//!   flattened: a group's offset adds to its children's, its opacity and
//!   parallax factors multiply theirs, and a hidden group hides them.
//!   Hidden layers and hidden objects are left out.
//! * Only the tilesets and images that something drawn uses are kept.
//! * Tiled: tile layers, tile objects (on object layers; other shapes are
//!   not drawn), image layers, the map's background colour. OGMO Editor 3:
//!   tile layers whose project tileset embeds its image (a `data:` URI, as
//!   OGMO writes it), the project's background colour; OGMO draws its first
//!   layer on top, so the layers are listed last to first.

pub mod covered;
pub(crate) mod ogmo;
pub(crate) mod tiled;

use serde::{Deserialize, Serialize};

use crate::LevelError;

/// Largest image file, bytes (16 MiB).
pub const MAX_ART_IMAGE_BYTES: u64 = 16 << 20;
/// Largest sum of a level's image files, bytes (64 MiB).
pub const MAX_ART_BYTES: u64 = 64 << 20;
/// Most images in a level.
pub const MAX_ART_IMAGES: usize = 1024;
/// Widest or tallest image, pixels (as its PNG header says).
pub const MAX_ART_IMAGE_SIDE: u32 = 8192;
/// Most tiles in one tileset.
pub const MAX_ART_TILES: u32 = 1 << 16;
/// Most cells of all tile layers together (empty ones included).
pub const MAX_ART_CELLS: u64 = 1 << 22;
/// Most tile objects of all object layers together.
pub const MAX_ART_OBJECTS: usize = 1 << 16;

/// A level's art (empty when the level has none): what to draw, back to
/// front, and the images it is drawn from.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LevelArt {
    /// The map's background colour, RGBA (none: the game's own background).
    pub background: Option<[u8; 4]>,
    /// The map's extent, world pixels (Tiled: its cells; OGMO: its tile
    /// layers'), for a camera when the collision grid is smaller.
    pub size: (f32, f32),
    /// Where parallax factors are measured from (world pixels; Tiled's
    /// `parallaxoriginx/y`, else the origin).
    pub parallax_origin: (f32, f32),
    /// Image files, each once.
    pub images: Vec<ArtImage>,
    /// Tilesets that layers use ([`ArtCell::tileset`] indexes this).
    pub tilesets: Vec<ArtTileset>,
    /// Layers to draw, back to front.
    pub layers: Vec<ArtLayer>,
    /// What was left out, one line each (an image that cannot be read or
    /// is not a PNG, and what uses it). Not sent.
    #[serde(skip)]
    pub warnings: Vec<String>,
}

/// An image file, as found (encoded bytes).
#[derive(Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ArtImage {
    /// Its path relative to the level file's folder, `/`-separated (for an
    /// image embedded in an OGMO project: the tileset's `path`, else its
    /// label with `.png`).
    pub name: String,
    /// Width, pixels, from the PNG header.
    pub width: u32,
    /// Height, pixels, from the PNG header.
    pub height: u32,
    /// A colour to draw as transparent (Tiled's `trans`), RGB.
    pub transparent: Option<[u8; 3]>,
    /// The file's bytes (a PNG).
    pub bytes: Vec<u8>,
}

impl std::fmt::Debug for ArtImage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ArtImage")
            .field("name", &self.name)
            .field("width", &self.width)
            .field("height", &self.height)
            .field("transparent", &self.transparent)
            .field("bytes", &format_args!("[{} bytes]", self.bytes.len()))
            .finish()
    }
}

/// A tileset: one image cut into a grid of tiles (an atlas), or an image
/// per tile (an image collection).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ArtTileset {
    /// Its name in the editor.
    pub name: String,
    /// Tile width, pixels (the largest tile of a collection).
    pub tile_width: u32,
    /// Tile height, pixels.
    pub tile_height: u32,
    /// Tiles per row of the atlas.
    pub columns: u32,
    /// Pixels around the atlas's tiles.
    pub margin: u32,
    /// Pixels between the atlas's tiles.
    pub spacing: u32,
    /// Where tiles are drawn relative to their cell, pixels (Tiled's
    /// `tileoffset`).
    pub offset: (i32, i32),
    /// Number of tiles (an atlas's ids are `0..tile_count`).
    pub tile_count: u32,
    /// The atlas image ([`LevelArt::images`] index); none for a collection.
    pub image: Option<u32>,
    /// A collection's tiles that are used, by id.
    pub tiles: Vec<CollectionTile>,
}

/// One tile of an image collection.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CollectionTile {
    /// Its id in the tileset.
    pub id: u32,
    /// Its image ([`LevelArt::images`] index).
    pub image: u32,
    /// The part of the image that is the tile: `[x, y, width, height]`.
    pub rect: [u32; 4],
}

/// Where a tile's pixels are: an image and a rectangle of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileSource {
    /// [`LevelArt::images`] index.
    pub image: u32,
    /// Left, pixels.
    pub x: u32,
    /// Top, pixels.
    pub y: u32,
    /// Width, pixels.
    pub w: u32,
    /// Height, pixels.
    pub h: u32,
}

impl ArtTileset {
    /// Where tile `id` is, if the tileset has it (inside its image).
    pub fn source(&self, id: u32, images: &[ArtImage]) -> Option<TileSource> {
        match self.image {
            Some(image) => {
                if id >= self.tile_count || self.columns == 0 {
                    return None;
                }
                let (col, row) = (id % self.columns, id / self.columns);
                let x = self.margin as u64 + col as u64 * (self.tile_width + self.spacing) as u64;
                let y = self.margin as u64 + row as u64 * (self.tile_height + self.spacing) as u64;
                let img = images.get(image as usize)?;
                (x + self.tile_width as u64 <= img.width as u64
                    && y + self.tile_height as u64 <= img.height as u64)
                    .then_some(TileSource {
                        image,
                        x: x as u32,
                        y: y as u32,
                        w: self.tile_width,
                        h: self.tile_height,
                    })
            }
            None => {
                let i = self.tiles.binary_search_by_key(&id, |t| t.id).ok()?;
                let t = self.tiles[i];
                Some(TileSource {
                    image: t.image,
                    x: t.rect[0],
                    y: t.rect[1],
                    w: t.rect[2],
                    h: t.rect[3],
                })
            }
        }
    }
}

/// One layer to draw.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArtLayer {
    /// Its name (groups' names first, `/`-separated).
    pub name: String,
    /// Shift, pixels (groups' offsets added).
    pub offset: (f32, f32),
    /// Parallax factors (1: moves with the level; groups' multiplied).
    pub parallax: (f32, f32),
    /// Opacity in `[0, 1]` (groups' multiplied).
    pub opacity: f32,
    /// What it holds.
    pub content: ArtContent,
}

/// What a layer holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ArtContent {
    /// A grid of tiles.
    Tiles(TileGrid),
    /// Tile objects, in drawing order.
    Objects(Vec<ArtObject>),
    /// One image, its top-left corner at the layer's offset.
    Image {
        /// [`LevelArt::images`] index.
        image: u32,
        /// Repeated across the level horizontally.
        repeat_x: bool,
        /// Repeated vertically.
        repeat_y: bool,
    },
}

/// A tile layer's cells.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TileGrid {
    /// Cells across.
    pub width: u32,
    /// Cells down.
    pub height: u32,
    /// Cell width, pixels.
    pub cell_width: u32,
    /// Cell height, pixels.
    pub cell_height: u32,
    /// Row-major cells; `None` is empty.
    pub cells: Vec<Option<ArtCell>>,
}

impl TileGrid {
    /// The cell at column `x`, row `y`.
    pub fn get(&self, x: u32, y: u32) -> Option<&ArtCell> {
        if x >= self.width || y >= self.height {
            return None;
        }
        self.cells
            .get(y as usize * self.width as usize + x as usize)?
            .as_ref()
    }
}

/// A tile placed in a cell. A tile is drawn with its bottom-left corner at
/// its cell's bottom-left corner, plus its tileset's offset (Tiled's
/// rule; tiles larger than the cell reach up and right).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ArtCell {
    /// [`LevelArt::tilesets`] index.
    pub tileset: u32,
    /// Tile id in that tileset.
    pub tile: u32,
    /// Mirrored left to right (applied after `flip_d`).
    pub flip_h: bool,
    /// Mirrored top to bottom (applied after `flip_d`).
    pub flip_v: bool,
    /// Mirrored across the top-left to bottom-right diagonal (x and y
    /// swapped), first.
    pub flip_d: bool,
}

/// A tile object: a tile stretched to a box, rotated about its
/// bottom-left corner.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ArtObject {
    /// [`LevelArt::tilesets`] index.
    pub tileset: u32,
    /// Tile id in that tileset.
    pub tile: u32,
    /// Bottom-left corner (the object's anchor), world pixels before the
    /// layer's offset.
    pub x: f32,
    /// Bottom-left corner, y.
    pub y: f32,
    /// Width, pixels (the tile is stretched to it).
    pub width: f32,
    /// Height, pixels.
    pub height: f32,
    /// Clockwise rotation about `(x, y)`, degrees.
    pub rotation: f32,
    /// Mirrored left to right (within its box).
    pub flip_h: bool,
    /// Mirrored top to bottom.
    pub flip_v: bool,
    /// Opacity of the object, in `[0, 1]`.
    pub opacity: f32,
}

impl LevelArt {
    /// Checks art that came from elsewhere (a server's level bundle) against
    /// the bounds the loaders keep: counts and sizes within the `MAX_ART_*`
    /// limits, every image a PNG whose header gives the size it claims, and
    /// every index (image, tileset) in range, so drawing it cannot index out
    /// of bounds or decode an oversized image.
    pub fn check(&self) -> Result<(), String> {
        if self.images.len() > MAX_ART_IMAGES {
            return Err(format!(
                "{} images, more than {MAX_ART_IMAGES}",
                self.images.len()
            ));
        }
        if self.image_bytes() > MAX_ART_BYTES {
            return Err(format!(
                "{} bytes of images, more than {MAX_ART_BYTES}",
                self.image_bytes()
            ));
        }
        for (i, image) in self.images.iter().enumerate() {
            let size = png_size(&image.bytes);
            if image.bytes.len() as u64 > MAX_ART_IMAGE_BYTES
                || size != Some((image.width, image.height))
                || image.width > MAX_ART_IMAGE_SIDE
                || image.height > MAX_ART_IMAGE_SIDE
            {
                return Err(format!(
                    "image {i} ({:?}) is not a PNG of {}x{} pixels (at most \
                     {MAX_ART_IMAGE_SIDE} a side and {MAX_ART_IMAGE_BYTES} bytes)",
                    image.name, image.width, image.height
                ));
            }
        }
        let image_ok = |i: u32| (i as usize) < self.images.len();
        for (t, set) in self.tilesets.iter().enumerate() {
            let bad = |what: &str| Err(format!("tileset {t} ({:?}): {what}", set.name));
            if set.tile_count > MAX_ART_TILES || set.tiles.len() > MAX_ART_TILES as usize {
                return bad("too many tiles");
            }
            if set.image.is_some_and(|i| !image_ok(i)) {
                return bad("its image is not in the bundle");
            }
            if set.tiles.iter().any(|tile| !image_ok(tile.image)) {
                return bad("a tile's image is not in the bundle");
            }
            if set.tiles.windows(2).any(|w| w[0].id >= w[1].id) {
                return bad("tiles not in ascending id order");
            }
        }
        let tileset_ok = |i: u32| (i as usize) < self.tilesets.len();
        let (mut cells, mut objects) = (0u64, 0usize);
        for (l, layer) in self.layers.iter().enumerate() {
            let bad = |what: &str| Err(format!("layer {l} ({:?}): {what}", layer.name));
            match &layer.content {
                ArtContent::Tiles(grid) => {
                    cells += grid.cells.len() as u64;
                    if u64::from(grid.width) * u64::from(grid.height) != grid.cells.len() as u64 {
                        return bad("its cells do not fill its grid");
                    }
                    if grid.cells.iter().flatten().any(|c| !tileset_ok(c.tileset)) {
                        return bad("a cell's tileset is not in the bundle");
                    }
                }
                ArtContent::Objects(list) => {
                    objects += list.len();
                    if list.iter().any(|o| !tileset_ok(o.tileset)) {
                        return bad("an object's tileset is not in the bundle");
                    }
                }
                ArtContent::Image { image, .. } => {
                    if !image_ok(*image) {
                        return bad("its image is not in the bundle");
                    }
                }
            }
        }
        if cells > MAX_ART_CELLS {
            return Err(format!("{cells} cells, more than {MAX_ART_CELLS}"));
        }
        if objects > MAX_ART_OBJECTS {
            return Err(format!(
                "{objects} tile objects, more than {MAX_ART_OBJECTS}"
            ));
        }
        Ok(())
    }

    /// Whether there is nothing to draw.
    pub fn is_empty(&self) -> bool {
        self.layers.is_empty()
    }

    /// Where a cell's or object's tile is.
    pub fn source(&self, tileset: u32, tile: u32) -> Option<TileSource> {
        self.tilesets
            .get(tileset as usize)?
            .source(tile, &self.images)
    }

    /// Bytes of all images.
    pub fn image_bytes(&self) -> u64 {
        self.images.iter().map(|i| i.bytes.len() as u64).sum()
    }
}

/// The size of a PNG from its header (`None`: not a PNG).
pub fn png_size(bytes: &[u8]) -> Option<(u32, u32)> {
    if bytes.get(..8)? != b"\x89PNG\r\n\x1a\n" || bytes.get(12..16)? != b"IHDR" {
        return None;
    }
    let w = u32::from_be_bytes(bytes.get(16..20)?.try_into().ok()?);
    let h = u32::from_be_bytes(bytes.get(20..24)?.try_into().ok()?);
    Some((w, h))
}

/// Builds a [`LevelArt`]'s image list within the bounds.
#[derive(Default)]
pub(crate) struct Images {
    images: Vec<ArtImage>,
    /// Key (resolved path or embedded name) of each image.
    keys: Vec<String>,
    total: u64,
}

impl Images {
    /// The index of the image under `key`, if already added.
    pub fn find(&self, key: &str) -> Option<u32> {
        self.keys.iter().position(|k| k == key).map(|i| i as u32)
    }

    /// Adds an image file's bytes (checked: a PNG, within every bound).
    /// Errors name `file` (the level, or the OGMO project) and, in the
    /// field, what uses the image (`field`) and the image (`name`).
    pub fn add(
        &mut self,
        file: &str,
        field: &str,
        key: String,
        name: String,
        transparent: Option<[u8; 3]>,
        bytes: Vec<u8>,
    ) -> Result<u32, LevelError> {
        if let Some(i) = self.find(&key) {
            return Ok(i);
        }
        let field = &format!("{field} (image {name:?})");
        if self.images.len() >= MAX_ART_IMAGES {
            return Err(LevelError::OutOfBounds {
                file: file.into(),
                field: field.into(),
                message: format!("more than {MAX_ART_IMAGES} images (MAX_ART_IMAGES)"),
            });
        }
        check_image_bytes(file, field, bytes.len() as u64)?;
        if self.total + bytes.len() as u64 > MAX_ART_BYTES {
            return Err(LevelError::OutOfBounds {
                file: file.into(),
                field: field.into(),
                message: format!(
                    "the level's images come to more than {MAX_ART_BYTES} bytes (MAX_ART_BYTES)"
                ),
            });
        }
        let Some((width, height)) = png_size(&bytes) else {
            return Err(LevelError::BadValue {
                file: file.into(),
                field: field.into(),
                message: "not a PNG image (level art must be PNG)".into(),
            });
        };
        if width == 0 || height == 0 || width > MAX_ART_IMAGE_SIDE || height > MAX_ART_IMAGE_SIDE {
            return Err(LevelError::OutOfBounds {
                file: file.into(),
                field: field.into(),
                message: format!(
                    "image of {width} x {height} px: each side must be 1 to {MAX_ART_IMAGE_SIDE} px (MAX_ART_IMAGE_SIDE)"
                ),
            });
        }
        self.total += bytes.len() as u64;
        self.keys.push(key);
        self.images.push(ArtImage {
            name,
            width,
            height,
            transparent,
            bytes,
        });
        Ok(self.images.len() as u32 - 1)
    }

    pub fn get(&self, i: u32) -> &ArtImage {
        &self.images[i as usize]
    }

    pub fn as_slice(&self) -> &[ArtImage] {
        &self.images
    }

    pub fn into_vec(self) -> Vec<ArtImage> {
        self.images
    }
}

/// Refuses an image file larger than [`MAX_ART_IMAGE_BYTES`].
pub(crate) fn check_image_bytes(file: &str, field: &str, len: u64) -> Result<(), LevelError> {
    if len > MAX_ART_IMAGE_BYTES {
        return Err(LevelError::OutOfBounds {
            file: file.into(),
            field: field.into(),
            message: format!(
                "{len} bytes is more than {MAX_ART_IMAGE_BYTES} bytes (MAX_ART_IMAGE_BYTES)"
            ),
        });
    }
    Ok(())
}

/// Counts cells and objects against [`MAX_ART_CELLS`] and
/// [`MAX_ART_OBJECTS`].
#[derive(Default)]
pub(crate) struct Budget {
    cells: u64,
    objects: usize,
}

impl Budget {
    pub fn cells(&mut self, level: &str, field: &str, n: u64) -> Result<(), LevelError> {
        self.cells += n;
        if self.cells > MAX_ART_CELLS {
            return Err(LevelError::OutOfBounds {
                file: level.into(),
                field: field.into(),
                message: format!(
                    "the tile layers have more than {MAX_ART_CELLS} cells together (MAX_ART_CELLS)"
                ),
            });
        }
        Ok(())
    }

    pub fn object(&mut self, level: &str, field: &str) -> Result<(), LevelError> {
        self.objects += 1;
        if self.objects > MAX_ART_OBJECTS {
            return Err(LevelError::OutOfBounds {
                file: level.into(),
                field: field.into(),
                message: format!("more than {MAX_ART_OBJECTS} tile objects (MAX_ART_OBJECTS)"),
            });
        }
        Ok(())
    }
}

/// Refuses a tileset of more than [`MAX_ART_TILES`] tiles.
pub(crate) fn check_tile_count(level: &str, field: &str, n: u64) -> Result<(), LevelError> {
    if n > MAX_ART_TILES as u64 {
        return Err(LevelError::OutOfBounds {
            file: level.into(),
            field: field.into(),
            message: format!("{n} tiles is more than {MAX_ART_TILES} (MAX_ART_TILES)"),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_size_reads_ihdr() {
        let mut b = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR".to_vec();
        b.extend_from_slice(&265u32.to_be_bytes());
        b.extend_from_slice(&199u32.to_be_bytes());
        assert_eq!(png_size(&b), Some((265, 199)));
        assert_eq!(png_size(b"GIF89a"), None);
        assert_eq!(png_size(&b[..20]), None);
    }

    #[test]
    fn atlas_source_rects_skip_margin_and_spacing() {
        let images = vec![ArtImage {
            name: "t.png".into(),
            width: 265,
            height: 199,
            transparent: None,
            bytes: Vec::new(),
        }];
        let ts = ArtTileset {
            tile_width: 32,
            tile_height: 32,
            columns: 8,
            margin: 1,
            spacing: 1,
            tile_count: 48,
            image: Some(0),
            ..ArtTileset::default()
        };
        let s = ts.source(9, &images).unwrap();
        assert_eq!((s.x, s.y, s.w, s.h), (34, 34, 32, 32));
        assert_eq!(ts.source(47, &images).unwrap().x, 1 + 7 * 33);
        assert_eq!(ts.source(48, &images), None);
    }
}
