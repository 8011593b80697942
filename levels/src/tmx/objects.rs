//! Tiled objects that are not ledge entities by their own name: what their
//! properties, their shape and their layer's name make of them ([`Role`]),
//! the one rule both the importer's pre-pass (is there collision drawn as
//! objects?) and its object pass read.

use ::tiled::{Object, ObjectShape};

use super::{props, Conv, LayerInfo};
use crate::collision::names::{layer_thing, Thing};
use crate::collision::tile_of_props;
use crate::entities::is_entity_name;
use crate::error::LevelError;
use crate::mapping::normalize;
use ledge_shared::tilemap::Tile;

/// What an object that is no entity by its own name becomes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Role {
    /// Static solid geometry: marked solid (or a slope), an unnamed shape,
    /// or a shape in a layer named for solid things (`Ground`, `Pipes`).
    Solid,
    /// A hazard box (marked so).
    Hazard,
    /// Marked one-way: not supported.
    OneWay,
    /// Marked not solid.
    Empty,
    /// This entity, by its layer's name (or its own, `Goomba`), or by the
    /// settings' `[entities]` alias for the layer.
    Entity {
        /// The ledge entity name.
        name: String,
        /// What said so: `layer "Coins"` or `the settings' [entities] alias`.
        why: String,
    },
    /// Skipped by its layer's name (`Camera`, `Background`, `Triggers`) or
    /// the settings' `decoration_layers`.
    Skip {
        /// What said so.
        why: String,
    },
    /// An unnamed point, text or capsule (a marker or label), or an unnamed
    /// tile object (drawn only).
    Marker,
    /// A name that is no entity: skipped with a warning (or refused).
    Unknown,
}

/// Whether a shape can be solid geometry by its layer's name (tile objects
/// are pictures: only their own marks make them solid).
fn is_plain_shape(o: &Object<'_>) -> bool {
    o.get_tile().is_none()
        && matches!(
            o.shape,
            ObjectShape::Rect { .. }
                | ObjectShape::Ellipse { .. }
                | ObjectShape::Polygon { .. }
                | ObjectShape::Polyline { .. }
        )
}

impl Conv<'_> {
    /// The role of object `o` (named `name`, which is no entity) in layer
    /// `info`. Its own marks win; then the settings' `decoration_layers`,
    /// an `[entities]` alias for the layer's name, the object's own name and
    /// its layer's name (`collision::names`); then an unnamed shape is
    /// solid.
    pub(super) fn object_role(
        &self,
        info: &LayerInfo<'_>,
        f: &str,
        o: &Object<'_>,
        name: &str,
    ) -> Result<Role, LevelError> {
        let own = tile_of_props(props(&o.properties), "")
            .map_err(|m| self.bad(format!("{f}.properties"), m))?;
        let from_tile = match (own, o.get_tile()) {
            (None, Some(t)) => match t.get_tile() {
                Some(td) => tile_of_props(props(&td.properties), &td.user_type)
                    .map_err(|m| self.bad(format!("{f}.properties"), m))?,
                None => None,
            },
            _ => None,
        };
        match own.or(from_tile) {
            Some(Tile::Solid) | Some(Tile::Slope(_)) => return Ok(Role::Solid),
            Some(Tile::Hazard) => return Ok(Role::Hazard),
            Some(Tile::OneWay) => return Ok(Role::OneWay),
            Some(Tile::Empty) => return Ok(Role::Empty),
            None => {}
        }
        if self
            .options
            .decoration_layers
            .iter()
            .any(|n| n == info.name)
        {
            return Ok(Role::Skip {
                why: format!("decoration_layers lists layer {:?}", info.name),
            });
        }
        if let Some(alias) = self.options.entity_aliases.get(&normalize(info.name)) {
            if is_entity_name(alias) {
                return Ok(Role::Entity {
                    name: alias.clone(),
                    why: format!("the settings' [entities] alias for layer {:?}", info.name),
                });
            }
        }
        let by_name = (!name.trim().is_empty())
            .then(|| layer_thing(name).map(|t| (t, format!("its name {name:?}"))))
            .flatten();
        let by_layer = || layer_thing(info.name).map(|t| (t, format!("layer {:?}", info.name)));
        match by_name.or_else(by_layer) {
            Some(((Thing::Entity(e), _), why)) => Ok(Role::Entity {
                name: e.into(),
                why,
            }),
            Some(((Thing::Solid, _), _)) if is_plain_shape(o) => Ok(Role::Solid),
            Some(((Thing::Skip, _), why)) => Ok(Role::Skip { why }),
            _ if name.trim().is_empty() && is_plain_shape(o) => Ok(Role::Solid),
            _ if name.trim().is_empty() => Ok(Role::Marker),
            _ => Ok(Role::Unknown),
        }
    }
}

impl Conv<'_> {
    /// Places object `o` as entity `entity` (its [`Role::Entity`]): its
    /// box (a point: one tile centred on it; a polygon or polyline: its
    /// points' bounds), its custom properties as parameters, and a note
    /// saying why and how to choose otherwise. Text and capsules are
    /// skipped, said.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn entity_by_name(
        &self,
        info: &LayerInfo<'_>,
        f: &str,
        o: &Object<'_>,
        entity: &str,
        why: &str,
        (x, y): (f64, f64),
        out: &mut Vec<crate::entities::PlacedEntity>,
    ) -> Result<(), LevelError> {
        let at = || format!("{} object {}", info.describe(), o.id());
        let bounds = |pts: &[(f32, f32)]| {
            let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
            for &(a, b) in pts {
                lo = (lo.0.min(a as f64), lo.1.min(b as f64));
                hi = (hi.0.max(a as f64), hi.1.max(b as f64));
            }
            (x + lo.0, y + lo.1, hi.0 - lo.0, hi.1 - lo.1)
        };
        let (left, top, w, h) = match &o.shape {
            ObjectShape::Polygon { points } | ObjectShape::Polyline { points }
                if !points.is_empty() =>
            {
                bounds(points)
            }
            ObjectShape::Text { .. }
            | ObjectShape::Polygon { .. }
            | ObjectShape::Polyline { .. } => {
                self.notes
                    .borrow_mut()
                    .add(format!("a text or empty shape is no {entity}: skipped"), at);
                return Ok(());
            }
            _ => match self.entity_box(f, o, (x, y)) {
                Ok(b) => b,
                Err(_) => {
                    self.notes
                        .borrow_mut()
                        .add(format!("a capsule is no {entity}: skipped"), at);
                    return Ok(());
                }
            },
        };
        let l = crate::entities::px_to_units(self.file, &format!("{f}.x"), left)?;
        let t = crate::entities::px_to_units(self.file, &format!("{f}.y"), top)?;
        let (centre, size) =
            crate::entities::place_box(self.file, f, l, t, w.max(1.0), h.max(1.0))?;
        let mut e = super::geometry_entity(info, f, centre, size, None);
        e.name = entity.into();
        let mut values: Vec<_> = o.properties.iter().collect();
        values.sort_by(|a, b| a.0.cmp(b.0));
        e.values = values
            .into_iter()
            .filter_map(|(k, v)| {
                use crate::entities::PropValue as P;
                use ::tiled::PropertyValue as V;
                let v = match v {
                    V::BoolValue(b) => P::Bool(*b),
                    V::FloatValue(n) => P::Number(*n as f64),
                    V::IntValue(n) => P::Number(*n as f64),
                    V::StringValue(s) => P::Text(s.clone()),
                    _ => return None,
                };
                Some((k.clone(), v))
            })
            .collect();
        out.push(e);
        self.notes.borrow_mut().add(
            format!(
                "objects with no ledge name or class are read as {entity:?} by {why}; give them a ledge name or class, or choose in the level's settings: [entities] {:?} = \"coin\" (any entity name) for the layer, or decoration_layers = [{:?}] to skip them",
                info.name, info.name
            ),
            at,
        );
        Ok(())
    }
}

/// The solid shapes a map draws in its object layers (the pre-pass's
/// count), and whether its tile layers hold any tile.
#[derive(Default)]
pub(super) struct DrawnSolids {
    /// Object ids of the solid shapes, with their layers' names (the first
    /// few, for the note).
    ids: Vec<u32>,
    /// How many there are.
    count: usize,
    /// The layers they are in (at most a few, for the note).
    layers: Vec<String>,
    /// A visible tile layer holds a tile.
    pub(super) tiles: bool,
}

/// Most object ids [`DrawnSolids`] keeps (the rest are only counted).
const KEPT_IDS: usize = 4096;

impl DrawnSolids {
    /// Whether any solid shape is not a platform's path.
    pub(super) fn found(&self, paths: &super::Paths) -> bool {
        self.count > self.ids.len()
            || self
                .ids
                .iter()
                .any(|id| !(paths.used.contains(id) && paths.by_id.contains_key(id)))
    }
}

impl Conv<'_> {
    /// Counts into `out` the objects of layer `info` that become solid
    /// geometry ([`Role::Solid`]), as the object pass will make them.
    pub(super) fn solid_objects(
        &self,
        info: &LayerInfo<'_>,
        ol: &::tiled::ObjectLayer<'_>,
        out: &mut DrawnSolids,
    ) -> Result<(), LevelError> {
        if !info.visible {
            return Ok(());
        }
        for (k, o) in ol.objects().enumerate() {
            let name = super::common::object_name(self.options, &o);
            if !o.visible || is_entity_name(self.options.entity_name(name)) {
                continue;
            }
            let f = format!("{}.objects[{k}]", info.field);
            if self.object_role(info, &f, &o, name)? == Role::Solid {
                out.count += 1;
                if out.ids.len() < KEPT_IDS {
                    out.ids.push(o.id());
                }
                if out.layers.len() < 4 && !out.layers.iter().any(|l| l == info.name) {
                    out.layers.push(info.name.to_owned());
                }
            }
        }
        Ok(())
    }

    /// Says that the map's collision is its object shapes, so its tile
    /// layers (when they hold tiles) are decoration.
    pub(super) fn objects_collide_note(&self, d: &DrawnSolids) {
        if !d.tiles {
            return;
        }
        self.notes.borrow_mut().add(
            format!(
                "the map has no collision data for its tiles (no tile collision shapes or properties, no collision layer property or class), but its collision is drawn as objects ({} solid shapes in layers {}), so its tile layers are decoration; list the tile layers that collide in collision_layers in the level's settings (see docs/LEVELS.md, \"What collides\")",
                d.count,
                d.layers.iter().map(|l| format!("{l:?}")).collect::<Vec<_>>().join(", ")
            ),
            || "map".into(),
        );
    }
}

/// Whether a tile layer holds at least one tile.
pub(super) fn holds_a_tile(tl: &::tiled::TileLayer<'_>) -> bool {
    match tl {
        ::tiled::TileLayer::Finite(fl) => {
            let (w, h) = (fl.width() as i32, fl.height() as i32);
            !super::common::short_data(fl)
                && (0..h).any(|y| (0..w).any(|x| fl.get_tile_data(x, y).is_some()))
        }
        ::tiled::TileLayer::Infinite(il) => il.chunks().any(|(_, c)| {
            let (w, h) = (
                ::tiled::ChunkData::WIDTH as i32,
                ::tiled::ChunkData::HEIGHT as i32,
            );
            (0..h).any(|y| (0..w).any(|x| c.get_tile_data(x, y).is_some()))
        }),
    }
}
