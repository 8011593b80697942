//! What the Tiled importer ([`super`]) and the Tiled art
//! (`crate::art::tiled`) read off a loaded map alike: the name an object
//! goes by, whether the game draws it itself, and whether a layer's data is
//! short.
//!
//! Kept apart from the importer so that the art depends only on these, not
//! on the importer that calls it: the importer sits on top of the art.

use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::collision::Prop;
use crate::entities::is_entity_name;
use crate::LoadOptions;
use ::tiled::PropertyValue;

/// The name an object goes by: its class (`type` before Tiled 1.9), else
/// its name, also when the class is no ledge entity (after the settings'
/// aliases) and the name is.
pub(crate) fn object_name<'o>(options: &LoadOptions, o: &'o ::tiled::ObjectData) -> &'o str {
    let known = |n: &str| is_entity_name(options.entity_name(n));
    if o.user_type.trim().is_empty() || (!known(&o.user_type) && known(&o.name)) {
        &o.name
    } else {
        &o.user_type
    }
}

/// Whether an object stands for an entity that moves or vanishes (a coin,
/// a walker, a moving platform), which the game draws itself: the level's
/// art leaves its picture out, or a collected coin would stay on screen.
/// An object without a ledge name counts by its own name's words or its
/// layer's (`layer`, `collision::names`), unless its own properties say
/// what it is, as the importer reads it.
pub(crate) fn is_drawn_entity(options: &LoadOptions, layer: &str, o: &::tiled::ObjectData) -> bool {
    use crate::collision::names::{layer_thing, Thing};
    let name = options.entity_name(object_name(options, o));
    if is_entity_name(name) {
        return crate::entities::moves_or_vanishes(name);
    }
    let marked = !matches!(
        crate::collision::tile_of_props(props(&o.properties), ""),
        Ok(None)
    );
    if marked || options.decoration_layers.iter().any(|n| n == layer) {
        return false;
    }
    if let Some(alias) = options
        .entity_aliases
        .get(&crate::mapping::normalize(layer))
    {
        return crate::entities::moves_or_vanishes(alias);
    }
    let thing = (!name.trim().is_empty())
        .then(|| layer_thing(name))
        .flatten()
        .or_else(|| layer_thing(layer));
    matches!(thing, Some((Thing::Entity(e), _)) if crate::entities::moves_or_vanishes(e))
}

/// Whether a finite layer has fewer cells of data than its size: the tiled
/// crate does not check, and indexing past short data panics. The pre-scan
/// ([`crate::limits`]) refuses such data; this probe of the last cell is
/// the second line, for every reader of a layer's cells.
pub(crate) fn short_data(fl: &::tiled::FiniteTileLayer<'_>) -> bool {
    let (w, h) = (fl.width(), fl.height());
    w > 0
        && h > 0
        && catch_unwind(AssertUnwindSafe(|| {
            fl.get_tile_data(w as i32 - 1, h as i32 - 1).is_some()
        }))
        .is_err()
}

/// A property as `crate::collision` reads it.
pub(super) fn prop(v: &PropertyValue) -> Prop<'_> {
    match v {
        PropertyValue::BoolValue(b) => Prop::Bool(*b),
        PropertyValue::StringValue(s) => Prop::Text(s),
        _ => Prop::Other,
    }
}

/// A Tiled property list as the collision rules read it.
pub(super) fn props(p: &::tiled::Properties) -> impl Iterator<Item = (&str, Prop<'_>)> {
    // Sorted, so the outcome does not depend on the map's hash order.
    let mut v: Vec<_> = p.iter().map(|(k, v)| (k.as_str(), prop(v))).collect();
    v.sort_by(|a, b| a.0.cmp(b.0));
    v.into_iter()
}
