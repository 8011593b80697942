//! What a layer's name says about it, for the layers whose file says
//! nothing else (see `docs/LEVELS.md`, "Layer names"):
//!
//! * [`decoration_word`]: a layer named for cameras, backgrounds,
//!   decoration or parallax (`Camera zones`, `BG`, `castledeco`) is never
//!   collision by its name alone;
//! * [`layer_thing`]: an object layer named for a kind of thing (`Coins`,
//!   `Goombas`, `Spikes`, `Pipes`) makes its objects without a ledge name
//!   that thing ([`LAYER_THINGS`]).
//!
//! Names are read ASCII case-insensitively with `-` and spaces as `_`.

use std::collections::BTreeMap;

use crate::entities::{is_entity_name, PlacedEntity};
use crate::mapping::normalize;
use crate::options::LoadOptions;

/// Parts of a layer's name (anywhere in it) that make it decoration.
pub(crate) const DECORATION_PARTS: &[&str] = &[
    "camera",
    "background",
    "backdrop",
    "bg",
    "deco",
    "parallax",
    "foreground",
    "scenery",
    "shadow",
];

/// Whole words of a layer's name that make it decoration.
const DECORATION_WORDS: &[&str] = &["fg", "sky", "art", "overlay"];

/// The part of `name` that makes it a decoration layer (`"camera"` for
/// `Camera_Zones`), or `None`.
pub(crate) fn decoration_word(name: &str) -> Option<&'static str> {
    let n = normalize(name);
    if let Some(p) = DECORATION_PARTS.iter().find(|p| n.contains(*p)) {
        return Some(p);
    }
    let found = words(&n).find_map(|w| DECORATION_WORDS.iter().find(|d| **d == w).copied());
    found
}

/// What an object layer's name makes its objects that have no ledge name of
/// their own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Thing {
    /// Static solid geometry (rectangles, ellipses, polygons).
    Solid,
    /// This ledge entity (a name of the entity table).
    Entity(&'static str),
    /// Not collision, not entities (cameras, triggers, decoration): skipped.
    Skip,
}

/// Layer name words and what they make of a layer's objects, in the order
/// they are tried (a name's first matching word decides).
pub(crate) const LAYER_THINGS: &[(&[&str], Thing)] = &[
    (
        &[
            "coin",
            "coins",
            "gem",
            "gems",
            "collectible",
            "collectibles",
            "collectable",
            "collectables",
            "pickup",
            "pickups",
        ],
        Thing::Entity("coin"),
    ),
    (
        &[
            "enemy", "enemies", "goomba", "goombas", "koopa", "koopas", "turtle", "turtles",
            "monster", "monsters", "walker", "walkers", "baddie", "baddies", "mob", "mobs",
        ],
        Thing::Entity("walker"),
    ),
    (
        &[
            "spike", "spikes", "hazard", "hazards", "lava", "trap", "traps", "acid", "death",
            "kill",
        ],
        Thing::Entity("hazard"),
    ),
    (&["checkpoint", "checkpoints"], Thing::Entity("checkpoint")),
    (
        &["goal", "goals", "exit", "exits", "finish", "flag", "flags"],
        Thing::Entity("goal"),
    ),
    (
        &[
            "spring",
            "springs",
            "springboard",
            "springboards",
            "trampoline",
            "trampolines",
        ],
        Thing::Entity("springboard"),
    ),
    (
        &[
            "ground",
            "grounds",
            "pipe",
            "pipes",
            "brick",
            "bricks",
            "wall",
            "walls",
            "block",
            "blocks",
            "solid",
            "solids",
            "collision",
            "collisions",
            "collider",
            "colliders",
            "terrain",
            "floor",
            "floors",
            "platform",
            "platforms",
            "obstacle",
            "obstacles",
        ],
        Thing::Solid,
    ),
    (
        &[
            "trigger", "triggers", "zone", "zones", "region", "regions", "area", "areas", "text",
            "label", "labels", "note", "notes", "comment", "comments",
        ],
        Thing::Skip,
    ),
];

/// What layer `name` makes of its objects without a ledge name, and the
/// word that said so: a decoration name ([`decoration_word`]) skips them,
/// else the name's first word found in [`LAYER_THINGS`] (trailing digits
/// dropped: `Enemies2`) decides.
pub(crate) fn layer_thing(name: &str) -> Option<(Thing, &'static str)> {
    if let Some(w) = decoration_word(name) {
        return Some((Thing::Skip, w));
    }
    let n = normalize(name);
    let found = words(&n).find_map(|w| {
        LAYER_THINGS
            .iter()
            .find_map(|(names, thing)| names.iter().find(|x| **x == w).map(|x| (*thing, *x)))
    });
    found
}

/// The words of a normalised name, trailing digits dropped (`coins_2`,
/// `Enemies1`).
fn words(n: &str) -> impl Iterator<Item = &str> {
    n.split('_')
        .map(|w| w.trim_end_matches(|c: char| c.is_ascii_digit()))
        .filter(|w| !w.is_empty())
}

/// `layers` without the collision layers named for decoration
/// ([`decoration_word`]) that the settings do not list (in
/// `collision_layers` or `decoration_layers`), each said in `warnings`.
/// `info` gives a layer's name and field when it is a collision layer (tile
/// or grid), `None` for the others (kept).
pub(crate) fn without_decoration<L>(
    file: &str,
    layers: Vec<L>,
    options: &LoadOptions,
    warnings: &mut Vec<String>,
    info: impl Fn(&L) -> Option<(&String, &String)>,
) -> Vec<L> {
    let mut kept = Vec::with_capacity(layers.len());
    for l in layers {
        let decor = info(&l).and_then(|(name, field)| {
            let listed = options.layer_collides(name).is_some();
            let word = decoration_word(name).filter(|_| !listed)?;
            Some(format!(
                "{file}: {field}: layer {name:?} is decoration by its name ({word:?}): it does not collide (list it in collision_layers in the level's settings to make it collide)"
            ))
        });
        match decor {
            Some(w) => warnings.push(w),
            None => kept.push(l),
        }
    }
    kept
}

/// Renames the entities whose name is no ledge entity (after the settings'
/// aliases) by their own name or their layer's ([`layer_thing`]): an OGMO
/// `Goomba` in layer `Enemies` becomes a walker, an entity in layer `Walls`
/// a block; the others stay as they are (skipped, said, by the entity
/// table). Says what it renamed, once per layer and name, in `warnings`.
pub(crate) fn rename_by_layer(
    file: &str,
    entities: &mut [PlacedEntity],
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) {
    // (layer, name) -> (first field, count, ledge name, why)
    let mut said: BTreeMap<(String, String), (String, usize, &'static str, String)> =
        BTreeMap::new();
    for e in entities.iter_mut() {
        if is_entity_name(options.entity_name(&e.name))
            || options.decoration_layers.contains(&e.layer)
        {
            continue;
        }
        let by_name = layer_thing(&e.name).map(|t| (t, format!("its name {:?}", e.name)));
        let by_layer = || layer_thing(&e.layer).map(|t| (t, format!("layer {:?}", e.layer)));
        let to = match by_name.or_else(by_layer) {
            Some(((Thing::Entity(n), _), why)) => (n, why),
            Some(((Thing::Solid, _), why)) => ("block", why),
            _ => continue,
        };
        let entry = said
            .entry((e.layer.clone(), e.name.clone()))
            .or_insert_with(|| (e.field.clone(), 0, to.0, to.1));
        entry.1 += 1;
        e.name = to.0.into();
    }
    for ((layer, name), (field, n, to, why)) in said {
        warnings.push(format!(
            "{file}: {field}: {n} entities {name:?} (not a ledge entity) are read as {to:?} by {why}; choose in the level's settings: [entities] {name:?} = \"coin\" (any entity name), or decoration_layers = [{layer:?}]"
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decoration_names() {
        for n in [
            "Camera",
            "camera_zones",
            "CameraZones",
            "Background",
            "BG",
            "tiles_bg",
            "castledeco",
            "Decorations",
            "Parallax 2",
            "Sky",
        ] {
            assert!(decoration_word(n).is_some(), "{n}");
        }
        for n in ["Ground", "Tiles", "Walls level 2", "Solids", "Coins"] {
            assert_eq!(decoration_word(n), None, "{n}");
        }
    }

    #[test]
    fn things_by_layer_name() {
        let t = |n| layer_thing(n).map(|x| x.0);
        assert_eq!(t("Coins"), Some(Thing::Entity("coin")));
        assert_eq!(t("Goombas"), Some(Thing::Entity("walker")));
        assert_eq!(t("Turtles"), Some(Thing::Entity("walker")));
        assert_eq!(t("Enemies2"), Some(Thing::Entity("walker")));
        assert_eq!(t("Spikes"), Some(Thing::Entity("hazard")));
        assert_eq!(t("Pipes"), Some(Thing::Solid));
        assert_eq!(t("Bricks"), Some(Thing::Solid));
        assert_eq!(t("Ground"), Some(Thing::Solid));
        assert_eq!(t("Camera"), Some(Thing::Skip));
        assert_eq!(t("Background"), Some(Thing::Skip));
        assert_eq!(t("Objects"), None);
        assert_eq!(t("game"), None);
    }
}
