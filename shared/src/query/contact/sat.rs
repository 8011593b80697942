//! The separating axis test with an exact minimum translation vector.

use super::proximity::Proximity;
use crate::fixed::{cmp_mul_u128, div_away, len2, line_order, wide};
use crate::shape::Convex;
use core::cmp::Ordering;
use glam::{I64Vec2, IVec2};

/// Best axis found so far: overlap `o` along `dir` (in units of `|dir|`).
struct Best {
    o: i64,
    dir: I64Vec2,
    len2: u128,
}

/// SAT over the axes of `a` then `b`. The MTV moves `a`.
///
/// Along each axis `n` the push that separates `a` towards `-n` is
/// `amax - bmin` and towards `+n` is `bmax - amin`; a negative one means a
/// gap (apart), a zero one a touch. The depth of an axis is `o / |n|`, compared
/// across axes exactly with [`cmp_mul_u128`].
#[inline]
pub(crate) fn sat<A: Convex, B: Convex>(a: &A, pos_a: IVec2, b: &B, pos_b: IVec2) -> Proximity {
    let rel = wide(pos_b) - wide(pos_a);
    // Bounding boxes first: cheap, and it keeps every later product small.
    let (alo, ahi) = a.local_bounds();
    let (blo, bhi) = b.local_bounds();
    let (blo, bhi) = (wide(blo) + rel, wide(bhi) + rel);
    let (alo, ahi) = (wide(alo), wide(ahi));
    if bhi.x < alo.x || blo.x > ahi.x || bhi.y < alo.y || blo.y > ahi.y {
        return Proximity::Apart;
    }
    let mut touching = false;
    let mut best: Option<Best> = None;
    for i in 0..a.axis_count() {
        if !test_axis(a, b, rel, a.axis(i), &mut touching, &mut best) {
            return Proximity::Apart;
        }
    }
    for i in 0..b.axis_count() {
        if !test_axis(a, b, rel, b.axis(i), &mut touching, &mut best) {
            return Proximity::Apart;
        }
    }
    match best {
        _ if touching => Proximity::Touching,
        Some(best) => Proximity::Overlapping(mtv_along(best.dir, best.o, best.len2)),
        // No axis at all (two points): only equality could relate them, and
        // the point-point pair handles that itself.
        None => Proximity::Touching,
    }
}

/// Tests one axis; returns false when it separates the shapes.
#[inline(always)]
fn test_axis<A: Convex, B: Convex>(
    a: &A,
    b: &B,
    rel: I64Vec2,
    n: I64Vec2,
    touching: &mut bool,
    best: &mut Option<Best>,
) -> bool {
    let (amin, amax) = a.project(n);
    let (bmin, bmax) = b.project(n);
    let shift = rel.dot(n);
    let (bmin, bmax) = (bmin + shift, bmax + shift);
    let push_neg = amax - bmin;
    let push_pos = bmax - amin;
    if push_neg < 0 || push_pos < 0 {
        return false;
    }
    if push_neg == 0 || push_pos == 0 {
        *touching = true;
        return true;
    }
    if *touching {
        return true;
    }
    let (o, dir) = match push_neg.cmp(&push_pos) {
        Ordering::Less => (push_neg, -n),
        Ordering::Greater => (push_pos, n),
        // Centred: no geometric side; push up (or left on a horizontal axis).
        Ordering::Equal => (push_pos, up_of(n)),
    };
    let l2 = len2(n);
    let better = match best {
        None => true,
        Some(b) => {
            let o2 = (o as u128) * (o as u128);
            let bo2 = (b.o as u128) * (b.o as u128);
            match cmp_mul_u128(o2, b.len2, bo2, l2) {
                Ordering::Less => true,
                Ordering::Greater => false,
                Ordering::Equal => line_order(n, b.dir) == Ordering::Less,
            }
        }
    };
    if better {
        *best = Some(Best { o, dir, len2: l2 });
    }
    true
}

/// The orientation of axis `n` that points up (`y < 0`), or left when horizontal.
#[inline]
fn up_of(n: I64Vec2) -> I64Vec2 {
    if n.y > 0 || (n.y == 0 && n.x > 0) {
        -n
    } else {
        n
    }
}

/// `dir * o / |dir|^2`, each component rounded away from zero.
#[inline]
pub(crate) fn mtv_along(dir: I64Vec2, o: i64, len2: u128) -> IVec2 {
    let den = len2 as i128;
    let x = div_away(dir.x as i128 * o as i128, den);
    let y = div_away(dir.y as i128 * o as i128, den);
    IVec2::new(x as i32, y as i32)
}
