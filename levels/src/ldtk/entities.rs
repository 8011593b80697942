//! LDtk entities as the importers' [`PlacedEntity`]s: their identifier
//! read through LDtk's usual names (and the settings' aliases), their box
//! from `px`, `__pivot`, `width` and `height`, their fields as parameters,
//! and a `Point` / `Array<Point>` field as a moving platform's path.
//!
//! | identifier (any case, `-` and spaces as `_`) | ledge entity |
//! |---|---|
//! | the entity table's names (the spawn names of [`crate::SPAWN_NAMES`]: `player`, `player_start`, `hero`, `Start1`, ...; `coin`, `goal`, `exit`, `flag`, `checkpoint`, `spike`, `hazard`, `walker`, `enemy`, ...) | as the table says |
//! | `gem`, `gems`, `coins`, `collectible`, `collectibles`, `collectable` | coin |
//! | `mob`, `mobs`, `monster` | walker (a patrol is not used: ledge walkers turn at walls and ledges) |
//! | `door`, `finish` | goal |
//! | `save_point`, `savepoint` | checkpoint |
//! | `hazards`, `lava` | hazard |
//! | any name containing `platform`, with a `Point` / `Array<Point>` field | moving platform along those points |
//!
//! A name containing `platform` without points is skipped with a warning;
//! any other name goes to the entity table as it is (unknown names are
//! skipped with a warning there).

use std::collections::BTreeMap;

use glam::IVec2;
use serde_json::Value;

use super::model::{self, EntityInstance, LayerInstance};
use crate::entities::{check_coord_field, place_box, px_to_units, PlacedEntity, PropValue};
use crate::error::LevelError;
use crate::mapping::normalize;
use crate::options::LoadOptions;

/// Field names read as a path first (any `Point` field otherwise).
const PATH_FIELDS: &[&str] = &["path", "points", "nodes", "waypoints", "route", "patrol"];

/// The ledge name of an LDtk identifier (normalised) from LDtk's usual
/// names, `None` when the entity table reads it as it is.
fn ldtk_name(n: &str) -> Option<&'static str> {
    Some(match n {
        "gem" | "gems" | "coins" | "collectible" | "collectibles" | "collectable" => "coin",
        "mob" | "mobs" | "monster" => "walker",
        "door" | "finish" => "goal",
        "save_point" | "savepoint" => "checkpoint",
        "hazards" | "lava" => "hazard",
        _ => return None,
    })
}

/// The entities of entity layer `l` (`field` its path in the level),
/// appended to `out`; warnings for platforms without a path and walkers
/// whose patrol is not used.
pub(crate) fn placed(
    file: &str,
    field: &str,
    l: &LayerInstance,
    options: &LoadOptions,
    out: &mut Vec<PlacedEntity>,
    warnings: &mut Vec<String>,
) -> Result<(), LevelError> {
    let grid = model::grid_size(file, field, l.grid_size)? as f64;
    let offset = (l.offset_x as f64, l.offset_y as f64);
    // identifier -> (entities, first field) whose patrol is not used
    let mut patrols: BTreeMap<&str, (usize, String)> = BTreeMap::new();
    for (j, e) in l.entity_instances.iter().enumerate() {
        let ef = format!("{field}.entityInstances[{j}]");
        let n = normalize(&e.identifier);
        let aliased = options.entity_aliases.contains_key(&n);
        let mut name = e.identifier.clone();
        if !aliased {
            if let Some(to) = ldtk_name(&n) {
                name = to.to_owned();
            } else if n.contains("platform") {
                name = "platform".to_owned();
            }
        }
        let path = path_field(e);
        let ledge = normalize(options.entity_name(&name));
        let is_platform = matches!(
            ledge.as_str(),
            "platform" | "moving_platform" | "movingplatform" | "mover" | "elevator"
        );
        if is_platform && path.is_none() {
            warnings.push(format!(
                "{file}: {ef}: skipped entity {:?} in layer {:?}: a moving platform needs a path: give it a field of type Array<Point> (path, points or nodes) with the points it moves through",
                e.identifier, l.identifier
            ));
            continue;
        }
        let geo = Geometry { grid, offset };
        let (centre, size) = geo.place(file, &ef, e, e.px)?;
        let mut nodes = Vec::new();
        match (path, is_platform) {
            (Some((k, points)), true) => {
                let pf = format!("{ef}.fieldInstances[{k}].__value");
                nodes = geo.nodes(file, &pf, e, points, centre)?;
            }
            (Some((_, points)), false)
                if !points.is_empty() && matches!(ledge.as_str(), "walker" | "enemy") =>
            {
                let p = patrols.entry(&e.identifier).or_insert((0, ef.clone()));
                p.0 += 1;
            }
            _ => {}
        }
        out.push(PlacedEntity {
            name,
            layer: l.identifier.clone(),
            field: ef,
            values_key: "fieldInstances",
            centre,
            size,
            nodes,
            values: values(e),
            polygon: None,
            turn: None,
            sized: true,
        });
    }
    for (ident, (count, first)) in patrols {
        warnings.push(format!(
            "{file}: {first}: the patrol points of {count} {ident:?} entities in layer {:?} are not used: ledge walkers walk until a wall or a ledge turns them",
            l.identifier
        ));
    }
    Ok(())
}

/// The entity's path: the first `Point` / `Array<Point>` field named like
/// a path, else the first such field, with its index; its points as JSON.
fn path_field(e: &EntityInstance) -> Option<(usize, &[Value])> {
    let points = |k: usize| {
        let f = &e.field_instances[k];
        match (&f.value, f.kind.as_str()) {
            (Value::Array(a), "Array<Point>") => Some((k, a.as_slice())),
            (v @ Value::Object(_), "Point") => Some((k, std::slice::from_ref(v))),
            _ => None,
        }
    };
    let named = (0..e.field_instances.len())
        .filter(|&k| PATH_FIELDS.contains(&normalize(&e.field_instances[k].identifier).as_str()))
        .find_map(points);
    named.or_else(|| (0..e.field_instances.len()).find_map(points))
}

/// An entity's fields as parameters: numbers, booleans and strings (enums,
/// colours, text); nulls, arrays and objects are left out.
fn values(e: &EntityInstance) -> Vec<(String, PropValue)> {
    e.field_instances
        .iter()
        .filter_map(|f| {
            let v = match &f.value {
                Value::Bool(b) => PropValue::Bool(*b),
                Value::Number(n) => PropValue::Number(n.as_f64().unwrap_or(f64::NAN)),
                Value::String(s) => PropValue::Text(s.clone()),
                _ => return None,
            };
            Some((f.identifier.clone(), v))
        })
        .collect()
}

/// Where a layer's entities are: its cell size and offset, pixels.
struct Geometry {
    grid: f64,
    offset: (f64, f64),
}

impl Geometry {
    /// The centre and size (units) of entity `e` with its pivot at `px`
    /// (layer pixels).
    fn place(
        &self,
        file: &str,
        field: &str,
        e: &EntityInstance,
        px: [f64; 2],
    ) -> Result<(IVec2, IVec2), LevelError> {
        let [pivot_x, pivot_y] = e.pivot;
        if !(pivot_x.is_finite() && pivot_y.is_finite()) {
            return Err(model::bad(
                file,
                format!("{field}.__pivot"),
                format!("pivot ({pivot_x}, {pivot_y}) is not a pair of numbers"),
            ));
        }
        let left = px[0] + self.offset.0 - pivot_x * e.width;
        let top = px[1] + self.offset.1 - pivot_y * e.height;
        let ux = px_to_units(file, &format!("{field}.px[0]"), left)?;
        let uy = px_to_units(file, &format!("{field}.px[1]"), top)?;
        check_coord_field(file, &format!("{field}.px[0]"), ux)?;
        check_coord_field(file, &format!("{field}.px[1]"), uy)?;
        place_box(file, field, ux, uy, e.width, e.height)
    }

    /// Path nodes (centres, units) from grid points `{cx, cy}`: the entity
    /// stands at each point as if placed in that cell (its pivot at the
    /// cell's pivot point). Leading points where the entity already is are
    /// dropped; more than [`crate::MAX_PATH_NODES`] points are refused
    /// before any is read.
    fn nodes(
        &self,
        file: &str,
        field: &str,
        e: &EntityInstance,
        points: &[Value],
        centre: IVec2,
    ) -> Result<Vec<IVec2>, LevelError> {
        use crate::entities::MAX_PATH_NODES;
        if points.len() >= MAX_PATH_NODES {
            return Err(LevelError::DegeneratePath {
                file: file.into(),
                field: field.into(),
                message: format!(
                    "{} points, at most {} allowed",
                    points.len(),
                    MAX_PATH_NODES - 1
                ),
            });
        }
        let mut nodes = Vec::with_capacity(points.len());
        for (i, p) in points.iter().enumerate() {
            let pf = format!("{field}[{i}]");
            let cell = |key: &str| {
                p.get(key).and_then(Value::as_f64).ok_or_else(|| {
                    model::bad(
                        file,
                        format!("{pf}.{key}"),
                        format!("expected a point {{\"cx\": .., \"cy\": ..}}, got {p}"),
                    )
                })
            };
            let (cx, cy) = (cell("cx")?, cell("cy")?);
            let px = [(cx + e.pivot[0]) * self.grid, (cy + e.pivot[1]) * self.grid];
            let (c, _) = self.place(file, &pf, e, px)?;
            if nodes.is_empty() && c == centre {
                continue;
            }
            nodes.push(c);
        }
        Ok(nodes)
    }
}
