//! The simulation's integration tests in one binary (one link step; every
//! file a module). Allocation tests count per thread with one counting
//! allocator (`counting_alloc`). The tile suites share their helpers
//! (`tile_kit`).

#[global_allocator]
static GLOBAL: counting_alloc::Counting = counting_alloc::Counting;

#[path = "../common/mod.rs"]
mod common;
#[path = "../counting_alloc/mod.rs"]
mod counting_alloc;
#[path = "../platformer_kit/mod.rs"]
mod platformer_kit;

mod alloc;
mod determinism;
mod game_snapshot;
mod narrow_phase;
mod platformer_controller;
mod platformer_entities;
mod platformer_platforms;
mod platformer_polygon;
mod platformer_world;
mod protocol;
mod ray;
mod replay;
mod runs;
mod spawn_spread;
mod stability;
mod sweep;
mod tile_kit;
mod tilemap;
mod tilemap_shapes;
mod tilemap_sizes;
mod world_corner;
mod world_restitute;
mod world_sweep;
mod world_threads;
mod world_warmup;
