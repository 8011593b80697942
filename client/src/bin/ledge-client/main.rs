//! `ledge-client`: the macroquad front end.
//!
//! * offline (no `--connect`/`--local`): the default level in a local game;
//! * `--connect HOST:PORT`: joins a server on a background network thread
//!   (macroquad owns the main thread) and predicts our player with the
//!   shared simulation. The server's certificate is pinned with
//!   `--cert-hash HEX`, or else trusted on first use and remembered in a
//!   known-hosts file (`--known-hosts PATH`, default
//!   `$XDG_CONFIG_HOME/ledge/known_hosts`); a changed certificate is refused
//!   with a message saying what to do, and exit code 3;
//! * `--local`: starts the real server in-process on `127.0.0.1:0` and
//!   joins it: one command, a playable game.
//!
//! The simulation runs at a fixed 60 Hz (accumulator); frames are drawn
//! interpolated between the last two ticks. `--script`, `--screenshot` and
//! `--exit-after-ticks` drive it without a human, for tests.
//!
//! A session that fails (the server cannot be reached, refuses us, drops
//! us; its certificate is refused) is told once on stderr, prefixed
//! `ledge-client: `, and in the window, wrapped to its size, until the
//! player quits; the message says what to do next. Exit codes (also in
//! `--help`):
//!
//! * 0: the game ended normally (Esc, window closed, `--exit-after-ticks`);
//! * 1 ([`EXIT_FAILED`]): the session failed, or the game could not start
//!   (a level or keys file, the screenshot);
//! * 2 ([`EXIT_JOIN_TIMEOUT`]): not joined within `--join-timeout` (with
//!   `--exit-after-ticks`); also clap's code for command-line errors;
//! * 3 ([`EXIT_UNTRUSTED`]): the server's certificate was refused.

// The browser build leaves out the command line, files and the network
// thread, and with them some helpers the native build uses.
#![cfg_attr(target_arch = "wasm32", allow(dead_code))]

mod art;
mod camera;
mod debug;
mod fx;
mod hud;
mod keys;
#[cfg(not(target_arch = "wasm32"))]
mod local;
#[cfg(not(target_arch = "wasm32"))]
mod native;
mod play;
mod render;
mod script;
mod shot;
#[cfg(target_arch = "wasm32")]
mod web;

use std::path::PathBuf;
use std::sync::atomic::{AtomicI32, Ordering};
use std::time::Duration;

use ledge_client::audio::{Audio, AudioStatus};
use ledge_client::cues::Cues;
use ledge_client::time::Instant;
use ledge_client::view::px2;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::input::Buttons;
use macroquad::prelude::*;

use camera::Camera;
use keys::{Bindings, Gamepads};
use render::EntitySprite;
use script::Script;

/// How long "sound off: why" stays on screen, seconds from the start.
const SOUND_NOTICE_SECONDS: f64 = 6.0;

/// The controls hint stays this long after the first move, then fades
/// out over [`HINT_FADE`] seconds.
const HINT_STAYS: f64 = 4.0;
const HINT_FADE: f64 = 1.5;

/// The controls hint's opacity at `now`, the player having first moved at
/// `first_move`.
fn hint_alpha(first_move: Option<f64>, now: f64) -> f32 {
    match first_move {
        None => 1.0,
        Some(t) => (1.0 - (now - t - HINT_STAYS) / HINT_FADE).clamp(0.0, 1.0) as f32,
    }
}

/// Coins in `level`.
fn coins_total(level: &ledge_shared::level::Level) -> u32 {
    let coins = level
        .entities
        .iter()
        .filter(|e| matches!(e.kind, ledge_shared::level::EntityKind::Coin))
        .count();
    u32::try_from(coins).unwrap_or(u32::MAX)
}

/// Frames are not drawn faster than this (no vsync under Xvfb).
const MAX_FPS: f64 = 240.0;

/// Exit code when the session failed (or the game could not start).
const EXIT_FAILED: i32 = 1;

/// Exit code when not joined within `--join-timeout` (clap's usage errors
/// exit with 2 too).
const EXIT_JOIN_TIMEOUT: i32 = 2;

/// Exit code when the server's certificate is refused.
const EXIT_UNTRUSTED: i32 = 3;

/// Frames drawn with a failure's banner before `--exit-after-ticks` ends
/// the run (and `--screenshot` takes the last): the first frames of a
/// new window may not be on screen yet.
const FAILURE_FRAMES: u32 = 3;

/// The process exit code, set by the game loop (macroquad's loop owns the
/// main thread until it ends).
static EXIT_CODE: AtomicI32 = AtomicI32::new(0);

/// Everything the game loop needs, prepared before the window opens.
struct Setup {
    play: play::Play,
    bindings: Bindings,
    script: Option<Script>,
    exit_after: Option<u64>,
    screenshot: Option<PathBuf>,
    join_timeout: Duration,
    name: String,
    debug: bool,
    net: bool,
    /// Start with the HUD shown.
    hud: bool,
    /// Volume, 0..=1.
    volume: f32,
    mute: bool,
    look_at: Option<Vec2>,
    /// The level's art (textures are made when the window exists).
    level_art: ledge_levels::art::LevelArt,
    /// Kept alive for the whole game; dropped after the network thread.
    #[cfg(not(target_arch = "wasm32"))]
    server: Option<local::LocalServer>,
}

fn main() {
    #[cfg(not(target_arch = "wasm32"))]
    native::main();
    #[cfg(target_arch = "wasm32")]
    web::main();
}

/// A line for the player outside the window: on stderr natively, prefixed
/// `ledge-client: ` (a closed stderr is no reason to panic); in the
/// browser's console.
fn tell(message: &str) {
    #[cfg(not(target_arch = "wasm32"))]
    {
        use std::io::Write;
        let _ = writeln!(std::io::stderr().lock(), "ledge-client: {message}");
    }
    #[cfg(target_arch = "wasm32")]
    macroquad::logging::error!("ledge-client: {}", message);
}

/// Fails the run: message on stderr, exit code `code` (the first failure's
/// code is kept).
fn fail(code: i32, message: &str) {
    tell(message);
    let _ = EXIT_CODE.compare_exchange(0, code, Ordering::Relaxed, Ordering::Relaxed);
}

/// Why the session cannot go on, if so: the exit code and the message
/// (what went wrong and what to do). `waited`: time since the window
/// opened.
fn session_failure(setup: &Setup, waited: Duration) -> Option<(i32, String)> {
    if let Some(message) = setup.play.untrusted() {
        return Some((EXIT_UNTRUSTED, message.to_owned()));
    }
    if let Some(message) = setup.play.failure() {
        return Some((EXIT_FAILED, message));
    }
    let waited_too_long =
        setup.exit_after.is_some() && !setup.play.joined() && waited > setup.join_timeout;
    waited_too_long.then(|| {
        (
            EXIT_JOIN_TIMEOUT,
            format!(
                "not joined to {} within {} s (--join-timeout): check the address and port \
                 (the server prints them when it starts), that the server is running, and \
                 that no firewall blocks UDP to that port",
                setup.play.server(),
                setup.join_timeout.as_secs()
            ),
        )
    })
}

async fn game(mut setup: Setup) {
    let started = Instant::now();
    let mut camera = Camera::new();
    // How players look from frame to frame (run, jump, landing squash).
    let mut animator = ledge_client::anim::Animator::new();
    let mut pads = Gamepads::new();
    let mut graph = hud::NetGraph::default();
    let mut show_debug = setup.debug;
    let mut show_hud = setup.hud;
    let mut show_net = setup.net;
    // Sound: never fails; without a device it is off and says why.
    let audio = Audio::start();
    audio.set_volume(setup.volume);
    audio.set_muted(setup.mute);
    let sound_off = match audio.status() {
        AudioStatus::Off { .. } => Some(audio.status().to_string()),
        AudioStatus::Playing { .. } => None,
    };
    let mut cues = Cues::default();
    let mut effects = fx::Fx::default();
    // When the player first moved (the controls hint fades after it).
    let mut first_move: Option<f64> = None;
    let restart_key = setup
        .bindings
        .restart_keys()
        .first()
        .map_or_else(|| "-".to_owned(), |k| format!("{k:?}"));
    // Ticks of play so far: the script's clock and --exit-after-ticks'.
    let mut played: u64 = 0;
    let mut last_frame = Instant::now();
    let mut art = art::ArtView::new(
        std::mem::take(&mut setup.level_art),
        &setup.play.level().tilemap,
    );
    // The server's art arrives with its level (downloaded or cached).
    let mut server_art = false;
    // Closing the window ends the loop below, so we leave the server.
    prevent_quit();
    // The session's failure, once known: told once, then shown until the
    // player quits.
    let mut failed: Option<String> = None;
    let mut failed_frames: u32 = 0;
    loop {
        // A page is left by closing its tab: Esc quits natively only.
        let quit = cfg!(not(target_arch = "wasm32")) && Bindings::pressed(&setup.bindings.quit);
        if quit || is_quit_requested() {
            break;
        }
        if !server_art && setup.play.joined() {
            if let Some(level_art) = setup.play.level_art() {
                art = art::ArtView::new(level_art.clone(), &setup.play.level().tilemap);
            }
            server_art = true;
        }
        if Bindings::pressed(&setup.bindings.debug) {
            show_debug = !show_debug;
        }
        if Bindings::pressed(&setup.bindings.hud) {
            show_hud = !show_hud;
        }
        if Bindings::pressed(&setup.bindings.net) {
            show_net = !show_net;
        }
        if Bindings::pressed(&setup.bindings.mute) {
            audio.toggle_mute();
        }
        let now = started.elapsed().as_secs_f64();
        let frame = last_frame.elapsed();
        last_frame = Instant::now();

        // Simulate: the ticks due, with the script's or the player's buttons.
        let remaining = setup
            .exit_after
            .map_or(u64::MAX, |n| n.saturating_sub(played));
        let script = &setup.script;
        let bindings = &setup.bindings;
        let base = played;
        let mut moved = false;
        played += setup.play.update(remaining, |i| {
            let b = match script {
                Some(script) => script.at(base + i),
                None => Buttons(bindings.held().0 | pads.held().0),
            };
            moved |= b.0 & Buttons::PLAY != 0;
            b
        });
        if moved && first_move.is_none() {
            first_move = Some(now);
        }
        // Sounds (and our player's effects) from what changed since the
        // last frame.
        let cued = match setup.play.game() {
            Some(g) => cues.observe(g.game(), g.me()),
            None => Vec::new(),
        };
        for &effect in &cued {
            audio.play(effect);
        }
        for _ in 0..setup.play.take_arrivals() {
            graph.arrival(now);
        }
        let stats = setup.play.net_stats();
        if let Some(stats) = &stats {
            graph.rtt(now, stats.rtt_ms);
        }
        if failed.is_none() {
            if let Some((code, message)) = session_failure(&setup, started.elapsed()) {
                fail(code, &message);
                failed = Some(message);
            }
        }

        // What to draw, and from where.
        let level = setup.play.level();
        // The camera stays inside everything in the level (grid, entities,
        // platform paths) and everything its art draws.
        let level_px = {
            let things = level.bounds().map(|(lo, hi)| {
                let (lo, hi) = (px2(lo), px2(hi));
                Rect::new(lo.x, lo.y, hi.x - lo.x, hi.y - lo.y)
            });
            match (things, art.extent()) {
                (Some(a), Some(e)) => a.combine_with(e),
                (Some(a), None) => a,
                (None, Some(e)) => e,
                (None, None) => Rect::new(0.0, 0.0, 1.0, 1.0),
            }
        };
        let frame_view = setup.play.view().unwrap_or_default();
        let (local, remotes) = play::sprites(&frame_view, &mut animator, frame.as_secs_f32());
        let entities: Vec<EntitySprite> =
            frame_view.entities.iter().map(EntitySprite::from).collect();
        let me = setup.play.me();
        let focus = setup.look_at.unwrap_or_else(|| {
            local
                .as_ref()
                .or(remotes.first())
                .map_or(level_px.center(), |p| p.pos)
        });
        let screen = vec2(screen_width(), screen_height());
        let view = camera.update(focus, level_px, screen, frame.as_secs_f32());
        // Effects: ours from the cues, the others' from what is drawn.
        effects.local(
            &cued,
            local.as_ref().map(|p| fx::At {
                pos: p.pos,
                size: p.size,
                tint: render::player_color(p.id, true),
            }),
        );
        effects.watch(
            &remotes
                .iter()
                .map(|p| fx::Watched {
                    id: p.id,
                    at: fx::At {
                        pos: p.pos,
                        size: p.size,
                        tint: render::player_color(p.id, false),
                    },
                    dead: p.dead,
                    won: p.won,
                })
                .collect::<Vec<_>>(),
        );
        let map = &level.tilemap;
        effects.update(frame.as_secs_f32(), |p| {
            let units = (p * UNITS_PER_PX as f32).clamp(Vec2::splat(-1e9), Vec2::splat(1e9));
            map.is_solid_at(IVec2::new(units.x as i32, units.y as i32))
        });
        // The shake moves the world, not the HUD.
        let view = camera::View {
            offset: view.offset + effects.shake(),
            ..view
        };

        // Draw: sky, tiles, entities, players, overlays.
        let time = now as f32;
        match art.background() {
            Some(colour) => clear_background(colour),
            None => render::draw_background(&view, time),
        }
        art.draw(&view);
        render::draw_tilemap(&level.tilemap, &view, art.covered());
        // A level's own art draws its solids; ledge draws them otherwise.
        let statics = art.is_empty();
        if statics {
            render::draw_polygon_blocks(level, &view);
        }
        render::draw_entities(
            &entities,
            &view,
            me.as_ref().and_then(|m| m.checkpoint),
            time,
            statics,
        );
        // Remote players wear their names (from the server's roster).
        let labels: Vec<String> = remotes
            .iter()
            .map(|p| {
                p.name
                    .clone()
                    .unwrap_or_else(|| format!("player #{}", p.id))
            })
            .collect();
        let local_label = local
            .as_ref()
            .map(|p| p.name.as_deref().unwrap_or(&setup.name));
        render::draw_players(
            &view,
            local.as_ref().zip(local_label),
            remotes.iter().zip(labels.iter().map(String::as_str)),
        );
        effects.draw(&view);
        effects.draw_flash();
        if show_debug {
            if let Some(game) = setup.play.game() {
                debug::draw(game.game().world(), &view);
            }
        }
        // A failure covers the scene; the HUD's figures mean nothing then.
        let failure = failed.as_deref().map(hud::failure);
        let run = me.as_ref().map(|m| hud::RunInfo {
            coins: m.coins,
            coins_total: coins_total(level),
            deaths: m.deaths,
            run_ticks: m.run_ticks,
            tick_rate: setup.play.tick_rate(),
            place: m.place,
        });
        let name = local
            .as_ref()
            .and_then(|p| p.name.as_deref())
            .unwrap_or(&setup.name)
            .to_owned();
        // The room's results table, names from the roster.
        let results: Vec<hud::ResultRow> = setup.play.game().map_or_else(Vec::new, |g| {
            g.game()
                .results()
                .iter()
                .map(|r| hud::ResultRow {
                    place: r.place.unwrap_or(0),
                    name: if r.id == g.me() {
                        name.clone()
                    } else {
                        g.player_names()
                            .get(&r.id)
                            .cloned()
                            .unwrap_or_else(|| format!("player #{}", r.id.0))
                    },
                    ticks: r.run_ticks,
                    deaths: r.deaths,
                    ours: r.id == g.me(),
                })
                .collect()
        });
        if show_hud && failure.is_none() {
            let status = setup.play.status_line();
            let info = hud::HudInfo {
                status: &status,
                net: stats.as_ref(),
                fps: get_fps(),
                tick: frame_view.tick,
                name: &name,
                run,
                show_net,
                hint_alpha: hint_alpha(first_move, now),
                sound_notice: sound_off.as_deref().filter(|_| now < SOUND_NOTICE_SECONDS),
                muted: audio.is_muted(),
                restart_key: &restart_key,
                results: &results,
            };
            hud::draw(&info, &graph, now);
        }
        if let (None, Some(text)) = (&failure, setup.play.banner()) {
            hud::banner(&text);
        }

        #[cfg(target_arch = "wasm32")]
        web::report(&web::Report {
            played,
            status: &setup.play.status_line(),
            failure: failed.as_deref(),
            joined: setup.play.joined(),
            me: me.as_ref().map(|m| m.pos),
            players: local
                .iter()
                .map(|p| (p, true, local_label.unwrap_or(&setup.name)))
                .chain(
                    remotes
                        .iter()
                        .zip(&labels)
                        .map(|(p, l)| (p, false, l.as_str())),
                )
                .map(|(p, ours, label)| {
                    let top_left = view.to_screen(p.pos - p.size / 2.0);
                    let size = p.size * view.zoom;
                    web::DrawnPlayer {
                        id: p.id,
                        name: label.to_owned(),
                        local: ours,
                        screen: [top_left.x, top_left.y, size.x, size.y],
                        rgb: render::palette::bytes(render::player_color(p.id, ours)),
                    }
                })
                .collect(),
        });

        // Done? (A failed run after a few frames showing why.)
        if failure.is_some() {
            failed_frames += 1;
        }
        let done = match failure {
            Some(_) => setup.exit_after.is_some() && failed_frames >= FAILURE_FRAMES,
            None => setup.exit_after.is_some_and(|n| played >= n),
        };
        if done {
            if let Some(path) = &setup.screenshot {
                let shot = shot::Shot {
                    tick: played,
                    view: &view,
                    level_px,
                    tile_px: level.tilemap.tile_size() / UNITS_PER_PX,
                    server: setup.play.server_me(),
                    drawn: local.as_ref().map(|p| p.pos),
                    remotes: remotes
                        .iter()
                        .zip(&labels)
                        .map(|(p, label)| shot::RemoteShot {
                            id: p.id,
                            label,
                            pos: p.pos,
                            size: p.size,
                        })
                        .collect(),
                    hud: (show_hud && failure.is_none()).then(|| shot::HudShot {
                        name: &name,
                        run,
                        net_panel: show_net,
                        muted: audio.is_muted(),
                        sound_notice: sound_off.as_deref().filter(|_| now < SOUND_NOTICE_SECONDS),
                        results: &results,
                    }),
                    failure: failed.as_deref().zip(failure.as_ref()),
                    fx: shot::FxShot {
                        particles: effects.particles().len(),
                        shake: effects.shake().length(),
                        flash: effects.flash().a,
                        recent: effects.recent(),
                        dead: me.as_ref().is_some_and(|m| m.dead.is_some()),
                    },
                };
                if let Err(e) = shot::save(path, &shot) {
                    fail(EXIT_FAILED, &format!("cannot save the screenshot: {e}"));
                }
            }
            break;
        }
        // No vsync (Xvfb, some drivers): do not spin. (A browser calls
        // us once per display frame.)
        #[cfg(not(target_arch = "wasm32"))]
        {
            let spent = last_frame.elapsed().as_secs_f64();
            if spent < 1.0 / MAX_FPS {
                std::thread::sleep(Duration::from_secs_f64(1.0 / MAX_FPS - spent));
            }
        }
        next_frame().await;
    }
    // Leave the server (if connected) before the window closes, then stop
    // the in-process server, if any.
    drop(setup.play);
    #[cfg(not(target_arch = "wasm32"))]
    drop(setup.server.take());
}
