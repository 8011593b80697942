//! How editor tiles become [`Tile`]s: per-tileset id tables, grid values,
//! and tile kind names.

use std::collections::BTreeMap;

use ledge_shared::tilemap::{Slope, Tile};

/// The echo-slopes tileset (`echo-slopes/project.ogmo`, image 208 x 32 px,
/// 16 px tiles, 13 columns x 2 rows, id = row * 13 + column), id by id, as
/// read from the image's pixels:
///
/// | id | picture | tile |
/// |---|---|---|
/// | 0, 13, 14, 25 | blank | [`Tile::Empty`] |
/// | 1 | full block | [`Tile::Solid`] |
/// | 2 | 45 degree floor rising right `/` | [`Slope::Right45`] |
/// | 3 | 45 degree floor rising left `\` | [`Slope::Left45`] |
/// | 4 | 22.5 degree floor rising right, low half (0 to 8 px) | [`Slope::RightLow22`] |
/// | 5 | 22.5 degree floor rising right, high half (8 to 16 px) | [`Slope::RightHigh22`] |
/// | 6 | 22.5 degree floor rising left, high half | [`Slope::LeftHigh22`] |
/// | 7 | 22.5 degree floor rising left, low half | [`Slope::LeftLow22`] |
/// | 8 | 63.4 degree (2:1) floor rising right, bottom tile (3/4 solid) | [`Tile::Solid`] |
/// | 9 | 63.4 degree floor rising left, bottom tile (3/4 solid) | [`Tile::Solid`] |
/// | 10 | 63.4 degree floor rising right, top tile (1/4 solid) | [`Tile::Empty`] |
/// | 11 | 63.4 degree floor rising left, top tile (1/4 solid) | [`Tile::Empty`] |
/// | 12 | thin plank at the tile top | [`Tile::OneWay`] |
/// | 15 | 45 degree ceiling, solid top-right | [`Tile::Solid`] |
/// | 16 | 45 degree ceiling, solid top-left | [`Tile::Solid`] |
/// | 17 | 22.5 degree ceiling, thin (1/4 solid) | [`Tile::Empty`] |
/// | 18 | 22.5 degree ceiling, thick (3/4 solid) | [`Tile::Solid`] |
/// | 19 | 22.5 degree ceiling, thick, mirrored | [`Tile::Solid`] |
/// | 20 | 22.5 degree ceiling, thin, mirrored | [`Tile::Empty`] |
/// | 21 | 63.4 degree ceiling, thick (3/4 solid) | [`Tile::Solid`] |
/// | 22 | 63.4 degree ceiling, thick, mirrored | [`Tile::Solid`] |
/// | 23 | 63.4 degree ceiling, thin (1/4 solid) | [`Tile::Empty`] |
/// | 24 | 63.4 degree ceiling, thin, mirrored | [`Tile::Empty`] |
///
/// Shapes the simulation has no tile for (ceilings, 63.4 degree floors)
/// become the nearest tile by area: solid when at least half the tile is
/// solid, empty otherwise.
pub const ECHO_SLOPES: [Tile; 26] = {
    use Slope::*;
    use Tile::{Empty as E, OneWay, Solid as S};
    [
        E,                       // 0
        S,                       // 1
        Tile::Slope(Right45),    // 2
        Tile::Slope(Left45),     // 3
        Tile::Slope(RightLow22), // 4
        Tile::Slope(RightHigh22),
        Tile::Slope(LeftHigh22),
        Tile::Slope(LeftLow22), // 7
        S,                      // 8
        S,                      // 9
        E,                      // 10
        E,                      // 11
        OneWay,                 // 12
        E,                      // 13
        E,                      // 14
        S,                      // 15
        S,                      // 16
        E,                      // 17
        S,                      // 18
        S,                      // 19
        E,                      // 20
        S,                      // 21
        S,                      // 22
        E,                      // 23
        E,                      // 24
        E,                      // 25
    ]
};

/// ledge's own tileset (`levels/default/ledge.png`, embedded in
/// `ledge.ogmo`): the echo-slopes layout ([`ECHO_SLOPES`]) with spikes drawn
/// in the blank slot 13, which is [`Tile::Hazard`].
pub const LEDGE_TILESET: [Tile; 26] = {
    let mut t = ECHO_SLOPES;
    t[13] = Tile::Hazard;
    t
};

/// How the ids of one tileset map to tiles.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum TileTable {
    /// `ids[id]` is the tile of `id`; an id past the end is an error.
    Ids(Vec<Tile>),
    /// Every placed tile is solid (for plain collision tilesets).
    AllSolid,
}

impl TileTable {
    /// The tile of `id`, `None` when the table has no entry for it.
    pub fn get(&self, id: u32) -> Option<Tile> {
        match self {
            TileTable::Ids(v) => v.get(id as usize).copied(),
            TileTable::AllSolid => Some(Tile::Solid),
        }
    }
}

/// The configurable mapping from editor tiles to [`Tile`]s.
///
/// * Tile layers (OGMO tile layers, Tiled tile layers): the [`TileTable`] of
///   the tileset (looked up by the tileset's label/name, case-insensitive),
///   when the mapping has one. The default mapping has one only for ledge's
///   own tileset, named `ledge` ([`LEDGE_TILESET`]): a foreign tileset never
///   gets ledge's table by accident. In Tiled, a tileset without a table
///   collides from the map's own data (tile collision shapes, properties,
///   classes; see `docs/LEVELS.md`, "What collides"); an OGMO tile layer
///   whose tileset has no table does not collide (with a warning).
///   [`TileMapping::new`] sets a table for every tileset instead.
/// * Grid layers (OGMO): the cell's string value. By default the value is the
///   tile's one-byte code ([`Tile::code`]): `"0"` empty, `"1"` solid, `"2"`
///   one-way, `"3"` hazard, `"4"`..`"9"` the slopes in [`Slope::ALL`] order;
///   kind names ([`parse_tile_kind`]) are accepted too. Add more with
///   [`TileMapping::with_grid_value`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TileMapping {
    tilesets: BTreeMap<String, TileTable>,
    default_table: Option<TileTable>,
    grid: BTreeMap<String, Tile>,
}

impl Default for TileMapping {
    /// [`LEDGE_TILESET`] for ledge's own tileset (`ledge`) only, grid values
    /// as tile codes.
    fn default() -> Self {
        Self {
            tilesets: BTreeMap::new(),
            default_table: None,
            grid: grid_codes(),
        }
        .with_tileset(LEDGE_TILESET_NAME, TileTable::Ids(LEDGE_TILESET.to_vec()))
    }
}

/// The name of ledge's own tileset (the default level's), the only one the
/// default mapping reads through [`LEDGE_TILESET`].
pub const LEDGE_TILESET_NAME: &str = "ledge";

fn grid_codes() -> BTreeMap<String, Tile> {
    (0..=9u8)
        .filter_map(|c| Some((c.to_string(), Tile::from_code(c)?)))
        .collect()
}

impl TileMapping {
    /// A mapping using `default_table` for every tileset, grid values as tile
    /// codes.
    pub fn new(default_table: TileTable) -> Self {
        Self {
            tilesets: BTreeMap::new(),
            default_table: Some(default_table),
            grid: grid_codes(),
        }
    }

    /// Uses `table` for the tileset labelled `name` (case-insensitive).
    pub fn with_tileset(mut self, name: &str, table: TileTable) -> Self {
        self.tilesets.insert(name.to_lowercase(), table);
        self
    }

    /// Maps the grid value `value` (exact, case-sensitive) to `tile`.
    pub fn with_grid_value(mut self, value: &str, tile: Tile) -> Self {
        self.grid.insert(value.to_owned(), tile);
        self
    }

    /// Whether tileset `tileset` has a table (its own or the default one).
    pub fn has_table(&self, tileset: &str) -> bool {
        self.table(tileset).is_some()
    }

    /// The tile of `id` in tileset `tileset`; `None` when the tileset has no
    /// table or the table has no entry for `id`.
    pub fn tile(&self, tileset: &str, id: u32) -> Option<Tile> {
        self.table(tileset)?.get(id)
    }

    fn table(&self, tileset: &str) -> Option<&TileTable> {
        self.tilesets
            .get(&tileset.to_lowercase())
            .or(self.default_table.as_ref())
    }

    /// The tile of a grid layer value; `None` when unmapped.
    pub fn grid_tile(&self, value: &str) -> Option<Tile> {
        self.grid
            .get(value)
            .copied()
            .or_else(|| parse_tile_kind(value))
    }
}

/// Tile kind names (Tiled's `kind` tile property, grid values), ASCII
/// case-insensitive, `-` and spaces read as `_`:
///
/// | name | tile |
/// |---|---|
/// | `empty`, `none` | [`Tile::Empty`] |
/// | `solid`, `wall`, `ground` | [`Tile::Solid`] |
/// | `one_way`, `oneway`, `platform` | [`Tile::OneWay`] |
/// | `hazard`, `spikes`, `spike`, `lava` | [`Tile::Hazard`] |
/// | `slope_45_right` | [`Slope::Right45`] (`/`) |
/// | `slope_45_left` | [`Slope::Left45`] (`\`) |
/// | `slope_22_right_low` | [`Slope::RightLow22`] |
/// | `slope_22_right_high` | [`Slope::RightHigh22`] |
/// | `slope_22_left_high` | [`Slope::LeftHigh22`] |
/// | `slope_22_left_low` | [`Slope::LeftLow22`] |
pub fn parse_tile_kind(name: &str) -> Option<Tile> {
    let n = normalize(name);
    Some(match n.as_str() {
        "empty" | "none" => Tile::Empty,
        "solid" | "wall" | "ground" => Tile::Solid,
        "one_way" | "oneway" | "platform" => Tile::OneWay,
        "hazard" | "spikes" | "spike" | "lava" => Tile::Hazard,
        "slope_45_right" => Tile::Slope(Slope::Right45),
        "slope_45_left" => Tile::Slope(Slope::Left45),
        "slope_22_right_low" => Tile::Slope(Slope::RightLow22),
        "slope_22_right_high" => Tile::Slope(Slope::RightHigh22),
        "slope_22_left_high" => Tile::Slope(Slope::LeftHigh22),
        "slope_22_left_low" => Tile::Slope(Slope::LeftLow22),
        _ => return None,
    })
}

/// The name of a tile kind in [`parse_tile_kind`]'s table (its first name).
pub fn tile_kind_name(tile: Tile) -> &'static str {
    match tile {
        Tile::Empty => "empty",
        Tile::Solid => "solid",
        Tile::OneWay => "one_way",
        Tile::Hazard => "hazard",
        Tile::Slope(Slope::Right45) => "slope_45_right",
        Tile::Slope(Slope::Left45) => "slope_45_left",
        Tile::Slope(Slope::RightLow22) => "slope_22_right_low",
        Tile::Slope(Slope::RightHigh22) => "slope_22_right_high",
        Tile::Slope(Slope::LeftHigh22) => "slope_22_left_high",
        Tile::Slope(Slope::LeftLow22) => "slope_22_left_low",
    }
}

/// The mirror image of a tile (left <-> right): the oracle for horizontally
/// flipped Tiled tiles (`collision::flip`).
#[cfg(test)]
pub(crate) fn mirror(tile: Tile) -> Tile {
    use Slope::*;
    match tile {
        Tile::Slope(s) => Tile::Slope(match s {
            Right45 => Left45,
            Left45 => Right45,
            RightLow22 => LeftLow22,
            LeftLow22 => RightLow22,
            RightHigh22 => LeftHigh22,
            LeftHigh22 => RightHigh22,
        }),
        t => t,
    }
}

/// Lower case, `-` and spaces as `_`.
pub(crate) fn normalize(name: &str) -> String {
    name.trim()
        .chars()
        .map(|c| match c {
            '-' | ' ' => '_',
            c => c.to_ascii_lowercase(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for code in 0..=9 {
            let t = Tile::from_code(code).unwrap();
            assert_eq!(parse_tile_kind(tile_kind_name(t)), Some(t));
            assert_eq!(mirror(mirror(t)), t);
        }
        assert_eq!(
            parse_tile_kind("Slope-45 Right"),
            Some(Tile::Slope(Slope::Right45))
        );
        assert_eq!(parse_tile_kind("ramp"), None);
    }

    #[test]
    fn default_grid_values_are_codes() {
        let m = TileMapping::default();
        assert_eq!(m.grid_tile("1"), Some(Tile::Solid));
        assert_eq!(m.grid_tile("3"), Some(Tile::Hazard));
        assert_eq!(m.grid_tile("4"), Some(Tile::Slope(Slope::Right45)));
        assert_eq!(m.grid_tile("one_way"), Some(Tile::OneWay));
        assert_eq!(m.grid_tile("g"), None);
        assert_eq!(
            m.with_grid_value("g", Tile::Solid).grid_tile("g"),
            Some(Tile::Solid)
        );
    }

    #[test]
    fn tables_per_tileset() {
        let m = TileMapping::default().with_tileset("Plain", TileTable::AllSolid);
        assert_eq!(m.tile("plain", 77), Some(Tile::Solid));
        // Only ledge's own tileset reads through LEDGE_TILESET by default.
        assert_eq!(m.tile("Ledge", 13), Some(Tile::Hazard));
        assert_eq!(m.tile("ledge", 26), None);
        assert!(!m.has_table("other"));
        assert_eq!(m.tile("other", 13), None);
        let all = TileMapping::new(TileTable::Ids(LEDGE_TILESET.to_vec()));
        assert_eq!(all.tile("other", 13), Some(Tile::Hazard));
    }
}
