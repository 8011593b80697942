//! The entity name table shared by every loader, entity parameters, and the
//! bot route.

use glam::IVec2;

use super::mapping::normalize;
use super::{EntityDef, EntityKind, LevelError, PlatformMotion, RouteAction, SpeedUnit, Waypoint};
use ledge_shared::fixed::{MAX_COORD, MAX_EXTENT, MAX_SPEED, UNITS_PER_PX};
use ledge_shared::level::Trigger;
use ledge_shared::shape::{ConvexPolygon, Obb, ShapeError, MAX_POLYGON_VERTICES};

/// The player spawn names every loader (Tiled, OGMO, LDtk) reads, before
/// the number a name may end with (`Start1`, `player_2`, `Player-3`); also
/// written without the `_` (`PlayerStart`, `SpawnPoint`). Matching is
/// ASCII case-insensitive, `-` and spaces read as `_`.
pub const SPAWN_NAMES: &[&str] = &[
    "player",
    "spawn",
    "player_spawn",
    "player_start",
    "start",
    "start_point",
    "spawn_point",
    "hero",
    "entrance",
];

/// Every entity name the loaders know, for messages (matching is ASCII
/// case-insensitive, with `-` and spaces read as `_`):
///
/// | names | becomes | parameters (OGMO `values`, Tiled `properties`) |
/// |---|---|---|
/// | [`SPAWN_NAMES`]: `player`, `spawn`, `player_spawn`, `player_start`, `start`, `start_point`, `spawn_point`, `hero`, `entrance`, also with a number (`Start1`, `Player_2`) | [`EntityKind::PlayerSpawn`] | |
/// | `block`, `solid`, `crate` | [`EntityKind::Block`]; a Tiled polygon object of these names: [`EntityKind::PolygonBlock`] | |
/// | `polygon`, `polygon_block`, `ramp` | [`EntityKind::PolygonBlock`]: a static convex polygon of 3 to 8 vertices. OGMO: the vertices are the entity's position followed by its `nodes` (raw positions of the entity's origin, as the editor draws them); Tiled: a polygon object's points (an unnamed polygon object is one too) | |
/// | `platform`, `moving_platform`, `mover`, `elevator` | [`EntityKind::MovingPlatform`] | `speed` (px/tick, default 1), `one_way` (bool, default false), `loop` (bool, default false); path: OGMO `nodes`, Tiled `path` (object property naming a polyline or polygon) |
/// | `walker`, `enemy` | [`EntityKind::Walker`] | `speed` (px/tick, default 0.5) |
/// | `spring`, `springboard`, `trampoline` | [`EntityKind::Springboard`] | `strength` (px/tick, default 10) |
/// | `coin` | [`EntityKind::Coin`] | |
/// | `checkpoint` | [`EntityKind::Checkpoint`] | |
/// | `goal`, `exit`, `flag` | [`EntityKind::Goal`] | |
/// | `hazard`, `spikes`, `spike` | [`EntityKind::Hazard`] | |
/// | `waypoint`, `route` | a [`Waypoint`] of the bot route (not an entity) | `action` (`walk`, `jump` or `spring`, default `walk`) |
pub const ENTITY_NAMES: &[&str] = &[
    "player",
    "spawn",
    "player_spawn",
    "player_start",
    "start",
    "start_point",
    "spawn_point",
    "hero",
    "entrance",
    "block",
    "solid",
    "crate",
    "polygon",
    "polygon_block",
    "ramp",
    "platform",
    "moving_platform",
    "mover",
    "elevator",
    "walker",
    "enemy",
    "spring",
    "springboard",
    "trampoline",
    "coin",
    "checkpoint",
    "goal",
    "exit",
    "flag",
    "hazard",
    "spikes",
    "spike",
    "waypoint",
    "route",
];

/// Default moving platform speed: 1 px per tick, in units per tick.
pub const DEFAULT_PLATFORM_SPEED: i32 = UNITS_PER_PX;
/// Default walker speed: 0.5 px per tick, in units per tick.
pub const DEFAULT_WALKER_SPEED: i32 = UNITS_PER_PX / 2;
/// Default springboard strength: 10 px per tick upwards, in units per tick.
pub const DEFAULT_SPRING_STRENGTH: i32 = 10 * UNITS_PER_PX;
/// Most nodes a platform path may have.
pub const MAX_PATH_NODES: usize = 256;

/// A parameter value from an editor (OGMO `values`, Tiled `properties`).
#[derive(Debug, Clone, PartialEq)]
pub enum PropValue {
    /// A boolean.
    Bool(bool),
    /// A number (integer or float).
    Number(f64),
    /// A string (also OGMO enum and colour values).
    Text(String),
}

impl PropValue {
    fn describe(&self) -> String {
        match self {
            PropValue::Bool(b) => b.to_string(),
            PropValue::Number(n) => n.to_string(),
            PropValue::Text(s) => format!("{s:?}"),
        }
    }
}

/// An entity as placed in an editor, converted to world units but not yet
/// classified: what both loaders hand to the entity table.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedEntity {
    /// The editor's name (OGMO entity name; Tiled class/type, else name).
    pub name: String,
    /// The layer's name.
    pub layer: String,
    /// Path of the entity in its file, e.g. `layers[3].entities[1]`.
    pub field: String,
    /// Name of the parameter table in the file (`values` or `properties`).
    pub values_key: &'static str,
    /// Centre, in units.
    pub centre: IVec2,
    /// Full size, in units (even).
    pub size: IVec2,
    /// Path nodes (centre positions, in units), not including the entity's
    /// own position.
    pub nodes: Vec<IVec2>,
    /// Parameters, in file order.
    pub values: Vec<(String, PropValue)>,
    /// The outline, for an entity drawn as a polygon (an OGMO polygon
    /// entity, a Tiled polygon object); `None` for boxes.
    pub polygon: Option<PlacedPolygon>,
    /// How the editor turned the box (`centre`, `size` are the box before
    /// turning); `None` when it is upright.
    pub turn: Option<Turn>,
    /// The file gives the size (a Tiled rectangle or tile object, an OGMO
    /// entity's own `width` and `height`, an LDtk entity), rather than a
    /// default (a Tiled point, an OGMO project's size): a spawn's size then
    /// sizes the player.
    pub sized: bool,
}

/// How an editor turned a box entity: clockwise on screen (y down) by
/// `degrees` about `pivot`. A block becomes a polygon block of its turned
/// outline; a hazard, coin, checkpoint or goal turns (a quarter turn stays
/// a box, other angles make an [`EntityKind::Turned`]); other entities
/// stand upright, with a warning.
#[derive(Debug, Clone, PartialEq)]
pub struct Turn {
    /// Degrees, clockwise: finite, not a whole number of turns.
    pub degrees: f64,
    /// The point it turns about (OGMO: the entity's origin, Tiled: the
    /// object's position), absolute, in units.
    pub pivot: (f64, f64),
    /// Path of the rotation in the file (`layers[1].entities[3].rotation`).
    pub field: String,
}

impl Turn {
    /// A turn by `degrees` about `pivot` (units), `None` when `degrees` is
    /// not finite or a whole number of turns.
    pub fn new(degrees: f64, pivot: (f64, f64), field: String) -> Option<Turn> {
        (degrees.is_finite() && degrees % 360.0 != 0.0).then_some(Turn {
            degrees,
            pivot,
            field,
        })
    }

    /// Whole quarter turns clockwise (0 to 3) when the angle is one (within
    /// 1e-6 degrees), else `None`.
    fn quarters(&self) -> Option<u32> {
        let q = self.degrees / 90.0;
        ((q - q.round()).abs() < 1e-8).then(|| (q.round() as i64).rem_euclid(4) as u32)
    }

    /// `p` (units) turned about the pivot.
    fn apply(&self, p: (f64, f64)) -> (f64, f64) {
        let (dx, dy) = (p.0 - self.pivot.0, p.1 - self.pivot.1);
        let (x, y) = match self.quarters() {
            // Exact for quarter turns.
            Some(0) => (dx, dy),
            Some(1) => (-dy, dx),
            Some(2) => (-dx, -dy),
            Some(3) => (dy, -dx),
            _ => {
                let (sin, cos) = self.degrees.to_radians().sin_cos();
                (dx * cos - dy * sin, dx * sin + dy * cos)
            }
        };
        (self.pivot.0 + x, self.pivot.1 + y)
    }

    /// A vector (units) turned, rounded to whole units.
    fn vector(&self, v: (f64, f64)) -> IVec2 {
        let (x, y) = self.apply((self.pivot.0 + v.0, self.pivot.1 + v.1));
        IVec2::new(
            (x - self.pivot.0).round() as i32,
            (y - self.pivot.1).round() as i32,
        )
    }
}

/// The outline of a polygon entity as placed: absolute vertices in units,
/// each with its path in the file, for errors.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedPolygon {
    /// Path of the outline, e.g. `layers[1].objects[2].polygon (object 7
    /// "ramp")` or `layers[1].entities[4].nodes`.
    pub field: String,
    /// Vertices in file order, absolute, in units.
    pub points: Vec<IVec2>,
    /// Path of each vertex (same length as `points`).
    pub point_fields: Vec<String>,
}

/// Whether `name` is one of the polygon block names of [`ENTITY_NAMES`]
/// (the OGMO loader reads such an entity's nodes as vertices).
pub(crate) fn is_polygon_name(name: &str) -> bool {
    matches!(class_of(name), Some(Class::Polygon))
}

/// Whether `name` is a block name of [`ENTITY_NAMES`] (`block`, `solid`,
/// `crate`).
pub(crate) fn is_block_name(name: &str) -> bool {
    matches!(class_of(name), Some(Class::Block))
}

/// Whether `name` names an entity that moves or vanishes in play: a coin,
/// a walker, a moving platform.
pub(crate) fn moves_or_vanishes(name: &str) -> bool {
    matches!(
        class_of(name),
        Some(Class::Coin | Class::Walker | Class::Platform)
    )
}

/// Whether `name` is a player spawn name ([`SPAWN_NAMES`]).
pub(crate) fn is_spawn(name: &str) -> bool {
    matches!(class_of(name), Some(Class::Spawn))
}

/// Whether `name` is in the entity table ([`ENTITY_NAMES`]).
pub(crate) fn is_entity_name(name: &str) -> bool {
    class_of(name).is_some()
}

/// What an entity became.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Classified {
    Entity(EntityDef),
    Waypoint(Waypoint),
    Unknown,
}

/// Pixels to units: finite and within the world bounds, rounded to the
/// nearest unit (exact for whole and 1/256 pixels).
pub(crate) fn px_to_units(file: &str, field: &str, px: f64) -> Result<i64, LevelError> {
    let limit = (MAX_COORD / UNITS_PER_PX) as f64;
    if !px.is_finite() || px.abs() > limit {
        return Err(LevelError::OutOfBounds {
            file: file.into(),
            field: field.into(),
            message: format!("{px} px is outside the world bound of ±{limit} px"),
        });
    }
    Ok((px * UNITS_PER_PX as f64).round() as i64)
}

/// A box of `left`, `top` (units, offsets included) and `w`, `h` (pixels) as
/// an even size and a centre, checked against the bounds.
pub(crate) fn place_box(
    file: &str,
    field: &str,
    left: i64,
    top: i64,
    w_px: f64,
    h_px: f64,
) -> Result<(IVec2, IVec2), LevelError> {
    let mut size = [0i64; 2];
    for (i, (v, name)) in [(w_px, "width"), (h_px, "height")].into_iter().enumerate() {
        let f = format!("{field}.{name}");
        let max = (MAX_EXTENT / UNITS_PER_PX) as f64;
        if !v.is_finite() || v <= 0.0 || v > max {
            return Err(LevelError::OutOfBounds {
                file: file.into(),
                field: f,
                message: format!("{v} px is not a size in (0, {max}] px"),
            });
        }
        // Even units, at least 2.
        size[i] = (2.0 * (v * UNITS_PER_PX as f64 / 2.0).round()).max(2.0) as i64;
    }
    let centre = [left + size[0] / 2, top + size[1] / 2];
    for (c, axis) in centre.iter().zip(["x", "y"]) {
        check_coord_field(file, &format!("{field}.{axis}"), *c)?;
    }
    Ok((
        IVec2::new(centre[0] as i32, centre[1] as i32),
        IVec2::new(size[0] as i32, size[1] as i32),
    ))
}

/// A coordinate in units within [`MAX_COORD`].
pub(crate) fn check_coord_field(file: &str, field: &str, v: i64) -> Result<(), LevelError> {
    if v.abs() > MAX_COORD as i64 {
        return Err(LevelError::OutOfBounds {
            file: file.into(),
            field: field.into(),
            message: format!("{v} units is outside the world bound of ±{MAX_COORD} units"),
        });
    }
    Ok(())
}

enum Class {
    Spawn,
    Block,
    Polygon,
    Platform,
    Walker,
    Spring,
    Coin,
    Checkpoint,
    Goal,
    Hazard,
    Waypoint,
}

/// Whether `n` (normalised) is a spawn name: one of [`SPAWN_NAMES`] (its
/// `_`s optional), optionally followed by a number (`start1`, `player_2`).
fn is_spawn_name(n: &str) -> bool {
    let base = n.trim_end_matches(|c: char| c.is_ascii_digit());
    let base = if base.len() < n.len() {
        base.strip_suffix('_').unwrap_or(base)
    } else {
        base
    };
    let squash = |s: &str| s.replace('_', "");
    let base = squash(base);
    SPAWN_NAMES.iter().any(|s| squash(s) == base)
}

fn class_of(name: &str) -> Option<Class> {
    Some(match normalize(name).as_str() {
        n if is_spawn_name(n) => Class::Spawn,
        "block" | "solid" | "crate" => Class::Block,
        "polygon" | "polygon_block" | "polygonblock" | "ramp" => Class::Polygon,
        "platform" | "moving_platform" | "movingplatform" | "mover" | "elevator" => Class::Platform,
        "walker" | "enemy" => Class::Walker,
        "spring" | "springboard" | "trampoline" => Class::Spring,
        "coin" => Class::Coin,
        "checkpoint" => Class::Checkpoint,
        "goal" | "exit" | "flag" => Class::Goal,
        "hazard" | "spikes" | "spike" => Class::Hazard,
        "waypoint" | "route" => Class::Waypoint,
        _ => return None,
    })
}

struct Params<'a> {
    file: &'a str,
    e: &'a PlacedEntity,
    /// Units of the speeds.
    unit: SpeedUnit,
    /// The level's player scale (1/256ths): default speeds scale with it.
    scale: u32,
}

impl Params<'_> {
    fn find(&self, keys: &[&str]) -> Option<(String, &PropValue)> {
        self.e.values.iter().find_map(|(k, v)| {
            let n = normalize(k);
            keys.contains(&n.as_str())
                .then(|| (format!("{}.{}.{k}", self.e.field, self.e.values_key), v))
        })
    }

    fn bad(&self, field: String, message: String) -> LevelError {
        LevelError::BadValue {
            file: self.file.into(),
            field,
            message,
        }
    }

    fn bool(&self, keys: &[&str]) -> Result<bool, LevelError> {
        let Some((field, v)) = self.find(keys) else {
            return Ok(false);
        };
        match v {
            PropValue::Bool(b) => Ok(*b),
            PropValue::Number(n) if *n == 0.0 || *n == 1.0 => Ok(*n == 1.0),
            PropValue::Text(s) if s.eq_ignore_ascii_case("true") => Ok(true),
            PropValue::Text(s) if s.eq_ignore_ascii_case("false") => Ok(false),
            other => Err(self.bad(
                field,
                format!("expected a boolean, got {}", other.describe()),
            )),
        }
    }

    /// A speed in the file's unit (px/tick unless the settings say px/s),
    /// as units/tick in `(0, MAX_SPEED]`.
    fn speed(&self, keys: &[&str], default: i32) -> Result<i32, LevelError> {
        let Some((field, v)) = self.find(keys) else {
            let scaled = (i64::from(default) * i64::from(self.scale) + 128) / 256;
            return Ok(scaled.clamp(1, i64::from(MAX_SPEED)) as i32);
        };
        let unit = self.unit.name();
        let n = match v {
            PropValue::Number(n) => *n,
            PropValue::Text(s) => s.trim().parse::<f64>().map_err(|_| {
                self.bad(
                    field.clone(),
                    format!("expected a number ({unit}), got {s:?}"),
                )
            })?,
            other => {
                return Err(self.bad(
                    field,
                    format!("expected a number ({unit}), got {}", other.describe()),
                ));
            }
        };
        let per_tick = n * self.unit.px_per_tick();
        let max = (MAX_SPEED / UNITS_PER_PX) as f64;
        let units = (per_tick * UNITS_PER_PX as f64).round();
        if !n.is_finite() || units < 1.0 || per_tick > max {
            return Err(self.bad(
                field,
                format!(
                    "{n} {unit} is not a speed in (0, {}] {unit}",
                    max / self.unit.px_per_tick()
                ),
            ));
        }
        Ok(units as i32)
    }

    fn action(&self) -> Result<RouteAction, LevelError> {
        let Some((field, v)) = self.find(&["action"]) else {
            return Ok(RouteAction::Walk);
        };
        match v {
            PropValue::Text(s) => match normalize(s).as_str() {
                "walk" | "" => Ok(RouteAction::Walk),
                "jump" => Ok(RouteAction::Jump),
                "spring" => Ok(RouteAction::Spring),
                _ => Err(self.bad(
                    field,
                    format!("expected \"walk\", \"jump\" or \"spring\", got {s:?}"),
                )),
            },
            other => Err(self.bad(
                field,
                format!(
                    "expected \"walk\", \"jump\" or \"spring\", got {}",
                    other.describe()
                ),
            )),
        }
    }
}

/// Classifies one placed entity through the name table and reads its
/// parameters (speeds in `unit`; default speeds times the level's player
/// `scale`, in 1/256ths).
pub(crate) fn classify(
    file: &str,
    e: &PlacedEntity,
    (unit, scale): (SpeedUnit, u32),
    warnings: &mut Vec<String>,
) -> Result<Classified, LevelError> {
    let p = Params {
        file,
        e,
        unit,
        scale,
    };
    let Some(class) = class_of(&e.name) else {
        return Ok(Classified::Unknown);
    };
    if let (Some(turn), None) = (&e.turn, &e.polygon) {
        if let Some(turned) = turned(file, e, turn, &class, warnings)? {
            return Ok(turned);
        }
    }
    if let Some(poly) = &e.polygon {
        if !matches!(class, Class::Block | Class::Polygon) {
            return Err(LevelError::BadPolygon {
                file: file.into(),
                field: poly.field.clone(),
                message: format!(
                    "a polygon can only be a static solid (named \"polygon\" or \"block\", or unnamed), not {:?} (moving polygon platforms are not supported)",
                    e.name
                ),
            });
        }
        return polygon_block(file, poly).map(Classified::Entity);
    }
    let kind = match class {
        Class::Spawn => EntityKind::PlayerSpawn,
        Class::Block => EntityKind::Block,
        Class::Polygon => {
            return Err(LevelError::BadPolygon {
                file: file.into(),
                field: e.field.clone(),
                message: "a polygon block needs vertices: in OGMO its position and `nodes` (at least 2), in Tiled a polygon object".into(),
            });
        }
        Class::Coin => EntityKind::Coin,
        Class::Checkpoint => EntityKind::Checkpoint,
        Class::Goal => EntityKind::Goal,
        Class::Hazard => EntityKind::Hazard,
        Class::Walker => EntityKind::Walker {
            speed: p.speed(&["speed"], DEFAULT_WALKER_SPEED)?,
        },
        Class::Spring => EntityKind::Springboard {
            strength: p.speed(&["strength", "speed", "power"], DEFAULT_SPRING_STRENGTH)?,
        },
        Class::Platform => {
            let speed = p.speed(&["speed"], DEFAULT_PLATFORM_SPEED)?;
            let one_way = p.bool(&["one_way", "oneway"])?;
            let looped = p.bool(&["loop", "looped", "loops"])?;
            let path = platform_path(file, e, looped)?;
            EntityKind::MovingPlatform {
                motion: PlatformMotion {
                    path,
                    speed,
                    looped,
                },
                one_way,
            }
        }
        Class::Waypoint => {
            return Ok(Classified::Waypoint(Waypoint {
                foot: IVec2::new(e.centre.x, e.centre.y + e.size.y / 2),
                action: p.action()?,
            }));
        }
    };
    Ok(Classified::Entity(EntityDef {
        kind,
        pos: e.centre,
        size: e.size,
    }))
}

/// A turned box entity ([`Turn`]): a block as the polygon block of its
/// turned outline, a hazard, coin, checkpoint or goal turned (a box for a
/// quarter turn, else [`EntityKind::Turned`]); `None` for the others, which
/// stand upright (said in `warnings`).
fn turned(
    file: &str,
    e: &PlacedEntity,
    turn: &Turn,
    class: &Class,
    warnings: &mut Vec<String>,
) -> Result<Option<Classified>, LevelError> {
    let (c, h) = (
        (e.centre.x as f64, e.centre.y as f64),
        (e.size.x as f64 / 2.0, e.size.y as f64 / 2.0),
    );
    let trigger = match class {
        Class::Block => {
            let corners = [(-h.0, -h.1), (h.0, -h.1), (h.0, h.1), (-h.0, h.1)];
            let mut poly = PlacedPolygon {
                field: turn.field.clone(),
                points: Vec::with_capacity(4),
                point_fields: Vec::with_capacity(4),
            };
            for (i, (dx, dy)) in corners.into_iter().enumerate() {
                let cf = format!("{} (corner {i})", turn.field);
                let (x, y) = turn.apply((c.0 + dx, c.1 + dy));
                let (x, y) = (x.round() as i64, y.round() as i64);
                check_coord_field(file, &format!("{cf}.x"), x)?;
                check_coord_field(file, &format!("{cf}.y"), y)?;
                poly.points.push(IVec2::new(x as i32, y as i32));
                poly.point_fields.push(cf);
            }
            return polygon_block(file, &poly).map(|d| Some(Classified::Entity(d)));
        }
        Class::Hazard => Trigger::Hazard,
        Class::Coin => Trigger::Coin,
        Class::Checkpoint => Trigger::Checkpoint,
        Class::Goal => Trigger::Goal,
        _ => {
            warnings.push(format!(
                "{file}: {}: entity {:?} is turned by {} degrees: only blocks, hazards, coins, checkpoints and goals turn in ledge; it stands upright",
                turn.field, e.name, turn.degrees
            ));
            return Ok(None);
        }
    };
    let (x, y) = turn.apply(c);
    let (x, y) = (x.round() as i64, y.round() as i64);
    check_coord_field(file, &format!("{}.x", turn.field), x)?;
    check_coord_field(file, &format!("{}.y", turn.field), y)?;
    let pos = IVec2::new(x as i32, y as i32);
    let (kind, size) = match turn.quarters() {
        Some(q) if q % 2 == 1 => (trigger.kind(), IVec2::new(e.size.y, e.size.x)),
        Some(_) => (trigger.kind(), e.size),
        None => {
            let (u, v) = (turn.vector((h.0, 0.0)), turn.vector((0.0, h.1)));
            if Obb::from_axes(u, v).is_err() {
                return Err(LevelError::OutOfBounds {
                    file: file.into(),
                    field: turn.field.clone(),
                    message: format!(
                        "a {} x {} px box turned by {} degrees is not a shape ledge can collide (too thin or too large)",
                        e.size.x as f64 / UNITS_PER_PX as f64,
                        e.size.y as f64 / UNITS_PER_PX as f64,
                        turn.degrees
                    ),
                });
            }
            let ext = u.abs() + v.abs();
            (EntityKind::Turned { trigger, u, v }, ext * 2)
        }
    };
    Ok(Some(Classified::Entity(EntityDef { kind, pos, size })))
}

/// The platform's centre followed by its nodes; every leg non-empty. A
/// looped path whose last node repeats the start is closed by dropping that
/// node.
fn platform_path(file: &str, e: &PlacedEntity, looped: bool) -> Result<Vec<IVec2>, LevelError> {
    let err = |field: String, message: String| LevelError::DegeneratePath {
        file: file.into(),
        field,
        message,
    };
    let nodes_field = format!("{}.nodes", e.field);
    if e.nodes.is_empty() {
        return Err(err(
            nodes_field,
            "a moving platform needs at least one node besides its own position".into(),
        ));
    }
    if e.nodes.len() >= MAX_PATH_NODES {
        return Err(err(
            nodes_field,
            format!(
                "{} nodes, at most {} allowed",
                e.nodes.len(),
                MAX_PATH_NODES - 1
            ),
        ));
    }
    let mut path = Vec::with_capacity(e.nodes.len() + 1);
    path.push(e.centre);
    path.extend_from_slice(&e.nodes);
    if looped && path.len() > 2 && path.last() == path.first() {
        path.pop();
    }
    for i in 1..path.len() {
        if path[i] == path[i - 1] {
            return Err(err(
                format!("{nodes_field}[{}]", i - 1),
                format!(
                    "node at ({}, {}) units repeats the previous point (a zero-length leg)",
                    path[i].x, path[i].y
                ),
            ));
        }
    }
    Ok(path)
}

/// A [`EntityKind::PolygonBlock`] from an outline: centred on its bounding
/// box (rounded down), every vertex checked by [`ConvexPolygon::new`].
fn polygon_block(file: &str, poly: &PlacedPolygon) -> Result<EntityDef, LevelError> {
    let bad = |field: &str, message: String| LevelError::BadPolygon {
        file: file.into(),
        field: field.into(),
        message,
    };
    let pts = &poly.points;
    let n = pts.len();
    if !(3..=MAX_POLYGON_VERTICES).contains(&n) {
        return Err(bad(
            &poly.field,
            format!(
                "polygon has {n} vertices; it needs 3 to {MAX_POLYGON_VERTICES}{}",
                if n > MAX_POLYGON_VERTICES {
                    " (split a larger outline into several convex polygons)"
                } else {
                    ""
                }
            ),
        ));
    }
    let (mut lo, mut hi) = (pts[0].as_i64vec2(), pts[0].as_i64vec2());
    for p in pts {
        lo = lo.min(p.as_i64vec2());
        hi = hi.max(p.as_i64vec2());
    }
    let centre = (lo + hi).div_euclid(glam::I64Vec2::splat(2));
    let half = (hi - centre).max(centre - lo).max(glam::I64Vec2::ONE);
    if half.max_element() > MAX_EXTENT as i64 {
        return Err(LevelError::OutOfBounds {
            file: file.into(),
            field: poly.field.clone(),
            message: format!(
                "polygon spans {} x {} px; each vertex must lie within {} px of its centre",
                (hi.x - lo.x) as f64 / UNITS_PER_PX as f64,
                (hi.y - lo.y) as f64 / UNITS_PER_PX as f64,
                MAX_EXTENT / UNITS_PER_PX
            ),
        });
    }
    let pos = IVec2::new(centre.x as i32, centre.y as i32);
    let local: Vec<IVec2> = pts.iter().map(|p| *p - pos).collect();
    let at = |i: usize| {
        let p = pts[i % n];
        format!(
            "vertex {} ({}, {}) px",
            i % n,
            p.x as f64 / UNITS_PER_PX as f64,
            p.y as f64 / UNITS_PER_PX as f64
        )
    };
    let vertex_field = |i: usize| {
        poly.point_fields
            .get(i % n)
            .map_or(poly.field.as_str(), String::as_str)
    };
    match ConvexPolygon::new(&local) {
        Ok(_) => Ok(EntityDef {
            kind: EntityKind::PolygonBlock { vertices: local },
            pos,
            size: IVec2::new(2 * half.x as i32, 2 * half.y as i32),
        }),
        Err(ShapeError::DuplicateVertex(i)) => Err(bad(
            vertex_field(i),
            format!(
                "polygon is degenerate: {} repeats vertex {}",
                at(i),
                (i + n - 1) % n
            ),
        )),
        Err(ShapeError::Collinear(i)) => Err(bad(
            vertex_field(i),
            format!(
                "polygon is degenerate at {}: it lies on the line through vertices {} and {} (a straight corner or zero area)",
                at(i),
                (i + n - 1) % n,
                (i + 1) % n
            ),
        )),
        Err(ShapeError::Concave(i)) => Err(bad(
            vertex_field(i),
            format!(
                "polygon is concave at {} (or its outline crosses itself); split it into convex polygons",
                at(i)
            ),
        )),
        Err(ShapeError::Bounds(b)) => Err(LevelError::OutOfBounds {
            file: file.into(),
            field: poly.field.clone(),
            message: b.to_string(),
        }),
        Err(other) => Err(bad(&poly.field, format!("polygon refused: {other}"))),
    }
}
