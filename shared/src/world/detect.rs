//! Detection: every pair of colliders that may interact, tested exactly.
//!
//! Brute force over pairs for now: one generic loop per pair of shape kinds
//! (21 monomorphised instances, same-kind pairs with `j > i`), a bounding-box
//! reject, then the narrow phase ([`Contact`]). Then [`detect_tiles`] asks the
//! world's tilemap ([`Tilemap::box_contacts`]) about every solid box collider
//! of an enabled dynamic body: tile contacts are records against one static
//! end, [`BodyId::TILEMAP`] (no per-tile collider exists). These are the only
//! entry points, so a broad phase can replace the pair enumeration without
//! touching restitution.

use crate::query::{Contact, Proximity};
use crate::shape::{Aabb, Circle, ConvexPolygon, Obb, Point, Segment};
use crate::tilemap::{ContactFlags, Tile, TileContact, Tilemap};
use glam::IVec2;

use super::body::{Body, BodyId};
use super::collider::{ColliderData, Colliders, Stored};
use super::contact::{ContactKind, ContactRecord, End};

/// Clears `out` and fills it with every overlapping pair that matters:
///
/// * not two colliders of the same body;
/// * layers and masks agree both ways;
/// * at least one collider is solid (no trigger-trigger pairs);
/// * at least one body is dynamic (static and kinematic bodies never push
///   each other; a trigger reports a dynamic body's solid, and a dynamic
///   body's trigger reports any solid);
/// * both bodies are enabled.
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
        let body_a = &bodies[ca.body as usize];
        if !body_a.enabled {
            continue;
        }
        let pos_a = body_a.pos;
        let (alo, ahi) = (pos_a + ca.lo, pos_a + ca.hi);
        let first = if same { i + 1 } else { 0 };
        for (j, cb) in sb.iter().enumerate().skip(first) {
            if !(ca.dynamic || cb.dynamic) || !(ca.solid || cb.solid) || ca.body == cb.body {
                continue;
            }
            if ca.layer & cb.mask == 0 || cb.layer & ca.mask == 0 {
                continue;
            }
            let body_b = &bodies[cb.body as usize];
            if !body_b.enabled {
                continue;
            }
            let pos_b = body_b.pos;
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
                tile: IVec2::ZERO,
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

/// The layer bit of the world's tilemap: a collider interacts with tiles when
/// its `mask` has this bit (the default mask has every bit).
pub const TILEMAP_LAYER: u32 = 1 << 31;

/// The tag tile contacts report for the tilemap end (in events).
pub const TILEMAP_TAG: u16 = u16::MAX;

/// The tile query flags of a body.
#[inline]
pub(crate) fn tile_flags(b: &Body) -> ContactFlags {
    ContactFlags {
        drop_through: b.drop_through,
    }
}

/// Appends to `out` one record per tile contact of every solid box collider
/// (mask with [`TILEMAP_LAYER`]) of an enabled dynamic body, in collider
/// order then row-major tile order: a solid record for a tile that pushes, a
/// trigger record (zero MTV) for an overlapped hazard. `scratch` is reused.
pub(crate) fn detect_tiles(
    map: &Tilemap,
    cols: &Colliders,
    bodies: &[Body],
    scratch: &mut Vec<TileContact>,
    out: &mut Vec<ContactRecord>,
) {
    let t = map.tile_size() as i64;
    let origin = map.origin().as_i64vec2();
    for (i, c) in cols.aabbs.items.iter().enumerate() {
        if !c.dynamic || !c.solid || c.mask & TILEMAP_LAYER == 0 {
            continue;
        }
        let b = &bodies[c.body as usize];
        if !b.enabled {
            continue;
        }
        let centre = b.pos + c.offset;
        scratch.clear();
        map.box_contacts(
            centre,
            c.shape.half(),
            b.pos - b.start,
            tile_flags(b),
            scratch,
        );
        let (lo, hi) = ((b.pos + c.lo).as_i64vec2(), (b.pos + c.hi).as_i64vec2());
        for tc in scratch.iter() {
            if !tile_push_ok(map, tc.tile, tc.kind, centre, tc.mtv) {
                continue;
            }
            let tlo = origin + tc.tile.as_i64vec2() * t;
            let thi = tlo + t;
            let ix = (hi.x.min(thi.x) - lo.x.max(tlo.x)).max(0) as u64;
            let iy = (hi.y.min(thi.y) - lo.y.max(tlo.y)).max(0) as u64;
            let solid = tc.kind != Tile::Hazard;
            out.push(ContactRecord {
                a: end_of(i, c),
                b: End {
                    body: BodyId::TILEMAP.0,
                    collider: BodyId::TILEMAP.0,
                    index: 0,
                    tag: TILEMAP_TAG,
                    one_way: None,
                    solid,
                },
                mtv: tc.mtv,
                kind: if solid {
                    ContactKind::Solid
                } else {
                    ContactKind::Trigger
                },
                pos_a: b.pos,
                pos_b: IVec2::ZERO,
                area: ix.saturating_mul(iy),
                recheck: no_recheck,
                tile: tc.tile,
            });
        }
    }
}

/// Whether a tile's push is one the world applies: a [`Tile::Solid`] tile
/// never pushes a box towards its far side, that is, every non-zero MTV
/// component must point from the tile's centre towards the box's centre (or
/// the centres are level on that axis).
///
/// Edge culling can leave a solid tile whose near faces are hidden by its
/// neighbours but whose far faces are exposed (the corner of a one-tile
/// thick floor and wall, a floor tile under a slope on the grid's last row):
/// a box resting against the neighbours dips a few units into it, and its
/// only "way out" is a push of most of a tile through the far face, which
/// largest-MTV-first would apply before the neighbours' small pushes. The
/// neighbours hold the box; this tile must not push it through them.
#[inline]
pub(crate) fn tile_push_ok(
    map: &Tilemap,
    tile: IVec2,
    kind: Tile,
    centre: IVec2,
    mtv: IVec2,
) -> bool {
    if kind != Tile::Solid {
        return true;
    }
    let t = map.tile_size() as i64;
    // Doubled coordinates: the tile centre is a whole number there.
    let tc = (map.origin().as_i64vec2() + tile.as_i64vec2() * t) * 2 + t;
    let bc = centre.as_i64vec2() * 2;
    let ok = |m: i32, b: i64, c: i64| (m <= 0 || b >= c) && (m >= 0 || b <= c);
    ok(mtv.x, bc.x, tc.x) && ok(mtv.y, bc.y, tc.y)
}

/// The re-check slot of a tile record (restitution re-checks tiles through
/// [`Tilemap::tile_contact`] instead; never called).
fn no_recheck(_: &Colliders, _: u32, _: IVec2, _: u32, _: IVec2) -> Proximity {
    Proximity::Apart
}
