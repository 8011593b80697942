//! Polygon-like pairs (point, segment, box, oriented box, polygon): a ray
//! against the Minkowski sum `K = B (+) (-A)`, exactly.
//!
//! `A` at `p` and `B` at `q` meet exactly when `p - q` is in `K`, and their
//! interiors overlap exactly when it is in `K`'s interior (the separating
//! axis test of the contact module is exact on these shapes). `K` is a convex
//! polygon with integer vertices (at most 16: eight plus eight), built by
//! merging the two edge sequences by angle. The relative path `o + t d`,
//! `t` in `[0, 1]`, is clipped against `K`'s open half-planes with exact
//! rational fractions (Cyrus–Beck): the toi is the largest entering fraction.
//! When `K` has no area (point/point, point/segment, parallel segments) the
//! thin rule of the [module documentation](super) applies.
//!
//! Bounds: `K`'s vertices are within 2^28 of its origin and its edges within
//! 2^29 per axis; relative positions are below 2^33 and `d` at most 2^32 per
//! axis, so `dot(o - v, w)` and `dot(d, w)` stay below 2^63 and their cross
//! products below 2^126 (`i128`).

use super::{better_normal, check_d, gcd, offset, primitive, round_outer, Entry, Sweep, SweepHit};
use crate::fixed::{cross128, dot128, perp, wide};
use crate::shape::{Aabb, Convex, ConvexPolygon, Obb, Point, Segment, MAX_POLYGON_VERTICES};
use core::cmp::Ordering;
use glam::{I64Vec2, IVec2};

/// Most vertices of a Minkowski sum of two shapes.
const MAX_K: usize = 2 * MAX_POLYGON_VERTICES;

/// A convex vertex list (positively wound when it has three or more).
pub(super) struct Poly {
    v: [I64Vec2; MAX_K],
    n: usize,
}

impl Poly {
    #[inline]
    fn push(&mut self, p: I64Vec2) {
        self.v[self.n] = p;
        self.n += 1;
    }

    /// The vertices.
    #[inline]
    fn verts(&self) -> &[I64Vec2] {
        &self.v[..self.n]
    }
}

/// The sweep of a polygon-like `a` from `start` by `d` against `b` at `pos_b`.
#[inline]
pub(super) fn sweep_poly<A: Convex, B: Convex>(
    a: &A,
    start: IVec2,
    d: I64Vec2,
    b: &B,
    pos_b: IVec2,
) -> Option<SweepHit> {
    check_d(d);
    let o = wide(start) - wide(pos_b);
    // Bounding boxes first: K's box is B's box minus A's box.
    let (alo, ahi) = a.local_bounds();
    let (blo, bhi) = b.local_bounds();
    let (klo, khi) = (wide(blo) - wide(ahi), wide(bhi) - wide(alo));
    let e = o + d;
    let (plo, phi) = (o.min(e), o.max(e));
    if phi.x < klo.x || plo.x > khi.x || phi.y < klo.y || plo.y > khi.y {
        return None;
    }
    let k = minkowski(a, b);
    if k.n >= 3 {
        let entry = enter(k.verts(), o, d)?;
        Some(finish(start, d, entry))
    } else {
        thin(k.verts(), start, o, d)
    }
}

/// The hit of an exact entry: stop by the outer-side rounding.
#[inline]
fn finish(start: IVec2, d: I64Vec2, e: Entry) -> SweepHit {
    if e.normal == I64Vec2::ZERO {
        return SweepHit {
            toi: e.toi(),
            normal: I64Vec2::ZERO,
            stop: start,
        };
    }
    let toi = e.toi();
    let normal = primitive(e.normal);
    let off = round_outer(d, toi, normal);
    SweepHit {
        toi,
        normal,
        stop: offset(start, off),
    }
}

/// `K = B (+) (-A)`: the vertices of both, lowest first, merged by edge angle
/// (parallel edges of the same direction combine into one).
pub(super) fn minkowski<A: Convex, B: Convex>(a: &A, b: &B) -> Poly {
    let mut p = [I64Vec2::ZERO; MAX_POLYGON_VERTICES];
    let mut q = [I64Vec2::ZERO; MAX_POLYGON_VERTICES];
    let (np, nq) = (b.vertex_count(), a.vertex_count());
    for (i, v) in p.iter_mut().enumerate().take(np) {
        *v = wide(b.vertex(i));
    }
    // Negating a positively wound polygon keeps its winding.
    for (i, v) in q.iter_mut().enumerate().take(nq) {
        *v = -wide(a.vertex(i));
    }
    let (p, q) = (&p[..np], &q[..nq]);
    let (ip, iq) = (lowest(p), lowest(q));
    // A segment has two edges (there and back), a point none.
    let edges = |n: usize| if n >= 2 { n } else { 0 };
    let (ep, eq) = (edges(np), edges(nq));
    let at = |s: &[I64Vec2], start: usize, i: usize| s[(start + i) % s.len()];
    let edge = |s: &[I64Vec2], start: usize, i: usize| at(s, start, i + 1) - at(s, start, i);
    let mut out = Poly {
        v: [I64Vec2::ZERO; MAX_K],
        n: 0,
    };
    let (mut i, mut j) = (0, 0);
    loop {
        out.push(at(p, ip, i) + at(q, iq, j));
        let (adv_p, adv_q) = match (i < ep, j < eq) {
            (false, false) => break,
            (true, false) => (true, false),
            (false, true) => (false, true),
            (true, true) => match angle_cmp(edge(p, ip, i), edge(q, iq, j)) {
                Ordering::Less => (true, false),
                Ordering::Greater => (false, true),
                Ordering::Equal => (true, true),
            },
        };
        i += adv_p as usize;
        j += adv_q as usize;
        if i == ep && j == eq {
            break;
        }
    }
    out
}

/// Index of the lowest vertex (smallest y, then smallest x): the start of
/// a positively wound edge sequence of increasing angle in `[0, 2 pi)`.
#[inline]
fn lowest(s: &[I64Vec2]) -> usize {
    let mut best = 0;
    for (i, v) in s.iter().enumerate() {
        if (v.y, v.x) < (s[best].y, s[best].x) {
            best = i;
        }
    }
    best
}

/// Orders edge directions by angle in `[0, 2 pi)` (measured from `+x`
/// towards `+y`), exactly.
#[inline]
fn angle_cmp(a: I64Vec2, b: I64Vec2) -> Ordering {
    let half = |v: I64Vec2| u8::from(!(v.y > 0 || (v.y == 0 && v.x > 0)));
    half(a).cmp(&half(b)).then_with(|| 0.cmp(&cross128(a, b)))
}

/// Where the path `o + t d` first enters the interior of the convex polygon
/// `k` (three or more positively wound vertices); `None` when it never does.
///
/// Edge `i` with outward normal `w` keeps the open half-plane
/// `s + t k < 0`, `s = dot(o - v_i, w)`, `k = dot(d, w)`: entering edges
/// (`k < 0`) need `t > s / -k`, leaving ones (`k > 0`) `t < -s / k`,
/// parallel ones `s < 0`. The interior times form the open interval
/// `(E, X)` cut to `[0, 1]`, which is non-empty exactly when
/// `max(E, 0) < min(X, 1)`; its start is the toi.
pub(super) fn enter(k: &[I64Vec2], o: I64Vec2, d: I64Vec2) -> Option<Entry> {
    let n = k.len();
    // Largest entering fraction s / m (m = -k > 0) and the edges attaining it.
    let mut e: Option<(i128, i128)> = None;
    let mut ties = 0u32;
    // Smallest leaving fraction, capped at 1.
    let (mut xn, mut xd) = (1i128, 1i128);
    for i in 0..n {
        let v = k[i];
        let w = perp(k[if i + 1 == n { 0 } else { i + 1 }] - v);
        let s = dot128(o - v, w);
        let kk = dot128(d, w);
        match kk.cmp(&0) {
            Ordering::Less => {
                let m = -kk;
                match e {
                    None => {
                        e = Some((s, m));
                        ties = 1 << i;
                    }
                    Some((es, em)) => match (s * em).cmp(&(es * m)) {
                        Ordering::Greater => {
                            e = Some((s, m));
                            ties = 1 << i;
                        }
                        Ordering::Equal => ties |= 1 << i,
                        Ordering::Less => {}
                    },
                }
            }
            Ordering::Greater => {
                if -s * xd < xn * kk {
                    (xn, xd) = (-s, kk);
                }
            }
            Ordering::Equal => {
                if s >= 0 {
                    return None;
                }
            }
        }
    }
    match e {
        Some((es, em)) if es >= 0 => {
            // E >= 0: the start is not strictly inside.
            if es * xd >= xn * em {
                return None;
            }
            let mut best: Option<I64Vec2> = None;
            for i in 0..n {
                if ties & (1 << i) == 0 {
                    continue;
                }
                let w = perp(k[(i + 1) % n] - k[i]);
                if best.is_none_or(|b| better_normal(w, b, d)) {
                    best = Some(w);
                }
            }
            Some(Entry {
                num: es as u128,
                den: em as u128,
                normal: best.expect("an entering edge"),
            })
        }
        // Behind every entering edge: inside at t = 0 when some time is
        // left before the first exit.
        _ => (xn > 0).then_some(Entry::INSIDE),
    }
}

/// The thin rule for a `K` with no area (a point or a segment): a crossing
/// at `0 < t <= 1`, the stop strictly on the side the path came from.
fn thin(k: &[I64Vec2], start: IVec2, o: I64Vec2, d: I64Vec2) -> Option<SweepHit> {
    if d == I64Vec2::ZERO {
        return None;
    }
    let (toi, normal, off) = if k.len() == 1 {
        // Through a point: w = j * d0 with d = g * d0, d0 primitive.
        let w = k[0] - o;
        if cross128(w, d) != 0 {
            return None;
        }
        let g = gcd(d.x.unsigned_abs() as u128, d.y.unsigned_abs() as u128) as i64;
        let d0 = d / g;
        let j = if d0.x != 0 { w.x / d0.x } else { w.y / d0.y };
        if j <= 0 || j > g {
            return None;
        }
        let toi = crate::query::ray::Toi::new(j as u64, g as u64).expect("0 < j <= g");
        let n = -d0;
        // Exactly on the point: one unit back along the larger axis.
        let off = w + dominant_step(n);
        (toi, n, off)
    } else {
        let (k0, e) = (k[0], k[1] - k[0]);
        let den = cross128(d, e);
        if den == 0 {
            // Parallel or collinear: no crossing.
            return None;
        }
        let w = k0 - o;
        let (mut tn, mut un, mut den) = (cross128(w, e), cross128(w, d), den);
        if den < 0 {
            (tn, un, den) = (-tn, -un, -den);
        }
        if tn <= 0 || tn > den || un < 0 || un > den {
            return None;
        }
        let toi = super::toi_floor(tn as u128, den as u128);
        let w = perp(e);
        let n = primitive(if dot128(o - k0, w) > 0 { w } else { -w });
        let mut off = round_outer(d, toi, n);
        if dot128(o + off - k0, n) <= 0 {
            off += dominant_step(n);
        }
        (toi, n, off)
    };
    Some(SweepHit {
        toi,
        normal,
        stop: offset(start, off),
    })
}

/// One unit along the larger axis of `n`, in its direction.
#[inline]
fn dominant_step(n: I64Vec2) -> I64Vec2 {
    if n.x.abs() >= n.y.abs() {
        I64Vec2::new(n.x.signum(), 0)
    } else {
        I64Vec2::new(0, n.y.signum())
    }
}

/// Implements [`Sweep`] for each listed (moving, static) pair with the
/// Minkowski kernel.
macro_rules! poly_sweep {
    ($($a:ty => [$($b:ty),*]);* $(;)?) => {
        $($(
            impl Sweep<$b> for $a {
                #[inline]
                fn sweep(
                    &self,
                    start: IVec2,
                    d: I64Vec2,
                    other: &$b,
                    other_pos: IVec2,
                ) -> Option<SweepHit> {
                    sweep_poly(self, start, d, other, other_pos)
                }
            }
        )*)*
    };
}

poly_sweep! {
    Point => [Point, Segment, Aabb, Obb, ConvexPolygon];
    Segment => [Point, Segment, Aabb, Obb, ConvexPolygon];
    Aabb => [Point, Segment, Aabb, Obb, ConvexPolygon];
    Obb => [Point, Segment, Aabb, Obb, ConvexPolygon];
    ConvexPolygon => [Point, Segment, Aabb, Obb, ConvexPolygon];
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::ray::Toi;

    fn v(x: i32, y: i32) -> IVec2 {
        IVec2::new(x, y)
    }

    fn w(x: i64, y: i64) -> I64Vec2 {
        I64Vec2::new(x, y)
    }

    fn boxed(x: i32, y: i32) -> Aabb {
        Aabb::new(v(x, y)).unwrap()
    }

    #[test]
    fn minkowski_of_boxes_is_a_box() {
        let k = minkowski(&boxed(2, 3), &boxed(10, 5));
        assert_eq!(k.verts(), &[w(-12, -8), w(12, -8), w(12, 8), w(-12, 8)][..]);
    }

    #[test]
    fn minkowski_of_a_segment_and_a_box_is_a_hexagon() {
        let s = Segment::new(v(0, 0), v(4, 2)).unwrap();
        let k = minkowski(&s, &boxed(1, 1));
        // -s = {(0, 0), (-4, -2)} added to the square.
        assert_eq!(k.n, 6);
        for i in 0..k.n {
            let e0 = k.v[(i + 1) % k.n] - k.v[i];
            let e1 = k.v[(i + 2) % k.n] - k.v[(i + 1) % k.n];
            assert!(cross128(e0, e1) > 0);
        }
        // Degenerate sums.
        assert_eq!(minkowski(&Point, &Point).n, 1);
        assert_eq!(minkowski(&Point, &s).n, 2);
        let t = Segment::new(v(5, 5), v(13, 9)).unwrap();
        assert_eq!(minkowski(&t, &s).n, 2);
    }

    #[test]
    fn box_onto_box() {
        // A 4x4 box falling onto a 20x2 floor at y = 10 (top at 9).
        let f = boxed(10, 1);
        let h = sweep_poly(&boxed(2, 2), v(0, 0), w(0, 20), &f, v(0, 10)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.stop),
            (Toi::new(7, 20).unwrap(), w(0, -1), v(0, 7))
        );
        // Sliding along it (touching) is no hit; moving away neither.
        assert!(sweep_poly(&boxed(2, 2), v(0, 7), w(50, 0), &f, v(0, 10)).is_none());
        assert!(sweep_poly(&boxed(2, 2), v(0, 7), w(3, -5), &f, v(0, 10)).is_none());
        // Resting on it and pushed down: toi 0.
        let h = sweep_poly(&boxed(2, 2), v(0, 7), w(1, 1), &f, v(0, 10)).unwrap();
        assert_eq!((h.toi, h.normal, h.stop), (Toi::ZERO, w(0, -1), v(0, 7)));
        // Started inside.
        let h = sweep_poly(&boxed(2, 2), v(0, 8), w(1, 1), &f, v(0, 10)).unwrap();
        assert!(h.started_inside());
        assert_eq!(h.stop, v(0, 8));
        // Corner tie: the more head-on face (x = -12 and y = 7 at t = 1/2).
        let h = sweep_poly(&boxed(2, 2), v(-16, 5), w(8, 4), &f, v(0, 10)).unwrap();
        assert_eq!((h.toi, h.normal), (Toi::new(1, 2).unwrap(), w(-1, 0)));
    }
}
