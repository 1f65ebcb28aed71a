//! Errors of the solvers.

/// Why a solve failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SolveError {
    /// An option is out of its range ([`crate::SolverOptions::validate`]).
    #[error("invalid {option}: {reason}")]
    InvalidOption {
        /// The option.
        option: crate::OptionId,
        /// Its allowed range.
        reason: &'static str,
    },
    /// The mesh does not belong to the scene: a caller's bug.
    #[error("the mesh has {meshes} surfaces but the scene has {surfaces} (this is a bug)")]
    MeshMismatch {
        /// The scene's surfaces.
        surfaces: usize,
        /// The mesh's surfaces.
        meshes: usize,
    },
    /// The linear system has no unique solution.
    #[error(
        "the radiosity system is singular (a closed scene with reflectance 1 has no steady state)"
    )]
    Singular,
    /// The interrupt was set before there was a solution to keep.
    #[error("interrupted before a solution existed")]
    Interrupted,
}
