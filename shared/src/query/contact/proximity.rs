//! How two placed shapes relate ([`Proximity`]): the result every pair test
//! returns. In a file of its own, below the pair files and the shared
//! kernels (`sat`, `circle_convex`) that build it, so that they need nothing
//! from the module that dispatches to them.

use glam::IVec2;

/// How two placed shapes relate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Proximity {
    /// A positive gap separates them.
    Apart,
    /// They touch with no overlap of interiors (zero gap on some axis).
    Touching,
    /// Interiors overlap; moving the first shape by the MTV separates them.
    Overlapping(IVec2),
}

impl Proximity {
    /// The same relation seen from the other shape (MTV negated).
    #[inline]
    pub fn reversed(self) -> Self {
        match self {
            Proximity::Overlapping(m) => Proximity::Overlapping(-m),
            p => p,
        }
    }

    /// The MTV when overlapping.
    #[inline]
    pub fn mtv(self) -> Option<IVec2> {
        match self {
            Proximity::Overlapping(m) => Some(m),
            _ => None,
        }
    }
}
