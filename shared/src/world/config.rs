//! The simulation's speed/accuracy knobs.

use serde::{Deserialize, Serialize};

use super::BuildError;

/// Most substeps or restitution passes a configuration may ask for.
pub const MAX_ROUNDS: u32 = 64;

/// How hard the simulation works per tick. Both knobs trade cost for
/// accuracy; the defaults suit the warm-up room (speeds well under a body's
/// half size per tick).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct SimConfig {
    /// Move/detect/restitute rounds per tick, `1..=MAX_ROUNDS`. Each substep
    /// moves every body by its share of its current velocity: substep `k` of
    /// `n` moves `floor(v (k+1) / n) - floor(v k / n)`, so the shares of an
    /// unchanged velocity sum to it exactly. More substeps: less tunnelling
    /// and shallower overlaps, proportionally more detection.
    pub substeps: u32,
    /// Restitution passes per substep, `1..=MAX_ROUNDS`. After each pass that
    /// moved something, contacts are detected again; a dynamic body still
    /// overlapping a solid after the last pass is reported squished. More
    /// passes: fewer false squishes in piles, more detection.
    pub restitution_iterations: u32,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            substeps: 1,
            restitution_iterations: 4,
        }
    }
}

impl SimConfig {
    /// Checks both knobs are in range.
    pub fn validate(&self) -> Result<(), BuildError> {
        for (what, v) in [
            ("substeps", self.substeps),
            ("restitution_iterations", self.restitution_iterations),
        ] {
            if !(1..=MAX_ROUNDS).contains(&v) {
                return Err(BuildError::Config {
                    what,
                    value: v as i64,
                });
            }
        }
        Ok(())
    }
}
