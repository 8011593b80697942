//! What collides, read from the editor's own data: the property and class
//! names level authors use to mark tiles, layers and objects, and tile
//! collision outlines turned into ledge tiles or static geometry.
//!
//! Names are matched ASCII case-insensitively with `-` and spaces read as
//! `_` (see `docs/LEVELS.md`, "What collides", for the table):
//!
//! | on | names | meaning |
//! |---|---|---|
//! | tile, object (bool property, true) | `solid`, `collides`, `collision`, `collidable`, `collide`, `blocked`, `block`, `wall`, `obstacle` | solid |
//! | tile, object (bool property, true) | `one_way`, `oneway`, `platform`, `jump_through`, `jumpthrough`, `semi_solid`, `semisolid`, `pass_through` | one-way (a tile's top edge) |
//! | tile, object (bool property, true) | `hazard`, `deadly`, `lethal`, `kill`, `kills`, `damage`, `harmful`, `spike`, `spikes`, `lava`, `death` | hazard |
//! | object (string property `bodyType`/`body_type`/`body`) | `static` | solid |
//! | tile, object (string property `kind`, or the class) | a tile kind name (`solid`, `one_way`, `hazard`, `slope_45_right`, ...) | that kind |
//! | layer (bool property, true) | the solid names above | every tile of the layer collides (unless the tile says otherwise) |
//! | layer (bool property, true) | `nocollide`, `no_collide`, `no_collision`, `nocollision`, `decoration`, `decor`, `ignore_collision` | the layer never collides |
//! | layer (class) | `collision`, `collisions`, `solid`, `solids`, `collider`, `colliders`, `walls`, `ground`, `terrain`, `platforms` | as the solid property |
//! | layer (class) | `decoration`, `decor`, `background`, `foreground`, `nocollide` | as `nocollide` |
//!
//! A property set to false says the opposite: `solid = false` on a tile makes
//! it empty, `collision = false` on a layer makes it non-colliding.

pub(crate) mod infer;
pub(crate) mod names;
pub(crate) mod resample;

use ledge_shared::tilemap::{Slope, Tile};

use crate::mapping::{normalize, parse_tile_kind};

/// A property value as far as collision cares.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Prop<'a> {
    Bool(bool),
    Text(&'a str),
    Other,
}

const SOLID: &[&str] = &[
    "solid",
    "collides",
    "collision",
    "collidable",
    "collide",
    "blocked",
    "block",
    "wall",
    "obstacle",
];
const ONE_WAY: &[&str] = &[
    "one_way",
    "oneway",
    "platform",
    "jump_through",
    "jumpthrough",
    "semi_solid",
    "semisolid",
    "pass_through",
];
const HAZARD: &[&str] = &[
    "hazard", "deadly", "lethal", "kill", "kills", "damage", "harmful", "spike", "spikes", "lava",
    "death",
];
const NO_COLLIDE: &[&str] = &[
    "nocollide",
    "no_collide",
    "no_collision",
    "nocollision",
    "decoration",
    "decor",
    "ignore_collision",
];
const LAYER_SOLID_CLASSES: &[&str] = &[
    "collision",
    "collisions",
    "solid",
    "solids",
    "collider",
    "colliders",
    "walls",
    "ground",
    "terrain",
    "platforms",
];
const LAYER_DECOR_CLASSES: &[&str] = &[
    "decoration",
    "decor",
    "background",
    "foreground",
    "nocollide",
];
/// Layer names that mark a collision layer when a map carries no collision
/// data at all (no tile shapes, no collision properties or classes).
const COLLISION_LAYER_NAMES: &[&str] = &[
    "collision",
    "collisions",
    "collider",
    "colliders",
    "solid",
    "solids",
    "walls",
    "wall",
    "ground",
    "terrain",
    "platforms",
    "level",
    "world",
    "blocks",
];

/// What a tile or an object's properties and class say about collision:
/// `Some(tile)` when they say something (`Tile::Empty` for "not solid"),
/// `None` when they are silent. A `kind` property wins over the flags; the
/// class counts when it is a tile kind name.
pub(crate) fn tile_of_props<'a>(
    props: impl IntoIterator<Item = (&'a str, Prop<'a>)>,
    class: &str,
) -> Result<Option<Tile>, String> {
    let mut said = None;
    let mut kind = None;
    for (key, value) in props {
        let key = normalize(key);
        match (key.as_str(), value) {
            ("kind", Prop::Text(s)) => {
                kind =
                    Some(parse_tile_kind(s).ok_or_else(|| {
                        format!("kind {s:?} is not a tile kind ({})", KIND_NAMES)
                    })?);
            }
            ("body_type" | "bodytype" | "body", Prop::Text(s)) => {
                said = Some(if normalize(s) == "static" {
                    Tile::Solid
                } else {
                    Tile::Empty
                });
            }
            (k, Prop::Bool(b)) => {
                let tile = if SOLID.contains(&k) {
                    Tile::Solid
                } else if ONE_WAY.contains(&k) {
                    Tile::OneWay
                } else if HAZARD.contains(&k) {
                    Tile::Hazard
                } else {
                    continue;
                };
                // A true flag wins over a false one (`solid = false` with
                // `hazard = true` is a hazard).
                if b {
                    said = Some(tile);
                } else if said.is_none() {
                    said = Some(Tile::Empty);
                }
            }
            _ => {}
        }
    }
    if kind.is_some() {
        return Ok(kind);
    }
    if said.is_some() {
        return Ok(said);
    }
    Ok(if class.trim().is_empty() {
        None
    } else {
        parse_tile_kind(class)
    })
}

/// The kind names accepted by `kind` (for messages).
pub(crate) const KIND_NAMES: &str = "empty, solid, one_way, hazard, slope_45_right, slope_45_left, slope_22_right_low, slope_22_right_high, slope_22_left_high, slope_22_left_low";

/// What a layer's properties and class say: `Some(true)` collides,
/// `Some(false)` never collides, `None` silent.
pub(crate) fn layer_collides<'a>(
    props: impl IntoIterator<Item = (&'a str, Prop<'a>)>,
    class: &str,
) -> Option<bool> {
    for (key, value) in props {
        let key = normalize(key);
        if let Prop::Bool(b) = value {
            if SOLID.contains(&key.as_str()) || key == "collisions" {
                return Some(b);
            }
            if NO_COLLIDE.contains(&key.as_str()) {
                return Some(!b);
            }
        }
    }
    let class = normalize(class);
    if LAYER_SOLID_CLASSES.contains(&class.as_str()) {
        Some(true)
    } else if LAYER_DECOR_CLASSES.contains(&class.as_str()) {
        Some(false)
    } else {
        None
    }
}

/// Words of a layer's name that mark a collision layer ("Walls level 2",
/// "Ground_1"), unless another word marks decoration.
const COLLISION_LAYER_WORDS: &[&str] = &[
    "collision",
    "collisions",
    "collider",
    "colliders",
    "solid",
    "solids",
    "wall",
    "walls",
    "ground",
    "terrain",
    "platform",
    "platforms",
    "blocks",
];
const DECORATION_LAYER_WORDS: &[&str] = &[
    "decoration",
    "decorations",
    "decor",
    "deco",
    "background",
    "foreground",
    "bg",
    "fg",
    "shadow",
    "shadows",
];

/// Whether a layer's name marks it as a collision layer (used only when the
/// map carries no collision data at all): the whole name (`level`,
/// `world`, ...) or one of its words (`Walls level 2`), and no decoration
/// word (`Ground decoration`).
pub(crate) fn is_collision_layer_name(name: &str) -> bool {
    let n = normalize(name);
    let words: Vec<&str> = n.split('_').filter(|w| !w.is_empty()).collect();
    if words.iter().any(|w| DECORATION_LAYER_WORDS.contains(w))
        || names::decoration_word(name).is_some()
    {
        return false;
    }
    COLLISION_LAYER_NAMES.contains(&n.as_str())
        || words.iter().any(|w| COLLISION_LAYER_WORDS.contains(w))
}

/// An outline in tile-local pixels (origin at the tile's top-left corner).
pub(crate) type Outline = Vec<(f64, f64)>;

/// What a tile's collision outlines amount to on the grid.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum TileShape {
    /// One ledge tile kind covers them exactly (a full square, a slope).
    Tile(Tile),
    /// Static geometry outside the grid: these outlines, tile-local pixels.
    Geometry(Vec<Outline>),
}

/// Classifies a tile's outlines (tile-local pixels, flips already applied)
/// on a tile of `t` pixels: one outline equal to the whole square is a solid
/// tile, one equal to a slope's region is that slope (within 1/16 of the
/// tile), anything else stays geometry.
pub(crate) fn classify_outlines(outlines: Vec<Outline>, t: f64) -> TileShape {
    if let [one] = outlines.as_slice() {
        let eps = t / 16.0;
        let mut pts = simplify(one, eps);
        if pts.len() >= 3 {
            normalise_start(&mut pts);
            for tile in std::iter::once(Tile::Solid).chain(Slope::ALL.into_iter().map(Tile::Slope))
            {
                let mut want = region_outline(tile, t);
                normalise_start(&mut want);
                if same_outline(&pts, &want, eps) {
                    return TileShape::Tile(tile);
                }
            }
        }
    }
    TileShape::Geometry(outlines)
}

/// The outline of a solid tile or a slope's solid region, clockwise on
/// screen (y down), tile-local pixels.
pub(crate) fn region_outline(tile: Tile, t: f64) -> Outline {
    let h = t / 2.0;
    match tile {
        Tile::Slope(Slope::Right45) => vec![(0.0, t), (t, 0.0), (t, t)],
        Tile::Slope(Slope::Left45) => vec![(0.0, 0.0), (t, t), (0.0, t)],
        Tile::Slope(Slope::RightLow22) => vec![(0.0, t), (t, h), (t, t)],
        Tile::Slope(Slope::RightHigh22) => vec![(0.0, h), (t, 0.0), (t, t), (0.0, t)],
        Tile::Slope(Slope::LeftHigh22) => vec![(0.0, 0.0), (t, h), (t, t), (0.0, t)],
        Tile::Slope(Slope::LeftLow22) => vec![(0.0, h), (t, t), (0.0, t)],
        _ => vec![(0.0, 0.0), (t, 0.0), (t, t), (0.0, t)],
    }
}

/// Applies Tiled's tile flips to tile-local points: the diagonal flip
/// (swap x and y) first, then horizontal, then vertical.
pub(crate) fn flip(points: &mut [(f64, f64)], t: f64, h: bool, v: bool, d: bool) {
    for p in points {
        if d {
            *p = (p.1, p.0);
        }
        if h {
            p.0 = t - p.0;
        }
        if v {
            p.1 = t - p.1;
        }
    }
}

/// Drops repeated points and points on the line through their neighbours.
fn simplify(points: &[(f64, f64)], eps: f64) -> Outline {
    let mut out: Outline = Vec::with_capacity(points.len());
    for &p in points {
        if out
            .last()
            .is_none_or(|q| (p.0 - q.0).abs() > eps || (p.1 - q.1).abs() > eps)
        {
            out.push(p);
        }
    }
    while out.len() > 1 {
        let (a, b) = (out[0], out[out.len() - 1]);
        if (a.0 - b.0).abs() <= eps && (a.1 - b.1).abs() <= eps {
            out.pop();
        } else {
            break;
        }
    }
    let mut i = 0;
    while out.len() >= 3 && i < out.len() {
        let n = out.len();
        let (a, b, c) = (out[(i + n - 1) % n], out[i], out[(i + 1) % n]);
        let cross = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
        let len = ((c.0 - a.0).powi(2) + (c.1 - a.1).powi(2)).sqrt().max(1e-9);
        if (cross / len).abs() <= eps {
            out.remove(i);
        } else {
            i += 1;
        }
    }
    out
}

/// Makes the winding clockwise on screen and starts at the smallest point
/// (by y, then x), so equal outlines compare equal.
fn normalise_start(points: &mut Outline) {
    let area: f64 = (0..points.len())
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % points.len()]);
            a.0 * b.1 - b.0 * a.1
        })
        .sum();
    if area < 0.0 {
        points.reverse();
    }
    let start = (0..points.len())
        .min_by(|&i, &j| {
            let (a, b) = (points[i], points[j]);
            (a.1, a.0)
                .partial_cmp(&(b.1, b.0))
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .unwrap_or(0);
    points.rotate_left(start);
}

fn same_outline(a: &Outline, b: &Outline, eps: f64) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(p, q)| (p.0 - q.0).abs() <= eps && (p.1 - q.1).abs() <= eps)
}

/// Whether an outline is strictly convex (every turn the same way, no
/// straight corners, not crossing itself: the turns add up to one full
/// turn).
pub(crate) fn is_convex(points: &[(f64, f64)]) -> bool {
    let n = points.len();
    if n < 3 {
        return false;
    }
    let mut sign = 0.0f64;
    let mut turning = 0.0f64;
    for i in 0..n {
        let (a, b, c) = (points[i], points[(i + 1) % n], points[(i + 2) % n]);
        let (u, v) = ((b.0 - a.0, b.1 - a.1), (c.0 - b.0, c.1 - b.1));
        let cross = u.0 * v.1 - u.1 * v.0;
        if cross == 0.0 || (sign != 0.0 && cross.signum() != sign) {
            return false;
        }
        sign = cross.signum();
        turning += cross.atan2(u.0 * v.0 + u.1 * v.1);
    }
    (turning.abs() - std::f64::consts::TAU).abs() < 1e-6
}

/// Splits a simple polygon (either winding, not crossing itself) into
/// triangles by ear clipping, then merges neighbouring triangles while the
/// result stays convex and at most `max_points` points; `None` when the
/// outline crosses itself or is degenerate.
pub(crate) fn convex_pieces(points: &[(f64, f64)], max_points: usize) -> Option<Vec<Outline>> {
    let mut pts: Outline = points.to_vec();
    if signed_area(&pts) < 0.0 {
        pts.reverse();
    }
    let n = pts.len();
    if n < 3 || signed_area(&pts).abs() < 1e-9 || crosses_itself(&pts) {
        return None;
    }
    // Ear clipping on indices (counter-clockwise in maths terms, so a left
    // turn is convex).
    let mut idx: Vec<usize> = (0..n).collect();
    let mut tris: Vec<[usize; 3]> = Vec::with_capacity(n - 2);
    let cross = |a: (f64, f64), b: (f64, f64), c: (f64, f64)| {
        (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
    };
    let mut guard = 0;
    while idx.len() > 3 {
        guard += 1;
        if guard > 4 * n * n {
            return None;
        }
        let m = idx.len();
        let mut clipped = false;
        for i in 0..m {
            let (ia, ib, ic) = (idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]);
            let (a, b, c) = (pts[ia], pts[ib], pts[ic]);
            if cross(a, b, c) <= 0.0 {
                continue;
            }
            let inside = idx.iter().any(|&j| {
                j != ia
                    && j != ib
                    && j != ic
                    && cross(a, b, pts[j]) >= 0.0
                    && cross(b, c, pts[j]) >= 0.0
                    && cross(c, a, pts[j]) >= 0.0
            });
            if !inside {
                tris.push([ia, ib, ic]);
                idx.remove(i);
                clipped = true;
                break;
            }
        }
        if !clipped {
            // Only collinear points left: drop one.
            let m = idx.len();
            let i = (0..m).find(|&i| {
                let (a, b, c) = (
                    pts[idx[(i + m - 1) % m]],
                    pts[idx[i]],
                    pts[idx[(i + 1) % m]],
                );
                cross(a, b, c).abs() < 1e-9
            })?;
            idx.remove(i);
        }
    }
    if cross(pts[idx[0]], pts[idx[1]], pts[idx[2]]) > 0.0 {
        tris.push([idx[0], idx[1], idx[2]]);
    }
    // Merge triangles across shared edges while convex.
    let mut pieces: Vec<Vec<usize>> = tris.into_iter().map(|t| t.to_vec()).collect();
    let mut merged = true;
    while merged {
        merged = false;
        'outer: for i in 0..pieces.len() {
            for j in i + 1..pieces.len() {
                if let Some(u) = union_on_edge(&pieces[i], &pieces[j]) {
                    let poly: Outline = u.iter().map(|&k| pts[k]).collect();
                    if u.len() <= max_points && is_convex(&poly) {
                        pieces[i] = u;
                        pieces.remove(j);
                        merged = true;
                        break 'outer;
                    }
                }
            }
        }
    }
    Some(
        pieces
            .into_iter()
            .map(|p| p.into_iter().map(|k| pts[k]).collect())
            .collect(),
    )
}

/// Two index cycles (same winding) sharing one edge, joined along it.
fn union_on_edge(a: &[usize], b: &[usize]) -> Option<Vec<usize>> {
    let (na, nb) = (a.len(), b.len());
    for i in 0..na {
        let (p, q) = (a[i], a[(i + 1) % na]);
        // The same edge runs q -> p in b.
        if let Some(j) = (0..nb).find(|&j| b[j] == q && b[(j + 1) % nb] == p) {
            let mut out = Vec::with_capacity(na + nb - 2);
            for k in 0..na {
                out.push(a[(i + 1 + k) % na]);
                if k == na - 1 {
                    break;
                }
            }
            // out runs q .. p around a; continue from p through b back to q.
            for k in 2..nb {
                out.push(b[(j + k) % nb]);
            }
            return Some(out);
        }
    }
    None
}

fn signed_area(p: &[(f64, f64)]) -> f64 {
    (0..p.len())
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            a.0 * b.1 - b.0 * a.1
        })
        .sum::<f64>()
        / 2.0
}

/// Whether two non-adjacent edges of the outline cross or touch.
fn crosses_itself(p: &[(f64, f64)]) -> bool {
    let n = p.len();
    let orient = |a: (f64, f64), b: (f64, f64), c: (f64, f64)| {
        let v = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
        if v > 0.0 {
            1
        } else if v < 0.0 {
            -1
        } else {
            0
        }
    };
    for i in 0..n {
        for j in i + 1..n {
            if j == i + 1 || (i == 0 && j == n - 1) {
                continue;
            }
            let (a, b, c, d) = (p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]);
            let (o1, o2, o3, o4) = (
                orient(a, b, c),
                orient(a, b, d),
                orient(c, d, a),
                orient(c, d, b),
            );
            if o1 != o2 && o3 != o4 {
                return true;
            }
        }
    }
    false
}

/// The line from `a` to `b` as a quad `thickness` pixels thick on its
/// right-hand side on screen (below a line drawn left to right); `None`
/// for a zero-length line.
pub(crate) fn thick_line(a: (f64, f64), b: (f64, f64), thickness: f64) -> Option<Outline> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len = (dx * dx + dy * dy).sqrt();
    if len < 1e-9 {
        return None;
    }
    let n = (-dy / len * thickness, dx / len * thickness);
    Some(vec![a, b, (b.0 + n.0, b.1 + n.1), (a.0 + n.0, a.1 + n.1)])
}

/// An ellipse inside the box `(x, y, w, h)` as an outline of 8 points (the
/// regular octagon's corners on the ellipse): what ledge collides with for
/// an ellipse shape.
pub(crate) fn ellipse_outline(x: f64, y: f64, w: f64, h: f64) -> Outline {
    let (cx, cy) = (x + w / 2.0, y + h / 2.0);
    (0..8)
        .map(|k| {
            let a = (k as f64 + 0.5) * std::f64::consts::FRAC_PI_4;
            (cx + a.cos() * w / 2.0, cy + a.sin() * h / 2.0)
        })
        .collect()
}

/// The box `(x, y, w, h)` turned by `rotation` degrees (clockwise on
/// screen) about `(x, y)`, as an outline.
pub(crate) fn rect_outline(x: f64, y: f64, w: f64, h: f64, rotation: f64) -> Outline {
    let corners = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)];
    rotate_about(&corners, (x, y), rotation)
}

/// Points relative to `origin`, turned by `rotation` degrees clockwise on
/// screen about it, made absolute.
pub(crate) fn rotate_about(points: &[(f64, f64)], origin: (f64, f64), rotation: f64) -> Outline {
    let (sin, cos) = if rotation == 0.0 {
        (0.0, 1.0)
    } else {
        rotation.to_radians().sin_cos()
    };
    points
        .iter()
        .map(|&(px, py)| {
            (
                origin.0 + px * cos - py * sin,
                origin.1 + px * sin + py * cos,
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outlines_become_tiles_only_when_they_match_exactly() {
        let t = 16.0;
        for tile in std::iter::once(Tile::Solid).chain(Slope::ALL.into_iter().map(Tile::Slope)) {
            let mut o = region_outline(tile, t);
            // Either winding, any start, an extra collinear point.
            o.reverse();
            o.rotate_left(1);
            let (a, b) = (o[0], o[1]);
            o.insert(1, ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0));
            assert_eq!(
                classify_outlines(vec![o], t),
                TileShape::Tile(tile),
                "{tile:?}"
            );
        }
        let half = vec![(0.0, 8.0), (16.0, 8.0), (16.0, 16.0), (0.0, 16.0)];
        assert_eq!(
            classify_outlines(vec![half.clone()], 16.0),
            TileShape::Geometry(vec![half])
        );
    }

    #[test]
    fn thick_lines_lie_below_lines_drawn_left_to_right() {
        let q = thick_line((0.0, 0.0), (10.0, 0.0), 2.0).unwrap();
        assert_eq!(q, vec![(0.0, 0.0), (10.0, 0.0), (10.0, 2.0), (0.0, 2.0)]);
        assert!(is_convex(&q));
        let q = thick_line((0.0, 0.0), (0.0, 10.0), 2.0).unwrap();
        assert_eq!(q[2], (-2.0, 10.0));
        assert!(thick_line((1.0, 1.0), (1.0, 1.0), 2.0).is_none());
    }

    #[test]
    fn convexity() {
        assert!(is_convex(&[(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)]));
        assert!(is_convex(&[(0.0, 4.0), (4.0, 4.0), (4.0, 0.0)]));
        // An L, a bow tie, a pentagram, a straight corner.
        assert!(!is_convex(&[
            (0.0, 0.0),
            (4.0, 0.0),
            (4.0, 2.0),
            (2.0, 2.0),
            (2.0, 4.0),
            (0.0, 4.0)
        ]));
        assert!(!is_convex(&[
            (0.0, 0.0),
            (4.0, 4.0),
            (4.0, 0.0),
            (0.0, 4.0)
        ]));
        let star: Vec<_> = (0..5)
            .map(|k| {
                let a = k as f64 * 4.0 * std::f64::consts::PI / 5.0;
                (a.cos(), a.sin())
            })
            .collect();
        assert!(!is_convex(&star));
        assert!(!is_convex(&[
            (0.0, 0.0),
            (2.0, 0.0),
            (4.0, 0.0),
            (4.0, 4.0)
        ]));
    }

    #[test]
    fn concave_outlines_split_into_convex_pieces_of_the_same_area() {
        let l = [
            (0.0, 0.0),
            (4.0, 0.0),
            (4.0, 2.0),
            (2.0, 2.0),
            (2.0, 4.0),
            (0.0, 4.0),
        ];
        let star: Vec<_> = (0..10)
            .map(|k| {
                let r = if k % 2 == 0 { 10.0 } else { 4.0 };
                let a = k as f64 * std::f64::consts::PI / 5.0;
                (r * a.cos(), r * a.sin())
            })
            .collect();
        let circle: Vec<_> = (0..20)
            .map(|k| {
                let a = k as f64 * std::f64::consts::PI / 10.0;
                (5.0 * a.cos(), 5.0 * a.sin())
            })
            .rev()
            .collect();
        for poly in [l.to_vec(), star, circle] {
            let pieces = convex_pieces(&poly, 8).unwrap();
            let total: f64 = pieces.iter().map(|p| signed_area(p).abs()).sum();
            assert!((total - signed_area(&poly).abs()).abs() < 1e-9, "{poly:?}");
            for p in &pieces {
                assert!(is_convex(p) && (3..=8).contains(&p.len()), "{p:?}");
            }
        }
        assert_eq!(convex_pieces(&l, 8).unwrap().len(), 2);
        // A bow tie crosses itself.
        assert!(convex_pieces(&[(0.0, 0.0), (4.0, 4.0), (4.0, 0.0), (0.0, 4.0)], 8).is_none());
    }

    #[test]
    fn flips_mirror_slopes() {
        let t = 16.0;
        for s in Slope::ALL {
            let mut o = region_outline(Tile::Slope(s), t);
            flip(&mut o, t, true, false, false);
            assert_eq!(
                classify_outlines(vec![o], t),
                TileShape::Tile(crate::mapping::mirror(Tile::Slope(s))),
                "{s:?}"
            );
        }
        // Vertically flipped: a ceiling, so geometry.
        let mut o = region_outline(Tile::Slope(Slope::Right45), t);
        flip(&mut o, t, false, true, false);
        assert!(matches!(
            classify_outlines(vec![o], t),
            TileShape::Geometry(_)
        ));
    }

    #[test]
    fn properties_and_classes() {
        let p = |k, v| (k, v);
        assert_eq!(
            tile_of_props([p("Collides", Prop::Bool(true))], ""),
            Ok(Some(Tile::Solid))
        );
        assert_eq!(
            tile_of_props([p("bodyType", Prop::Text("static"))], ""),
            Ok(Some(Tile::Solid))
        );
        assert_eq!(
            tile_of_props([p("one-way", Prop::Bool(true))], ""),
            Ok(Some(Tile::OneWay))
        );
        assert_eq!(
            tile_of_props(
                [p("solid", Prop::Bool(false)), p("deadly", Prop::Bool(true))],
                ""
            ),
            Ok(Some(Tile::Hazard))
        );
        assert_eq!(
            tile_of_props([p("solid", Prop::Bool(false))], ""),
            Ok(Some(Tile::Empty))
        );
        assert_eq!(tile_of_props([], "spikes"), Ok(Some(Tile::Hazard)));
        assert_eq!(
            tile_of_props([p("friction", Prop::Other)], "tree"),
            Ok(None)
        );
        assert!(tile_of_props([p("kind", Prop::Text("lava pit"))], "")
            .unwrap_err()
            .contains("slope_45_right"));
        assert_eq!(
            layer_collides([p("collision", Prop::Bool(true))], ""),
            Some(true)
        );
        assert_eq!(
            layer_collides([p("NoCollide", Prop::Bool(true))], ""),
            Some(false)
        );
        assert_eq!(layer_collides([], "Collision"), Some(true));
        assert_eq!(layer_collides([], "background"), Some(false));
        assert_eq!(layer_collides([], ""), None);
        assert!(is_collision_layer_name("Walls"));
        assert!(is_collision_layer_name("Walls level 2"));
        assert!(is_collision_layer_name("level"));
        assert!(!is_collision_layer_name("Fringe"));
        assert!(!is_collision_layer_name("Ground decoration"));
        assert!(!is_collision_layer_name("Background level"));
    }
}
