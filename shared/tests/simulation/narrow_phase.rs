//! Property tests of the narrow phase, for every ordered pair of shape kinds.
//!
//! Each generated case checks, against oracles in `common` that share no code
//! with the kernels:
//!
//! * classification (apart / touching / overlapping) against an exact
//!   configuration-space test (polygon-like pairs) or exact squared distances
//!   (pairs with a circle);
//! * for polygon-like pairs, the exact MTV: the push to the nearest face of
//!   the configuration-space obstacle, with the documented tie rule (smallest
//!   line angle, centred axes push up) and rounding rule (away from zero);
//!   minimality against every SAT axis of either shape, computed separately;
//! * separation: A moved by the MTV no longer overlaps, and is at most the
//!   rounding bound away: the MTV shortened by one unit per non-zero
//!   component (circles: two) overlaps again, and the gap measured in `f64`
//!   is at most `sqrt(2)` units (circles: `2 sqrt(2)`). (Moving back a fixed
//!   distance along the dominant axis instead is not a valid property: near a
//!   sharp corner it can leave through the other face; see
//!   `point_polygon.rs`'s `moving_back_along_one_axis_can_exit_elsewhere`.)
//!   The shortened MTV lies componentwise between zero and the exact push,
//!   so it is shorter than the penetration depth and must still overlap;
//! * for circle pairs, the MTV is within two units per axis of a true
//!   penetration vector, with the same signs (rounded away from zero);
//! * symmetry: `mtv(a, b) == -mtv(b, a)` and the same class, except the
//!   documented degenerate cases (same-kind SAT pairs centred on the chosen
//!   axis, coincident circle centres), which must both push up;
//! * translation invariance with both shapes moved anywhere in the world;
//! * the moved (touching or just-apart) configuration is classified
//!   correctly too.

use crate::common;

use common::*;
use core::fmt::Debug;
use glam::IVec2;
use ledge_shared::query::contact::{contact, Contact, Proximity};
use ledge_shared::shape::{Aabb, Circle, ConvexPolygon, Obb, Point, Segment, Shape, ShapeKind};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

/// Cases per ordered pair: 4096 by default, so the whole file runs in a few
/// seconds in the dev profile; `PROPTEST_CASES=100000` soaks (about 30 s).
fn config() -> Config {
    Config {
        cases: Config::default().cases.max(4096),
        failure_persistence: None,
        ..Config::default()
    }
}

fn verts(g: &Geom) -> &[glam::I64Vec2] {
    match g {
        Geom::Poly(v) => v,
        Geom::Disk(_) => unreachable!(),
    }
}

/// Each non-zero component moved `k` units towards zero (not past it).
fn shrink(m: IVec2, k: i32) -> IVec2 {
    let s = |c: i32| {
        if c > 0 {
            (c - k).max(0)
        } else {
            (c + k).min(0)
        }
    };
    IVec2::new(s(m.x), s(m.y))
}

fn len(m: IVec2) -> f64 {
    ((m.x as f64).powi(2) + (m.y as f64).powi(2)).sqrt()
}

/// Checks one placement against the oracles (class, exact or bounded MTV,
/// separation, tightness, minimality). Returns whether the answer is one of
/// the documented degenerate (non-antisymmetric) cases.
fn check_oracle<A, B>(
    a: &A,
    pa: IVec2,
    b: &B,
    pb: IVec2,
    got: Proximity,
) -> Result<bool, TestCaseError>
where
    A: Contact<B> + Geometry + Shape,
    B: Geometry + Shape,
{
    let (ga, gb) = (a.geom(), b.geom());
    if is_sat_kind(A::KIND) && is_sat_kind(B::KIND) {
        let (va, vb) = (verts(&ga), verts(&gb));
        // The kernel runs with the lower kind first and negates for the
        // reverse order, so the "push up" rule applies to the lower kind.
        let exp = if A::KIND <= B::KIND {
            sat_oracle(va, pa, vb, pb)
        } else {
            let mut e = sat_oracle(vb, pb, va, pa);
            e.mtv = e.mtv.map(|m| -m);
            e
        };
        prop_assert_eq!(class(got), exp.class, "classification");
        let Some(m) = got.mtv() else { return Ok(false) };
        prop_assert_eq!(Some(m), exp.mtv, "exact MTV (depth {})", exp.depth);
        // Separation, independently of the exact-MTV oracle.
        let k = obstacle(va, vb);
        let rel = |p: IVec2| glam::I64Vec2::new(p.x as i64 - pb.x as i64, p.y as i64 - pb.y as i64);
        prop_assert_ne!(
            classify_in_hull(&k, rel(pa + m)),
            Class::Overlapping,
            "MTV leaves an overlap"
        );
        prop_assert_ne!(
            class(a.contact(pa + m, b, pb)),
            Class::Overlapping,
            "kernel sees an overlap after the MTV"
        );
        prop_assert_eq!(
            classify_in_hull(&k, rel(pa + shrink(m, 1))),
            Class::Overlapping,
            "MTV overshoots by a unit or more on some axis"
        );
        let gap = sat_gap(va, pa + m, vb, pb);
        prop_assert!(gap <= 2f64.sqrt() + 1e-9, "gap {} after the MTV", gap);
        // Minimality: no SAT axis of either shape gives a shorter push, and the
        // shortest one is the oracle's depth.
        let mut shortest: Option<(u128, u128)> = None;
        for n in sat_axes(va).into_iter().chain(sat_axes(vb)) {
            let Some((o, l2)) = axis_push(va, pa, vb, pb, n) else {
                return Err(TestCaseError::fail(format!("axis {n} does not overlap")));
            };
            let d = o as f64 / (l2 as f64).sqrt();
            prop_assert!(
                len(m) <= d + 2f64.sqrt() + 1e-9 * d,
                "axis {} pushes {} < |mtv| {}",
                n,
                d,
                len(m)
            );
            if shortest.is_none_or(|(so, sl)| cmp_frac(o * o, l2, so * so, sl).is_lt()) {
                shortest = Some((o, l2));
            }
        }
        let (so, sl) = shortest.unwrap();
        let sd = so as f64 / (sl as f64).sqrt();
        prop_assert!(
            (sd - exp.depth).abs() <= 1e-9 * sd.max(1.0),
            "SAT axes depth {} vs obstacle depth {}",
            sd,
            exp.depth
        );
        prop_assert!(
            len(m) + 1e-9 * sd >= sd,
            "|mtv| {} below the depth {}",
            len(m),
            sd
        );
        Ok(A::KIND == B::KIND && exp.centred)
    } else {
        // Circle pairs, seen from the circle: `sign` turns A's MTV into the
        // circle's.
        let circle_first = A::KIND == ShapeKind::Circle;
        let view = |pa: IVec2| {
            if circle_first {
                circle_view(&ga, pa, &gb, pb)
            } else {
                circle_view(&gb, pb, &ga, pa)
            }
        };
        let sign = if circle_first { 1 } else { -1 };
        let (r, c, g) = view(pa);
        let exp = circle_oracle(r, c, &g);
        prop_assert_eq!(class(got), exp.class, "classification");
        let Some(m) = got.mtv() else { return Ok(false) };
        let mc = m * sign;
        if exp.coincident {
            prop_assert_eq!(
                mc,
                IVec2::new(0, -(r as i32)),
                "coincident centres push the circle up"
            );
        }
        let ok = exp.candidates.iter().any(|t| {
            [(mc.x, t[0]), (mc.y, t[1])].iter().all(|&(mi, ti)| {
                let mi = mi as f64;
                let tol = 1e-6 * ti.abs().max(1.0);
                (mi - ti).abs() <= 2.0 + tol
                    && (ti.abs() <= tol
                        || (mi.signum() == ti.signum() && mi.abs() + tol >= ti.abs()))
            })
        });
        prop_assert!(
            ok,
            "MTV {} (circle {}) not within 2 units, rounded away, of {:?}",
            m,
            mc,
            exp.candidates
        );
        let (r2, c2, g2) = view(pa + m);
        prop_assert_ne!(
            circle_oracle(r2, c2, &g2).class,
            Class::Overlapping,
            "MTV leaves an overlap"
        );
        prop_assert_ne!(
            class(a.contact(pa + m, b, pb)),
            Class::Overlapping,
            "kernel sees an overlap after the MTV"
        );
        let (r3, c3, g3) = view(pa + shrink(m, 2));
        prop_assert_eq!(
            circle_oracle(r3, c3, &g3).class,
            Class::Overlapping,
            "MTV overshoots by two units or more on some axis"
        );
        let gap = dist_f64(c2, &g2) - r2 as f64;
        prop_assert!(
            gap <= 2.0 * 2f64.sqrt() + 1e-6 * (r2 as f64),
            "gap {} after the MTV",
            gap
        );
        Ok(A::KIND == B::KIND && exp.coincident)
    }
}

/// Euclidean distance from `c` to a point, segment or polygon (0 inside).
fn dist_f64(c: glam::I64Vec2, g: &[glam::I64Vec2]) -> f64 {
    let n = g.len();
    if n >= 3 && (0..n).all(|i| cross(g[(i + 1) % n] - g[i], c - g[i]) >= 0) {
        return 0.0;
    }
    // A point is one degenerate edge, a segment one edge.
    let edges = if n <= 2 { 1 } else { n };
    (0..edges)
        .map(|i| {
            let (p, q) = (f(g[i]), f(g[(i + 1) % n]));
            let (ex, ey) = (q[0] - p[0], q[1] - p[1]);
            let (dx, dy) = (c.x as f64 - p[0], c.y as f64 - p[1]);
            let l2 = ex * ex + ey * ey;
            let t = if l2 == 0.0 {
                0.0
            } else {
                ((dx * ex + dy * ey) / l2).clamp(0.0, 1.0)
            };
            ((dx - t * ex).powi(2) + (dy - t * ey).powi(2)).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

/// All properties of one generated case of the ordered pair (A, B).
fn check_case<A, B>(cs: &Case<A, B>) -> Result<(), TestCaseError>
where
    A: Contact<B> + Geometry + Shape + Debug,
    B: Contact<A> + Geometry + Shape + Debug,
{
    let Case { a, pa, b, pb, .. } = cs;
    let (pa, pb) = (*pa, *pb);
    let ab = contact(a, pa, b, pb);
    let ba = contact(b, pb, a, pa);
    let degenerate = check_oracle(a, pa, b, pb, ab)?;
    // Symmetry.
    prop_assert_eq!(
        class(ab),
        class(ba),
        "classification depends on argument order"
    );
    if let (Some(m1), Some(m2)) = (ab.mtv(), ba.mtv()) {
        if degenerate {
            prop_assert_eq!(m1, m2, "degenerate case: both orders push up");
        } else {
            prop_assert_eq!(m1, -m2, "mtv(a, b) != -mtv(b, a)");
        }
    }
    // Translation invariance, anywhere in the world.
    let t = shift_of(cs);
    prop_assert_eq!(
        contact(a, pa + t, b, pb + t),
        ab,
        "not translation invariant (shift {})",
        t
    );
    prop_assert_eq!(
        contact(b, pb + t, a, pa + t),
        ba,
        "reverse not translation invariant (shift {})",
        t
    );
    // The separated configuration is a touch or a sliver apart: classify it too.
    if let Some(m) = ab.mtv() {
        let moved = contact(a, pa + m, b, pb);
        check_oracle(a, pa + m, b, pb, moved)?;
        prop_assert_eq!(
            class(contact(b, pb, a, pa + m)),
            class(moved),
            "moved: classification depends on order"
        );
        prop_assert_eq!(
            contact(a, pa + m + t, b, pb + t),
            moved,
            "moved: not translation invariant"
        );
    }
    Ok(())
}

macro_rules! pairs {
    ($($name:ident: $a:expr, $b:expr;)*) => {
        proptest! {
            #![proptest_config(config())]
            $(
                #[test]
                fn $name(cs in case($a, $b)) {
                    check_case(&cs)?;
                }
            )*
        }

        /// The generators reach every class for every ordered pair (so the
        /// properties above are not vacuous), and the pairs without area never
        /// overlap.
        #[test]
        fn generators_cover_every_class() {
            const SAMPLES: usize = 2000;
            let mut report = String::new();
            let mut bad: Vec<&str> = Vec::new();
            $(
                {
                    let mut runner = TestRunner::deterministic();
                    let strategy = case($a, $b);
                    let mut counts = [0usize; 3];
                    for _ in 0..SAMPLES {
                        let cs = strategy.new_tree(&mut runner).unwrap().current();
                        let i = match class(contact(&cs.a, cs.pa, &cs.b, cs.pb)) {
                            Class::Apart => 0,
                            Class::Touching => 1,
                            Class::Overlapping => 2,
                        };
                        counts[i] += 1;
                    }
                    report += &format!("{:<18} apart {:>4} touching {:>4} overlapping {:>4}\n", stringify!($name), counts[0], counts[1], counts[2]);
                    let name = stringify!($name);
                    let no_area = ["point_point", "point_segment", "segment_point"].contains(&name);
                    // At least 5% apart, 3% overlapping (none without area) and
                    // 1% exact touches (rare for circles against slanted edges).
                    let low = counts[0] < SAMPLES / 20
                        || counts[1] < SAMPLES / 100
                        || if no_area { counts[2] != 0 } else { counts[2] < SAMPLES * 3 / 100 };
                    if low {
                        bad.push(name);
                    }
                }
            )*
            println!("{report}");
            assert!(bad.is_empty(), "poor class coverage for {bad:?}:\n{report}");
        }
    };
}

pairs! {
    point_point: point(), point();
    point_segment: point(), segment();
    point_circle: point(), circle();
    point_aabb: point(), aabb();
    point_obb: point(), obb();
    point_polygon: point(), polygon();
    segment_point: segment(), point();
    segment_segment: segment(), segment();
    segment_circle: segment(), circle();
    segment_aabb: segment(), aabb();
    segment_obb: segment(), obb();
    segment_polygon: segment(), polygon();
    circle_point: circle(), point();
    circle_segment: circle(), segment();
    circle_circle: circle(), circle();
    circle_aabb: circle(), aabb();
    circle_obb: circle(), obb();
    circle_polygon: circle(), polygon();
    aabb_point: aabb(), point();
    aabb_segment: aabb(), segment();
    aabb_circle: aabb(), circle();
    aabb_aabb: aabb(), aabb();
    aabb_obb: aabb(), obb();
    aabb_polygon: aabb(), polygon();
    obb_point: obb(), point();
    obb_segment: obb(), segment();
    obb_circle: obb(), circle();
    obb_aabb: obb(), aabb();
    obb_obb: obb(), obb();
    obb_polygon: obb(), polygon();
    polygon_point: polygon(), point();
    polygon_segment: polygon(), segment();
    polygon_circle: polygon(), circle();
    polygon_aabb: polygon(), aabb();
    polygon_obb: polygon(), obb();
    polygon_polygon: polygon(), polygon();
}

// ------------------------------------------------------------- consistency

/// The same rectangle as every box-like kind.
#[derive(Debug, Clone)]
struct Rect {
    aabb: Aabb,
    obb: Obb,
    obb_turned: Obb,
    /// Vertices in the same order as the box's (top-left first).
    poly: ConvexPolygon,
    /// Any starting vertex, either winding.
    poly_any: ConvexPolygon,
}

fn rect() -> impl Strategy<Value = Rect> {
    (scale(), scale(), 0usize..4, any::<bool>()).prop_flat_map(|(sx, sy, rot, rev)| {
        (1..=sx, 1..=sy).prop_map(move |(hx, hy)| {
            let aabb = Aabb::new(IVec2::new(hx, hy)).unwrap();
            let obb = Obb::from_axes(IVec2::new(hx, 0), IVec2::new(0, hy)).unwrap();
            // A box turned by a multiple of 90 degrees is the same rectangle.
            let obb_turned = Obb::new(IVec2::new(hy, hx), IVec2::new(0, -7)).unwrap();
            let corners = [
                IVec2::new(-hx, -hy),
                IVec2::new(hx, -hy),
                IVec2::new(hx, hy),
                IVec2::new(-hx, hy),
            ];
            let poly = ConvexPolygon::new(&corners).unwrap();
            let mut any = corners.to_vec();
            if rev {
                any.reverse();
            }
            any.rotate_left(rot);
            let poly_any = ConvexPolygon::new(&any).unwrap();
            Rect {
                aabb,
                obb,
                obb_turned,
                poly,
                poly_any,
            }
        })
    })
}

fn near(r: i32) -> impl Strategy<Value = IVec2> {
    prop_oneof![(-r..=r, -r..=r), (-3i32..=3, -3i32..=3)].prop_map(|(x, y)| IVec2::new(x, y))
}

/// Asserts that `$a` against every form of the rectangle `$r` gives `$want`,
/// both ways round.
macro_rules! same_against_rect {
    ($a:expr, $pa:expr, $r:expr, $pr:expr, $want:expr, [$($field:ident),*]) => {
        $(
            prop_assert_eq!(contact($a, $pa, &$r.$field, $pr), $want, "against {}", stringify!($field));
            prop_assert_eq!(contact(&$r.$field, $pr, $a, $pa), $want.reversed(), "{} against", stringify!($field));
        )*
    };
}

proptest! {
    #![proptest_config(Config { cases: 512, ..config() })]

    /// Box against box is the same answer whether each box is an `Aabb`, an
    /// axis-aligned `Obb` (two ways) or a `ConvexPolygon` rectangle (any
    /// starting vertex and winding): the specialised pair agrees with SAT.
    #[test]
    fn rectangles_agree_across_kinds(r1 in rect(), r2 in rect(), d in scale().prop_flat_map(|s| near(2 * s + 2))) {
        let (p1, p2) = (IVec2::new(-5, 9), IVec2::new(-5, 9) + d);
        let want = contact(&r1.aabb, p1, &r2.aabb, p2);
        let a = [
            contact(&r1.obb, p1, &r2.obb, p2),
            contact(&r1.obb_turned, p1, &r2.obb_turned, p2),
            contact(&r1.poly, p1, &r2.poly, p2),
            contact(&r1.poly_any, p1, &r2.poly_any, p2),
            contact(&r1.poly, p1, &r2.poly_any, p2),
            contact(&r1.poly_any, p1, &r2.poly, p2),
        ];
        for (i, got) in a.iter().enumerate() {
            prop_assert_eq!(*got, want, "form {}", i);
        }
        // Mixed kinds: the lower kind's implementation is negated for the
        // reverse order, so only non-centred answers are antisymmetric; the
        // forward direction (lower kind first) must match the AABB answer.
        prop_assert_eq!(contact(&r1.aabb, p1, &r2.obb, p2), want);
        prop_assert_eq!(contact(&r1.aabb, p1, &r2.poly_any, p2), want);
        prop_assert_eq!(contact(&r1.obb_turned, p1, &r2.poly_any, p2), want);
    }

    /// Every other kind sees a rectangle the same whatever its kind. Circles
    /// pick the first of equally deep edges, so they are compared only with
    /// forms that list the vertices in the same order.
    #[test]
    fn others_see_rectangles_alike(
        r in rect(),
        p in point(), s in segment(), c in circle(),
        d in scale().prop_flat_map(|s| near(3 * s + 2)),
    ) {
        let (pr, po) = (IVec2::new(100, -3), IVec2::new(100, -3) + d);
        let want = contact(&p, po, &r.aabb, pr);
        same_against_rect!(&p, po, r, pr, want, [aabb, obb, obb_turned, poly, poly_any]);
        let want = contact(&s, po, &r.aabb, pr);
        same_against_rect!(&s, po, r, pr, want, [aabb, obb, obb_turned, poly, poly_any]);
        let want = contact(&c, po, &r.aabb, pr);
        same_against_rect!(&c, po, r, pr, want, [aabb, obb, poly]);
        prop_assert_eq!(class(contact(&c, po, &r.poly_any, pr)), class(want));
        prop_assert_eq!(class(contact(&c, po, &r.obb_turned, pr)), class(want));
    }

    /// A circle against a point is a circle of the same radius against a
    /// circle of radius zero: compare with an equal-radius split.
    #[test]
    fn circle_circle_depends_on_the_radius_sum(r1 in 1i32..1000, r2 in 1i32..1000, k in 0i32..1000, d in near(2100)) {
        let k = k % (r1 + r2 - 1).max(1);
        let (a, b) = (Circle::new(r1).unwrap(), Circle::new(r2).unwrap());
        let (a2, b2) = (Circle::new(r1 + r2 - 1 - k).unwrap(), Circle::new(1 + k).unwrap());
        let want = contact(&a, IVec2::ZERO, &b, d);
        prop_assert_eq!(contact(&a2, IVec2::ZERO, &b2, d), want);
        prop_assert_eq!(contact(&Circle::new(r1 + r2).unwrap(), IVec2::ZERO, &Point, d), want);
    }
}

/// Near the world edge: the largest positions and the largest shapes.
#[test]
fn extremes_of_the_numeric_model() {
    use ledge_shared::fixed::{MAX_COORD, MAX_EXTENT};
    let big = Aabb::new(IVec2::splat(MAX_EXTENT)).unwrap();
    let poly = ConvexPolygon::new(&[
        IVec2::new(-MAX_EXTENT, -MAX_EXTENT),
        IVec2::new(MAX_EXTENT, -MAX_EXTENT),
        IVec2::new(0, MAX_EXTENT),
    ])
    .unwrap();
    let circle = Circle::new(MAX_EXTENT).unwrap();
    let edge = IVec2::splat(MAX_COORD - MAX_EXTENT);
    let far = IVec2::splat(-(MAX_COORD - MAX_EXTENT));
    for d in [
        IVec2::ZERO,
        IVec2::new(1, 0),
        IVec2::new(-MAX_EXTENT, 3),
        IVec2::new(2 * MAX_EXTENT, 0),
        IVec2::new(2 * MAX_EXTENT - 1, 2 * MAX_EXTENT - 1),
    ] {
        for (p, q) in [(edge, edge - d), (far, far + d)] {
            let rel = q - p;
            let want = contact(&big, IVec2::ZERO, &poly, rel);
            assert_eq!(contact(&big, p, &poly, q), want);
            assert_eq!(contact(&poly, q, &big, p), want.reversed());
            let want = contact(&circle, IVec2::ZERO, &poly, rel);
            assert_eq!(contact(&circle, p, &poly, q), want);
            let want = contact(&circle, IVec2::ZERO, &circle, rel);
            assert_eq!(contact(&circle, p, &circle, q), want);
            let want = contact(&circle, IVec2::ZERO, &big, rel);
            assert_eq!(contact(&circle, p, &big, q), want);
        }
    }
    // Whole-world distances are apart without overflow.
    let corner = IVec2::splat(MAX_COORD);
    assert_eq!(contact(&big, corner, &poly, -corner), Proximity::Apart);
    assert_eq!(contact(&circle, -corner, &circle, corner), Proximity::Apart);
    assert_eq!(
        contact(
            &Segment::new(IVec2::ZERO, IVec2::splat(MAX_EXTENT)).unwrap(),
            corner,
            &circle,
            -corner
        ),
        Proximity::Apart
    );
}
