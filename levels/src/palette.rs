//! The colours levels are drawn with, in one place: the game's plain
//! colours for a level without art ([`flat`]) and the collision overlay's
//! ([`overlay`]). The client's window and `ledge-level render` both take
//! them from here, so the two pictures cannot drift apart.
//!
//! Colours are `[r, g, b, a]` bytes, straight (not premultiplied) alpha.

/// A colour: red, green, blue, alpha (straight), 0 to 255.
pub type Rgba = [u8; 4];

const fn rgb(r: u8, g: u8, b: u8) -> Rgba {
    [r, g, b, 255]
}

/// The game's plain colours (a level without art, and the defaults behind
/// a level's art).
pub mod flat {
    use super::{rgb, Rgba};

    /// The sky behind everything.
    pub const SKY: Rgba = rgb(104, 164, 226);
    /// Solid ground (tiles and the body of slopes).
    pub const SOLID: Rgba = rgb(124, 84, 60);
    /// Pebbles in the ground.
    pub const SOLID_SPECK: Rgba = rgb(104, 70, 50);
    /// Edges of the ground facing empty space.
    pub const SOLID_EDGE: Rgba = rgb(70, 46, 34);
    /// Grass on exposed ground tops and slope surfaces.
    pub const GRASS: Rgba = rgb(92, 184, 72);
    /// The darker line under the grass.
    pub const GRASS_DARK: Rgba = rgb(56, 128, 48);
    /// One-way ledges (tiles).
    pub const PLANK: Rgba = rgb(196, 142, 78);
    /// Their shaded underside.
    pub const PLANK_DARK: Rgba = rgb(128, 86, 44);
    /// Spikes.
    pub const SPIKE: Rgba = rgb(222, 226, 236);
    /// Spike outlines and bases.
    pub const SPIKE_DARK: Rgba = rgb(120, 30, 40);
    /// Crates (blocks).
    pub const CRATE: Rgba = rgb(186, 124, 58);
    /// Crate boards.
    pub const CRATE_DARK: Rgba = rgb(120, 74, 30);
    /// Solid moving platforms.
    pub const STEEL: Rgba = rgb(108, 120, 146);
    /// Their outline.
    pub const STEEL_DARK: Rgba = rgb(58, 64, 84);
    /// One-way moving platforms.
    pub const ONE_WAY: Rgba = rgb(240, 196, 72);
    /// Walkers.
    pub const WALKER: Rgba = rgb(170, 60, 160);
    /// Coins.
    pub const COIN: Rgba = rgb(252, 206, 40);
    /// Springboard pads.
    pub const SPRING: Rgba = rgb(226, 62, 62);
    /// Poles of checkpoints and the goal.
    pub const POLE: Rgba = rgb(236, 236, 240);
    /// Checkpoints' flags.
    pub const FLAG_IDLE: Rgba = rgb(140, 140, 152);
    /// The goal.
    pub const GOAL: Rgba = rgb(255, 208, 32);
}

/// The collision overlay: what collides, translucent over the level, each
/// kind its own colour (`ledge-level render`, the window's C key).
pub mod overlay {
    use super::Rgba;

    /// Solid tiles, blocks and polygon blocks.
    pub const SOLID: Rgba = [255, 40, 40, 110];
    /// One-way tiles and platforms: the cell.
    pub const ONE_WAY: Rgba = [40, 130, 255, 90];
    /// One-way tiles and platforms: the top edge, what a player stands on.
    pub const ONE_WAY_EDGE: Rgba = [40, 130, 255, 230];
    /// Slope tiles: the solid part under the surface.
    pub const SLOPE: Rgba = [255, 150, 0, 130];
    /// Hazard tiles and hazard entities.
    pub const HAZARD: Rgba = [255, 0, 230, 130];
    /// Solid moving platforms.
    pub const PLATFORM: Rgba = [0, 230, 230, 120];
    /// Walkers (they hurt, their heads can be stomped).
    pub const WALKER: Rgba = [150, 60, 255, 130];
    /// Springboards.
    pub const SPRING: Rgba = [255, 110, 40, 130];
    /// Coins.
    pub const COIN: Rgba = [255, 235, 0, 140];
    /// Checkpoints.
    pub const CHECKPOINT: Rgba = [60, 230, 80, 120];
    /// The goal.
    pub const GOAL: Rgba = [255, 255, 255, 140];
    /// A player spawn entity's box.
    pub const SPAWN: Rgba = [255, 255, 255, 50];
    /// A player's box where the game spawns one (the player's size).
    pub const PLAYER: Rgba = [40, 255, 90, 150];
    /// Outlines are their fill's colour with this alpha.
    pub const OUTLINE_ALPHA: u8 = 230;

    /// `c` as an outline colour.
    pub const fn outline(c: Rgba) -> Rgba {
        [c[0], c[1], c[2], OUTLINE_ALPHA]
    }
}
