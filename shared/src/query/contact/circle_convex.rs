//! A circle against any convex vertex shape, by closest feature.

use super::proximity::Proximity;
use crate::fixed::{cmp_mul_u128, dir_order, div_away, len2, perp, wide};
use crate::shape::Convex;
use core::cmp::Ordering;
use glam::{I64Vec2, IVec2};

/// The feature of the convex shape that decides the contact: push direction
/// `w` and `s = dot(c - feature, w)`, so the signed distance is `s / |w|`.
#[derive(Clone, Copy)]
struct Feature {
    w: I64Vec2,
    s: i128,
    /// The circle centre is inside the shape.
    inside: bool,
}

/// A circle of radius `r` centred at `pos` against `b` at `pos_b`; the MTV
/// moves the circle. A circle against a circle is a circle of the summed
/// radius against a point.
#[inline]
pub(crate) fn circle_convex<B: Convex>(r: i64, pos: IVec2, b: &B, pos_b: IVec2) -> Proximity {
    // Centre relative to b's origin.
    let c = wide(pos) - wide(pos_b);
    let (lo, hi) = b.local_bounds();
    if c.x + r < lo.x as i64
        || c.x - r > hi.x as i64
        || c.y + r < lo.y as i64
        || c.y - r > hi.y as i64
    {
        return Proximity::Apart;
    }
    let f = closest_feature(b, c);
    match classify(f, r) {
        Ordering::Greater => Proximity::Apart,
        Ordering::Equal => Proximity::Touching,
        Ordering::Less => {
            let mut m = push(f, r);
            // Verify exactly; the computed square root can leave a sliver.
            let step = I64Vec2::new(f.w.x.signum(), f.w.y.signum());
            let step = if step.x != 0 && step.y != 0 {
                if f.w.x.abs() >= f.w.y.abs() {
                    I64Vec2::new(step.x, 0)
                } else {
                    I64Vec2::new(0, step.y)
                }
            } else {
                step
            };
            for _ in 0..4 {
                if classify(closest_feature(b, c + m), r) != Ordering::Less {
                    break;
                }
                m += step;
            }
            debug_assert!(classify(closest_feature(b, c + m), r) != Ordering::Less);
            Proximity::Overlapping(IVec2::new(m.x as i32, m.y as i32))
        }
    }
}

/// Compares the distance from the centre to the shape with `r`:
/// `Less` means overlapping.
#[inline]
fn classify(f: Feature, r: i64) -> Ordering {
    // `w == 0`: the centre is on a point shape (coincident centres), at
    // distance zero, which the comparison below would call a touch.
    if f.inside || f.s < 0 || f.w == I64Vec2::ZERO {
        return Ordering::Less;
    }
    // s / |w| against r, both sides non-negative: s^2 against r^2 |w|^2.
    let s = f.s as u128;
    let r2 = (r as u128) * (r as u128);
    cmp_mul_u128(s, s, r2, len2(f.w))
}

/// `w * (r |w| - s) / |w|^2`, with `|w|` to 2^-32 precision rounded up (so
/// the vector is never shorter than the exact one), each component rounded
/// away from zero.
#[inline]
fn push(f: Feature, r: i64) -> I64Vec2 {
    let w2 = len2(f.w);
    if w2 == 0 {
        // Coincident centres: no geometric direction; push up.
        return I64Vec2::new(0, -r);
    }
    // |w| * 2^32, rounded up: with the floor, an overlap thinner than about
    // r * 2^-32 units made `num` negative and the rounded push point into the
    // shape.
    let l32 = {
        let v = w2 << 64;
        let q = v.isqrt();
        (if q * q < v { q + 1 } else { q }) as i128
    };
    let num = r as i128 * l32 - (f.s << 32);
    let den = (w2 as i128) << 32;
    I64Vec2::new(
        div_away(f.w.x as i128 * num, den) as i64,
        div_away(f.w.y as i128 * num, den) as i64,
    )
}

/// Finds the feature of `b` closest to `c` (b's local coordinates).
#[inline]
fn closest_feature<B: Convex>(b: &B, c: I64Vec2) -> Feature {
    let n = b.vertex_count();
    if n == 1 {
        let d = c - wide(b.vertex(0));
        return Feature {
            w: d,
            s: len2(d) as i128,
            inside: false,
        };
    }
    // Edge regions: the centre is on the outer side of the edge (or on it)
    // and projects inside it. For n >= 3, all-negative sides mean inside.
    let mut all_inside = n >= 3;
    let mut deepest: Option<Feature> = None;
    for i in 0..n {
        let v = wide(b.vertex(i));
        let e = wide(b.vertex(if i + 1 == n { 0 } else { i + 1 })) - v;
        let w = perp(e);
        let cv = c - v;
        let s = cv.x as i128 * w.x as i128 + cv.y as i128 * w.y as i128;
        if s >= 0 {
            all_inside = false;
            let t = cv.x as i128 * e.x as i128 + cv.y as i128 * e.y as i128;
            if t >= 0 && t <= len2(e) as i128 {
                return Feature {
                    w,
                    s,
                    inside: false,
                };
            }
        } else if all_inside {
            // Closest edge from inside: largest s / |w| (s < 0), i.e. the
            // smallest s^2 / |w|^2.
            let f = Feature { w, s, inside: true };
            deepest = Some(match deepest {
                None => f,
                Some(d) => {
                    let (s2, d2) = ((s * s) as u128, (d.s * d.s) as u128);
                    // Equal depths: the push closest to up wins, so the
                    // answer does not depend on where the vertex list starts.
                    match cmp_mul_u128(s2, len2(d.w), d2, len2(w)) {
                        Ordering::Less => f,
                        Ordering::Equal if dir_order(w, d.w) == Ordering::Less => f,
                        _ => d,
                    }
                }
            });
        }
    }
    if all_inside {
        if let Some(d) = deepest {
            return d;
        }
    }
    // Vertex regions: between the normals of the two edges meeting there.
    let mut best: Option<(u128, I64Vec2)> = None;
    for i in 0..n {
        let v = wide(b.vertex(i));
        let next = wide(b.vertex(if i + 1 == n { 0 } else { i + 1 })) - v;
        let prev = v - wide(b.vertex(if i == 0 { n - 1 } else { i - 1 }));
        let d = c - v;
        if d.dot(next) <= 0 && d.dot(prev) >= 0 {
            return Feature {
                w: d,
                s: len2(d) as i128,
                inside: false,
            };
        }
        let l = len2(d);
        if best.is_none_or(|(bl, _)| l < bl) {
            best = Some((l, d));
        }
    }
    // Unreachable for a valid convex shape; the nearest vertex is a safe answer.
    let (l, d) = best.expect("a convex shape has vertices");
    Feature {
        w: d,
        s: l as i128,
        inside: false,
    }
}
