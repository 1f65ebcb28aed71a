//! The options of a run, their defaults, and the one place their ranges are checked, for the
//! command line and library callers alike.

use penumbra_meshing::DEFAULT_PENUMBRA_DENSITY;
use penumbra_meshing::ElementBudget;
use penumbra_meshing::discontinuity::DiscontinuityOptions;
use penumbra_meshing::polygon_minimum;
use penumbra_scenes::Scene;
pub use penumbra_solver::OptionId;
use penumbra_solver::estimate::IndirectEstimate;
use penumbra_solver::{SolveError, SolverMethod, SolverOptions};
use penumbra_viz::RenderOptions;
use serde::Serialize;

use crate::adaptive::RefineOptions;

mod shard;
pub use shard::{Shard, ShardError, ShardPart, extra_shares, meshed_alone, surface_costs};

/// How surfaces are meshed (`--mesh`; `method.mesh_requested` in `report.json`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MeshMethod {
    /// Constrained Delaunay triangulation of each polygon, refined to a uniform size.
    Uniform,
    /// The same, with the discontinuities of the direct light as constraint edges.
    Discontinuity,
    /// Error-driven: a mesh along the discontinuities that carry a real jump (contact lines,
    /// umbra and outer penumbra boundaries), refined where its interpolation of the exact
    /// direct light is measured worst ([`crate::error_mesh`]), up to the budget or
    /// [`RunOptions::tolerance`]. With adaptive refinement (`refine`) it is the discontinuity
    /// mesh if the scene casts shadows, else uniform: the discontinuity search is
    /// made, and a scene where it finds no segment (and skips no emitter–receiver pair) is
    /// meshed uniformly.
    Auto,
}

/// Triangles for the whole scene by default with every solver but the hierarchical one, and in
/// direct-only runs: this many, or what the scene needs when that is more (its least mesh and
/// [`penumbra_meshing::FIT_TRIANGLES_PER_SURFACE`] per surface; see [`ElementBudget::Fit`]).
pub const DEFAULT_MAX_ELEMENTS: usize = 10_000;

/// The element budget of a run when none is given, but for a full solution by the hierarchical
/// solver ([`default_budget`]): [`DEFAULT_MAX_ELEMENTS`] fitted to the scene.
pub const DEFAULT_BUDGET: ElementBudget = ElementBudget::fit(DEFAULT_MAX_ELEMENTS);

/// Triangles for the whole scene by default with the hierarchical solver: its cost grows about
/// linearly with the vertices (each gathers along its own links), so a finer display mesh, which
/// the exact direct light needs for 1 % on the Cornell box, costs it little.
pub const HIERARCHICAL_MAX_ELEMENTS: usize = 25_000;

/// The element budget of a run with `method` when none is given (direct-only runs, which do
/// not use the solver, get [`DEFAULT_BUDGET`]).
pub fn default_budget(method: SolverMethod, direct_only: bool) -> ElementBudget {
    match method {
        SolverMethod::Hierarchical if !direct_only => ElementBudget::fit(HIERARCHICAL_MAX_ELEMENTS),
        _ => DEFAULT_BUDGET,
    }
}

/// The penumbra density of a run when none is given: [`DEFAULT_PENUMBRA_DENSITY`], or 1 (no
/// grading) with adaptive refinement, which finds the penumbrae itself.
pub fn default_penumbra_density(refining: bool) -> f64 {
    if refining {
        1.0
    } else {
        DEFAULT_PENUMBRA_DENSITY
    }
}

/// The starting mesh of adaptive refinement when none is given: a fraction
/// ([`crate::adaptive::INITIAL_FRACTION`]) of the element cap, or of [`DEFAULT_MAX_ELEMENTS`]
/// without one (the run raises it to the scene's least mesh if that is more).
pub fn default_initial_elements(max_elements: Option<usize>) -> usize {
    (max_elements.unwrap_or(DEFAULT_MAX_ELEMENTS) as f64 * crate::adaptive::INITIAL_FRACTION)
        as usize
}

/// Monte Carlo form factors' samples per vertex and patch when none are given.
pub const DEFAULT_FF_SAMPLES: usize = 256;

/// Hemicube form factors' pixels across the top face when none are given.
pub const DEFAULT_HEMICUBE_RESOLUTION: usize = 128;

/// Penumbra densities accepted: 1 (no grading) up to this.
pub const MAX_PENUMBRA_DENSITY: f64 = 1e6;

/// Render sizes accepted, in pixels per side: a larger image would take gigabytes.
pub const MAX_RENDER_SIZE: u32 = 16_384;

/// Rounds of adaptive refinement accepted: each takes at most a third of the room left, so a
/// budget is spent long before this.
pub const MAX_REFINE_ROUNDS: usize = 1_000;

/// Everything a run can be asked to do. [`RunOptions::default`] is the command line's default
/// full run: a discontinuity mesh where the scene casts shadows, of 25,000 triangles (or what
/// the scene needs), solved by hierarchical radiosity; [`default_budget`] gives the default
/// budget for another solver or a direct-only run.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// How surfaces are meshed.
    pub mesh: MeshMethod,
    /// Triangles for the whole scene: a cap, or fitted to the scene ([`default_budget`]).
    pub max_elements: ElementBudget,
    /// How many times smaller in area discontinuity-mesh triangles are in penumbrae than in
    /// full light or full shadow: from 1 (no grading) to [`MAX_PENUMBRA_DENSITY`];
    /// [`DEFAULT_PENUMBRA_DENSITY`] by default.
    pub penumbra_density: f64,
    /// How discontinuities are found (EEE events on or off, tolerances).
    pub discontinuity: DiscontinuityOptions,
    /// Adaptive refinement from a coarser mesh up to `max_elements`, if asked for.
    pub refine: Option<RefineOptions>,
    /// Error-driven meshes ([`MeshMethod::Auto`]): the error a check point of the direct light
    /// may have, relative to the scene's mean reflected direct light;
    /// [`crate::error_mesh::DEFAULT_TOLERANCE`] by default.
    pub tolerance: f64,
    /// Discontinuity and error-driven meshes: the smallest angle (degrees) quality refinement
    /// aims for where the constraints do not force a smaller one; 0 for none (triangles are
    /// then split only by size and by the error), at most
    /// [`penumbra_meshing::MAX_MIN_ANGLE_DEG`]; [`DEFAULT_MIN_ANGLE_DEG`] by default.
    pub min_angle: f64,
    /// Seconds from the run's start after which the discontinuity search, adaptive refinement
    /// and the solver stop, and the best so far is kept (`None`: no limit); `report.json` then
    /// marks the run `partial`.
    pub time_budget: Option<f64>,
    /// The solver's own options (tolerances, rays, seed, interrupt).
    pub solver: SolverOptions,
    /// How the radiosity system is solved.
    pub method: SolverMethod,
    /// The size and exposure of `render.png`.
    pub render: RenderOptions,
    /// Bytes the run may use (default: what the machine has available when it starts).
    pub memory_limit: Option<u64>,
    /// Light only this shard's surfaces (direct light only; see [`crate::shard`]).
    pub shard: Option<Shard>,
}

/// The smallest angle discontinuity and error-driven meshes aim for by default, in degrees.
pub const DEFAULT_MIN_ANGLE_DEG: f64 = penumbra_meshing::CONSTRAINED_MIN_ANGLE_DEG;

impl Default for RunOptions {
    fn default() -> Self {
        let method = SolverMethod::Hierarchical;
        RunOptions {
            mesh: MeshMethod::Auto,
            max_elements: default_budget(method, false),
            penumbra_density: DEFAULT_PENUMBRA_DENSITY,
            discontinuity: DiscontinuityOptions::default(),
            refine: None,
            tolerance: crate::error_mesh::DEFAULT_TOLERANCE,
            min_angle: DEFAULT_MIN_ANGLE_DEG,
            time_budget: None,
            solver: SolverOptions::default(),
            method,
            render: RenderOptions::default(),
            memory_limit: None,
            shard: None,
        }
    }
}

/// An option outside its range, or options that do not go together. `option` names it in words
/// (`"penumbra density"`); a front end maps that to its own spelling (a flag, an argument).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("invalid {option}: {reason}")]
pub struct InvalidOption {
    /// The option.
    pub option: OptionId,
    /// What is wrong with its value, and what it may be.
    pub reason: String,
}

impl InvalidOption {
    fn new(option: OptionId, reason: impl Into<String>) -> InvalidOption {
        InvalidOption {
            option,
            reason: reason.into(),
        }
    }
}

impl From<SolveError> for InvalidOption {
    /// The solver's own option errors; any other solver error is not an option's.
    fn from(e: SolveError) -> InvalidOption {
        match e {
            SolveError::InvalidOption { option, reason } => InvalidOption::new(option, reason),
            e => InvalidOption::new(OptionId::Solver, e.to_string()),
        }
    }
}

impl RunOptions {
    /// The triangles the element budget resolves to on `scene`, as far as its polygons alone
    /// tell; [`MeshError::BudgetTooSmall`](penumbra_meshing::MeshError) for a cap below what
    /// they need.
    pub fn planned_elements(&self, scene: &Scene) -> Result<usize, penumbra_meshing::MeshError> {
        self.max_elements
            .resolve(polygon_minimum(scene), scene.surfaces.len())
    }

    /// Whether the mesh is error-driven ([`MeshMethod::Auto`] without adaptive refinement).
    pub fn error_driven(&self) -> bool {
        self.mesh == MeshMethod::Auto && self.refine.is_none()
    }

    /// Checks every option's range and that the options go together. [`crate::run`] calls it
    /// first; front ends call it to refuse bad input before loading a scene.
    pub fn validate(&self) -> Result<(), InvalidOption> {
        self.solver.validate()?;
        if self.max_elements == ElementBudget::AtMost(0) {
            return Err(InvalidOption::new(
                OptionId::MaxElements,
                "must be at least 1 triangle",
            ));
        }
        if !(1.0..=MAX_PENUMBRA_DENSITY).contains(&self.penumbra_density) {
            return Err(InvalidOption::new(
                OptionId::PenumbraDensity,
                format!(
                    "must be between 1 and {MAX_PENUMBRA_DENSITY:e}, not {}",
                    self.penumbra_density
                ),
            ));
        }
        if !(self.tolerance >= 0.0 && self.tolerance <= 1.0) {
            return Err(InvalidOption::new(
                OptionId::Tolerance,
                format!(
                    "must be a fraction in [0, 1] of the mean reflected direct light, not {}",
                    self.tolerance
                ),
            ));
        }
        if !(0.0..=penumbra_meshing::MAX_MIN_ANGLE_DEG).contains(&self.min_angle) {
            return Err(InvalidOption::new(
                OptionId::MinAngle,
                format!(
                    "must be between 0 and {} degrees, not {}",
                    penumbra_meshing::MAX_MIN_ANGLE_DEG,
                    self.min_angle
                ),
            ));
        }
        let event_tolerance = self.discontinuity.event_tolerance;
        if !(0.0..=1.0).contains(&event_tolerance) {
            return Err(InvalidOption::new(
                OptionId::EventTolerance,
                format!("must be a fraction between 0 and 1, not {event_tolerance}"),
            ));
        }
        if let Some(t) = self.time_budget
            && !(t > 0.0 && t.is_finite())
        {
            return Err(InvalidOption::new(
                OptionId::TimeBudget,
                format!("must be a positive number of seconds, not {t}"),
            ));
        }
        if self.memory_limit == Some(0) {
            return Err(InvalidOption::new(
                OptionId::MemoryLimit,
                "must be positive",
            ));
        }
        let (width, height) = (self.render.width, self.render.height);
        let pixels = u64::from(width) * u64::from(height);
        if !(1..=MAX_RENDER_SIZE).contains(&width)
            || !(1..=MAX_RENDER_SIZE).contains(&height)
            || pixels > penumbra_viz::MAX_PIXELS
        {
            return Err(InvalidOption::new(
                OptionId::RenderSize,
                format!(
                    "must be from 1 to {MAX_RENDER_SIZE} pixels a side and {} pixels in all, \
                     not {width} x {height}",
                    penumbra_viz::MAX_PIXELS
                ),
            ));
        }
        if let Some(refine) = &self.refine {
            self.validate_refinement(refine)?;
        }
        Ok(())
    }

    fn validate_refinement(&self, refine: &RefineOptions) -> Result<(), InvalidOption> {
        if !(refine.tolerance > 0.0 && refine.tolerance <= 1.0) {
            return Err(InvalidOption::new(
                OptionId::RefineTolerance,
                format!(
                    "must be a fraction in (0, 1] of the mean reflected radiosity, not {}",
                    refine.tolerance
                ),
            ));
        }
        if refine.initial_elements == 0 {
            return Err(InvalidOption::new(
                OptionId::InitialElements,
                "must be at least 1 triangle",
            ));
        }
        if !(1..=MAX_REFINE_ROUNDS).contains(&refine.max_rounds) {
            return Err(InvalidOption::new(
                OptionId::RefineRounds,
                format!(
                    "must be from 1 to {MAX_REFINE_ROUNDS}, not {}",
                    refine.max_rounds
                ),
            ));
        }
        let direct_only = self.solver.direct_only;
        if !matches!(
            self.method,
            SolverMethod::Progressive | SolverMethod::Hierarchical
        ) {
            return Err(InvalidOption::new(
                OptionId::Solver,
                "adaptive refinement feeds the progressive or the hierarchical solver",
            ));
        }
        if self.method == SolverMethod::Hierarchical
            && refine.indirect == IndirectEstimate::Gathered
            && !direct_only
        {
            return Err(InvalidOption::new(
                OptionId::RefineIndirect,
                "the hierarchical solver estimates the indirect light's error from its \
                 gradient's jumps; use gradient",
            ));
        }
        if self.solver.form_factors.by_rows() && !direct_only {
            return Err(InvalidOption::new(
                OptionId::FormFactors,
                "the hemicube gives the rows of a fixed mesh; adaptive refinement needs analytic \
                 or monte-carlo",
            ));
        }
        Ok(())
    }
}

/// How a run was asked for on the command line: `report.json` records it so that the run can
/// be repeated (`penumbra run --replay`).
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct Invocation {
    /// The command line, the program first.
    pub arguments: Vec<String>,
    /// The directory that relative paths on it are relative to.
    pub working_directory: String,
    /// Every option of the command as it was resolved, defaults included, by option name.
    pub options: serde_json::Value,
}
