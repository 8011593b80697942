//! Collision layers of several grid sizes in one level: the layer that
//! decides the level's grid ([`deciding_layer`]) keeps its cells, and each
//! other layer whose cell size is a whole multiple or a whole fraction of
//! it, on a lined-up origin, is resampled onto that grid ([`onto_one_grid`]):
//!
//! * a coarser layer (64 px onto 32 px) exactly: each cell becomes its
//!   sub-cells, a slope the slope tiles (and solid and empty cells) that
//!   draw the same surface, a one-way tile its top row;
//! * a finer layer (16 px onto 32 px) approximately: a cell is solid when
//!   at least half of its area is, else a hazard when any part is one,
//!   else one-way when any part is one, else empty.
//!
//! Other layers are left as they are (`assemble` says they do not line
//! up). The output cells of all resampled layers count towards
//! [`MAX_LEVEL_CELLS`](crate::limits::MAX_LEVEL_CELLS) before they are
//! allocated.

use glam::IVec2;

use crate::assemble::GridLayer;
use crate::error::LevelError;
use crate::limits::{check_count, MAX_LEVEL_CELLS};
use crate::options::LoadOptions;
use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::tilemap::{Slope, Tile};

/// The layer whose grid the level takes, and why: the first layer named
/// for collision (or listed in `collision_layers`) holding a tile, else the
/// layer whose tiles cover the most area (the first of equals).
pub(crate) fn deciding_layer(
    grids: &[GridLayer],
    options: &LoadOptions,
) -> Option<(usize, &'static str)> {
    let used = |g: &GridLayer| g.tiles.iter().any(|t| *t != Tile::Empty);
    let named = |g: &GridLayer| {
        options.layer_collides(&g.name) == Some(true)
            || crate::collision::is_collision_layer_name(&g.name)
    };
    if let Some(k) = grids.iter().position(|g| used(g) && named(g)) {
        return Some((k, "its name says collision"));
    }
    let area = |g: &GridLayer| {
        let n = g.tiles.iter().filter(|t| **t != Tile::Empty).count() as u64;
        n * g.cell.0 as u64 * g.cell.1 as u64
    };
    let best = grids.iter().map(area).max().filter(|a| *a > 0)?;
    let k = grids.iter().position(|g| area(g) == best)?;
    Some((k, "its tiles cover the most area"))
}

/// Resamples every layer of `grids` that can be onto the grid of the
/// deciding layer ([`deciding_layer`]), in place (the order, which decides
/// what wins where layers overlap, is kept), each said in `warnings`.
pub(crate) fn onto_one_grid(
    file: &str,
    grids: &mut [GridLayer],
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Result<(), LevelError> {
    let Some((d, why)) = deciding_layer(grids, options) else {
        return Ok(());
    };
    let (dcell, dcells, dorigin) = (grids[d].cell, grids[d].cells, grids[d].origin);
    let (dname, dfield) = (grids[d].name.clone(), grids[d].field.clone());
    let mut budget = 0u64;
    for g in grids.iter_mut() {
        if (g.cell, g.cells, g.origin) == (dcell, dcells, dorigin) || !lines_up(g, dcell.0, dorigin)
        {
            continue;
        }
        budget += dcells.0 as u64 * dcells.1 as u64;
        check_count(
            file,
            g.field.clone(),
            "resampled collision cells in all layers",
            budget,
            MAX_LEVEL_CELLS,
            "MAX_LEVEL_CELLS",
        )?;
        let (tiles, lost) = if g.cell.0 > dcell.0 {
            refine(g, dcell.0, dcells, dorigin)
        } else {
            coarsen(g, dcell.0, dcells, dorigin)
        };
        let how = if g.cell.0 > dcell.0 {
            "exactly"
        } else {
            "approximately: a cell is solid when at least half of it is"
        };
        let lost = if lost > 0 {
            format!("; {lost} of its tiles lie outside that grid and are left out")
        } else {
            String::new()
        };
        warnings.push(format!(
            "{file}: {}: layer {:?} of {} px cells is resampled onto the level's grid of {} px cells ({dfield} {dname:?} decides the grid: {why}), {how}{lost} (choose the layers with collision_layers or decoration_layers in the level's settings)",
            g.field, g.name, g.cell.0, dcell.0
        ));
        g.cell = dcell;
        g.cells = dcells;
        g.origin = dorigin;
        g.tiles = tiles;
    }
    // The level's grid is the first layer's: the layers left off it go
    // last (they do not collide; `assemble` says so), the others keep
    // their order.
    grids.sort_by_key(|g| (g.cell, g.cells, g.origin) != (dcell, dcells, dorigin));
    Ok(())
}

/// Whether layer `g` can be resampled onto square cells of `cell` px at
/// `origin`: square cells, one size a whole multiple of the other, the
/// origins a whole number of the smaller cells apart.
fn lines_up(g: &GridLayer, cell: u32, origin: IVec2) -> bool {
    let (a, b) = (g.cell.0, cell);
    if g.cell.0 != g.cell.1 || a == 0 || b == 0 || (a % b != 0 && b % a != 0) {
        return false;
    }
    let step = a.min(b) as i64 * UNITS_PER_PX as i64;
    let off = (g.origin - origin).as_i64vec2();
    off.x % step == 0 && off.y % step == 0
}

/// A coarser layer's tiles on the finer grid (`cell` px, `cells`, at
/// `origin`), and how many of its tiles fall outside it.
fn refine(g: &GridLayer, cell: u32, cells: (u32, u32), origin: IVec2) -> (Vec<Tile>, usize) {
    let k = (g.cell.0 / cell) as i64;
    let u = UNITS_PER_PX as i64;
    let off = ((origin - g.origin).as_i64vec2()) / (cell as i64 * u);
    let mut out = Vec::with_capacity(cells.0 as usize * cells.1 as usize);
    for r in 0..cells.1 as i64 {
        for c in 0..cells.0 as i64 {
            let (fx, fy) = (c + off.x, r + off.y);
            let (gc, gr) = (fx.div_euclid(k), fy.div_euclid(k));
            let inside = (0..g.cells.0 as i64).contains(&gc) && (0..g.cells.1 as i64).contains(&gr);
            out.push(if inside {
                let t = g.tiles[(gr * g.cells.0 as i64 + gc) as usize];
                sub_tile(t, k, fx.rem_euclid(k), fy.rem_euclid(k))
            } else {
                Tile::Empty
            });
        }
    }
    let covered = |gc: i64, gr: i64| {
        let (x0, y0) = (gc * k - off.x, gr * k - off.y);
        x0 + k > 0 && y0 + k > 0 && x0 < cells.0 as i64 && y0 < cells.1 as i64
    };
    let lost = count_lost(g, covered);
    (out, lost)
}

/// The non-empty tiles of `g` for which `covered(column, row)` is false.
fn count_lost(g: &GridLayer, covered: impl Fn(i64, i64) -> bool) -> usize {
    g.tiles
        .iter()
        .enumerate()
        .filter(|(i, t)| {
            let (c, r) = (
                (*i % g.cells.0 as usize) as i64,
                (*i / g.cells.0 as usize) as i64,
            );
            **t != Tile::Empty && !covered(c, r)
        })
        .count()
}

/// Sub-cell `(i, j)` (column, row from the top) of `k` x `k` of tile `t`.
fn sub_tile(t: Tile, k: i64, i: i64, j: i64) -> Tile {
    match t {
        Tile::OneWay if j == 0 => Tile::OneWay,
        Tile::OneWay => Tile::Empty,
        Tile::Slope(s) => slope_part(s, k, i, k - 1 - j),
        t => t,
    }
}

/// The surface of slope `s` as a fraction of its tile's height at `u`
/// (0 its left edge, 1 its right).
fn surface(s: Slope, u: f64) -> f64 {
    match s {
        Slope::Right45 => u,
        Slope::Left45 => 1.0 - u,
        Slope::RightLow22 => u / 2.0,
        Slope::RightHigh22 => 0.5 + u / 2.0,
        Slope::LeftHigh22 => 1.0 - u / 2.0,
        Slope::LeftLow22 => 0.5 - u / 2.0,
    }
}

/// Sub-cell `(i, jb)` (column, row from the bottom) of `k` x `k` of slope
/// `s`: solid below the surface, empty above, the slope tile of the same
/// surface across it (else the nearer of solid and empty by area).
fn slope_part(s: Slope, k: i64, i: i64, jb: i64) -> Tile {
    let kf = k as f64;
    let local = |u: f64| (kf * surface(s, u) - jb as f64).clamp(0.0, 1.0);
    let (a, b) = (local(i as f64 / kf), local((i + 1) as f64 / kf));
    const EPS: f64 = 1e-9;
    if a >= 1.0 - EPS && b >= 1.0 - EPS {
        return Tile::Solid;
    }
    if a <= EPS && b <= EPS {
        return Tile::Empty;
    }
    let near = |x: f64, y: f64| (x - y).abs() < 1e-6;
    if let Some(m) = Slope::ALL
        .iter()
        .find(|m| near(surface(**m, 0.0), a) && near(surface(**m, 1.0), b))
    {
        return Tile::Slope(*m);
    }
    if a + b >= 1.0 {
        Tile::Solid
    } else {
        Tile::Empty
    }
}

/// A finer layer's tiles on the coarser grid (`cell` px, `cells`, at
/// `origin`), and how many of its tiles fall outside it.
fn coarsen(g: &GridLayer, cell: u32, cells: (u32, u32), origin: IVec2) -> (Vec<Tile>, usize) {
    let k = (cell / g.cell.0) as i64;
    let u = UNITS_PER_PX as i64;
    let off = ((g.origin - origin).as_i64vec2()) / (g.cell.0 as i64 * u);
    let n = cells.0 as usize * cells.1 as usize;
    // Per output cell: solid area in quarters of a fine cell, hazard and
    // one-way seen.
    let mut area = vec![0u64; n];
    let mut hazard = vec![false; n];
    let mut one_way = vec![false; n];
    let mut lost = 0;
    for (i, t) in g.tiles.iter().enumerate() {
        if *t == Tile::Empty {
            continue;
        }
        let (c, r) = (
            (i % g.cells.0 as usize) as i64,
            (i / g.cells.0 as usize) as i64,
        );
        let (fx, fy) = (c + off.x, r + off.y);
        let (oc, or) = (fx.div_euclid(k), fy.div_euclid(k));
        if !(0..cells.0 as i64).contains(&oc) || !(0..cells.1 as i64).contains(&or) {
            lost += 1;
            continue;
        }
        let o = (or * cells.0 as i64 + oc) as usize;
        match t {
            Tile::Solid => area[o] += 4,
            Tile::Slope(Slope::Right45 | Slope::Left45) => area[o] += 2,
            Tile::Slope(Slope::RightLow22 | Slope::LeftLow22) => area[o] += 1,
            Tile::Slope(_) => area[o] += 3,
            Tile::Hazard => hazard[o] = true,
            Tile::OneWay => one_way[o] = true,
            Tile::Empty => {}
        }
    }
    let half = 2 * (k * k) as u64;
    let tiles = (0..n)
        .map(|o| {
            if area[o] >= half {
                Tile::Solid
            } else if hazard[o] {
                Tile::Hazard
            } else if one_way[o] {
                Tile::OneWay
            } else {
                Tile::Empty
            }
        })
        .collect();
    (tiles, lost)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slopes_split_into_the_tiles_of_the_same_surface() {
        use Slope::*;
        // A 45 degree slope over 2 x 2: the diagonal cells are slopes, the
        // one under it solid, the one over it empty.
        assert_eq!(slope_part(Right45, 2, 0, 0), Tile::Slope(Right45));
        assert_eq!(slope_part(Right45, 2, 1, 0), Tile::Solid);
        assert_eq!(slope_part(Right45, 2, 0, 1), Tile::Empty);
        assert_eq!(slope_part(Right45, 2, 1, 1), Tile::Slope(Right45));
        // The low half of a 22.5 degree ramp: its bottom row is a whole
        // ramp, its top row empty.
        assert_eq!(slope_part(RightLow22, 2, 0, 0), Tile::Slope(RightLow22));
        assert_eq!(slope_part(RightLow22, 2, 1, 0), Tile::Slope(RightHigh22));
        assert_eq!(slope_part(RightLow22, 2, 1, 1), Tile::Empty);
        assert_eq!(slope_part(LeftHigh22, 2, 0, 1), Tile::Slope(LeftHigh22));
        assert_eq!(slope_part(LeftHigh22, 2, 1, 1), Tile::Slope(LeftLow22));
    }

    fn layer(cell: u32, cells: (u32, u32), tiles: Vec<Tile>) -> GridLayer {
        GridLayer {
            field: "layers[0]".into(),
            name: "x".into(),
            origin: IVec2::ZERO,
            cell: (cell, cell),
            cells,
            tiles,
        }
    }

    #[test]
    fn finer_layers_are_solid_where_half_a_cell_is() {
        use Tile::*;
        // 4 x 2 cells of 16 px onto 2 x 1 of 32: the left cell half solid,
        // the right one a quarter solid with a spike.
        let g = layer(
            16,
            (4, 2),
            vec![Solid, Empty, Solid, Hazard, Solid, Empty, Empty, Empty],
        );
        let (t, lost) = coarsen(&g, 32, (2, 1), IVec2::ZERO);
        assert_eq!((t, lost), (vec![Solid, Hazard], 0));
        // A cell outside the grid is lost, and counted.
        let (t, lost) = coarsen(&g, 32, (1, 1), IVec2::ZERO);
        assert_eq!((t, lost), (vec![Solid], 2));
    }

    #[test]
    fn coarser_layers_split_exactly() {
        use Tile::*;
        let g = layer(64, (1, 1), vec![OneWay]);
        let (t, lost) = refine(&g, 32, (2, 2), IVec2::ZERO);
        assert_eq!((t, lost), (vec![OneWay, OneWay, Empty, Empty], 0));
    }
}
