//! Helpers for the narrow-phase property tests: shape generators and exact
//! oracles written from scratch, sharing no code with `query::contact`.
//!
//! * Polygon-like pairs (point, segment, box, oriented box, polygon): the
//!   oracle builds the configuration-space obstacle `K = B (-) A` (convex hull
//!   of all vertex differences) and classifies the relative position against
//!   it; the exact expected MTV is the push to the nearest face of `K`, with
//!   the documented tie rule and rounding rule applied.
//! * Pairs with a circle: exact squared-distance classification, and the
//!   true penetration vector(s) in `f64` for the tolerance checks.
#![allow(dead_code)]

use core::cmp::Ordering;
use glam::{I64Vec2, IVec2};
use ledge_shared::fixed::{cmp_mul_u128, line_order, MAX_COORD};
use ledge_shared::query::contact::Proximity;
use ledge_shared::shape::{Aabb, Circle, ConvexPolygon, Obb, Point, Segment, Shape, ShapeKind};
use proptest::prelude::*;

// ---------------------------------------------------------------- geometry

/// A shape as plain data, read through the public API only.
#[derive(Debug, Clone)]
pub enum Geom {
    /// Vertices in local units: one (point), two (segment) or a positively
    /// wound convex polygon.
    Poly(Vec<I64Vec2>),
    /// A disk of this radius around the origin.
    Disk(i64),
}

/// Converts a shape to [`Geom`].
pub trait Geometry {
    /// The plain description.
    fn geom(&self) -> Geom;
}

fn w(v: IVec2) -> I64Vec2 {
    I64Vec2::new(v.x as i64, v.y as i64)
}

impl Geometry for Point {
    fn geom(&self) -> Geom {
        Geom::Poly(vec![I64Vec2::ZERO])
    }
}
impl Geometry for Segment {
    fn geom(&self) -> Geom {
        Geom::Poly(vec![w(self.a()), w(self.b())])
    }
}
impl Geometry for Aabb {
    fn geom(&self) -> Geom {
        let h = w(self.half());
        Geom::Poly(vec![
            I64Vec2::new(-h.x, -h.y),
            I64Vec2::new(h.x, -h.y),
            I64Vec2::new(h.x, h.y),
            I64Vec2::new(-h.x, h.y),
        ])
    }
}
impl Geometry for Obb {
    fn geom(&self) -> Geom {
        let (u, v) = (w(self.u()), w(self.v()));
        Geom::Poly(vec![-u - v, u - v, u + v, -u + v])
    }
}
impl Geometry for ConvexPolygon {
    fn geom(&self) -> Geom {
        Geom::Poly(self.vertices().iter().map(|v| w(*v)).collect())
    }
}
impl Geometry for Circle {
    fn geom(&self) -> Geom {
        Geom::Disk(self.radius() as i64)
    }
}

/// Largest absolute local coordinate of a shape.
pub fn reach<S: Shape>(s: &S) -> i64 {
    let (lo, hi) = s.local_bounds();
    [lo.x, lo.y, hi.x, hi.y]
        .iter()
        .map(|c| (*c as i64).abs())
        .max()
        .unwrap()
}

/// Relation without the MTV.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Class {
    /// Positive gap.
    Apart,
    /// Zero gap.
    Touching,
    /// Interiors overlap.
    Overlapping,
}

/// The class of a kernel answer.
pub fn class(p: Proximity) -> Class {
    match p {
        Proximity::Apart => Class::Apart,
        Proximity::Touching => Class::Touching,
        Proximity::Overlapping(_) => Class::Overlapping,
    }
}

// ------------------------------------------------------------ exact maths

pub fn cross(a: I64Vec2, b: I64Vec2) -> i128 {
    a.x as i128 * b.y as i128 - a.y as i128 * b.x as i128
}
pub fn dot(a: I64Vec2, b: I64Vec2) -> i128 {
    a.x as i128 * b.x as i128 + a.y as i128 * b.y as i128
}
pub fn norm2(a: I64Vec2) -> u128 {
    dot(a, a) as u128
}
/// Outward normal of an edge of a positively wound polygon.
pub fn perp(e: I64Vec2) -> I64Vec2 {
    I64Vec2::new(e.y, -e.x)
}
/// `n / d` rounded away from zero, `d > 0` (written again here on purpose).
pub fn div_away(n: i128, d: i128) -> i128 {
    let q = n / d;
    if q * d == n {
        q
    } else if n > 0 {
        q + 1
    } else {
        q - 1
    }
}
/// Compares `a / b` with `c / d` for non-negative `a, c` and positive `b, d`.
pub fn cmp_frac(a: u128, b: u128, c: u128, d: u128) -> Ordering {
    cmp_mul_u128(a, d, c, b)
}
pub fn f(v: I64Vec2) -> [f64; 2] {
    [v.x as f64, v.y as f64]
}

/// Convex hull (positively wound, no collinear points) by the monotone chain.
pub fn hull(mut pts: Vec<I64Vec2>) -> Vec<I64Vec2> {
    pts.sort_by_key(|p| (p.x, p.y));
    pts.dedup();
    if pts.len() <= 2 {
        return pts;
    }
    let mut lower: Vec<I64Vec2> = Vec::new();
    for &p in &pts {
        while lower.len() >= 2
            && cross(
                lower[lower.len() - 1] - lower[lower.len() - 2],
                p - lower[lower.len() - 1],
            ) <= 0
        {
            lower.pop();
        }
        lower.push(p);
    }
    let mut upper: Vec<I64Vec2> = Vec::new();
    for &p in pts.iter().rev() {
        while upper.len() >= 2
            && cross(
                upper[upper.len() - 1] - upper[upper.len() - 2],
                p - upper[upper.len() - 1],
            ) <= 0
        {
            upper.pop();
        }
        upper.push(p);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

// ------------------------------------------------------- polygon-like oracle

/// What the oracle expects of a polygon-like pair.
#[derive(Debug, Clone)]
pub struct SatExpect {
    pub class: Class,
    /// Exact expected MTV (moving A) when overlapping.
    pub mtv: Option<IVec2>,
    /// The chosen axis was centred (both directions equally deep), so the
    /// "push up" convention applies and the answer is not antisymmetric.
    pub centred: bool,
    /// Exact penetration depth, in units, as `f64`.
    pub depth: f64,
}

/// The configuration-space obstacle of A against B: A at `pa` overlaps B at
/// `pb` exactly when `pa - pb` is in `K = {q - p : p in A, q in B}`.
pub fn obstacle(a: &[I64Vec2], b: &[I64Vec2]) -> Vec<I64Vec2> {
    let mut d = Vec::with_capacity(a.len() * b.len());
    for &p in a {
        for &q in b {
            d.push(q - p);
        }
    }
    hull(d)
}

/// Classifies point `x` against a convex hull (1, 2 or more vertices).
pub fn classify_in_hull(k: &[I64Vec2], x: I64Vec2) -> Class {
    match k.len() {
        1 => {
            if x == k[0] {
                Class::Touching
            } else {
                Class::Apart
            }
        }
        2 => {
            let e = k[1] - k[0];
            let d = x - k[0];
            if cross(e, d) == 0 && dot(e, d) >= 0 && dot(e, d) <= dot(e, e) {
                Class::Touching
            } else {
                Class::Apart
            }
        }
        n => {
            let mut zero = false;
            for i in 0..n {
                let c = cross(k[(i + 1) % n] - k[i], x - k[i]);
                if c < 0 {
                    return Class::Apart;
                }
                zero |= c == 0;
            }
            if zero {
                Class::Touching
            } else {
                Class::Overlapping
            }
        }
    }
}

/// The exact answer for polygon-like A at `pa` against B at `pb`, following
/// the documented conventions with A first (the caller negates for the
/// reverse-order implementations).
pub fn sat_oracle(a: &[I64Vec2], pa: IVec2, b: &[I64Vec2], pb: IVec2) -> SatExpect {
    let k = obstacle(a, b);
    let x = w(pa) - w(pb);
    let class = classify_in_hull(&k, x);
    if class != Class::Overlapping {
        return SatExpect {
            class,
            mtv: None,
            centred: false,
            depth: 0.0,
        };
    }
    let n = k.len();
    // Faces: outward normal and overlap `o = n . (vertex - x) > 0`.
    let faces: Vec<(I64Vec2, i128)> = (0..n)
        .map(|i| {
            let e = k[(i + 1) % n] - k[i];
            (perp(e), cross(e, x - k[i]))
        })
        .collect();
    // Deepest-first order by o / |n|, exactly.
    let depth_cmp = |a: &(I64Vec2, i128), b: &(I64Vec2, i128)| {
        let (oa, ob) = (a.1 as u128, b.1 as u128);
        cmp_frac(oa * oa, norm2(a.0), ob * ob, norm2(b.0))
    };
    let min = faces.iter().min_by(|a, b| depth_cmp(a, b)).unwrap();
    let tied: Vec<&(I64Vec2, i128)> = faces
        .iter()
        .filter(|f| depth_cmp(f, min) == Ordering::Equal)
        .collect();
    // Tie rule: smallest line angle in [0, pi).
    let first = tied.iter().min_by(|a, b| line_order(a.0, b.0)).unwrap();
    let on_line: Vec<&&(I64Vec2, i128)> = tied
        .iter()
        .filter(|f| line_order(f.0, first.0) == Ordering::Equal)
        .collect();
    let centred = on_line.len() == 2;
    let (nrm, o) = if centred {
        // Both orientations equally deep: the one pointing up (or left).
        ***on_line
            .iter()
            .find(|f| f.0.y < 0 || (f.0.y == 0 && f.0.x < 0))
            .unwrap()
    } else {
        **first
    };
    let l2 = norm2(nrm) as i128;
    let mtv = IVec2::new(
        div_away(nrm.x as i128 * o, l2) as i32,
        div_away(nrm.y as i128 * o, l2) as i32,
    );
    let depth = o as f64 / (l2 as f64).sqrt();
    SatExpect {
        class,
        mtv: Some(mtv),
        centred,
        depth,
    }
}

/// Every SAT axis of a vertex list, written independently of the shapes:
/// edge normals of a polygon; normal and direction of a segment; none for a
/// point.
pub fn sat_axes(v: &[I64Vec2]) -> Vec<I64Vec2> {
    match v.len() {
        1 => vec![],
        2 => vec![perp(v[1] - v[0]), v[1] - v[0]],
        n => (0..n).map(|i| perp(v[(i + 1) % n] - v[i])).collect(),
    }
}

/// Smallest push along axis `n` (exact), as `(overlap, |n|^2)`; `None` when
/// the axis separates or touches.
pub fn axis_push(
    a: &[I64Vec2],
    pa: IVec2,
    b: &[I64Vec2],
    pb: IVec2,
    n: I64Vec2,
) -> Option<(u128, u128)> {
    let proj = |v: &[I64Vec2], p: IVec2| {
        let s = dot(w(p), n);
        let it = v.iter().map(|q| dot(*q, n) + s);
        (it.clone().min().unwrap(), it.max().unwrap())
    };
    let (amin, amax) = proj(a, pa);
    let (bmin, bmax) = proj(b, pb);
    let o = (amax - bmin).min(bmax - amin);
    (o > 0).then_some((o as u128, norm2(n)))
}

/// Gap between two placed polygon-like shapes after separation, in `f64`:
/// the largest separating distance over all SAT axes (0 when touching).
pub fn sat_gap(a: &[I64Vec2], pa: IVec2, b: &[I64Vec2], pb: IVec2) -> f64 {
    let mut gap: f64 = f64::NEG_INFINITY;
    for n in sat_axes(a).into_iter().chain(sat_axes(b)) {
        let s = |p: IVec2| dot(w(p), n);
        let pr = |v: &[I64Vec2], p: IVec2| {
            let it = v.iter().map(|q| dot(*q, n) + s(p));
            (it.clone().min().unwrap(), it.max().unwrap())
        };
        let (amin, amax) = pr(a, pa);
        let (bmin, bmax) = pr(b, pb);
        let g = (bmin - amax).max(amin - bmax) as f64 / (norm2(n) as f64).sqrt();
        gap = gap.max(g);
    }
    gap
}

// ------------------------------------------------------------ circle oracle

/// What the oracle expects of a circle (radius `r`, centre `c`) against a
/// polygon-like shape with vertices `g` at the origin.
#[derive(Debug, Clone)]
pub struct CircleExpect {
    pub class: Class,
    /// The true MTV(s) moving the circle; several when the geometry gives
    /// equally good directions (centre inside with tied faces, centre on a
    /// segment, coincident centres).
    pub candidates: Vec<[f64; 2]>,
    /// Centre coincides with a point shape: the documented "push up" case.
    pub coincident: bool,
}

/// Exact classification and the true MTV(s) of a circle against `g`.
pub fn circle_oracle(r: i64, c: I64Vec2, g: &[I64Vec2]) -> CircleExpect {
    let n = g.len();
    let r2 = (r as u128) * (r as u128);
    let rf = r as f64;
    // Inside (or on the boundary of) a polygon: overlapping.
    if n >= 3 {
        let cr: Vec<i128> = (0..n)
            .map(|i| cross(g[(i + 1) % n] - g[i], c - g[i]))
            .collect();
        if cr.iter().all(|&x| x >= 0) {
            // Nearest faces (exact ties), each pushed out by r + depth.
            let key = |i: usize| {
                (
                    (cr[i] as u128) * (cr[i] as u128),
                    norm2(g[(i + 1) % n] - g[i]),
                )
            };
            let best = (0..n).min_by(|&i, &j| {
                let (a, b) = key(i);
                let (c2, d) = key(j);
                cmp_frac(a, b, c2, d)
            });
            let best = best.unwrap();
            let (bn, bd) = key(best);
            let candidates = (0..n)
                .filter(|&i| {
                    let (a, b) = key(i);
                    cmp_frac(a, b, bn, bd) == Ordering::Equal
                })
                .map(|i| {
                    let e = g[(i + 1) % n] - g[i];
                    let nn = perp(e);
                    let len = (norm2(e) as f64).sqrt();
                    let depth = cr[i] as f64 / len;
                    let k = (rf + depth) / len;
                    [nn.x as f64 * k, nn.y as f64 * k]
                })
                .collect();
            return CircleExpect {
                class: Class::Overlapping,
                candidates,
                coincident: false,
            };
        }
    }
    if n == 1 && c == g[0] {
        return CircleExpect {
            class: Class::Overlapping,
            candidates: vec![[0.0, -rf]],
            coincident: true,
        };
    }
    if n == 2 {
        let e = g[1] - g[0];
        let d = c - g[0];
        if cross(e, d) == 0 && dot(e, d) >= 0 && dot(e, d) <= dot(e, e) {
            let nn = perp(e);
            let k = rf / (norm2(e) as f64).sqrt();
            let m = [nn.x as f64 * k, nn.y as f64 * k];
            return CircleExpect {
                class: Class::Overlapping,
                candidates: vec![m, [-m[0], -m[1]]],
                coincident: false,
            };
        }
    }
    // Outside: exact squared distance to the nearest feature, as a fraction,
    // and the vector from the nearest point to the centre, computed so that
    // each component has full relative precision (an exact zero stays zero).
    let mut best: Option<(u128, u128, [f64; 2])> = None; // (num, den, centre - nearest)
    let mut consider = |num: u128, den: u128, d: [f64; 2]| {
        if best.is_none_or(|(bn, bd, _)| cmp_frac(num, den, bn, bd) == Ordering::Less) {
            best = Some((num, den, d));
        }
    };
    for &v in g {
        consider(norm2(c - v), 1, f(c - v));
    }
    let edges = match n {
        1 => 0,
        2 => 1,
        _ => n,
    };
    for i in 0..edges {
        let (v, e) = (g[i], g[(i + 1) % n] - g[i]);
        let t = dot(c - v, e);
        if t >= 0 && t <= dot(e, e) {
            let cr = cross(e, c - v);
            // centre - nearest = perp(e) * (perp(e) . (c - v)) / |e|^2.
            let pe = perp(e);
            let k = dot(pe, c - v) as f64 / dot(e, e) as f64;
            consider(
                (cr * cr) as u128,
                norm2(e),
                [pe.x as f64 * k, pe.y as f64 * k],
            );
        }
    }
    let (num, den, d) = best.unwrap();
    let class = match cmp_frac(num, den, r2, 1) {
        Ordering::Less => Class::Overlapping,
        Ordering::Equal => Class::Touching,
        Ordering::Greater => Class::Apart,
    };
    let mut candidates = vec![];
    if class == Class::Overlapping {
        let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let k = (rf - len) / len;
        candidates.push([d[0] * k, d[1] * k]);
    }
    CircleExpect {
        class,
        candidates,
        coincident: false,
    }
}

/// Circle-against-anything oracle: `(radius, centre relative to the other
/// shape's origin, other vertices)`, folding circle-circle into
/// circle-against-point.
pub fn circle_view(
    circle: &Geom,
    pc: IVec2,
    other: &Geom,
    po: IVec2,
) -> (i64, I64Vec2, Vec<I64Vec2>) {
    let Geom::Disk(r) = circle else {
        unreachable!()
    };
    let c = w(pc) - w(po);
    match other {
        Geom::Disk(r2) => (r + r2, c, vec![I64Vec2::ZERO]),
        Geom::Poly(v) => (*r, c, v.clone()),
    }
}

/// Is this kind polygon-like (handled by the SAT kernel)?
pub fn is_sat_kind(k: ShapeKind) -> bool {
    k != ShapeKind::Circle
}

// ---------------------------------------------------------------- generators

/// A size scale in units: often tiny (lots of exact touches and centred
/// cases), otherwise log-uniform up to `2^26` units, where every generated
/// shape still fits [`ledge_shared::fixed::MAX_EXTENT`] (`2^27`).
pub fn scale() -> impl Strategy<Value = i32> {
    prop_oneof![
        3 => 1i32..=8,
        2 => 3i32..=1000,
        4 => (0u32..=26).prop_map(|e| 1i32 << e),
    ]
}

pub fn point() -> impl Strategy<Value = Point> {
    Just(Point)
}

pub fn segment() -> impl Strategy<Value = Segment> {
    scale()
        .prop_flat_map(|s| {
            let c = -s..=s;
            prop_oneof![
                // Any direction.
                2 => (c.clone(), c.clone(), c.clone(), c.clone()),
                // Horizontal and vertical, as in one-way platforms and walls.
                1 => (c.clone(), c.clone(), c.clone()).prop_map(|(x0, x1, y)| (x0, y, x1, y)),
                1 => (c.clone(), c.clone(), c.clone()).prop_map(|(y0, y1, x)| (x, y0, x, y1)),
            ]
        })
        .prop_filter_map("zero-length segment", |(ax, ay, bx, by)| {
            Segment::new(IVec2::new(ax, ay), IVec2::new(bx, by)).ok()
        })
}

pub fn circle() -> impl Strategy<Value = Circle> {
    scale().prop_flat_map(|s| (1..=s).prop_map(|r| Circle::new(r).unwrap()))
}

pub fn aabb() -> impl Strategy<Value = Aabb> {
    scale()
        .prop_flat_map(|s| (1..=s, 1..=s).prop_map(|(x, y)| Aabb::new(IVec2::new(x, y)).unwrap()))
}

/// Oriented boxes: rounded turned rectangles of every direction (small and
/// large direction vectors, Pythagorean ones) and arbitrary parallelograms.
pub fn obb() -> impl Strategy<Value = Obb> {
    scale()
        .prop_flat_map(|s| {
            let dir = prop_oneof![
                (-8i32..=8, -8i32..=8),
                (-(1 << 20)..=(1 << 20), -(1 << 20)..=(1 << 20)),
                (
                    prop::sample::select(vec![
                        (3, 4),
                        (4, 3),
                        (-3, 4),
                        (5, 12),
                        (-12, 5),
                        (8, 15),
                        (1, 1),
                        (1, -1)
                    ]),
                    1i32..=4
                )
                    .prop_map(|((x, y), k)| (x * k, y * k)),
            ];
            let turned = (1..=s, 1..=s, dir).prop_map(|(hx, hy, (dx, dy))| {
                Obb::new(IVec2::new(hx, hy), IVec2::new(dx, dy)).ok()
            });
            let c = -s..=s;
            let skew = (c.clone(), c.clone(), c.clone(), c)
                .prop_map(|(a, b, c, d)| Obb::from_axes(IVec2::new(a, b), IVec2::new(c, d)).ok());
            prop_oneof![3 => turned, 1 => skew]
        })
        .prop_filter_map("degenerate box", |o| o)
}

/// Convex polygons: rounded points on a circle or random points in a box,
/// hulled, offset from the origin; validated by `ConvexPolygon::new`.
pub fn polygon() -> impl Strategy<Value = ConvexPolygon> {
    scale().prop_flat_map(|s| {
        let c = -s..=s;
        let on_circle =
            (1..=s, prop::collection::vec(0u32..3600, 3..=8)).prop_map(|(r, angles)| {
                angles
                    .into_iter()
                    .map(|a| {
                        let t = a as f64 * core::f64::consts::PI / 1800.0;
                        IVec2::new(
                            (r as f64 * t.cos()).round() as i32,
                            (r as f64 * t.sin()).round() as i32,
                        )
                    })
                    .collect::<Vec<_>>()
            });
        let in_box = prop::collection::vec(
            (c.clone(), c.clone()).prop_map(|(x, y)| IVec2::new(x, y)),
            3..=10,
        );
        let pts = prop_oneof![on_circle, in_box];
        (
            pts,
            c.clone(),
            c,
            1..=s.max(1),
            any::<bool>(),
            any::<prop::sample::Index>(),
        )
            .prop_map(|(pts, ox, oy, t, rev, rot)| {
                let off = IVec2::new(ox, oy);
                let mut h: Vec<IVec2> = hull(pts.iter().map(|p| w(*p)).collect())
                    .into_iter()
                    .map(|p| IVec2::new(p.x as i32, p.y as i32) + off)
                    .collect();
                h.truncate(8);
                if h.len() < 3 {
                    // Too small to make a polygon from the sample: a right triangle.
                    h = vec![off, off + IVec2::new(t, 0), off + IVec2::new(0, t)];
                }
                // Either winding and any starting vertex.
                if rev {
                    h.reverse();
                }
                let k = rot.index(h.len());
                h.rotate_left(k);
                ConvexPolygon::new(&h).unwrap_or_else(|e| panic!("hull {h:?} refused: {e}"))
            })
    })
}

/// A placed pair: shapes, positions, and a translation fraction per axis
/// (in `[-2^20, 2^20]`) for the translation-invariance check.
#[derive(Debug, Clone)]
pub struct Case<A, B> {
    pub a: A,
    pub pa: IVec2,
    pub b: B,
    pub pb: IVec2,
    pub shift: (i64, i64),
}

const SHIFT_ONE: i64 = 1 << 20;

/// A boundary point of a shape with integer coordinates: a vertex, a
/// lattice point of an edge, or an axis extreme of a circle.
pub fn boundary_point(g: &Geom, i: prop::sample::Index, j: u32) -> IVec2 {
    let p = match g {
        Geom::Disk(r) => [
            I64Vec2::new(*r, 0),
            I64Vec2::new(0, *r),
            I64Vec2::new(-r, 0),
            I64Vec2::new(0, -r),
        ][i.index(4)],
        Geom::Poly(v) => {
            let n = v.len();
            let k = i.index(n);
            if n == 1 {
                v[0]
            } else {
                // The edge's lattice points are v_k + t * e / gcd(e), t in
                // [0, g]; one step beyond either end is on the edge's line but
                // off the shape (what only a segment's direction axis sees).
                let e = v[(k + 1) % n] - v[k];
                let g = gcd(e.x.unsigned_abs(), e.y.unsigned_abs()) as i64;
                let t = if j % 4 == 0 {
                    [-1, g + 1][(j / 4 % 2) as usize]
                } else {
                    j as i64 % (g + 1)
                };
                v[k] + e / g * t
            }
        }
    };
    IVec2::new(p.x as i32, p.y as i32)
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Places two generated shapes close enough to relate in every way: random
/// offsets at the scale of the shapes, nearly centred ones, and a boundary
/// point of one on a boundary point of the other (exact touches).
pub fn case<A, B>(
    sa: impl Strategy<Value = A>,
    sb: impl Strategy<Value = B>,
) -> impl Strategy<Value = Case<A, B>>
where
    A: Shape + Geometry + Clone + core::fmt::Debug,
    B: Shape + Geometry + Clone + core::fmt::Debug,
{
    (sa, sb).prop_flat_map(|(a, b)| {
        let r = (reach(&a) + reach(&b) + 2) as i32;
        let q = r / 8 + 1;
        let (ga, gb) = (a.geom(), b.geom());
        let on = (
            any::<prop::sample::Index>(),
            any::<u32>(),
            any::<prop::sample::Index>(),
            any::<u32>(),
            -1i32..=1,
            -1i32..=1,
        )
            .prop_map(move |(i, j, k, l, dx, dy)| {
                let d = boundary_point(&ga, i, j) - boundary_point(&gb, k, l);
                // Exactly on, or a unit off.
                let nudge = if (j ^ l) % 3 == 0 {
                    IVec2::new(dx, dy)
                } else {
                    IVec2::ZERO
                };
                ((d + nudge).x, (d + nudge).y)
            });
        let off = prop_oneof![
            4 => (-r..=r, -r..=r),
            2 => (-q..=q, -q..=q),
            2 => (-3i32..=3, -3i32..=3),
            3 => on,
        ];
        let frac = prop_oneof![
            3 => -SHIFT_ONE..=SHIFT_ONE,
            1 => Just(SHIFT_ONE),
            1 => Just(-SHIFT_ONE),
        ];
        (
            Just(a),
            Just(b),
            -(1i32 << 20)..=(1 << 20),
            -(1i32 << 20)..=(1 << 20),
            off,
            frac.clone(),
            frac,
        )
            .prop_map(|(a, b, px, py, (ox, oy), fx, fy)| {
                let pa = IVec2::new(px, py);
                Case {
                    a,
                    pa,
                    b,
                    pb: pa + IVec2::new(ox, oy),
                    shift: (fx, fy),
                }
            })
    })
}

/// The translation of a case: as far as the world bounds allow (positions
/// stay within `MAX_COORD` minus the shape's reach), scaled by the case's
/// fraction.
pub fn shift_of<A: Shape, B: Shape>(c: &Case<A, B>) -> IVec2 {
    let (ra, rb) = (reach(&c.a), reach(&c.b));
    let lim =
        |a: i32, b: i32| MAX_COORD as i64 - ((a as i64).abs() + ra).max((b as i64).abs() + rb);
    let lx = lim(c.pa.x, c.pb.x);
    let ly = lim(c.pa.y, c.pb.y);
    IVec2::new(
        (lx * c.shift.0 / SHIFT_ONE) as i32,
        (ly * c.shift.1 / SHIFT_ONE) as i32,
    )
}
