//! The game loop: frame after frame until the player quits, the ticks
//! asked for are played, or a failed session has been shown; each frame a
//! sequence of named steps ([`GameLoop::frame`]): input, simulation,
//! sound, network, the scene, drawing, the page's report, the end.
//!
//! Both entry points ([`crate::native`], and `web` in the browser) prepare a
//! [`Setup`] and hand it to [`game`]; the loop uses the modules below it
//! (play, keys, camera, render, effects, HUD, screenshot) and none of
//! them uses it.

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::draw::anim::Animator;
use crate::sound::audio::{Audio, AudioStatus, Effect};
use crate::sound::cues::Cues;
use ledge_client::time::Instant;
use ledge_client::view::{FrameView, NetStats};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::game::PlayerView;
use ledge_shared::input::Buttons;
use ledge_shared::level::Level;
use macroquad::prelude::*;

use crate::chat::{Chat, Key};
use crate::draw::art::ArtView;
use crate::draw::camera::{self, Camera};
use crate::draw::ghost::{self, GhostSprite};
use crate::draw::overlay::CollisionOverlay;
use crate::draw::render::{self, EntitySprite, PlayerSprite};
use crate::draw::{card, chat as chat_view, fx, hud, levels, scene};
use crate::frame::{sound_notice, FrameClock};
use crate::input::keys::{Bindings, Gamepads};
use crate::input::script::{Press, Script};
use crate::input::typing;
use crate::outcome::{fail, EXIT_FAILED, EXIT_JOIN_TIMEOUT, EXIT_UNTRUSTED};
use crate::spectate::{self, Spectate};
use crate::splits::{Split, Splits};
use crate::{play, shot};
use ledge_shared::protocol::PlayerId;

/// The controls hint stays this long after the first move, then fades
/// out over [`HINT_FADE`] seconds.
const HINT_STAYS: f64 = 4.0;
const HINT_FADE: f64 = 1.5;

/// Frames drawn with a failure's banner before `--exit-after-ticks` ends
/// the run (and `--screenshot` takes the last): the first frames of a
/// new window may not be on screen yet.
const FAILURE_FRAMES: u32 = 3;

/// The controls hint's opacity at `now`, the player having first moved at
/// `first_move`.
fn hint_alpha(first_move: Option<f64>, now: f64) -> f32 {
    match first_move {
        None => 1.0,
        Some(t) => (1.0 - (now - t - HINT_STAYS) / HINT_FADE).clamp(0.0, 1.0) as f32,
    }
}

/// Coins in `level`.
fn coins_total(level: &Level) -> u32 {
    let coins = level
        .entities
        .iter()
        .filter(|e| matches!(e.kind, ledge_shared::level::EntityKind::Coin))
        .count();
    u32::try_from(coins).unwrap_or(u32::MAX)
}

/// Everything the game loop needs, prepared before the window opens.
pub struct Setup {
    pub play: play::Play,
    pub bindings: Bindings,
    pub script: Option<Script>,
    pub exit_after: Option<u64>,
    pub screenshot: Option<PathBuf>,
    pub join_timeout: Duration,
    pub name: String,
    pub debug: bool,
    pub net: bool,
    /// Start with the collision overlay shown (`--collision`).
    pub collision: bool,
    /// Start with the HUD shown.
    pub hud: bool,
    /// Volume, 0..=1.
    pub volume: f32,
    pub mute: bool,
    pub look_at: Option<Vec2>,
    /// Watch rather than play (`--spectate`).
    pub spectate: bool,
    /// Spectating, follow the player of this name (`--follow`).
    pub follow: Option<String>,
    /// The level's art (textures are made when the window exists).
    pub level_art: ledge_levels::art::LevelArt,
    /// Kept alive for the whole game; dropped after the network thread.
    #[cfg(not(target_arch = "wasm32"))]
    pub server: Option<crate::local::LocalServer>,
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

/// Runs the game in the window until it ends, then leaves the server.
pub async fn game(setup: Setup) {
    let mut game = GameLoop::new(setup);
    // Closing the window ends the loop below, so we leave the server.
    prevent_quit();
    while game.frame() {
        game.frame_clock.pace();
        next_frame().await;
    }
    game.leave();
}

/// What lives from frame to frame.
struct GameLoop {
    setup: Setup,
    started: Instant,
    camera: Camera,
    /// How players look from frame to frame (run, jump, landing squash).
    animator: Animator,
    pads: Gamepads,
    graph: hud::NetGraph,
    show_debug: bool,
    show_hud: bool,
    show_net: bool,
    /// The ghosts are drawn (their key toggles them).
    show_ghosts: bool,
    /// The collision overlay (its key toggles it).
    collision: CollisionOverlay,
    /// The server's level list is open (its key toggles it; a vote
    /// closes it).
    show_levels: bool,
    /// The room's level changes seen ([`play::Play::level_changes`]): when
    /// it grows, what was drawn of the old level goes.
    level_changes: u64,
    /// Our run's split times against the first ghost.
    splits: Splits,
    /// Spectating: whom the camera follows.
    spectate: Option<Spectate>,
    /// Sound: never fails; without a device it is off and says why.
    audio: Audio,
    /// Why there is no sound, if so.
    sound_off: Option<String>,
    cues: Cues,
    effects: fx::Fx,
    /// When the player first moved (the controls hint fades after it).
    first_move: Option<f64>,
    restart_key: String,
    /// The level list key's name, for the HUD.
    levels_key: String,
    /// Ticks of play so far: the script's clock and --exit-after-ticks'.
    played: u64,
    frame_clock: FrameClock,
    art: ArtView,
    /// The server's art arrives with its level (downloaded or cached).
    server_art: bool,
    /// The session's failure, once known: told once, then shown until the
    /// player quits.
    failed: Option<String>,
    failed_frames: u32,
    /// The chat: the line typed, the lines received, who is muted.
    chat: Chat,
    /// Chat lines taken from the game so far ([`play::Play::chat_since`]).
    chat_seen: u64,
}

/// What a frame shows, and from where.
struct Scene {
    /// The level's extent, world pixels (the camera stays inside).
    level_px: Rect,
    frame_view: FrameView,
    /// Our player as drawn, if in the game.
    local: Option<PlayerSprite>,
    remotes: Vec<PlayerSprite>,
    /// The remote players' labels, in the order of `remotes`.
    labels: Vec<String>,
    entities: Vec<EntitySprite>,
    /// Spectating: the player followed (drawn as `local`).
    followed: Option<PlayerId>,
    /// The ghosts drawn (none when hidden).
    ghosts: Vec<GhostSprite>,
    me: Option<PlayerView>,
    view: camera::View,
}

/// What the HUD (or the failure covering it) shows.
struct Hud {
    /// The failure's banner as drawn, if the session failed.
    failure: Option<hud::BannerLayout>,
    run: Option<hud::RunInfo>,
    name: String,
    results: Vec<hud::ResultRow>,
    /// The results card, once our run is finished.
    card: Option<card::Card>,
    /// The chat as laid out: the lines received (with the HUD) and the
    /// line typed.
    chat: chat_view::ChatView,
    /// The split against a ghost on screen, and its text.
    split: Option<(Split, String)>,
    /// Spectating: the line saying whom we watch.
    spectate: Option<String>,
    /// The level list, when open.
    levels: Option<levels::LevelsView>,
    /// "next: NAME in N s", once the room's move is decided.
    next_level: Option<String>,
    /// A level downloading: what, bytes so far, its size.
    downloading: Option<(&'static str, u64, u64)>,
}

impl GameLoop {
    /// The loop's state at the start: sound started, the level's art.
    fn new(mut setup: Setup) -> GameLoop {
        let started = Instant::now();
        let camera = Camera::new();
        let animator = Animator::new();
        let pads = Gamepads::new();
        let graph = hud::NetGraph::default();
        let audio = Audio::start();
        audio.set_volume(setup.volume);
        audio.set_muted(setup.mute);
        let sound_off = match audio.status() {
            AudioStatus::Off { .. } => Some(audio.status().to_string()),
            AudioStatus::Playing { .. } => None,
        };
        let restart_key = setup
            .bindings
            .restart_keys()
            .first()
            .map_or_else(|| "-".to_owned(), |k| format!("{k:?}"));
        let levels_key = setup
            .bindings
            .levels
            .first()
            .map_or_else(|| "-".to_owned(), |k| format!("{k:?}"));
        let art = ArtView::new(
            std::mem::take(&mut setup.level_art),
            &setup.play.level().tilemap,
        );
        GameLoop {
            started,
            camera,
            animator,
            pads,
            graph,
            show_debug: setup.debug,
            show_hud: setup.hud,
            show_net: setup.net,
            show_ghosts: true,
            collision: CollisionOverlay::new(setup.collision),
            show_levels: false,
            level_changes: 0,
            splits: Splits::default(),
            spectate: setup.spectate.then(|| Spectate::new(setup.follow.clone())),
            audio,
            sound_off,
            cues: Cues::default(),
            effects: fx::Fx::default(),
            first_move: None,
            restart_key,
            levels_key,
            played: 0,
            frame_clock: FrameClock::new(),
            art,
            server_art: false,
            failed: None,
            failed_frames: 0,
            chat: Chat::default(),
            chat_seen: 0,
            setup,
        }
    }

    /// One frame, step by step; false once the game is over.
    fn frame(&mut self) -> bool {
        // While typing, the keys are the chat line's (Escape closes it).
        let chatting = self.chat.is_open();
        if self.quit_asked(chatting) {
            return false;
        }
        self.adopt_server_art();
        let now = self.started.elapsed().as_secs_f64();
        self.type_chat(now);
        if !chatting && !self.chat.is_open() {
            self.toggle_overlays();
            let pressed = Bindings::pressed(&self.setup.bindings.levels);
            self.level_keys(pressed, Bindings::number_pressed(), now);
        }
        let dt = self.frame_clock.lap();
        let before = self.played;
        self.simulate(now);
        self.race_ghosts(now);
        self.script_chat(before, now);
        self.script_keys(before, now);
        self.receive_chat(now);
        let cued = self.play_sounds();
        let stats = self.watch_network(now);
        self.check_failure();
        let mut scene = self.compose(dt);
        self.animate_effects(&cued, &mut scene, dt);
        self.draw_world(&scene, now);
        self.draw_collision(&scene);
        let hud = self.hud_info(&scene, now);
        self.draw_hud(&scene, &hud, stats.as_ref(), now);
        #[cfg(target_arch = "wasm32")]
        self.report_to_page(&scene);
        !self.finished(&scene, &hud, now)
    }

    /// Esc (natively only, and not while `chatting`: a page is left by closing its tab) or the window closed.
    fn quit_asked(&self, chatting: bool) -> bool {
        let quit = cfg!(not(target_arch = "wasm32"))
            && !chatting
            && Bindings::pressed(&self.setup.bindings.quit);
        quit || is_quit_requested()
    }

    /// The chat line: opened by its key (what was typed before is the
    /// game's), then fed the keys typed; a line Enter sends goes out.
    fn type_chat(&mut self, now: f64) {
        if !self.chat.is_open() {
            if Bindings::pressed(&self.setup.bindings.chat) {
                if self.spectate.is_some() {
                    // The server would answer so: said at once.
                    self.chat.tell(spectate::NO_CHAT, now);
                } else {
                    self.chat.open();
                }
            }
            typing::forget();
            return;
        }
        for key in typing::keys() {
            if let Some(text) = self.chat.key(key, now) {
                self.send_chat(&text, now);
            }
        }
    }

    /// Sends a chat line; the chat says why not if it cannot.
    fn send_chat(&mut self, text: &str, now: f64) {
        if let Err(why) = self.setup.play.say(text) {
            self.chat.not_sent(&why, now);
        }
    }

    /// The script's chat lines of the ticks just played (from tick
    /// `before`), typed into the chat line and Enter pressed.
    fn script_chat(&mut self, before: u64, now: f64) {
        let Some(script) = &self.setup.script else {
            return;
        };
        let lines: Vec<String> = script
            .said(before..self.played)
            .map(str::to_owned)
            .collect();
        for line in lines {
            self.chat.open();
            for c in line.chars() {
                self.chat.key(Key::Char(c), now);
            }
            if let Some(text) = self.chat.key(Key::Enter, now) {
                self.send_chat(&text, now);
            }
        }
    }

    /// Takes the chat lines received since the last frame.
    fn receive_chat(&mut self, now: f64) {
        let (seen, lines) = self.setup.play.chat_since(self.chat_seen);
        self.chat_seen = seen;
        for (from, text) in lines {
            self.chat.receive(&from, &text, now);
        }
    }

    /// Swaps in the server's level art once joined (it comes with its
    /// level), and again each time the room moves to another level (the
    /// splits against the old level's ghost go too).
    fn adopt_server_art(&mut self) {
        let changes = self.setup.play.level_changes();
        let changed = changes != self.level_changes;
        if changed {
            self.level_changes = changes;
            self.server_art = false;
            self.splits = Splits::default();
        }
        if !self.server_art && self.setup.play.joined() {
            let art = self.setup.play.level_art().cloned();
            if art.is_some() || changed {
                let tiles = &self.setup.play.level().tilemap;
                self.art = ArtView::new(art.unwrap_or_default(), tiles);
            }
            self.server_art = true;
        }
    }

    /// The script's window keys of the ticks just played (from tick
    /// `before`), pressed.
    fn script_keys(&mut self, before: u64, now: f64) {
        let Some(script) = &self.setup.script else {
            return;
        };
        let presses: Vec<Press> = script.pressed(before..self.played).collect();
        for press in presses {
            match press {
                Press::Levels => self.level_keys(true, None, now),
                Press::Number(n) => self.level_keys(false, Some(n), now),
            }
        }
    }

    /// The level list's key (`toggle`) opens or closes it; while it is
    /// open a number key (`number`) votes for that level and closes it
    /// (the chat says what came of it).
    fn level_keys(&mut self, toggle: bool, number: Option<u32>, now: f64) {
        if toggle {
            self.show_levels = !self.show_levels;
            if self.show_levels && self.setup.play.levels().is_none() {
                self.show_levels = false;
                self.chat
                    .tell("no level list: the server has not sent one", now);
            }
            return;
        }
        if !self.show_levels {
            return;
        }
        let Some(number) = number else {
            return;
        };
        match self.setup.play.vote(number - 1) {
            Ok(()) => {
                let name = self
                    .setup
                    .play
                    .levels()
                    .and_then(|l| l.levels.get(number as usize - 1))
                    .map_or_else(String::new, |l| l.name.clone());
                self.chat.tell(&format!("voted for {number}. {name}"), now);
                self.show_levels = false;
            }
            Err(why) => self.chat.tell(&format!("no vote: {why}"), now),
        }
    }

    /// Toggles the debug overlay, the HUD, the network panel and the sound by their keys.
    fn toggle_overlays(&mut self) {
        let bindings = &self.setup.bindings;
        if Bindings::pressed(&bindings.debug) {
            self.show_debug = !self.show_debug;
        }
        if Bindings::pressed(&bindings.hud) {
            self.show_hud = !self.show_hud;
        }
        if Bindings::pressed(&bindings.net) {
            self.show_net = !self.show_net;
        }
        if Bindings::pressed(&bindings.mute) {
            self.audio.toggle_mute();
        }
        if Bindings::pressed(&bindings.ghosts) {
            self.show_ghosts = !self.show_ghosts;
        }
        if Bindings::pressed(&bindings.collision) {
            self.collision.toggle();
        }
    }

    /// Compares our run with the first ghost's (the record, else our
    /// best) at the checkpoints and the goal.
    fn race_ghosts(&mut self, now: f64) {
        if let Some(me) = self.setup.play.me() {
            let ghost = self.setup.play.ghosts().first();
            self.splits.observe(&me, ghost, now);
        }
    }

    /// Simulates the ticks due, with the script's or the player's buttons.
    fn simulate(&mut self, now: f64) {
        let remaining = self
            .setup
            .exit_after
            .map_or(u64::MAX, |n| n.saturating_sub(self.played));
        let script = &self.setup.script;
        let bindings = &self.setup.bindings;
        let pads = &mut self.pads;
        let base = self.played;
        let mut moved = false;
        // While typing, the player's buttons are released.
        let chatting = self.chat.is_open();
        self.played += self.setup.play.update(remaining, |i| {
            let b = match script {
                Some(script) => script.at(base + i),
                None if chatting => Buttons::NONE,
                None => Buttons(bindings.held().0 | pads.held().0),
            };
            moved |= b.0 & Buttons::PLAY != 0;
            b
        });
        if moved && self.first_move.is_none() {
            self.first_move = Some(now);
        }
    }

    /// Plays the sounds of what changed since the last frame; returns them (our effects).
    fn play_sounds(&mut self) -> Vec<Effect> {
        let cued = match self.setup.play.game() {
            Some(g) => self.cues.observe(g.game(), g.me()),
            None => Vec::new(),
        };
        for &effect in &cued {
            self.audio.play(effect);
        }
        cued
    }

    /// Feeds the network graph (arrivals, round trip); returns the figures for the HUD.
    fn watch_network(&mut self, now: f64) -> Option<NetStats> {
        for _ in 0..self.setup.play.take_arrivals() {
            self.graph.arrival(now);
        }
        let stats = self.setup.play.net_stats();
        if let Some(stats) = &stats {
            self.graph.rtt(now, stats.rtt_ms);
        }
        stats
    }

    /// Tells the session's failure, once, when it happens.
    fn check_failure(&mut self) {
        if self.failed.is_none() {
            if let Some((code, message)) = session_failure(&self.setup, self.started.elapsed()) {
                fail(code, &message);
                self.failed = Some(message);
            }
        }
    }

    /// What to draw (players posed, entities), and the camera following us.
    fn compose(&mut self, dt: Duration) -> Scene {
        let level_px = scene::level_extent(self.setup.play.level(), &self.art);
        let (frame_view, followed) = self.watched_view(dt);
        let (local, remotes) = play::sprites(&frame_view, &mut self.animator, dt.as_secs_f32());
        let entities: Vec<EntitySprite> =
            frame_view.entities.iter().map(EntitySprite::from).collect();
        let me = match (&self.spectate, followed) {
            (Some(_), Some(id)) => self.setup.play.game().and_then(|g| g.game().player(id)),
            (Some(_), None) => None,
            (None, _) => self.setup.play.me(),
        };
        let ghosts = if self.show_ghosts {
            ghost::place(
                self.setup.play.ghosts(),
                me.as_ref(),
                self.setup.play.tick_rate(),
            )
        } else {
            Vec::new()
        };
        let shown = local.as_ref().or(remotes.first()).map(|p| p.pos);
        let focus = match (self.setup.look_at, &mut self.spectate) {
            (Some(at), _) => at,
            (None, Some(watch)) => watch.focus(local.as_ref().map(|p| p.pos), level_px),
            (None, None) => shown.unwrap_or_else(|| level_px.center()),
        };
        let screen = vec2(screen_width(), screen_height());
        // The level's player scale (it may change with the level).
        let scale = self.setup.play.level().player.scale as f32 / 256.0;
        self.camera.set_scale(scale);
        let view = self
            .camera
            .update(focus, level_px, screen, dt.as_secs_f32());
        // Remote players wear their names (from the server's roster).
        let labels: Vec<String> = remotes
            .iter()
            .map(|p| {
                p.name
                    .clone()
                    .unwrap_or_else(|| format!("player #{}", p.id))
            })
            .collect();
        Scene {
            level_px,
            frame_view,
            local,
            remotes,
            labels,
            entities,
            followed,
            ghosts,
            me,
            view,
        }
    }

    /// What to draw, and spectating whom the camera follows (its keys
    /// read first): that player is drawn as the featured one.
    fn watched_view(&mut self, dt: Duration) -> (FrameView, Option<PlayerId>) {
        let view = self.setup.play.view().unwrap_or_default();
        let Some(watch) = &mut self.spectate else {
            return (view, None);
        };
        let players = self.setup.play.players();
        if let Some(g) = self.setup.play.game() {
            watch.keys(&players, g.player_names(), dt.as_secs_f32());
        }
        let followed = watch.followed(&players);
        (spectate::feature(view, followed), followed)
    }

    /// Moves the effects on (ours from the cues, the others' from what is drawn); shakes the view.
    fn animate_effects(&mut self, cued: &[Effect], scene: &mut Scene, dt: Duration) {
        self.effects.local(
            cued,
            scene.local.as_ref().map(|p| fx::At {
                pos: p.pos,
                size: p.size,
                tint: render::player_color(p.id, true),
            }),
        );
        self.effects.watch(
            &scene
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
                .collect::<Vec<_>>(),
        );
        let map = &self.setup.play.level().tilemap;
        self.effects.update(dt.as_secs_f32(), |p| {
            let units = (p * UNITS_PER_PX as f32).clamp(Vec2::splat(-1e9), Vec2::splat(1e9));
            map.is_solid_at(IVec2::new(units.x as i32, units.y as i32))
        });
        // The shake moves the world, not the HUD.
        scene.view = camera::View {
            offset: scene.view.offset + self.effects.shake(),
            ..scene.view
        };
    }

    /// Draws the world: sky, art, tiles, entities, players, effects, debug overlay.
    fn draw_world(&self, scene: &Scene, now: f64) {
        let debug = self
            .show_debug
            .then(|| self.setup.play.game())
            .flatten()
            .map(|g| g.game().world());
        scene::draw(scene::WorldFrame {
            level: self.setup.play.level(),
            art: &self.art,
            view: &scene.view,
            entities: &scene.entities,
            ghosts: &scene.ghosts,
            checkpoint: scene.me.as_ref().and_then(|m| m.checkpoint),
            local: scene.local.as_ref().zip(self.local_label(scene)),
            remotes: scene
                .remotes
                .iter()
                .zip(scene.labels.iter().map(String::as_str))
                .collect(),
            effects: &self.effects,
            debug,
            time: now as f32,
        });
    }

    /// The collision overlay over the world, when shown (remade for each
    /// level: at joining and at each level change).
    fn draw_collision(&mut self, scene: &Scene) {
        let key = self.level_changes * 2 + u64::from(self.setup.play.joined());
        let level = self.setup.play.level();
        self.collision
            .draw(level, key, &scene.view, &scene.entities);
    }

    /// Our player's label: its name from the roster, else ours.
    fn local_label<'a>(&'a self, scene: &'a Scene) -> Option<&'a str> {
        scene
            .local
            .as_ref()
            .map(|p| p.name.as_deref().unwrap_or(&self.setup.name))
    }

    /// Draws a failure over the scene; our run, name, the room's results and the results card for the HUD.
    fn hud_info(&self, scene: &Scene, now: f64) -> Hud {
        // A failure covers the scene; the HUD's figures mean nothing then.
        let failure = self.failed.as_deref().map(hud::failure);
        let run = scene.me.as_ref().map(|m| hud::RunInfo {
            coins: m.coins,
            coins_total: coins_total(self.setup.play.level()),
            deaths: m.deaths,
            run_ticks: m.run_ticks,
            tick_rate: self.setup.play.tick_rate(),
            place: m.place,
        });
        let name = scene
            .local
            .as_ref()
            .and_then(|p| p.name.as_deref())
            .unwrap_or(&self.setup.name)
            .to_owned();
        let results = self.room_results(&name);
        // Once finished: the card, with the records online (not a
        // spectator's: it is nobody's run of ours).
        let mine = run.filter(|_| self.spectate.is_none());
        let card = mine.filter(|r| r.place.is_some()).map(|run| {
            card::Card::new(
                &run,
                &self.restart_key,
                self.setup.play.records(),
                &name,
                vec2(screen_width(), screen_height()),
                hud::measure,
            )
        });
        let shown = if self.show_hud {
            self.chat.shown(now)
        } else {
            Vec::new()
        };
        let chat = chat_view::layout(
            &shown,
            self.chat.line(),
            vec2(screen_width(), screen_height()),
            |t| hud::measure(t, chat_view::SIZE),
        );
        let rate = self.setup.play.tick_rate();
        let split = self.splits.shown(now).map(|s| (s.clone(), s.text(rate)));
        let spectate = self.spectate.as_ref().map(|_| {
            let room = self.setup.play.room().unwrap_or("the room");
            let following = scene.followed.map(|_| name.as_str());
            spectate::line(room, following)
        });
        let list = self.setup.play.levels();
        let next_in = self.setup.play.next_level_in();
        Hud {
            levels: list
                .filter(|_| self.show_levels)
                .map(|l| levels::view(l, next_in)),
            next_level: list.and_then(|l| levels::next_line(l, next_in)),
            downloading: self.setup.play.downloading(),
            failure,
            run,
            name,
            results,
            card,
            chat,
            split,
            spectate,
        }
    }

    /// The room's results table: everyone in the game who finished, names
    /// from the roster (ours: `name`).
    fn room_results(&self, name: &str) -> Vec<hud::ResultRow> {
        self.setup.play.game().map_or_else(Vec::new, |g| {
            g.game()
                .results()
                .iter()
                .map(|r| hud::ResultRow {
                    place: r.place.unwrap_or(0),
                    name: if r.id == g.me() {
                        name.to_owned()
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
        })
    }

    /// "sound off: why", for the first seconds after the start.
    fn sound_notice(&self, now: f64) -> Option<&str> {
        sound_notice(self.sound_off.as_deref(), now)
    }

    /// Draws the HUD (unless a failure covers the scene) and the status banner.
    fn draw_hud(&self, scene: &Scene, hud: &Hud, stats: Option<&NetStats>, now: f64) {
        if self.show_hud && hud.failure.is_none() {
            let status = self.setup.play.status_line();
            let info = hud::HudInfo {
                status: &status,
                net: stats,
                fps: get_fps(),
                tick: scene.frame_view.tick,
                name: &hud.name,
                run: hud.run,
                show_net: self.show_net,
                hint_alpha: if self.spectate.is_some() {
                    0.0
                } else {
                    hint_alpha(self.first_move, now)
                },
                sound_notice: self.sound_notice(now),
                muted: self.audio.is_muted(),
                restart_key: &self.restart_key,
                results: &hud.results,
                split: hud.split.as_ref().map(|(s, t)| (t.as_str(), s.faster())),
                spectate: hud.spectate.as_deref(),
                next_level: hud.next_level.as_deref(),
                // Only where there is a choice: a server of one level
                // sends its list too.
                levels_key: self
                    .setup
                    .play
                    .levels()
                    .filter(|l| l.levels.len() > 1)
                    .map(|_| self.levels_key.as_str()),
            };
            hud::draw(&info, &self.graph, now);
            if let Some(card) = &hud.card {
                card::draw(card);
            }
        }
        if hud.failure.is_none() {
            if let Some(view) = &hud.levels {
                levels::draw(view);
            }
            if let Some((what, got, total)) = hud.downloading {
                levels::progress(&levels::progress_text(what, got, total), got, total);
            }
            chat_view::draw(&hud.chat);
        }
        if let (None, Some(text)) = (&hud.failure, self.setup.play.banner()) {
            hud::banner(&text);
        }
    }

    /// Publishes what the frame showed to the page (`window.ledgeState`).
    #[cfg(target_arch = "wasm32")]
    fn report_to_page(&self, scene: &Scene) {
        use crate::page;
        let view = &scene.view;
        page::report(&page::Report {
            played: self.played,
            status: &self.setup.play.status_line(),
            failure: self.failed.as_deref(),
            joined: self.setup.play.joined(),
            me: scene.me.as_ref().map(|m| m.pos),
            players: scene
                .local
                .iter()
                .map(|p| (p, true, self.local_label(scene).unwrap_or(&self.setup.name)))
                .chain(
                    scene
                        .remotes
                        .iter()
                        .zip(&scene.labels)
                        .map(|(p, l)| (p, false, l.as_str())),
                )
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
                .collect(),
            spectating: self.setup.play.spectating(),
            level: self.setup.play.level_id(),
        });
    }

    /// Whether the run is over (a failure shown a few frames, or the ticks played); the screenshot then.
    fn finished(&mut self, scene: &Scene, hud: &Hud, now: f64) -> bool {
        if hud.failure.is_some() {
            self.failed_frames += 1;
        }
        let done = match hud.failure {
            Some(_) => self.setup.exit_after.is_some() && self.failed_frames >= FAILURE_FRAMES,
            None => self.setup.exit_after.is_some_and(|n| self.played >= n),
        };
        if done {
            if let Some(path) = &self.setup.screenshot {
                self.save_screenshot(path, scene, hud, now);
            }
        }
        done
    }

    /// Saves the frame as `path` and its description beside it (`--screenshot`).
    fn save_screenshot(&self, path: &Path, scene: &Scene, hud: &Hud, now: f64) {
        let level = self.setup.play.level();
        let shot = shot::Shot {
            tick: self.played,
            view: &scene.view,
            level_px: scene.level_px,
            tile_px: level.tilemap.tile_size() / UNITS_PER_PX,
            server: self.setup.play.server_me(),
            drawn: scene.local.as_ref().map(|p| p.pos),
            remotes: shot::remotes(&scene.remotes, &scene.labels),
            hud: (self.show_hud && hud.failure.is_none()).then(|| shot::HudShot {
                name: &hud.name,
                run: hud.run,
                net_panel: self.show_net,
                muted: self.audio.is_muted(),
                sound_notice: self.sound_notice(now),
                results: &hud.results,
                card: hud.card.as_ref(),
            }),
            failure: self.failed.as_deref().zip(hud.failure.as_ref()),
            chat: hud.failure.is_none().then_some(shot::ChatShot {
                view: &hud.chat,
                muted: self.chat.muted().collect(),
            }),
            fx: shot::FxShot {
                particles: self.effects.particles().len(),
                shake: self.effects.shake().length(),
                flash: self.effects.flash().a,
                recent: self.effects.recent(),
                dead: scene.me.as_ref().is_some_and(|m| m.dead.is_some()),
            },
            replay: None,
            ghosts: &scene.ghosts,
            ghosts_shown: self.show_ghosts,
            split: hud.split.as_ref().map(|(s, t)| (s, t.clone())),
            spectate: self.spectate_shot(scene, hud),
            levels: self.setup.play.levels().map(|list| shot::LevelsShot {
                list,
                panel: hud.levels.as_ref(),
                next_line: hud.next_level.as_deref().filter(|_| self.show_hud),
                level_changes: self.level_changes,
            }),
            downloading: hud.downloading.filter(|_| hud.failure.is_none()),
        };
        if let Err(e) = shot::save(path, &shot) {
            fail(EXIT_FAILED, &format!("cannot save the screenshot: {e}"));
        }
    }

    /// What a spectator's screenshot says it watched.
    fn spectate_shot<'a>(
        &'a self,
        scene: &'a Scene,
        hud: &'a Hud,
    ) -> Option<shot::SpectateShot<'a>> {
        let watch = self.spectate.as_ref()?;
        let following = scene
            .followed
            .zip(scene.local.as_ref())
            .map(|(id, p)| (id.0, hud.name.as_str(), p.pos));
        Some(shot::SpectateShot {
            room: self.setup.play.room().unwrap_or(""),
            line: hud.spectate.as_deref().unwrap_or(""),
            free_camera: watch.follow() == ledge_client::follow::Follow::Free,
            following,
            render_tick: scene.frame_view.remote_tick,
            server: scene
                .followed
                .and_then(|id| self.setup.play.server_player(id)),
        })
    }

    /// Leaves the server (if connected) before the window closes, then stops the in-process server, if any.
    fn leave(self) {
        let GameLoop { setup, .. } = self;
        #[cfg(not(target_arch = "wasm32"))]
        let Setup { play, server, .. } = setup;
        #[cfg(target_arch = "wasm32")]
        let Setup { play, .. } = setup;
        drop(play);
        #[cfg(not(target_arch = "wasm32"))]
        drop(server);
    }
}
