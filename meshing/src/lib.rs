//! # penumbra-meshing
//!
//! Per-surface meshes for radiosity: each surface's polygon is triangulated in its own 2D
//! coordinates with a constrained Delaunay triangulation (`spade`) and refined to a target size.
//! Values live at mesh vertices and are interpolated linearly over the triangles.
//!
//! ```
//! use penumbra_meshing::mesh_scene_uniform;
//! let scene = penumbra_scenes::builtin::textbook();
//! let mesh = mesh_scene_uniform(&scene, 500).unwrap();
//! assert!(mesh.triangle_count() <= 500);
//! mesh.sanity_check().unwrap();
//! ```

mod budget;
mod constrained;
pub mod discontinuity;
mod error;
#[doc(hidden)]
pub mod fuzzing;
mod grading;
mod locate;
mod mesh;
mod progress;
mod scene_mesh;
mod uniform;
mod wedges;

pub use budget::{ElementBudget, FIT_TRIANGLES_PER_SURFACE, polygon_minimum};
pub use constrained::{ConstrainedSurface, Constraint, RefinableSurface, SPLIT_MIN_ANGLE_DEG};
pub use error::MeshError;
pub use grading::DEFAULT_PENUMBRA_DENSITY;
pub use locate::{TriangleLocator, transfer_density};
pub use mesh::{FORCING_WEDGE_DEG, MeshQuality, SurfaceMesh, quality_of};
pub use progress::{Interrupt, NoProgress, Progress};
pub use scene_mesh::{
    SceneMesh, mesh_scene_discontinuity, mesh_scene_discontinuity_on, mesh_scene_uniform,
};
pub use uniform::mesh_surface_uniform;
