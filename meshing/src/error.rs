//! Errors of meshing.

use penumbra_scenes::SurfaceId;

/// Why a scene or a surface could not be meshed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// The surface's polygon has no area or no usable edge (validation refuses such polygons).
    #[error("surface {surface} (\"{name}\") has no usable area to mesh")]
    Degenerate {
        /// The surface.
        surface: SurfaceId,
        /// Its name.
        name: String,
    },
    /// The constrained triangulation failed (spade refused a point or a constraint).
    #[error("triangulating surface {surface} failed: {message}")]
    Triangulation {
        /// The surface.
        surface: SurfaceId,
        /// What failed.
        message: String,
    },
    #[error(
        "an element budget of {max_elements} triangles is too small: the scene's polygons{} need at least \
         {needed} triangles",
        if *.discontinuities { ", with their discontinuities as edges," } else { "" }
    )]
    /// The element budget is below the least mesh of the scene's polygons.
    BudgetTooSmall {
        /// The budget asked for.
        max_elements: usize,
        /// The triangles the least mesh has.
        needed: usize,
        /// Whether `needed` counts the discontinuity segments inserted as edges (known only
        /// after they are found), or the polygons alone.
        discontinuities: bool,
    },
    /// A mesh failed its invariant check ([`crate::SurfaceMesh::sanity_check`]): a bug of
    /// this crate.
    #[error("mesh of surface {surface} is broken: {what} (this is a bug)")]
    SanityCheck {
        /// The surface.
        surface: SurfaceId,
        /// The broken invariant.
        what: String,
    },
    /// The interrupt ([`crate::Interrupt`]) was set: meshing stopped, and its mesh was let go.
    #[error("meshing was interrupted")]
    Interrupted,
}
