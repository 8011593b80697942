//! The simulation's speed/accuracy knobs.
//!
//! `substeps` and `restitution_iterations` change results (and are part of
//! [`super::World::state_hash`]). `sweep` changes results only for bodies
//! it sweeps (a scene with none gives the same states whatever its value,
//! `tests/simulation/world_sweep.rs`), so it is not hashed either: its effect is in
//! the bodies' states. The other three only change how the work is done:
//! every combination of `broad_phase`, `pipeline` and `threads` gives the
//! same contacts in the same order and bit-identical states
//! (`tests/simulation/world_threads.rs`), so they are not hashed.

use serde::{Deserialize, Serialize};

use super::error::BuildError;
use crate::fixed::{px, MAX_SPEED};

/// Most substeps or restitution passes a configuration may ask for.
pub const MAX_ROUNDS: u32 = 64;

/// Most threads [`SimConfig::threads`] may ask for.
pub const MAX_THREADS: u32 = 256;

/// How detection finds the pairs of colliders to test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum BroadPhaseKind {
    /// Every pair of colliders, one monomorphised loop per pair of shape
    /// kinds with a bounding-box reject: quadratic, the reference for tests
    /// and comparisons (and what the world did before the broad phase).
    BruteForce,
    /// The levelled-strip sort-and-sweep of [`crate::broad`]: static
    /// colliders indexed once, the others updated every detection.
    Strips {
        /// `log2` of the finest strip height in units, `4..=31` (14 is
        /// 64 px).
        strip_shift: u32,
        /// `log2` of the height ratio between consecutive levels, `1..=28`
        /// (2 is x4).
        level_shift: u32,
    },
}

impl BroadPhaseKind {
    /// The default: strips of 64 px growing x4 per level (the best of the
    /// settings measured on the world benchmarks, `docs/PERFORMANCE.md`,
    /// "World pipeline: general vs specialised").
    pub const DEFAULT: BroadPhaseKind = BroadPhaseKind::Strips {
        strip_shift: 14,
        level_shift: 2,
    };

    /// The broad phase's own configuration for this kind (brute force keeps
    /// an unused broad phase with the defaults).
    pub fn broad_config(self) -> crate::broad::BroadPhaseConfig {
        match self {
            BroadPhaseKind::Strips {
                strip_shift,
                level_shift,
            } => crate::broad::BroadPhaseConfig {
                strip_shift,
                level_shift,
                ..crate::broad::BroadPhaseConfig::default()
            },
            BroadPhaseKind::BruteForce => crate::broad::BroadPhaseConfig::default(),
        }
    }
}

impl Default for BroadPhaseKind {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Which bodies the move phase sweeps (time of impact against static and
/// kinematic solids and the tilemap, instead of a plain move that a fast
/// body can tunnel through). See "Swept collision in the world" in
/// `docs/ARCHITECTURE.md`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SweepMode {
    /// No body is swept, even one marked with [`super::World::set_swept`]:
    /// every body moves by its velocity and the discrete contact pass alone
    /// separates overlaps (a body faster than about its half size per
    /// substep may tunnel through a thin wall).
    Off,
    /// Only bodies marked with [`super::World::set_swept`] are swept (the
    /// default): projectiles opt in, everything else moves as without
    /// sweeps, and a scene with no marked body runs no sweep code at all.
    #[default]
    Flagged,
    /// Marked bodies, and also every enabled dynamic body whose displacement
    /// in a substep exceeds `min_speed` units on some axis (with the
    /// response [`super::SweepResponse::Slide`] unless marked otherwise).
    Auto {
        /// Per-substep displacement (units, largest axis) above which an
        /// unmarked dynamic body is swept: [`SweepMode::AUTO_MIN_SPEED`] in
        /// [`SweepMode::AUTO`].
        min_speed: u32,
    },
}

impl SweepMode {
    /// The default threshold of [`SweepMode::Auto`]: 4 px (1,024 units) per
    /// substep. A box of half width `h` moving `d` into a wall of thickness
    /// `w` from touching it is pushed back out (not through) while
    /// `d <= h + w / 2`; the game's smallest moving boxes have `h >= 4 px`,
    /// so below this speed the discrete pass cannot lose them through even a
    /// 1 px wall, and above it the sweep takes over. (The player's run
    /// speed is 2.5 px and its fall speed 6 px per tick.)
    pub const AUTO_MIN_SPEED: u32 = px(4) as u32;

    /// [`SweepMode::Auto`] with [`SweepMode::AUTO_MIN_SPEED`].
    pub const AUTO: SweepMode = SweepMode::Auto {
        min_speed: Self::AUTO_MIN_SPEED,
    };
}

/// Which passes a tick runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Pipeline {
    /// Only the passes the scene needs, chosen from its
    /// [`super::SceneFeatures`] whenever colliders, bodies or the tilemap
    /// change: the AABB fast path when every collider is a box, no rider
    /// search without riders and kinematic boxes, no tile queries without a
    /// tilemap, no trigger logging without triggers (the default).
    #[default]
    Specialised,
    /// Every pass for every scene, through the general narrow-phase
    /// dispatch: the comparison point for the specialised pipeline.
    General,
}

/// How hard the simulation works per tick, and how. `substeps`,
/// `restitution_iterations` and `sweep` trade cost for accuracy; the
/// defaults suit the warm-up room (speeds well under a body's half size per
/// tick), and fast movers opt in to sweeps ([`SweepMode::Flagged`]).
/// `broad_phase`, `pipeline` and `threads` never change a result, so a
/// client predicting with a server's configuration (sent in the welcome) may
/// replace them with its own.
///
/// Deserialising from a self-describing format (JSON, ...) fills missing
/// fields with their defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(default)]
pub struct SimConfig {
    /// Move/detect/restitute rounds per tick, `1..=MAX_ROUNDS`. Each substep
    /// moves every body by its share of its current velocity: substep `k` of
    /// `n` moves `floor(v (k+1) / n) - floor(v k / n)`, so the shares of an
    /// unchanged velocity sum to it exactly. More substeps: less tunnelling
    /// and shallower overlaps, proportionally more detection.
    pub substeps: u32,
    /// Restitution passes per substep, `1..=MAX_ROUNDS`. After each pass that
    /// moved something, contacts are detected again; a dynamic body still
    /// overlapping a solid after the last pass is reported squished. A pass
    /// that only pushes bodies away from pinned or immovable ends, each for
    /// the first time this substep (support propagating up a stack), is not
    /// counted. More passes: fewer false
    /// squishes in piles, more detection.
    pub restitution_iterations: u32,
    /// How pairs are found (default: [`BroadPhaseKind::DEFAULT`]).
    pub broad_phase: BroadPhaseKind,
    /// Which passes run (default: [`Pipeline::Specialised`]).
    pub pipeline: Pipeline,
    /// Threads for detection (the broad-phase update, the pair search and
    /// the narrow phase), `0..=MAX_THREADS`:
    ///
    /// * `1` (default): this thread only; rayon is never touched.
    /// * `0`: rayon's *current* pool: the pool attached with
    ///   [`super::World::set_thread_pool`] if any, else the pool `step` is
    ///   called from (inside `ThreadPool::install`), else rayon's global
    ///   pool.
    /// * `n >= 2`: the attached pool if any, else a pool of `n` threads the
    ///   world builds at its first step (shared by its clones).
    ///
    /// Only full detections through the broad phase are split (update, pair
    /// search and narrow phase); brute force, restitution and incremental
    /// re-detections run on the stepping thread, and so does everything in
    /// scenes with fewer than 2,048 moving colliders (too little work to
    /// share).
    pub threads: u32,
    /// Which bodies the move phase sweeps (default:
    /// [`SweepMode::Flagged`], only bodies marked with
    /// [`super::World::set_swept`]). A swept body moves to its first time of
    /// impact against solid static and kinematic colliders it can collide
    /// with and the tilemap, then stops, slides or reflects
    /// ([`super::SweepResponse`]) and reports one [`super::Event::SweptHit`]:
    /// nothing moving up to [`crate::fixed::MAX_SPEED`] per tick passes
    /// through a 1 px wall. Costs nothing in a scene without swept bodies.
    pub sweep: SweepMode,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            substeps: 1,
            restitution_iterations: 4,
            broad_phase: BroadPhaseKind::DEFAULT,
            pipeline: Pipeline::Specialised,
            threads: 1,
            sweep: SweepMode::Flagged,
        }
    }
}

impl SimConfig {
    /// Checks every knob is in range.
    pub fn validate(&self) -> Result<(), BuildError> {
        let bad = |what, v: u32| BuildError::Config {
            what,
            value: v as i64,
        };
        for (what, v) in [
            ("substeps", self.substeps),
            ("restitution_iterations", self.restitution_iterations),
        ] {
            if !(1..=MAX_ROUNDS).contains(&v) {
                return Err(bad(what, v));
            }
        }
        if let SweepMode::Auto { min_speed } = self.sweep {
            if min_speed > MAX_SPEED as u32 {
                return Err(BuildError::Config {
                    what: "sweep.min_speed",
                    value: min_speed as i64,
                });
            }
        }
        if self.threads > MAX_THREADS {
            return Err(bad("threads", self.threads));
        }
        if let BroadPhaseKind::Strips {
            strip_shift,
            level_shift,
        } = self.broad_phase
        {
            if !(4..=31).contains(&strip_shift) {
                return Err(bad("broad_phase.strip_shift", strip_shift));
            }
            if !(1..=28).contains(&level_shift) {
                return Err(bad("broad_phase.level_shift", level_shift));
            }
        }
        Ok(())
    }
}
