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

pub mod clip;
pub mod coupling;
pub mod direct;
pub mod elements;
pub mod error;
pub mod estimate;
pub mod gathering;
pub mod hemicube;
pub mod hierarchical;
pub mod lambert;
pub mod measure;
mod occluder_tree;
pub mod path_trace;
pub mod progress;
pub mod progressive;
mod shadow_union;
pub mod solids;

pub use direct::DirectLight;
pub use elements::Discretization;
pub use error::SolveError;
pub use gathering::{SolverMethod, solve_gathering};
pub use hierarchical::solve_hierarchical;
pub use lambert::{ReceivingPoint, form_factor};
pub use progress::{NoProgress, Progress};
pub use progressive::{
    ConvergencePoint, Interrupt, ProgressiveSolver, Solution, SolveStats, SolverOptions,
    StopReason, solve_direct_on, solve_progressive,
};
