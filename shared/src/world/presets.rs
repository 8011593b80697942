//! Named [`SimConfig`] presets: `fast`, `balanced` (the default) and
//! `exact`. Their measured cost and accuracy are in `docs/TRADEOFFS.md`
//! (`ledge-sim tradeoff`).

use super::config::{SimConfig, SweepMode};

impl SimConfig {
    /// The cheapest configuration that still plays well: one substep and two
    /// restitution passes. Fine while bodies move less than their half size
    /// per tick and stacks stay two or three boxes deep.
    pub fn fast() -> Self {
        Self {
            substeps: 1,
            restitution_iterations: 2,
            ..Self::default()
        }
    }

    /// The default configuration ([`SimConfig::default`]): one substep and
    /// four restitution passes.
    pub fn balanced() -> Self {
        Self::default()
    }

    /// Accuracy first: four substeps, sixteen restitution passes and every
    /// fast body swept ([`SweepMode::AUTO`]), for fast projectiles and deep
    /// stacks.
    pub fn exact() -> Self {
        Self {
            substeps: 4,
            restitution_iterations: 16,
            sweep: SweepMode::AUTO,
            ..Self::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_and_balanced_is_the_default() {
        for c in [SimConfig::fast(), SimConfig::balanced(), SimConfig::exact()] {
            assert!(c.validate().is_ok(), "{c:?}");
        }
        assert_eq!(SimConfig::balanced(), SimConfig::default());
    }
}
