//! Tilemap collision by direct lookup: a grid of tiles, looked up by
//! division, never a collider per tile.
//!
//! * [`Tile`]: empty, solid, one-way, [`Slope`], hazard (one byte each);
//! * [`Tilemap`]: the grid placed in the world (`grid.rs`), box contacts
//!   (`contacts.rs`), contacts of every other shape kind (`shapes.rs`), the
//!   floor under a foot (`ground.rs`).
//!
//! Coordinates are integer units (y grows down, up is `-y`); tile `(c, r)`
//! covers `origin + [c, c + 1) * T` by `origin + [r, r + 1) * T`. Every answer
//! is exact integer arithmetic (no rounding: all faces are axis-aligned and
//! slope surfaces are integer functions of the unit column), and depends only
//! on positions relative to the grid.
//!
//! The tile size `T` is any even number of units from 2 to
//! [`crate::fixed::MAX_EXTENT`], so any whole number of pixels (1 px is 256
//! units): 16, 18, 21, 24, 70 px alike. Nothing relies on a power of two:
//! tile lookups are floor divisions (`div_euclid`), tile edges
//! multiplications, never shifts or masks, and the exactness arguments
//! (integer surfaces, the sweep's fractions) hold for any `T`. Evenness keeps
//! `T / 2` whole: a tile's centre (its region's box, the world's
//! far-side test) and the middle of a 22.5 degree ramp.
//!
//! # Contact rules ([`Tilemap::box_contacts`])
//! For an axis-aligned box, each overlapped tile gives at most one contact
//! whose MTV moves the box out of it:
//!
//! * **Internal edge culling.** A tile's *full* faces (solid: all four;
//!   slopes: the bottom, plus the high side of `/`, `\` and the high halves of
//!   22.5 degree ramps; others: none) are its candidate collision faces. A
//!   face is dropped when the neighbour on that side has a full face against
//!   it. So a floor, wall or ceiling made of many tiles pushes only through
//!   its outer surface and a box sliding along it never snags on a seam.
//! * **Solid.** The shortest push through one of its collision faces (none:
//!   no contact, the box is inside solid ground and other tiles handle it).
//!   Ties prefer up, then down, then left, then right.
//! * **The foot rule (slopes, Mario style).** The foot is the box's
//!   bottom-centre point. The foot *stands in* a slope tile when the unit
//!   cell just above the foot is in that slope tile, or is in a solid tile
//!   right under a slope tile (a foot sunk through the slope's bottom by
//!   gravity or a fast landing). That slope then pushes the box straight up
//!   so its bottom sits exactly on the surface at the foot's x, whenever the
//!   foot is below it, and never otherwise (no sideways or downward push).
//! * **Plateaus defer to their slope.** A solid tile whose shortest push
//!   would be up gives no push when its side facing the foot is hidden by a
//!   slope's full high side (the plateau at the top of a ramp, seen from a
//!   foot on or beyond the ramp). This is what makes flat -> slope -> flat
//!   seamless: the box's other half may overlap the plateau while the foot
//!   climbs or descends, without a bump, and the height follows the surface
//!   function of the foot's x; the floor under the foot of a ramp needs no
//!   special case (its top is culled under the slope, and beside it never
//!   pushes further than the slope does). One-way tiles do not push a box
//!   whose foot stands in a slope.
//! * **Other slope contacts.** A slope the foot does not stand in pushes only
//!   a box overlapping its solid part, and only through an exposed full face:
//!   down through its bottom when the box reaches below the tile (hit from
//!   below), sideways through its full high side when the foot is beyond
//!   that side (a wall); the shorter wins, ties prefer down. A box whose foot
//!   is not over the slope but whose corner dips into its triangle gets no
//!   push (the classic platformer behaviour: the corner overlaps a little,
//!   like a sprite's feet on a hillside, until the foot gets there).
//! * **One-way.** Only its top line: pushes the box up to it when the box
//!   straddles the line, was not below it at the start of the tick
//!   (`bottom - moved.y <= top`, which also means it is moving down or
//!   level), is not dropping through ([`ContactFlags::drop_through`]) and
//!   its foot does not stand in a slope.
//! * **Hazard.** Never pushes; an overlapped hazard is reported in the same
//!   output as a trigger contact with zero MTV ([`TileContact::is_trigger`]).
//!
//! # Other shapes ([`Tilemap::shape_contacts`])
//! Circles, segments, points, oriented boxes and polygons are tested
//! exactly against each overlapped tile's region ([`Tilemap::tile_region`]:
//! a solid tile's box, a slope's polygon under its surface line, a one-way
//! tile's top segment) with the pair contact functions. Culling: a solid
//! tile's push with a part through a covered face is dropped when a slope's
//! full side covers it (the slope holds the shape), else replaced by the
//! shortest push straight out through an exposed face; a slope's push
//! through its covered bottom or high side (or level through a covered low
//! side) is dropped. One-way tiles push a shape that was on or above the
//! line at the start of the tick, moving down and not dropping through;
//! hazards give triggers. No foot rule: a shape rests on a slope along the
//! surface normal. Known limit: a level segment (or a point) lying exactly on
//! a tile line only touches the tiles on both sides and can slip along it.
//!
//! Slope surfaces: see [`Slope::height`] (`x/2` is `floor(x/2)`; ramps are
//! continuous). Known limit: the rising-right surfaces top out at
//! `h(T - 1) = T - 1`, one unit below the next tile's top; stepping onto a
//! solid plateau pushes that unit up, but a [`Tile::OneWay`] there would let
//! the box through (end a `/` ramp on a solid tile).

mod contacts;
mod error;
mod grid;
mod ground;
mod shapes;
mod slope;
mod tile;

pub use contacts::{ContactFlags, TileContact};
pub use error::TilemapError;
pub use grid::Tilemap;
pub use shapes::{TileRegion, TileShape};
pub use slope::Slope;
pub use tile::Tile;
