//! Swept collision (`query::sweep`) against exact oracles.
//!
//! * **Brute force**: small random scenes where `d = k * d0`, so the path
//!   passes exactly through the integer positions `start + j * d0`; each is
//!   classified with the contact query. Lattice positions before the toi
//!   never overlap; the first overlapping one is at or after it, and its
//!   predecessor at or before it (the path enters between the two).
//! * **Enters or not**: for polygon-like pairs the exact answer is the
//!   contact query between the obstacle and the convex hull of the mover at
//!   the start and the end (the swept shape): the path makes the shapes
//!   overlap exactly when that hull overlaps the obstacle. For circles, a
//!   distance in `f64`, skipping the (measure-zero) near-tangent cases.
//! * **No tunnelling** at world scale: projectiles crossing the whole world in
//!   one tick against one-pixel walls, tile rows and one-way platforms.
//! * **Tilemap** brute force against `Tilemap::box_contacts` along unit
//!   lattice paths, and hand cases for each rule.

use glam::{I64Vec2, IVec2};
use ledge_shared::fixed::{cross128, MAX_COORD};
use ledge_shared::query::contact::{contact, Contact, Proximity};
use ledge_shared::query::ray::Toi;
use ledge_shared::query::sweep::{
    advance, reflect, slide, sweep, sweep_tiles, Sweep, MAX_DISPLACEMENT,
};
use ledge_shared::shape::{Aabb, Circle, Convex, ConvexPolygon, Obb, Point, Segment};
use ledge_shared::tilemap::{ContactFlags, Slope, Tile, Tilemap};
use proptest::prelude::*;
use proptest::test_runner::TestCaseResult;

use crate::platformer_kit;
use crate::tile_kit::{against, first_pushed_back, pushes, random_map, v, w};
use platformer_kit::map_at;

// ------------------------------------------------------------------ helpers

fn overlaps<A: Contact<B>, B>(a: &A, pa: IVec2, b: &B, pb: IVec2) -> bool {
    matches!(contact(a, pa, b, pb), Proximity::Overlapping(_))
}

fn t64(t: Toi) -> f64 {
    t.num() as f64 / t.den() as f64
}

/// Any shape, for random scenes.
#[derive(Debug, Clone)]
enum Any {
    Pt(Point),
    Seg(Segment),
    Cir(Circle),
    Box(Aabb),
    Obb(Obb),
    Poly(ConvexPolygon),
}

/// Runs `$body` with `$x` bound to the concrete shape inside `$a`.
macro_rules! with_any {
    ($a:expr, |$x:ident| $body:expr) => {
        match $a {
            Any::Pt($x) => $body,
            Any::Seg($x) => $body,
            Any::Cir($x) => $body,
            Any::Box($x) => $body,
            Any::Obb($x) => $body,
            Any::Poly($x) => $body,
        }
    };
}

impl Any {
    /// Vertices (local, i64) of a polygon-like shape; `None` for a circle.
    fn verts(&self) -> Option<Vec<I64Vec2>> {
        fn of<C: Convex>(c: &C) -> Vec<I64Vec2> {
            (0..c.vertex_count())
                .map(|i| c.vertex(i).as_i64vec2())
                .collect()
        }
        match self {
            Any::Pt(s) => Some(of(s)),
            Any::Seg(s) => Some(of(s)),
            Any::Cir(_) => None,
            Any::Box(s) => Some(of(s)),
            Any::Obb(s) => Some(of(s)),
            Any::Poly(s) => Some(of(s)),
        }
    }

    fn radius(&self) -> Option<f64> {
        match self {
            Any::Cir(c) => Some(c.radius() as f64),
            _ => None,
        }
    }

    /// Point, or segment: no area.
    fn thin(&self) -> bool {
        matches!(self, Any::Pt(_) | Any::Seg(_))
    }
}

/// Strict convex hull (monotone chain), positively wound.
fn hull(pts: &[I64Vec2]) -> Vec<I64Vec2> {
    let mut p = pts.to_vec();
    p.sort_by_key(|q| (q.x, q.y));
    p.dedup();
    if p.len() <= 2 {
        return p;
    }
    let turn = |a: I64Vec2, b: I64Vec2, c: I64Vec2| cross128(b - a, c - b);
    let mut out: Vec<I64Vec2> = Vec::new();
    for pass in [p.clone(), p.iter().rev().copied().collect()] {
        let start = out.len();
        for q in pass {
            while out.len() >= start + 2 && turn(out[out.len() - 2], out[out.len() - 1], q) <= 0 {
                out.pop();
            }
            out.push(q);
        }
        out.pop();
    }
    out
}

/// The shape swept by a polygon-like `a` from `start` by `d`, placed at
/// `start`: the hull of its two end positions.
fn swept(a: &Any, d: IVec2) -> Any {
    let vs = a.verts().expect("polygon-like");
    let mut pts = vs.clone();
    pts.extend(vs.iter().map(|p| *p + d.as_i64vec2()));
    let h = hull(&pts);
    let iv = |p: I64Vec2| v(p.x as i32, p.y as i32);
    match h.len() {
        1 => Any::Pt(Point),
        2 => Any::Seg(Segment::new(iv(h[0]), iv(h[1])).unwrap()),
        _ => Any::Poly(ConvexPolygon::new(&h.iter().map(|p| iv(*p)).collect::<Vec<_>>()).unwrap()),
    }
}

/// Distance from `p` to the segment `[a, b]` (f64).
fn dist_ps(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (ex, ey) = (b.0 - a.0, b.1 - a.1);
    let l2 = ex * ex + ey * ey;
    let t = if l2 == 0.0 {
        0.0
    } else {
        (((p.0 - a.0) * ex + (p.1 - a.1) * ey) / l2).clamp(0.0, 1.0)
    };
    ((p.0 - a.0 - t * ex).powi(2) + (p.1 - a.1 - t * ey).powi(2)).sqrt()
}

fn seg_cross(a: (f64, f64), b: (f64, f64), c: (f64, f64), d: (f64, f64)) -> bool {
    let o = |p: (f64, f64), q: (f64, f64), r: (f64, f64)| {
        ((q.0 - p.0) * (r.1 - p.1) - (q.1 - p.1) * (r.0 - p.0)).signum()
    };
    o(a, b, c) * o(a, b, d) < 0.0 && o(c, d, a) * o(c, d, b) < 0.0
}

/// Distance between the segment `[p, q]` and the convex vertex list `vs`
/// (a point, a segment or a polygon), f64.
fn dist_seg_convex(p: (f64, f64), q: (f64, f64), vs: &[(f64, f64)]) -> f64 {
    let n = vs.len();
    if n >= 3 {
        let inside = |x: (f64, f64)| {
            (0..n).all(|i| {
                let (a, b) = (vs[i], vs[(i + 1) % n]);
                (b.0 - a.0) * (x.1 - a.1) - (b.1 - a.1) * (x.0 - a.0) >= 0.0
            })
        };
        if inside(p) || inside(q) {
            return 0.0;
        }
    }
    let mut best = f64::INFINITY;
    for &x in vs {
        best = best.min(dist_ps(x, p, q));
    }
    let edges: Vec<((f64, f64), (f64, f64))> = match n {
        1 => vec![],
        2 => vec![(vs[0], vs[1])],
        _ => (0..n).map(|i| (vs[i], vs[(i + 1) % n])).collect(),
    };
    for (a, b) in edges {
        if seg_cross(p, q, a, b) {
            return 0.0;
        }
        best = best.min(dist_ps(p, a, b)).min(dist_ps(q, a, b));
    }
    best
}

/// Whether the motion makes the shapes overlap (exact for polygon-like
/// pairs, f64 for circles: `None` when too close to tangent to tell, or for
/// a thin pair).
fn enters_oracle(a: &Any, start: IVec2, d: IVec2, b: &Any, pos_b: IVec2) -> Option<bool> {
    let f = |p: IVec2| (p.x as f64, p.y as f64);
    let place = |vs: Vec<I64Vec2>, at: IVec2| -> Vec<(f64, f64)> {
        vs.iter()
            .map(|p| ((p.x + at.x as i64) as f64, (p.y + at.y as i64) as f64))
            .collect()
    };
    let decide = |dist: f64, r: f64| ((dist - r).abs() > 1e-6).then_some(dist < r);
    match (a.radius(), b.radius()) {
        (Some(ra), Some(rb)) => {
            let dist = dist_ps(f(pos_b), f(start), f(start + d));
            decide(dist, ra + rb)
        }
        (Some(r), None) => {
            let vs = place(b.verts().unwrap(), pos_b);
            decide(dist_seg_convex(f(start), f(start + d), &vs), r)
        }
        (None, Some(r)) => {
            // The circle moves by -d against the mover.
            let vs = place(a.verts().unwrap(), start);
            decide(dist_seg_convex(f(pos_b), f(pos_b - d), &vs), r)
        }
        (None, None) => {
            if a.thin() && b.thin() {
                return None;
            }
            let h = swept(a, d);
            Some(with_any!(&h, |x| with_any!(b, |y| overlaps(
                x, start, y, pos_b
            ))))
        }
    }
}

/// What an independent computation says about the time of impact.
#[derive(Debug, Clone, Copy)]
enum TimeOracle {
    /// No independent answer (thin pair, or too close to call in f64).
    Unknown,
    /// The shapes overlap at the start.
    Inside,
    /// The motion never makes them overlap.
    Miss,
    /// Polygon-like pairs: the exact entry fraction `num / den`.
    Exact(i128, i128),
    /// Circle pairs: the entry time in f64.
    Approx(f64),
}

/// The exact interior entry of the relative path `t d` into the hull of
/// `{pos_b + b - start - a}` (written independently of the library: all
/// vertex differences, a monotone-chain hull, half-plane clipping).
fn poly_time(a: &[I64Vec2], start: IVec2, d: IVec2, b: &[I64Vec2], pos_b: IVec2) -> TimeOracle {
    let off = (pos_b - start).as_i64vec2();
    let pts: Vec<I64Vec2> = b
        .iter()
        .flat_map(|q| a.iter().map(move |p| *q + off - *p))
        .collect();
    let k = hull(&pts);
    if k.len() < 3 {
        return TimeOracle::Unknown;
    }
    let d = d.as_i64vec2();
    // Points t d with s_i + t k_i < 0 for every edge (outward normal w_i).
    let (mut lo_n, mut lo_d) = (-1i128, 0i128); // -infinity
    let (mut hi_n, mut hi_d) = (1i128, 1i128);
    let n = k.len();
    for i in 0..n {
        let e = k[(i + 1) % n] - k[i];
        let w = I64Vec2::new(e.y, -e.x);
        let s = -(k[i].x as i128 * w.x as i128 + k[i].y as i128 * w.y as i128);
        let kk = d.x as i128 * w.x as i128 + d.y as i128 * w.y as i128;
        if kk < 0 {
            // t > s / -kk
            if lo_d == 0 || s * lo_d > lo_n * -kk {
                (lo_n, lo_d) = (s, -kk);
            }
        } else if kk > 0 {
            // t < -s / kk
            if -s * hi_d < hi_n * kk {
                (hi_n, hi_d) = (-s, kk);
            }
        } else if s >= 0 {
            return TimeOracle::Miss;
        }
    }
    if lo_d == 0 || lo_n < 0 {
        return if hi_n > 0 {
            TimeOracle::Inside
        } else {
            TimeOracle::Miss
        };
    }
    if lo_n * hi_d < hi_n * lo_d {
        TimeOracle::Exact(lo_n, lo_d)
    } else {
        TimeOracle::Miss
    }
}

/// The first time the point `s + t d` comes within `r` of the convex vertex
/// list `vs` (f64), or `Inside` / `Miss` / `Unknown` near a tie.
fn round_time(s: (f64, f64), d: (f64, f64), vs: &[(f64, f64)], r: f64) -> TimeOracle {
    let e = (s.0 + d.0, s.1 + d.1);
    let gap = dist_seg_convex(s, s, vs) - r;
    if gap.abs() < 1e-7 {
        return TimeOracle::Unknown;
    }
    if gap < 0.0 {
        return TimeOracle::Inside;
    }
    let path = dist_seg_convex(s, e, vs) - r;
    if path.abs() < 1e-7 {
        return TimeOracle::Unknown;
    }
    if path > 0.0 {
        return TimeOracle::Miss;
    }
    let mut best = f64::INFINITY;
    // Vertex discs.
    for v in vs {
        let o = (s.0 - v.0, s.1 - v.1);
        let a = d.0 * d.0 + d.1 * d.1;
        let b = o.0 * d.0 + o.1 * d.1;
        let c = o.0 * o.0 + o.1 * o.1 - r * r;
        let disc = b * b - a * c;
        if a > 0.0 && disc >= 0.0 {
            let t = (-b - disc.sqrt()) / a;
            if (0.0..=1.0).contains(&t) {
                best = best.min(t);
            }
        }
    }
    // Offset edges (both sides; only the outer side of a polygon matters,
    // the inner ones are never reached first from outside).
    let n = vs.len();
    let edges = if n == 2 {
        1
    } else if n >= 3 {
        n
    } else {
        0
    };
    for i in 0..edges {
        let (a, b) = (vs[i], vs[(i + 1) % n]);
        let (ex, ey) = (b.0 - a.0, b.1 - a.1);
        let l = (ex * ex + ey * ey).sqrt();
        for sign in [1.0, -1.0] {
            let (nx, ny) = (sign * ey / l, -sign * ex / l);
            let f0 = (s.0 - a.0) * nx + (s.1 - a.1) * ny;
            let fd = d.0 * nx + d.1 * ny;
            if f0 >= r && fd < 0.0 {
                let t = (r - f0) / fd;
                let (px, py) = (s.0 + t * d.0 - a.0, s.1 + t * d.1 - a.1);
                let u = (px * ex + py * ey) / l;
                if (0.0..=1.0).contains(&t) && (-1e-9..=l + 1e-9).contains(&u) {
                    best = best.min(t);
                }
            }
        }
    }
    if best.is_finite() {
        TimeOracle::Approx(best)
    } else {
        TimeOracle::Unknown
    }
}

/// The independent time of impact of a small scene.
fn time_oracle(a: &Any, start: IVec2, d: IVec2, b: &Any, pos_b: IVec2) -> TimeOracle {
    let f = |p: IVec2| (p.x as f64, p.y as f64);
    let place = |vs: Vec<I64Vec2>, at: IVec2| -> Vec<(f64, f64)> {
        vs.iter()
            .map(|p| ((p.x + at.x as i64) as f64, (p.y + at.y as i64) as f64))
            .collect()
    };
    match (a.radius(), b.radius()) {
        (Some(ra), Some(rb)) => round_time(f(start), f(d), &[f(pos_b)], ra + rb),
        (Some(r), None) => round_time(f(start), f(d), &place(b.verts().unwrap(), pos_b), r),
        (None, Some(r)) => round_time(f(pos_b), f(-d), &place(a.verts().unwrap(), start), r),
        (None, None) => {
            if a.thin() && b.thin() {
                TimeOracle::Unknown
            } else {
                poly_time(&a.verts().unwrap(), start, d, &b.verts().unwrap(), pos_b)
            }
        }
    }
}

// ----------------------------------------------------------- generators

fn small_seg() -> impl Strategy<Value = Segment> {
    ((-12i32..=12, -12i32..=12), (-12i32..=12, -12i32..=12))
        .prop_filter("distinct", |(a, b)| a != b)
        .prop_map(|(a, b)| Segment::new(v(a.0, a.1), v(b.0, b.1)).unwrap())
}

fn small_poly(max: usize) -> impl Strategy<Value = ConvexPolygon> {
    proptest::collection::vec((-12i32..=12, -12i32..=12), 3..12).prop_filter_map(
        "a hull with area",
        move |pts| {
            let ps: Vec<I64Vec2> = pts.iter().map(|p| w(p.0 as i64, p.1 as i64)).collect();
            let mut h = hull(&ps);
            h.truncate(max);
            if h.len() < 3 {
                return None;
            }
            ConvexPolygon::new(
                &h.iter()
                    .map(|p| v(p.x as i32, p.y as i32))
                    .collect::<Vec<_>>(),
            )
            .ok()
        },
    )
}

fn small_obb() -> impl Strategy<Value = Obb> {
    ((-8i32..=8, -8i32..=8), (-8i32..=8, -8i32..=8)).prop_filter_map("axes", |(u, vv)| {
        Obb::from_axes(v(u.0, u.1), v(vv.0, vv.1)).ok()
    })
}

/// A small shape of any kind (moving polygons have at most six vertices so
/// that their swept hull fits a polygon).
fn small_any() -> impl Strategy<Value = Any> {
    prop_oneof![
        Just(Any::Pt(Point)),
        small_seg().prop_map(Any::Seg),
        (1i32..=12).prop_map(|r| Any::Cir(Circle::new(r).unwrap())),
        (1i32..=12, 1i32..=12).prop_map(|(x, y)| Any::Box(Aabb::new(v(x, y)).unwrap())),
        small_obb().prop_map(Any::Obb),
        small_poly(6).prop_map(Any::Poly),
    ]
}

// --------------------------------------------------------- the core check

/// All the checks on one small sweep with `d = k * d0`.
#[allow(clippy::too_many_arguments)]
fn check<A, B>(
    a: &A,
    start: IVec2,
    d0: IVec2,
    k: i32,
    b: &B,
    pos_b: IVec2,
    oracle: Option<bool>,
    time: TimeOracle,
    thin: bool,
) -> TestCaseResult
where
    A: Sweep<B> + Contact<B>,
{
    let d = d0 * k;
    let dd = d.as_i64vec2();
    let hit = sweep(a, start, dd, b, pos_b);
    // The independent time: exact for polygon-like pairs, a close lower
    // bound for circles.
    match (time, hit) {
        (TimeOracle::Inside, h) => prop_assert!(h.is_some_and(|h| h.started_inside()), "{:?}", h),
        (TimeOracle::Miss, h) => prop_assert!(h.is_none(), "{:?}", h),
        (TimeOracle::Exact(n, dn), h) => {
            let h = h.expect("a hit");
            prop_assert!(!h.started_inside());
            prop_assert_eq!(
                h.toi.num() as i128 * dn,
                n * h.toi.den() as i128,
                "toi {:?} vs {}/{}",
                h.toi,
                n,
                dn
            );
        }
        (TimeOracle::Approx(t), h) => {
            // Never later; short by less than 1 / |d|^2 (a vertex disc; an
            // offset edge is far closer).
            let h = h.expect("a hit");
            prop_assert!(!h.started_inside());
            let got = t64(h.toi);
            let slack = 1.0 / dd.as_dvec2().length_squared() + 1e-9;
            prop_assert!(got <= t + 1e-9 && t - got <= slack, "toi {} vs {}", got, t);
        }
        (TimeOracle::Unknown, _) => {}
    }
    let lat = |j: i32| start + d0 * j;
    let ov: Vec<bool> = (0..=k).map(|j| overlaps(a, lat(j), b, pos_b)).collect();
    if ov[0] {
        let h = hit.expect("a start inside is a hit");
        prop_assert!(h.started_inside(), "{:?}", h);
        prop_assert_eq!(h.stop, start);
        prop_assert_eq!(advance(start, dd, Some(&h)), start);
        return Ok(());
    }
    let first = ov.iter().position(|o| *o);
    let Some(h) = hit else {
        prop_assert!(
            first.is_none(),
            "no hit, but lattice {:?} of {} overlaps",
            first,
            k
        );
        if let Some(e) = oracle {
            prop_assert!(!e, "no hit, but the swept shape overlaps");
        }
        prop_assert_eq!(advance(start, dd, None), start + d);
        return Ok(());
    };
    prop_assert!(!h.started_inside());
    prop_assert!(h.normal != I64Vec2::ZERO);
    if let Some(e) = oracle {
        prop_assert!(e, "hit {:?}, but the swept shape does not overlap", h);
    }
    let t = t64(h.toi);
    let exact_pt = (
        start.x as f64 + d.x as f64 * t,
        start.y as f64 + d.y as f64 * t,
    );
    // Never later than the first overlapping lattice position, and the
    // lattice before the toi is clear.
    if let Some(j1) = first {
        let tj = j1 as f64 / k as f64;
        prop_assert!(
            h.toi <= Toi::new(j1 as u64, k as u64).unwrap(),
            "toi {} after lattice {}",
            t,
            tj
        );
        prop_assert!(
            t >= (j1 as f64 - 1.0) / k as f64 - 1e-9,
            "toi {} before the predecessor of {}",
            t,
            tj
        );
        // The stop is within a lattice step of the brute force's stop.
        let pred = lat(j1 as i32 - 1);
        let slack = d0.abs() + IVec2::splat(if thin { 2 } else { 1 });
        prop_assert!(
            (h.stop - pred).abs().cmple(slack).all(),
            "stop {} vs brute {}",
            h.stop,
            pred
        );
    }
    for (j, o) in ov.iter().enumerate() {
        if Toi::new(j as u64, k as u64).unwrap() < h.toi {
            prop_assert!(!o, "lattice {} before toi {} overlaps", j, t);
        }
    }
    // Entering: the normal faces the motion.
    prop_assert!(
        h.normal.dot(dd) < 0 || (h.toi.is_zero() && h.normal.dot(dd) <= 0),
        "normal {} d {}",
        h.normal,
        d
    );
    // The stop position: never overlapping, near the exact point, within the
    // path's box.
    prop_assert!(!overlaps(a, h.stop, b, pos_b), "stop {} overlaps", h.stop);
    let reach = if thin { 2.0 } else { 1.0 };
    prop_assert!(
        (h.stop.x as f64 - exact_pt.0).abs() <= reach
            && (h.stop.y as f64 - exact_pt.1).abs() <= reach,
        "stop {} vs exact {:?}",
        h.stop,
        exact_pt
    );
    if !thin {
        let (lo, hi) = (start.min(start + d), start.max(start + d));
        prop_assert!(h.stop.cmpge(lo).all() && h.stop.cmple(hi).all());
    }
    prop_assert_eq!(advance(start, dd, Some(&h)), h.stop);
    // Stopped means blocked: the same move again from the stop is a hit
    // that does not start inside (at once, or, when the stop was rounded
    // aside off a slanted face, a little later), or, where it was rounded a
    // unit aside past a corner, passes beside it: never through it.
    match sweep(a, h.stop, dd, b, pos_b) {
        Some(g) => prop_assert!(!g.started_inside(), "again from {}: {:?}", h.stop, g),
        None => {
            for j in 0..=k {
                prop_assert!(
                    !overlaps(a, h.stop + d0 * j, b, pos_b),
                    "again from {}: passed through",
                    h.stop
                );
            }
        }
    }
    // Translation invariance, by large offsets.
    for s in [v(1 << 30, -(1 << 30)), v(-987_654_321, 123_456_789)] {
        let m = sweep(a, start + s, dd, b, pos_b + s).expect("a moved hit");
        prop_assert_eq!(m.toi.num(), h.toi.num());
        prop_assert_eq!(m.toi.den(), h.toi.den());
        prop_assert_eq!(m.normal, h.normal);
        prop_assert_eq!(m.stop, h.stop + s);
    }
    Ok(())
}

/// A random small scene: mover, obstacle, start, obstacle position, d0, k.
fn scene() -> impl Strategy<Value = (Any, Any, IVec2, IVec2, IVec2, i32)> {
    (
        small_any(),
        small_any(),
        (-40i32..=40, -40i32..=40),
        (-6i32..=6, -6i32..=6),
        (-3i32..=3, -3i32..=3),
        1i32..=32,
    )
        .prop_map(|(a, b, s, p, d0, k)| (a, b, v(s.0, s.1), v(p.0, p.1), v(d0.0, d0.1), k))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10_000, ..ProptestConfig::default() })]

    /// Every pair of kinds against the brute force and the swept-shape oracle.
    #[test]
    fn agrees_with_brute_force((a, b, start, pos_b, d0, k) in scene()) {
        let oracle = enters_oracle(&a, start, d0 * k, &b, pos_b);
        let time = time_oracle(&a, start, d0 * k, &b, pos_b);
        let thin = a.thin() && b.thin();
        with_any!(&a, |x| with_any!(&b, |y| check(x, start, d0, k, y, pos_b, oracle, time, thin)))?;
    }

    /// Aimed at the obstacle, so that most cases hit.
    #[test]
    fn aimed_sweeps_agree(
        (a, b, start, pos_b, _, _) in scene(),
        k in 1i32..=40,
        aim in (-3i32..=3, -3i32..=3),
    ) {
        let to = pos_b - start + v(aim.0, aim.1);
        let g = gcd(to.x, to.y).max(1);
        let d0 = to / g;
        let k = k.min(2 * g + 2);
        prop_assume!(d0 != IVec2::ZERO);
        let oracle = enters_oracle(&a, start, d0 * k, &b, pos_b);
        let time = time_oracle(&a, start, d0 * k, &b, pos_b);
        let thin = a.thin() && b.thin();
        with_any!(&a, |x| with_any!(&b, |y| check(x, start, d0, k, y, pos_b, oracle, time, thin)))?;
    }
}

fn gcd(a: i32, b: i32) -> i32 {
    let (mut a, mut b) = (a.abs(), b.abs());
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

// ------------------------------------------------------------- hand cases

#[test]
fn box_lands_on_a_box() {
    let mover = Aabb::new(v(512, 1024)).unwrap();
    let floor = Aabb::new(v(4096, 128)).unwrap();
    let h = sweep(&mover, v(100, -5000), w(300, 6000), &floor, v(0, 0)).unwrap();
    // Bottom from -3976 to the top face at -128: 3848 of 6000.
    assert_eq!(h.toi, Toi::new(3848, 6000).unwrap());
    assert_eq!(h.normal, w(0, -1));
    // x = 100 + 192.4 rounds towards the start.
    assert_eq!(h.stop, v(292, -1152));
    assert_eq!(
        advance(v(100, -5000), w(300, 6000), Some(&h)),
        v(292, -1152)
    );
    // Resting there and sliding: nothing; pushed into it: toi 0.
    assert_eq!(sweep(&mover, h.stop, w(9000, 0), &floor, v(0, 0)), None);
    let again = sweep(&mover, h.stop, w(300, 6000), &floor, v(0, 0)).unwrap();
    assert_eq!(
        (again.toi, again.normal, again.stop),
        (Toi::ZERO, w(0, -1), h.stop)
    );
    // Ending exactly on it is no hit.
    assert_eq!(
        sweep(&mover, v(0, -2152), w(0, 1000), &floor, v(0, 0)),
        None
    );
}

#[test]
fn corner_ties_pick_the_head_on_face() {
    let f = Aabb::new(v(10, 1)).unwrap();
    let b = Aabb::new(v(2, 2)).unwrap();
    // Reaches x = -12 and y = 7 together at t = 1/2: the x face is met
    // more head-on (8 against 4).
    let h = sweep(&b, v(-16, 5), w(8, 4), &f, v(0, 10)).unwrap();
    assert_eq!((h.toi, h.normal), (Toi::new(1, 2).unwrap(), w(-1, 0)));
    let h = sweep(&b, v(-14, 3), w(4, 8), &f, v(0, 10)).unwrap();
    assert_eq!((h.toi, h.normal), (Toi::new(1, 2).unwrap(), w(0, -1)));
    // Exactly diagonal: the upward face.
    let h = sweep(&b, v(-16, 3), w(8, 8), &f, v(0, 10)).unwrap();
    assert_eq!((h.toi, h.normal), (Toi::new(1, 2).unwrap(), w(0, -1)));
}

#[test]
fn slanted_faces_round_to_the_outer_side() {
    // A 45-degree diamond (|x| + |y| <= 10); a 2x2 box moving right meets
    // the face y - x = 10 with its corner (x + 1, y - 1) at x = -5.
    let dia = Obb::from_axes(v(5, -5), v(5, 5)).unwrap();
    let b = Aabb::new(v(1, 1)).unwrap();
    let h = sweep(&b, v(-8, 7), w(7, 0), &dia, v(0, 0)).unwrap();
    assert_eq!(
        (h.toi, h.normal, h.stop),
        (Toi::new(3, 7).unwrap(), w(-1, 1), v(-5, 7))
    );
    assert!(!overlaps(&b, h.stop, &dia, v(0, 0)));
    // The position a unit further would overlap.
    assert!(overlaps(&b, h.stop + v(1, 0), &dia, v(0, 0)));
}

#[test]
fn circles_against_corners_stay_outside() {
    let c = Circle::new(300).unwrap();
    let sq = Aabb::new(v(1000, 1000)).unwrap();
    for dx in [-7i64, -3, 0, 2, 5, 11] {
        for dy in [-9i64, -1, 0, 4, 13] {
            let start = v(2000 + dx as i32 * 37, 1900 + dy as i32 * 41);
            let d = w(-1500 - dx * 11, -1300 + dy * 7);
            let Some(h) = c.sweep(start, d, &sq, v(0, 0)) else {
                continue;
            };
            assert!(!overlaps(&c, h.stop, &sq, v(0, 0)), "{start} {d}: {h:?}");
            // Reversed roles: the square moving into the circle.
            let r = sq.sweep(v(0, 0), -d, &c, start).unwrap();
            assert_eq!((r.toi, r.normal), (h.toi, -h.normal));
            assert!(!overlaps(&sq, r.stop, &c, start));
        }
    }
}

#[test]
fn thin_pairs_cross_and_never_stop_on_the_line() {
    let wall = Segment::new(v(0, -100), v(0, 100)).unwrap();
    // A point crossing x = 0 at t = 1/4.
    let h = sweep(&Point, v(-10, 3), w(40, 8), &wall, v(0, 0)).unwrap();
    assert_eq!((h.toi, h.normal), (Toi::new(1, 4).unwrap(), w(-1, 0)));
    assert_eq!(h.stop, v(-1, 5));
    // From the stop, the same motion is stopped again, still on its side.
    let h2 = sweep(&Point, h.stop, w(40, 8), &wall, v(0, 0)).unwrap();
    assert!(h2.stop.x < 0);
    // Along the line, or leaving it, is no hit.
    assert_eq!(sweep(&Point, v(0, -200), w(0, 400), &wall, v(0, 0)), None);
    assert_eq!(sweep(&Point, v(0, 5), w(10, 0), &wall, v(0, 0)), None);
    // A point through a point; a segment onto a point.
    let h = sweep(&Point, v(-6, -3), w(12, 6), &Point, v(0, 0)).unwrap();
    assert_eq!(
        (h.toi, h.normal, h.stop),
        (Toi::new(1, 2).unwrap(), w(-2, -1), v(-1, 0))
    );
    let bar = Segment::new(v(-5, 0), v(5, 0)).unwrap();
    let h = sweep(&bar, v(2, -20), w(0, 40), &Point, v(0, 0)).unwrap();
    assert_eq!(
        (h.toi, h.normal, h.stop),
        (Toi::new(1, 2).unwrap(), w(0, -1), v(2, -1))
    );
    // Crossing segments are an overlap (area pair): stop touching.
    let post = Segment::new(v(0, 0), v(0, 30)).unwrap();
    let h = sweep(&bar, v(0, -20), w(0, 40), &post, v(0, 0)).unwrap();
    assert_eq!(
        (h.toi, h.normal, h.stop),
        (Toi::new(1, 2).unwrap(), w(0, -1), v(0, 0))
    );
    assert_eq!(contact(&bar, h.stop, &post, v(0, 0)), Proximity::Touching);
}

#[test]
fn reflect_and_slide_are_exact_on_axes() {
    assert_eq!(reflect(v(300, 700), w(0, -1)), v(300, -700));
    assert_eq!(reflect(v(-300, 700), w(1, 0)), v(300, 700));
    assert_eq!(slide(v(300, 700), w(0, -1)), v(300, 0));
    assert_eq!(slide(v(300, -700), w(0, -1)), v(300, -700));
    // Slanted: away from the surface, never into it.
    for (vel, n) in [
        (v(7, 3), w(-1, -2)),
        (v(100, 1), w(-3, -1)),
        (v(-5, 9), w(2, -7)),
    ] {
        let r = reflect(vel, n);
        let s = slide(vel, n);
        assert!(
            r.as_i64vec2().dot(n) >= -vel.as_i64vec2().dot(n),
            "{vel} {n} {r}"
        );
        assert!(s.as_i64vec2().dot(n) >= 0, "{vel} {n} {s}");
    }
}

// -------------------------------------------------- world-scale tunnelling

/// A projectile of any kind.
fn projectile() -> impl Strategy<Value = Any> {
    prop_oneof![
        Just(Any::Pt(Point)),
        (1i32..=1 << 16, -(1i32 << 16)..=1 << 16)
            .prop_map(|(x, y)| Any::Seg(Segment::new(v(-x, -y), v(x, y)).unwrap())),
        (1i32..=1 << 16).prop_map(|r| Any::Cir(Circle::new(r).unwrap())),
        (1i32..=1 << 16, 1i32..=1 << 16).prop_map(|(x, y)| Any::Box(Aabb::new(v(x, y)).unwrap())),
    ]
}

/// A wall one pixel (256 units) thick, tall, across the x axis at its origin:
/// a box, an oriented box turned a little, or a slanted quad.
fn wall() -> impl Strategy<Value = Any> {
    let tall = 1i32 << 26;
    prop_oneof![
        Just(Any::Box(Aabb::new(v(128, tall)).unwrap())),
        (1i32..=64).prop_map(move |dy| Any::Obb(Obb::from_axes(v(128, 0), v(dy, tall)).unwrap())),
        (-100i32..=100).prop_map(move |s| {
            Any::Poly(
                ConvexPolygon::new(&[
                    v(-128 + s, -tall),
                    v(128 + s, -tall),
                    v(128 - s, tall),
                    v(-128 - s, tall),
                ])
                .unwrap(),
            )
        }),
    ]
}

fn no_tunnel<A: Sweep<B> + Contact<B>, B>(
    a: &A,
    start: IVec2,
    d: I64Vec2,
    b: &B,
    pos_b: IVec2,
) -> TestCaseResult {
    let h = sweep(a, start, d, b, pos_b);
    let Some(h) = h else {
        return Err(TestCaseError::fail(format!("passed through: {start} {d}")));
    };
    prop_assert!(!h.started_inside());
    prop_assert!(!overlaps(a, h.stop, b, pos_b), "stop {} overlaps", h.stop);
    // Still on the start's side of the wall.
    prop_assert!(
        (h.stop.x < pos_b.x) == (start.x < pos_b.x),
        "stop {} wall {}",
        h.stop,
        pos_b
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    /// A projectile crossing the whole world in one tick never passes a
    /// one-pixel wall, in either direction, anywhere.
    #[test]
    fn projectiles_never_tunnel_through_walls(
        a in projectile(),
        b in wall(),
        wall_x in -(MAX_COORD / 2)..=MAX_COORD / 2,
        y in -(1i32 << 24)..=1 << 24,
        dy in -(1i64 << 24)..=1 << 24,
        left in any::<bool>(),
        gap in 1i32 << 18..=1 << 20,
    ) {
        let pos_b = v(wall_x, 0);
        // From one end of the world to the other.
        let (sx, ex) = if left {
            (-MAX_COORD + (1 << 17), MAX_COORD - (1 << 17))
        } else {
            (MAX_COORD - (1 << 17), -MAX_COORD + (1 << 17))
        };
        let sx = if left { sx.min(wall_x - gap) } else { sx.max(wall_x + gap) };
        let start = v(sx, y);
        let d = w(ex as i64 - sx as i64, dy);
        prop_assert!(d.x.abs() <= MAX_DISPLACEMENT);
        with_any!(&a, |x| with_any!(&b, |y| no_tunnel(x, start, d, y, pos_b)))?;
    }
}

// ------------------------------------------------------------------ tilemap

const T: i32 = 16;

/// The map as text (the `map_at` characters), for failure messages.
fn render(m: &Tilemap) -> String {
    let mut out = format!("origin {} size {}:", m.origin(), m.tile_size());
    for (i, t) in m.tiles().iter().enumerate() {
        if i % m.width() as usize == 0 {
            out.push_str(" | ");
        }
        out.push(match t {
            Tile::Empty => '.',
            Tile::Solid => '#',
            Tile::OneWay => '-',
            Tile::Hazard => '^',
            Tile::Slope(Slope::Right45) => '/',
            Tile::Slope(Slope::Left45) => '\\',
            Tile::Slope(Slope::RightLow22) => 'a',
            Tile::Slope(Slope::RightHigh22) => 'b',
            Tile::Slope(Slope::LeftHigh22) => 'c',
            Tile::Slope(Slope::LeftLow22) => 'd',
        });
    }
    out
}

#[test]
fn tile_floor_wall_and_seams() {
    let m = map_at(
        v(-1000, 300),
        256,
        &["........", "......#.", "......#.", "########"],
    );
    let b = Aabb::new(v(100, 100)).unwrap();
    let top = 300 + 3 * 256;
    // Falling onto the floor, landing across a seam: one hit, up.
    let start = v(-1000 + 256 * 2, 0);
    let h = sweep_tiles(&m, &b, start, w(0, 5000), ContactFlags::default()).unwrap();
    assert_eq!(h.hit.normal, w(0, -1));
    assert_eq!(h.hit.stop, v(start.x, top - 100));
    assert_eq!(h.kind, Tile::Solid);
    // Sunk one unit into the floor and sliding right across every seam: the
    // wall is the first thing hit, never a seam.
    let sunk = v(-1000 + 120, top - 99);
    let h = sweep_tiles(&m, &b, sunk, w(3000, 0), ContactFlags::default()).unwrap();
    assert_eq!(h.hit.normal, w(-1, 0));
    assert_eq!(h.tile, v(6, 2));
    assert_eq!(h.hit.stop, v(-1000 + 6 * 256 - 100, top - 99));
    // Resting exactly on the floor and sliding under the wall's overhang: no
    // hit until the wall's left face.
    let rest = v(-1000 + 120, top - 100);
    let h = sweep_tiles(&m, &b, rest, w(3000, 0), ContactFlags::default()).unwrap();
    assert_eq!((h.tile, h.hit.normal), (v(6, 2), w(-1, 0)));
    // Sliding left on the floor: clear (past the map's left edge).
    assert_eq!(
        sweep_tiles(&m, &b, rest, w(-3000, 0), ContactFlags::default()),
        None
    );
    // Sweeping again from a stop with the same motion: toi 0, same normal.
    let h = sweep_tiles(&m, &b, start, w(0, 5000), ContactFlags::default()).unwrap();
    let again = sweep_tiles(&m, &b, h.hit.stop, w(0, 5000), ContactFlags::default()).unwrap();
    assert_eq!(
        (again.hit.toi, again.hit.normal, again.hit.stop),
        (Toi::ZERO, w(0, -1), h.hit.stop)
    );
    // Sliding along it from there (the normal component removed): clear to the wall.
    let s = slide(v(0, 5000), h.hit.normal);
    assert_eq!(s, v(0, 0));
}

#[test]
fn tile_one_way_platforms() {
    let m = map_at(v(0, 0), T, &["......", "..--..", "......", "......"]);
    let b = Aabb::new(v(5, 4)).unwrap();
    let top = T;
    let flags = ContactFlags::default();
    // From above: stops on the top line.
    let h = sweep_tiles(&m, &b, v(40, 0), w(0, 40), flags).unwrap();
    assert_eq!(
        (h.hit.normal, h.hit.stop, h.kind),
        (w(0, -1), v(40, top - 4), Tile::OneWay)
    );
    // Resting on it and pushed down: toi 0.
    let h = sweep_tiles(&m, &b, v(40, top - 4), w(3, 2), flags).unwrap();
    assert_eq!(h.hit.toi, Toi::ZERO);
    // From below, upwards through it: nothing; starting below the line
    // (straddling) and moving down: nothing; dropping through: nothing.
    assert_eq!(sweep_tiles(&m, &b, v(40, 50), w(0, -45), flags), None);
    assert_eq!(sweep_tiles(&m, &b, v(40, top - 3), w(0, 30), flags), None);
    let drop = ContactFlags { drop_through: true };
    assert_eq!(sweep_tiles(&m, &b, v(40, 0), w(0, 40), drop), None);
    // Sideways over it: nothing; just beside it: nothing.
    assert_eq!(sweep_tiles(&m, &b, v(0, top - 4), w(90, 0), flags), None);
    assert_eq!(sweep_tiles(&m, &b, v(2 * T - 5, 0), w(0, 40), flags), None);
}

#[test]
fn tile_slopes_and_plateaus() {
    // Floor, a 45-degree ramp up to a plateau, and a 22.5-degree ramp down.
    let m = map_at(
        v(0, 0),
        T,
        &["..........", "..../##cd.", "...//####.", "##########"],
    );
    let b = Aabb::new(v(3, 5)).unwrap();
    let flags = ContactFlags::default();
    // Falling onto the middle of the first '/' (column 3, row 2): the foot
    // at x = 3T + 8 meets the surface y = 3T - 8.
    // Slopes push straight up (Mario style): the normal is up.
    let h = sweep_tiles(&m, &b, v(3 * T + 8, 0), w(0, 100), flags).unwrap();
    assert_eq!((h.tile, h.hit.normal), (v(3, 2), w(0, -1)));
    assert_eq!(h.hit.stop, v(3 * T + 8, 3 * T - 8 - 5));
    assert!(pushes(&m, h.hit.stop, v(3, 5), h.hit.stop - v(3 * T + 8, 0), flags).is_empty());
    // Diagonally down-left onto it: stopped on the surface, rounded to its
    // outer side.
    let s0 = v(4 * T + 3, 5);
    let h = sweep_tiles(&m, &b, s0, w(-17, 40), flags).unwrap();
    assert_eq!(h.hit.normal, w(0, -1));
    assert!(pushes(&m, h.hit.stop, v(3, 5), h.hit.stop - s0, flags).is_empty());
    // Walking on the floor into the ramp: not stopped; the contact rules
    // lift the box onto the ramp (as at low speed).
    let s0 = v(T, 3 * T - 5);
    assert_eq!(sweep_tiles(&m, &b, s0, w(40, 0), flags), None);
    let lifted = pushes(&m, s0 + v(40, 0), v(3, 5), v(40, 0), flags);
    assert!(
        lifted.iter().any(|c| c.mtv.x == 0 && c.mtv.y < 0),
        "{lifted:?}"
    );
    // Falling onto the 22.5-degree ramp: never below the surface.
    for x in 7 * T..9 * T {
        let h = sweep_tiles(&m, &b, v(x, 0), w(0, 200), flags).unwrap();
        assert!(
            pushes(&m, h.hit.stop, v(3, 5), h.hit.stop - v(x, 0), flags).is_empty(),
            "x {x}: {h:?}"
        );
        // And one unit lower something pushes: it stopped on the surface.
        assert!(
            !pushes(
                &m,
                h.hit.stop + v(0, 1),
                v(3, 5),
                h.hit.stop + v(0, 1) - v(x, 0),
                flags
            )
            .is_empty(),
            "x {x}"
        );
    }
    // From the plateau walking left onto the top of the ramp: the plateau's
    // top does not hold a foot over the ramp, nothing is hit walking left.
    assert_eq!(sweep_tiles(&m, &b, v(6 * T, T - 5), w(-20, 0), flags), None);
}

#[test]
fn tile_boxes_resting_on_ramps_never_fall_through() {
    // Both 22.5-degree ramps and both 45-degree slopes, on solid ground.
    let m = map_at(v(-5, 3), T, &["..........", ".ab/..\\cd.", "##########"]);
    let flags = ContactFlags::default();
    for half in [v(1, 1), v(3, 5), v(8, 2)] {
        let b = Aabb::new(half).unwrap();
        for x in m.origin().x + T..m.origin().x + 9 * T {
            let Some(y) = m.ground_below(v(x, m.origin().y), 4 * T) else {
                continue;
            };
            let rest = v(x, y - half.y);
            if !pushes(&m, rest, half, IVec2::ZERO, flags).is_empty() {
                continue;
            }
            // Falling fast from a resting position: stopped where it is
            // (at once, or, on a 22.5-degree ramp whose line runs half a
            // unit under the step, a fraction of a unit down, the stop
            // rounded to the outer side of the surface: maybe a unit along
            // it), and not pushed there.
            let h = sweep_tiles(&m, &b, rest, w(3, 5000), flags)
                .unwrap_or_else(|| panic!("x {x}: fell through"));
            assert_eq!((h.hit.stop.y, h.hit.normal), (rest.y, w(0, -1)), "x {x}");
            assert!((h.hit.stop.x - rest.x).abs() <= 1, "x {x}: {h:?}");
            assert!(h.hit.toi < Toi::new(1, 5000).unwrap(), "x {x}: {h:?}");
            assert!(
                pushes(&m, h.hit.stop, half, h.hit.stop - rest, flags).is_empty(),
                "x {x}: {h:?}"
            );
        }
    }
}

#[test]
fn tile_hazards_are_ignored() {
    let m = map_at(v(0, 0), T, &["....", "^^^^", "...."]);
    let b = Aabb::new(v(4, 4)).unwrap();
    assert_eq!(
        sweep_tiles(&m, &b, v(20, 0), w(0, 60), ContactFlags::default()),
        None
    );
}

/// Unit lattice directions.
fn unit_dir() -> impl Strategy<Value = IVec2> {
    prop_oneof![
        Just(v(1, 0)),
        Just(v(-1, 0)),
        Just(v(0, 1)),
        Just(v(0, -1)),
        Just(v(1, 1)),
        Just(v(-1, 1)),
        Just(v(1, -1)),
        Just(v(-1, -1)),
    ]
}

proptest! {
    // Random dense maps: many random starts are not clean and are skipped.
    #![proptest_config(ProptestConfig { cases: 8000, max_global_rejects: 200_000, ..ProptestConfig::default() })]

    /// Along unit lattice paths every position is an integer and every tile
    /// line is crossed at a lattice position: the sweep stops no later than
    /// the first position the contact rules push back against the motion,
    /// at a clean position, the position after its hit is pushed, and it
    /// reports nothing when no position along the way is pushed back.
    #[test]
    fn tiles_agree_with_box_contacts(
        m in random_map(Just(T)),
        half in (1i32..=14, 1i32..=14),
        start in (-30i32..=150, -30i32..=110),
        d0 in unit_dir(),
        k in 1i32..=90,
        drop in any::<bool>(),
    ) {
        let half = v(half.0, half.1);
        let start = v(start.0, start.1);
        let flags = ContactFlags { drop_through: drop };
        prop_assume!(pushes(&m, start, half, IVec2::ZERO, flags).is_empty());
        let b = Aabb::new(half).unwrap();
        let d = d0 * k;
        let hit = sweep_tiles(&m, &b, start, d.as_i64vec2(), flags);
        let first = first_pushed_back(&m, start, half, d0, k, flags);
        match (hit, first) {
            (None, None) => {}
            (None, Some(j)) => prop_assert!(false, "no hit, but lattice {} of {} is pushed; {}", j, k, render(&m)),
            (Some(h), first) => {
                let h = h.hit;
                prop_assert!(!h.started_inside());
                if let Some(j) = first {
                    prop_assert!(h.toi <= Toi::new(j as u64, k as u64).unwrap(), "toi {:?} after {}", h.toi, j);
                }
                let moved = h.stop - start;
                // The stop is clean: nothing pushes it back against the
                // motion. (Pushes along or across the motion, say a block
                // under a ramp the box's body has entered through a culled
                // face, are the contact pass's, at any speed.)
                let p = pushes(&m, h.stop, half, moved, flags);
                let back = p.iter().any(|c| against(c, d0));
                prop_assert!(!back, "stop {} pushed back: {:?}; {}", h.stop, p, render(&m));
                // The hit is real: the motion is pushed at it (a hit exactly
                // at a lattice position, say a foot entering a column from
                // the left, which is in it from the column's line on) or
                // right after it (the next lattice position); or, moving
                // diagonally, a corner
                // clips a tile between two lattice positions (seen at half
                // the scale: the map doubled); or a slope's surface line
                // runs up to half a unit above its unit-column steps between
                // integer columns, and the foot two units under the stop
                // (one for that, one for rounding) is pushed.
                // (A hit at toi 1: the end itself is pushed, and the stop is
                // short of it.)
                let (num, den) = (h.toi.num() as i128, h.toi.den() as i128);
                let jat = ((num * k as i128 + den - 1) / den) as i32;
                let jn = ((num * k as i128 / den) as i32 + 1).min(k);
                let double = Tilemap::new(m.origin() * 2, 2 * T, 7, 5, m.tiles().to_vec()).unwrap();
                let mid = d0 * (2 * jn - 1);
                prop_assert!(
                    !pushes(&m, start + d0 * jat, half, d0 * jat, flags).is_empty()
                        || !pushes(&m, start + d0 * jn, half, d0 * jn, flags).is_empty()
                        || !pushes(&double, start * 2 + mid, half * 2, mid, flags).is_empty()
                        || !pushes(&m, h.stop + v(0, 2), half, moved + v(0, 2), flags).is_empty(),
                    "hit {:?} but lattice {} of {} is clean; {}", h, jn, k, render(&m)
                );
                let moved_map = Tilemap::new(m.origin() + v(7 * T, -3 * T), T, 7, 5, m.tiles().to_vec()).unwrap();
                let tr2 = sweep_tiles(&moved_map, &b, start + v(7 * T, -3 * T), d.as_i64vec2(), flags).unwrap();
                prop_assert_eq!(tr2.hit.toi, h.toi);
                prop_assert_eq!(tr2.hit.normal, h.normal);
                prop_assert_eq!(tr2.hit.stop, h.stop + v(7 * T, -3 * T));
            }
        }
    }

    /// A box crossing the whole world in one tick never passes a one-tile
    /// floor (solid or one-way, from above) or a wall.
    #[test]
    fn boxes_never_tunnel_through_tile_rows(
        half in (1i32..=1 << 14, 1i32..=1 << 14),
        ox in -(MAX_COORD / 2)..=MAX_COORD / 2,
        x in 256i32..3 * 256,
        kind in proptest::sample::select(vec!['#', '-']),
        down in any::<bool>(),
        drift in -(1i64 << 7)..=1 << 7,
    ) {
        let half = v(half.0, half.1);
        let b = Aabb::new(half).unwrap();
        let row: String = std::iter::repeat_n(kind, 4).collect();
        let m = map_at(v(ox, 0), 256, &["....", &row, "...."]);
        let flags = ContactFlags::default();
        if down || kind == '-' {
            // Falling from the top of the world to the bottom.
            let start = v(ox + x, -MAX_COORD + (1 << 16));
            let d = w(drift, 2 * MAX_COORD as i64 - (1 << 17));
            let h = sweep_tiles(&m, &b, start, d, flags).expect("stopped by the floor");
            prop_assert_eq!(h.hit.normal, w(0, -1));
            prop_assert_eq!(h.hit.stop.y + half.y, 256);
        } else {
            // Rising from the bottom of the world through the solid row.
            let start = v(ox + x, MAX_COORD - (1 << 16));
            let d = w(drift, -(2 * MAX_COORD as i64) + (1 << 17));
            let h = sweep_tiles(&m, &b, start, d, flags).expect("stopped by the ceiling");
            prop_assert_eq!(h.hit.normal, w(0, 1));
            prop_assert_eq!(h.hit.stop.y - half.y, 512);
        }
        // Sideways through a wall column.
        let m = map_at(v(ox, 0), 256, &[".#..", ".#..", ".#.."]);
        let start = v(-MAX_COORD + (1 << 16), 300);
        let h = sweep_tiles(&m, &b, start, w(2 * MAX_COORD as i64 - (1 << 17), 0), flags).expect("stopped by the wall");
        prop_assert_eq!((h.hit.normal, h.hit.stop.x + half.x), (w(-1, 0), ox + 256));
    }
}
