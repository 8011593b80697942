//! `ledge-level`: the level author's tool. `ledge-level render FILE -o
//! OUT.png` draws it with what collides on top; `ledge-level check FILE` loads a
//! level the way the server does and prints what it became (size, tiles by
//! kind, entities by kind, spawn, warnings, art warnings); it exits non-zero
//! when the file is refused, so it can run before hosting or in a level's
//! own CI. An LDtk project is checked level by level: `FILE.ldtk#LEVEL` one
//! of them, `FILE.ldtk` every one.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use ledge_levels::render::RenderOptions;
use ledge_levels::report::LevelReport;
use ledge_levels::{entity_kind_name, load_level, settings_path_for, LoadedLevel};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::level::EntityKind;
use ledge_shared::tilemap::Tile;

#[derive(Parser)]
#[command(
    name = "ledge-level",
    version,
    about = "Check and draw ledge level files (OGMO Editor 3 .json, Tiled .tmx, LDtk .ldtk)"
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
        /// Level files (.json from OGMO Editor 3, .tmx from Tiled, .ldtk from
        /// LDtk: PROJECT.ldtk#LEVEL for one level, PROJECT.ldtk for every
        /// level of the project).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// A settings file for every level (default: each level's own
        /// LEVEL.ledge.toml beside it, when there is one).
        #[arg(long, value_name = "FILE")]
        settings: Option<PathBuf>,
        /// Print the findings as one JSON document on stdout (`levels`: one
        /// object per level; `refused`: file and error of each refused
        /// one), for scripts.
        #[arg(long)]
        json: bool,
    },
    /// Draw a level as the game does (its art, or the game's plain
    /// colours) with what collides on top (solid, one-way, slopes,
    /// hazards, entities, spawns and a player's box at each) into a PNG.
    Render {
        /// The level file (PROJECT.ldtk#LEVEL for one level of an LDtk
        /// project; PROJECT.ldtk: its first).
        file: PathBuf,
        /// The picture to write [default: the level's name with .png, in
        /// the current folder].
        #[arg(short, long, value_name = "OUT.png")]
        output: Option<PathBuf>,
        /// Picture pixels per world pixel (above 0, at most 16) [default:
        /// 1, or the largest scale at which a large level fits the
        /// picture's bounds].
        #[arg(long, value_name = "S")]
        scale: Option<f32>,
        /// Only this part of the world, in world pixels: X,Y,WIDTH,HEIGHT
        /// [default: the whole level].
        #[arg(long, value_name = "X,Y,W,H", value_parser = parse_region)]
        region: Option<[f32; 4]>,
        /// Leave the collision overlay out (the level as the game draws it).
        #[arg(long)]
        no_overlay: bool,
        /// The level's settings file (default: LEVEL.ledge.toml beside it,
        /// when there is one).
        #[arg(long, value_name = "FILE")]
        settings: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Check {
            files,
            settings,
            json: false,
        } => check(expand(files), settings),
        Command::Check {
            files,
            settings,
            json: true,
        } => check_json(expand(files), settings),
        Command::Render {
            file,
            output,
            scale,
            region,
            no_overlay,
            settings,
        } => {
            let options = RenderOptions {
                scale,
                overlay: !no_overlay,
                region,
            };
            render(&file, output, &options, settings)
        }
    }
}

/// `render`: loads the level, draws it and writes the PNG; says where, at
/// what scale and which world box it shows.
fn render(
    file: &Path,
    output: Option<PathBuf>,
    options: &RenderOptions,
    settings: Option<PathBuf>,
) -> ExitCode {
    let used = settings_for(file, &settings);
    let loaded = match load_level(file, used.as_deref()) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let picture = match ledge_levels::render::render(&loaded, options) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {}: {e}", file.display());
            return ExitCode::FAILURE;
        }
    };
    let out = output.unwrap_or_else(|| PathBuf::from(format!("{}.png", picture_name(&loaded))));
    let written = picture
        .encode_png()
        .map_err(|e| e.to_string())
        .and_then(|bytes| std::fs::write(&out, bytes).map_err(|e| e.to_string()));
    if let Err(e) = written {
        eprintln!("error: cannot write {}: {e}", out.display());
        return ExitCode::FAILURE;
    }
    for note in &picture.notes {
        println!("note: {note}");
    }
    let [x, y] = picture.origin;
    println!(
        "{}: {} x {} px at scale {}, world ({x}, {y}) to ({}, {}) px",
        out.display(),
        picture.width(),
        picture.height(),
        picture.scale,
        x + picture.width() as f32 / picture.scale,
        y + picture.height() as f32 / picture.scale,
    );
    ExitCode::SUCCESS
}

/// `X,Y,W,H`: four numbers.
fn parse_region(s: &str) -> Result<[f32; 4], String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>().map_err(|e| format!("{p:?}: {e}")))
        .collect::<Result<_, _>>()?;
    <[f32; 4]>::try_from(v).map_err(|_| "expected X,Y,WIDTH,HEIGHT in world pixels".to_owned())
}

/// The level's name as a file name: letters, digits, `-` and `_` kept,
/// anything else `_` (`level` when that leaves nothing).
fn picture_name(loaded: &LoadedLevel) -> String {
    let name: String = loaded
        .level
        .name
        .chars()
        .take(64)
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if name.is_empty() {
        "level".into()
    } else {
        name
    }
}

/// The settings file a level is loaded with: the one given, else its own
/// beside it when there is one.
fn settings_for(file: &Path, given: &Option<PathBuf>) -> Option<PathBuf> {
    given
        .clone()
        .or_else(|| Some(settings_path_for(file)).filter(|p| p.is_file()))
}

/// `check --json`: one document, `{"levels": [...], "refused": [...]}`.
fn check_json(files: Vec<PathBuf>, settings: Option<PathBuf>) -> ExitCode {
    let mut levels = Vec::new();
    let mut refused = Vec::new();
    for file in &files {
        let used = settings_for(file, &settings);
        let name = file.display().to_string();
        match load_level(file, used.as_deref()) {
            Ok(loaded) => {
                let s = used.as_ref().map(|p| p.display().to_string());
                levels.push(LevelReport::new(&name, &loaded, s.as_deref()));
            }
            Err(e) => refused.push(Refused {
                file: name,
                error: e.to_string(),
            }),
        }
    }
    let failed = !refused.is_empty();
    match serde_json::to_string_pretty(&CheckJson { levels, refused }) {
        Ok(text) => println!("{text}"),
        Err(e) => {
            eprintln!("error: cannot write the report as JSON: {e}");
            return ExitCode::FAILURE;
        }
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// What `check --json` prints.
#[derive(serde::Serialize)]
struct CheckJson {
    /// The levels that loaded.
    levels: Vec<LevelReport>,
    /// The files refused.
    refused: Vec<Refused>,
}

/// A refused file.
#[derive(serde::Serialize)]
struct Refused {
    /// The file as given.
    file: String,
    /// Why, as `check` prints it.
    error: String,
}

/// `check`: the report in words.
fn check(files: Vec<PathBuf>, settings: Option<PathBuf>) -> ExitCode {
    let mut failed = 0;
    for (i, file) in files.iter().enumerate() {
        if i > 0 {
            println!();
        }
        let used = settings_for(file, &settings);
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

/// The files to check: an LDtk project without `#LEVEL` stands for every
/// one of its levels (a project that cannot be listed stays as it is, to
/// be refused with its reason).
fn expand(files: Vec<PathBuf>) -> Vec<PathBuf> {
    let mut out = Vec::with_capacity(files.len());
    for f in files {
        match ledge_levels::ldtk::split_level_path(&f) {
            Some((_, None)) => match ledge_levels::ldtk::level_paths(&f) {
                Ok(paths) if !paths.is_empty() => out.extend(paths),
                _ => out.push(f),
            },
            _ => out.push(f),
        }
    }
    out
}

/// The report for one loaded level.
fn describe(file: &str, loaded: &LoadedLevel) -> String {
    use std::fmt::Write;
    let level = &loaded.level;
    let map = &level.tilemap;
    let px = |u: i32| u as f64 / UNITS_PER_PX as f64;
    let mut out = String::new();
    let _ = writeln!(out, "{file}: ok, level {:?}", level.name);
    out.push_str(guessed_note(loaded));
    if map.width() == 0 || map.height() == 0 {
        let _ = writeln!(out, "  grid: none (no tile or grid layer collides)");
    } else {
        let _ = writeln!(
            out,
            "  grid: {} x {} tiles of {} px at ({}, {}) px",
            map.width(),
            map.height(),
            px(map.tile_size()),
            px(map.origin().x),
            px(map.origin().y)
        );
    }
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
        *kinds.entry(entity_kind_name(&e.kind)).or_default() += 1;
    }
    let _ = writeln!(out, "  entities: {}", counts(&kinds));
    for l in &loaded.layers {
        let mut what: BTreeMap<&str, usize> = BTreeMap::new();
        for (k, n) in [
            ("solid", l.solid),
            ("one-way", l.one_way),
            ("hazard", l.hazard),
            ("slope", l.slopes),
        ] {
            if n > 0 {
                what.insert(k, n);
            }
        }
        let tiles = counts(&what);
        let ents = counts(&l.entities.iter().map(|(k, n)| (*k, *n)).collect());
        let grid = if l.field.is_empty() {
            String::new()
        } else if l.on_grid {
            format!(" ({}), tiles: {tiles};", l.field)
        } else {
            format!(" ({}), not on the level's grid: does not collide;", l.field)
        };
        let _ = writeln!(out, "  layer {:?}{grid} entities: {ents}", l.name);
    }
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
    let _ = writeln!(
        out,
        "  player: {}",
        ledge_levels::scale::describe(&loaded.level)
    );
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
    if !loaded.art.warnings.is_empty() {
        let _ = writeln!(out, "  art warnings: {}", loaded.art.warnings.len());
        for w in &loaded.art.warnings {
            let _ = writeln!(out, "    warning: {w}");
        }
    }
    out
}

/// The line saying the level's collision was guessed, if it was.
fn guessed_note(loaded: &LoadedLevel) -> &'static str {
    if ledge_levels::report::guessed_collision(loaded) {
        "  collision: GUESSED (the file says nothing about what collides; see the warning)\n"
    } else {
        ""
    }
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
