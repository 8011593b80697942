//! The level's player scale ([`PlayerScale`]): how big the player is and how
//! fast it moves, from the settings file, else the spawn object's size,
//! else the level's tile size (see `docs/LEVELS.md`, "Player scale").
//! Floats from files become integers here, once, by one rounding rule.

use glam::IVec2;
use ledge_shared::fixed::{MAX_EXTENT, UNITS_PER_PX};
use ledge_shared::game::PlayerConfig;
use ledge_shared::level::{Level, PlayerScale, ScaleSource, MAX_PLAYER_SCALE, MIN_PLAYER_SCALE};
use ledge_shared::tilemap::Tilemap;

use crate::entities::{is_spawn, PlacedEntity};
use crate::error::LevelError;
use crate::options::LoadOptions;

/// Ledge's own tile size, px: the default level's, what the player's
/// rules are tuned for.
pub const DEFAULT_TILE_PX: i64 = 16;

/// Ledge's own player's height, units (16 px).
fn default_height() -> i64 {
    2 * i64::from(PlayerConfig::default().half.y)
}

/// Scale 1 in [`PlayerScale::scale`] units.
const ONE: f64 = 256.0;

/// The settings' `scale`, in 1/256ths: finite and in [1/8, 256].
pub(crate) fn settings_scale(v: f64) -> Result<u32, String> {
    let (lo, hi) = (
        f64::from(MIN_PLAYER_SCALE) / ONE,
        f64::from(MAX_PLAYER_SCALE) / ONE,
    );
    if !v.is_finite() || v < lo || v > hi {
        return Err(format!(
            "{v} is not a player scale in [{lo}, {hi}] (1: ledge's own 12 x 16 px player)"
        ));
    }
    Ok((v * ONE).round() as u32)
}

/// The settings' `[player]` size: px to even units; one side alone keeps
/// ledge's 12:16 proportion. Errors name the key (`width`, `height`).
pub(crate) fn settings_size(
    w: Option<f64>,
    h: Option<f64>,
) -> Result<IVec2, (&'static str, String)> {
    let max = f64::from(MAX_EXTENT) * 2.0 / f64::from(UNITS_PER_PX);
    let check = |key: &'static str, v: f64| {
        if v.is_finite() && v > 0.0 && v <= max {
            Ok(v)
        } else {
            Err((key, format!("{v} px is not a player size in (0, {max}] px")))
        }
    };
    let d = PlayerConfig::default().half;
    let ratio = f64::from(d.x) / f64::from(d.y);
    let (w, h) = match (w, h) {
        (Some(w), Some(h)) => (check("width", w)?, check("height", h)?),
        (Some(w), None) => (check("width", w)?, w / ratio),
        (None, Some(h)) => (h * ratio, check("height", h)?),
        (None, None) => {
            return Err((
                "width",
                "missing: give the player's width, height or both (px)".into(),
            ))
        }
    };
    let even = |px: f64| (2.0 * (px * f64::from(UNITS_PER_PX) / 2.0).round()).max(2.0) as i32;
    Ok(IVec2::new(even(w), even(h)))
}

/// The scale of a player `height` units tall, in 1/256ths (rounded).
fn scale_of_height(height: i64) -> i64 {
    (height * 256 + default_height() / 2) / default_height()
}

/// The level's player scale: the settings' `scale` and `[player]`, else
/// the first spawn whose size the file gives, else the tile grid's cell
/// size over [`DEFAULT_TILE_PX`]. A spawn or tile size beyond the scale's
/// bounds is not used (said in `warnings`).
pub(crate) fn choose(
    file: &str,
    tilemap: &Tilemap,
    entities: &[PlacedEntity],
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Result<PlayerScale, LevelError> {
    let range = i64::from(MIN_PLAYER_SCALE)..=i64::from(MAX_PLAYER_SCALE);
    let half = options.player_size.map(|s| s / 2);
    let chosen = match (options.player_scale, half) {
        (Some(scale), half) => Some(PlayerScale {
            scale,
            half,
            source: ScaleSource::Settings,
        }),
        (None, Some(h)) => {
            let scale = scale_of_height(2 * i64::from(h.y));
            if !range.contains(&scale) {
                return Err(LevelError::BadValue {
                    file: file.into(),
                    field: "player.height (settings)".into(),
                    message: format!(
                        "a player {} px tall moves at scale {}: outside [1/8, 256]; give a scale too",
                        2 * h.y / UNITS_PER_PX,
                        scale as f64 / ONE
                    ),
                });
            }
            Some(PlayerScale {
                scale: scale as u32,
                half: Some(h),
                source: ScaleSource::Settings,
            })
        }
        (None, None) => None,
    };
    let chosen = chosen
        .or_else(|| from_spawn(file, entities, options, warnings))
        .unwrap_or_else(|| from_tiles(file, tilemap, warnings));
    PlayerConfig::default()
        .scaled(&chosen)
        .map_err(|m| LevelError::BadValue {
            file: file.into(),
            field: "player scale".into(),
            message: m,
        })?;
    Ok(chosen)
}

/// The scale of the first spawn whose size the file gives: its height over
/// ledge's player's; the player has its size.
fn from_spawn(
    file: &str,
    entities: &[PlacedEntity],
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Option<PlayerScale> {
    let e = entities
        .iter()
        .find(|e| e.sized && e.polygon.is_none() && is_spawn(options.entity_name(&e.name)))?;
    let scale = scale_of_height(i64::from(e.size.y));
    let range = i64::from(MIN_PLAYER_SCALE)..=i64::from(MAX_PLAYER_SCALE);
    if !range.contains(&scale) {
        warnings.push(format!(
            "{file}: {}: the spawn {:?} is {} x {} px: a player of that size is outside ledge's scale range (1/8 to 256 times its 12 x 16 px player), so the player's size comes from the tile size (give `scale` or `[player]` in the settings file to choose)",
            e.field,
            e.name,
            f64::from(e.size.x) / f64::from(UNITS_PER_PX),
            f64::from(e.size.y) / f64::from(UNITS_PER_PX)
        ));
        return None;
    }
    Some(PlayerScale {
        scale: scale as u32,
        half: Some(e.size / 2),
        source: ScaleSource::SpawnSize,
    })
}

/// The scale of the tile grid: its cell size over [`DEFAULT_TILE_PX`]
/// (ledge's own player on a level without a grid), clamped to the bounds.
fn from_tiles(file: &str, tilemap: &Tilemap, warnings: &mut Vec<String>) -> PlayerScale {
    if tilemap.width() == 0 || tilemap.height() == 0 {
        return PlayerScale::default();
    }
    let tile = i64::from(tilemap.tile_size());
    let ideal = tile * 256 / (DEFAULT_TILE_PX * i64::from(UNITS_PER_PX));
    let scale = ideal.clamp(i64::from(MIN_PLAYER_SCALE), i64::from(MAX_PLAYER_SCALE));
    if scale != ideal {
        warnings.push(format!(
            "{file}: the level's {} px tiles would make the player {} times ledge's: it is {} times (the scale's bound)",
            tile / i64::from(UNITS_PER_PX),
            ideal as f64 / ONE,
            scale as f64 / ONE
        ));
    }
    PlayerScale {
        scale: scale as u32,
        half: None,
        source: if scale == 256 {
            ScaleSource::Default
        } else {
            ScaleSource::TileSize
        },
    }
}

/// The player's size and scale and where they came from, for
/// `ledge-level check`: `128 x 160 px, scale 10 (the spawn object's size:
/// 160 px tall over ledge's 16 px)`.
pub fn describe(level: &Level) -> String {
    let s = &level.player;
    let px = |u: i32| f64::from(u) / f64::from(UNITS_PER_PX);
    let size = match PlayerConfig::default().scaled(s) {
        Ok(c) => format!("{} x {} px", px(2 * c.half.x), px(2 * c.half.y)),
        Err(e) => format!("refused ({e})"),
    };
    let why = match s.source {
        ScaleSource::Default => "ledge's own player".to_owned(),
        ScaleSource::TileSize => format!(
            "the level's {} px tiles over ledge's {DEFAULT_TILE_PX} px",
            px(level.tilemap.tile_size())
        ),
        ScaleSource::SpawnSize => format!(
            "the spawn object's size: {} px tall over ledge's player's {} px",
            px(2 * s.half.unwrap_or_default().y),
            px(default_height() as i32)
        ),
        ScaleSource::Settings => "the settings file's scale / [player]".to_owned(),
    };
    format!("{size}, scale {} ({why})", f64::from(s.scale) / ONE)
}
