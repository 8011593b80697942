//! Tiled tile layers painted edge to edge in a map without collision data
//! (`crate::collision::infer`): their background tiles are made empty.

use std::collections::BTreeMap;

use ::tiled::LayerTile;

use super::{Conv, TileRule};
use crate::assemble::GridLayer;
use crate::collision::infer::{apply_painted, painted_warning, solid_elsewhere};
use crate::entities::PlacedEntity;

/// A tile layer the fallback made solid: its field and each cell's tile
/// (tileset index, id), row-major.
pub(super) struct FallbackLayer {
    field: String,
    cells: Vec<Option<(usize, u32)>>,
}

impl Conv<'_> {
    /// Keeps the cells of fallback layer `field` (`w` x `h`, read with
    /// `cell`) for [`Conv::infer_painted`], unless a tile of it has a rule
    /// of its own (the settings' tile kinds decide then).
    pub(super) fn keep_fallback_cells<'t>(
        &self,
        field: &str,
        (w, h): (u32, u32),
        cell: &dyn Fn(i32, i32) -> Option<LayerTile<'t>>,
        rules: &BTreeMap<(usize, u32), TileRule>,
    ) {
        let mut cells = Vec::with_capacity(w as usize * h as usize);
        for y in 0..h as i32 {
            for x in 0..w as i32 {
                let key = cell(x, y).map(|t| (t.tileset_index(), t.id()));
                if key.is_some_and(|k| !matches!(rules.get(&k), Some(TileRule::Silent))) {
                    return;
                }
                cells.push(key);
            }
        }
        self.fallback_cells.borrow_mut().push(FallbackLayer {
            field: field.into(),
            cells,
        });
    }

    /// Makes the background tiles of each painted fallback layer empty
    /// (evidence: `entities`), with a note saying which tiles are which.
    pub(super) fn infer_painted(&self, grids: &mut [GridLayer], entities: &[PlacedEntity]) {
        let layers = std::mem::take(&mut *self.fallback_cells.borrow_mut());
        for l in layers {
            let Some(k) = grids.iter().position(|g| g.field == l.field) else {
                continue;
            };
            let others = solid_elsewhere(grids, k, entities);
            let g = &mut grids[k];
            let Some(p) = apply_painted(g, &l.cells, entities, self.options, others) else {
                continue;
            };
            let tilesets = self.map.tilesets();
            let name = |(ts, id): (usize, u32)| {
                (
                    tilesets.get(ts).map(|t| t.name.clone()).unwrap_or_default(),
                    id,
                )
            };
            let place = format!("layer {:?} ({})", g.name, g.field);
            let line = painted_warning(&p, name);
            self.notes.borrow_mut().add(line, || place);
        }
    }
}
