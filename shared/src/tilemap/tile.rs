//! What one grid cell holds, and which of its faces are full.

use serde::{Deserialize, Serialize};

use super::{Slope, TilemapError};

/// One grid cell. One byte in memory; serialised as its one-byte code
/// ([`Tile::code`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(into = "u8", try_from = "u8")]
pub enum Tile {
    /// Nothing (also every cell outside the grid). Code 0.
    #[default]
    Empty,
    /// A full solid square. Code 1.
    Solid,
    /// A one-way platform: only its top line, solid only from above. Code 2.
    OneWay,
    /// A slope: solid below its surface. Codes 4 to 9 in [`Slope::ALL`] order.
    Slope(Slope),
    /// Not solid: a box overlapping it gets a trigger contact. Code 3.
    Hazard,
}

const _: () = assert!(core::mem::size_of::<Tile>() == 1);

/// Face bits (see [`Tile::full_faces`]).
pub(crate) mod face {
    /// The top face (y = tile top).
    pub const TOP: u8 = 1;
    /// The bottom face.
    pub const BOTTOM: u8 = 2;
    /// The left face.
    pub const LEFT: u8 = 4;
    /// The right face.
    pub const RIGHT: u8 = 8;
}

impl Tile {
    /// The one-byte code: 0 empty, 1 solid, 2 one-way, 3 hazard, 4 + the
    /// slope's index in [`Slope::ALL`] for slopes.
    #[inline]
    pub fn code(self) -> u8 {
        match self {
            Tile::Empty => 0,
            Tile::Solid => 1,
            Tile::OneWay => 2,
            Tile::Hazard => 3,
            Tile::Slope(s) => 4 + s as u8,
        }
    }

    /// The tile of a code; `None` for codes above 9.
    #[inline]
    pub fn from_code(code: u8) -> Option<Tile> {
        Some(match code {
            0 => Tile::Empty,
            1 => Tile::Solid,
            2 => Tile::OneWay,
            3 => Tile::Hazard,
            4..=9 => Tile::Slope(Slope::ALL[(code - 4) as usize]),
            _ => return None,
        })
    }

    /// Faces entirely covered by solid material, as `face` bits: a full face
    /// hides the touching face of the neighbour on that side (internal edge
    /// culling). Solid: all four; slopes: the bottom, plus the high side when
    /// it is a whole tile tall (`/` and the high half of a 22.5 degree ramp
    /// rising right: right; `\` and its 22.5 degree counterpart: left);
    /// one-way, hazard, empty: none.
    #[inline]
    pub(crate) fn full_faces(self) -> u8 {
        use face::*;
        match self {
            Tile::Solid => TOP | BOTTOM | LEFT | RIGHT,
            Tile::Slope(Slope::Right45 | Slope::RightHigh22) => BOTTOM | RIGHT,
            Tile::Slope(Slope::Left45 | Slope::LeftHigh22) => BOTTOM | LEFT,
            Tile::Slope(Slope::RightLow22 | Slope::LeftLow22) => BOTTOM,
            Tile::OneWay | Tile::Hazard | Tile::Empty => 0,
        }
    }
}

impl From<Tile> for u8 {
    #[inline]
    fn from(t: Tile) -> u8 {
        t.code()
    }
}

impl TryFrom<u8> for Tile {
    type Error = TilemapError;
    #[inline]
    fn try_from(code: u8) -> Result<Tile, TilemapError> {
        Tile::from_code(code).ok_or(TilemapError::TileCode { value: code })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all() -> impl Iterator<Item = Tile> {
        [Tile::Empty, Tile::Solid, Tile::OneWay, Tile::Hazard]
            .into_iter()
            .chain(Slope::ALL.map(Tile::Slope))
    }

    #[test]
    fn codes_round_trip() {
        for (i, t) in all().enumerate() {
            assert_eq!(t.code() as usize, i);
            assert_eq!(Tile::from_code(t.code()), Some(t));
        }
        assert_eq!(Tile::from_code(10), None);
        assert_eq!(
            Tile::try_from(200u8),
            Err(TilemapError::TileCode { value: 200 })
        );
    }

    #[test]
    fn serialises_as_one_byte() {
        let cfg = bincode::config::standard();
        for t in all() {
            let bytes = bincode::serde::encode_to_vec(t, cfg).unwrap();
            assert_eq!(bytes, vec![t.code()]);
            let (back, _): (Tile, usize) = bincode::serde::decode_from_slice(&bytes, cfg).unwrap();
            assert_eq!(back, t);
        }
        assert!(bincode::serde::decode_from_slice::<Tile, _>(&[42], cfg).is_err());
    }

    #[test]
    fn full_faces_match_the_slope_heights() {
        let t = 4096;
        for s in Slope::ALL {
            let f = Tile::Slope(s).full_faces();
            assert_ne!(f & face::BOTTOM, 0);
            assert_eq!(f & face::TOP, 0);
            // A side is full exactly when the surface reaches the tile top there.
            assert_eq!(f & face::LEFT != 0, s.height(0, t) == t, "{s:?}");
            assert_eq!(
                f & face::RIGHT != 0,
                s.height(t - 1, t) == t - 1 && s.rises_right(),
                "{s:?}"
            );
        }
    }
}
