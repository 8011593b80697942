//! What a loaded level became, as data: [`LevelReport`] (what `ledge-level
//! check --json` prints), and the kinds of warnings ([`WarningKind`]) with
//! the one a host must see first ([`worst_warning`]).
//!
//! Importers give warnings as text (one line each, naming the file and the
//! place); [`WarningKind::of`] reads the kind from that text, so a
//! warning of a new kind is [`WarningKind::Other`] until it is listed here.

use std::collections::BTreeMap;

use ledge_shared::fixed::UNITS_PER_PX;
use ledge_shared::level::EntityKind;
use ledge_shared::tilemap::Tile;
use serde::Serialize;

use crate::{entity_kind_name, LoadedLevel};

/// What a warning is about, worst first (the order of [`WarningKind::rank`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningKind {
    /// The file says nothing about collision: which tiles collide was
    /// guessed (every tile of some layers is solid).
    GuessedCollision,
    /// The level's tiles do not collide at all (an LDtk level without an
    /// IntGrid layer).
    NoCollision,
    /// The level has no player spawn: one was placed.
    SpawnPlaced,
    /// A tile or grid layer does not collide (not on the level's grid, no
    /// tile table, left out by the collision layers).
    LayerNotCollided,
    /// A value or tile ledge does not know was read as solid.
    ReadAsSolid,
    /// A tile kind ledge has no such tile for (ladder, water) was read as
    /// empty.
    UnsupportedTile,
    /// An entity or object was skipped (unknown name, a platform without a
    /// path).
    EntitySkipped,
    /// A shape, field or object was ignored (collision shapes ledge cannot
    /// use, markers, patrol points).
    Ignored,
    /// A short row of cells was read as empty.
    ShortRow,
    /// A hidden layer or object was left out.
    Hidden,
    /// Anything else.
    Other,
    /// Something of the level's art is not drawn (its collision is not
    /// affected).
    Art,
}

impl WarningKind {
    /// The kind of an importer's warning line (not an art warning: those
    /// are [`WarningKind::Art`]).
    pub fn of(text: &str) -> WarningKind {
        const KINDS: &[(&str, WarningKind)] = &[
            ("has no collision data", WarningKind::GuessedCollision),
            ("tiles do not collide", WarningKind::NoCollision),
            ("no player spawn", WarningKind::SpawnPlaced),
            ("not collided", WarningKind::LayerNotCollided),
            ("does not collide", WarningKind::LayerNotCollided),
            ("not on the level's grid", WarningKind::LayerNotCollided),
            ("read as solid", WarningKind::ReadAsSolid),
            ("is not supported in ledge", WarningKind::UnsupportedTile),
            ("skipped", WarningKind::EntitySkipped),
            ("the rest read as empty", WarningKind::ShortRow),
            ("hidden", WarningKind::Hidden),
            ("ignored", WarningKind::Ignored),
            ("not used", WarningKind::Ignored),
            ("not supported", WarningKind::Ignored),
        ];
        KINDS
            .iter()
            .find(|(needle, _)| text.contains(needle))
            .map_or(WarningKind::Other, |&(_, kind)| kind)
    }

    /// 0 for the worst kind, counting up (the enum's order).
    pub fn rank(self) -> u8 {
        self as u8
    }

    /// Its name in JSON and messages (`guessed_collision`).
    pub fn name(self) -> &'static str {
        match self {
            WarningKind::GuessedCollision => "guessed_collision",
            WarningKind::NoCollision => "no_collision",
            WarningKind::SpawnPlaced => "spawn_placed",
            WarningKind::LayerNotCollided => "layer_not_collided",
            WarningKind::ReadAsSolid => "read_as_solid",
            WarningKind::UnsupportedTile => "unsupported_tile",
            WarningKind::EntitySkipped => "entity_skipped",
            WarningKind::Ignored => "ignored",
            WarningKind::ShortRow => "short_row",
            WarningKind::Hidden => "hidden",
            WarningKind::Other => "other",
            WarningKind::Art => "art",
        }
    }

    /// A few words for a start line: `collision guessed`.
    pub fn summary(self) -> &'static str {
        match self {
            WarningKind::GuessedCollision => "collision guessed",
            WarningKind::NoCollision => "its tiles do not collide",
            WarningKind::SpawnPlaced => "spawn placed",
            WarningKind::LayerNotCollided => "a layer does not collide",
            WarningKind::ReadAsSolid => "unknown tiles read as solid",
            WarningKind::UnsupportedTile => "unsupported tiles read as empty",
            WarningKind::EntitySkipped => "entities skipped",
            WarningKind::Ignored => "shapes or fields ignored",
            WarningKind::ShortRow => "short rows read as empty",
            WarningKind::Hidden => "hidden layers left out",
            WarningKind::Other => "see the log",
            WarningKind::Art => "art not drawn",
        }
    }
}

/// A level's warnings (and art warnings), each with its kind, in the
/// loader's order.
pub fn warnings(loaded: &LoadedLevel) -> Vec<Warning> {
    let plain = loaded.warnings.iter().map(|w| Warning {
        kind: WarningKind::of(w),
        text: w.clone(),
    });
    let art = loaded.art.warnings.iter().map(|w| Warning {
        kind: WarningKind::Art,
        text: w.clone(),
    });
    plain.chain(art).collect()
}

/// The warning a host must see first (the worst kind, the first of it), if
/// the level has any.
pub fn worst_warning(loaded: &LoadedLevel) -> Option<Warning> {
    warnings(loaded).into_iter().min_by_key(|w| w.kind.rank())
}

/// Whether the importer guessed which tiles collide (the file carries no
/// collision data).
pub fn guessed_collision(loaded: &LoadedLevel) -> bool {
    loaded
        .warnings
        .iter()
        .any(|w| WarningKind::of(w) == WarningKind::GuessedCollision)
}

/// One warning.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Warning {
    /// What it is about.
    pub kind: WarningKind,
    /// The line as the importer wrote it.
    pub text: String,
}

/// What a level became: `ledge-level check --json`'s object for one level.
/// Lengths are pixels.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LevelReport {
    /// The file as given.
    pub file: String,
    /// The level's name.
    pub level: String,
    /// The collision grid (`None`: no tile or grid layer collides).
    pub grid: Option<GridReport>,
    /// Everything in the level (grid, entities, platform paths):
    /// `[left, top, right, bottom]`.
    pub bounds: Option<[f64; 4]>,
    /// The bounds' width and height.
    pub size: Option<[f64; 2]>,
    /// Tiles by kind (`solid`, `one_way`, `hazard`, `slope`; kinds with none
    /// left out).
    pub tiles: BTreeMap<&'static str, usize>,
    /// Entities by kind ([`entity_kind_name`]).
    pub entities: BTreeMap<&'static str, usize>,
    /// What each editor layer became, in file order.
    pub layers: Vec<LayerReport>,
    /// The player spawns: centre and size of each spawn entity's box.
    pub spawns: Vec<BoxReport>,
    /// Waypoints of the bot route.
    pub route_waypoints: usize,
    /// Every warning, art warnings last.
    pub warnings: Vec<Warning>,
    /// The settings file used, if any.
    pub settings: Option<String>,
}

/// The collision grid.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridReport {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Side of a tile.
    pub tile: f64,
    /// Top-left corner: `[x, y]`.
    pub origin: [f64; 2],
}

/// One editor layer.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayerReport {
    /// Its name.
    pub name: String,
    /// Its path in the file (`layers[2]`); empty for an entity layer.
    pub field: String,
    /// What it became: `collision` (its cells are in the grid),
    /// `off_grid` (a tile layer that does not line up: it does not
    /// collide) or `entities`.
    pub became: &'static str,
    /// Its tiles by kind.
    pub tiles: BTreeMap<&'static str, usize>,
    /// Its entities by kind.
    pub entities: BTreeMap<&'static str, usize>,
}

/// A box: centre and size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BoxReport {
    /// Centre x.
    pub x: f64,
    /// Centre y.
    pub y: f64,
    /// Width.
    pub width: f64,
    /// Height.
    pub height: f64,
}

fn px(u: i32) -> f64 {
    u as f64 / UNITS_PER_PX as f64
}

/// The tile kind names of reports (`None`: empty).
pub fn tile_kind_label(t: Tile) -> Option<&'static str> {
    match t {
        Tile::Empty => None,
        Tile::Solid => Some("solid"),
        Tile::OneWay => Some("one_way"),
        Tile::Hazard => Some("hazard"),
        Tile::Slope(_) => Some("slope"),
    }
}

impl LevelReport {
    /// The report of `loaded`, loaded from `file` with `settings`.
    pub fn new(file: &str, loaded: &LoadedLevel, settings: Option<&str>) -> LevelReport {
        let level = &loaded.level;
        let bounds = level
            .bounds()
            .map(|(lo, hi)| [px(lo.x), px(lo.y), px(hi.x), px(hi.y)]);
        let map = &level.tilemap;
        let grid = (map.width() > 0 && map.height() > 0).then(|| GridReport {
            width: map.width(),
            height: map.height(),
            tile: px(map.tile_size()),
            origin: [px(map.origin().x), px(map.origin().y)],
        });
        let mut tiles = BTreeMap::new();
        for name in map.tiles().iter().filter_map(|&t| tile_kind_label(t)) {
            *tiles.entry(name).or_default() += 1;
        }
        let mut entities = BTreeMap::new();
        for e in &level.entities {
            *entities.entry(entity_kind_name(&e.kind)).or_default() += 1;
        }
        let spawns = level
            .entities
            .iter()
            .filter(|e| e.kind == EntityKind::PlayerSpawn)
            .map(|e| BoxReport {
                x: px(e.pos.x),
                y: px(e.pos.y),
                width: px(e.size.x),
                height: px(e.size.y),
            })
            .collect();
        LevelReport {
            file: file.to_owned(),
            level: level.name.clone(),
            grid,
            bounds,
            size: bounds.map(|[l, t, r, b]| [r - l, b - t]),
            tiles,
            entities,
            layers: loaded.layers.iter().map(layer_report).collect(),
            spawns,
            route_waypoints: loaded.route.len(),
            warnings: warnings(loaded),
            settings: settings.map(str::to_owned),
        }
    }
}

fn layer_report(l: &crate::LayerStats) -> LayerReport {
    let tiles = [
        ("solid", l.solid),
        ("one_way", l.one_way),
        ("hazard", l.hazard),
        ("slope", l.slopes),
    ]
    .into_iter()
    .filter(|&(_, n)| n > 0)
    .collect();
    LayerReport {
        name: l.name.clone(),
        field: l.field.clone(),
        became: match (l.field.is_empty(), l.on_grid) {
            (true, _) => "entities",
            (false, true) => "collision",
            (false, false) => "off_grid",
        },
        tiles,
        entities: l.entities.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warnings_have_their_kinds() {
        let cases = [
            (
                "x.tmx: map: the map has no collision data (no tile ...",
                WarningKind::GuessedCollision,
            ),
            (
                "x.json: the level has no collision data (no grid layer",
                WarningKind::GuessedCollision,
            ),
            (
                "x.ldtk: the level has no IntGrid layer, so its tiles do not collide",
                WarningKind::NoCollision,
            ),
            (
                "x.tmx: no player spawn: players start at (1, 2) px",
                WarningKind::SpawnPlaced,
            ),
            (
                "x.tmx: layer \"a\" (layers[1]): hidden tile layer: not collided (make it",
                WarningKind::LayerNotCollided,
            ),
            (
                "x.json: layers[0]: tile layer \"a\" does not collide: its tileset",
                WarningKind::LayerNotCollided,
            ),
            (
                "x.ldtk: value 3 ... is not a name ledge knows: read as solid",
                WarningKind::ReadAsSolid,
            ),
            (
                "x.ldtk: ladder is not supported in ledge (it has no such tile): read as empty",
                WarningKind::UnsupportedTile,
            ),
            (
                "x.tmx: skipped objects named \"hero\": not a ledge entity",
                WarningKind::EntitySkipped,
            ),
            (
                "x.tmx: layer \"bounds\": hidden object layer: its 4 objects are ignored",
                WarningKind::Hidden,
            ),
            (
                "x.tmx: a collision rectangle of zero size is ignored",
                WarningKind::Ignored,
            ),
            ("x.tmx: something new", WarningKind::Other),
        ];
        for (text, kind) in cases {
            assert_eq!(WarningKind::of(text), kind, "{text}");
        }
        assert!(WarningKind::GuessedCollision.rank() < WarningKind::SpawnPlaced.rank());
        assert!(WarningKind::Other.rank() < WarningKind::Art.rank());
    }
}
