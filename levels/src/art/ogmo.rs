//! The art of an OGMO Editor 3 level: its tile layers, drawn with the
//! project's embedded tileset images.

use std::collections::BTreeMap;

use ledge_shared::fixed::UNITS_PER_PX;

use super::{
    check_image_bytes, check_tile_count, ArtCell, ArtContent, ArtLayer, ArtTileset, Budget, Images,
    LevelArt, TileGrid,
};
use crate::ogmo::model::{LayerContent, OgmoLevel, Project};
use crate::LevelError;

/// The art of an OGMO level: its tile layers whose project tileset embeds
/// its image (last layer first: OGMO draws the first layer on top), and the
/// project's background colour. `file` is the level, `project_file` the
/// project (named in errors about its images).
pub(crate) fn from_ogmo(
    file: &str,
    project_file: &str,
    project: &Project,
    level: &OgmoLevel,
) -> Result<LevelArt, LevelError> {
    let mut images = Images::default();
    let mut tilesets: Vec<ArtTileset> = Vec::new();
    let mut by_label: BTreeMap<&str, Option<u32>> = BTreeMap::new();
    let mut budget = Budget::default();
    let mut layers = Vec::new();
    for l in level.layers.iter().rev() {
        let LayerContent::Tiles { tileset, key, ids } = &l.content else {
            continue;
        };
        let t = match by_label.get(tileset.as_str()) {
            Some(&t) => t,
            None => {
                let t = match project
                    .tilesets
                    .iter()
                    .enumerate()
                    .find(|(_, t)| &t.label == tileset)
                {
                    Some((i, pt)) => {
                        let field = format!("tilesets[{i}]");
                        let Some(bytes) =
                            data_uri(project_file, &format!("{field}.image"), &pt.image)?
                        else {
                            by_label.insert(tileset, None);
                            continue;
                        };
                        let name = if pt.path.is_empty() {
                            format!("{}.png", pt.label)
                        } else {
                            pt.path.replace('\\', "/")
                        };
                        let image = images.add(
                            project_file,
                            &format!("{field}.image"),
                            format!("ogmo tileset {i}"),
                            name,
                            None,
                            bytes,
                        )?;
                        let img = images.get(image);
                        let (tw, th) = (pt.tile_width.max(1), pt.tile_height.max(1));
                        let fit = |side: u32, tile: u32| -> u32 {
                            ((side as u64 + pt.spacing as u64).saturating_sub(2 * pt.margin as u64)
                                / (tile as u64 + pt.spacing as u64))
                                as u32
                        };
                        let (columns, rows) = (fit(img.width, tw), fit(img.height, th));
                        check_tile_count(project_file, &field, columns as u64 * rows as u64)?;
                        tilesets.push(ArtTileset {
                            name: pt.label.clone(),
                            tile_width: tw,
                            tile_height: th,
                            columns,
                            margin: pt.margin,
                            spacing: pt.spacing,
                            offset: (0, 0),
                            tile_count: columns * rows,
                            image: Some(image),
                            tiles: Vec::new(),
                        });
                        Some(tilesets.len() as u32 - 1)
                    }
                    None => None,
                };
                by_label.insert(tileset, t);
                t
            }
        };
        let Some(t) = t else { continue };
        let (w, h) = l.cells;
        budget.cells(file, &l.field, w as u64 * h as u64)?;
        let ts = &tilesets[t as usize];
        let mut cells = Vec::with_capacity(ids.len());
        for (i, &id) in ids.iter().enumerate() {
            if id < 0 {
                cells.push(None);
                continue;
            }
            if id as u32 >= ts.tile_count {
                return Err(LevelError::BadValue {
                    file: file.into(),
                    field: format!("{}.{key}[{i}]", l.field),
                    message: format!(
                        "tile id {id} is outside tileset {:?} ({} tiles)",
                        ts.name, ts.tile_count
                    ),
                });
            }
            cells.push(Some(ArtCell {
                tileset: t,
                tile: id as u32,
                ..ArtCell::default()
            }));
        }
        let px = UNITS_PER_PX as f32;
        layers.push(ArtLayer {
            name: l.name.clone(),
            offset: (l.origin.x as f32 / px, l.origin.y as f32 / px),
            parallax: (1.0, 1.0),
            opacity: 1.0,
            content: ArtContent::Tiles(TileGrid {
                width: w,
                height: h,
                cell_width: l.cell.0,
                cell_height: l.cell.1,
                cells,
            }),
        });
    }
    Ok(LevelArt {
        background: parse_colour(&project.background_color),
        size: layers
            .iter()
            .fold((0.0, 0.0), |(w, h), l: &ArtLayer| match &l.content {
                ArtContent::Tiles(g) => (
                    f32::max(w, l.offset.0 + (g.width * g.cell_width) as f32),
                    f32::max(h, l.offset.1 + (g.height * g.cell_height) as f32),
                ),
                _ => (w, h),
            }),
        parallax_origin: (0.0, 0.0),
        images: images.into_vec(),
        tilesets,
        layers,
        warnings: Vec::new(),
    })
}

/// `#rrggbb` or `#rrggbbaa`.
fn parse_colour(s: &str) -> Option<[u8; 4]> {
    let hex = s.strip_prefix('#')?;
    if !(hex.len() == 6 || hex.len() == 8) || !hex.is_ascii() {
        return None;
    }
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).ok();
    Some([
        byte(0)?,
        byte(2)?,
        byte(4)?,
        if hex.len() == 8 { byte(6)? } else { 255 },
    ])
}

/// The bytes of a `data:...;base64,` URI (`None`: not a data URI), at
/// most [`super::MAX_ART_IMAGE_BYTES`].
fn data_uri(file: &str, field: &str, uri: &str) -> Result<Option<Vec<u8>>, LevelError> {
    let Some(rest) = uri.strip_prefix("data:") else {
        return Ok(None);
    };
    let Some((_, b64)) = rest.split_once(";base64,") else {
        return Ok(None);
    };
    check_image_bytes(file, field, b64.len() as u64 / 4 * 3)?;
    decode_base64(b64)
        .map(Some)
        .ok_or_else(|| LevelError::BadValue {
            file: file.into(),
            field: field.into(),
            message: "the embedded image is not valid base64".into(),
        })
}

/// Standard base64, padded or not (OGMO writes padded data URIs).
pub(crate) fn decode_base64(s: &str) -> Option<Vec<u8>> {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD_NO_PAD
        .decode(s.trim_end_matches('='))
        .ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_and_colours() {
        assert_eq!(decode_base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(decode_base64("aGk").unwrap(), b"hi");
        assert_eq!(decode_base64("a*"), None);
        assert_eq!(parse_colour("#282c34ff"), Some([0x28, 0x2c, 0x34, 0xff]));
        assert_eq!(parse_colour("#282c34"), Some([0x28, 0x2c, 0x34, 0xff]));
        assert_eq!(parse_colour("282c34"), None);
    }
}
