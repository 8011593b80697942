//! `ledge-bench`: the standard broad-phase scene (see
//! `ledge_shared::broad::standard`) through ledge's broad phase, brute force,
//! rapier2d's collision pipeline and a plain copy of the box array, timed in
//! the same run and on the same boxes; prints a Markdown table.
//!
//! ```text
//! cargo run --release --manifest-path bench/Cargo.toml -- --threads 1,2
//! ```
//!
//! Options (`--help` lists them): `--n 1000,10000,50000,100000`,
//! `--threads 1,2` (parallel runs, one pool per count), `--ticks 20` (timed
//! ticks per N), `--warmup 10`, `--rounds 3` (every method runs once per
//! round, medians over all rounds), `--no-rapier`, `--strip-shift 14`,
//! `--breakdown` (update vs pair search), `--brute-full 10000` (largest N
//! timed in full; above it brute force is estimated from a sample of rows),
//! `--only-fast` / `--only-par K` (quick runs of our one-thread path / of it
//! against rayon on K threads in alternating passes), `--runs 5` (five whole
//! comparisons, then a summary per N).
//!
//! Each method runs in its own pass over a fresh copy of the scene (same
//! seed, so the very same boxes every tick), so that none of them finds
//! another's data in the caches. Every timed tick the output of every
//! method is compared with ours by digest (rapier's boxes are
//! shrunk by a quarter pixel per side, so that boxes sharing an edge do not
//! count, and a pair counts when a contact point has negative distance); a
//! mismatch aborts the run.

use clap::Parser;
use glam::IVec2;
use ledge_shared::broad::standard::{StandardScene, SEED};
use ledge_shared::broad::{aabb_mtv, Bounds, BroadPhase, BroadPhaseConfig, Isa};
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::query::Contact;
use ledge_shared::shape::{Aabb, Circle};
use std::time::Instant;

type Contacts = Vec<(u32, u32, IVec2)>;

/// Times the standard broad-phase scene through ledge's broad phase, brute
/// force, rapier2d's collision pipeline and a plain copy of the boxes, in
/// one run; prints a Markdown table.
#[derive(Parser, Debug)]
#[command(name = "ledge-bench")]
struct Args {
    /// Body counts to run.
    #[arg(long = "n", value_delimiter = ',', default_values_t = [1_000, 10_000, 50_000, 100_000])]
    ns: Vec<usize>,
    /// Thread counts of the parallel runs (one rayon pool per count).
    #[arg(long, value_delimiter = ',', default_values_t = [1, 2])]
    threads: Vec<usize>,
    /// Timed ticks per N and round.
    #[arg(long, default_value_t = 20)]
    ticks: usize,
    /// Untimed ticks before them.
    #[arg(long, default_value_t = 10)]
    warmup: usize,
    /// Leave rapier2d out.
    #[arg(long = "no-rapier", action = clap::ArgAction::SetFalse)]
    rapier: bool,
    /// `log2` of the finest strip height in units.
    #[arg(long, default_value_t = BroadPhaseConfig::default().strip_shift)]
    strip_shift: u32,
    /// Run the x86-64 baseline versions of our hot loops (`Isa::Baseline`)
    /// rather than the best the CPU has, to compare the two.
    #[arg(long)]
    baseline: bool,
    /// Also time the update and the pair search apart.
    #[arg(long)]
    breakdown: bool,
    /// Largest N whose brute force is timed in full (above it: estimated
    /// from a sample of rows).
    #[arg(long, default_value_t = 10_000)]
    brute_full: usize,
    /// Only our one-thread path: median and fastest tick.
    #[arg(long)]
    only_fast: bool,
    /// Only our one-thread path against rayon on this many threads, in
    /// alternating passes (`--rounds` of each).
    #[arg(long)]
    only_par: Option<usize>,
    /// Rounds: every method runs once per round, medians over all rounds.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..))]
    rounds: u64,
    /// Whole comparisons in a row (each printed), then a summary per N of
    /// every run's one-thread figures and the least rapier2d / ours.
    #[arg(long, default_value_t = 1)]
    runs: usize,
    /// Pin worker `i` of every rayon pool (and calibration thread `i`) to
    /// core `i`. Unpinned, Linux sometimes stacks both workers of a
    /// two-thread pool on one core for tens of milliseconds (seen on this
    /// 2-vCPU VM: whole rounds at 1.0x); pinned, every round shows the
    /// parallel path itself.
    #[arg(long)]
    pin: bool,
}

/// Pins the calling thread to core `i` (modulo the cores this process may
/// use) when `pin` is set; silently a no-op where the OS refuses.
fn pin_to(i: usize, pin: bool) {
    if !pin {
        return;
    }
    if let Some(cores) = core_affinity::get_core_ids().filter(|c| !c.is_empty()) {
        core_affinity::set_for_current(cores[i % cores.len()]);
    }
}

/// A rayon pool of `k` workers, pinned one per core with `pin`.
fn new_pool(k: usize, pin: bool) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(k)
        .start_handler(move |i| pin_to(i, pin))
        .build()
        .expect("a thread pool")
}

/// `--only-par K`: our one-thread path and rayon on `k` threads in
/// alternating passes over the scene, `a.rounds` of each, so that a burst of
/// load on the machine hits both alike; prints the medians over all passes,
/// the ratio of each round and the update/search split. Then both again on
/// *paired ticks* (each tick runs both paths, in turn), which a burst of load
/// lasting longer than a tick cannot favour either way. `reference` is a
/// one-thread trace whose output every pass must match.
fn only_par(n: usize, a: &Args, cfg: BroadPhaseConfig, k: usize, reference: &Trace) {
    let pool = new_pool(k, a.pin);
    let pool1 = new_pool(1, a.pin);
    // Per timed tick: (update, search) of each side.
    let (mut one, mut many) = (Vec::new(), Vec::new());
    let (mut rounds, mut both) = (Vec::new(), Vec::new());
    // The one-thread path on a worker thread (the scene is moved on this
    // one, as a game moves its bodies before detecting), and the rayon path
    // on one worker.
    let (mut away, mut par1) = (Vec::new(), Vec::new());
    // Paired ticks: (one thread, k threads) on the same tick.
    let mut paired = Vec::new();
    for _ in 0..a.rounds {
        // The machine's own ceiling: `k` independent one-thread runs at
        // once. Were the cores independent, each tick would take as long as
        // alone and the ceiling would be `k`; shared caches, memory
        // bandwidth or a hyperthread sibling make it less.
        let serial = |_| {
            let mut bp = BroadPhase::new(cfg);
            trace(n, a, |s, out| {
                time(|| {
                    bp.update_dynamic(&s.boxes);
                    bp.contacts_aabb(out);
                })
            })
            .ns
        };
        std::thread::scope(|sc| {
            let hs: Vec<_> = (0..k)
                .map(|t| {
                    sc.spawn(move || {
                        pin_to(t, a.pin);
                        serial(t)
                    })
                })
                .collect();
            for h in hs {
                both.extend(h.join().expect("a calibration thread"));
            }
        });
        let mut parts = Vec::new();
        let mut bp = BroadPhase::new(cfg);
        let mut t1 = trace(n, a, |s, out| {
            let u = time(|| bp.update_dynamic(&s.boxes));
            let c = time(|| bp.contacts_aabb(out));
            parts.push((u, c));
            u + c
        });
        check("one thread", n, reference, &t1, true);
        one.extend_from_slice(&parts[a.warmup..]);
        parts.clear();
        let mut bp = BroadPhase::new(cfg);
        // The whole loop in the pool, as a game loop run by the pool: the
        // bodies are moved on one of the workers.
        let mut tk = pool.install(|| {
            trace(n, a, |s, out| {
                let u = time(|| bp.update_dynamic_par(&s.boxes));
                let c = time(|| bp.contacts_aabb_par(out));
                parts.push((u, c));
                u + c
            })
        });
        check("rayon", n, reference, &tk, true);
        many.extend_from_slice(&parts[a.warmup..]);
        rounds.push(t1.median() / tk.median());
        // Paired ticks: both paths on the same tick, one after the other
        // (which goes first alternates), on the worker that moved the
        // boxes; a burst of load lasting longer than a tick hits both.
        let (mut b1, mut bk) = (BroadPhase::new(cfg), BroadPhase::new(cfg));
        let mut out_k = Contacts::new();
        let mut tick = 0usize;
        let t = pool.install(|| {
            trace(n, a, |s, out| {
                tick += 1;
                let mut one = |out: &mut Contacts| {
                    time(|| {
                        b1.update_dynamic(&s.boxes);
                        b1.contacts_aabb(out);
                    })
                };
                let mut many = || {
                    time(|| {
                        bk.update_dynamic_par(&s.boxes);
                        bk.contacts_aabb_par(&mut out_k);
                    })
                };
                let (x, y) = if tick.is_multiple_of(2) {
                    (one(out), many())
                } else {
                    let y = many();
                    (one(out), y)
                };
                assert!(*out == out_k, "rayon differs from one thread at N={n}");
                if tick > a.warmup {
                    paired.push((x, y));
                }
                x
            })
        });
        check("paired one thread", n, reference, &t, true);
        // Each tick handed to the one worker of `pool1`, by the plain path
        // or the rayon path.
        let on_worker = |par: bool| {
            let mut bp = BroadPhase::new(cfg);
            trace(n, a, |s, out| {
                pool1.install(|| {
                    time(|| {
                        if par {
                            bp.update_dynamic_par(&s.boxes);
                            bp.contacts_aabb_par(out);
                        } else {
                            bp.update_dynamic(&s.boxes);
                            bp.contacts_aabb(out);
                        }
                    })
                })
            })
        };
        let t = on_worker(false);
        check("one thread on a worker", n, reference, &t, true);
        away.extend(t.ns);
        let t = on_worker(true);
        check("rayon on one thread", n, reference, &t, true);
        par1.extend(t.ns);
    }
    let med = |v: &[(f64, f64)], f: fn(&(f64, f64)) -> f64| {
        median(&mut v.iter().map(f).collect::<Vec<_>>())
    };
    let (t1, tk) = (med(&one, |p| p.0 + p.1), med(&many, |p| p.0 + p.1));
    let per_round: Vec<String> = rounds.iter().map(|r| format!("{r:.2}x")).collect();
    println!(
        "N={n}: serial {}, rayon {k} threads {} ({:.2}x; rounds {})",
        fmt_ns(t1),
        fmt_ns(tk),
        t1 / tk,
        per_round.join(", ")
    );
    println!(
        "update: serial {} par {}; search: serial {} par {}",
        fmt_ns(med(&one, |p| p.0)),
        fmt_ns(med(&many, |p| p.0)),
        fmt_ns(med(&one, |p| p.1)),
        fmt_ns(med(&many, |p| p.1)),
    );
    let (p1, pk) = (med(&paired, |p| p.0), med(&paired, |p| p.1));
    println!(
        "paired ticks (both paths on every tick, in turn): serial {}, rayon {k} threads {} \
         ({:.2}x; median of the per-tick ratios {:.2}x)",
        fmt_ns(p1),
        fmt_ns(pk),
        p1 / pk,
        med(&paired, |p| p.0 / p.1)
    );
    // Fastest ticks: noise on this kind of machine only ever adds time.
    let fastest = |v: &[(f64, f64)]| v.iter().map(|p| p.0 + p.1).fold(f64::INFINITY, f64::min);
    let (f1, fk) = (fastest(&one), fastest(&many));
    println!(
        "fastest ticks: serial {}, rayon {k} threads {} ({:.2}x)",
        fmt_ns(f1),
        fmt_ns(fk),
        f1 / fk
    );
    let (away, par1) = (median(&mut away), median(&mut par1));
    println!(
        "the one-thread path on a worker thread (input written by another): {}; \
         the rayon path on one worker: {} ({k} threads against it: {:.2}x)",
        fmt_ns(away),
        fmt_ns(par1),
        par1 / tk
    );
    let alongside = median(&mut both);
    println!(
        "machine ceiling: {k} independent one-thread runs at once take {} per tick each, \
         so {k} threads can give at most {:.2}x on this work (ours: {:.2}x)",
        fmt_ns(alongside),
        k as f64 * t1 / alongside,
        t1 / tk
    );
}

// ---------------------------------------------------------------- rapier2d

mod rapier {
    use super::*;
    use rapier2d::prelude::*;

    /// rapier2d's collision pipeline (BVH broad phase + narrow phase, no
    /// dynamics) over parentless cuboid colliders.
    pub struct Rapier {
        pipeline: CollisionPipeline,
        islands: IslandManager,
        broad: BroadPhaseBvh,
        narrow: NarrowPhase,
        bodies: RigidBodySet,
        colliders: ColliderSet,
        handles: Vec<ColliderHandle>,
    }

    fn centre(b: &Bounds) -> Vector {
        let c = (b.min + b.max).as_vec2() * (0.5 / UNITS_PER_PX as f32);
        Vector::new(c.x, c.y)
    }

    impl Rapier {
        pub fn new(boxes: &[(u32, Bounds)]) -> Self {
            let mut colliders = ColliderSet::new();
            let handles = boxes
                .iter()
                .map(|(id, b)| {
                    let h = (b.max - b.min).as_vec2() * (0.5 / UNITS_PER_PX as f32) - 0.25;
                    colliders.insert(
                        ColliderBuilder::cuboid(h.x, h.y)
                            .translation(centre(b))
                            .active_collision_types(ActiveCollisionTypes::all())
                            .user_data(*id as u128)
                            .build(),
                    )
                })
                .collect();
            Self {
                pipeline: CollisionPipeline::new(),
                islands: IslandManager::new(),
                broad: BroadPhaseBvh::new(),
                narrow: NarrowPhase::new(),
                bodies: RigidBodySet::new(),
                colliders,
                handles,
            }
        }

        /// Moves the colliders (the motion step: not timed).
        pub fn set(&mut self, boxes: &[(u32, Bounds)]) {
            for (h, (_, b)) in self.handles.iter().zip(boxes) {
                self.colliders[*h].set_translation(centre(b));
            }
        }

        /// One collision step (timed).
        pub fn step(&mut self) {
            self.pipeline.step(
                0.0,
                &mut self.islands,
                &mut self.broad,
                &mut self.narrow,
                &mut self.bodies,
                &mut self.colliders,
                &(),
                &(),
            );
        }

        /// Pairs with penetrating contact points, as sorted `(min id, max id)`.
        pub fn pairs(&self, out: &mut Vec<(u32, u32)>) {
            out.clear();
            for p in self.narrow.contact_pairs() {
                let touching = p
                    .manifolds()
                    .iter()
                    .any(|m| m.points.iter().any(|c| c.dist < 0.0));
                if touching {
                    let a = self.colliders[p.collider1].user_data as u32;
                    let b = self.colliders[p.collider2].user_data as u32;
                    out.push((a.min(b), a.max(b)));
                }
            }
            out.sort_unstable();
        }
    }
}

// ------------------------------------------------------- the general path

/// Colliders grouped by shape kind, as the world stores them: the general
/// path looks each id up and runs the monomorphised narrow phase of its kind
/// pair.
struct KindStore {
    aabbs: Vec<Aabb>,
    circles: Vec<Circle>,
    /// `(kind, index in its Vec)` per id.
    of: Vec<(Kind, u32)>,
}

/// The kinds the store dispatches on. The standard scene has boxes only; the
/// circle arms keep the dispatch as general as the world's.
#[derive(Clone, Copy)]
#[allow(dead_code)]
enum Kind {
    Aabb,
    Circle,
}

impl KindStore {
    fn new(boxes: &[(u32, Bounds)]) -> Self {
        let mut s = KindStore {
            aabbs: Vec::new(),
            circles: Vec::new(),
            of: vec![(Kind::Aabb, 0); boxes.len()],
        };
        for (id, b) in boxes {
            s.of[*id as usize] = (Kind::Aabb, s.aabbs.len() as u32);
            s.aabbs.push(Aabb::from_size(b.max - b.min).unwrap());
        }
        s
    }

    #[inline]
    fn narrow(&self, boxes: &[(u32, Bounds)], a: u32, b: u32) -> Option<IVec2> {
        let pos = |id: u32| {
            let b = boxes[id as usize].1;
            (b.min + b.max) / 2
        };
        let (ka, ia) = self.of[a as usize];
        let (kb, ib) = self.of[b as usize];
        let (pa, pb) = (pos(a), pos(b));
        match (ka, kb) {
            (Kind::Aabb, Kind::Aabb) => self.aabbs[ia as usize]
                .contact(pa, &self.aabbs[ib as usize], pb)
                .mtv(),
            (Kind::Aabb, Kind::Circle) => self.aabbs[ia as usize]
                .contact(pa, &self.circles[ib as usize], pb)
                .mtv(),
            (Kind::Circle, Kind::Aabb) => self.circles[ia as usize]
                .contact(pa, &self.aabbs[ib as usize], pb)
                .mtv(),
            (Kind::Circle, Kind::Circle) => self.circles[ia as usize]
                .contact(pa, &self.circles[ib as usize], pb)
                .mtv(),
        }
    }
}

// -------------------------------------------------------------- brute force

/// Every pair `i < j` tested, SoA; pairs in `(i, j)` order are already in the
/// canonical order because ids are indices.
fn brute_rows(boxes: &[(u32, Bounds)], rows: impl Iterator<Item = usize>, out: &mut Contacts) {
    out.clear();
    for i in rows {
        let a = boxes[i].1;
        for (j, (_, b)) in boxes.iter().enumerate().skip(i + 1) {
            if let Some(m) = aabb_mtv(&a, b) {
                out.push((i as u32, j as u32, m));
            }
        }
    }
}

// ------------------------------------------------------------------ timing

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

fn time(f: impl FnOnce()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_nanos() as f64
}

fn fmt_ns(ns: f64) -> String {
    if ns >= 1e6 {
        format!("{:.2} ms", ns / 1e6)
    } else {
        format!("{:.0} µs", ns / 1e3)
    }
}

struct Row {
    n: usize,
    pairs: f64,
    fast: f64,
    general: f64,
    par: Vec<(usize, f64)>,
    rapier: Option<f64>,
    /// rapier2d / ours, median of each round.
    rapier_rounds: Vec<f64>,
    /// rapier2d / ours, fastest tick of each.
    rapier_fastest: Option<f64>,
    brute: f64,
    brute_estimated: bool,
    copy: f64,
    update: f64,
    search: f64,
}

/// FNV-1a over a contact list (ids and, with `mtv`, the MTVs).
fn digest(c: &[(u32, u32, IVec2)], mtv: bool) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |v: u32| {
        for b in v.to_le_bytes() {
            h = (h ^ b as u64).wrapping_mul(0x100_0000_01b3);
        }
    };
    for &(a, b, m) in c {
        eat(a);
        eat(b);
        if mtv {
            eat(m.x as u32);
            eat(m.y as u32);
        }
    }
    h
}

/// What one method measured over the timed ticks.
#[derive(Default)]
struct Trace {
    ns: Vec<f64>,
    /// Per timed tick: digest with MTVs, digest of ids only, pair count.
    digests: Vec<(u64, u64, usize)>,
}

impl Trace {
    fn median(&mut self) -> f64 {
        median(&mut self.ns)
    }
}

/// Runs `detect` on a fresh copy of the scene for every tick (its own pass,
/// so that no other method's data sits in the caches), timing it.
fn trace(
    n: usize,
    a: &Args,
    mut detect: impl FnMut(&StandardScene, &mut Contacts) -> f64,
) -> Trace {
    let mut scene = StandardScene::new(n, SEED);
    let mut out = Contacts::new();
    let mut t = Trace::default();
    for tick in 0..a.warmup + a.ticks {
        scene.step();
        let ns = detect(&scene, &mut out);
        if tick >= a.warmup {
            t.ns.push(ns);
            t.digests
                .push((digest(&out, true), digest(&out, false), out.len()));
        }
    }
    t
}

fn check(what: &str, n: usize, reference: &Trace, other: &Trace, mtv: bool) {
    for (tick, (r, o)) in reference.digests.iter().zip(&other.digests).enumerate() {
        let (rd, od) = if mtv { (r.0, o.0) } else { (r.1, o.1) };
        assert!(
            rd == od,
            "{what} differs from ours at N={n}, timed tick {tick}: {} vs {} pairs",
            o.2,
            r.2
        );
    }
}

fn run(n: usize, a: &Args, pools: &[(usize, rayon::ThreadPool)]) -> Row {
    let cfg = BroadPhaseConfig {
        strip_shift: a.strip_shift,
        isa: if a.baseline { Isa::Baseline } else { Isa::Best },
        ..BroadPhaseConfig::default()
    };
    // Ours, AABB fast path, one thread, no rayon.
    let mut bp = BroadPhase::new(cfg);
    let mut fast = trace(n, a, |s, out| {
        time(|| {
            bp.update_dynamic(&s.boxes);
            bp.contacts_aabb(out);
        })
    });
    if let Some(k) = a.only_par {
        only_par(n, a, cfg, k, &fast);
        std::process::exit(0);
    }
    if a.only_fast {
        let lo = fast.ns.iter().cloned().fold(f64::MAX, f64::min);
        let f = fast.median();
        println!(
            "N={n}: ours 1 thread median {} ({:.1} ns/body), min {} ({:.1} ns/body)",
            fmt_ns(f),
            f / n as f64,
            fmt_ns(lo),
            lo / n as f64
        );
        std::process::exit(0);
    }
    // The timed methods run in rounds: each round runs every method once over
    // the whole scene, so that a burst of load on the machine hits all of
    // them alike; medians are over the timed ticks of all rounds.
    let store = KindStore::new(&StandardScene::new(n, SEED).boxes);
    let mut bp_gen = BroadPhase::new(cfg);
    let mut bp_par: Vec<BroadPhase> = pools.iter().map(|_| BroadPhase::new(cfg)).collect();
    let mut bp_split = BroadPhase::new(cfg);
    let mut rap = a
        .rapier
        .then(|| rapier::Rapier::new(&StandardScene::new(n, SEED).boxes));
    let mut floor = StandardScene::new(n, SEED).boxes;
    let mut pairs = Vec::new();
    let mut general = Trace::default();
    let mut par_t: Vec<Trace> = pools.iter().map(|_| Trace::default()).collect();
    let mut rap_t = Trace::default();
    let mut copy = Trace::default();
    let (mut upd, mut srch) = (Vec::new(), Vec::new());
    let mut rapier_rounds = Vec::new();
    for round in 0..a.rounds {
        let ours_round = if round > 0 {
            let mut t = trace(n, a, |s, out| {
                time(|| {
                    bp.update_dynamic(&s.boxes);
                    bp.contacts_aabb(out);
                })
            });
            fast.ns.extend_from_slice(&t.ns);
            t.median()
        } else {
            median(&mut fast.ns.clone())
        };
        let t = trace(n, a, |s, out| {
            time(|| {
                bp_gen.update_dynamic(&s.boxes);
                bp_gen.contacts_with(&|x, y| store.narrow(&s.boxes, x, y), out);
            })
        });
        check("the general path", n, &fast, &t, true);
        general.ns.extend(t.ns);
        for (k, ((threads, pool), bpp)) in pools.iter().zip(&mut bp_par).enumerate() {
            let t = trace(n, a, |s, out| {
                pool.install(|| {
                    time(|| {
                        bpp.update_dynamic_par(&s.boxes);
                        bpp.contacts_aabb_par(out);
                    })
                })
            });
            check(&format!("rayon on {threads} threads"), n, &fast, &t, true);
            par_t[k].ns.extend(t.ns);
        }
        if a.breakdown {
            let mut u = Vec::new();
            let t = trace(n, a, |s, out| {
                u.push(time(|| bp_split.update_dynamic(&s.boxes)));
                time(|| bp_split.contacts_aabb(out))
            });
            upd.extend_from_slice(&u[a.warmup..]);
            srch.extend(t.ns);
        }
        if let Some(r) = rap.as_mut() {
            let t = trace(n, a, |s, out| {
                r.set(&s.boxes);
                let ns = time(|| r.step());
                r.pairs(&mut pairs);
                out.clear();
                out.extend(pairs.iter().map(|&(x, y)| (x, y, IVec2::ZERO)));
                ns
            });
            check("rapier2d's pair set", n, &fast, &t, false);
            rapier_rounds.push(median(&mut t.ns.clone()) / ours_round);
            rap_t.ns.extend(t.ns);
        }
        let t = trace(n, a, |s, out| {
            out.clear();
            let ns = time(|| floor.copy_from_slice(&s.boxes));
            std::hint::black_box(&floor);
            ns
        });
        copy.ns.extend(t.ns);
    }
    let par: Vec<(usize, f64)> = pools
        .iter()
        .zip(&mut par_t)
        .map(|((k, _), t)| (*k, t.median()))
        .collect();
    let rapier_ns = a.rapier.then(|| rap_t.median());
    let fastest = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let rapier_fastest = a.rapier.then(|| fastest(&rap_t.ns) / fastest(&fast.ns));
    let (update, search) = if a.breakdown {
        (median(&mut upd), median(&mut srch))
    } else {
        (0.0, 0.0)
    };
    // Brute force: every pair when N is small, else a sample of rows.
    let full_brute = n <= a.brute_full;
    let stride = if full_brute { 1 } else { (n / 400).max(1) };
    let tests: f64 = (0..n).step_by(stride).map(|i| (n - i - 1) as f64).sum();
    let all = n as f64 * (n as f64 - 1.0) / 2.0;
    let mut tick = 0;
    let mut brute = trace(n, a, |s, out| {
        tick += 1;
        // Only every fourth tick when sampling (it is slow), never in warm-up.
        if tick <= a.warmup || (!full_brute && tick % 4 != 0) {
            out.clear();
            return f64::NAN;
        }
        time(|| brute_rows(&s.boxes, (0..n).step_by(stride), out)) * all / tests
    });
    if full_brute {
        check("brute force", n, &fast, &brute, true);
    }
    brute.ns.retain(|x| !x.is_nan());
    Row {
        n,
        pairs: fast.digests.iter().map(|d| d.2 as f64).sum::<f64>() / fast.digests.len() as f64,
        fast: fast.median(),
        general: general.median(),
        par,
        rapier: rapier_ns,
        rapier_rounds,
        rapier_fastest,
        brute: brute.median(),
        brute_estimated: !full_brute,
        copy: copy.median(),
        update,
        search,
    }
}

fn main() {
    let a = Args::parse();
    let pools: Vec<(usize, rayon::ThreadPool)> =
        a.threads.iter().map(|&k| (k, new_pool(k, a.pin))).collect();
    let mut all = Vec::new();
    for r in 0..a.runs {
        if a.runs > 1 {
            println!("## Run {} of {}\n", r + 1, a.runs);
        }
        let rows: Vec<Row> = a.ns.iter().map(|&n| run(n, &a, &pools)).collect();
        print_run(&a, &pools, &rows);
        all.push(rows);
    }
    if a.runs > 1 {
        summary(&a, &all);
    }
}

/// `--runs K`: per N, each run's figures side by side, and the worst.
fn summary(a: &Args, all: &[Vec<Row>]) {
    println!(
        "\n## Summary of {} runs (one thread, medians per run)\n",
        all.len()
    );
    println!("| N | ours | rapier2d | rapier2d / ours | least | ours / floor | fastest ticks, rapier2d / ours |");
    println!("|---:|---|---|---|---:|---|---|");
    for (k, &n) in a.ns.iter().enumerate() {
        let rows: Vec<&Row> = all.iter().map(|r| &r[k]).collect();
        let list =
            |f: &dyn Fn(&Row) -> String| rows.iter().map(|r| f(r)).collect::<Vec<_>>().join(", ");
        let ratio = |r: &Row| r.rapier.map_or(f64::NAN, |x| x / r.fast);
        let least = rows.iter().map(|r| ratio(r)).fold(f64::INFINITY, f64::min);
        println!(
            "| {n} | {} | {} | {} | {least:.1}x | {} | {} |",
            list(&|r| fmt_ns(r.fast)),
            list(&|r| r.rapier.map_or("—".into(), fmt_ns)),
            list(&|r| format!("{:.1}x", ratio(r))),
            list(&|r| format!("{:.0}x ({})", r.fast / r.copy, fmt_ns(r.copy))),
            list(&|r| format!("{:.1}x", r.rapier_fastest.unwrap_or(f64::NAN))),
        );
    }
}

/// Prints the tables of one run.
fn print_run(a: &Args, pools: &[(usize, rayon::ThreadPool)], rows: &[Row]) {
    println!(
        "Median per tick over {} rounds of {} timed ticks (each after {} warm-up ticks), \
         detection only; ratios are times of the other method divided by ours, same run.\n",
        a.rounds, a.ticks, a.warmup
    );
    let mut head =
        String::from("| N | pairs/tick | ours, AABB fast path, 1 thread | ours, general path |");
    let mut rule = String::from("|---:|---:|---:|---:|");
    for (k, _) in pools {
        head += &format!(" ours, rayon {k} thr |");
        rule += "---:|";
    }
    head += " rapier2d | brute force | copy of the boxes (floor) | rapier2d / ours | brute / ours | ours / floor |";
    rule += "---:|---:|---:|---:|---:|---:|";
    println!("{head}\n{rule}");
    for r in rows {
        let mut line = format!(
            "| {} | {:.0} | {} | {} ({:.2}x) |",
            r.n,
            r.pairs,
            fmt_ns(r.fast),
            fmt_ns(r.general),
            r.general / r.fast
        );
        for (_, ns) in &r.par {
            line += &format!(" {} ({:.2}x) |", fmt_ns(*ns), r.fast / ns);
        }
        let rap = r.rapier.map_or("—".into(), fmt_ns);
        let rap_ratio = r
            .rapier
            .map_or("—".into(), |x| format!("{:.1}x", x / r.fast));
        line += &format!(
            " {} | {}{} | {} | {} | {:.0}x | {:.1}x |",
            rap,
            fmt_ns(r.brute),
            if r.brute_estimated { " (est.)" } else { "" },
            fmt_ns(r.copy),
            rap_ratio,
            r.brute / r.fast,
            r.fast / r.copy
        );
        println!("{line}");
    }
    if a.rapier {
        println!("\nrapier2d / ours, one thread: median of each round, and fastest tick against fastest tick\n");
        println!("| N | per round | fastest ticks |");
        println!("|---:|---|---:|");
        for r in rows {
            let rounds: Vec<String> = r.rapier_rounds.iter().map(|x| format!("{x:.1}x")).collect();
            println!(
                "| {} | {} | {:.1}x |",
                r.n,
                rounds.join(", "),
                r.rapier_fastest.unwrap_or(f64::NAN)
            );
        }
    }
    println!();
    println!(
        "Per body, ours 1 thread (growth check, N log N from 10k to 100k allows x1.25 per body):\n"
    );
    println!("| N | ns/body/tick | vs previous N |");
    println!("|---:|---:|---:|");
    let mut prev: Option<f64> = None;
    for r in rows {
        let per = r.fast / r.n as f64;
        println!(
            "| {} | {:.1} | {} |",
            r.n,
            per,
            prev.map_or("—".into(), |p| format!("{:.2}x", per / p))
        );
        prev = Some(per);
    }
    if a.breakdown {
        println!("\nBreakdown, 1 thread: update_dynamic vs contacts_aabb\n");
        println!("| N | update | pair search + MTV + sort |");
        println!("|---:|---:|---:|");
        for r in rows {
            println!("| {} | {} | {} |", r.n, fmt_ns(r.update), fmt_ns(r.search));
        }
    }
}
