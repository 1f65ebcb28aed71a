//! # penumbra-solver
//!
//! Radiosity on meshed scenes. Radiosity B (W/m² per channel) lives at mesh vertices and obeys
//! B = E + ρ H, with E a surface's own exitance, ρ its reflectance and H the irradiance arriving
//! from every other surface.
//!
//! - Direct light is exact, without sampling: [`DirectLight`] finds the part of each emitter a
//!   point sees by backprojection through the occluders, and [`form_factor`] integrates it with
//!   Lambert's contour formula from a [`ReceivingPoint`].
//! - Indirect light comes from one of several solvers, chosen by [`SolverMethod`] and tuned by
//!   [`SolverOptions`]: progressive refinement with vertex receivers ([`solve_progressive`],
//!   Cohen, Chen, Wallace & Greenberg 1988; [`ProgressiveSolver`] step by step), Jacobi,
//!   Gauss–Seidel or a dense direct solve of the patch system ([`solve_gathering`],
//!   [`PatchSystem`]), hierarchical radiosity with clustering ([`solve_hierarchical`], Hanrahan,
//!   Salzman & Aupperle 1991), or one exact bounce ([`solve_direct_on`]). Each gives a
//!   [`Solution`]: radiosity and irradiance at every vertex and [`SolveStats`], whose energy
//!   account (emitted = absorbed + unshot + escaped) closes.
//! - [`coupling`] and [`hemicube`] compute vertex-to-patch form factors by Lambert's formula
//!   with ray-traced visibility, by Monte Carlo, or by hemicube.
//! - [`estimate`] gives the residuals that adaptive refinement splits triangles by, and
//!   [`direct_interpolation_error`] measures a mesh's error against the exact direct light.
//! - [`path_trace`] gives Monte Carlo references with standard errors.
//!
//! Long solves report to a [`Progress`] and stop when an [`Interrupt`] is set; a [`SolveError`]
//! says why a solve failed.
//!
//! ## Example
//!
//! Below the centre of a unit square light at height d, parallel to the floor, the form factor is
//! that of four corner rectangles: F = (4/π) r atan r, with r = x/√(1 + x²) and x = 1/(2d). The
//! exact direct light matches it at every distance:
//!
//! ```
//! use glam::DVec3;
//! use penumbra_meshing::mesh_scene_uniform;
//! use penumbra_scenes::{Rgb, Scene, Surface, Visibility};
//! use penumbra_solver::{DirectLight, NoProgress, ReceivingPoint, SolverOptions, solve_progressive};
//!
//! /// A unit square light of exitance 10 at height `d`, facing down onto a grey floor.
//! fn square_over_floor(d: f64) -> Scene {
//!     let corner = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
//!     let light = vec![
//!         corner(-0.5, -0.5, d),
//!         corner(-0.5, 0.5, d),
//!         corner(0.5, 0.5, d),
//!         corner(0.5, -0.5, d),
//!     ];
//!     let floor = vec![
//!         corner(-4.0, -4.0, 0.0),
//!         corner(4.0, -4.0, 0.0),
//!         corner(4.0, 4.0, 0.0),
//!         corner(-4.0, 4.0, 0.0),
//!     ];
//!     Scene {
//!         name: "square".into(),
//!         camera: None,
//!         up: None,
//!         unit: None,
//!         surfaces: vec![
//!             Surface::new("light", light, Rgb::ZERO).with_emission(Rgb::splat(10.0)),
//!             Surface::new("floor", floor, Rgb::splat(0.5)),
//!         ],
//!     }
//! }
//!
//! for d in [0.1, 0.5, 1.0, 4.0] {
//!     let scene = square_over_floor(d);
//!     let visibility = Visibility::build(&scene);
//!     let direct = DirectLight::new(&scene, &visibility);
//!     let x = 0.5 / d;
//!     let r = x / (1.0 + x * x).sqrt();
//!     let f = 4.0 / std::f64::consts::PI * r * r.atan();
//!     let h = direct.irradiance(&ReceivingPoint::interior(DVec3::ZERO, DVec3::Z), 1);
//!     assert!((h.r - 10.0 * f).abs() <= 1e-12 * 10.0 * f, "d = {d}: {} against {}", h.r, 10.0 * f);
//! }
//!
//! // A whole solve: the floor's light reaches only the light's black face, so one bounce is all
//! // there is, and the energy account closes.
//! let scene = square_over_floor(1.0);
//! let visibility = Visibility::build(&scene);
//! let mesh = mesh_scene_uniform(&scene, 400).unwrap();
//! let options = SolverOptions::default();
//! let solution = solve_progressive(&scene, &mesh, &visibility, &options, &NoProgress).unwrap();
//! for (b, h) in solution.radiosity[1].iter().zip(&solution.irradiance[1]) {
//!     assert!((b.r - 0.5 * h.r).abs() <= 1e-12 * h.r);
//! }
//! let stats = &solution.stats;
//! let unaccounted = stats.emitted - stats.absorbed - stats.unshot - stats.escaped;
//! assert!(unaccounted.mean().abs() <= 1e-6 * stats.emitted.mean());
//! ```

#![warn(missing_docs)]

mod clip;
pub mod coupling;
mod direct;
mod direct_pass;
mod elements;
mod error;
pub mod estimate;
mod gathering;
pub mod hemicube;
pub mod hierarchical;
mod lambert;
mod measure;
mod occluder_tree;
mod option_id;
mod options;
pub mod path_trace;
pub mod photon_map;
mod progress;
mod progressive;
mod rays;
mod shadow_union;
mod sheet_outline;
mod solids;
mod solution;

pub use direct::{DirectLight, SEQUENTIAL_SHADOWS};
pub use direct_pass::{OVERLAY_CAP, SHARED_POINT, irradiance_shared, shared_points};
pub use elements::{Discretization, Element, Patch, hover_lift, hover_lifts, on_line_distance};
pub use error::SolveError;
pub use gathering::{PatchSystem, SolverMethod, SystemSolution, solve_gathering};
pub use hierarchical::solve_hierarchical;
pub use lambert::{ReceivingPoint, form_factor};
pub use measure::{InterpolationError, direct_interpolation_error};
pub use option_id::OptionId;
pub use options::{DEFAULT_EPSILON, SolverOptions};
pub use progress::{Interrupt, NoProgress, Progress};
pub use progressive::{ProgressiveSolver, solve_direct_on, solve_progressive};
pub use solution::{ConvergencePoint, Solution, SolveStats, StopReason, ambient_term, displayed};
