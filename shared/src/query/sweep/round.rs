//! Pairs with a circle: a ray against the other shape inflated by the
//! radius, `K = B (+) disc(r)`: the offset edges plus a disc at every vertex
//! (a capsule for a segment, a disc for a point or a circle).
//!
//! A circle moving against `B` is the ray of its centre against `K`; a
//! polygon-like shape moving by `d` against a static circle is the circle
//! moving by `-d` against it; two circles are a point against a disc of the
//! summed radius.
//!
//! * **Whether** the path enters `K`'s interior is decided exactly: it does
//!   when the path segment comes closer than `r` to `B`, that is to one of its
//!   edges (segment–segment distance: a crossing, or one of the four
//!   endpoint-to-segment distances, each compared squared with
//!   [`cmp_mul_u128`]).
//! * **When**: the first touch of `K` is the earliest touch of its pieces,
//!   all contained in `K`: an offset edge (exact crossing test, including
//!   whether the crossing lies within the edge's extent, by comparing
//!   `X` with `c sqrt(|e|^2)` through squares) and the vertex discs. Each
//!   piece's time is rounded down (the irrational `r |e|` and `sqrt(disc)`
//!   rounded up), so the minimum is a lower bound of the exact toi.
//!
//! Bounds: relative positions below 2^33, `d` at most 2^32, radius at most
//! 2^28, edges at most 2^28 per axis: every quantity fits `i128`, and the
//! few comparisons of products of four use [`cmp_mul_u128`].

use super::{check_d, cmp_frac, reduce, verified_stop, Entry, Sweep, SweepHit};
use crate::fixed::{cmp_mul_u128, cross128, dot128, len2, perp, wide};
use crate::query::contact::{contact, Contact, Proximity};
use crate::shape::{
    Aabb, Circle, Convex, ConvexPolygon, Obb, Point, Segment, MAX_POLYGON_VERTICES,
};
use core::cmp::Ordering;
use glam::{I64Vec2, IVec2};

/// The centre path `o + t d` (relative to `b`'s origin) against `b` inflated
/// by `r`: the entry (a lower bound of the exact time) and its normal.
pub(super) fn kernel<B: Convex>(r: i64, o: I64Vec2, d: I64Vec2, b: &B) -> Option<Entry> {
    debug_assert!(r > 0);
    // Bounding boxes first: the interior of K is inside the open box.
    let (lo, hi) = b.local_bounds();
    let e = o + d;
    let (plo, phi) = (o.min(e), o.max(e));
    if phi.x <= lo.x as i64 - r
        || plo.x >= hi.x as i64 + r
        || phi.y <= lo.y as i64 - r
        || plo.y >= hi.y as i64 + r
    {
        return None;
    }
    let n = b.vertex_count();
    let mut vs = [I64Vec2::ZERO; MAX_POLYGON_VERTICES];
    for (i, v) in vs.iter_mut().enumerate().take(n) {
        *v = wide(b.vertex(i));
    }
    let vs = &vs[..n];
    let r2 = (r as u128) * (r as u128);
    if point_cmp(vs, o, r2) == Ordering::Less {
        return Some(Entry::INSIDE);
    }
    if !path_enters(vs, o, d, r2) {
        return None;
    }
    let mut best: Option<Entry> = None;
    let mut offer = |c: Entry| {
        if best.is_none_or(|b| cmp_frac(c.num, c.den, b.num, b.den) == Ordering::Less) {
            best = Some(c);
        }
    };
    for_edges(vs, |v, next| {
        if let Some(c) = edge_entry(v, next - v, r, r2, o, d) {
            offer(c);
        }
    });
    for &v in vs {
        if let Some(c) = disc_entry(v, r2, o, d) {
            offer(c);
        }
    }
    // The path enters K, so its first touch is on some piece.
    debug_assert!(best.is_some(), "entering path with no piece hit");
    Some(best.unwrap_or(Entry {
        num: 0,
        den: 1,
        normal: -d,
    }))
}

/// Calls `f(v, next)` for every edge: none for a point, both directions of
/// a segment, the wound edges of a polygon.
#[inline]
fn for_edges(vs: &[I64Vec2], mut f: impl FnMut(I64Vec2, I64Vec2)) {
    match vs.len() {
        1 => {}
        2 => {
            f(vs[0], vs[1]);
            f(vs[1], vs[0]);
        }
        n => {
            for i in 0..n {
                f(vs[i], vs[(i + 1) % n]);
            }
        }
    }
}

/// Distance from `p` to the convex shape `vs` compared with `r`
/// (`Less`: closer than `r`).
fn point_cmp(vs: &[I64Vec2], p: I64Vec2, r2: u128) -> Ordering {
    let n = vs.len();
    if n == 1 {
        return len2(p - vs[0]).cmp(&r2);
    }
    if n >= 3 {
        let inside = (0..n).all(|i| dot128(p - vs[i], perp(vs[(i + 1) % n] - vs[i])) <= 0);
        if inside {
            return Ordering::Less;
        }
    }
    let mut out = Ordering::Greater;
    let edges = if n == 2 { 1 } else { n };
    for i in 0..edges {
        match seg_cmp(p, vs[i], vs[(i + 1) % n] - vs[i], r2) {
            Ordering::Less => return Ordering::Less,
            Ordering::Equal => out = Ordering::Equal,
            Ordering::Greater => {}
        }
    }
    out
}

/// Distance from `p` to the segment from `a` along `e` compared with `r`.
#[inline]
fn seg_cmp(p: I64Vec2, a: I64Vec2, e: I64Vec2, r2: u128) -> Ordering {
    let ap = p - a;
    let u = dot128(ap, e);
    let e2 = len2(e);
    if u <= 0 {
        len2(ap).cmp(&r2)
    } else if u as u128 >= e2 {
        len2(ap - e).cmp(&r2)
    } else {
        let c = cross128(ap, e).unsigned_abs();
        cmp_mul_u128(c, c, r2, e2)
    }
}

/// Whether the path from `o` along `d` comes closer than `r` to the shape
/// (whose start is not closer than `r`).
fn path_enters(vs: &[I64Vec2], o: I64Vec2, d: I64Vec2, r2: u128) -> bool {
    if d == I64Vec2::ZERO {
        return false;
    }
    let e = o + d;
    if vs.len() == 1 {
        return seg_cmp(vs[0], o, d, r2) == Ordering::Less;
    }
    let mut enters = false;
    for_edges(vs, |a, b| {
        if enters {
            return;
        }
        // A proper crossing is distance 0; touching and collinear overlaps
        // show in the endpoint distances.
        let ab = b - a;
        let s1 = cross128(ab, o - a).signum();
        let s2 = cross128(ab, e - a).signum();
        let s3 = cross128(d, a - o).signum();
        let s4 = cross128(d, b - o).signum();
        enters = (s1 * s2 < 0 && s3 * s4 < 0)
            || seg_cmp(o, a, ab, r2) == Ordering::Less
            || seg_cmp(e, a, ab, r2) == Ordering::Less
            || seg_cmp(a, o, d, r2) == Ordering::Less
            || seg_cmp(b, o, d, r2) == Ordering::Less;
    });
    enters
}

/// Compares `x` with `c * sqrt(e2)` exactly (`e2 > 0`).
#[inline]
fn cmp_root(x: i128, c: i128, e2: u128) -> Ordering {
    match (x >= 0, c >= 0) {
        (false, true) => Ordering::Less,
        (true, false) => Ordering::Greater,
        (true, true) => {
            let (x, c) = (x as u128, c as u128);
            cmp_mul_u128(x, x, c, c * e2)
        }
        (false, false) => {
            let (x, c) = (x.unsigned_abs(), c.unsigned_abs());
            cmp_mul_u128(c, c * e2, x, x)
        }
    }
}

/// The first touch of the offset edge of the edge from `v` along `e` (its
/// outward side, `perp(e)`), if the path crosses that offset line inwards
/// within `[0, 1]` and within the edge's extent; the time rounded down.
fn edge_entry(v: I64Vec2, e: I64Vec2, r: i64, r2: u128, o: I64Vec2, d: I64Vec2) -> Option<Entry> {
    let w = perp(e);
    let kk = dot128(d, w);
    if kk >= 0 {
        return None;
    }
    let m = -kk;
    let a = o - v;
    let s = dot128(a, w);
    let e2 = len2(e);
    let rr = r2 * e2; // (r |e|)^2
                      // Start on the outer side of the offset line: s >= r |e|.
    if s < 0 || (s as u128) * (s as u128) < rr {
        return None;
    }
    // Reached by t = 1: s - m <= r |e|.
    let sk = s - m;
    if sk > 0 && (sk as u128) * (sk as u128) > rr {
        return None;
    }
    // Within the edge: with c = cross(a, d) and du = dot(d, e), the crossing
    // projects inside [0, |e|^2] exactly when
    // r du <= c |e|  and  (c - m) |e| <= r du.
    let c = cross128(a, d);
    let x = r as i128 * dot128(d, e);
    if cmp_root(x, c, e2) == Ordering::Greater || cmp_root(x, c - m, e2) == Ordering::Less {
        return None;
    }
    // t = (s - r |e|) / m, with r |e| to 2^-p rounded up.
    let bits = |v: u128| 128 - v.leading_zeros();
    let p = ((126u32.saturating_sub(bits(rr))) / 2).min(63u32.saturating_sub(bits(m as u128)));
    let scaled = rr << (2 * p);
    let mut root = scaled.isqrt();
    if root * root < scaled {
        root += 1;
    }
    let num = (s << p) - root as i128;
    debug_assert!(num >= 0);
    Some(Entry {
        num: num.max(0) as u128,
        den: (m as u128) << p,
        normal: w,
    })
}

/// The first touch of the disc of radius `r` around `v`, if the path enters
/// it within `[0, 1]`; the time rounded down (`sqrt` rounded up), the normal
/// from `v` to the centre at that time.
fn disc_entry(v: I64Vec2, r2: u128, o: I64Vec2, d: I64Vec2) -> Option<Entry> {
    let a = o - v;
    let b = dot128(a, d);
    if b >= 0 {
        return None;
    }
    let c0 = len2(a);
    if c0 <= r2 {
        // On the circle (the start is never inside K here), moving in.
        return Some(Entry {
            num: 0,
            den: 1,
            normal: a,
        });
    }
    let aa = len2(d);
    let cr = cross128(a, d).unsigned_abs();
    let line = cmp_mul_u128(cr, cr, r2, aa) != Ordering::Greater;
    let end_in = len2(a + d) <= r2;
    if !(end_in || ((-b) as u128 <= aa && line)) {
        return None;
    }
    let disc = r2 * aa - cr * cr;
    let mut s = disc.isqrt();
    if s * s < disc {
        s += 1;
    }
    let num = ((-b) as u128).saturating_sub(s).min(aa);
    let (ni, di) = (num as i128, aa as i128);
    Some(Entry {
        num,
        den: aa,
        normal: reduce(
            a.x as i128 * di + d.x as i128 * ni,
            a.y as i128 * di + d.y as i128 * ni,
        ),
    })
}

/// The hit from a circle entry; `overlaps` is the exact contact test of the
/// mover at a position.
#[inline]
fn finish(start: IVec2, d: I64Vec2, e: Entry, overlaps: impl Fn(IVec2) -> bool) -> SweepHit {
    if e.normal == I64Vec2::ZERO {
        return SweepHit {
            toi: e.toi(),
            normal: I64Vec2::ZERO,
            stop: start,
        };
    }
    let toi = e.toi();
    let normal = reduce(e.normal.x as i128, e.normal.y as i128);
    SweepHit {
        toi,
        normal,
        stop: verified_stop(start, d, toi, normal, overlaps),
    }
}

/// A circle moving against a polygon-like shape (or a point).
#[inline]
pub(super) fn circle_vs<B: Convex>(
    c: &Circle,
    start: IVec2,
    d: I64Vec2,
    b: &B,
    pos_b: IVec2,
) -> Option<SweepHit>
where
    Circle: Contact<B>,
{
    check_d(d);
    let o = wide(start) - wide(pos_b);
    let e = kernel(c.radius() as i64, o, d, b)?;
    Some(finish(start, d, e, |q| {
        matches!(contact(c, q, b, pos_b), Proximity::Overlapping(_))
    }))
}

/// A polygon-like shape moving against a static circle: the circle moving
/// by `-d` against it, normal negated.
#[inline]
pub(super) fn vs_circle<A: Convex + Contact<Circle>>(
    a: &A,
    start: IVec2,
    d: I64Vec2,
    c: &Circle,
    pos_c: IVec2,
) -> Option<SweepHit> {
    check_d(d);
    let o = wide(pos_c) - wide(start);
    let mut e = kernel(c.radius() as i64, o, -d, a)?;
    e.normal = -e.normal;
    Some(finish(start, d, e, |q| {
        matches!(contact(a, q, c, pos_c), Proximity::Overlapping(_))
    }))
}

/// A circle against a circle: a point against a disc of the summed radius.
impl Sweep<Circle> for Circle {
    #[inline]
    fn sweep(
        &self,
        start: IVec2,
        d: I64Vec2,
        other: &Circle,
        other_pos: IVec2,
    ) -> Option<SweepHit> {
        check_d(d);
        let o = wide(start) - wide(other_pos);
        let r = self.radius() as i64 + other.radius() as i64;
        let e = kernel(r, o, d, &Point)?;
        Some(finish(start, d, e, |q| {
            matches!(
                contact(self, q, other, other_pos),
                Proximity::Overlapping(_)
            )
        }))
    }
}

/// Implements [`Sweep`] between `Circle` and each listed kind, both ways.
macro_rules! circle_sweep {
    ($($b:ty),*) => {
        $(
            impl Sweep<$b> for Circle {
                #[inline]
                fn sweep(
                    &self,
                    start: IVec2,
                    d: I64Vec2,
                    other: &$b,
                    other_pos: IVec2,
                ) -> Option<SweepHit> {
                    circle_vs(self, start, d, other, other_pos)
                }
            }
            impl Sweep<Circle> for $b {
                #[inline]
                fn sweep(
                    &self,
                    start: IVec2,
                    d: I64Vec2,
                    other: &Circle,
                    other_pos: IVec2,
                ) -> Option<SweepHit> {
                    vs_circle(self, start, d, other, other_pos)
                }
            }
        )*
    };
}

circle_sweep!(Point, Segment, Aabb, Obb, ConvexPolygon);

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

    use proptest::prelude::*;

    proptest! {
        /// The offset-edge time is a lower bound, exactly: the centre at the
        /// reported time is on the outer side of the offset line
        /// (`dot(p - v, w) >= r |e|`), with `r |e|` irrational in general.
        #[test]
        fn edge_times_are_exact_lower_bounds(
            v in (-(1i64 << 26)..=1 << 26, -(1i64 << 26)..=1 << 26),
            e in (-(1i64 << 26)..=1 << 26, -(1i64 << 26)..=1 << 26),
            u in 0i64..=16,
            along in (1i64..=64, -64i64..=64),
            back in (1i64..=64, -64i64..=64),
            r in 1i64..=1 << 27,
            shift in 0u32..26,
        ) {
            // Aimed at the edge: from its outer side, moving in. Some cases
            // scaled down so that small values occur too.
            let sc = |x: i64| x >> shift;
            let (v, e) = (w(sc(v.0), sc(v.1)), w(sc(e.0), sc(e.1)));
            prop_assume!(e != I64Vec2::ZERO);
            let n = perp(e);
            let o = v + e * u / 16 + n * along.0 / 8 + e * along.1 / 64;
            let d = -n * back.0 / 4 + e * back.1 / 64;
            prop_assume!(d != I64Vec2::ZERO);
            let r = (r >> shift).max(1);
            let r2 = (r as u128) * (r as u128);
            if let Some(en) = edge_entry(v, e, r, r2, o, d) {
                let (num, den) = (en.num as i128, en.den as i128);
                prop_assert!(num >= 0 && num <= den);
                // den * (o + d t) - den * v, against w, compared with
                // r |e| den: squares through cmp_mul_u128.
                let w = perp(e);
                let p = |c: i64, dc: i64, vc: i64| (c - vc) as i128 * den + dc as i128 * num;
                let s = p(o.x, d.x, v.x) * w.x as i128 + p(o.y, d.y, v.y) * w.y as i128;
                prop_assert!(s >= 0);
                let rhs = r2 * len2(e);
                let sa = s as u128;
                prop_assert_ne!(
                    cmp_mul_u128(sa, sa, rhs, (den as u128) * (den as u128)),
                    Ordering::Less,
                    "inside the offset line at the reported time"
                );
            }
        }
    }

    #[test]
    fn root_comparison() {
        assert_eq!(cmp_root(3, 1, 9), Ordering::Equal);
        assert_eq!(cmp_root(4, 1, 9), Ordering::Greater);
        assert_eq!(cmp_root(2, 1, 9), Ordering::Less);
        assert_eq!(cmp_root(-2, -1, 9), Ordering::Greater);
        assert_eq!(cmp_root(-4, -1, 9), Ordering::Less);
        assert_eq!(cmp_root(-1, 0, 2), Ordering::Less);
        assert_eq!(cmp_root(0, 0, 2), Ordering::Equal);
        assert_eq!(cmp_root(0, -1, 2), Ordering::Greater);
        assert_eq!(cmp_root(1, 1, 2), Ordering::Less);
        assert_eq!(cmp_root(2, 1, 2), Ordering::Greater);
    }

    #[test]
    fn circle_onto_a_box_face_is_exact() {
        let c = Circle::new(5).unwrap();
        let f = Aabb::new(v(100, 10)).unwrap();
        // Centre falls from y = -40 towards the top face y = -10: touches at y = -15.
        let h = c.sweep(v(3, -40), w(0, 50), &f, v(0, 0)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.stop),
            (Toi::new(25, 50).unwrap(), w(0, -1), v(3, -15))
        );
        // The box falling onto the circle: same toi, opposite normal.
        let h = f.sweep(v(0, 0), w(0, -50), &c, v(3, -40)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.stop),
            (Toi::new(25, 50).unwrap(), w(0, 1), v(0, -25))
        );
        // Rolling along the face (tangent) is no hit.
        assert!(c.sweep(v(-200, -15), w(400, 0), &f, v(0, 0)).is_none());
    }

    #[test]
    fn circle_against_circle() {
        let (a, b) = (Circle::new(3).unwrap(), Circle::new(2).unwrap());
        let h = a.sweep(v(-20, 0), w(40, 0), &b, v(0, 0)).unwrap();
        assert_eq!(
            (h.toi, h.normal, h.stop),
            (Toi::new(15, 40).unwrap(), w(-1, 0), v(-5, 0))
        );
        // Tangent pass: no hit; one unit closer: a hit.
        assert!(a.sweep(v(-20, 5), w(40, 0), &b, v(0, 0)).is_none());
        assert!(a.sweep(v(-20, 4), w(40, 0), &b, v(0, 0)).is_some());
        // Coincident centres: started inside.
        assert!(a
            .sweep(v(0, 0), w(1, 0), &b, v(0, 0))
            .unwrap()
            .started_inside());
    }

    #[test]
    fn corner_arc_is_a_lower_bound_and_never_overlaps() {
        let c = Circle::new(10).unwrap();
        let f = Aabb::new(v(10, 10)).unwrap();
        // Diagonally onto the corner (10, 10): touches at distance 10 from it.
        let h = c.sweep(v(40, 40), w(-30, -30), &f, v(0, 0)).unwrap();
        let t = h.toi.num() as f64 / h.toi.den() as f64;
        let exact = (30.0 - 10.0 / 2f64.sqrt()) / 30.0;
        assert!(t <= exact && exact - t < 1e-3, "{t} vs {exact}");
        assert_eq!(h.normal, w(1, 1));
        assert!(
            contact(&c, h.stop, &f, v(0, 0)).mtv().is_none(),
            "{:?}",
            h.stop
        );
    }
}
