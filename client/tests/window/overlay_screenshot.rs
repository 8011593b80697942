//! The collision overlay: `ledge-level render`'s picture against the
//! client's own screenshot of the same level with the overlay on
//! (`--collision`), pixel by pixel, for one real level of each editor
//! (from `shared/testdata/levels`): Tiled's `tiled_csv.tmx` (tiled-rs's
//! test map: tileset art, collision guessed), OGMO's `slopes.json`
//! (echo-slopes, its tileset embedded in the project) and LDtk's
//! `Typical_2D_platformer_example.ldtk` (its first level: auto-layer art,
//! IntGrid collision, walkers, a checkpoint, the goal).
//!
//! The picture is made by `ledge_levels::render` (what `ledge-level
//! render` writes) at the window's zoom, encoded as the PNG file, and
//! read back. Each screen pixel inside the level is compared with the
//! picture's pixel at the same world point. **Tolerance**: a pixel
//! matches when each of R, G, B is within [`CHANNEL`] (GL blending rounds
//! differently from tiny-skia); at most [`MAX_DIFFERENT`] of the pixels
//! may differ (what the two draw differently: the player's body and the
//! window's entity sprites, animated coins and walkers that walked 10
//! ticks, where the picture has still, simpler shapes). Both sides draw
//! the overlay's shapes over everything, so the overlay itself must
//! match; the test also checks that the overlay is there at all (every
//! colliding tile in view, and a twentieth of the picture or more,
//! changed by it).
//!
//! The window's level-load line (stderr) says its collision was guessed
//! exactly when `ledge_levels::report::guessed_collision` says so.
//!
//! Needs `xvfb-run` and `shared/testdata`: without either it prints a loud
//! notice and passes, except with `CI=true` (a missing `xvfb-run` fails).

use crate::common;
use std::path::{Path, PathBuf};
use std::time::Duration;

use common::{pair, run_to_end, xvfb_run, Png};
use ledge_levels::render::{render, RenderOptions};
use serde_json::Value;

/// A colour channel may differ by this much.
const CHANNEL: u8 = 24;
/// At most this fraction of the compared pixels may differ.
const MAX_DIFFERENT: f64 = 0.04;
/// The client must have saved its screenshot within this time.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(90);

fn notice(what: &str) {
    let text = format!(
        "\n************************************************************\n\
         *  SKIPPED overlay screenshot test: {what}\n\
         *  with CI=true this test fails instead.\n\
         ************************************************************\n\n"
    );
    let _ = std::io::Write::write_all(&mut std::io::stderr(), text.as_bytes());
}

fn testdata() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/testdata/levels")
}

/// Where the pictures go: `LEDGE_SCREENSHOT_DIR` (to look at them), else
/// a temporary folder.
fn out_dir(tmp: &Path) -> PathBuf {
    let dir = std::env::var_os("LEDGE_SCREENSHOT_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| tmp.to_owned());
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The client's screenshot of `level` with the overlay on, the camera on
/// `look_at`, and its JSON.
fn screenshot(xvfb: &Path, level: &str, look_at: (f32, f32), png: &Path) -> (Png, Value, String) {
    let mut command = common::client_under_xvfb(xvfb, env!("CARGO_BIN_EXE_ledge-client"), 10, png);
    command
        .arg("--level")
        .arg(level)
        .args(["--look-at", &format!("{},{}", look_at.0, look_at.1)])
        .args(["--collision", "--no-hud", "--mute"]);
    let out = run_to_end(command, CLIENT_TIMEOUT);
    assert!(
        out.status.success(),
        "the client failed: {}; stderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let json_path = format!("{}.json", png.display());
    let json = serde_json::from_str(&std::fs::read_to_string(json_path).unwrap()).unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (Png::load(png), json, stderr)
}

/// How many pixels were compared, how many differ, and a few of them.
fn compare(shot: &Png, picture: &Png, offset: (i64, i64)) -> (u64, u64, Vec<String>) {
    let (mut n, mut bad, mut some) = (0, 0, Vec::new());
    for sy in 0..shot.height {
        for sx in 0..shot.width {
            let (px, py) = (sx as i64 - offset.0, sy as i64 - offset.1);
            if px < 0 || py < 0 || px >= picture.width as i64 || py >= picture.height as i64 {
                continue;
            }
            n += 1;
            let (a, b) = (shot.at(sx, sy), picture.at(px as u32, py as u32));
            if a[..3]
                .iter()
                .zip(&b[..3])
                .any(|(x, y)| x.abs_diff(*y) > CHANNEL)
            {
                bad += 1;
                if some.len() < 8 {
                    some.push(format!(
                        "screen ({sx}, {sy}): {:?} vs {:?}",
                        &a[..3],
                        &b[..3]
                    ));
                }
            }
        }
    }
    (n, bad, some)
}

/// Renders `level`, screenshots it and compares the two.
fn check_level(xvfb: &Path, level: &str, look_at: (f32, f32), name: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = out_dir(tmp.path());
    let shot_path = dir.join(format!("{name}-window.png"));
    let (shot, json, stderr) = screenshot(xvfb, level, look_at, &shot_path);
    let zoom = json["camera"]["zoom"].as_f64().unwrap();
    let (ox, oy) = pair(&json["camera"]["offset"]);

    let loaded = ledge_levels::load_level(Path::new(level), None).expect("the level loads");
    // The level-load line says whether the collision was guessed.
    let guessed = ledge_levels::report::guessed_collision(&loaded);
    let line = stderr
        .lines()
        .find(|l| l.starts_with("ledge-client: level "))
        .unwrap_or_else(|| panic!("no level-load line: {stderr}"));
    assert_eq!(line.contains("its collision is GUESSED"), guessed, "{line}");
    // What the window shows of the world (the level is 3200 px square at
    // zoom 2 for Tiled's: larger than a whole picture may be).
    let (w, h) = (shot.width as f64 / zoom, shot.height as f64 / zoom);
    let options = RenderOptions {
        scale: Some(zoom as f32),
        overlay: true,
        region: Some([(-ox / zoom) as f32, (-oy / zoom) as f32, w as f32, h as f32]),
    };
    let picture = render(&loaded, &options).expect("the level renders");
    let picture_path = dir.join(format!("{name}-render.png"));
    std::fs::write(&picture_path, picture.encode_png().unwrap()).unwrap();
    let picture_png = Png::load(&picture_path);

    // Screen = world * zoom + offset; picture = (world - origin) * zoom.
    let offset = (
        (ox + picture.origin[0] as f64 * zoom).round() as i64,
        (oy + picture.origin[1] as f64 * zoom).round() as i64,
    );
    let (n, bad, some) = compare(&shot, &picture_png, offset);
    let share = bad as f64 / n.max(1) as f64;
    eprintln!("{name}: {bad} of {n} pixels differ ({:.2}%)", share * 100.0);
    assert!(n > 50_000, "{name}: only {n} pixels of the level on screen");
    assert!(
        share <= MAX_DIFFERENT,
        "{name}: {bad} of {n} pixels ({:.2}%) differ by more than {CHANNEL}: {some:?} \
         (pictures in {})",
        share * 100.0,
        dir.display()
    );
    overlay_is_there(&loaded, &picture, &options);
}

/// The overlay is in the picture: every tile that collides in view has
/// its centre changed by it, and so has a good part of the picture.
fn overlay_is_there(
    loaded: &ledge_levels::LoadedLevel,
    shown: &ledge_levels::render::Rendered,
    options: &RenderOptions,
) {
    use ledge_shared::fixed::UNITS_PER_PX;
    use ledge_shared::tilemap::Tile;
    let plain = render(
        loaded,
        &RenderOptions {
            overlay: false,
            ..*options
        },
    )
    .unwrap();
    let map = &loaded.level.tilemap;
    let u = UNITS_PER_PX as f32;
    let t = map.tile_size() as f32 / u;
    let (w, h) = (shown.width(), shown.height());
    for (i, &tile) in map.tiles().iter().enumerate() {
        let (c, r) = (
            (i as u32 % map.width()) as f32,
            (i as u32 / map.width()) as f32,
        );
        let wx = map.origin().x as f32 / u + (c + 0.5) * t;
        let wy = map.origin().y as f32 / u + (r + 0.5) * t;
        let (x, y) = (
            (wx - shown.origin[0]) * shown.scale,
            (wy - shown.origin[1]) * shown.scale,
        );
        if tile == Tile::Empty || x < 0.0 || y < 0.0 || x >= w as f32 || y >= h as f32 {
            continue;
        }
        let (x, y) = (x as u32, y as u32);
        assert_ne!(
            shown.pixel(x, y),
            plain.pixel(x, y),
            "{tile:?} at ({x}, {y})"
        );
    }
    let changed = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| shown.pixel(x, y) != plain.pixel(x, y))
        .count();
    assert!(
        changed * 20 > (w * h) as usize,
        "the overlay changed {changed} pixels"
    );
}

fn prerequisites() -> Option<PathBuf> {
    let Some(xvfb) = xvfb_run() else {
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("xvfb-run is not on PATH: install xvfb (apt-get install xvfb) to run the screenshot tests in CI");
        }
        notice("xvfb-run is not on PATH (apt-get install xvfb xauth).");
        return None;
    };
    if !testdata().is_dir() {
        notice("no shared/testdata/levels beside the repository.");
        return None;
    }
    Some(xvfb)
}

#[test]
fn tiled_the_window_overlay_matches_ledge_level_render() {
    let Some(xvfb) = prerequisites() else { return };
    let level = testdata().join("tiled-rs-tiled/assets/tiled_csv.tmx");
    check_level(
        &xvfb,
        level.to_str().unwrap(),
        (240.0, 200.0),
        "overlay-tiled",
    );
}

#[test]
fn ogmo_the_window_overlay_matches_ledge_level_render() {
    let Some(xvfb) = prerequisites() else { return };
    let level = testdata().join("echo-slopes/slopes.json");
    check_level(
        &xvfb,
        level.to_str().unwrap(),
        (120.0, 88.0),
        "overlay-ogmo",
    );
}

#[test]
fn ldtk_the_window_overlay_matches_ledge_level_render() {
    let Some(xvfb) = prerequisites() else { return };
    let level = testdata().join("ldtk-samples/Typical_2D_platformer_example.ldtk");
    check_level(
        &xvfb,
        level.to_str().unwrap(),
        (200.0, 200.0),
        "overlay-ldtk",
    );
}
