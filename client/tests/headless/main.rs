//! The client library's integration tests (no window): online play,
//! bots. One binary, one link step; every file a module.

#[path = "../common/mod.rs"]
mod common;

mod online_game;
mod rotation;
mod runner_race;
mod thin_bot;
