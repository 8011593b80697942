//! Which collision cells a level's art draws over: there the game's plain
//! tile colours are not drawn (the client's window and `ledge-level
//! render` alike).

use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::tilemap::Tilemap;

use super::{ArtContent, LevelArt};

/// The collision cells of `map` (row-major) whose centre some tile, or
/// unrotated tile object, of a layer without parallax and at least half
/// opaque covers.
pub fn covered_cells(art: &LevelArt, map: &Tilemap) -> Vec<bool> {
    let (w, h) = (map.width() as i64, map.height() as i64);
    let mut covered = vec![false; (w * h) as usize];
    if art.is_empty() || w == 0 || h == 0 {
        return covered;
    }
    let px = UNITS_PER_PX as f32;
    let t = map.tile_size() as f32 / px;
    let (ox, oy) = (map.origin().x as f32 / px, map.origin().y as f32 / px);
    // Marks the cells whose centre is inside the box `x, y, bw, bh`.
    let mut mark = |x: f32, y: f32, bw: f32, bh: f32| {
        let c0 = ((x - ox) / t - 0.5).ceil().max(0.0) as i64;
        let r0 = ((y - oy) / t - 0.5).ceil().max(0.0) as i64;
        let c1 = (((x + bw - ox) / t - 0.5).floor() as i64).min(w - 1);
        let r1 = (((y + bh - oy) / t - 0.5).floor() as i64).min(h - 1);
        for rr in r0..=r1 {
            for cc in c0..=c1 {
                covered[(rr * w + cc) as usize] = true;
            }
        }
    };
    for layer in &art.layers {
        if layer.parallax != (1.0, 1.0) || layer.opacity < 0.5 {
            continue;
        }
        let (lx, ly) = layer.offset;
        match &layer.content {
            ArtContent::Tiles(g) => {
                for (i, cell) in g.cells.iter().enumerate() {
                    let Some(cell) = cell else { continue };
                    let Some(src) = art.source(cell.tileset, cell.tile) else {
                        continue;
                    };
                    let (c, r) = (i as u32 % g.width.max(1), i as u32 / g.width.max(1));
                    let to = art.tilesets[cell.tileset as usize].offset;
                    let x = lx + (c * g.cell_width) as f32 + to.0 as f32;
                    let y = ly + ((r + 1) * g.cell_height) as f32 - src.h as f32 + to.1 as f32;
                    mark(x, y, src.w as f32, src.h as f32);
                }
            }
            ArtContent::Objects(objs) => {
                for ob in objs.iter().filter(|ob| ob.rotation == 0.0) {
                    if art.source(ob.tileset, ob.tile).is_some() {
                        mark(lx + ob.x, ly + ob.y - ob.height, ob.width, ob.height);
                    }
                }
            }
            ArtContent::Image { .. } => {}
        }
    }
    covered
}
