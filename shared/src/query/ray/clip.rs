//! Cyrus–Beck clipping of a ray against a convex polygon-like shape, with
//! exact rational entry and exit fractions.

use super::{Ray, RayHit};
use crate::fixed::{dot128, perp, wide};
use crate::shape::Convex;
use glam::{I64Vec2, IVec2};

/// Where a ray first meets a convex shape with area.
pub(super) struct Clip {
    /// Entry fraction `num / den` of `dir`, `0 <= num <= den`.
    pub num: u128,
    /// Denominator, positive.
    pub den: u128,
    /// The edge whose normal the hit reports: the entering edge, or when the
    /// ray enters through none (it starts on the surface and slides along it
    /// or leaves) the first edge the origin lies on; `None` when the origin is
    /// strictly inside.
    pub edge: Option<usize>,
}

/// Clips the ray `o + t d`, `t` in `[0, 1]` (coordinates relative to the
/// shape's origin), against the closed shape `s`, which must have at least
/// three positively wound vertices.
///
/// Each edge `i` from vertex `v` with outward normal `w = perp(edge)` keeps
/// the points with `dot(o - v, w) + t dot(d, w) <= 0`. With `s = dot(o - v, w)`
/// and `k = dot(d, w)`: an entering edge (`k < 0`) needs `t >= s / -k`, a
/// leaving one (`k > 0`) `t <= -s / k`, a parallel one (`k = 0`) `s <= 0`.
/// The ray hits when the largest entry fraction (at least 0) is at most the
/// smallest exit fraction (at most 1). Fractions are compared by
/// cross-multiplication: `|s| < 2^62` and `|k| < 2^61`, so products fit `i128`.
#[inline]
pub(super) fn clip<C: Convex>(shape: &C, o: I64Vec2, d: I64Vec2) -> Option<Clip> {
    // Bounding boxes first: cheap, and most rays in a scene miss most shapes.
    let (lo, hi) = shape.local_bounds();
    let e = o + d;
    if o.x.max(e.x) < lo.x as i64
        || o.x.min(e.x) > hi.x as i64
        || o.y.max(e.y) < lo.y as i64
        || o.y.min(e.y) > hi.y as i64
    {
        return None;
    }
    let n = shape.vertex_count();
    debug_assert!(n >= 3);
    // Entry starts at 0 (the ray's start), exit at 1 (its end).
    let (mut enter_num, mut enter_den, mut enter_edge) = (0i128, 1i128, None);
    let (mut exit_num, mut exit_den) = (1i128, 1i128);
    let mut on_edge = None;
    let mut v = wide(shape.vertex(0));
    for i in 0..n {
        let next = wide(shape.vertex(if i + 1 == n { 0 } else { i + 1 }));
        let w = perp(next - v);
        let s = dot128(o - v, w);
        let k = dot128(d, w);
        v = next;
        if k < 0 {
            // Entering at s / -k; an edge the origin is behind (s < 0) was
            // entered before the ray started. The first candidate replaces
            // the initial 0 (even at 0 itself, so a start on the surface
            // reports that surface); later ones must be strictly later.
            if s >= 0 && (enter_edge.is_none() || s * enter_den > enter_num * -k) {
                (enter_num, enter_den, enter_edge) = (s, -k, Some(i));
            }
        } else {
            if s > 0 {
                // Leaving (or parallel) while already outside this edge.
                return None;
            }
            if s == 0 && on_edge.is_none() {
                on_edge = Some(i);
            }
            if k > 0 && -s * exit_den < exit_num * k {
                (exit_num, exit_den) = (-s, k);
            }
        }
    }
    if enter_num * exit_den > exit_num * enter_den {
        return None;
    }
    Some(Clip {
        num: enter_num as u128,
        den: enter_den as u128,
        edge: enter_edge.or(on_edge),
    })
}

/// The outward normal `perp(edge)` of edge `i` of `shape`.
#[inline]
pub(super) fn edge_normal<C: Convex>(shape: &C, i: usize) -> I64Vec2 {
    let n = shape.vertex_count();
    perp(wide(shape.vertex((i + 1) % n)) - wide(shape.vertex(i)))
}

/// A full ray cast against a convex shape with area; `normal` maps the hit
/// edge's `perp(edge)` to the normal reported.
#[inline]
pub(super) fn cast<C: Convex>(
    shape: &C,
    pos: IVec2,
    ray: &Ray,
    normal: impl Fn(I64Vec2) -> I64Vec2,
) -> Option<RayHit> {
    let (o, d) = super::relative(pos, ray);
    let c = clip(shape, o, d)?;
    let n = c
        .edge
        .map_or(I64Vec2::ZERO, |i| normal(edge_normal(shape, i)));
    Some(RayHit::new(ray, c.num, c.den, n))
}
