//! Detection through the broad phase gives the same contacts, in the same
//! order, as brute force, whatever the pipeline (general or specialised) and
//! the thread count; so the state of any run does not depend on them.
//!
//! * every tick of busy scenes (every shape kind, triggers, one-way, layers,
//!   kinematic platforms with riders, a tilemap with slopes; a large box
//!   scene): contact buffer, events and state hash equal across brute force,
//!   strips (general and specialised) and 1, 2, 8 threads, an attached pool
//!   and the caller's pool;
//! * long scripted runs of the default level with 8 players and of a busy
//!   box scene: the same state hash for 1, 2 and 8 threads (and brute force
//!   for the level);
//! * content changes mid-run (static bodies moved, disabled, removed,
//!   colliders added) keep strips equal to brute force;
//! * the features the world finds in a scene, and the level's own report;
//! * the broad-phase pipeline (full and incremental detections, tiles, the
//!   sorted rider search) allocates nothing per tick in steady state.

use std::sync::Arc;

use glam::IVec2;
use ledge_levels::default_level;
use ledge_shared::fixed::px;
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use ledge_shared::scene::{scripted_inputs, warmup_room_with};
use ledge_shared::shape::{Aabb, Circle, ShapeKind};
use ledge_shared::world::{
    scenes, BodyDesc, BroadPhaseKind, ColliderDesc, ContactKind, Event, Pipeline, SimConfig, World,
};

/// A contact as the public API shows it.
type Seen = (u32, u32, u32, u32, IVec2, bool, Option<IVec2>);

fn seen(w: &World) -> Vec<Seen> {
    w.contacts()
        .iter()
        .map(|c| {
            (
                c.body_a().0,
                c.collider_a().0,
                c.body_b().0,
                c.collider_b().0,
                c.mtv(),
                c.kind() == ContactKind::Solid,
                c.tile(),
            )
        })
        .collect()
}

fn config(broad_phase: BroadPhaseKind, pipeline: Pipeline, threads: u32) -> SimConfig {
    SimConfig {
        broad_phase,
        pipeline,
        threads,
        ..SimConfig::default()
    }
}

/// Reference first: brute force, general pipeline, one thread.
fn variants() -> Vec<(&'static str, SimConfig)> {
    let strips = BroadPhaseKind::DEFAULT;
    vec![
        (
            "brute force",
            config(BroadPhaseKind::BruteForce, Pipeline::General, 1),
        ),
        ("strips, general", config(strips, Pipeline::General, 1)),
        (
            "strips, specialised",
            config(strips, Pipeline::Specialised, 1),
        ),
        ("2 threads", config(strips, Pipeline::Specialised, 2)),
        ("8 threads, general", config(strips, Pipeline::General, 8)),
        (
            "32 px strips, x2 levels, 2 threads",
            config(
                BroadPhaseKind::Strips {
                    strip_shift: 13,
                    level_shift: 1,
                },
                Pipeline::Specialised,
                2,
            ),
        ),
    ]
}

/// Steps every world in lock step with the same inputs and asserts that
/// contacts, events and hashes agree every tick.
fn lock_step(what: &str, mut worlds: Vec<(String, World)>, ticks: u64, min_busy: usize) {
    let slots = worlds[0].1.controllers().len();
    let mut inputs = vec![Buttons::NONE; slots];
    let mut busy = 0usize;
    for _ in 0..ticks {
        scenes::inputs(worlds[0].1.tick(), &mut inputs);
        let mut reference: Option<(Vec<Event>, Vec<Seen>, u64)> = None;
        for (name, w) in worlds.iter_mut() {
            let events = w.step(&inputs).to_vec();
            let got = (events, seen(w), w.state_hash());
            match &reference {
                None => {
                    busy += got.0.len() + got.1.len();
                    reference = Some(got);
                }
                Some(r) => {
                    let t = w.tick();
                    assert_eq!(got.1, r.1, "{what}: contacts of {name} at tick {t}");
                    assert_eq!(got.0, r.0, "{what}: events of {name} at tick {t}");
                    assert_eq!(got.2, r.2, "{what}: state of {name} at tick {t}");
                }
            }
        }
    }
    // Threaded worlds of large scenes really ran in parallel.
    for (name, w) in &worlds {
        let threaded = w.config().threads != 1
            && w.config().broad_phase != BroadPhaseKind::BruteForce
            && w.collider_count() > 3_000;
        assert!(
            !threaded || w.detection_stats().parallel > 0,
            "{what}: {name} never detected in parallel"
        );
    }
    // The specialised worlds re-detected incrementally at least sometimes
    // (unless the scene is small enough to skip the broad phase).
    let incremental: u64 = worlds
        .iter()
        .map(|(_, w)| w.detection_stats().incremental)
        .sum();
    assert!(
        incremental > 0 || worlds[0].1.collider_count() < 64,
        "{what}: no incremental re-detection"
    );
    assert!(
        busy >= min_busy,
        "{what}: the scene is busy ({busy} events and contacts in {ticks} ticks)"
    );
}

#[test]
fn every_tick_of_a_mixed_scene_is_the_same_in_every_mode() {
    let worlds = variants()
        .into_iter()
        .map(|(n, c)| (n.to_string(), scenes::mixed(400, 11, c).unwrap()))
        .collect();
    lock_step("mixed", worlds, 200, 1_000);
}

/// Small enough for the specialised pipeline's direct pair tests (no broad
/// phase), with every shape kind.
#[test]
fn every_tick_of_a_tiny_mixed_scene_is_the_same_in_every_mode() {
    let worlds: Vec<(String, World)> = variants()
        .into_iter()
        .map(|(n, c)| (n.to_string(), scenes::mixed(14, 3, c).unwrap()))
        .collect();
    lock_step("tiny mixed", worlds, 1_500, 300);
}

#[test]
fn every_tick_of_the_warmup_room_is_the_same_in_every_mode() {
    let worlds = variants()
        .into_iter()
        .map(|(n, c)| (n.to_string(), warmup_room_with(c).unwrap()))
        .collect();
    lock_step("warm-up room", worlds, 3_000, 150);
}

#[test]
fn every_tick_of_a_tile_room_is_the_same_in_every_mode() {
    let worlds = variants()
        .into_iter()
        .map(|(n, c)| (n.to_string(), scenes::tile_room(300, 5, c).unwrap()))
        .collect();
    lock_step("tile room", worlds, 200, 1_000);
}

/// Thousands of moving boxes: several parallel batches per update and
/// search, so the work really is split differently for each thread count.
#[test]
fn every_tick_of_a_large_box_scene_is_the_same_for_any_thread_count() {
    let strips = BroadPhaseKind::DEFAULT;
    let mut worlds = Vec::new();
    for (name, c) in [
        ("1 thread", config(strips, Pipeline::Specialised, 1)),
        ("general, 1 thread", config(strips, Pipeline::General, 1)),
        ("2 threads", config(strips, Pipeline::Specialised, 2)),
        ("8 threads", config(strips, Pipeline::Specialised, 8)),
        ("general, 8 threads", config(strips, Pipeline::General, 8)),
    ] {
        worlds.push((name.to_string(), scenes::boxes(5_000, 3, c).unwrap()));
    }
    // And the caller's pool: `threads: 0` inside `install`, through a
    // wrapper world stepped from a 3-thread pool.
    lock_step("5,000 boxes", worlds, 40, 10_000);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    let mut a = scenes::boxes(5_000, 3, SimConfig::default()).unwrap();
    let mut b = scenes::boxes(5_000, 3, config(strips, Pipeline::Specialised, 0)).unwrap();
    let mut c = scenes::boxes(5_000, 3, config(strips, Pipeline::Specialised, 2)).unwrap();
    c.set_thread_pool(Some(Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(5)
            .build()
            .unwrap(),
    )));
    let mut inputs = vec![Buttons::NONE; a.controllers().len()];
    for _ in 0..40 {
        scenes::inputs(a.tick(), &mut inputs);
        a.step(&inputs);
        pool.install(|| b.step(&inputs));
        c.step(&inputs);
        assert_eq!(seen(&b), seen(&a), "caller's pool, tick {}", a.tick());
        assert_eq!(seen(&c), seen(&a), "attached pool, tick {}", a.tick());
        assert_eq!(b.state_hash(), a.state_hash());
        assert_eq!(c.state_hash(), a.state_hash());
    }
}

/// Thousands of moving bodies of every shape kind: the general narrow-phase
/// dispatch split over threads.
#[test]
fn every_tick_of_a_large_mixed_scene_is_the_same_for_any_thread_count() {
    let strips = BroadPhaseKind::DEFAULT;
    let worlds = [
        ("1 thread", config(strips, Pipeline::Specialised, 1)),
        ("2 threads", config(strips, Pipeline::Specialised, 2)),
        ("8 threads", config(strips, Pipeline::Specialised, 8)),
        ("general, 8 threads", config(strips, Pipeline::General, 8)),
    ]
    .into_iter()
    .map(|(n, c)| (n.to_string(), scenes::mixed(4_000, 8, c).unwrap()))
    .collect();
    lock_step("4,000 mixed bodies", worlds, 60, 5_000);
}

/// The final hash of `ticks` scripted ticks of the default level with 8
/// players under `sim`.
fn default_level_run(sim: SimConfig, ticks: u64) -> (u64, u64) {
    let mut g = Game::with_config(
        &default_level(),
        GameConfig {
            sim,
            ..GameConfig::default()
        },
    )
    .unwrap();
    for id in 1..=8 {
        g.add_player(PlayerId(id)).unwrap();
    }
    let mut inputs = [(PlayerId(1), Buttons::NONE); 8];
    let mut events = 0u64;
    let mut trail = 0u64;
    for _ in 0..ticks {
        let t = g.tick();
        for (k, slot) in inputs.iter_mut().enumerate() {
            *slot = (PlayerId(k as u32 + 1), scripted_inputs(t + 555 * k as u64));
        }
        events += g.step(&inputs).len() as u64;
        events += g.world().events().len() as u64;
        trail = trail.rotate_left(7) ^ g.state_hash() ^ g.world().state_hash();
    }
    assert!(events > ticks, "the run is busy: {events} events");
    (g.state_hash(), trail)
}

#[test]
fn a_long_run_of_the_default_level_does_not_depend_on_threads() {
    let ticks = 5_000;
    let strips = BroadPhaseKind::DEFAULT;
    let reference = default_level_run(config(strips, Pipeline::Specialised, 1), ticks);
    for (name, sim) in [
        (
            "brute force",
            config(BroadPhaseKind::BruteForce, Pipeline::General, 1),
        ),
        ("general", config(strips, Pipeline::General, 1)),
        ("2 threads", config(strips, Pipeline::Specialised, 2)),
        ("8 threads", config(strips, Pipeline::Specialised, 8)),
    ] {
        assert_eq!(default_level_run(sim, ticks), reference, "{name}");
    }
}

/// The state hash after `ticks` ticks of the busy box scene.
fn box_run(n: usize, sim: SimConfig, ticks: u64) -> (u64, u64) {
    let mut w = scenes::boxes(n, 17, sim).unwrap();
    let mut inputs = vec![Buttons::NONE; w.controllers().len()];
    let mut trail = 0u64;
    let mut pushes = 0u64;
    for _ in 0..ticks {
        scenes::inputs(w.tick(), &mut inputs);
        pushes += w.step(&inputs).len() as u64;
        trail = trail.rotate_left(7) ^ w.state_hash();
    }
    assert!(pushes > ticks * 10, "the scene is busy: {pushes} events");
    (w.state_hash(), trail)
}

#[test]
fn a_long_run_of_a_busy_box_scene_does_not_depend_on_threads() {
    let (n, ticks) = (3_000, 400);
    let strips = BroadPhaseKind::DEFAULT;
    let reference = box_run(n, config(strips, Pipeline::Specialised, 1), ticks);
    for threads in [2, 8] {
        let sim = config(strips, Pipeline::Specialised, threads);
        assert_eq!(box_run(n, sim, ticks), reference, "{threads} threads");
    }
}

/// Static bodies moved, disabled and removed, colliders added and bodies
/// removed during a run: the broad phase's static set follows.
#[test]
fn content_changes_mid_run_keep_strips_equal_to_brute_force() {
    let strips = BroadPhaseKind::DEFAULT;
    let mut worlds: Vec<World> = [
        config(BroadPhaseKind::BruteForce, Pipeline::General, 1),
        config(strips, Pipeline::Specialised, 1),
        config(strips, Pipeline::General, 2),
    ]
    .into_iter()
    .map(|c| scenes::tile_room(120, 9, c).unwrap())
    .collect();
    let mut inputs = vec![Buttons::NONE; worlds[0].controllers().len()];
    let mut extra = Vec::new();
    for t in 0..600u64 {
        for (i, w) in worlds.iter_mut().enumerate() {
            match t {
                // A static wall appears in the middle of the room, then moves,
                // is disabled, comes back and goes.
                100 => {
                    let b = w
                        .add_body(BodyDesc::fixed(IVec2::new(px(200), px(200))))
                        .unwrap();
                    let shape = Aabb::new(IVec2::new(px(8), px(120))).unwrap();
                    w.add_collider(b, ColliderDesc::solid(shape)).unwrap();
                    if i == 0 {
                        extra.push(b);
                    }
                }
                200 => w
                    .set_position(extra[0], IVec2::new(px(320), px(240)))
                    .unwrap(),
                250 => w.shift(extra[0], IVec2::new(px(-40), 0)).unwrap(),
                300 => w.set_enabled(extra[0], false).unwrap(),
                350 => w.set_enabled(extra[0], true).unwrap(),
                // A circle sensor on the first box's body: the scene is no
                // longer boxes only (the AABB fast path turns off).
                400 => {
                    let first = w.bodies().find(|(_, b)| b.is_dynamic()).unwrap().0;
                    let c = ColliderDesc::trigger(Circle::new(px(30)).unwrap());
                    w.add_collider(first, c).unwrap();
                }
                450 => w.remove_body(extra[0]).unwrap(),
                _ => {}
            }
        }
        scenes::inputs(t, &mut inputs);
        let mut reference = None;
        for w in worlds.iter_mut() {
            let events = w.step(&inputs).to_vec();
            let got = (events, seen(w), w.state_hash());
            match &reference {
                None => reference = Some(got),
                Some(r) => assert_eq!(&got, r, "tick {t}"),
            }
        }
    }
}

#[test]
fn worlds_report_the_features_of_their_scene() {
    let c = SimConfig::default();
    let f = scenes::boxes(100, 1, c).unwrap().features();
    assert!(f.aabb_only() && f.has_kind(ShapeKind::Aabb));
    assert!(!f.tilemap && !f.triggers && !f.one_way && !f.kinematic && !f.riders && !f.rotated);

    let f = scenes::tile_room(100, 1, c).unwrap().features();
    assert!(f.aabb_only() && f.tilemap);
    assert!(!f.slopes && !f.one_way_tiles && !f.hazard_tiles && !f.triggers && !f.one_way);

    let f = scenes::mixed(200, 1, c).unwrap().features();
    assert_eq!(f.kinds, 0b11_1111, "every shape kind");
    assert!(f.rotated && f.triggers && f.one_way && f.kinematic && f.riders);
    assert!(f.tilemap && f.slopes && f.one_way_tiles && f.hazard_tiles);

    // The game's world agrees with the level's own report.
    let level = default_level();
    let lf = level.features();
    let mut g = Game::from_level(&level).unwrap();
    g.add_player(PlayerId(1)).unwrap();
    let f = g.world().features();
    // Boxes, and the level's one polygon solid.
    assert_eq!(
        f.kinds,
        (1 << ShapeKind::Aabb as u8) | (1 << ShapeKind::Polygon as u8)
    );
    assert_eq!(f.slopes, lf.slopes);
    assert_eq!(f.one_way_tiles, lf.one_way_tiles);
    assert_eq!(f.hazard_tiles, lf.hazard_tiles);
    assert_eq!(f.kinematic, lf.moving_platforms);
    assert_eq!(f.one_way, lf.one_way_platforms);
    assert!(f.riders, "players and walkers ride platforms");
    // Coins, goals and hazards are rule boxes in the game, not colliders.
    assert!(!f.triggers);
}

/// Worlds and games move between threads (a server's rooms) and share
/// their pool.
#[test]
fn worlds_and_games_are_send() {
    fn send<T: Send>() {}
    send::<World>();
    send::<Game>();
}

#[test]
fn configurations_out_of_range_are_refused_and_old_ones_still_load() {
    let bad = |c: SimConfig| World::new(c).is_err();
    assert!(bad(SimConfig {
        threads: 100_000,
        ..SimConfig::default()
    }));
    for (strip_shift, level_shift) in [(3, 2), (32, 2), (14, 0), (14, 29)] {
        assert!(bad(SimConfig {
            broad_phase: BroadPhaseKind::Strips {
                strip_shift,
                level_shift,
            },
            ..SimConfig::default()
        }));
    }
    // A configuration saved before the broad-phase knobs existed.
    let old: SimConfig =
        serde_json::from_str(r#"{"substeps": 2, "restitution_iterations": 3}"#).unwrap();
    assert_eq!(
        old,
        SimConfig {
            substeps: 2,
            restitution_iterations: 3,
            ..SimConfig::default()
        }
    );
    let all = SimConfig {
        broad_phase: BroadPhaseKind::BruteForce,
        pipeline: Pipeline::General,
        threads: 4,
        ..SimConfig::default()
    };
    let text = serde_json::to_string(&all).unwrap();
    assert_eq!(serde_json::from_str::<SimConfig>(&text).unwrap(), all);
}

/// A clone continues exactly like the original (the broad phase's state is
/// copied), and shares the original's pool.
#[test]
fn clones_continue_identically() {
    let mut a = scenes::mixed(
        300,
        4,
        config(BroadPhaseKind::DEFAULT, Pipeline::Specialised, 2),
    )
    .unwrap();
    let mut inputs = vec![Buttons::NONE; a.controllers().len()];
    for _ in 0..50 {
        scenes::inputs(a.tick(), &mut inputs);
        a.step(&inputs);
    }
    let mut b = a.clone();
    for _ in 0..100 {
        scenes::inputs(a.tick(), &mut inputs);
        let ea = a.step(&inputs).to_vec();
        let eb = b.step(&inputs).to_vec();
        assert_eq!(ea, eb);
        assert_eq!(seen(&a), seen(&b));
        assert_eq!(a.state_hash(), b.state_hash());
    }
}

/// Detection alone, on hundreds of random placements of every body of a
/// mixed scene (teleported, so almost everything overlaps something): the
/// same contacts, in the same order, for brute force, both pipelines and
/// any thread count.
#[test]
fn detection_of_random_placements_is_the_same_in_every_mode() {
    let mut worlds: Vec<(&str, World)> = variants()
        .into_iter()
        .map(|(n, c)| (n, scenes::mixed(300, 21, c).unwrap()))
        .collect();
    let ids: Vec<_> = worlds[0]
        .1
        .bodies()
        .filter(|(_, b)| b.kind() != ledge_shared::world::BodyKind::Static)
        .map(|(id, _)| id)
        .collect();
    let mut rng = ledge_shared::broad::standard::SplitMix64(5);
    let mut total = 0;
    for round in 0..60 {
        // Crowd the bodies into a shrinking square.
        let side = px(800 - 10 * round);
        let places: Vec<IVec2> = ids
            .iter()
            .map(|_| IVec2::new(rng.range(px(40), side), rng.range(px(40), side)))
            .collect();
        let mut reference: Option<Vec<Seen>> = None;
        for (name, w) in worlds.iter_mut() {
            for (&id, &p) in ids.iter().zip(&places) {
                w.set_position(id, p).unwrap();
            }
            w.detect_contacts();
            let got = seen(w);
            match &reference {
                None => {
                    total += got.len();
                    reference = Some(got);
                }
                Some(r) => assert_eq!(&got, r, "{name}, round {round}"),
            }
        }
    }
    assert!(total > 60 * 100, "{total} contacts");
}

// ------------------------------------------------------------ allocations

use crate::counting_alloc;
use counting_alloc::allocations;

/// The warm-up room and the game (tiny scenes) are covered by
/// `tests/simulation/alloc.rs`; these scenes go through the broad phase, incremental
/// re-detection, tiles and the sorted rider search.
#[test]
fn large_scenes_allocate_nothing_per_tick_in_steady_state() {
    for (name, mut w) in [
        (
            "boxes",
            scenes::boxes(3_000, 2, SimConfig::default()).unwrap(),
        ),
        (
            "mixed",
            scenes::mixed(2_500, 2, SimConfig::default()).unwrap(),
        ),
        (
            "tile room",
            scenes::tile_room(1_000, 2, SimConfig::default()).unwrap(),
        ),
    ] {
        let mut inputs = vec![Buttons::NONE; w.controllers().len()];
        let mut run = |w: &mut World, ticks: u64| {
            for _ in 0..ticks {
                scenes::inputs(w.tick(), &mut inputs);
                w.step(&inputs);
            }
        };
        run(&mut w, 1_000);
        let before = w.detection_stats();
        let n = allocations(|| run(&mut w, 400));
        let after = w.detection_stats();
        assert_eq!(n, 0, "{name}: allocations in 400 steady-state ticks");
        assert!(after.incremental > before.incremental, "{name}: {after:?}");
    }
}
