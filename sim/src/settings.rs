//! The knob settings `ledge-sim tradeoff` measures: the default
//! configuration, each knob moved on its own from there, and the presets.
//!
//! A full cartesian product of the knobs would be thousands of rows; one
//! knob at a time shows each knob's own effect, and the presets show the
//! combinations worth using.

use ledge_shared::game::{GameConfig, PlayerShape};
use ledge_shared::world::{BroadPhaseKind, Pipeline, SimConfig, SweepMode};

/// One measured configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    /// Unique row name (`substeps=2`, `preset:fast`...).
    pub name: String,
    /// The knob this row moves (`baseline`, `substeps`, `preset`...): rows
    /// of one knob share a colour in the plot.
    pub knob: &'static str,
    /// What the scenes run with (the player constants only matter to the
    /// scenes that run the platformer).
    pub config: GameConfig,
    /// The thin-wall shots are marked for swept collision
    /// ([`ledge_shared::world::World::set_swept`]): what a game does for its
    /// projectiles under the default [`SweepMode::Flagged`].
    pub mark_shots: bool,
}

impl Setting {
    fn new(name: impl Into<String>, knob: &'static str, sim: SimConfig) -> Self {
        Self {
            name: name.into(),
            knob,
            config: GameConfig {
                sim,
                ..GameConfig::default()
            },
            mark_shots: false,
        }
    }

    /// Whether this row is one of the presets.
    pub fn is_preset(&self) -> bool {
        self.knob == "preset"
    }
}

/// Every setting, in table order: `baseline` (the default configuration),
/// then each knob's other values, then the presets `fast`, `balanced` and
/// `exact`.
pub fn all() -> Vec<Setting> {
    let base = SimConfig::default();
    let mut v = vec![Setting::new("baseline", "baseline", base)];
    for n in [2, 4, 8] {
        v.push(Setting::new(
            format!("substeps={n}"),
            "substeps",
            SimConfig {
                substeps: n,
                ..base
            },
        ));
    }
    for n in [1, 2, 8, 16] {
        v.push(Setting::new(
            format!("iterations={n}"),
            "iterations",
            SimConfig {
                restitution_iterations: n,
                ..base
            },
        ));
    }
    v.push(Setting::new(
        "sweep=off",
        "sweep",
        SimConfig {
            sweep: SweepMode::Off,
            ..base
        },
    ));
    v.push(Setting {
        mark_shots: true,
        ..Setting::new("sweep=flagged+marked", "sweep", base)
    });
    v.push(Setting::new(
        "sweep=auto",
        "sweep",
        SimConfig {
            sweep: SweepMode::AUTO,
            ..base
        },
    ));
    v.push(Setting::new(
        "sweep=auto1px",
        "sweep",
        SimConfig {
            sweep: SweepMode::Auto { min_speed: 256 },
            ..base
        },
    ));
    v.push(Setting::new(
        "broad=brute",
        "broad_phase",
        SimConfig {
            broad_phase: BroadPhaseKind::BruteForce,
            ..base
        },
    ));
    for (name, strip_shift, level_shift) in [
        ("broad=strips32px", 13, 2),
        ("broad=strips128px", 15, 2),
        ("broad=strips64px/x8", 14, 3),
    ] {
        v.push(Setting::new(
            name,
            "broad_phase",
            SimConfig {
                broad_phase: BroadPhaseKind::Strips {
                    strip_shift,
                    level_shift,
                },
                ..base
            },
        ));
    }
    v.push(Setting::new(
        "pipeline=general",
        "pipeline",
        SimConfig {
            pipeline: Pipeline::General,
            ..base
        },
    ));
    v.push(Setting::new(
        "threads=2",
        "threads",
        SimConfig { threads: 2, ..base },
    ));
    let mut feet = Setting::new("player=box+feet+head", "player_shape", base);
    feet.config.player.shape = PlayerShape::BoxFeetHead;
    v.push(feet);
    v.push(Setting::new("preset:fast", "preset", SimConfig::fast()));
    v.push(Setting::new(
        "preset:balanced",
        "preset",
        SimConfig::balanced(),
    ));
    v.push(Setting::new("preset:exact", "preset", SimConfig::exact()));
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_configs_valid() {
        let all = all();
        for (i, s) in all.iter().enumerate() {
            assert!(s.config.sim.validate().is_ok(), "{}", s.name);
            assert!(all[..i].iter().all(|t| t.name != s.name), "{}", s.name);
        }
        assert_eq!(all.iter().filter(|s| s.is_preset()).count(), 3);
    }
}
