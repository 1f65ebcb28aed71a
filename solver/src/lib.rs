//! # penumbra-solver
//!
//! Radiosity on meshed scenes: point-to-polygon form factors by Lambert's contour formula
//! ([`lambert`]), exact direct light from area emitters by backprojection ([`DirectLight`]), and
//! progressive refinement radiosity with vertex receivers ([`solve_progressive`]).
//!
//! ```
//! use penumbra_scenes::{builtin, Visibility};
//! use penumbra_solver::{DirectLight, ReceivingPoint};
//! let scene = builtin::textbook();
//! let vis = Visibility::build(&scene);
//! let direct = DirectLight::new(&scene, &vis);
//! let floor = scene.surface_id("floor").unwrap();
//! // Directly below the blocker the floor is in umbra; at x = 1 the penumbra ends.
//! let at = |x: f64| ReceivingPoint::interior(glam::DVec3::new(x, 0.0, 0.0), glam::DVec3::Z);
//! assert_eq!(direct.irradiance(&at(0.0), floor).r, 0.0);
//! assert!((direct.irradiance(&at(1.0), floor).r - 0.0279891563025598).abs() < 1e-12);
//! ```

mod clip;
pub mod coupling;
mod direct;
mod elements;
mod error;
pub mod estimate;
mod gathering;
pub mod hemicube;
pub mod hierarchical;
mod lambert;
mod measure;
mod occluder_tree;
pub mod path_trace;
mod progress;
mod progressive;
mod shadow_union;
mod solids;

pub use direct::{DirectLight, SEQUENTIAL_SHADOWS};
pub use elements::{Discretization, Element, Patch};
pub use error::SolveError;
pub use gathering::{PatchSystem, SolverMethod, SystemSolution, solve_gathering};
pub use hierarchical::solve_hierarchical;
pub use lambert::{ReceivingPoint, form_factor};
pub use measure::{InterpolationError, direct_interpolation_error};
pub use progress::{Interrupt, NoProgress, Progress};
pub use progressive::{
    ConvergencePoint, DEFAULT_EPSILON, ProgressiveSolver, SHARED_POINT, Solution, SolveStats,
    SolverOptions, StopReason, ambient_term, solve_direct_on, solve_progressive,
};
