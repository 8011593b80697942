//! The broad phase against brute force: same pairs, same MTVs, same order,
//! whatever the scene (huge and tiny boxes, touching boxes, boxes at the
//! world bounds, static and dynamic mixes, many updates in a row), the
//! configuration, the number of threads and the compiled versions of the
//! hot loops (the best the CPU has and the x86-64 baseline, [`Isa`]); box
//! queries against both sets equal brute force too; and no allocation per
//! tick in steady state.

use std::sync::OnceLock;

use glam::IVec2;
use ledge_shared::broad::standard::{SplitMix64, StandardScene};
use ledge_shared::broad::{aabb_mtv, brute_force, Bounds, BroadPhase, BroadPhaseConfig, Isa};
use ledge_shared::fixed::{px, MAX_COORD, MAX_EXTENT};
use ledge_shared::query::{Contact, Proximity};
use ledge_shared::shape::Aabb;
use proptest::prelude::*;

// ------------------------------------------------------------ allocations

mod counting_alloc;
use counting_alloc::allocations;

#[global_allocator]
static GLOBAL: counting_alloc::Counting = counting_alloc::Counting;

// ----------------------------------------------------------------- helpers

type Contacts = Vec<(u32, u32, IVec2)>;

/// Pools of 1, 2 and 8 threads, built once.
fn pools() -> &'static [rayon::ThreadPool] {
    static POOLS: OnceLock<Vec<rayon::ThreadPool>> = OnceLock::new();
    POOLS.get_or_init(|| {
        [1, 2, 8]
            .iter()
            .map(|&n| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .unwrap()
            })
            .collect()
    })
}

/// Both choices of compiled versions: the best the CPU has, and always the
/// x86-64 baseline, which a machine with AVX2 would otherwise never run.
const ISAS: [Isa; 2] = [Isa::Best, Isa::Baseline];

/// The default configuration with the versions `isa`.
fn default_with(isa: Isa) -> BroadPhaseConfig {
    BroadPhaseConfig {
        isa,
        ..BroadPhaseConfig::default()
    }
}

/// The configurations every scene is checked under: the default, tiny strips
/// with many levels, and huge strips (everything on one level), each under
/// both [`ISAS`].
fn configs() -> [BroadPhaseConfig; 6] {
    let shapes = [
        BroadPhaseConfig::default(),
        BroadPhaseConfig {
            strip_shift: 4,
            level_shift: 1,
            batch: 1,
            ..BroadPhaseConfig::default()
        },
        BroadPhaseConfig {
            strip_shift: 30,
            level_shift: 2,
            batch: 3,
            ..BroadPhaseConfig::default()
        },
    ];
    core::array::from_fn(|k| BroadPhaseConfig {
        isa: ISAS[k / shapes.len()],
        ..shapes[k % shapes.len()]
    })
}

/// Every output of `bp` (built with `cfg`, which failures name) for the
/// current sets, checked against `expect`: the pairs, the AABB contacts and
/// the general path, on this thread and on 1, 2 and 8 threads.
fn check_all(
    bp: &mut BroadPhase,
    cfg: &BroadPhaseConfig,
    dynamics: &[(u32, Bounds)],
    all: &[(u32, Bounds)],
    expect: &Contacts,
) {
    let pairs: Vec<(u32, u32)> = expect.iter().map(|c| (c.0, c.1)).collect();
    let lookup = |id: u32| all.iter().find(|b| b.0 == id).unwrap().1;
    let narrow = |a: u32, b: u32| aabb_mtv(&lookup(a), &lookup(b));
    let (mut p, mut c) = (Vec::new(), Vec::new());
    bp.find_pairs(&mut p);
    assert_eq!(p, pairs, "pairs, one thread, {cfg:?}");
    bp.contacts_aabb(&mut c);
    assert_eq!(&c, expect, "aabb contacts, one thread, {cfg:?}");
    bp.contacts_with(&narrow, &mut c);
    assert_eq!(&c, expect, "general path, one thread, {cfg:?}");
    for pool in pools() {
        let n = pool.current_num_threads();
        pool.install(|| {
            bp.update_dynamic_par(dynamics);
            bp.find_pairs_par(&mut p);
            assert_eq!(p, pairs, "pairs, {n} threads, {cfg:?}");
            bp.contacts_aabb_par(&mut c);
            assert_eq!(&c, expect, "aabb contacts, {n} threads, {cfg:?}");
            bp.contacts_with_par(&narrow, &mut c);
            assert_eq!(&c, expect, "general path, {n} threads, {cfg:?}");
        });
    }
}

/// The box queries: every box of both sets (and a point at each one's
/// corner) as a query finds exactly the boxes of each set whose interior
/// overlaps it. Failures name `cfg`, `bp`'s configuration.
fn check_queries(
    bp: &BroadPhase,
    cfg: &BroadPhaseConfig,
    statics: &[(u32, Bounds)],
    dynamics: &[(u32, Bounds)],
) {
    let brute = |set: &[(u32, Bounds)], q: &Bounds| {
        let mut v: Vec<u32> = set
            .iter()
            .filter(|b| b.1.overlaps(q))
            .map(|b| b.0)
            .collect();
        v.sort_unstable();
        v
    };
    let mut got = Vec::new();
    for (_, b) in statics.iter().chain(dynamics) {
        let p = Bounds::new(b.min + 1, b.min + 1);
        for q in [*b, p] {
            got.clear();
            bp.query_static(&q, |id| got.push(id));
            got.sort_unstable();
            assert_eq!(got, brute(statics, &q), "static query {q:?}, {cfg:?}");
            got.clear();
            bp.query_dynamic(&q, |id| got.push(id));
            got.sort_unstable();
            assert_eq!(got, brute(dynamics, &q), "dynamic query {q:?}, {cfg:?}");
        }
    }
}

/// Checks one static + dynamic scene under every configuration.
fn check_scene(statics: &[(u32, Bounds)], dynamics: &[(u32, Bounds)]) {
    let mut expect = Vec::new();
    brute_force(statics, dynamics, &mut expect);
    let all: Vec<_> = statics.iter().chain(dynamics).copied().collect();
    for cfg in configs() {
        let mut bp = BroadPhase::new(cfg);
        bp.set_static(statics);
        bp.update_dynamic(dynamics);
        check_all(&mut bp, &cfg, dynamics, &all, &expect);
        check_queries(&bp, &cfg, statics, dynamics);
    }
}

/// Ids `first..` for a list of boxes.
fn ided(first: u32, boxes: &[Bounds]) -> Vec<(u32, Bounds)> {
    boxes
        .iter()
        .enumerate()
        .map(|(i, &b)| (first + i as u32, b))
        .collect()
}

// -------------------------------------------------------------- generators

/// A box size: tiny (2 px or less), small, platform-sized, or up to the
/// largest shape extent.
fn size() -> impl Strategy<Value = i32> {
    prop_oneof![
        3 => 1..=px(2),
        6 => px(4)..=px(40),
        2 => px(40)..=px(4096),
        1 => px(4096)..=2 * MAX_EXTENT,
    ]
}

/// Where a scene lives: near the origin or against a world bound.
fn anchor() -> impl Strategy<Value = IVec2> {
    let edge = MAX_COORD + MAX_EXTENT;
    prop_oneof![
        4 => Just(IVec2::ZERO),
        1 => Just(IVec2::new(edge, edge)),
        1 => Just(IVec2::new(-edge, -edge)),
        1 => Just(IVec2::new(-edge, edge)),
    ]
}

/// `n` boxes around `anchor` in a region of about 3000 px, optionally
/// snapped to a 16 px lattice so that many of them exactly touch, clamped
/// into the representable range.
fn boxes(n: usize) -> impl Strategy<Value = Vec<Bounds>> {
    (
        anchor(),
        any::<bool>(),
        prop::collection::vec(
            (-px(1500)..px(1500), -px(1500)..px(1500), size(), size()),
            0..n,
        ),
    )
        .prop_map(|(anchor, snap, raw)| {
            let lim = MAX_COORD + 2 * MAX_EXTENT;
            raw.into_iter()
                .map(|(x, y, w, h)| {
                    let q = |v: i32| {
                        if snap {
                            (v / px(16)).max(1) * px(16)
                        } else {
                            v
                        }
                    };
                    let (x, y, w, h) = (q(x), q(y), q(w), q(h));
                    let min = IVec2::new(
                        (anchor.x as i64 + x as i64).clamp(-lim as i64, (lim - w) as i64) as i32,
                        (anchor.y as i64 + y as i64).clamp(-lim as i64, (lim - h) as i64) as i32,
                    );
                    Bounds::from_min_size(min, IVec2::new(w, h))
                })
                .collect()
        })
}

const CASES: u32 = 96;

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, ..ProptestConfig::default() })]

    #[test]
    fn equals_brute_force(statics in boxes(40), dynamics in boxes(120)) {
        let s = ided(1000, &statics);
        let d = ided(0, &dynamics);
        check_scene(&s, &d);
    }

    #[test]
    fn ids_in_any_order(dynamics in boxes(80), seed in any::<u64>()) {
        // Sparse, shuffled ids over the whole `u32` range: the order is by
        // id, not by input position, and the parallel sort's id parts span
        // every id.
        let mut rng = SplitMix64(seed);
        let d: Vec<_> = dynamics
            .iter()
            .map(|&b| ((rng.next_u64() >> 32) as u32, b))
            .collect();
        let mut ids: Vec<_> = d.iter().map(|e| e.0).collect();
        ids.sort_unstable();
        ids.dedup();
        prop_assume!(ids.len() == d.len());
        check_scene(&[], &d);
    }

    #[test]
    fn repeated_updates(statics in boxes(30), dynamics in boxes(100), seed in any::<u64>()) {
        // Small moves most ticks (the coherent path), jumps across strips and
        // levels, resizes, and a change in body count now and then.
        let mut rng = SplitMix64(seed);
        let s = ided(5000, &statics);
        let mut d = ided(0, &dynamics);
        let all_cfgs = configs();
        let mut bps: Vec<BroadPhase> = all_cfgs.iter().map(|&c| BroadPhase::new(c)).collect();
        for bp in &mut bps {
            bp.set_static(&s);
        }
        for tick in 0..12 {
            for (_, b) in &mut d {
                let jump = rng.range(0, 20) == 0;
                let r = if jump { px(400) } else { px(3) };
                let v = IVec2::new(rng.range(-r, r), rng.range(-r, r));
                let lim = MAX_COORD;
                if b.min.x.abs() < lim && b.min.y.abs() < lim {
                    b.min += v;
                    b.max += v;
                }
                if rng.range(0, 30) == 0 {
                    b.max.y = b.min.y + rng.range(1, px(300));
                }
            }
            if tick == 6 {
                d.truncate(d.len() * 2 / 3);
            }
            let mut expect = Vec::new();
            brute_force(&s, &d, &mut expect);
            let all: Vec<_> = s.iter().chain(&d).copied().collect();
            for (bp, cfg) in bps.iter_mut().zip(&all_cfgs) {
                // Alternate the serial and the parallel update on the moving
                // set, so that both see strips change.
                if tick % 2 == 0 {
                    bp.update_dynamic(&d);
                } else {
                    pools()[tick % 3].install(|| bp.update_dynamic_par(&d));
                }
                check_all(bp, cfg, &d, &all, &expect);
                check_queries(bp, cfg, &s, &d);
            }
        }
    }

    #[test]
    fn mtv_is_the_aabb_contact(
        ax in -px(100)..px(100), ay in -px(100)..px(100),
        bx in -px(100)..px(100), by in -px(100)..px(100),
        ahx in 1..px(60), ahy in 1..px(60), bhx in 1..px(60), bhy in 1..px(60),
    ) {
        let (ha, hb) = (IVec2::new(ahx, ahy), IVec2::new(bhx, bhy));
        let (pa, pb) = (IVec2::new(ax, ay), IVec2::new(bx, by));
        let a = Bounds::new(pa - ha, pa + ha);
        let b = Bounds::new(pb - hb, pb + hb);
        let want = Aabb::new(ha).unwrap().contact(pa, &Aabb::new(hb).unwrap(), pb);
        match want {
            Proximity::Overlapping(m) => prop_assert_eq!(aabb_mtv(&a, &b), Some(m)),
            _ => prop_assert_eq!(aabb_mtv(&a, &b), None),
        }
    }
}

// ------------------------------------------------------------ fixed scenes

#[test]
fn touching_boxes_are_not_pairs() {
    // A lattice of 16 px boxes sharing edges and corners: no pair; the same
    // lattice grown by one unit: every neighbour is a pair.
    let mut touching = Vec::new();
    let mut grown = Vec::new();
    for i in 0..12 {
        for j in 0..12 {
            let min = IVec2::new(i * px(16), j * px(16) - px(100));
            touching.push(Bounds::from_min_size(min, IVec2::splat(px(16))));
            grown.push(Bounds::from_min_size(min, IVec2::splat(px(16) + 1)));
        }
    }
    let mut out = Vec::new();
    brute_force(&[], &ided(0, &touching), &mut out);
    assert!(out.is_empty());
    check_scene(&[], &ided(0, &touching));
    // Half static, half dynamic.
    let (s, d) = touching.split_at(touching.len() / 2);
    check_scene(&ided(1000, s), &ided(0, d));
    brute_force(&[], &ided(0, &grown), &mut out);
    // Each box overlaps its right, lower and two lower diagonal neighbours.
    assert_eq!(out.len(), 11 * 12 * 2 + 11 * 11 * 2);
    check_scene(&[], &ided(0, &grown));
}

#[test]
fn world_bounds_and_extreme_sizes() {
    let lim = MAX_COORD + 2 * MAX_EXTENT;
    let big = 2 * MAX_EXTENT;
    let boxes = [
        Bounds::new(IVec2::splat(lim - big), IVec2::splat(lim)),
        Bounds::new(IVec2::splat(lim - 1), IVec2::splat(lim)),
        Bounds::new(IVec2::splat(lim - px(2)), IVec2::splat(lim)),
        Bounds::new(IVec2::splat(-lim), IVec2::splat(-lim + big)),
        Bounds::new(IVec2::splat(-lim), IVec2::splat(-lim + 1)),
        Bounds::new(IVec2::new(-lim, lim - px(4)), IVec2::new(-lim + px(4), lim)),
        Bounds::new(IVec2::new(-lim, lim - big), IVec2::new(-lim + big, lim)),
        // A 4096 px platform beside 2 px bullets.
        Bounds::new(IVec2::new(0, 0), IVec2::new(px(4096), px(16))),
        Bounds::new(IVec2::new(px(100), px(15)), IVec2::new(px(102), px(17))),
        Bounds::new(IVec2::new(px(4095), px(-1)), IVec2::new(px(4097), px(1))),
        Bounds::new(IVec2::new(px(4096), px(0)), IVec2::new(px(4098), px(2))),
        Bounds::new(IVec2::new(px(-1), px(-1)), IVec2::new(px(1), px(1))),
        // A tall column crossing many strips of the small level.
        Bounds::new(IVec2::new(px(50), px(-3000)), IVec2::new(px(60), px(3000))),
    ];
    let d = ided(0, &boxes);
    check_scene(&[], &d);
    for k in 0..boxes.len() {
        let (s, d): (Vec<_>, Vec<_>) = d.iter().partition(|e| (e.0 as usize + k) % 3 == 0);
        check_scene(&s, &d);
    }
}

/// One big box with the smallest id over hundreds of small ones with
/// shuffled ids: every pair lands in the first bucket of the output sort, in
/// sweep order, which is far from sorted (the one-thread sort gives up its
/// insertion sort there and must still be exact).
#[test]
fn crowded_first_id_sorts_like_brute_force() {
    let mut rng = SplitMix64(11);
    let mut dynamics = vec![(0, Bounds::new(IVec2::ZERO, IVec2::splat(px(600))))];
    let mut ids: Vec<u32> = (1..=400).collect();
    for i in (1..ids.len()).rev() {
        ids.swap(i, rng.range(0, i as i32) as usize);
    }
    for (k, &id) in ids.iter().enumerate() {
        let at = IVec2::new((k % 20) as i32 * 30 + 1, (k / 20) as i32 * 30 + 1);
        dynamics.push((id, Bounds::from_min_size(px(1) * at, IVec2::splat(px(8)))));
    }
    let mut expect = Vec::new();
    brute_force(&[], &dynamics, &mut expect);
    assert_eq!(expect.len(), 400, "the big box meets every small one");
    check_scene(&[], &dynamics);
    let statics: Vec<_> = dynamics[1..].to_vec();
    check_scene(&statics, &dynamics[..1]);
}

#[test]
fn standard_scene_over_ticks() {
    let mut scene = StandardScene::new(3000, 7);
    let mut bps = ISAS.map(|isa| BroadPhase::new(default_with(isa)));
    let mut expect = Vec::new();
    let mut got = Vec::new();
    let mut coherent_ticks = [0; ISAS.len()];
    for _ in 0..20 {
        scene.step();
        brute_force(&[], &scene.boxes, &mut expect);
        assert!(!expect.is_empty());
        for ((bp, isa), coherent) in bps.iter_mut().zip(ISAS).zip(&mut coherent_ticks) {
            bp.update_dynamic(&scene.boxes);
            *coherent += usize::from(!bp.stats().full_sort);
            bp.contacts_aabb(&mut got);
            assert_eq!(got, expect, "{isa:?}");
            for pool in pools() {
                pool.install(|| {
                    bp.update_dynamic_par(&scene.boxes);
                    bp.contacts_aabb_par(&mut got)
                });
                assert_eq!(
                    got,
                    expect,
                    "{isa:?}, {} threads",
                    pool.current_num_threads()
                );
            }
        }
    }
    // Every tick after the first reuses the previous order.
    assert_eq!(coherent_ticks, [19; ISAS.len()]);
}

#[test]
fn many_pairs_sort_in_parallel_like_on_one_thread() {
    // Enough pairs (about 4,700) that the parallel paths sort their output
    // in parallel, by id-range parts; the one-thread output is checked
    // against brute force on the last tick.
    // Both versions must also agree with each other on every tick.
    let mut scene = StandardScene::new(20_000, 5);
    let mut bps = ISAS.map(|isa| BroadPhase::new(default_with(isa)));
    let mut ones = [Vec::new(), Vec::new()];
    let (mut many, mut pairs) = (Vec::new(), Vec::new());
    for _ in 0..3 {
        scene.step();
        for ((bp, isa), one) in bps.iter_mut().zip(ISAS).zip(&mut ones) {
            bp.update_dynamic(&scene.boxes);
            bp.contacts_aabb(one);
            assert!(one.len() > 4096, "{} pairs", one.len());
            for pool in &pools()[1..] {
                let n = pool.current_num_threads();
                pool.install(|| {
                    bp.update_dynamic_par(&scene.boxes);
                    bp.contacts_aabb_par(&mut many);
                    bp.find_pairs_par(&mut pairs);
                });
                assert_eq!(&many, one, "{isa:?}, {n} threads");
                let ids = one.iter().map(|c| (c.0, c.1));
                assert!(pairs.iter().copied().eq(ids), "{isa:?}, {n} threads");
            }
        }
        assert_eq!(ones[0], ones[1], "{:?} against {:?}", ISAS[0], ISAS[1]);
    }
    let mut expect = Vec::new();
    brute_force(&[], &scene.boxes, &mut expect);
    for (one, isa) in ones.iter().zip(ISAS) {
        assert_eq!(one, &expect, "{isa:?}");
    }
}

#[test]
fn parallel_update_over_ticks() {
    // Only parallel updates, on 2 and 8 threads, small batches.
    for pool in &pools()[1..] {
        let mut scene = StandardScene::new(4000, 3);
        let mut bps = ISAS.map(|isa| {
            BroadPhase::new(BroadPhaseConfig {
                batch: 64,
                ..default_with(isa)
            })
        });
        let (mut expect, mut got) = (Vec::new(), Vec::new());
        for _ in 0..15 {
            scene.step();
            brute_force(&[], &scene.boxes, &mut expect);
            for (bp, isa) in bps.iter_mut().zip(ISAS) {
                pool.install(|| {
                    bp.update_dynamic_par(&scene.boxes);
                    bp.contacts_aabb_par(&mut got);
                });
                let n = pool.current_num_threads();
                assert_eq!(got, expect, "{isa:?}, {n} threads");
                assert!(!bp.stats().full_sort || expect.is_empty() || got.len() == expect.len());
            }
        }
    }
}

#[test]
fn no_allocation_per_tick_in_steady_state() {
    let mut scene = StandardScene::new(5000, 11);
    let statics: Vec<_> = (0..50)
        .map(|i| {
            let min = IVec2::new(i * px(97) % scene.side, i * px(61) % scene.side);
            (
                10_000 + i as u32,
                Bounds::from_min_size(min, IVec2::new(px(500), px(300))),
            )
        })
        .collect();
    let mut bps = ISAS.map(|isa| BroadPhase::new(default_with(isa)));
    for bp in &mut bps {
        bp.set_static(&statics);
    }
    let mut pairs = Vec::new();
    let mut contacts = Vec::new();
    let narrow = |_: u32, _: u32| Some(IVec2::ZERO);
    // One tick of the scene through both broad phases.
    let mut tick = |bps: &mut [BroadPhase], scene: &mut StandardScene| {
        scene.step();
        for bp in bps {
            bp.update_dynamic(&scene.boxes);
            bp.find_pairs(&mut pairs);
            bp.contacts_aabb(&mut contacts);
            bp.contacts_with(&narrow, &mut contacts);
        }
    };
    // Warm up until every buffer has reached its high-water mark.
    for _ in 0..300 {
        tick(&mut bps, &mut scene);
    }
    let n = allocations(|| {
        for _ in 0..50 {
            tick(&mut bps, &mut scene);
        }
    });
    assert_eq!(n, 0, "allocations in 50 ticks, {ISAS:?}");
}

#[test]
fn empty_sets() {
    for isa in ISAS {
        let mut bp = BroadPhase::new(default_with(isa));
        let mut out = vec![(1, 2)];
        bp.find_pairs(&mut out);
        assert!(out.is_empty(), "{isa:?}");
        bp.set_static(&ided(0, &[Bounds::new(IVec2::ZERO, IVec2::ONE)]));
        bp.find_pairs_par(&mut out);
        assert!(out.is_empty(), "{isa:?}");
        bp.update_dynamic(&[]);
        bp.find_pairs(&mut out);
        assert!(out.is_empty(), "{isa:?}");
        bp.update_dynamic(&ided(5, &[Bounds::new(IVec2::ZERO, IVec2::ONE)]));
        bp.find_pairs(&mut out);
        assert_eq!(out, vec![(0, 5)], "{isa:?}");
    }
}
