//! The grid: storage, validation, world <-> tile coordinates, point queries.

use glam::IVec2;
use serde::{Deserialize, Serialize};

use super::{Tile, TilemapError};
use crate::fixed::{check_coord, check_extent};

/// A grid of [`Tile`]s placed in the world, looked up by division: collision
/// against it never creates a collider per tile.
///
/// Tile `(c, r)` covers world x in `[origin.x + c * T, origin.x + (c + 1) * T)`
/// and y in `[origin.y + r * T, origin.y + (r + 1) * T)` (`T` = tile size;
/// y grows down, so row 0 is the top row). Cells outside the grid are
/// [`Tile::Empty`].
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "TilemapRepr", into = "TilemapRepr")]
pub struct Tilemap {
    origin: IVec2,
    tile_size: i32,
    width: u32,
    height: u32,
    tiles: Vec<Tile>,
}

/// The serialised form, validated by [`Tilemap::new`] on the way in.
#[derive(Serialize, Deserialize)]
struct TilemapRepr {
    origin: IVec2,
    tile_size: i32,
    width: u32,
    height: u32,
    tiles: Vec<Tile>,
}

impl TryFrom<TilemapRepr> for Tilemap {
    type Error = TilemapError;
    fn try_from(r: TilemapRepr) -> Result<Self, TilemapError> {
        Tilemap::new(r.origin, r.tile_size, r.width, r.height, r.tiles)
    }
}

impl From<Tilemap> for TilemapRepr {
    fn from(m: Tilemap) -> Self {
        TilemapRepr {
            origin: m.origin,
            tile_size: m.tile_size,
            width: m.width,
            height: m.height,
            tiles: m.tiles,
        }
    }
}

impl Tilemap {
    /// A `width` x `height` grid whose top-left corner is at `origin` (units),
    /// with square tiles of `tile_size` units, `tiles` in row-major order
    /// (row 0 first).
    ///
    /// `tile_size` must be even, at least 2 units and at most
    /// [`crate::fixed::MAX_EXTENT`]: any whole number of pixels qualifies
    /// (16 px is 4096 units, 21 px is 5376). Nothing needs a power of two
    /// (lookups are floor divisions, never shifts or masks); evenness keeps a
    /// tile's centre and the middle of a 22.5 degree ramp (`T / 2`) on whole
    /// units. Both corners of the grid must lie within
    /// [`crate::fixed::MAX_COORD`]; `tiles.len()` must be `width * height`.
    /// Errors name the offending value.
    pub fn new(
        origin: IVec2,
        tile_size: i32,
        width: u32,
        height: u32,
        tiles: Vec<Tile>,
    ) -> Result<Self, TilemapError> {
        if tile_size < 2 || tile_size % 2 != 0 {
            return Err(TilemapError::TileSize {
                value: tile_size as i64,
            });
        }
        check_extent("tile size", tile_size as i64)?;
        check_coord("tilemap origin x", origin.x as i64)?;
        check_coord("tilemap origin y", origin.y as i64)?;
        check_coord(
            "tilemap right edge x",
            origin.x as i64 + width as i64 * tile_size as i64,
        )?;
        check_coord(
            "tilemap bottom edge y",
            origin.y as i64 + height as i64 * tile_size as i64,
        )?;
        let expected = width as u64 * height as u64;
        if tiles.len() as u64 != expected {
            return Err(TilemapError::TileCount {
                width,
                height,
                expected,
                got: tiles.len() as u64,
            });
        }
        Ok(Self {
            origin,
            tile_size,
            width,
            height,
            tiles,
        })
    }

    /// World position of the grid's top-left corner, in units.
    #[inline]
    pub fn origin(&self) -> IVec2 {
        self.origin
    }

    /// Side of one tile, in units.
    #[inline]
    pub fn tile_size(&self) -> i32 {
        self.tile_size
    }

    /// Width in tiles.
    #[inline]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in tiles.
    #[inline]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// All tiles, row-major.
    #[inline]
    pub fn tiles(&self) -> &[Tile] {
        &self.tiles
    }

    /// The tile at tile coordinates `tile`; [`Tile::Empty`] outside the grid.
    #[inline]
    pub fn tile(&self, tile: IVec2) -> Tile {
        self.at(tile.x as i64, tile.y as i64)
    }

    /// Tile coordinates of the tile containing world point `p` (floor
    /// division of `p - origin` by the tile size; may lie outside the grid).
    #[inline]
    pub fn tile_of(&self, p: IVec2) -> IVec2 {
        IVec2::new(
            self.col_of(p.x as i64) as i32,
            self.row_of(p.y as i64) as i32,
        )
    }

    /// Whether the unit cell at `p` (the square `[p, p + 1)`) is solid
    /// material: inside a [`Tile::Solid`] tile, or on or below the surface of
    /// a slope tile. One-way, hazard and empty tiles are never solid.
    pub fn is_solid_at(&self, p: IVec2) -> bool {
        let (c, r) = (self.col_of(p.x as i64), self.row_of(p.y as i64));
        match self.at(c, r) {
            Tile::Solid => true,
            Tile::Slope(s) => {
                let t = self.tile_size as i64;
                let bottom = self.row_top(r) + t;
                p.y as i64 >= bottom - s.height64(p.x as i64 - self.col_left(c), t)
            }
            _ => false,
        }
    }

    // Internal coordinates are i64: `p - origin` can exceed i32.

    /// The tile at `(c, r)`, empty outside the grid.
    #[inline]
    pub(crate) fn at(&self, c: i64, r: i64) -> Tile {
        if c >= 0 && r >= 0 && c < self.width as i64 && r < self.height as i64 {
            self.tiles[(r as usize) * self.width as usize + c as usize]
        } else {
            Tile::Empty
        }
    }

    /// Column containing world x.
    #[inline]
    pub(crate) fn col_of(&self, x: i64) -> i64 {
        (x - self.origin.x as i64).div_euclid(self.tile_size as i64)
    }

    /// Row containing world y.
    #[inline]
    pub(crate) fn row_of(&self, y: i64) -> i64 {
        (y - self.origin.y as i64).div_euclid(self.tile_size as i64)
    }

    /// World x of column `c`'s left edge.
    #[inline]
    pub(crate) fn col_left(&self, c: i64) -> i64 {
        self.origin.x as i64 + c * self.tile_size as i64
    }

    /// World y of row `r`'s top edge.
    #[inline]
    pub(crate) fn row_top(&self, r: i64) -> i64 {
        self.origin.y as i64 + r * self.tile_size as i64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::{BoundsError, MAX_COORD};
    use crate::tilemap::Slope;

    fn map() -> Tilemap {
        // 2 x 2: [Solid, '/'], [Empty, Hazard]; origin negative and unaligned.
        Tilemap::new(
            IVec2::new(-1000, -77),
            256,
            2,
            2,
            vec![
                Tile::Solid,
                Tile::Slope(Slope::Right45),
                Tile::Empty,
                Tile::Hazard,
            ],
        )
        .unwrap()
    }

    #[test]
    fn lookup_by_floor_division() {
        let m = map();
        assert_eq!(m.tile_of(IVec2::new(-1000, -77)), IVec2::new(0, 0));
        assert_eq!(m.tile_of(IVec2::new(-1001, -78)), IVec2::new(-1, -1));
        assert_eq!(
            m.tile_of(IVec2::new(-1000 + 256, -77 + 255)),
            IVec2::new(1, 0)
        );
        assert_eq!(m.tile(IVec2::new(1, 0)), Tile::Slope(Slope::Right45));
        assert_eq!(m.tile(IVec2::new(1, 1)), Tile::Hazard);
        for out in [
            IVec2::new(-1, 0),
            IVec2::new(0, -1),
            IVec2::new(2, 0),
            IVec2::new(0, 2),
            IVec2::new(i32::MIN, i32::MAX),
        ] {
            assert_eq!(m.tile(out), Tile::Empty);
        }
    }

    #[test]
    fn solid_points() {
        let m = map();
        assert!(m.is_solid_at(IVec2::new(-1000, -77)));
        assert!(!m.is_solid_at(IVec2::new(-1001, -77)));
        // '/' tile: left edge x = -744, bottom y = 179; surface at offset x is 179 - x.
        assert!(m.is_solid_at(IVec2::new(-744 + 10, 179 - 10)));
        assert!(!m.is_solid_at(IVec2::new(-744 + 10, 179 - 11)));
        assert!(!m.is_solid_at(IVec2::new(-744, 178)));
        assert!(!m.is_solid_at(IVec2::new(-1000 + 300, -77 + 300))); // hazard
    }

    #[test]
    fn errors_name_the_value() {
        let e = Tilemap::new(IVec2::ZERO, 3001, 1, 1, vec![Tile::Solid]).unwrap_err();
        assert_eq!(e, TilemapError::TileSize { value: 3001 });
        assert!(e.to_string().contains("3001"));
        // Any even size is fine: 3000 units, 21 px, 2 units.
        for t in [3000, 21 * 256, 2, crate::fixed::MAX_EXTENT] {
            assert!(Tilemap::new(IVec2::ZERO, t, 1, 1, vec![Tile::Solid]).is_ok());
        }
        for t in [1, 3, 255, 257, 21 * 256 + 1, -2] {
            assert_eq!(
                Tilemap::new(IVec2::ZERO, t, 1, 1, vec![Tile::Solid]),
                Err(TilemapError::TileSize { value: t as i64 })
            );
        }
        let e =
            Tilemap::new(IVec2::new(0, MAX_COORD + 1), 256, 1, 1, vec![Tile::Solid]).unwrap_err();
        assert_eq!(
            e,
            TilemapError::Bounds(BoundsError::Coord {
                what: "tilemap origin y",
                value: MAX_COORD as i64 + 1
            })
        );
        let e = Tilemap::new(
            IVec2::new(MAX_COORD - 256, 0),
            256,
            2,
            1,
            vec![Tile::Solid; 2],
        )
        .unwrap_err();
        assert!(e.to_string().contains("tilemap right edge x"), "{e}");
        let e = Tilemap::new(IVec2::ZERO, 256, 3, 2, vec![Tile::Solid; 5]).unwrap_err();
        assert_eq!(
            e,
            TilemapError::TileCount {
                width: 3,
                height: 2,
                expected: 6,
                got: 5
            }
        );
        assert!(Tilemap::new(IVec2::ZERO, 1 << 28, 1, 1, vec![Tile::Solid]).is_err());
        assert!(Tilemap::new(IVec2::ZERO, 0, 1, 1, vec![Tile::Solid]).is_err());
        assert!(Tilemap::new(IVec2::ZERO, -256, 1, 1, vec![Tile::Solid]).is_err());
    }

    #[test]
    fn serde_round_trip_validates() {
        let cfg = bincode::config::standard();
        let m = map();
        let bytes = bincode::serde::encode_to_vec(&m, cfg).unwrap();
        let (back, _): (Tilemap, usize) = bincode::serde::decode_from_slice(&bytes, cfg).unwrap();
        assert_eq!(back, m);
        // Corrupt the width: the tile count no longer matches.
        let bad = TilemapRepr {
            origin: m.origin,
            tile_size: 256,
            width: 3,
            height: 2,
            tiles: m.tiles.clone(),
        };
        let bytes = bincode::serde::encode_to_vec(&bad, cfg).unwrap();
        assert!(bincode::serde::decode_from_slice::<Tilemap, _>(&bytes, cfg).is_err());
    }
}
