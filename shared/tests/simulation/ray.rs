//! Property tests of the ray casts against the exact contact queries.
//!
//! Every check is exact (integer contact queries on integer points and
//! segments) except the "two units further along" check, which rounds a
//! point to the nearest unit with `f64` and allows for that with a unit disc.
//!
//! Lattice points: a ray whose `dir` is `k * d0` (`d0` primitive) passes
//! exactly through the integer points `origin + j * d0`, `j = 0..=k`; points
//! and prefixes of the ray ending there are exact probes of "before the hit"
//! and "at or after the hit".

use glam::{I64Vec2, IVec2};
use ledge_shared::query::contact::{contact, Contact, Proximity};
use ledge_shared::query::ray::{Ray, RayCast, RayHit, Toi};
use ledge_shared::shape::{Aabb, Circle, Convex, ConvexPolygon, Obb, Point, Segment};
use proptest::prelude::*;
use proptest::test_runner::TestCaseResult;

const CASES: u32 = 4000;

/// What the generic checks need to know about a shape kind.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Area {
    /// Point or segment: nothing is strictly inside.
    None,
    /// Exact toi (box, oriented box, polygon).
    Exact,
    /// Circle: toi is a lower bound.
    Circle,
}

fn gcd(a: i64, b: i64) -> i64 {
    let (mut a, mut b) = (a.abs(), b.abs());
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

fn wide(v: IVec2) -> I64Vec2 {
    I64Vec2::new(v.x as i64, v.y as i64)
}

/// `origin + dir * toi`, times `toi.den()`, exactly.
fn scaled_point(h: &RayHit) -> (i128, i128, i128) {
    let (n, d) = (h.toi.num() as i128, h.toi.den() as i128);
    let p = |o: i32, v: i32| o as i128 * d + v as i128 * n;
    (
        p(h.ray.origin.x, h.ray.dir.x),
        p(h.ray.origin.y, h.ray.dir.y),
        d,
    )
}

fn seg_contact<S>(shape: &S, pos: IVec2, from: IVec2, to: IVec2) -> Proximity
where
    Point: Contact<S>,
    Segment: Contact<S>,
{
    if from == to {
        contact(&Point, from, shape, pos)
    } else {
        contact(
            &Segment::new(IVec2::ZERO, to - from).unwrap(),
            from,
            shape,
            pos,
        )
    }
}

/// A sample of `0..=hi`: every value when few, else evenly spread plus the ends.
fn sample(hi: i64) -> Vec<i64> {
    if hi < 0 {
        return vec![];
    }
    if hi <= 24 {
        return (0..=hi).collect();
    }
    let mut v: Vec<i64> = (0..=16).map(|i| hi * i / 16).collect();
    v.push(hi - 1);
    v
}

/// All the checks on one cast. `pos` and `ray` are in world units and small
/// enough for the test arithmetic (|coords| < 2^40, segments within extent).
fn check<S>(shape: &S, pos: IVec2, ray: Ray, area: Area) -> TestCaseResult
where
    S: RayCast,
    Point: Contact<S>,
    Segment: Contact<S>,
    Circle: Contact<S>,
{
    let hit = shape.cast_ray(pos, &ray);
    let (o, d) = (ray.origin, ray.dir);
    let end = o + d;

    // The ray hits exactly when the closed segment touches the closed shape.
    let seg = seg_contact(shape, pos, o, end);
    prop_assert_eq!(
        hit.is_some(),
        seg != Proximity::Apart,
        "hit {:?} vs segment {:?}",
        hit,
        seg
    );
    // Casting the same segment backwards gives the same answer.
    let rev = shape.cast_ray(pos, &Ray::new(end, -d));
    prop_assert_eq!(hit.is_some(), rev.is_some());

    // Lattice structure of the ray.
    let k = gcd(d.x as i64, d.y as i64);
    let d0 = if k == 0 { IVec2::ZERO } else { d / k as i32 };
    let lattice = |j: i64| o + d0 * j as i32;

    let mut at_origin = contact(&Point, o, shape, pos);
    if area == Area::Circle && o == pos {
        // The contact query reports a point exactly at a circle's centre as
        // Touching (no push direction, zero-length feature); it is inside.
        at_origin = Proximity::Overlapping(IVec2::ZERO);
    }
    let Some(h) = hit else {
        // (4) A miss: no point along the ray is inside, or even touching.
        for j in sample(k) {
            prop_assert_eq!(contact(&Point, lattice(j), shape, pos), Proximity::Apart);
        }
        return Ok(());
    };
    prop_assert_eq!(h.ray, ray);
    prop_assert!(h.toi.den() > 0 && h.toi.num() <= h.toi.den());

    // Starting inside <=> the origin is strictly inside (or, with no area
    // and no direction, a zero-length ray on the shape); else on the surface
    // at toi 0 or outside before it.
    let inside = match at_origin {
        Proximity::Overlapping(_) => true,
        Proximity::Touching => area == Area::None && d == IVec2::ZERO,
        Proximity::Apart => false,
    };
    prop_assert_eq!(h.started_inside(), inside);
    if h.started_inside() {
        prop_assert_eq!(h.point(), o);
        prop_assert_eq!(h.distance(), 0);
        return Ok(());
    }
    if h.toi.is_zero() {
        // On the surface; or, for a circle, outside with the exact entry
        // closer than the lower bound's resolution.
        prop_assert!(
            at_origin == Proximity::Touching
                || (area == Area::Circle && at_origin == Proximity::Apart)
        );
        prop_assert!(h.normal != I64Vec2::ZERO);
        prop_assert_eq!(h.point(), o);
    } else {
        prop_assert_eq!(at_origin, Proximity::Apart);
        prop_assert!(h.normal != I64Vec2::ZERO);
        // The normal faces the ray (it was hit from outside).
        prop_assert!(
            h.normal.dot(wide(d)) <= 0,
            "normal {:?} dir {:?}",
            h.normal,
            d
        );
    }
    if area == Area::None && d != IVec2::ZERO {
        // No interior: the normal is never zero.
        prop_assert!(h.normal != I64Vec2::ZERO);
    }

    // (1) The reported point is within a unit per axis of o + d * toi and
    // not strictly inside; the surface is within reach of it.
    let p = h.point();
    let (sx, sy, den) = scaled_point(&h);
    prop_assert!((p.x as i128 * den - sx).abs() < den && (p.y as i128 * den - sy).abs() < den);
    prop_assert!(
        !matches!(contact(&Point, p, shape, pos), Proximity::Overlapping(_)),
        "point {:?} inside",
        p
    );
    let reach = if area == Area::Circle { 3 } else { 2 };
    prop_assert!(contact(&Circle::new(reach).unwrap(), p, shape, pos) != Proximity::Apart);

    // The distance is floor(toi * |dir|), exactly.
    let l2 = (d.x as i128 * d.x as i128 + d.y as i128 * d.y as i128) as u128;
    let dist = h.distance() as u128;
    let (num, dn) = (h.toi.num() as u128, h.toi.den() as u128);
    prop_assert!((dist * dn).pow(2) <= num * num * l2);
    prop_assert!(((dist + 1) * dn).pow(2) > num * num * l2);

    // (2) No earlier hit: lattice points strictly before toi are apart, and
    // so is the prefix of the ray up to the last of them.
    if k > 0 {
        // The first lattice index at or after toi: ceil(toi * k).
        let first_after = ((num * k as u128).div_ceil(dn)) as i64;
        let before = (first_after > 0).then(|| first_after - 1);
        if let Some(jb) = before {
            for j in sample(jb) {
                prop_assert_eq!(
                    contact(&Point, lattice(j), shape, pos),
                    Proximity::Apart,
                    "lattice {} of {}",
                    j,
                    k
                );
            }
            prop_assert_eq!(seg_contact(shape, pos, o, lattice(jb)), Proximity::Apart);
        }
        // Not later: the prefix up to the first lattice point at or after toi
        // (one more for circles, whose toi may be short by under 1 / |dir|^2)
        // touches the shape.
        let mut ja = first_after;
        if area == Area::Circle {
            ja = (ja + 1).min(k);
        }
        prop_assert!(seg_contact(shape, pos, o, lattice(ja)) != Proximity::Apart);
    }

    // (1, continued) Two units further along the ray is inside or touching,
    // when the chord there is long enough that this is a geometric fact (a
    // graze or a clipped corner has no "inside" two units on).
    if area != Area::None && d != IVec2::ZERO {
        let len = (l2 as f64).sqrt();
        let t = num as f64 / dn as f64;
        let t2 = t + 2.0 / len;
        let rev = rev.expect("the reverse cast hits too");
        let exit = 1.0 - rev.toi.num() as f64 / rev.toi.den() as f64;
        if t2 <= 1.0 && (exit - t2) * len >= 1.0 {
            let q = IVec2::new(
                (o.x as f64 + d.x as f64 * t2).round() as i32,
                (o.y as f64 + d.y as f64 * t2).round() as i32,
            );
            // The exact point is within 0.71 of q: a unit disc reaches it.
            prop_assert!(
                contact(&Circle::new(1).unwrap(), q, shape, pos) != Proximity::Apart,
                "2 units on: {:?}",
                q
            );
        }
    }

    // (3) Translation invariance, by a large offset.
    for s in [
        IVec2::new(1 << 30, -(1 << 30)),
        IVec2::new(-987_654_321, 123_456_789),
    ] {
        let moved = shape
            .cast_ray(pos + s, &Ray::new(o + s, d))
            .expect("a moved hit");
        prop_assert_eq!(moved.toi.num(), h.toi.num());
        prop_assert_eq!(moved.toi.den(), h.toi.den());
        prop_assert_eq!(moved.normal, h.normal);
        prop_assert_eq!(moved.point(), p + s);
        prop_assert_eq!(moved.distance(), h.distance());
    }
    Ok(())
}

/// The normal of a polygon-like hit is the (unit, for a box) normal of an
/// edge whose line passes exactly through `origin + dir * toi`.
fn check_edge_normal<C: Convex>(shape: &C, pos: IVec2, h: &RayHit, unit: bool) -> TestCaseResult {
    if h.normal == I64Vec2::ZERO {
        return Ok(());
    }
    let (sx, sy, den) = scaled_point(h);
    let n = shape.vertex_count();
    let on_edge = (0..n).any(|i| {
        let v = wide(shape.vertex(i) + pos);
        let e = wide(shape.vertex((i + 1) % n)) - wide(shape.vertex(i));
        let w = I64Vec2::new(e.y, -e.x);
        let want = if unit {
            I64Vec2::new(w.x.signum(), w.y.signum())
        } else {
            w
        };
        want == h.normal
            && (sx - v.x as i128 * den) * w.x as i128 + (sy - v.y as i128 * den) * w.y as i128 == 0
    });
    prop_assert!(
        on_edge,
        "normal {:?} is not an edge through the hit",
        h.normal
    );
    Ok(())
}

/// Exact bounds of the circle's toi: `num / a <= t_exact < (num + 1) / a`.
fn check_circle_toi(r: i32, pos: IVec2, h: &RayHit) -> TestCaseResult {
    if h.toi.is_zero() {
        return Ok(());
    }
    let o = wide(h.ray.origin - pos);
    let d = wide(h.ray.dir);
    let a = (d.x * d.x + d.y * d.y) as i128;
    prop_assert_eq!(h.toi.den() as i128, a);
    let b = (o.x * d.x + o.y * d.y) as i128;
    let cross = (o.x * d.y - o.y * d.x) as i128;
    let disc = (r as i128).pow(2) * a - cross * cross;
    prop_assert!(disc >= 0);
    // Entry t1 = (-b - sqrt(disc)) / a.
    let num = h.toi.num() as i128;
    // t1 >= num / a  <=>  -b - num >= sqrt(disc).
    prop_assert!(-b - num >= 0 && (-b - num).pow(2) >= disc);
    // t1 < (num + 1) / a  <=>  -b - num - 1 < sqrt(disc).
    let m = -b - num - 1;
    prop_assert!(m < 0 || m * m < disc);
    Ok(())
}

// ---- generators ----

fn ivec(lo: i32, hi: i32) -> impl Strategy<Value = IVec2> {
    (lo..=hi, lo..=hi).prop_map(|(x, y)| IVec2::new(x, y))
}

fn hull(mut pts: Vec<IVec2>) -> Vec<IVec2> {
    pts.sort_by_key(|p| (p.x, p.y));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: IVec2, a: IVec2, b: IVec2| {
        (a.x - o.x) as i64 * (b.y - o.y) as i64 - (a.y - o.y) as i64 * (b.x - o.x) as i64
    };
    let mut h: Vec<IVec2> = Vec::new();
    for pass in 0..2 {
        let start = h.len();
        let it: Vec<IVec2> = if pass == 0 {
            pts.clone()
        } else {
            pts.iter().rev().copied().collect()
        };
        for p in it {
            while h.len() >= start + 2 && cross(h[h.len() - 2], h[h.len() - 1], p) <= 0 {
                h.pop();
            }
            h.push(p);
        }
        h.pop();
    }
    h
}

fn aabb() -> impl Strategy<Value = Aabb> {
    ivec(1, 1200).prop_map(|h| Aabb::new(h).unwrap())
}

fn circle() -> impl Strategy<Value = Circle> {
    prop_oneof![1..=8, 1..=1200].prop_map(|r| Circle::new(r).unwrap())
}

fn obb() -> impl Strategy<Value = Obb> {
    prop_oneof![
        (ivec(1, 900), ivec(-60, 60)).prop_filter_map("zero dir", |(h, d)| Obb::new(h, d).ok()),
        (ivec(-500, 500), ivec(-500, 500))
            .prop_filter_map("parallel", |(u, v)| Obb::from_axes(u, v).ok()),
    ]
}

fn polygon() -> impl Strategy<Value = ConvexPolygon> {
    prop::collection::vec(ivec(-1200, 1200), 3..=8)
        .prop_filter_map("degenerate", |p| ConvexPolygon::new(&hull(p)).ok())
}

fn segment() -> impl Strategy<Value = Segment> {
    (ivec(-1200, 1200), ivec(-1200, 1200))
        .prop_filter_map("zero length", |(a, b)| Segment::new(a, b).ok())
}

/// How to build a ray around a shape's special points (vertices, extremes).
#[derive(Debug, Clone)]
struct RayGen {
    pos: IVec2,
    origin: (Option<usize>, IVec2),
    target: (Option<usize>, IVec2),
    /// 0: aim at the target; 1: aim past it (twice as far); 2: a lattice ray
    /// `k * d0` from the origin; 3: zero length.
    mode: u8,
    d0: IVec2,
    k: i32,
}

fn raygen() -> impl Strategy<Value = RayGen> {
    let pick = || {
        prop_oneof![
            (Just(None), ivec(-3000, 3000)),
            (any::<usize>().prop_map(Some), ivec(-1, 1)),
            (any::<usize>().prop_map(Some), Just(IVec2::ZERO)),
        ]
    };
    (
        ivec(-(1 << 20), 1 << 20),
        pick(),
        pick(),
        prop_oneof![4 => Just(0u8), 2 => Just(1u8), 3 => Just(2u8), 1 => Just(3u8)],
        ivec(-6, 6),
        1..=500,
    )
        .prop_map(|(pos, origin, target, mode, d0, k)| RayGen {
            pos,
            origin,
            target,
            mode,
            d0,
            k,
        })
}

impl RayGen {
    fn build(&self, special: &[IVec2]) -> (IVec2, Ray) {
        let at = |(i, v): (Option<usize>, IVec2)| match i {
            Some(i) => special[i % special.len()] + v,
            None => v,
        };
        let (o, t) = (at(self.origin), at(self.target));
        let dir = match self.mode {
            0 => t - o,
            1 => (t - o) * 2,
            2 => self.d0 * self.k,
            _ => IVec2::ZERO,
        };
        (self.pos, Ray::new(self.pos + o, dir))
    }
}

fn convex_special<C: Convex>(c: &C) -> Vec<IVec2> {
    let mut v: Vec<IVec2> = (0..c.vertex_count()).map(|i| c.vertex(i)).collect();
    let n = v.len();
    for i in 0..n {
        // Edge midpoints (rounded) and points on edge lines beyond the ends.
        let (a, b) = (v[i], v[(i + 1) % n]);
        v.push((a + b) / 2);
        v.push(a * 2 - b);
    }
    v.push(IVec2::ZERO);
    v
}

fn circle_special(c: &Circle) -> Vec<IVec2> {
    let r = c.radius();
    let mut v = vec![
        IVec2::ZERO,
        IVec2::new(r, 0),
        IVec2::new(-r, 0),
        IVec2::new(0, r),
        IVec2::new(0, -r),
        IVec2::new(r, r),
        IVec2::new(-r, r),
    ];
    // Pythagorean points on the circle when r is a multiple of 5.
    if r % 5 == 0 {
        let s = r / 5;
        v.extend([
            IVec2::new(3 * s, 4 * s),
            IVec2::new(-4 * s, 3 * s),
            IVec2::new(3 * s, -4 * s),
            IVec2::new(-4 * s, -3 * s),
        ]);
    }
    v
}

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, ..ProptestConfig::default() })]

    #[test]
    fn ray_vs_point(g in raygen()) {
        let (pos, ray) = g.build(&[IVec2::ZERO, IVec2::new(1, 0), IVec2::new(3, -2)]);
        check(&Point, pos, ray, Area::None)?;
    }

    #[test]
    fn ray_vs_segment(s in segment(), g in raygen()) {
        let (pos, ray) = g.build(&[s.a(), s.b(), s.a() * 2 - s.b(), s.b() * 2 - s.a(), (s.a() + s.b()) / 2]);
        check(&s, pos, ray, Area::None)?;
    }

    #[test]
    fn ray_vs_circle(c in circle(), g in raygen()) {
        let (pos, ray) = g.build(&circle_special(&c));
        check(&c, pos, ray, Area::Circle)?;
        if let Some(h) = c.cast_ray(pos, &ray) {
            check_circle_toi(c.radius(), pos, &h)?;
        }
    }

    #[test]
    fn ray_vs_aabb(b in aabb(), g in raygen()) {
        let (pos, ray) = g.build(&convex_special(&b));
        check(&b, pos, ray, Area::Exact)?;
        if let Some(h) = b.cast_ray(pos, &ray) {
            check_edge_normal(&b, pos, &h, true)?;
        }
    }

    #[test]
    fn ray_vs_obb(b in obb(), g in raygen()) {
        let (pos, ray) = g.build(&convex_special(&b));
        check(&b, pos, ray, Area::Exact)?;
        if let Some(h) = b.cast_ray(pos, &ray) {
            check_edge_normal(&b, pos, &h, false)?;
        }
    }

    #[test]
    fn ray_vs_polygon(p in polygon(), g in raygen()) {
        let (pos, ray) = g.build(&convex_special(&p));
        check(&p, pos, ray, Area::Exact)?;
        if let Some(h) = p.cast_ray(pos, &ray) {
            check_edge_normal(&p, pos, &h, false)?;
        }
    }

    /// Extreme inputs: shapes of the largest extent near the world's edge,
    /// rays spanning most of the `i32` range. No overflow (debug builds check
    /// it), the point is never inside, and it is close to the exact hit.
    #[test]
    fn extreme_coordinates(
        half in ivec(1, 1 << 26),
        u in ivec(-(1 << 26), 1 << 26),
        v in ivec(-(1 << 26), 1 << 26),
        r in 1..=(1 << 27),
        pos in ivec(-(1 << 30), 1 << 30),
        origin in ivec(-(1 << 30), 1 << 30),
        aim in ivec(-(1 << 27), 1 << 27),
        past in 1i32..=2,
    ) {
        let target = pos + aim;
        let fits = |v: i64| v.abs() <= i32::MAX as i64;
        let mut dir = (wide(target) - wide(origin)) * past as i64;
        // Halve until the direction and the end point fit an i32.
        while !(fits(dir.x) && fits(dir.y) && fits(origin.x as i64 + dir.x) && fits(origin.y as i64 + dir.y)) {
            dir /= 2;
        }
        let ray = Ray::new(origin, IVec2::new(dir.x as i32, dir.y as i32));
        fn far<S>(s: &S, pos: IVec2, ray: &Ray) -> TestCaseResult
        where
            S: RayCast,
            Point: Contact<S>,
        {
            if let Some(h) = s.cast_ray(pos, ray) {
                let p = h.point();
                if !h.started_inside() {
                    prop_assert!(!matches!(contact(&Point, p, s, pos), Proximity::Overlapping(_)));
                }
                let (sx, sy, den) = scaled_point(&h);
                prop_assert!((p.x as i128 * den - sx).abs() < den && (p.y as i128 * den - sy).abs() < den);
                let _ = h.distance();
                let back = s.cast_ray(pos, &Ray::new(ray.origin + ray.dir, -ray.dir));
                prop_assert!(back.is_some());
            }
            Ok(())
        }
        far(&Aabb::new(half).unwrap(), pos, &ray)?;
        far(&Circle::new(r).unwrap(), pos, &ray)?;
        if let Ok(b) = Obb::from_axes(u, v) {
            far(&b, pos, &ray)?;
        }
        if let Ok(s) = Segment::new(u, v) {
            far(&s, pos, &ray)?;
        }
        far(&Point, pos, &ray)?;
        let tri = ConvexPolygon::new(&[u, v, -u - v]).ok();
        if let Some(tri) = tri {
            far(&tri, pos, &ray)?;
        }
    }
}

#[test]
fn toi_order_is_exact() {
    let a = Toi::new(u64::MAX / 3, u64::MAX).unwrap();
    let b = Toi::new(1, 3).unwrap();
    assert_eq!(a, b);
    assert!(Toi::new(1, 3).unwrap() == Toi::new(5, 15).unwrap());
    assert!(Toi::new(u64::MAX / 3 - 1, u64::MAX).unwrap() < b);
}
