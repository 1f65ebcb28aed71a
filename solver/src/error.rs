//! Errors of the solvers.

#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SolveError {
    #[error("invalid {option}: {reason}")]
    InvalidOption {
        option: &'static str,
        reason: &'static str,
    },
    #[error("the mesh has {meshes} surfaces but the scene has {surfaces} (this is a bug)")]
    MeshMismatch { surfaces: usize, meshes: usize },
    #[error(
        "the radiosity system is singular (a closed scene with reflectance 1 has no steady state)"
    )]
    Singular,
    #[error("interrupted before a solution existed")]
    Interrupted,
}
