//! Broad phase on the standard scene (`ledge_shared::broad::standard`): one
//! tick of detection (update the dynamic set, find every overlapping pair
//! with its MTV, in canonical order), per N, on one thread and through rayon.
//!
//! `cargo bench -p ledge-shared --bench broad_phase`. Only our side: the
//! comparison with brute force and rapier2d is the `ledge-bench` CLI
//! (`bench/`), whose table is in `docs/PERFORMANCE.md`. The scene moves
//! between timed ticks (motion is not timed), so the incremental update sees
//! the usual few strip changes per tick. `contacts_aabb_baseline` is
//! `contacts_aabb` with the x86-64 baseline versions of the hot loops
//! (`Isa::Baseline`), to compare with the best the CPU has.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use ledge_shared::broad::standard::{StandardScene, SEED};
use ledge_shared::broad::{BroadPhase, BroadPhaseConfig, Isa};
use std::time::{Duration, Instant};

const SIZES: [usize; 4] = [1_000, 10_000, 50_000, 100_000];

/// Times `detect` over `iters` ticks of a moving scene, motion excluded.
fn ticks(
    scene: &mut StandardScene,
    iters: u64,
    mut detect: impl FnMut(&StandardScene) -> usize,
) -> Duration {
    let mut total = Duration::ZERO;
    for _ in 0..iters {
        scene.step();
        let t = Instant::now();
        black_box(detect(scene));
        total += t.elapsed();
    }
    total
}

fn broad_phase(c: &mut Criterion) {
    let mut g = c.benchmark_group("broad_phase");
    g.sample_size(20);
    g.measurement_time(Duration::from_secs(3));
    for &n in &SIZES {
        g.throughput(Throughput::Elements(n as u64));
        let mut scene = StandardScene::new(n, SEED);
        let mut out = Vec::new();
        let mut bps = [Isa::Best, Isa::Baseline].map(|isa| {
            BroadPhase::new(BroadPhaseConfig {
                isa,
                ..BroadPhaseConfig::default()
            })
        });
        for (name, bp) in ["contacts_aabb", "contacts_aabb_baseline"]
            .into_iter()
            .zip(&mut bps)
        {
            g.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter_custom(|iters| {
                    ticks(&mut scene, iters, |s| {
                        bp.update_dynamic(&s.boxes);
                        bp.contacts_aabb(&mut out);
                        out.len()
                    })
                })
            });
        }
        let [bp, _] = &mut bps;
        let mut pairs = Vec::new();
        g.bench_with_input(BenchmarkId::new("find_pairs", n), &n, |b, _| {
            b.iter_custom(|iters| {
                ticks(&mut scene, iters, |s| {
                    bp.update_dynamic(&s.boxes);
                    bp.find_pairs(&mut pairs);
                    pairs.len()
                })
            })
        });
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let id = BenchmarkId::new(format!("contacts_aabb_par_{threads}t"), n);
            g.bench_with_input(id, &n, |b, _| {
                b.iter_custom(|iters| {
                    pool.install(|| {
                        ticks(&mut scene, iters, |s| {
                            bp.update_dynamic_par(&s.boxes);
                            bp.contacts_aabb_par(&mut out);
                            out.len()
                        })
                    })
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, broad_phase);
criterion_main!(benches);
