//! The level importers' integration tests in one binary (one link step;
//! every file a module). The tests that measure peak memory are in
//! `tests/bounded`, whose allocator counts the whole process.

#[path = "../../../shared/tests/platformer_kit/mod.rs"]
mod platformer_kit;

mod art;
mod check_cli;
mod corpus;
mod layer_rules;
mod ldtk;
mod ldtk_edge;
mod level_errors;
mod level_ogmo;
mod level_polygon;
mod level_tiled;
mod real_levels;
mod settings;
mod stands_still;
mod tiled_collision;
