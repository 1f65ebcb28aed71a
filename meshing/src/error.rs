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
        "an element budget of {max_elements} triangles is too small: the scene's polygons{} need at least \
         {needed} triangles",
        if *.discontinuities { ", with their discontinuities as edges," } else { "" }
    )]
    BudgetTooSmall {
        max_elements: usize,
        needed: usize,
        /// Whether `needed` counts the discontinuity segments inserted as edges (known only
        /// after they are found), or the polygons alone.
        discontinuities: bool,
    },
    #[error("mesh of surface {surface} is broken: {what} (this is a bug)")]
    SanityCheck { surface: SurfaceId, what: String },
}
