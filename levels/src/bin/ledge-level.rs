//! `ledge-level`: the level author's tool. `ledge-level check FILE` loads a
//! level the way the server does and prints what it became (size, tiles by
//! kind, entities by kind, spawn, warnings); it exits non-zero when the file
//! is refused, so it can run before hosting or in a level's own CI.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use ledge_levels::{load_level, settings_path_for, LoadedLevel};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::level::EntityKind;
use ledge_shared::tilemap::Tile;

#[derive(Parser)]
#[command(
    name = "ledge-level",
    version,
    about = "Check ledge level files (OGMO Editor 3 .json, Tiled .tmx)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Load each file as the server would and print what it became; exits
    /// 1 if any file is refused.
    Check {
        /// Level files (.json from OGMO Editor 3, .tmx from Tiled).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// A settings file for every level (default: each level's own
        /// LEVEL.ledge.toml beside it, when there is one).
        #[arg(long, value_name = "FILE")]
        settings: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    let Command::Check { files, settings } = Cli::parse().command;
    let mut failed = 0;
    for (i, file) in files.iter().enumerate() {
        if i > 0 {
            println!();
        }
        let used = settings
            .clone()
            .or_else(|| Some(settings_path_for(file)).filter(|p| p.is_file()));
        match load_level(file, used.as_deref()) {
            Ok(loaded) => {
                print!("{}", describe(&file.display().to_string(), &loaded));
                match used {
                    Some(s) => println!("  settings: {}", s.display()),
                    None => println!(
                        "  settings: none ({} would be read)",
                        settings_path_for(file).display()
                    ),
                }
            }
            Err(e) => {
                failed += 1;
                eprintln!("error: {e}");
            }
        }
    }
    if failed > 0 {
        eprintln!(
            "{failed} of {} level file(s) refused; fix what each error names and check again",
            files.len()
        );
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// The report for one loaded level.
fn describe(file: &str, loaded: &LoadedLevel) -> String {
    use std::fmt::Write;
    let level = &loaded.level;
    let map = &level.tilemap;
    let px = |u: i32| u as f64 / UNITS_PER_PX as f64;
    let mut out = String::new();
    let _ = writeln!(out, "{file}: ok, level {:?}", level.name);
    let _ = writeln!(
        out,
        "  grid: {} x {} tiles of {} px at ({}, {}) px",
        map.width(),
        map.height(),
        px(map.tile_size()),
        px(map.origin().x),
        px(map.origin().y)
    );
    let mut tiles: BTreeMap<&str, usize> = BTreeMap::new();
    for t in map.tiles() {
        let name = match t {
            Tile::Empty => continue,
            Tile::Solid => "solid",
            Tile::OneWay => "one-way",
            Tile::Hazard => "hazard",
            Tile::Slope(_) => "slope",
        };
        *tiles.entry(name).or_default() += 1;
    }
    let _ = writeln!(out, "  tiles: {}", counts(&tiles));
    let mut kinds: BTreeMap<&str, usize> = BTreeMap::new();
    for e in &level.entities {
        *kinds.entry(kind_name(&e.kind)).or_default() += 1;
    }
    let _ = writeln!(out, "  entities: {}", counts(&kinds));
    match level
        .entities
        .iter()
        .find(|e| e.kind == EntityKind::PlayerSpawn)
    {
        Some(s) => {
            let _ = writeln!(out, "  spawn: ({}, {}) px", px(s.pos.x), px(s.pos.y));
        }
        None => {
            let _ = writeln!(out, "  spawn: none");
        }
    }
    if !loaded.route.is_empty() {
        let _ = writeln!(out, "  bot route: {} waypoints", loaded.route.len());
    }
    if loaded.warnings.is_empty() {
        let _ = writeln!(out, "  warnings: none");
    } else {
        let _ = writeln!(out, "  warnings: {}", loaded.warnings.len());
        for w in &loaded.warnings {
            let _ = writeln!(out, "    warning: {w}");
        }
    }
    out
}

fn counts(map: &BTreeMap<&str, usize>) -> String {
    if map.is_empty() {
        return "none".into();
    }
    map.iter()
        .map(|(k, n)| format!("{n} {k}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn kind_name(kind: &EntityKind) -> &'static str {
    match kind {
        EntityKind::PlayerSpawn => "spawn",
        EntityKind::Block => "block",
        EntityKind::PolygonBlock { .. } => "polygon",
        EntityKind::MovingPlatform { .. } => "moving platform",
        EntityKind::Walker { .. } => "walker",
        EntityKind::Springboard { .. } => "springboard",
        EntityKind::Coin => "coin",
        EntityKind::Checkpoint => "checkpoint",
        EntityKind::Goal => "goal",
        EntityKind::Hazard => "hazard",
    }
}
