//! Errors of meshing.

use penumbra_scenes::SurfaceId;

#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    #[error("surface {surface} (\"{name}\") has no usable area to mesh")]
    Degenerate { surface: SurfaceId, name: String },
    #[error("triangulating surface {surface} failed: {message}")]
    Triangulation { surface: SurfaceId, message: String },
    #[error(
        "--max-elements {max_elements} is too small: the scene's polygons need at least {needed} triangles; \
         use --max-elements {needed} or more"
    )]
    BudgetTooSmall { max_elements: usize, needed: usize },
    #[error("mesh of surface {surface} is broken: {what} (this is a bug)")]
    SanityCheck { surface: SurfaceId, what: String },
}
