//! Interpolation of remote players: drawn between two snapshots a little in
//! the past, through a playout buffer that adapts to jitter.
//!
//! The [`Interpolator`] keeps the last snapshots' remote players and a
//! *render tick*, a fractional server tick that advances with local time at
//! the tick rate, scaled by a small adjustment (at most
//! [`MAX_RENDER_ADJUST`]) that keeps it `delay` ticks behind the newest
//! snapshot as it would be by now (the newest tick plus the time since it
//! arrived). `delay` is one snapshot interval plus half a tick plus
//! [`JITTER_DELAY`] times the measured arrival jitter: with regular arrivals
//! the next snapshot is always there before it is needed; with jitter the
//! buffer deepens. The render tick does not go backwards (but see below):
//! when the buffer runs dry it holds the newest state (an *underrun*,
//! counted), and when it falls far behind (a stall) it jumps forward.
//!
//! A quiet server (nothing changed for us, [`Interpolator::skipped`]) sends
//! snapshots a few times a second instead of every interval: the state held
//! between them, and while the newest two frames agree the render tick
//! goes on past the newest at its pace (extrapolating it, not an
//! underrun), so the first motion after a quiet stretch plays at the usual
//! delay. Should it run past the next snapshot too (the server stalled), it
//! goes back to the usual delay behind that one, no further back than the
//! newest it had (a standing player does not move; one extrapolated steps
//! back to where the server says it was).
//!
//! Why interpolation rather than predicting remote players with their last
//! input: the server does not send other players' inputs (only states), so
//! "their last input" would have to be guessed from velocities; a guess
//! turns every change of direction and every jump into a visible snap back,
//! and remote players do not interact with ours (no player collisions), so
//! showing them 50 ms late costs nothing in play. See `docs/CLIENT.md`.

use crate::time::Instant;
use std::collections::VecDeque;

use glam::Vec2;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::protocol::{extrapolate, extrapolates_to, EntityState};

use crate::view::px2;

/// Extra delay per tick of jitter.
pub const JITTER_DELAY: f64 = 2.5;
/// Most delay, ticks.
pub const MAX_DELAY: f64 = 30.0;
/// Render speed adjustment per tick of delay error.
const RENDER_GAIN: f64 = 0.05;
/// Largest render speed adjustment (10%).
pub const MAX_RENDER_ADJUST: f64 = 0.1;
/// Behind by this many ticks more than the delay: jump forward.
const RESYNC: f64 = 30.0;
/// Snapshots kept.
const KEPT: usize = 64;
/// A remote player moving more than this between two snapshots (pixels)
/// teleported (a respawn): not blended.
pub const TELEPORT_PX: i32 = 64;

/// One snapshot's remote entities.
#[derive(Debug, Clone)]
struct Frame {
    tick: u64,
    entities: Vec<EntityState>,
}

/// A remote entity at the render tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// The entity's id.
    pub id: u32,
    /// Its centre, pixels (blended).
    pub pos: Vec2,
    /// Its velocity, pixels per tick (blended).
    pub vel: Vec2,
    /// The state of the nearer of the two snapshots (flags, kind, aux).
    pub state: EntityState,
}

/// Counters of the interpolator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct InterpStats {
    /// Snapshots buffered.
    pub snapshots: u64,
    /// Frames where the render tick reached the newest snapshot and held.
    pub underruns: u64,
    /// Forward jumps after falling too far behind.
    pub resyncs: u64,
}

/// The playout buffer of remote players.
#[derive(Debug, Clone)]
pub struct Interpolator {
    rate: f64,
    interval: f64,
    frames: VecDeque<Frame>,
    newest_arrival: Option<Instant>,
    render: Option<f64>,
    at: Option<Instant>,
    jitter: f64,
    /// Snapshot intervals of extra delay for loss.
    loss_intervals: f64,
    adjust: f64,
    stats: InterpStats,
}

impl Interpolator {
    /// A buffer for snapshots every `interval` ticks at `tick_rate` Hz.
    pub fn new(tick_rate: u32, interval: u32) -> Interpolator {
        Interpolator {
            rate: f64::from(tick_rate.max(1)),
            interval: f64::from(interval.max(1)),
            frames: VecDeque::new(),
            newest_arrival: None,
            render: None,
            at: None,
            jitter: 0.0,
            loss_intervals: 0.0,
            adjust: 0.0,
            stats: InterpStats::default(),
        }
    }

    /// Sets the measured arrival jitter, ticks.
    pub fn set_jitter(&mut self, jitter_ticks: f64) {
        self.jitter = jitter_ticks.max(0.0);
    }

    /// Sets the measured snapshot loss (fraction): the buffer deepens by
    /// the snapshot intervals `k` such that `k + 1` snapshots in a row are
    /// lost with probability under 1% (10% loss: one interval, 30%:
    /// three), at most three.
    pub fn set_loss(&mut self, loss: f64) {
        self.loss_intervals = if loss <= 0.01 {
            0.0
        } else if loss >= 0.5 {
            3.0
        } else {
            ((0.01f64.ln() / loss.ln()).ceil() - 1.0).clamp(0.0, 3.0)
        };
    }

    /// The delay aimed for, ticks behind the newest snapshot.
    pub fn target_delay(&self) -> f64 {
        let base = self.interval * (1.0 + self.loss_intervals) + 0.5;
        (base + JITTER_DELAY * self.jitter).min(MAX_DELAY)
    }

    /// How far behind the newest snapshot (extrapolated to the last
    /// [`Interpolator::advance`]) the render tick is, ticks.
    pub fn delay(&self) -> f64 {
        match (self.render, self.at) {
            (Some(r), Some(at)) => self.expected_newest(at) - r,
            _ => self.target_delay(),
        }
    }

    /// The render tick (fractional server tick), once a snapshot arrived.
    pub fn render_tick(&self) -> Option<f64> {
        self.render
    }

    /// The render speed adjustment in force.
    pub fn adjust(&self) -> f64 {
        self.adjust
    }

    /// Counters.
    pub fn stats(&self) -> InterpStats {
        self.stats
    }

    /// Newest snapshot tick buffered.
    pub fn newest_tick(&self) -> Option<u64> {
        self.frames.back().map(|f| f.tick)
    }

    /// Buffers the remote `entities` of the snapshot of `tick`, which
    /// arrived at `now`. Older than the newest: ignored.
    pub fn push(&mut self, tick: u64, entities: Vec<EntityState>, now: Instant) {
        let before = match self.frames.back() {
            Some(f) if f.tick >= tick => return,
            f => f.map(|f| f.tick as f64),
        };
        self.frames.push_back(Frame { tick, entities });
        if let (Some(r), Some(before)) = (self.render, before) {
            if r > tick as f64 {
                // Extrapolated ([`Self::still`]) past even this snapshot (a
                // stalled server): back to the usual delay behind it, but
                // not before `before`, whose state it showed meanwhile.
                // Short of `tick`, the blend towards it carries on.
                let usual = tick as f64 - self.target_delay();
                self.render = Some(usual.min(r).max(before));
            }
        }
        self.newest_arrival = Some(now);
        self.stats.snapshots += 1;
        while self.frames.len() > KEPT {
            self.frames.pop_front();
        }
        if self.render.is_none() {
            self.render = Some((tick as f64 - self.target_delay()).max(0.0));
            self.at = Some(now);
        }
    }

    /// The server sent no snapshot between `previous` and `tick` because
    /// nothing but time changed: when `previous` is our newest frame, it
    /// goes on as it was (extrapolated) until one interval before `tick`,
    /// so that motion which starts at `tick` starts there instead of being
    /// spread over the whole gap. Call before [`Interpolator::push`] of
    /// `tick`.
    pub fn skipped(&mut self, previous: u64, tick: u64) {
        let until = tick.saturating_sub(self.interval as u64);
        let Some(last) = self.frames.back() else {
            return;
        };
        if last.tick != previous || until <= previous {
            return;
        }
        let held = Frame {
            tick: until,
            entities: last
                .entities
                .iter()
                .map(|e| extrapolate(e, until - previous))
                .collect(),
        };
        self.frames.push_back(held);
        while self.frames.len() > KEPT {
            self.frames.pop_front();
        }
    }

    /// Whether the newest frame is the one before it with nothing but time
    /// changed (players standing, or moving at a constant velocity): the
    /// render tick may pass the newest, extrapolating it, without waiting.
    fn still(&self) -> bool {
        let n = self.frames.len();
        if n < 2 {
            return false;
        }
        let (a, b) = (&self.frames[n - 2], &self.frames[n - 1]);
        extrapolates_to(&a.entities, &b.entities, b.tick - a.tick)
    }

    /// The newest tick as it would be at `now`, if snapshots kept coming.
    fn expected_newest(&self, now: Instant) -> f64 {
        match (self.frames.back(), self.newest_arrival) {
            (Some(f), Some(at)) => {
                f.tick as f64 + now.saturating_duration_since(at).as_secs_f64() * self.rate
            }
            _ => 0.0,
        }
    }

    /// Advances the render tick to `now` and returns it (never backwards).
    pub fn advance(&mut self, now: Instant) -> Option<f64> {
        let (Some(render), Some(at)) = (self.render, self.at) else {
            return None;
        };
        let newest = self.frames.back().map_or(0, |f| f.tick) as f64;
        let dt = now.saturating_duration_since(at).as_secs_f64();
        let behind = self.expected_newest(now) - render;
        let error = behind - self.target_delay();
        let mut r = render;
        // Far behind what is actually buffered (not merely expected: a
        // stall of the server is held, not skipped).
        if newest - render - self.target_delay() > RESYNC {
            r = r.max(self.expected_newest(now) - self.target_delay());
            self.stats.resyncs += 1;
            self.adjust = 0.0;
        } else {
            self.adjust = (error * RENDER_GAIN).clamp(-MAX_RENDER_ADJUST, MAX_RENDER_ADJUST);
            r += dt * self.rate * (1.0 + self.adjust);
        }
        if r > newest && !self.still() {
            if render < newest || dt > 0.0 {
                self.stats.underruns += 1;
            }
            r = newest.max(render);
        }
        self.render = Some(r);
        self.at = Some(now.max(at));
        // Keep one frame at or before the render tick.
        while self.frames.len() > 2 && self.frames[1].tick as f64 <= r {
            self.frames.pop_front();
        }
        Some(r)
    }

    /// The remote entities at the render tick: blended between the two
    /// snapshots around it (an entity in only the older one is held there;
    /// one only in the newer appears when the render tick reaches it).
    pub fn sample(&self) -> Vec<Sample> {
        let Some(r) = self.render else {
            return Vec::new();
        };
        let Some(i) = self.frames.iter().rposition(|f| f.tick as f64 <= r) else {
            // Before the first snapshot: show the first.
            return self.frames.front().map_or_else(Vec::new, hold);
        };
        let a = &self.frames[i];
        let Some(b) = self.frames.get(i + 1) else {
            let mut out = hold(a);
            if self.still() {
                // Past the newest: it goes on at its velocity.
                let ahead = (r - a.tick as f64) as f32;
                for s in &mut out {
                    s.pos += s.vel * ahead;
                }
            }
            return out;
        };
        let f = ((r - a.tick as f64) / (b.tick - a.tick) as f64).clamp(0.0, 1.0) as f32;
        let mut out = Vec::with_capacity(a.entities.len());
        for ea in &a.entities {
            let s = match b.entities.binary_search_by_key(&ea.id, |e| e.id) {
                Ok(j) => {
                    let eb = &b.entities[j];
                    let jump = (eb.pos - ea.pos).abs().max_element();
                    if jump > TELEPORT_PX * UNITS_PER_PX {
                        let e = if f < 0.5 { ea } else { eb };
                        Sample {
                            id: e.id,
                            pos: px2(e.pos),
                            vel: px2(e.vel),
                            state: *e,
                        }
                    } else {
                        Sample {
                            id: ea.id,
                            pos: px2(ea.pos).lerp(px2(eb.pos), f),
                            vel: px2(ea.vel).lerp(px2(eb.vel), f),
                            state: if f < 0.5 { *ea } else { *eb },
                        }
                    }
                }
                Err(_) => Sample {
                    id: ea.id,
                    pos: px2(ea.pos),
                    vel: px2(ea.vel),
                    state: *ea,
                },
            };
            out.push(s);
        }
        out
    }
}

fn hold(f: &Frame) -> Vec<Sample> {
    f.entities
        .iter()
        .map(|e| Sample {
            id: e.id,
            pos: px2(e.pos),
            vel: px2(e.vel),
            state: *e,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::IVec2;
    use std::time::Duration;

    fn player(id: u32, x_px: i32) -> EntityState {
        EntityState {
            id,
            kind: 1,
            pos: IVec2::new(x_px * UNITS_PER_PX, 0),
            vel: IVec2::ZERO,
            flags: 0,
            aux: 0,
        }
    }

    /// Player 7 running right at 3 px a tick, at tick `tick`.
    fn runner(tick: u64) -> EntityState {
        EntityState {
            vel: IVec2::new(3 * UNITS_PER_PX, 0),
            ..player(7, 3 * tick as i32)
        }
    }

    fn ms(t0: Instant, ms: f64) -> Instant {
        t0 + Duration::from_secs_f64(ms / 1000.0)
    }

    /// Feeds snapshots every 2 ticks at 60 Hz (x = tick px) with the given
    /// extra arrival delays (ms), sampling every millisecond; returns the
    /// render ticks and the sampled x of player 7.
    fn play(delays: &[f64], jitter: f64) -> (Interpolator, Vec<f64>, Vec<f32>) {
        let t0 = Instant::now();
        let mut it = Interpolator::new(60, 2);
        it.set_jitter(jitter);
        let mut arrivals: Vec<(f64, u64)> = delays
            .iter()
            .enumerate()
            .map(|(i, d)| (i as f64 * 2000.0 / 60.0 + d, 100 + 2 * i as u64))
            .collect();
        arrivals.sort_by(|a, b| a.0.total_cmp(&b.0));
        let end = arrivals.last().unwrap().0 as usize;
        let (mut renders, mut xs) = (Vec::new(), Vec::new());
        let mut next = 0;
        for t in 0..end {
            while next < arrivals.len() && arrivals[next].0 <= t as f64 {
                let tick = arrivals[next].1;
                it.push(tick, vec![player(7, tick as i32)], ms(t0, t as f64));
                next += 1;
            }
            if let Some(r) = it.advance(ms(t0, t as f64)) {
                renders.push(r);
                xs.push(it.sample()[0].pos.x);
            }
        }
        (it, renders, xs)
    }

    #[test]
    fn positions_are_blended_between_the_two_snapshots_around_the_render_tick() {
        let t0 = Instant::now();
        let mut it = Interpolator::new(60, 2);
        it.push(100, vec![player(1, 100), player(2, 0)], t0);
        it.push(102, vec![player(1, 110), player(3, 50)], t0);
        it.render = Some(101.5);
        let s = it.sample();
        assert_eq!(s.len(), 2, "player 3 appears only when reached: {s:?}");
        assert_eq!(s[0].id, 1);
        assert!((s[0].pos.x - 107.5).abs() < 1e-4, "{}", s[0].pos.x);
        assert_eq!(
            (s[1].id, s[1].pos.x),
            (2, 0.0),
            "player 2 held where it was"
        );
        // A teleport is not blended.
        it.push(104, vec![player(1, 500)], t0);
        it.render = Some(102.5);
        assert_eq!(it.sample()[0].pos.x, 110.0);
        it.render = Some(103.5);
        assert_eq!(it.sample()[0].pos.x, 500.0);
    }

    #[test]
    fn regular_snapshots_play_smoothly_without_underruns() {
        let (it, renders, xs) = play(&vec![10.0; 300], 0.0);
        assert!(renders.windows(2).all(|w| w[1] >= w[0]), "never backwards");
        assert!(xs.windows(2).all(|w| w[1] >= w[0]));
        // After settling: no hold, and the delay is the target.
        let settled = &renders[2000..];
        let steps: Vec<f64> = settled.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(steps.iter().all(|&d| d > 0.0), "never held once settled");
        assert!(
            (it.delay() - it.target_delay()).abs() < 1.0,
            "{}",
            it.delay()
        );
        assert!(it.stats().underruns < 5, "{:?}", it.stats());
    }

    #[test]
    fn the_buffer_deepens_with_jitter_and_rarely_runs_dry() {
        let mut rng = 99u64;
        let delays: Vec<f64> = (0..600)
            .map(|_| {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                (rng % 40) as f64 // 0..40 ms: about 1.2 ticks of jitter
            })
            .collect();
        // Without accounting for jitter, the buffer runs dry often.
        let (dry, ..) = play(&delays, 0.0);
        let (deep, renders, _) = play(&delays, 1.2);
        assert!(deep.target_delay() > dry.target_delay() + 2.0);
        assert!(renders.windows(2).all(|w| w[1] >= w[0]), "never backwards");
        assert!(
            deep.stats().underruns * 4 < dry.stats().underruns.max(4),
            "with jitter {:?}, without {:?}",
            deep.stats(),
            dry.stats()
        );
    }

    #[test]
    fn a_stall_holds_then_catches_up_forward() {
        let t0 = Instant::now();
        let mut it = Interpolator::new(60, 2);
        it.push(100, vec![player(1, 0)], t0);
        it.push(102, vec![player(1, 2)], ms(t0, 33.0));
        let r1 = it.advance(ms(t0, 500.0)).unwrap();
        assert_eq!(r1, 102.0, "held at the newest");
        assert!(it.stats().underruns >= 1);
        // Snapshots resume 2 s later, far ahead.
        it.push(220, vec![player(1, 10)], ms(t0, 2000.0));
        let r2 = it.advance(ms(t0, 2001.0)).unwrap();
        assert!(r2 > 200.0 && r2 <= 220.0, "{r2}");
        assert_eq!(it.stats().resyncs, 1);
    }

    #[test]
    fn a_quiet_stretch_holds_still_and_the_next_motion_plays_at_the_usual_delay() {
        let t0 = Instant::now();
        let mut it = Interpolator::new(60, 2);
        let at_tick = |tick: u64| ms(t0, tick as f64 * 1000.0 / 60.0 + 10.0);
        // Snapshots every 2 ticks up to 40, then quiet (one every 12 ticks,
        // each naming the one before), then the player runs: x = 50 px
        // until tick 98, then 4 px a tick; the first snapshot that shows
        // it (100) names the last quiet one (88).
        let mut sent: Vec<(u64, Option<u64>)> = (0..=20).map(|i| (2 * i, None)).collect();
        for t in (52..=88).step_by(12).chain([100]) {
            let before = sent.last().unwrap().0;
            sent.push((t, Some(before)));
        }
        for t in (102..=160).step_by(2) {
            sent.push((t, Some(t - 2)));
        }
        let x = |tick: u64| 50 + 4 * tick.saturating_sub(98) as i32;
        let mut next = 0;
        let mut delays = Vec::new();
        let mut underruns = 0;
        for f in 0..170 * 16 {
            // Frames every ~1 ms of a 60 Hz tick's 16.7 ms.
            let now = ms(t0, f as f64 * 1000.0 / 60.0 / 16.0);
            while next < sent.len() && at_tick(sent[next].0) <= now {
                let (tick, previous) = sent[next];
                if let Some(p) = previous {
                    it.skipped(p, tick);
                }
                it.push(tick, vec![player(7, x(tick))], at_tick(tick));
                next += 1;
            }
            let before = it.stats().underruns;
            let Some(r) = it.advance(now) else { continue };
            // From the first frames' warm-up to the end of the stream.
            if (10.0..155.0).contains(&r) {
                underruns += it.stats().underruns - before;
            }
            let drawn = it.sample()[0].pos.x;
            // Never ahead of the truth at the render tick: still until 98.
            let truth = 50.0 + 4.0 * (r - 98.0).max(0.0) as f32;
            assert!(
                (drawn - truth).abs() <= 1.0 + 1e-3,
                "render tick {r:.2}: drawn {drawn}, truth {truth}"
            );
            if (120.0..150.0).contains(&r) {
                delays.push(it.delay());
            }
        }
        assert_eq!(underruns, 0, "holding still is no underrun");
        let mean = delays.iter().sum::<f64>() / delays.len() as f64;
        assert!(
            (mean - it.target_delay()).abs() < 1.0,
            "walking after the quiet stretch: delay {mean:.2}, target {:.2}",
            it.target_delay()
        );
    }

    #[test]
    fn after_a_stall_of_a_still_world_the_render_tick_comes_back_at_once() {
        let t0 = Instant::now();
        let mut it = Interpolator::new(60, 2);
        // Snapshots every 2 ticks of a still player up to tick 40, then the
        // server stalls for 2 s and resumes at tick 42 with the player
        // moving 2 px a tick.
        let arrival = |tick: u64| {
            let stall = if tick > 40 { 2000.0 } else { 0.0 };
            ms(t0, tick as f64 * 1000.0 / 60.0 + stall)
        };
        let x = |tick: u64| 50 + 2 * tick.saturating_sub(40) as i32;
        let mut ticks = (0..=80u64).step_by(2).peekable();
        let mut late = Vec::new();
        for f in 0..400 {
            let now = ms(t0, f as f64 * 1000.0 / 60.0);
            while let Some(&t) = ticks.peek().filter(|&&t| arrival(t) <= now) {
                it.push(t, vec![player(7, x(t))], arrival(t));
                ticks.next();
            }
            it.advance(now);
            // Half a second after it resumed.
            if (arrival(72)..arrival(80)).contains(&now) {
                late.push(it.delay() - it.target_delay());
            }
        }
        assert!(!late.is_empty());
        for d in late {
            assert!(d.abs() < 1.5, "off the target delay by {d:.2} ticks");
        }
    }

    #[test]
    fn past_the_newest_a_steady_runner_runs_on_and_a_skip_extrapolates() {
        let t0 = Instant::now();
        let mut it = Interpolator::new(60, 2);
        let at_tick = |tick: f64| ms(t0, tick * 1000.0 / 60.0);
        it.push(0, vec![runner(0)], at_tick(0.0));
        it.push(2, vec![runner(2)], at_tick(2.0));
        // Ten ticks later nothing new came: it runs on, no underrun.
        let r = it.advance(at_tick(12.0)).unwrap();
        assert!(r > 2.0, "{r}");
        let x = it.sample()[0].pos.x;
        assert!((x - 3.0 * r as f32).abs() < 1e-3, "{x} at {r}");
        assert_eq!(it.stats().underruns, 0);
        // The server skipped 4..12 and sends 14 (it stopped at 13): the
        // frame held at 12 is the runner carried on to 12.
        it.skipped(2, 14);
        let stopped = player(7, 39);
        it.push(14, vec![stopped], at_tick(14.0));
        assert_eq!(it.frames[it.frames.len() - 2].entities[0], runner(12));
    }

    #[test]
    fn a_late_snapshot_of_a_steady_runner_does_not_step_it_back() {
        let t0 = Instant::now();
        let mut it = Interpolator::new(60, 2);
        let at_tick = |tick: f64| ms(t0, tick * 1000.0 / 60.0);
        // On time up to 20, every quarter tick drawn; snapshot 22 is late.
        for q in 0..=(23 * 4 + 1) {
            let now = q as f64 / 4.0;
            if q % 8 == 0 && q <= 80 {
                let tick = q as u64 / 4;
                it.push(tick, vec![runner(tick)], at_tick(now));
            }
            it.advance(at_tick(now));
        }
        let r = it.render_tick().unwrap();
        assert!(r > 20.0 && r < 22.0, "extrapolating past 20: {r}");
        let x = it.sample()[0].pos.x;
        it.push(22, vec![runner(22)], at_tick(23.3));
        it.advance(at_tick(23.35));
        let after = it.sample()[0].pos.x;
        assert!(after >= x, "stepped back from {x} to {after} px");
    }
}
