//! The replay's window: frame after frame, the viewer's keys, the replay
//! stepped by the frame's time at its speed ([`ReplayViewer::advance`]),
//! drawn as the game draws a match (the same camera, scene, animation and
//! effects; the followed player as ours, the others with their names), the
//! replay's HUD, and `--screenshot`'s picture and description; until Esc
//! or the window is closed (or `--exit-after-ticks`). In the browser (the
//! page's `?replay=ID`) the same, but no screenshot, no Esc (a page is
//! left by closing it), and each frame's state reported to the page
//! (`window.ledgeState`).
//!
//! Keys (fixed; Esc, F1, F2 and M as `--keys` binds them): Space pauses
//! (at the end it plays again), `-`/`+` (or `[`/`]`) slower and faster,
//! Left/Right 5 s back and forward, Home/End to where it opened and to
//! the end, Tab follows the next player (Shift+Tab the one before), F a
//! free camera (WASD moves it). A long seek goes on over the next frames
//! ([`ledge_client::replay::viewer::SEEK_TICKS_PER_FRAME`] ticks each,
//! drawn as it goes, the HUD saying `seeking to m:ss.cc...`).

#[cfg(not(target_arch = "wasm32"))]
use std::path::PathBuf;

use ledge_client::replay::{Follow, ReplayViewer};
use ledge_client::time::Instant;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::game::PlayerView;
use ledge_shared::level::{EntityKind, Level};
use ledge_shared::replay::ReplayError;
use macroquad::prelude::*;

use crate::draw::anim::Animator;
use crate::draw::art::ArtView;
use crate::draw::camera::{self, Camera};
use crate::draw::hud::{self, BannerLayout, ResultRow, RunInfo};
use crate::draw::render::{self, EntitySprite, PlayerSprite};
use crate::draw::replay_hud::{self, ReplayHud, ReplayLines};
use crate::draw::{fx, scene};
use crate::frame::{sound_notice, FrameClock};
use crate::input::follow::FollowCamera;
use crate::input::keys::Bindings;
use crate::outcome::{fail, EXIT_FAILED};
use crate::play;
use crate::replay::advice::advice;
#[cfg(not(target_arch = "wasm32"))]
use crate::shot;
use crate::sound::audio::{Audio, AudioStatus, Effect};
use crate::sound::cues::Cues;

/// Left and Right seek this many seconds.
pub const SKIP_SECONDS: f64 = 5.0;

/// Frames drawn before `--exit-after-ticks` ends the replay (and
/// `--screenshot` takes the last): a new window's first frames may not be
/// on screen yet.
const MIN_FRAMES: u32 = 3;

/// Everything the replay's window needs, prepared before it opens.
pub struct Watch {
    /// The replay, opened where it starts.
    pub viewer: ReplayViewer,
    /// Its level.
    pub level: Level,
    /// The level's art (textures are made when the window exists).
    pub level_art: ledge_levels::art::LevelArt,
    /// Esc, F1, F2 and M.
    pub bindings: Bindings,
    /// Where the replay came from (for messages).
    pub source: String,
    /// Quit after this many ticks played (`--exit-after-ticks`).
    pub exit_after: Option<u64>,
    /// Save the last frame there (`--screenshot`).
    #[cfg(not(target_arch = "wasm32"))]
    pub screenshot: Option<PathBuf>,
    /// What the page's state says of the replay beside the viewer's.
    #[cfg(target_arch = "wasm32")]
    pub page: PageReplay,
    /// Start with the debug overlay.
    pub debug: bool,
    /// Start with the HUD.
    pub hud: bool,
    /// 0..=1.
    pub volume: f32,
    /// Start muted.
    pub mute: bool,
}

/// What the page's state (`window.ledgeState.replay`) says of a replay
/// beside what the viewer knows.
#[cfg(target_arch = "wasm32")]
pub struct PageReplay {
    /// The replay's id.
    pub id: String,
    /// Where its level came from: "embedded", or the URL it was
    /// downloaded from.
    pub level_from: String,
}

/// Shows the replay in the window until it is closed.
pub async fn watch(watch: Watch) {
    let mut window = ReplayLoop::new(watch);
    prevent_quit();
    while window.frame() {
        window.frame_clock.pace();
        next_frame().await;
    }
}

/// What lives from frame to frame.
struct ReplayLoop {
    watch: Watch,
    started: Instant,
    frame_clock: FrameClock,
    camera: Camera,
    animator: Animator,
    effects: fx::Fx,
    cues: Cues,
    audio: Audio,
    sound_off: Option<String>,
    art: ArtView,
    show_debug: bool,
    show_hud: bool,
    /// Ticks played (not sought): `--exit-after-ticks`' count.
    played: u64,
    frames: u32,
    /// Tab, F and WASD: whom the camera follows, or where it is free.
    follow_camera: FollowCamera,
    /// The failure, once told.
    failed: Option<String>,
}

/// What a frame shows, and from where.
struct Scene {
    level_px: Rect,
    local: Option<PlayerSprite>,
    remotes: Vec<PlayerSprite>,
    labels: Vec<String>,
    entities: Vec<EntitySprite>,
    /// The followed player.
    me: Option<PlayerView>,
    view: camera::View,
}

/// What the HUD showed.
struct Shown {
    lines: ReplayLines,
    run: Option<RunInfo>,
    name: String,
    results: Vec<ResultRow>,
    failure: Option<BannerLayout>,
}

impl ReplayLoop {
    fn new(mut watch: Watch) -> ReplayLoop {
        let audio = Audio::start();
        audio.set_volume(watch.volume);
        audio.set_muted(watch.mute);
        let sound_off = match audio.status() {
            AudioStatus::Off { .. } => Some(audio.status().to_string()),
            AudioStatus::Playing { .. } => None,
        };
        let art = ArtView::new(std::mem::take(&mut watch.level_art), &watch.level.tilemap);
        let cues = Cues::new(&watch.viewer.game().config().player);
        ReplayLoop {
            started: Instant::now(),
            frame_clock: FrameClock::new(),
            camera: Camera::new(),
            animator: Animator::new(),
            effects: fx::Fx::default(),
            cues,
            audio,
            sound_off,
            art,
            show_debug: watch.debug,
            show_hud: watch.hud,
            played: 0,
            frames: 0,
            follow_camera: FollowCamera::default(),
            failed: None,
            watch,
        }
    }

    /// One frame; false once the window is to close.
    fn frame(&mut self) -> bool {
        let esc = cfg!(not(target_arch = "wasm32")) && Bindings::pressed(&self.watch.bindings.quit);
        if esc || is_quit_requested() {
            return false;
        }
        let now = self.started.elapsed().as_secs_f64();
        let dt = self.frame_clock.lap().as_secs_f32();
        self.frames += 1;
        self.toggle_overlays();
        self.keys(dt);
        self.play(dt);
        // Animation and effects run at the replay's pace (frozen paused).
        let viewer = &self.watch.viewer;
        let pace = if viewer.paused() || viewer.at_end() {
            0.0
        } else {
            dt * viewer.speed()
        };
        let cued = self.play_sounds();
        let mut scene = self.compose(dt, pace);
        self.animate_effects(&cued, &mut scene, pace);
        self.draw_world(&scene, now);
        let shown = self.draw_hud(&scene, now);
        #[cfg(target_arch = "wasm32")]
        self.report_to_page(&scene, &shown);
        let done = self.finished();
        #[cfg(not(target_arch = "wasm32"))]
        if done {
            if let Some(path) = &self.watch.screenshot {
                self.save_screenshot(path, &scene, &shown, now);
            }
        }
        !done
    }

    /// F1, F2 and M as bound.
    fn toggle_overlays(&mut self) {
        let bindings = &self.watch.bindings;
        if Bindings::pressed(&bindings.debug) {
            self.show_debug = !self.show_debug;
        }
        if Bindings::pressed(&bindings.hud) {
            self.show_hud = !self.show_hud;
        }
        if Bindings::pressed(&bindings.mute) {
            self.audio.toggle_mute();
        }
    }

    /// The replay's keys (see the module documentation). A seek or another
    /// player followed starts the sound cues and effects afresh.
    fn keys(&mut self, dt: f32) {
        let any = |keys: &[KeyCode]| keys.iter().any(|&k| is_key_pressed(k));
        let v = &mut self.watch.viewer;
        let before = (v.tick(), v.followed());
        let mut result = Ok(());
        if is_key_pressed(KeyCode::Space) {
            result = v.toggle_pause();
        }
        if any(&[KeyCode::Minus, KeyCode::KpSubtract, KeyCode::LeftBracket]) {
            v.slower();
        }
        if any(&[KeyCode::Equal, KeyCode::KpAdd, KeyCode::RightBracket]) {
            v.faster();
        }
        if is_key_pressed(KeyCode::Left) {
            result = result.and_then(|()| v.skip(-SKIP_SECONDS));
        }
        if is_key_pressed(KeyCode::Right) {
            result = result.and_then(|()| v.skip(SKIP_SECONDS));
        }
        if is_key_pressed(KeyCode::Home) {
            result = result.and_then(|()| v.seek_home());
        }
        if is_key_pressed(KeyCode::End) {
            result = result.and_then(|()| v.seek_end());
        }
        let players = v.players();
        v.set_follow(self.follow_camera.keys(v.follow(), &players, dt));
        let after = (v.tick(), v.followed());
        if let Err(e) = result {
            self.failure(&e);
        }
        if after != before {
            self.afresh();
        }
    }

    /// Sound cues and effects start over (after a seek, or following
    /// another player): what changed was not played.
    fn afresh(&mut self) {
        self.cues = Cues::new(&self.watch.viewer.game().config().player);
        self.effects = fx::Fx::default();
    }

    /// Tells why the replay stopped playing, once.
    fn failure(&mut self, e: &ReplayError) {
        if self.failed.is_none() {
            let message = format!("the replay {} {e}: {}", self.watch.source, advice(e));
            fail(EXIT_FAILED, &message);
            self.failed = Some(message);
        }
    }

    /// Steps the ticks due (at most those `--exit-after-ticks` leaves),
    /// or a seek under way on by its budget of ticks (then what changed
    /// is not sounded: the cues start afresh).
    fn play(&mut self, dt: f32) {
        let remaining = self
            .watch
            .exit_after
            .map_or(u64::MAX, |n| n.saturating_sub(self.played));
        let seeking = self.watch.viewer.seeking().is_some();
        match self.watch.viewer.advance(f64::from(dt), remaining) {
            Ok(n) => self.played += n,
            Err(e) => self.failure(&e),
        }
        if seeking {
            self.afresh();
        }
    }

    /// The followed player's sounds of what changed since the last frame;
    /// returns them (its effects).
    fn play_sounds(&mut self) -> Vec<Effect> {
        let viewer = &self.watch.viewer;
        let cued = match viewer.followed() {
            Some(id) => self.cues.observe(viewer.game(), id),
            None => Vec::new(),
        };
        for &effect in &cued {
            self.audio.play(effect);
        }
        cued
    }

    /// What to draw: the players posed (by `pace` seconds of the replay),
    /// the entities, the camera on the followed player (or free).
    fn compose(&mut self, dt: f32, pace: f32) -> Scene {
        let viewer = &self.watch.viewer;
        let level_px = scene::level_extent(&self.watch.level, &self.art);
        let frame_view = viewer.view();
        let (local, remotes) = play::sprites(&frame_view, &mut self.animator, pace);
        let entities = frame_view.entities.iter().map(EntitySprite::from).collect();
        let me = viewer.followed().and_then(|id| viewer.game().player(id));
        let followed = local.as_ref().or(remotes.first()).map(|p| p.pos);
        let focus = self
            .follow_camera
            .focus(viewer.follow(), followed, level_px);
        let screen = vec2(screen_width(), screen_height());
        let view = self.camera.update(focus, level_px, screen, dt);
        let labels = remotes
            .iter()
            .map(|p| {
                p.name
                    .clone()
                    .unwrap_or_else(|| format!("player #{}", p.id))
            })
            .collect();
        Scene {
            level_px,
            local,
            remotes,
            labels,
            entities,
            me,
            view,
        }
    }

    /// Moves the effects on by `pace` seconds: the followed player's from
    /// its cues (as ours in a game), the others' from what is drawn.
    fn animate_effects(&mut self, cued: &[Effect], scene: &mut Scene, pace: f32) {
        self.effects.local(
            cued,
            scene.local.as_ref().map(|p| fx::At {
                pos: p.pos,
                size: p.size,
                tint: render::player_color(p.id, true),
            }),
        );
        let watched: Vec<fx::Watched> = scene
            .remotes
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
            .collect();
        self.effects.watch(&watched);
        let map = &self.watch.level.tilemap;
        self.effects.update(pace, |p| {
            let units = (p * UNITS_PER_PX as f32).clamp(Vec2::splat(-1e9), Vec2::splat(1e9));
            map.is_solid_at(IVec2::new(units.x as i32, units.y as i32))
        });
        scene.view = camera::View {
            offset: scene.view.offset + self.effects.shake(),
            ..scene.view
        };
    }

    /// Draws the world as the game does.
    fn draw_world(&self, scene: &Scene, now: f64) {
        let viewer = &self.watch.viewer;
        scene::draw(scene::WorldFrame {
            level: &self.watch.level,
            art: &self.art,
            view: &scene.view,
            entities: &scene.entities,
            checkpoint: scene.me.as_ref().and_then(|m| m.checkpoint),
            local: scene
                .local
                .as_ref()
                .map(|p| (p, p.name.as_deref().unwrap_or_default())),
            remotes: scene
                .remotes
                .iter()
                .zip(scene.labels.iter().map(String::as_str))
                .collect(),
            effects: &self.effects,
            debug: self.show_debug.then(|| viewer.game().world()),
            ghosts: &[],
            time: now as f32,
        });
    }

    /// Draws the replay's HUD (or the failure where the replay stopped);
    /// returns what it showed.
    fn draw_hud(&self, scene: &Scene, now: f64) -> Shown {
        let viewer = &self.watch.viewer;
        let lines = ReplayLines::of(viewer);
        let rate = viewer.tick_rate();
        let coins_total = self
            .watch
            .level
            .entities
            .iter()
            .filter(|e| matches!(e.kind, EntityKind::Coin))
            .count();
        let run = scene.me.as_ref().map(|m| RunInfo {
            coins: m.coins,
            coins_total: u32::try_from(coins_total).unwrap_or(u32::MAX),
            deaths: m.deaths,
            run_ticks: m.run_ticks,
            tick_rate: rate,
            place: m.place,
        });
        let name = scene.me.map_or_else(String::new, |m| viewer.name_of(m.id));
        let results = viewer
            .game()
            .results()
            .iter()
            .map(|r| ResultRow {
                place: r.place.unwrap_or(0),
                name: viewer.name_of(r.id),
                ticks: r.run_ticks,
                deaths: r.deaths,
                ours: Some(r.id) == viewer.followed(),
            })
            .collect::<Vec<_>>();
        // Where it failed, the failure covers the scene.
        let failure = self
            .failed
            .as_deref()
            .filter(|_| viewer.at_end())
            .map(hud::failure);
        if self.show_hud && failure.is_none() {
            replay_hud::draw(&ReplayHud {
                followed: run.map(|r| (name.as_str(), r)),
                lines: &lines,
                results: &results,
                tick_rate: rate,
                muted: self.audio.is_muted(),
                sound_notice: self.sound_notice(now),
                at_end: viewer.at_end(),
            });
        }
        Shown {
            lines,
            run,
            name,
            results,
            failure,
        }
    }

    /// "sound off: why", for the first seconds.
    fn sound_notice(&self, now: f64) -> Option<&str> {
        sound_notice(self.sound_off.as_deref(), now)
    }

    /// Whether `--exit-after-ticks` is reached (or the replay's end).
    fn finished(&self) -> bool {
        self.watch.exit_after.is_some_and(|n| {
            (self.played >= n || self.watch.viewer.at_end()) && self.frames >= MIN_FRAMES
        })
    }

    /// Publishes what the frame showed to the page (`window.ledgeState`):
    /// the replay's state, the players drawn (the followed one as ours).
    #[cfg(target_arch = "wasm32")]
    fn report_to_page(&self, scene: &Scene, shown: &Shown) {
        use crate::page;
        let viewer = &self.watch.viewer;
        let view = &scene.view;
        let local = scene
            .local
            .iter()
            .map(|p| (p, true, p.name.as_deref().unwrap_or_default()));
        let remotes = scene
            .remotes
            .iter()
            .zip(&scene.labels)
            .map(|(p, label)| (p, false, label.as_str()));
        let players = local
            .chain(remotes)
            .map(|(p, ours, label)| {
                let top_left = view.to_screen(p.pos - p.size / 2.0);
                let size = p.size * view.zoom;
                page::DrawnPlayer {
                    id: p.id,
                    name: label.to_owned(),
                    local: ours,
                    screen: [top_left.x, top_left.y, size.x, size.y],
                    world: [p.pos.x, p.pos.y],
                    rgb: render::palette::bytes(render::player_color(p.id, ours)),
                }
            })
            .collect();
        let me = scene.me.as_ref();
        let report = page::Report {
            played: self.played,
            status: &shown.lines.clock,
            failure: self.failed.as_deref(),
            joined: true,
            me: me.map(|m| m.pos),
            players,
            spectating: false,
            level: None,
        };
        page::report_replay(
            &report,
            &page::ReplayState {
                id: &self.watch.page.id,
                level: &viewer.replay().header.level_name,
                level_from: &self.watch.page.level_from,
                tick: viewer.tick(),
                start_tick: viewer.start_tick(),
                end_tick: viewer.end_tick(),
                home: viewer.home(),
                speed: viewer.speed(),
                paused: viewer.paused(),
                at_end: viewer.at_end(),
                following: me.map(|_| shown.name.as_str()),
                follow_pos: me.map(|m| m.pos),
                free_camera: viewer.follow() == Follow::Free,
                clock: &shown.lines.clock,
                error: self.failed.as_deref(),
            },
        );
    }

    /// Saves the frame as `path` and its description beside it.
    #[cfg(not(target_arch = "wasm32"))]
    fn save_screenshot(&self, path: &std::path::Path, scene: &Scene, shown: &Shown, now: f64) {
        let viewer = &self.watch.viewer;
        let level = &self.watch.level;
        let following = scene.me.map(|m| (m.id.0, shown.name.as_str()));
        let replay = shot::ReplayShot {
            tick: viewer.tick(),
            start_tick: viewer.start_tick(),
            end_tick: viewer.end_tick(),
            home: viewer.home(),
            speed: viewer.speed(),
            paused: viewer.paused(),
            at_end: viewer.at_end(),
            run: matches!(
                viewer.replay().header.kind,
                ledge_shared::replay::ReplayKind::Run { .. }
            ),
            following,
            free_camera: viewer.follow() == Follow::Free,
            lines: &shown.lines,
            end_banner: (viewer.at_end() && self.show_hud && shown.failure.is_none())
                .then_some(&replay_hud::END_TEXT),
        };
        let shot = shot::Shot {
            tick: self.played,
            view: &scene.view,
            level_px: scene.level_px,
            tile_px: level.tilemap.tile_size() / UNITS_PER_PX,
            server: scene.me.map(|m| (viewer.tick(), m.id.0, m.pos, m.half)),
            drawn: scene.local.as_ref().map(|p| p.pos),
            remotes: shot::remotes(&scene.remotes, &scene.labels),
            hud: (self.show_hud && shown.failure.is_none()).then(|| shot::HudShot {
                name: &shown.name,
                run: shown.run,
                net_panel: false,
                muted: self.audio.is_muted(),
                sound_notice: self.sound_notice(now),
                results: &shown.results,
                card: None,
            }),
            failure: self.failed.as_deref().zip(shown.failure.as_ref()),
            chat: None,
            fx: shot::FxShot {
                particles: self.effects.particles().len(),
                shake: self.effects.shake().length(),
                flash: self.effects.flash().a,
                recent: self.effects.recent(),
                dead: scene.me.as_ref().is_some_and(|m| m.dead.is_some()),
            },
            replay: Some(replay),
            ghosts: &[],
            ghosts_shown: false,
            split: None,
            spectate: None,
            levels: None,
            downloading: None,
        };
        if let Err(e) = shot::save(path, &shot) {
            fail(EXIT_FAILED, &format!("cannot save the screenshot: {e}"));
        }
    }
}
