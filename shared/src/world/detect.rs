//! Detection: every pair of colliders that may interact, tested exactly.
//!
//! Brute force over pairs for now: one generic loop per pair of shape kinds
//! (21 monomorphised instances, same-kind pairs with `j > i`), a bounding-box
//! reject, then the narrow phase ([`Contact`]). The only entry point is
//! [`detect_all`], so a broad phase can replace the pair enumeration without
//! touching restitution.

use crate::query::{Contact, Proximity};
use crate::shape::{Aabb, Circle, ConvexPolygon, Obb, Point, Segment};
use glam::IVec2;

use super::body::Body;
use super::collider::{ColliderData, Colliders, Stored};
use super::contact::{ContactKind, ContactRecord, End};

/// Clears `out` and fills it with every overlapping pair that matters:
///
/// * not two colliders of the same body;
/// * layers and masks agree both ways;
/// * at least one collider is solid (no trigger-trigger pairs);
/// * at least one body is dynamic (static and kinematic bodies never push
///   each other; a trigger reports a dynamic body's solid, and a dynamic
///   body's trigger reports any solid).
///
/// The output order is fixed (kind pair, then set indices), so it is
/// deterministic before any sort.
pub(crate) fn detect_all(cols: &Colliders, bodies: &[Body], out: &mut Vec<ContactRecord>) {
    out.clear();
    detect_pair::<Point, Point>(cols, bodies, out);
    detect_pair::<Point, Segment>(cols, bodies, out);
    detect_pair::<Point, Circle>(cols, bodies, out);
    detect_pair::<Point, Aabb>(cols, bodies, out);
    detect_pair::<Point, Obb>(cols, bodies, out);
    detect_pair::<Point, ConvexPolygon>(cols, bodies, out);
    detect_pair::<Segment, Segment>(cols, bodies, out);
    detect_pair::<Segment, Circle>(cols, bodies, out);
    detect_pair::<Segment, Aabb>(cols, bodies, out);
    detect_pair::<Segment, Obb>(cols, bodies, out);
    detect_pair::<Segment, ConvexPolygon>(cols, bodies, out);
    detect_pair::<Circle, Circle>(cols, bodies, out);
    detect_pair::<Circle, Aabb>(cols, bodies, out);
    detect_pair::<Circle, Obb>(cols, bodies, out);
    detect_pair::<Circle, ConvexPolygon>(cols, bodies, out);
    detect_pair::<Aabb, Aabb>(cols, bodies, out);
    detect_pair::<Aabb, Obb>(cols, bodies, out);
    detect_pair::<Aabb, ConvexPolygon>(cols, bodies, out);
    detect_pair::<Obb, Obb>(cols, bodies, out);
    detect_pair::<Obb, ConvexPolygon>(cols, bodies, out);
    detect_pair::<ConvexPolygon, ConvexPolygon>(cols, bodies, out);
}

/// All pairs of a kind-`A` collider and a kind-`B` collider.
#[inline(never)]
fn detect_pair<A, B>(cols: &Colliders, bodies: &[Body], out: &mut Vec<ContactRecord>)
where
    A: Stored + Contact<B>,
    B: Stored,
{
    let sa = &A::set(cols).items;
    let sb = &B::set(cols).items;
    if sa.is_empty() || sb.is_empty() {
        return;
    }
    // Same kind: one set, each unordered pair once (`j > i`).
    let same = A::KIND == B::KIND;
    for (i, ca) in sa.iter().enumerate() {
        let pos_a = bodies[ca.body as usize].pos;
        let (alo, ahi) = (pos_a + ca.lo, pos_a + ca.hi);
        let first = if same { i + 1 } else { 0 };
        for (j, cb) in sb.iter().enumerate().skip(first) {
            if !(ca.dynamic || cb.dynamic) || !(ca.solid || cb.solid) || ca.body == cb.body {
                continue;
            }
            if ca.layer & cb.mask == 0 || cb.layer & ca.mask == 0 {
                continue;
            }
            let pos_b = bodies[cb.body as usize].pos;
            let (blo, bhi) = (pos_b + cb.lo, pos_b + cb.hi);
            // Boxes that only touch cannot have overlapping interiors.
            if bhi.x <= alo.x || blo.x >= ahi.x || bhi.y <= alo.y || blo.y >= ahi.y {
                continue;
            }
            let Proximity::Overlapping(mtv) =
                ca.shape
                    .contact(pos_a + ca.offset, &cb.shape, pos_b + cb.offset)
            else {
                continue;
            };
            let ix = (ahi.x.min(bhi.x) as i64 - alo.x.max(blo.x) as i64) as u64;
            let iy = (ahi.y.min(bhi.y) as i64 - alo.y.max(blo.y) as i64) as u64;
            out.push(ContactRecord {
                a: end_of(i, ca),
                b: end_of(j, cb),
                mtv,
                kind: if ca.solid && cb.solid {
                    ContactKind::Solid
                } else {
                    ContactKind::Trigger
                },
                pos_a,
                pos_b,
                area: ix.saturating_mul(iy),
                recheck: recheck::<A, B>,
            });
        }
    }
}

/// The contact end for collider `c` at `index` in its set.
#[inline(always)]
fn end_of<S>(index: usize, c: &ColliderData<S>) -> End {
    End {
        body: c.body,
        collider: c.id,
        index: index as u32,
        tag: c.tag,
        one_way: c.one_way,
        solid: c.solid,
    }
}

/// The narrow phase for one stored pair at the given body positions.
fn recheck<A, B>(cols: &Colliders, ia: u32, pos_a: IVec2, ib: u32, pos_b: IVec2) -> Proximity
where
    A: Stored + Contact<B>,
    B: Stored,
{
    let a = &A::set(cols).items[ia as usize];
    let b = &B::set(cols).items[ib as usize];
    a.shape
        .contact(pos_a + a.offset, &b.shape, pos_b + b.offset)
}
