//! The world pipeline, general vs specialised: whole ticks (controllers,
//! move, detect, restitute, events) of the same scene under several
//! configurations, in one run.
//!
//! ```sh
//! cargo bench -p ledge-shared --bench world               # the table
//! cargo bench -p ledge-shared --bench world -- --tune     # + strip heights
//! cargo bench -p ledge-shared --bench world -- --quick    # fewer rounds
//! cargo bench -p ledge-shared --bench world -- --only "(c)"  # one scenario
//! ```
//!
//! Each scenario builds one world per configuration from the same seed, runs
//! them through the same warm-up, then times them in turn, round after
//! round, on batches of ticks with the same inputs (precomputed outside the
//! timing): all worlds stay in the same state (checked by state hash after
//! every round, the run aborts otherwise), so every configuration does
//! exactly the same simulation work. Figures are medians per tick over the
//! rounds, of wall time and of the stepping thread's CPU time (steadier on a
//! shared machine; it leaves out rayon workers, so compare threaded rows by
//! wall time); speed-ups are the scenario's first row's time divided by the
//! row's, from the same run.
//! Results are printed as markdown tables (`docs/PERFORMANCE.md`, "World
//! pipeline: general vs specialised").

use std::time::{Duration, Instant};

use ledge_levels::default_level;
use ledge_shared::game::{Game, GameConfig};
use ledge_shared::input::Buttons;
use ledge_shared::protocol::PlayerId;
use ledge_shared::scene::{scripted_inputs, warmup_room_with};
use ledge_shared::world::{scenes, BroadPhaseKind, DetectionStats, Pipeline, SimConfig, World};

/// Something that ticks: a world with movers, or a game.
trait Subject {
    fn slots(&self) -> usize;
    fn tick_now(&self) -> u64;
    fn step_with(&mut self, inputs: &[Buttons]);
    fn hash(&self) -> u64;
    fn event_count(&self) -> usize;
    fn stats(&self) -> DetectionStats;
}

impl Subject for World {
    fn slots(&self) -> usize {
        self.controllers().len()
    }
    fn tick_now(&self) -> u64 {
        self.tick()
    }
    fn step_with(&mut self, inputs: &[Buttons]) {
        self.step(inputs);
    }
    fn hash(&self) -> u64 {
        self.state_hash()
    }
    fn event_count(&self) -> usize {
        self.events().len()
    }
    fn stats(&self) -> DetectionStats {
        self.detection_stats()
    }
}

/// The default level with 8 players holding scripted inputs.
struct Room {
    game: Game,
    inputs: Vec<(PlayerId, Buttons)>,
}

impl Room {
    fn new(sim: SimConfig) -> Self {
        let mut game = Game::with_config(
            &default_level(),
            GameConfig {
                sim,
                ..GameConfig::default()
            },
        )
        .expect("default level");
        for id in 1..=8 {
            game.add_player(PlayerId(id)).expect("player");
        }
        Self {
            game,
            inputs: Vec::new(),
        }
    }
}

impl Subject for Room {
    fn slots(&self) -> usize {
        8
    }
    fn tick_now(&self) -> u64 {
        self.game.tick()
    }
    fn step_with(&mut self, inputs: &[Buttons]) {
        self.inputs.clear();
        for (k, b) in inputs.iter().enumerate() {
            self.inputs.push((PlayerId(k as u32 + 1), *b));
        }
        self.game.step(&self.inputs);
    }
    fn hash(&self) -> u64 {
        self.game.state_hash() ^ self.game.world().state_hash()
    }
    fn event_count(&self) -> usize {
        self.game.world().events().len()
    }
    fn stats(&self) -> DetectionStats {
        self.game.world().detection_stats()
    }
}

/// Inputs of tick `t` for `slots` slots: per-slot scripts for scenes with
/// movers, players shifted by 555 ticks each for the game.
fn fill_inputs(game: bool, t: u64, out: &mut [Buttons]) {
    if game {
        for (k, b) in out.iter_mut().enumerate() {
            *b = scripted_inputs(t + 555 * k as u64);
        }
    } else {
        scenes::inputs(t, out);
    }
}

struct Run {
    rounds: usize,
    quick: bool,
    /// Only scenarios whose title contains this.
    only: Option<String>,
    /// Only configurations whose label contains this (for profiling).
    config: Option<String>,
}

impl Run {
    /// Whether the scenario titled `title` runs (`--only`).
    fn wants(&self, title: &str) -> bool {
        self.only
            .as_ref()
            .is_none_or(|o| title.contains(o.as_str()))
    }
}

/// Times `subjects` (label, subject) in turn; prints one table.
fn scenario<S: Subject>(
    run: &Run,
    title: &str,
    game: bool,
    warmup: u64,
    batch: u64,
    mut subjects: Vec<(String, S)>,
) -> Vec<f64> {
    if !run.wants(title) {
        return Vec::new();
    }
    if let Some(c) = &run.config {
        subjects.retain(|(name, _)| name.contains(c.as_str()));
        if subjects.is_empty() {
            return Vec::new();
        }
    }
    let slots = subjects[0].1.slots();
    let mut inputs: Vec<Vec<Buttons>> = vec![vec![Buttons::NONE; slots]; batch as usize];
    let fill = |t0: u64, inputs: &mut Vec<Vec<Buttons>>| {
        for (k, v) in inputs.iter_mut().enumerate() {
            fill_inputs(game, t0 + k as u64, v);
        }
    };
    // Warm-up (buffers grow, the scene gets busy).
    let mut t = subjects[0].1.tick_now();
    let mut events = 0usize;
    while t < warmup {
        let n = batch.min(warmup - t);
        fill(t, &mut inputs);
        for (_, s) in subjects.iter_mut() {
            for v in &inputs[..n as usize] {
                s.step_with(v);
            }
        }
        t += n;
    }
    let stats0: Vec<DetectionStats> = subjects.iter().map(|(_, s)| s.stats()).collect();
    let mut times: Vec<Vec<Duration>> = vec![Vec::new(); subjects.len()];
    let mut cpu: Vec<Vec<Duration>> = vec![Vec::new(); subjects.len()];
    let rounds = if run.quick {
        run.rounds / 3
    } else {
        run.rounds
    }
    .max(3);
    for _ in 0..rounds {
        fill(t, &mut inputs);
        for (i, (_, s)) in subjects.iter_mut().enumerate() {
            let c0 = cpu_time();
            let start = Instant::now();
            for v in &inputs {
                s.step_with(v);
            }
            times[i].push(start.elapsed() / batch as u32);
            cpu[i].push(cpu_time().saturating_sub(c0) / batch as u32);
        }
        events += subjects[0].1.event_count();
        t += batch;
        let h = subjects[0].1.hash();
        for (name, s) in &subjects {
            assert_eq!(s.hash(), h, "{title}: {name} diverged at tick {t}");
        }
    }
    let median = |v: &mut Vec<Duration>| {
        v.sort();
        v[v.len() / 2].as_secs_f64()
    };
    let med: Vec<f64> = times.iter_mut().map(median).collect();
    let med_cpu: Vec<f64> = cpu.iter_mut().map(median).collect();
    println!("\n#### {title}\n");
    println!(
        "{rounds} rounds of {batch} ticks after {warmup} warm-up ticks; \
         {:.1} events per tick in the first configuration's timed ticks.\n",
        events as f64 / rounds as f64
    );
    let ticks = (rounds as u64 * batch) as f64;
    println!(
        "| configuration | wall per tick | speed-up | CPU per tick (stepping thread) | speed-up \
         | detections per tick: full + incremental |"
    );
    println!("|---|---:|---:|---:|---:|---:|");
    for (i, (name, _)) in subjects.iter().enumerate() {
        // A tick run inside a rayon pool leaves the stepping thread waiting:
        // its CPU time says nothing.
        let (cpu, up) = if med_cpu[i] < med[i] / 4.0 {
            ("(in a pool)".to_string(), "—".to_string())
        } else {
            (fmt(med_cpu[i]), format!("{:.2}x", med_cpu[0] / med_cpu[i]))
        };
        let (s0, s1) = (stats0[i], subjects[i].1.stats());
        println!(
            "| {name} | {} | {:.2}x | {cpu} | {up} | {:.2} + {:.2} |",
            fmt(med[i]),
            med[0] / med[i],
            (s1.full - s0.full) as f64 / ticks,
            (s1.incremental - s0.incremental) as f64 / ticks,
        );
    }
    med
}

/// CPU time this thread has run so far (`CLOCK_THREAD_CPUTIME_ID`; zero off
/// Linux). Unlike wall time it does not count the time other processes held
/// the core, which on a shared machine makes it the steadier figure for
/// one-thread configurations. It does not include rayon workers' time.
#[cfg(target_os = "linux")]
fn cpu_time() -> Duration {
    #[repr(C)]
    struct Timespec {
        sec: i64,
        nsec: i64,
    }
    extern "C" {
        fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
    }
    const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
    let mut t = Timespec { sec: 0, nsec: 0 };
    // SAFETY: `t` is a valid, writable `struct timespec` (two 64-bit fields
    // on 64-bit Linux) and the clock id is a constant of the kernel ABI.
    let r = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut t) };
    if r != 0 {
        return Duration::ZERO;
    }
    Duration::new(t.sec as u64, t.nsec as u32)
}

#[cfg(not(target_os = "linux"))]
fn cpu_time() -> Duration {
    Duration::ZERO
}

fn fmt(s: f64) -> String {
    if s >= 1e-3 {
        format!("{:.2} ms", s * 1e3)
    } else if s >= 1e-6 {
        format!("{:.1} µs", s * 1e6)
    } else {
        format!("{:.0} ns", s * 1e9)
    }
}

fn sim(broad_phase: BroadPhaseKind, pipeline: Pipeline, threads: u32) -> SimConfig {
    SimConfig {
        broad_phase,
        pipeline,
        threads,
        ..SimConfig::default()
    }
}

const STRIPS: BroadPhaseKind = BroadPhaseKind::DEFAULT;

/// A pool of `k` workers, worker `i` pinned to the `i`-th core this process
/// may use (modulo their number), as a host attaches with
/// `World::set_thread_pool`. Linux only; elsewhere the workers stay unpinned.
fn pinned_pool(k: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(k)
        .thread_name(|i| format!("pinned-{i}"))
        .start_handler(pin_to_core)
        .build()
        .expect("a thread pool")
}

/// Pins the calling thread to the `i`-th core of its affinity mask.
#[cfg(target_os = "linux")]
fn pin_to_core(i: usize) {
    // SAFETY: `cpu_set_t` is plain data (all zeroes is the empty set), the
    // calls get its exact size and a valid pointer, and pid 0 is this thread.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        let size = std::mem::size_of::<libc::cpu_set_t>();
        if libc::sched_getaffinity(0, size, &mut set) != 0 {
            return;
        }
        let cores: Vec<usize> = (0..libc::CPU_SETSIZE as usize)
            .filter(|&c| libc::CPU_ISSET(c, &set))
            .collect();
        if cores.is_empty() {
            return;
        }
        let mut one: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cores[i % cores.len()], &mut one);
        libc::sched_setaffinity(0, size, &one);
    }
}

#[cfg(not(target_os = "linux"))]
fn pin_to_core(_: usize) {}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let run = Run {
        rounds: 21,
        quick: args.iter().any(|a| a == "--quick"),
        only: args
            .iter()
            .position(|a| a == "--only")
            .and_then(|i| args.get(i + 1).cloned()),
        config: args
            .iter()
            .position(|a| a == "--config")
            .and_then(|i| args.get(i + 1).cloned()),
    };
    let tune = args.iter().any(|a| a == "--tune");
    // `cargo bench` passes `--bench`; nothing else is expected.
    let before = sim(BroadPhaseKind::BruteForce, Pipeline::General, 1);
    let general = sim(STRIPS, Pipeline::General, 1);
    let special = sim(STRIPS, Pipeline::Specialised, 1);

    // (a) AABB-only: the broad-phase standard scene as world bodies.
    for (n, brute) in [(1_000usize, true), (10_000, false)] {
        let mut v = vec![
            ("general: strips + narrow dispatch".to_string(), general),
            ("specialised: AABB fast path".to_string(), special),
            (
                "general, 2 threads".to_string(),
                sim(STRIPS, Pipeline::General, 2),
            ),
            (
                "specialised, 2 threads".to_string(),
                sim(STRIPS, Pipeline::Specialised, 2),
            ),
        ];
        if brute {
            v.push(("brute force (before)".to_string(), before));
        }
        let subjects = v
            .into_iter()
            .map(|(name, c)| (name, scenes::boxes(n, 1, c).expect("scene")))
            .collect();
        scenario(
            &run,
            &format!("(a) {n} moving boxes (`scenes::boxes`), AABB only"),
            false,
            60,
            if n > 5_000 { 2 } else { 10 },
            subjects,
        );
    }

    // (b) A feature-poor level: solid tiles and boxes only.
    for n in [300usize, 3_000] {
        let subjects = [
            ("general", general),
            ("specialised", special),
            ("brute force (before)", before),
        ]
        .into_iter()
        .filter(|(name, _)| n <= 1_000 || !name.starts_with("brute"))
        .map(|(name, c)| (name.to_string(), scenes::tile_room(n, 1, c).expect("scene")))
        .collect();
        scenario(
            &run,
            &format!("(b) tile room with {n} moving boxes (`scenes::tile_room`): tiles + boxes"),
            false,
            60,
            if n > 1_000 { 5 } else { 20 },
            subjects,
        );
    }

    // (c) The warm-up room, before and after.
    let subjects = [
        ("before: brute force, general passes", before),
        ("strips, general passes", general),
        ("after: strips, specialised (default)", special),
    ]
    .into_iter()
    .map(|(name, c)| (name.to_string(), warmup_room_with(c).expect("room")))
    .collect();
    scenario(
        &run,
        "(c) the warm-up room (`scene::warmup_room`), one tick",
        false,
        600,
        2_000,
        subjects,
    );

    // The platformer: the default level with 8 players.
    let subjects = [
        ("before: brute force, general passes", before),
        ("strips, general passes", general),
        ("after: strips, specialised (default)", special),
    ]
    .into_iter()
    .map(|(name, c)| (name.to_string(), Room::new(c)))
    .collect();
    scenario(
        &run,
        "(d) the default level with 8 players (`Game::step`)",
        true,
        600,
        500,
        subjects,
    );

    // Every feature at once: the general path is the only one.
    let subjects = [
        ("strips, specialised", special),
        ("strips, general", general),
        (
            "strips, specialised, 2 threads",
            sim(STRIPS, Pipeline::Specialised, 2),
        ),
        ("brute force (before)", before),
    ]
    .into_iter()
    .map(|(name, c)| (name.to_string(), scenes::mixed(2_000, 1, c).expect("scene")))
    .collect();
    scenario(
        &run,
        "(e) 2,000 moving bodies of every shape kind (`scenes::mixed`)",
        false,
        60,
        5,
        subjects,
    );

    // Threads on larger scenes (the parallel part is detection only): the
    // world's own pool, and an attached pool whose workers are pinned one
    // per core (Linux can stack two unpinned workers on one core). Scenes
    // and the pinned pool are built only when these scenarios run.
    let (boxes_f, mixed_f) = (
        "(f) threads: 50,000 moving boxes",
        "(f) threads: 20,000 mixed bodies",
    );
    if run.wants(boxes_f) || run.wants(mixed_f) {
        let par = [
            ("specialised, 1 thread", special, false),
            (
                "specialised, 2 threads",
                sim(STRIPS, Pipeline::Specialised, 2),
                false,
            ),
            (
                "specialised, 2 pinned threads",
                sim(STRIPS, Pipeline::Specialised, 2),
                true,
            ),
        ];
        let pinned = std::sync::Arc::new(pinned_pool(2));
        // One world per configuration, the pinned pool attached where asked.
        let subjects = |scene: &dyn Fn(SimConfig) -> World| -> Vec<(String, World)> {
            par.into_iter()
                .map(|(name, c, pin)| {
                    let mut w = scene(c);
                    if pin {
                        w.set_thread_pool(Some(pinned.clone()));
                    }
                    (name.to_string(), w)
                })
                .collect()
        };
        let boxes = subjects(&|c| scenes::boxes(50_000, 1, c).expect("scene"));
        scenario(&run, boxes_f, false, 30, 1, boxes);
        let mixed = subjects(&|c| scenes::mixed(20_000, 1, c).expect("scene"));
        scenario(&run, mixed_f, false, 30, 1, mixed);
    }

    if tune {
        let strips = |s: u32, l: u32| {
            sim(
                BroadPhaseKind::Strips {
                    strip_shift: s,
                    level_shift: l,
                },
                Pipeline::Specialised,
                1,
            )
        };
        let grid = [(14, 2), (13, 2), (15, 2), (16, 2), (14, 1), (14, 3)];
        let label = |s: u32, l: u32| format!("strips {} px, x{} per level", (1 << s) / 256, 1 << l);
        let subjects = grid
            .iter()
            .map(|&(s, l)| {
                (
                    label(s, l),
                    scenes::boxes(10_000, 1, strips(s, l)).expect("scene"),
                )
            })
            .collect();
        scenario(&run, "tune: 10,000 boxes", false, 60, 2, subjects);
        let subjects = grid
            .iter()
            .map(|&(s, l)| {
                (
                    label(s, l),
                    scenes::tile_room(3_000, 1, strips(s, l)).expect("scene"),
                )
            })
            .collect();
        scenario(&run, "tune: tile room, 3,000 boxes", false, 60, 5, subjects);
        let subjects = grid
            .iter()
            .map(|&(s, l)| {
                (
                    label(s, l),
                    scenes::mixed(2_000, 1, strips(s, l)).expect("scene"),
                )
            })
            .collect();
        scenario(&run, "tune: mixed, 2,000 bodies", false, 60, 5, subjects);
        let subjects = grid
            .iter()
            .map(|&(s, l)| (label(s, l), Room::new(strips(s, l))))
            .collect();
        scenario(
            &run,
            "tune: default level, 8 players",
            true,
            600,
            500,
            subjects,
        );
    }
}
