//! The client's integration tests that run the real window binary
//! (`ledge-client`, the `gui` feature): pictures under Xvfb, failures and
//! the command line. One binary, one link step; every file a module.

#[path = "../common/mod.rs"]
mod common;

mod art_screenshot;
mod chat_screenshot;
mod failure_screenshot;
mod ghost_screenshot;
mod levels_screenshot;
mod overlay_screenshot;
mod replay_check;
mod replay_files;
mod replay_screenshot;
mod replay_url;
mod rooms_cli;
mod run_screenshots;
mod screenshot;
mod spectate_screenshot;
mod trust_cli;
