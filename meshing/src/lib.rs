//! # penumbra-meshing
//!
//! Per-surface meshes for radiosity. Each surface's polygon is triangulated in its own 2D
//! coordinates with a constrained Delaunay triangulation (`spade`) and refined for quality
//! (Ruppert's refinement) to a share of the scene's element budget. Values live at mesh vertices
//! and are interpolated linearly over the triangles.
//!
//! Discontinuity meshing (Heckbert 1992; Lischinski, Tampieri & Greenberg 1992) first finds where
//! the direct light from each emitter changes its analytic form on each receiver — EV, VE and
//! EEE visual events and contact lines — and makes those segments edges of the mesh, so that
//! linear interpolation does not smear shadows across them. Where the light jumps (a blocker
//! standing on the receiver), the two sides get separate vertices.
//!
//! ## Main types
//!
//! - [`SceneMesh`] holds one [`SurfaceMesh`] per surface: vertices in the surface's mesh
//!   coordinates and in 3D, counter-clockwise triangles, and the constraint segments.
//!   [`SurfaceMesh::sanity_check`] checks its invariants; [`MeshQuality`] measures it.
//! - [`mesh_scene_uniform`] meshes every surface without constraints, the budget spread by area;
//!   [`mesh_surface_uniform`] meshes one surface.
//! - [`discontinuity::find_discontinuities`] finds the segments, and
//!   [`mesh_scene_discontinuity`] meshes the scene with them as constraint edges, with smaller
//!   triangles in partial shadow ([`DEFAULT_PENUMBRA_DENSITY`]).
//! - [`ElementBudget`] says how many triangles the whole scene may have.
//! - [`ConstrainedSurface`] and [`RefinableSurface`] are one surface's constrained
//!   triangulation before and after refinement; [`SceneMesh::split_triangles`] refines further
//!   where an error estimate asks for it.
//! - [`TriangleLocator`] finds the triangle holding a point, and [`transfer_density`] carries
//!   per-triangle values from one mesh of a surface to another.
//! - [`Progress`] and [`Interrupt`] report on and stop long work; [`MeshError`] says why
//!   meshing failed.
//!
//! ## Example
//!
//! Find the discontinuities of the textbook scene (a square light over a square blocker over a
//! floor) and mesh it along them:
//!
//! ```
//! use penumbra_meshing::discontinuity::{Boundary, DiscontinuityOptions, find_discontinuities};
//! use penumbra_meshing::{DEFAULT_PENUMBRA_DENSITY, mesh_scene_discontinuity, mesh_scene_uniform};
//! use penumbra_scenes::{Visibility, builtin};
//!
//! let scene = builtin::textbook();
//! let visibility = Visibility::build(&scene);
//! let found = find_discontinuities(&scene, &visibility, &DiscontinuityOptions::default());
//!
//! // The blocker's shadow on the floor has an umbra and the outer edge of a penumbra, and every
//! // segment lies on the floor (z = 0).
//! let floor = scene.surface_id("floor").unwrap();
//! let on_floor = &found.segments[floor];
//! assert!(on_floor.iter().any(|s| s.boundary == Boundary::Umbra));
//! assert!(on_floor.iter().any(|s| s.boundary == Boundary::Penumbra));
//! assert!(on_floor.iter().all(|s| s.from.z == 0.0 && s.to.z == 0.0));
//!
//! let mesh =
//!     mesh_scene_discontinuity(&scene, &visibility, found, 2000, DEFAULT_PENUMBRA_DENSITY)
//!         .unwrap();
//! assert!(mesh.segment_count() > 0);
//! assert!(mesh.triangle_count() > 0 && mesh.triangle_count() <= 2000);
//! // Counter-clockwise triangles covering each polygon, every segment a chain of mesh edges.
//! mesh.sanity_check().unwrap();
//! for (m, s) in mesh.surfaces.iter().zip(&scene.surfaces) {
//!     assert!((m.area() - s.area()).abs() <= 1e-9 * s.area());
//! }
//!
//! // Without the segments: a uniform mesh of the same budget.
//! let uniform = mesh_scene_uniform(&scene, 2000).unwrap();
//! assert!(uniform.triangle_count() <= 2000 && uniform.segment_count() == 0);
//! ```

#![warn(missing_docs)]

mod bisection;
mod budget;
mod cdt;
mod constrained;
pub mod discontinuity;
mod error;
#[doc(hidden)]
pub mod fuzzing;
mod grading;
mod locate;
mod mesh;
mod mesh_coordinates;
mod progress;
mod quality;
mod scene_mesh;
mod tolerances;
mod uniform;
mod wedges;

pub use bisection::{BisectionMesh, SHORTEST_SPLIT_EDGE, Split, Terminal};
pub use budget::{ElementBudget, FIT_TRIANGLES_PER_SURFACE, polygon_minimum};
pub use constrained::{ConstrainedSurface, Constraint, RefinableSurface};
pub use error::MeshError;
pub use grading::DEFAULT_PENUMBRA_DENSITY;
pub use locate::{TriangleLocator, transfer_density};
pub use mesh::SurfaceMesh;
pub use progress::{Interrupt, NoProgress, Progress};
pub use quality::{MeshQuality, quality_of};
pub use scene_mesh::{
    DiscontinuityMeshing, SceneMesh, mesh_scene_discontinuity, mesh_scene_discontinuity_on,
    mesh_scene_uniform, mesh_scene_uniform_until,
};
pub use tolerances::{
    CONSTRAINED_MIN_ANGLE_DEG, FORCING_WEDGE_DEG, MAX_MIN_ANGLE_DEG, SPLIT_MIN_ANGLE_DEG,
};
pub use uniform::mesh_surface_uniform;
