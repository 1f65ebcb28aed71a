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

pub mod budget;
pub mod constrained;
pub mod error;
pub mod fuzzing;
pub mod grading;
pub mod locate;
pub mod mesh;
pub mod planar;
pub mod progress;
pub mod scene_mesh;
pub mod uniform;
pub mod wedges;

pub use budget::{ElementBudget, FIT_TRIANGLES_PER_SURFACE, polygon_minimum};
pub use error::MeshError;
pub use mesh::{MeshQuality, SurfaceMesh, quality_of};
pub use scene_mesh::{
    SceneMesh, mesh_scene_discontinuity, mesh_scene_discontinuity_on, mesh_scene_uniform,
    share_alone, spread_by_area,
};
pub use uniform::{MeshCoordinates, mesh_surface_uniform};
pub mod discontinuity;
