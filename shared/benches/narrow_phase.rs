//! Narrow phase cost in ns per pair for every pair of shape kinds, and one
//! tick of the warm-up room (`tick/warmup_room`).
//!
//! `cargo bench -p ledge-shared --bench narrow_phase`; `docs/PERFORMANCE.md`
//! has the table. Each pair is timed over a fixed batch of placements drawn
//! from a seeded generator so that about half overlap: the figure mixes the
//! early-out (apart) and full (overlapping) paths the way a real scene does.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use glam::IVec2;
use ledge_shared::fixed::px;
use ledge_shared::query::Contact;
use ledge_shared::shape::{Aabb, Circle, ConvexPolygon, Obb, Point, Segment};

/// Placements per batch.
const BATCH: usize = 1024;

/// A tiny deterministic generator (no `rand` in the sim's dependency tree).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) as u32
    }
    fn range(&mut self, lo: i32, hi: i32) -> i32 {
        lo + (self.next() % (hi - lo + 1) as u32) as i32
    }
}

trait Gen: Sized {
    fn gen(r: &mut Lcg) -> Self;
}
impl Gen for Point {
    fn gen(_: &mut Lcg) -> Self {
        Point
    }
}
impl Gen for Segment {
    fn gen(r: &mut Lcg) -> Self {
        let a = IVec2::new(r.range(-px(12), px(12)), r.range(-px(12), px(12)));
        let b = IVec2::new(r.range(-px(12), px(12)), r.range(-px(12), px(12)));
        Segment::new(a, if a == b { a + IVec2::ONE } else { b }).unwrap()
    }
}
impl Gen for Circle {
    fn gen(r: &mut Lcg) -> Self {
        Circle::new(r.range(px(2), px(12))).unwrap()
    }
}
impl Gen for Aabb {
    fn gen(r: &mut Lcg) -> Self {
        Aabb::new(IVec2::new(r.range(px(2), px(12)), r.range(px(2), px(12)))).unwrap()
    }
}
impl Gen for Obb {
    fn gen(r: &mut Lcg) -> Self {
        let half = IVec2::new(r.range(px(2), px(12)), r.range(px(2), px(12)));
        let dir = IVec2::new(r.range(-100, 100), r.range(1, 100));
        Obb::new(half, dir).unwrap()
    }
}
impl Gen for ConvexPolygon {
    fn gen(r: &mut Lcg) -> Self {
        // A hexagon with jittered radius: always convex.
        const DIRS: [(i32, i32); 6] = [
            (256, 0),
            (128, 222),
            (-128, 222),
            (-256, 0),
            (-128, -222),
            (128, -222),
        ];
        let s = r.range(8, 12);
        let pts: Vec<IVec2> = DIRS
            .iter()
            .map(|&(x, y)| IVec2::new(x * s, y * s))
            .collect();
        ConvexPolygon::new(&pts).unwrap()
    }
}

fn bench_pair<A: Gen + Contact<B>, B: Gen>(c: &mut Criterion, name: &str) {
    let mut r = Lcg(0x1ed9e);
    let cases: Vec<(A, IVec2, B, IVec2)> = (0..BATCH)
        .map(|_| {
            let a = A::gen(&mut r);
            let b = B::gen(&mut r);
            let pa = IVec2::new(r.range(-px(1000), px(1000)), r.range(-px(1000), px(1000)));
            let pb = pa + IVec2::new(r.range(-px(24), px(24)), r.range(-px(24), px(24)));
            (a, pa, b, pb)
        })
        .collect();
    let mut g = c.benchmark_group("narrow");
    g.throughput(Throughput::Elements(BATCH as u64));
    g.bench_function(name, |bench| {
        bench.iter(|| {
            let mut n = 0u32;
            for (a, pa, b, pb) in &cases {
                if black_box(a).contact(*pa, black_box(b), *pb).mtv().is_some() {
                    n += 1;
                }
            }
            n
        })
    });
    g.finish();
}

fn narrow(c: &mut Criterion) {
    bench_pair::<Point, Point>(c, "point_point");
    bench_pair::<Point, Segment>(c, "point_segment");
    bench_pair::<Point, Circle>(c, "point_circle");
    bench_pair::<Point, Aabb>(c, "point_aabb");
    bench_pair::<Point, Obb>(c, "point_obb");
    bench_pair::<Point, ConvexPolygon>(c, "point_polygon");
    bench_pair::<Segment, Segment>(c, "segment_segment");
    bench_pair::<Segment, Circle>(c, "segment_circle");
    bench_pair::<Segment, Aabb>(c, "segment_aabb");
    bench_pair::<Segment, Obb>(c, "segment_obb");
    bench_pair::<Segment, ConvexPolygon>(c, "segment_polygon");
    bench_pair::<Circle, Circle>(c, "circle_circle");
    bench_pair::<Circle, Aabb>(c, "circle_aabb");
    bench_pair::<Circle, Obb>(c, "circle_obb");
    bench_pair::<Circle, ConvexPolygon>(c, "circle_polygon");
    bench_pair::<Aabb, Aabb>(c, "aabb_aabb");
    bench_pair::<Aabb, Obb>(c, "aabb_obb");
    bench_pair::<Aabb, ConvexPolygon>(c, "aabb_polygon");
    bench_pair::<Obb, Obb>(c, "obb_obb");
    bench_pair::<Obb, ConvexPolygon>(c, "obb_polygon");
    bench_pair::<ConvexPolygon, ConvexPolygon>(c, "polygon_polygon");
}

/// One tick of the warm-up room under the scripted inputs (steady state:
/// the room is warmed up first so the buffers are allocated).
fn warmup_tick(c: &mut Criterion) {
    let mut world = ledge_shared::scene::warmup_room();
    for t in 0..600 {
        world.step(&[ledge_shared::scene::scripted_inputs(t)]);
    }
    let mut t = 600u64;
    c.bench_function("tick/warmup_room", |bench| {
        bench.iter(|| {
            t += 1;
            world.step(&[ledge_shared::scene::scripted_inputs(t)]).len()
        })
    });
}

criterion_group!(benches, narrow, warmup_tick);
criterion_main!(benches);
