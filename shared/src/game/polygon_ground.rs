//! Polygon solids as ground: where a player's boxes rest on the up-facing
//! faces of the level's static convex polygons, and whether such a face is
//! walkable.
//!
//! The world separates a box from a polygon along the SAT axis of least
//! overlap, which for a box corner on a slanted face is the face normal: the
//! gravity that presses a standing player into a slope comes back as a push
//! with a sideways part, and the player slides. The rules (`rules.rs`) use
//! these answers to treat a walkable face like a tile slope (pushed
//! straight up: no slide; snapped onto when walking down it) and a steeper
//! face as a wall (no ground). Everything is integer and exact.

use glam::{I64Vec2, IVec2};

use crate::shape::{ConvexPolygon, MAX_POLYGON_VERTICES};
use crate::world::BodyId;

/// How far (units) a box's bottom may be from a face, above it or into it,
/// and still rest on it: restitution rounds a slanted push away from zero
/// (up to a unit per axis) and [`PolygonSolid::surface`] rounds heights up.
pub(super) const TOUCH: i64 = 4;

/// The run [`super::PlayerConfig::max_walkable_slope`] is measured over:
/// a slope of `SLOPE_RUN` rises 45 degrees.
pub(super) const SLOPE_RUN: i32 = 256;

/// A static polygon solid of the level, in world units.
#[derive(Debug, Clone)]
pub(super) struct PolygonSolid {
    /// Its body (what contact events name).
    pub body: BodyId,
    /// World vertices, positively wound (as [`ConvexPolygon`] stores them).
    verts: [I64Vec2; MAX_POLYGON_VERTICES],
    len: usize,
}

/// The highest point of a polygon's up-facing faces over an x-span.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Surface {
    /// Its y, rounded up (towards -y): a box bottom there does not overlap
    /// the polygon.
    pub y: i64,
    /// Whether the player stands there: the face reaching that point is no
    /// steeper than the walkable slope, or the point is a vertex strictly
    /// inside the span (the box's flat bottom rests on a tip).
    pub walkable: bool,
}

/// How a body's boxes meet one polygon from above: the smallest
/// `surface - bottom` over the boxes the polygon lies under (negative: the
/// box's bottom is below the face).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Gap {
    /// Distance from the lowest box bottom down to the face (units).
    pub gap: i64,
    /// Whether the face there is walkable ([`Surface::walkable`]).
    pub walkable: bool,
}

impl Gap {
    /// The box rests on the face (within [`TOUCH`]).
    pub fn touching(&self) -> bool {
        self.gap.abs() <= TOUCH
    }
}

impl PolygonSolid {
    /// The polygon `poly` of a static body `body` at `pos`.
    pub fn new(body: BodyId, pos: IVec2, poly: &ConvexPolygon) -> Self {
        let mut verts = [I64Vec2::ZERO; MAX_POLYGON_VERTICES];
        let vs = poly.vertices();
        for (v, p) in verts.iter_mut().zip(vs) {
            *v = (pos + *p).as_i64vec2();
        }
        PolygonSolid {
            body,
            verts,
            len: vs.len(),
        }
    }

    /// The highest point of the up-facing faces (outward normal pointing to
    /// -y) over the closed x-span `[l, r]`, or `None` when no such face lies
    /// under it. `slope` is the steepest walkable rise per [`SLOPE_RUN`].
    ///
    /// A face's height is linear in x, so its highest point over the span is
    /// at one end of the part of the face the span covers; an end strictly
    /// inside the span is a vertex under the box's flat bottom.
    pub fn surface(&self, l: i64, r: i64, slope: i32) -> Option<Surface> {
        let mut best: Option<Surface> = None;
        for i in 0..self.len {
            let p = self.verts[i];
            let q = self.verts[(i + 1) % self.len];
            let d = q - p;
            // Positive winding: the outward normal is (d.y, -d.x); up-facing
            // means -d.x < 0. Vertical faces (d.x = 0) are sides.
            if d.x <= 0 {
                continue;
            }
            let (a, b) = (l.max(p.x), r.min(q.x));
            if a > b {
                continue;
            }
            let steep =
                d.y.unsigned_abs() as i128 * SLOPE_RUN as i128 > d.x as i128 * slope.max(0) as i128;
            for x in [a, b] {
                // floor(d.y (x - p.x) / d.x): rounded towards -y, d.x > 0.
                let num = d.y as i128 * (x - p.x) as i128;
                let y = p.y + num.div_euclid(d.x as i128) as i64;
                let here = Surface {
                    y,
                    walkable: !steep || (l < x && x < r),
                };
                best = Some(match best {
                    Some(s) if s.y < here.y => s,
                    Some(s) if s.y == here.y => Surface {
                        y,
                        walkable: s.walkable || here.walkable,
                    },
                    _ => here,
                });
            }
        }
        best
    }

    /// How the boxes `(half extents, offset)` of a body at `pos` meet this
    /// polygon from above ([`Gap`]), or `None` when it lies under none of
    /// them. Ties between boxes favour a walkable face.
    pub fn gap(&self, pos: IVec2, boxes: &[(IVec2, IVec2)], slope: i32) -> Option<Gap> {
        let mut best: Option<Gap> = None;
        for &(half, offset) in boxes {
            let c = (pos + offset).as_i64vec2();
            let h = half.as_i64vec2();
            let Some(s) = self.surface(c.x - h.x, c.x + h.x, slope) else {
                continue;
            };
            let here = Gap {
                gap: s.y - (c.y + h.y),
                walkable: s.walkable,
            };
            best = Some(match best {
                Some(g) if g.gap < here.gap => g,
                Some(g) if g.gap == here.gap => Gap {
                    gap: g.gap,
                    walkable: g.walkable || here.walkable,
                },
                _ => here,
            });
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PX: i32 = 256;

    /// The 1:4 ramp of `ramp.tmx`: (96, 96) px up to (160, 80) px.
    fn ramp() -> PolygonSolid {
        let v = |x: i32, y: i32| IVec2::new(x * PX, y * PX);
        let poly = ConvexPolygon::new(&[v(-32, 8), v(32, -8), v(32, 8)]).unwrap();
        PolygonSolid::new(BodyId(7), v(128, 88), &poly)
    }

    #[test]
    fn the_surface_is_the_highest_up_facing_point_over_the_span() {
        let r = ramp();
        let px = |x: i32| (x * PX) as i64;
        // Box corner on the slope at x = 112 px: 92 px high.
        let s = r.surface(px(100), px(112), 256).unwrap();
        assert_eq!(
            s,
            Surface {
                y: px(92),
                walkable: true
            }
        );
        // A quarter unit of height rounds up (towards -y).
        let s = r.surface(px(100), px(112) + 1, 256).unwrap();
        assert_eq!(s.y, px(92) - 1);
        // Over the top vertex: the tip, under a flat bottom.
        let s = r.surface(px(150), px(170), 0).unwrap();
        assert_eq!(
            s,
            Surface {
                y: px(80),
                walkable: true
            }
        );
        // Steeper than allowed: 1:4 is 64 per 256.
        let s = r.surface(px(100), px(112), 63).unwrap();
        assert!(!s.walkable);
        assert!(r.surface(px(100), px(112), 64).unwrap().walkable);
        // Off the sides, or under only the vertical face: nothing.
        assert_eq!(r.surface(px(0), px(95), 256), None);
        assert_eq!(r.surface(px(161), px(200), 256), None);
    }

    #[test]
    fn the_gap_is_taken_over_every_box() {
        let r = ramp();
        let boxes = [(IVec2::new(6 * PX, 8 * PX), IVec2::ZERO)];
        // Box 12 x 16 px with its bottom right corner at (112, 92) px.
        let pos = IVec2::new(106 * PX, 84 * PX);
        let g = r.gap(pos, &boxes, 256).unwrap();
        assert_eq!(
            g,
            Gap {
                gap: 0,
                walkable: true
            }
        );
        assert!(g.touching());
        let g = r.gap(pos - IVec2::new(0, 10), &boxes, 256).unwrap();
        assert_eq!(g.gap, 10);
        // Two boxes: the lower one counts.
        let two = [boxes[0], (IVec2::new(6 * PX, PX), IVec2::new(0, 8 * PX))];
        let g = r.gap(pos - IVec2::new(0, 10), &two, 256).unwrap();
        assert!(g.gap < 10, "{g:?}");
    }
}
