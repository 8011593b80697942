//! The real client binary, under Xvfb, offline on a Tiled map drawn with a
//! real tileset: `tests/fixtures/desert_art.tmx` with the Desert tileset
//! image of Tiled's examples (`tmw_desert_spacing.png`: 32 px tiles, margin
//! 1, spacing 1), copied beside the map from the level corpus
//! (`scripts/fetch-level-corpus`). The screenshot must show, cell by cell,
//! the tileset's own pixels: brick floor tiles, sand, and props over sand,
//! four of them flipped (horizontally, vertically, diagonally, all three),
//! as Tiled draws them, and none of ledge's flat colours.
//!
//! Needs `xvfb-run` and the corpus. Without either the test prints a loud
//! notice and passes without checking anything, except with `CI=true`:
//! there a missing corpus is fetched (the script is idempotent) and a
//! missing `xvfb-run` fails the test.

use crate::common;
use std::path::{Path, PathBuf};

use std::process::Command;
use std::time::Duration;

use common::{pair, run_to_end, xvfb_run, Png};

use serde_json::Value;

/// The client must have saved its screenshot within this time.
const CLIENT_TIMEOUT: Duration = Duration::from_secs(90);
/// The map's tiles, pixels.
const T: u32 = 32;
/// Where the camera looks (world pixels): the right part of the map, away
/// from the player's spawn on the left.
const LOOK_AT: (f64, f64) = (448.0, 240.0);

const H: u32 = 0x8000_0000;
const V: u32 = 0x4000_0000;
const D: u32 = 0x2000_0000;

fn notice(what: &str) {
    // Straight to the process's stderr: the test harness captures
    // `eprintln!`, and this notice must be seen.
    let text = format!(
        "\n************************************************************\n\
         *  SKIPPED art screenshot test: {what}\n\
         *  with CI=true this test fails (or fetches) instead.\n\
         ************************************************************\n\n"
    );
    let _ = std::io::Write::write_all(&mut std::io::stderr(), text.as_bytes());
}

fn ci() -> bool {
    std::env::var("CI").as_deref() == Ok("true")
}

/// The Desert tileset image from the corpus (fetched in CI when missing).
fn corpus_image() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let image = root.join("target/level-corpus/tiled-examples/tmw_desert_spacing.png");
    if !image.is_file() && ci() {
        let status = Command::new("bash")
            .arg(root.join("scripts/fetch-level-corpus"))
            .status()
            .expect("scripts/fetch-level-corpus runs");
        assert!(
            status.success(),
            "scripts/fetch-level-corpus failed: {status}"
        );
    }
    image.is_file().then_some(image)
}

/// The tileset pixel that Tiled shows at `(u, v)` of tile `gid` (first gid
/// 1; flip bits included): the diagonal flip is applied first, then the
/// horizontal and vertical ones.
fn texel(tiles: &Png, gid: u32, u: u32, v: u32) -> [u8; 4] {
    let id = (gid & !(H | V | D)) - 1;
    let (mut x, mut y) = (u, v);
    if gid & V != 0 {
        y = T - 1 - y;
    }
    if gid & H != 0 {
        x = T - 1 - x;
    }
    if gid & D != 0 {
        std::mem::swap(&mut x, &mut y);
    }
    let (col, row) = (id % 8, id / 8);
    tiles.at(1 + col * (T + 1) + x, 1 + row * (T + 1) + y)
}

/// `top` over `under` (straight alpha), RGB.
fn over(top: [u8; 4], under: [u8; 4]) -> [u8; 3] {
    let a = top[3] as f64 / 255.0;
    [0, 1, 2].map(|i| (top[i] as f64 * a + under[i] as f64 * (1.0 - a)).round() as u8)
}

/// Runs the real client under Xvfb offline on `map`, the camera on
/// `look_at` (world pixels), and returns its screenshot and the JSON beside
/// it. `LEDGE_SCREENSHOT_DIR` keeps the pictures (to look at them).
fn run_client(xvfb: &Path, map: &Path, look_at: (f64, f64), name: &str) -> (Png, Value) {
    let out = tempfile::tempdir().unwrap();
    let dir = std::env::var_os("LEDGE_SCREENSHOT_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| out.path().to_owned());
    std::fs::create_dir_all(&dir).unwrap();
    let png_path = dir.join(name);
    let mut command =
        common::client_under_xvfb(xvfb, env!("CARGO_BIN_EXE_ledge-client"), 10, &png_path);
    command
        .arg("--level")
        .arg(map)
        .args(["--look-at", &format!("{},{}", look_at.0, look_at.1)])
        // The level's art is compared cell by cell: nothing drawn over it.
        .arg("--no-hud");
    let out = run_to_end(command, CLIENT_TIMEOUT);
    let status = out.status;
    assert!(
        status.success(),
        "the client failed: {status}; stderr:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join(format!("{name}.json"))).expect("the screenshot's JSON"),
    )
    .expect("valid JSON");
    (Png::load(&png_path), json)
}

/// How many of the sampled texels of cell `(c, r)` show `stack` (gids,
/// bottom first) as the tileset has them, and a few that do not.
fn cell_matches(
    shot: &Png,
    json: &Value,
    tiles: &Png,
    stack: &[u32],
    (c, r): (u32, u32),
) -> (usize, usize, Vec<String>) {
    let zoom = json["camera"]["zoom"].as_f64().unwrap();
    let (ox, oy) = pair(&json["camera"]["offset"]);
    // The centre of every third texel's screen square.
    let samples: Vec<(u32, u32)> = (0..T)
        .step_by(3)
        .flat_map(|v| (0..T).step_by(3).map(move |u| (u, v)))
        .collect();
    let mut ok = 0;
    let mut bad = Vec::new();
    for &(u, v) in &samples {
        let mut want = [0u8; 3];
        for &gid in stack {
            let t = texel(tiles, gid, u, v);
            want = over(t, [want[0], want[1], want[2], 255]);
        }
        let wx = (c * T + u) as f64 + 0.5;
        let wy = (r * T + v) as f64 + 0.5;
        let (sx, sy) = (wx * zoom + ox, wy * zoom + oy);
        let got = shot.at(sx as u32, sy as u32);
        if got[..3].iter().zip(want).all(|(&g, w)| g.abs_diff(w) <= 6) {
            ok += 1;
        } else if bad.len() < 5 {
            bad.push(format!(
                "texel ({u}, {v}) at screen ({sx}, {sy}): got {:?}, want {want:?}",
                &got[..3]
            ));
        }
    }
    (ok, samples.len(), bad)
}

/// `xvfb-run` and the Desert tileset image of the corpus; `None` (after a
/// loud notice) when one is missing outside CI; in CI a missing `xvfb-run`
/// fails.
fn prerequisites() -> Option<(PathBuf, PathBuf)> {
    let Some(xvfb) = xvfb_run() else {
        if ci() {
            panic!("xvfb-run is not on PATH: install xvfb (apt-get install xvfb) to run the screenshot tests in CI");
        }
        notice("xvfb-run is not on PATH (apt-get install xvfb xauth).");
        return None;
    };
    let Some(image) = corpus_image() else {
        notice("no level corpus: run scripts/fetch-level-corpus.");
        return None;
    };
    Some((xvfb, image))
}

#[test]
fn the_client_draws_a_tiled_map_with_its_own_tileset() {
    let Some((xvfb, image)) = prerequisites() else {
        return;
    };

    // The map and the corpus image side by side, as the map names it.
    let level_dir = tempfile::tempdir().unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/desert_art.tmx");
    let map = level_dir.path().join("desert_art.tmx");
    std::fs::copy(&fixture, &map).unwrap();
    std::fs::copy(&image, level_dir.path().join("tmw_desert_spacing.png")).unwrap();

    let (shot, json) = run_client(&xvfb, &map, LOOK_AT, "art.png");
    let tiles = Png::load(&image);
    assert_eq!(
        (tiles.width, tiles.height),
        (265, 199),
        "the Desert tileset"
    );
    let solid = json["colors"]["solid"].clone();

    // Cells (column, row) and what is drawn there, bottom layer first: the
    // sand (gid 30) everywhere, then the fixture's "ground" layer.
    let sand = 30;
    let cells: [((u32, u32), &[u32]); 10] = [
        ((7, 5), &[sand]),
        ((6, 9), &[sand, 2]),
        ((19, 9), &[sand, 3]),
        ((8, 10), &[sand, 10]),
        ((19, 10), &[sand, 11]),
        ((10, 8), &[sand, 48 | H | V | D]),
        ((12, 8), &[sand, 46 | H]),
        ((14, 8), &[sand, 31 | V]),
        ((16, 8), &[sand, 32 | D]),
        ((17, 8), &[sand, 32]),
    ];
    for ((c, r), stack) in cells {
        let (ok, n, bad) = cell_matches(&shot, &json, &tiles, stack, (c, r));
        assert!(
            ok * 100 >= n * 97,
            "cell ({c}, {r}) drawn with {stack:x?}: {ok} of {n} samples match the tileset: {bad:?} ({json})"
        );
        // A flipped tile is drawn flipped: unflipped, it would not match.
        if let Some(&top) = stack.last() {
            if top & (H | V | D) != 0 {
                let plain = [sand, top & !(H | V | D)];
                let (same, n, _) = cell_matches(&shot, &json, &tiles, &plain, (c, r));
                assert!(
                    same * 100 < n * 90,
                    "cell ({c}, {r}): {same} of {n} samples also match the unflipped tile"
                );
            }
        }
    }
    // None of ledge's flat ground colour where the art draws.
    let solid = [0, 1, 2].map(|i| solid[i].as_u64().unwrap() as u8);
    let mut flat = 0;
    for y in (0..shot.height).step_by(4) {
        for x in (0..shot.width).step_by(4) {
            flat += (shot.at(x, y)[..3] == solid) as u32;
        }
    }
    assert!(
        flat < 10,
        "{flat} pixels of the flat solid colour {solid:?}"
    );
}

/// Tiled's own `desert.tmx` (one 40 x 40 layer, its external `desert.tsx`),
/// exactly as Tiled's examples ship it: every cell in view shows the tile
/// the file puts there, read with the `tiled` crate.
#[test]
fn the_client_draws_tileds_own_desert_map() {
    let Some((xvfb, image)) = prerequisites() else {
        return;
    };
    let map = image.with_file_name("desert.tmx");
    let (shot, json) = run_client(&xvfb, &map, (640.0, 640.0), "desert.png");
    let tiles = Png::load(&image);
    let tmx = tiled::Loader::new().load_tmx_map(&map).expect("desert.tmx");
    let layer = tmx.get_layer(0).unwrap().as_tile_layer().unwrap();
    let ts = tmx.tilesets()[0].clone();
    assert_eq!((ts.margin, ts.spacing, ts.columns), (1, 1, 8));
    // The 10 x 6 cells around the camera (640, 640) px, all in view at
    // 960 x 540 and zoom 2 or less.
    let mut checked = 0;
    for r in 17..23 {
        for c in 15..25 {
            let lt = layer
                .get_tile(c as i32, r as i32)
                .expect("desert.tmx fills every cell");
            let mut gid = lt.id() + 1;
            gid |= if lt.flip_h { H } else { 0 }
                | if lt.flip_v { V } else { 0 }
                | if lt.flip_d { D } else { 0 };
            let (ok, n, bad) = cell_matches(&shot, &json, &tiles, &[gid], (c, r));
            assert!(
                ok * 100 >= n * 97,
                "desert.tmx cell ({c}, {r}), tile {}: {ok} of {n} samples match: {bad:?} ({json})",
                lt.id()
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 60);
}
