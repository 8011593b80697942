//! What a tile layer painted edge to edge means when its file says nothing
//! about collision: such a layer cannot be all walls (the player would
//! spawn inside one). The evidence in the file decides ([`infer_painted`]):
//!
//! * the most common tile of the layer is background (passable);
//! * so is every tile under the player spawn and under entities that stand
//!   or move in open space (coins, walkers, checkpoints, the goal, ...);
//! * every other tile is a wall (solid), the tiles bordering the background
//!   being its surface.
//!
//! The importers say what was chosen (the tile ids on each side) and the
//! settings key that overrides it (`[tiles."TILESET"]`).

use std::collections::{BTreeMap, BTreeSet};

use glam::IVec2;

use crate::assemble::GridLayer;
use crate::entities::{is_block_name, is_entity_name, is_polygon_name, PlacedEntity};
use crate::mapping::normalize;
use crate::options::LoadOptions;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::tilemap::Tile;

/// A layer is painted edge to edge when at least this share (in tenths) of
/// its cells hold a tile.
pub(crate) const PAINTED_TENTHS: usize = 9;

/// Entities wider or taller than this many cells are not evidence (a
/// zone, a backdrop object): each entity marks at most this squared.
const MAX_EVIDENCE_SIDE: i64 = 16;

/// What a painted layer's evidence made of its tiles.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Painted<K> {
    /// Cells holding a tile, and all cells.
    pub placed: usize,
    pub total: usize,
    /// The most common tile and its cell count.
    pub most_common: (K, usize),
    /// Tiles under entities (other than the most common), sorted.
    pub under_entities: Vec<K>,
    /// Every background tile (the two above), sorted.
    pub background: BTreeSet<K>,
    /// The wall tiles with their cell counts, most common first.
    pub walls: Vec<(K, usize)>,
}

/// Reads layer `cells` (a tile key per cell, `None` empty; row-major) as
/// [`Painted`] when at least [`PAINTED_TENTHS`] of its cells hold a tile;
/// `evidence` are the cells under entities ([`cells_under_entities`]).
/// `None` for a layer with more empty space.
pub(crate) fn infer_painted<K: Ord + Copy>(
    cells: &[Option<K>],
    evidence: &[bool],
) -> Option<Painted<K>> {
    let mut counts: BTreeMap<K, usize> = BTreeMap::new();
    for k in cells.iter().flatten() {
        *counts.entry(*k).or_default() += 1;
    }
    let placed: usize = counts.values().sum();
    let total = cells.len();
    if total == 0 || placed * 10 < total * PAINTED_TENTHS {
        return None;
    }
    let most_common = counts
        .iter()
        .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(a.0)))
        .map(|(k, n)| (*k, *n))?;
    let mut background = BTreeSet::from([most_common.0]);
    for (c, _) in cells.iter().zip(evidence).filter(|(_, e)| **e) {
        if let Some(k) = c {
            background.insert(*k);
        }
    }
    let under_entities = background
        .iter()
        .copied()
        .filter(|k| *k != most_common.0)
        .collect();
    let mut walls: Vec<(K, usize)> = counts
        .into_iter()
        .filter(|(k, _)| !background.contains(k))
        .collect();
    walls.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    Some(Painted {
        placed,
        total,
        most_common,
        under_entities,
        background,
        walls,
    })
}

/// Reads collision layer `g` as painted ([`infer_painted`], evidence from
/// `entities`; `cells` its tiles' keys) and makes its background tiles
/// empty. `others_collide`: something else in the level collides; when
/// not, a painted layer with no wall tile (one picture over everything)
/// stays as it is, there being no evidence of what it is.
pub(crate) fn apply_painted<K: Ord + Copy>(
    g: &mut GridLayer,
    cells: &[Option<K>],
    entities: &[PlacedEntity],
    options: &LoadOptions,
    others_collide: bool,
) -> Option<Painted<K>> {
    let cell = g.cell.0 as i64 * UNITS_PER_PX as i64;
    let evidence = cells_under_entities(entities, options, g.origin, cell, g.cells);
    let p = infer_painted(cells, &evidence)?;
    if p.walls.is_empty() && !others_collide {
        return None;
    }
    for (t, c) in g.tiles.iter_mut().zip(cells) {
        if c.is_some_and(|k| p.background.contains(&k)) {
            *t = Tile::Empty;
        }
    }
    Some(p)
}

/// Whether anything but grid `k` collides: another layer's tile, or solid
/// geometry among `entities`.
pub(crate) fn solid_elsewhere(grids: &[GridLayer], k: usize, entities: &[PlacedEntity]) -> bool {
    grids
        .iter()
        .enumerate()
        .any(|(i, g)| i != k && g.tiles.iter().any(|t| *t != Tile::Empty))
        || entities
            .iter()
            .any(|e| is_block_name(&e.name) || e.polygon.is_some())
}

/// Whether entity `e` (after the settings' aliases) stands or moves in open
/// space: any entity but blocks, polygons and hazards (which may sit in a
/// wall's cells), and not one turned or drawn as a polygon.
fn is_evidence(e: &PlacedEntity, options: &LoadOptions) -> bool {
    let name = options.entity_name(&e.name);
    let n = normalize(name);
    is_entity_name(name)
        && e.polygon.is_none()
        && !is_block_name(name)
        && !is_polygon_name(name)
        && !matches!(n.as_str(), "hazard" | "spikes" | "spike")
}

/// The cells of a grid (`origin` and `cell` size in units, `w` x `h`
/// cells) under the open-space entities of `entities`: a mask, row-major.
/// An entity marks the cells its box's interior overlaps, at most
/// [`MAX_EVIDENCE_SIDE`] a side.
pub(crate) fn cells_under_entities(
    entities: &[PlacedEntity],
    options: &LoadOptions,
    origin: IVec2,
    cell: i64,
    (w, h): (u32, u32),
) -> Vec<bool> {
    let mut mask = vec![false; w as usize * h as usize];
    if cell <= 0 {
        return mask;
    }
    for e in entities.iter().filter(|e| is_evidence(e, options)) {
        let lo = (e.centre - e.size / 2 - origin).as_i64vec2() + 1;
        let hi = (e.centre + e.size / 2 - origin).as_i64vec2() - 1;
        let (c0, r0) = (lo.x.div_euclid(cell), lo.y.div_euclid(cell));
        let (c1, r1) = (hi.x.div_euclid(cell), hi.y.div_euclid(cell));
        if c1 < c0 || r1 < r0 || c1 - c0 >= MAX_EVIDENCE_SIDE || r1 - r0 >= MAX_EVIDENCE_SIDE {
            continue;
        }
        for r in r0.max(0)..=r1.min(h as i64 - 1) {
            for c in c0.max(0)..=c1.min(w as i64 - 1) {
                mask[(r * w as i64 + c) as usize] = true;
            }
        }
    }
    mask
}

/// The warning for a painted layer (without its place): what was chosen
/// and the settings that choose otherwise. `tile` names a key as
/// `(tileset, id)`.
pub(crate) fn painted_warning<K: Ord + Copy>(
    p: &Painted<K>,
    tile: impl Fn(K) -> (String, u32),
) -> String {
    let list = |ks: &mut dyn Iterator<Item = K>| {
        let all: Vec<String> = ks
            .map(|k| {
                let (ts, id) = tile(k);
                format!("{ts:?} {id}")
            })
            .collect();
        let n = all.len();
        let mut s = all.into_iter().take(8).collect::<Vec<_>>().join(", ");
        if n > 8 {
            s.push_str(&format!(" and {} more", n - 8));
        }
        s
    };
    let (mts, mid) = tile(p.most_common.0);
    let under = if p.under_entities.is_empty() {
        String::new()
    } else {
        format!(
            ", and the tiles under the spawn and entities ({})",
            list(&mut p.under_entities.iter().copied())
        )
    };
    let walls = if p.walls.is_empty() {
        "no tile is a wall: the layer is decoration".to_string()
    } else {
        format!(
            "the other tiles are walls (solid): {}",
            list(&mut p.walls.iter().map(|w| w.0))
        )
    };
    let example = match p.walls.first() {
        Some(&(k, _)) => {
            let (ts, id) = tile(k);
            if ts == mts {
                format!("[tiles.{mts:?}] {mid} = \"empty\", {id} = \"solid\"")
            } else {
                format!("[tiles.{mts:?}] {mid} = \"empty\" and [tiles.{ts:?}] {id} = \"solid\"")
            }
        }
        None => format!("[tiles.{mts:?}] {mid} = \"solid\""),
    };
    format!(
        "this tile layer is painted edge to edge ({} of {} cells) and the file has no collision data for it, so it cannot be all walls: its most common tile ({mts:?} {mid}, {} cells){under} are background (empty); {walls}. Choose in the level's settings with {example}, or list the layer in collision_layers (every tile solid) or decoration_layers",
        p.placed, p.total, p.most_common.1
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn most_common_and_entity_tiles_are_background() {
        // 4 x 3: sky 0, walls 1 on the bottom row, a cloud 2 under an
        // entity, a rock 3.
        let cells = [0, 0, 2, 3, 0, 0, 0, 0, 1, 1, 1, 1].map(Some);
        let mut ev = [false; 12];
        ev[2] = true;
        let p = infer_painted(&cells, &ev).unwrap();
        assert_eq!(p.most_common, (0, 6));
        assert_eq!(p.background, BTreeSet::from([0, 2]));
        assert_eq!(p.walls, vec![(1, 4), (3, 1)]);
        assert_eq!(p.under_entities, vec![2]);
    }

    #[test]
    fn a_layer_with_open_space_is_not_painted() {
        let cells = [Some(1), None, None, Some(1)];
        assert_eq!(infer_painted(&cells, &[false; 4]), None);
        assert_eq!(infer_painted::<u32>(&[], &[]), None);
    }
}
