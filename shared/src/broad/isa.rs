//! Which compiled versions of the broad phase's hot loops run
//! ([`super::BroadPhaseConfig::isa`]; the module docs, "Compiled twice").

/// A choice of instruction-set versions for the broad phase's hot loops
/// ([`super::BroadPhaseConfig::isa`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Isa {
    /// The best version the CPU has, picked at run time: x86-64-v3 (AVX2,
    /// BMI1/2, ...) where available, else the baseline. The default.
    #[default]
    Best,
    /// Always the x86-64 baseline version, even on a CPU with AVX2: what a
    /// CPU without it runs, for tests on any machine and for benchmarks.
    Baseline,
}
