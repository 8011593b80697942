//! Visual effects: particles, screen shake and flashes for what happens in
//! the game (a death's pop, a respawn's shimmer, a coin's sparkle, a
//! checkpoint, a stomp, a springboard, the goal's confetti, dust on jumps
//! and landings).
//!
//! Effects are cosmetic and frame-driven: they never touch the simulation
//! and are not part of its state. Our player's effects come from the same
//! [`Effect`] cues the sound plays ([`crate::sound::cues::Cues`], so a
//! rollback never replays one); the other players' deaths, respawns and
//! finishes from what their drawn state says frame to frame
//! ([`Fx::watch`]). Ours shake the screen and flash it; theirs do not.
//!
//! Everything here but [`Fx::draw`] is plain arithmetic, tested below:
//! time advances only by the `dt` given to [`Fx::update`], and the
//! particles' scatter comes from a seeded generator, so the same calls
//! give the same effects.

use std::collections::BTreeMap;

use crate::sound::audio::Effect;
use ledge_client::rng::SplitMix64;
use macroquad::prelude::*;

use crate::draw::camera::View;
use crate::draw::render::palette;

/// Particles alive at most: a burst past it replaces the oldest.
pub const MAX_PARTICLES: usize = 768;

/// Largest screen shake, screen pixels (at full trauma).
pub const MAX_SHAKE_PX: f32 = 7.0;

/// Trauma (0..=1) lost per second: a full shake is gone in 0.6 s.
const TRAUMA_DECAY: f32 = 1.7;

/// A flash's opacity lost per second.
const FLASH_DECAY: f32 = 1.6;

/// How a particle looks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A filled square `size` world px wide.
    Square,
    /// A filled circle of radius `size`.
    Dot,
    /// A ring growing from radius `size` to `size * 6` over its life.
    Ring,
    /// A line `size` long along its velocity.
    Streak,
    /// A word rising and fading (e.g. `+1`), `size` px high on screen.
    Text(&'static str),
}

/// One particle, in world pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Particle {
    /// Centre, world px.
    pub pos: Vec2,
    /// Velocity, world px per second.
    pub vel: Vec2,
    /// Added to the velocity per second (px/s², down is +y).
    pub gravity: f32,
    /// Fraction of the velocity kept per second (1: no drag).
    pub drag: f32,
    /// Seconds lived.
    pub age: f32,
    /// Seconds it lives.
    pub life: f32,
    /// Size, world px (see [`Shape`]).
    pub size: f32,
    /// Its colour (its opacity fades to 0 over the last half of its life).
    pub color: Color,
    /// How it looks.
    pub shape: Shape,
}

impl Particle {
    /// Opacity now: full for the first half of its life, then fading.
    pub fn alpha(&self) -> f32 {
        let t = (self.age / self.life).clamp(0.0, 1.0);
        self.color.a * (1.0 - ((t - 0.5) * 2.0).max(0.0))
    }
}

/// Where an effect happens: the player's box (world px, centre and full
/// size) and the colour it is drawn in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct At {
    /// Centre of the player's box.
    pub pos: Vec2,
    /// Full size of the box.
    pub size: Vec2,
    /// The player's colour.
    pub tint: Color,
}

impl At {
    fn feet(&self) -> Vec2 {
        self.pos + vec2(0.0, self.size.y * 0.5)
    }
}

/// What [`Fx::watch`] remembers of another player.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Seen {
    dead: bool,
    won: bool,
    /// The frame it was last seen in (players gone are forgotten).
    frame: u64,
}

/// What one player looked like this frame, for [`Fx::watch`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Watched {
    /// Its id.
    pub id: u32,
    /// Where it is and its colour.
    pub at: At,
    /// Dead, waiting to respawn.
    pub dead: bool,
    /// Finished its run.
    pub won: bool,
}

/// The effects on screen.
#[derive(Debug, Clone)]
pub struct Fx {
    particles: Vec<Particle>,
    rng: SplitMix64,
    /// 0..=1; the shake is its square times [`MAX_SHAKE_PX`].
    trauma: f32,
    /// A full-screen colour over the world, fading.
    flash: Color,
    /// Seconds since the start (the shake's wobble).
    time: f32,
    /// Where our player was last frame: a death with no respawn delay is
    /// told in the frame the body is already back at its checkpoint.
    last_local: Option<At>,
    others: BTreeMap<u32, Seen>,
    frame: u64,
    /// The effects started, newest last, at most 16 (for the screenshot's
    /// description).
    recent: Vec<Effect>,
}

impl Default for Fx {
    fn default() -> Fx {
        Fx::new(0x1ed9e)
    }
}

/// A burst's recipe: `count` particles from `from`, spread `spread` px
/// around it, flying at `speed` px/s within `angle` radians of `dir`
/// (radians, 0 is +x, -π/2 is up), each living `life` seconds.
#[derive(Debug, Clone, Copy)]
struct Burst {
    count: usize,
    spread: Vec2,
    dir: f32,
    angle: f32,
    speed: (f32, f32),
    life: (f32, f32),
    size: (f32, f32),
    gravity: f32,
    drag: f32,
    shape: Shape,
}

const UP: f32 = -std::f32::consts::FRAC_PI_2;
const ALL_AROUND: f32 = std::f32::consts::PI;

impl Burst {
    const fn new(count: usize, shape: Shape) -> Burst {
        Burst {
            count,
            spread: Vec2::ZERO,
            dir: UP,
            angle: ALL_AROUND,
            speed: (40.0, 120.0),
            life: (0.4, 0.7),
            size: (1.5, 2.5),
            gravity: 0.0,
            drag: 1.0,
            shape,
        }
    }
}

impl Fx {
    /// No effects; `seed` scatters the particles.
    pub fn new(seed: u64) -> Fx {
        Fx {
            particles: Vec::new(),
            rng: SplitMix64(seed),
            trauma: 0.0,
            flash: Color::new(0.0, 0.0, 0.0, 0.0),
            time: 0.0,
            last_local: None,
            others: BTreeMap::new(),
            frame: 0,
            recent: Vec::new(),
        }
    }

    /// The particles alive.
    pub fn particles(&self) -> &[Particle] {
        &self.particles
    }

    /// The screen's offset this frame (screen px), from the shake.
    pub fn shake(&self) -> Vec2 {
        let s = self.trauma * self.trauma * MAX_SHAKE_PX;
        let t = self.time;
        vec2(
            (t * 71.0).sin() * 0.7 + (t * 43.0 + 1.3).sin() * 0.3,
            (t * 59.0 + 2.1).sin() * 0.7 + (t * 37.0 + 0.4).sin() * 0.3,
        ) * s
    }

    /// The flash over the world this frame (transparent when none).
    pub fn flash(&self) -> Color {
        self.flash
    }

    /// The effects started lately, oldest first (at most 16).
    pub fn recent(&self) -> &[Effect] {
        &self.recent
    }

    /// Our player's cues of this frame, our player being at `at` (`None`:
    /// not in the game).
    pub fn local(&mut self, effects: &[Effect], at: Option<At>) {
        let Some(now) = at else {
            self.last_local = None;
            return;
        };
        for &effect in effects {
            // Died and already back at the checkpoint (no respawn delay):
            // the pop goes where the body was.
            let here = match (effect, self.last_local) {
                (Effect::Hurt, Some(before)) if effects.contains(&Effect::Respawn) => before,
                _ => now,
            };
            self.start(effect, here, true);
        }
        self.last_local = Some(now);
    }

    /// The other players as drawn this frame: a death pops, a respawn
    /// shimmers, a finish throws confetti (no shake, no flash). A player
    /// seen for the first time starts nothing.
    pub fn watch(&mut self, players: &[Watched]) {
        self.frame += 1;
        for p in players {
            let was = self.others.insert(
                p.id,
                Seen {
                    dead: p.dead,
                    won: p.won,
                    frame: self.frame,
                },
            );
            let Some(was) = was else { continue };
            if p.dead && !was.dead {
                self.start(Effect::Hurt, p.at, false);
            }
            if was.dead && !p.dead {
                self.start(Effect::Respawn, p.at, false);
            }
            if p.won && !was.won {
                self.start(Effect::Goal, p.at, false);
            }
        }
        let frame = self.frame;
        self.others.retain(|_, s| s.frame == frame);
    }

    /// Starts `effect` at `at`; `ours`: our player's (shakes and flashes).
    pub fn start(&mut self, effect: Effect, at: At, ours: bool) {
        if self.recent.len() == 16 {
            self.recent.remove(0);
        }
        self.recent.push(effect);
        let feet = at.feet();
        match effect {
            Effect::Hurt => self.hurt(at, ours),
            Effect::Respawn => self.respawn(at, ours),
            Effect::Coin => {
                self.burst(
                    at.pos,
                    &[palette::COIN, palette::COIN_LIGHT],
                    Burst {
                        speed: (40.0, 120.0),
                        life: (0.3, 0.5),
                        size: (1.0, 2.0),
                        drag: 0.1,
                        ..Burst::new(12, Shape::Dot)
                    },
                );
                self.text(at.pos - vec2(0.0, at.size.y), "+1", palette::COIN_LIGHT);
            }
            Effect::Checkpoint => {
                self.burst(
                    at.pos,
                    &[palette::FLAG_ACTIVE, WHITE],
                    Burst {
                        spread: vec2(6.0, 10.0),
                        angle: 0.5,
                        speed: (30.0, 80.0),
                        life: (0.6, 1.0),
                        size: (1.0, 2.0),
                        ..Burst::new(18, Shape::Dot)
                    },
                );
                self.ring(at.pos, 3.0, 0.45, palette::FLAG_ACTIVE);
                self.text(
                    at.pos - vec2(0.0, at.size.y * 1.5),
                    "checkpoint",
                    palette::FLAG_ACTIVE,
                );
            }
            Effect::Stomp => {
                self.dust(feet, 10, 1.5);
                self.burst(
                    feet + vec2(0.0, 3.0),
                    &[palette::WALKER],
                    Burst {
                        speed: (50.0, 120.0),
                        angle: 1.0,
                        life: (0.3, 0.5),
                        size: (1.5, 2.5),
                        gravity: 300.0,
                        ..Burst::new(8, Shape::Square)
                    },
                );
                if ours {
                    self.kick(0.3);
                }
            }
            Effect::Spring => {
                self.burst(
                    feet,
                    &[WHITE, palette::SPRING],
                    Burst {
                        spread: vec2(at.size.x * 0.5, 0.0),
                        dir: std::f32::consts::FRAC_PI_2,
                        angle: 0.3,
                        speed: (60.0, 140.0),
                        life: (0.2, 0.35),
                        size: (3.0, 6.0),
                        ..Burst::new(10, Shape::Streak)
                    },
                );
                self.ring(feet, 2.0, 0.25, WHITE);
                if ours {
                    self.kick(0.2);
                }
            }
            Effect::Goal => self.goal(at, ours),
            Effect::Land => self.dust(feet, 6, 1.0),
            Effect::Jump => self.dust(feet, 4, 0.7),
        }
    }

    /// A hurt player pops: bits of its colour, some white, a ring.
    fn hurt(&mut self, at: At, ours: bool) {
        self.burst(
            at.pos,
            &[at.tint],
            Burst {
                spread: at.size * 0.4,
                speed: (70.0, 190.0),
                life: (0.45, 0.8),
                size: (2.0, 3.5),
                gravity: 420.0,
                drag: 0.3,
                ..Burst::new(22, Shape::Square)
            },
        );
        self.burst(
            at.pos,
            &[WHITE],
            Burst {
                speed: (30.0, 110.0),
                life: (0.25, 0.45),
                size: (1.0, 1.8),
                drag: 0.2,
                ..Burst::new(10, Shape::Dot)
            },
        );
        self.ring(at.pos, 3.0, 0.3, WHITE);
        if ours {
            self.kick(0.6);
            self.flash_with(Color::new(0.85, 0.1, 0.12, 0.35));
        }
    }

    /// A respawn: a shimmer rising from the feet, and a ring.
    fn respawn(&mut self, at: At, ours: bool) {
        let feet = at.feet();
        self.burst(
            feet,
            &[WHITE, at.tint],
            Burst {
                spread: vec2(at.size.x * 0.7, 1.0),
                angle: 0.15,
                speed: (30.0, 90.0),
                life: (0.4, 0.7),
                size: (1.0, 2.0),
                ..Burst::new(16, Shape::Streak)
            },
        );
        self.ring(at.pos, 2.0, 0.35, at.tint);
        if ours {
            self.flash_with(Color::new(1.0, 1.0, 1.0, 0.12));
        }
    }

    /// The goal reached: confetti and a ring (more, a kick and a flash, for ours).
    fn goal(&mut self, at: At, ours: bool) {
        self.burst(
            at.pos,
            &palette::CONFETTI,
            Burst {
                angle: 1.1,
                speed: (90.0, 230.0),
                life: (1.0, 1.8),
                size: (1.5, 3.0),
                gravity: 260.0,
                drag: 0.35,
                ..Burst::new(if ours { 60 } else { 30 }, Shape::Square)
            },
        );
        self.ring(at.pos, 4.0, 0.5, palette::GOAL);
        if ours {
            self.kick(0.25);
            self.flash_with(Color::new(1.0, 0.85, 0.25, 0.25));
        }
    }

    /// Dust puffs at `feet`, thrown sideways.
    fn dust(&mut self, feet: Vec2, count: usize, strength: f32) {
        for side in [-1.0f32, 1.0] {
            self.burst(
                feet - vec2(0.0, 1.0),
                &[palette::DUST],
                Burst {
                    dir: if side < 0.0 {
                        std::f32::consts::PI + 0.25
                    } else {
                        -0.25
                    },
                    angle: 0.35,
                    speed: (25.0 * strength, 60.0 * strength),
                    life: (0.25, 0.4),
                    size: (1.5, 2.5),
                    drag: 0.05,
                    ..Burst::new(count / 2, Shape::Dot)
                },
            );
        }
    }

    fn ring(&mut self, at: Vec2, size: f32, life: f32, color: Color) {
        self.push(Particle {
            pos: at,
            vel: Vec2::ZERO,
            gravity: 0.0,
            drag: 1.0,
            age: 0.0,
            life,
            size,
            color,
            shape: Shape::Ring,
        });
    }

    fn text(&mut self, at: Vec2, text: &'static str, color: Color) {
        self.push(Particle {
            pos: at,
            vel: vec2(0.0, -28.0),
            gravity: 0.0,
            drag: 0.5,
            age: 0.0,
            life: 0.9,
            size: 16.0,
            color,
            shape: Shape::Text(text),
        });
    }

    fn random(&mut self, (lo, hi): (f32, f32)) -> f32 {
        lo + (hi - lo) * self.rng.next_f64() as f32
    }

    fn burst(&mut self, from: Vec2, colors: &[Color], b: Burst) {
        for i in 0..b.count {
            let a = b.dir + self.random((-b.angle, b.angle));
            let speed = self.random(b.speed);
            let offset = vec2(
                self.random((-b.spread.x, b.spread.x)),
                self.random((-b.spread.y, b.spread.y)),
            );
            let p = Particle {
                pos: from + offset,
                vel: vec2(a.cos(), a.sin()) * speed,
                gravity: b.gravity,
                drag: b.drag,
                age: 0.0,
                life: self.random(b.life),
                size: self.random(b.size),
                color: colors[i % colors.len().max(1)],
                shape: b.shape,
            };
            self.push(p);
        }
    }

    fn push(&mut self, p: Particle) {
        if self.particles.len() >= MAX_PARTICLES {
            // The oldest goes (particles are in birth order).
            self.particles.remove(0);
        }
        self.particles.push(p);
    }

    fn kick(&mut self, trauma: f32) {
        self.trauma = (self.trauma + trauma).min(1.0);
    }

    fn flash_with(&mut self, color: Color) {
        if color.a >= self.flash.a {
            self.flash = color;
        }
    }

    /// Advances everything by `dt` seconds (clamped to a tenth of a
    /// second: a stalled frame does not throw particles across the level).
    /// Falling pieces stop where `solid(world px)` says the ground is, and
    /// lie there while they fade.
    pub fn update(&mut self, dt: f32, solid: impl Fn(Vec2) -> bool) {
        let dt = dt.clamp(0.0, 0.1);
        self.time += dt;
        self.trauma = (self.trauma - TRAUMA_DECAY * dt).max(0.0);
        self.flash.a = (self.flash.a - FLASH_DECAY * dt).max(0.0);
        for p in &mut self.particles {
            p.age += dt;
            p.vel.y += p.gravity * dt;
            p.vel *= p.drag.powf(dt);
            let next = p.pos + p.vel * dt;
            if p.gravity > 0.0 && solid(next) {
                p.vel = Vec2::ZERO;
                p.gravity = 0.0;
            } else {
                p.pos = next;
            }
        }
        self.particles.retain(|p| p.age < p.life);
    }

    /// Draws the particles through `view` (the world's camera).
    pub fn draw(&self, view: &View) {
        let seen = view.visible();
        let margin = Rect::new(seen.x - 32.0, seen.y - 32.0, seen.w + 64.0, seen.h + 64.0);
        for p in &self.particles {
            if !margin.contains(p.pos) {
                continue;
            }
            let color = Color {
                a: p.alpha(),
                ..p.color
            };
            let s = view.to_screen(p.pos);
            let size = p.size * view.zoom;
            match p.shape {
                Shape::Square => {
                    draw_rectangle(s.x - size / 2.0, s.y - size / 2.0, size, size, color)
                }
                Shape::Dot => draw_circle(s.x, s.y, size, color),
                Shape::Ring => {
                    let t = (p.age / p.life).clamp(0.0, 1.0);
                    let r = size * (1.0 + 5.0 * (1.0 - (1.0 - t) * (1.0 - t)));
                    draw_circle_lines(s.x, s.y, r, view.zoom.max(1.0), color);
                }
                Shape::Streak => {
                    let tail = s - p.vel.normalize_or_zero() * size;
                    draw_line(s.x, s.y, tail.x, tail.y, view.zoom.max(1.0), color);
                }
                Shape::Text(text) => {
                    let dims = measure_text(text, None, p.size as u16, 1.0);
                    let x = (s.x - dims.width / 2.0).round();
                    draw_text(
                        text,
                        x + 1.0,
                        s.y.round() + 1.0,
                        p.size,
                        Color::new(0.0, 0.0, 0.0, color.a * 0.6),
                    );
                    draw_text(text, x, s.y.round(), p.size, color);
                }
            }
        }
    }

    /// Draws the flash over the whole screen (after the world, before the
    /// HUD).
    pub fn draw_flash(&self) {
        if self.flash.a > 0.0 {
            draw_rectangle(0.0, 0.0, screen_width(), screen_height(), self.flash);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: f32, y: f32) -> At {
        At {
            pos: vec2(x, y),
            size: vec2(12.0, 16.0),
            tint: palette::LOCAL_PLAYER,
        }
    }

    fn watched(id: u32, dead: bool, won: bool) -> Watched {
        Watched {
            id,
            at: at(10.0 * id as f32, 0.0),
            dead,
            won,
        }
    }

    #[test]
    fn a_death_pops_shakes_and_flashes_then_everything_fades() {
        let mut fx = Fx::default();
        fx.local(&[], Some(at(100.0, 50.0)));
        fx.local(&[Effect::Hurt], Some(at(100.0, 50.0)));
        let n = fx.particles().len();
        assert!(n >= 20, "{n} particles");
        // Bits of the player's colour, around the body.
        let ours = fx
            .particles()
            .iter()
            .filter(|p| p.color == palette::LOCAL_PLAYER)
            .count();
        assert!(ours >= 10, "{ours}");
        fx.update(1.0 / 60.0, |_| false);
        assert!(fx.shake().length() > 0.0);
        assert!(fx.flash().a > 0.2);
        // They fly apart.
        fx.update(0.1, |_| false);
        let far = fx
            .particles()
            .iter()
            .filter(|p| p.pos.distance(vec2(100.0, 50.0)) > 8.0)
            .count();
        assert!(far > n / 2, "{far} of {n}");
        for _ in 0..20 {
            fx.update(0.1, |_| false);
        }
        assert!(fx.particles().is_empty());
        assert_eq!(fx.shake(), Vec2::ZERO);
        assert_eq!(fx.flash().a, 0.0);
        assert_eq!(fx.recent(), [Effect::Hurt]);
    }

    #[test]
    fn falling_pieces_lie_on_the_ground() {
        let mut fx = Fx::default();
        fx.start(Effect::Hurt, at(100.0, 50.0), true);
        // Ground from y = 60 down.
        let ground = |p: Vec2| p.y >= 60.0;
        for _ in 0..30 {
            fx.update(1.0 / 60.0, ground);
        }
        let pieces: Vec<&Particle> = fx
            .particles()
            .iter()
            .filter(|p| p.shape == Shape::Square)
            .collect();
        assert!(!pieces.is_empty());
        assert!(pieces.iter().all(|p| p.pos.y < 60.0), "{pieces:?}");
        let resting = pieces.iter().filter(|p| p.vel == Vec2::ZERO).count();
        assert!(resting > pieces.len() / 2, "{resting} of {}", pieces.len());
    }

    #[test]
    fn each_effect_leaves_something_on_screen_and_only_ours_shake() {
        for effect in Effect::ALL {
            let mut fx = Fx::new(7);
            fx.start(effect, at(0.0, 0.0), false);
            assert!(!fx.particles().is_empty(), "{effect:?}");
            fx.update(0.01, |_| false);
            assert_eq!(fx.shake(), Vec2::ZERO, "{effect:?} is not ours");
            assert_eq!(fx.flash().a, 0.0, "{effect:?}");
        }
        let mut fx = Fx::new(7);
        fx.start(Effect::Goal, at(0.0, 0.0), true);
        fx.update(0.01, |_| false);
        assert!(fx.shake().length() > 0.0 && fx.flash().a > 0.0);
    }

    #[test]
    fn an_instant_respawn_pops_where_the_body_was() {
        let mut fx = Fx::default();
        fx.local(&[], Some(at(700.0, 400.0)));
        fx.local(&[Effect::Hurt, Effect::Respawn], Some(at(88.0, 416.0)));
        let player_bits: Vec<&Particle> = fx
            .particles()
            .iter()
            .filter(|p| p.shape == Shape::Square)
            .collect();
        assert!(!player_bits.is_empty());
        assert!(player_bits.iter().all(|p| (p.pos.x - 700.0).abs() < 10.0));
    }

    #[test]
    fn others_pop_respawn_and_finish_from_their_flags() {
        let mut fx = Fx::default();
        fx.watch(&[watched(2, false, false), watched(3, true, false)]);
        assert!(fx.particles().is_empty(), "first sight plays nothing");
        fx.watch(&[watched(2, true, false), watched(3, true, false)]);
        assert_eq!(fx.recent(), [Effect::Hurt]);
        fx.watch(&[watched(2, false, false), watched(3, false, true)]);
        assert_eq!(
            fx.recent(),
            [Effect::Hurt, Effect::Respawn, Effect::Respawn, Effect::Goal]
        );
        fx.update(0.01, |_| false);
        assert_eq!(fx.shake(), Vec2::ZERO);
        // Gone, then back: seen for the first time again.
        fx.watch(&[]);
        fx.watch(&[watched(2, true, false)]);
        assert_eq!(fx.recent().len(), 4);
    }

    #[test]
    fn particles_are_bounded_and_the_same_calls_give_the_same_effects() {
        let mut a = Fx::new(1);
        let mut b = Fx::new(1);
        for i in 0..200 {
            for fx in [&mut a, &mut b] {
                fx.start(Effect::Goal, at(i as f32, 0.0), true);
                fx.update(0.004, |_| false);
            }
        }
        assert_eq!(a.particles().len(), MAX_PARTICLES);
        assert_eq!(a.particles(), b.particles());
        assert_eq!(a.shake(), b.shake());
        // A stalled frame moves particles at most a tenth of a second's
        // worth.
        let before: Vec<Vec2> = a.particles().iter().map(|p| p.pos).collect();
        a.update(5.0, |_| false);
        for (p, q) in a.particles().iter().zip(&before) {
            assert!(p.pos.distance(*q) < 40.0, "{p:?} from {q}");
        }
    }
}
