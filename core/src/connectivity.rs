//! Connectivity of discrete rays and surfaces.

/// Which adjacency consecutive voxels of a discrete ray have.
///
/// Two voxels are *6-adjacent* when they share a face and *26-adjacent* when
/// they share a face, an edge or a corner. The names follow Yagel, Cohen &
/// Kaufman 1992, "Efficient Discrete Ray Traversal".
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Connectivity {
    /// 6-connected rays: never miss a voxel the continuous ray passes through;
    /// `n6 = |Δx| + |Δy| + |Δz|` steps between lattice endpoints.
    Six,
    /// 26-connected rays: one unit step along the driving axis per voxel,
    /// `n26 = max(|Δx|, |Δy|, |Δz|)` steps; need 26-tunnel-free surfaces and
    /// may miss a voxel at a silhouette.
    TwentySix,
    /// 26-steps in empty space, 6-steps where the proximity flag is set: the
    /// speed of 26-rays with the hits of 6-rays.
    #[default]
    Adaptive,
}

impl Connectivity {
    /// All three modes, for tests and benchmarks.
    pub const ALL: [Self; 3] = [Self::Six, Self::TwentySix, Self::Adaptive];

    /// The short name used on command lines: `six`, `twenty-six`, `adaptive`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Six => "six",
            Self::TwentySix => "twenty-six",
            Self::Adaptive => "adaptive",
        }
    }
}
