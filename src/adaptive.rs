//! Adaptive refinement: split the triangles whose linear interpolation misses the solution by
//! more than a tolerance, round after round, within the element budget, feeding the refined mesh
//! to the progressive solver without restarting it.
//!
//! Each round measures every triangle's residual ([`penumbra_solver::estimate`]): the exact
//! direct light at its edge midpoints and centroid and, in full solutions, the light gathered at
//! its centroid from the patches shot so far. The triangles over the tolerance are split, largest
//! share of the squared error first, by longest-edge bisection in the surface's constrained
//! triangulation: never across a discontinuity, with quality restored around the splits. The
//! solver then takes the new mesh: new vertices get the exact direct light and gather what has
//! been shot, and shooting goes on. The hierarchical solver takes it the same way: its
//! hierarchy and links stay, and new vertices gather along them.

use penumbra_meshing::SceneMesh;
use penumbra_scenes::{Scene, Visibility};
use penumbra_solver::estimate::{
    IndirectEstimate, ResidualSummary, gradient_jump_estimate, residuals_of, solution_residuals,
    summarize,
};
use penumbra_solver::hierarchical::{Round, solve_hierarchical_refining};
use penumbra_solver::solve_hierarchical;
use penumbra_solver::{Progress, ProgressiveSolver, Solution, SolveError, SolverOptions};
use serde::Serialize;

/// How adaptive refinement runs ([`crate::RunOptions::refine`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RefineOptions {
    /// Split triangles whose residual exceeds this fraction of the mean reflected radiosity
    /// (B − E, area-weighted over the surfaces that reflect): the light a dim floor under a
    /// bright lamp reflects sets its scale, not the lamp's own exitance.
    pub tolerance: f64,
    /// Triangles of the mesh refinement starts from (the budget caps where it ends);
    /// [`INITIAL_FRACTION`] of the budget by default.
    pub initial_elements: usize,
    /// Rounds at most, from 1 to [`crate::options::MAX_REFINE_ROUNDS`];
    /// [`DEFAULT_MAX_ROUNDS`] by default.
    pub max_rounds: usize,
    /// How full solutions estimate the indirect light's error: from its gradient's jumps (the
    /// default, and the only estimate the hierarchical solver takes), or gathered at triangle
    /// centroids from the patches shot so far. Direct-only runs have no indirect light, and
    /// ignore it.
    pub indirect: IndirectEstimate,
}

/// Why refinement stopped (`refinement.stop` in `report.json`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RefineStop {
    /// No residual exceeds the tolerance.
    Tolerance,
    /// The element budget is spent.
    Budget,
    /// The last round was run.
    Rounds,
    /// The time budget ran out.
    TimeBudget,
    /// The run was interrupted (Ctrl-C, SIGTERM).
    Interrupted,
}

/// The fraction of the element budget adaptive runs start from, by default: the estimate, not a
/// guess made before any solving, should place most triangles. On the Cornell floor, direct light
/// only, 30,000 triangles, 10-degree splits: RMS error 0.099 % from a tenth, 0.105 % from a
/// quarter.
pub const INITIAL_FRACTION: f64 = 0.1;

/// What refinement tolerances are relative to, as `report.json` names it.
pub const TOLERANCE_RELATIVE_TO: &str = "mean_reflected_radiosity";

/// Rounds of refinement at most, by default. A round takes at most a third of the room left, so
/// going from a tenth of the budget to its last half percent takes about 13.
pub const DEFAULT_MAX_ROUNDS: usize = 32;

/// Light left unshot (fraction of the emitted power) when a round's residuals are measured in a
/// full solution. The indirect light is smooth, and what is still unshot changes it little.
pub const ROUND_EPSILON: f64 = 0.02;

/// One round: the residuals found, and what was split (an entry of `refinement.rounds` in
/// `report.json`).
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct RefineRound {
    /// Triangles of the mesh at the start of the round.
    pub triangles: usize,
    /// Patch shots of progressive refinement so far (0 in direct-only runs and with the
    /// hierarchical solver).
    pub shots: usize,
    /// The residuals of this round's mesh, in W/m².
    pub residual: ResidualSummary,
    /// The residual a triangle may have this round, in W/m²: the tolerance times this round's
    /// mean reflected radiosity.
    pub threshold: f64,
    /// Triangles whose residual exceeds `threshold`.
    pub over_tolerance: usize,
    /// Of those, how many were split: the worst, within the room left in the budget.
    pub split: usize,
    /// Triangles the splits, and the quality refinement around them, added.
    pub added: usize,
}

/// What adaptive refinement did (`refinement` in `report.json`).
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct RefineReport {
    /// The tolerance asked for, relative to [`RefineReport::tolerance_relative_to`].
    pub tolerance: f64,
    /// What the tolerance is a fraction of: always `"mean_reflected_radiosity"`, the
    /// area-weighted mean of B − E over the surfaces that reflect, round by round.
    pub tolerance_relative_to: String,
    /// Each round, in order. The last one splits nothing.
    pub rounds: Vec<RefineRound>,
    /// Why refinement stopped.
    pub stop: RefineStop,
    /// The residuals of the final mesh (those of the last round), in W/m².
    pub residual: ResidualSummary,
    /// Each triangle's residual in the last round (the final mesh's), in W/m², per surface in
    /// the scene's order: the error indicator of the exports.
    #[serde(skip)]
    pub triangle_residuals: Vec<Vec<f64>>,
}

impl RefineReport {
    fn new(
        options: &RefineOptions,
        rounds: Vec<RefineRound>,
        stop: RefineStop,
        residual: ResidualSummary,
        triangle_residuals: Vec<Vec<f64>>,
    ) -> RefineReport {
        RefineReport {
            tolerance: options.tolerance,
            tolerance_relative_to: TOLERANCE_RELATIVE_TO.to_owned(),
            rounds,
            stop,
            residual,
            triangle_residuals,
        }
    }
}

/// Refines `mesh` adaptively within `max_elements` triangles, solving as it goes; returns what
/// it did and the solution on the final mesh (shot to `solver.epsilon`).
pub fn refine_adaptively(
    scene: &Scene,
    visibility: &Visibility,
    mesh: &mut SceneMesh,
    max_elements: usize,
    options: &RefineOptions,
    solver_options: &SolverOptions,
    progress: &dyn Progress,
) -> Result<(RefineReport, Solution), SolveError> {
    let mut solver = ProgressiveSolver::new(scene, mesh, visibility, solver_options, progress)?;
    let mut rounds = Vec::new();
    let mut stop = RefineStop::Rounds;
    let mut residual = ResidualSummary::default();
    let mut residuals = Vec::new();
    let mut limits = RoundLimits::new(max_elements, options, solver_options);
    for round in 0..=options.max_rounds {
        limits.round = round;
        solver.shoot(ROUND_EPSILON.max(solver_options.epsilon), progress);
        residuals = solution_residuals(scene, &solver, options.indirect);
        residual = summarize(scene, &mesh.surfaces, &solver.radiosity(), &residuals);
        let (this, plan) = plan_round(scene, mesh, &residuals, residual, solver.shots(), &limits);
        rounds.push(this);
        match plan {
            Plan::Stop(reason) => {
                stop = reason;
                break;
            }
            Plan::Split(refined) => {
                *mesh = *refined;
                solver.remesh(mesh, progress)?;
            }
        }
    }
    solver.shoot(solver_options.epsilon, progress);
    let report = RefineReport::new(options, rounds, stop, residual, residuals);
    Ok((report, solver.solution()))
}

/// [`refine_adaptively`] with the hierarchical solver: through the rounds its hierarchy and
/// links stay those of the starting mesh, and each round's new vertices get the exact direct
/// light and gather along the links of the leaf they lie in; the refined mesh is then solved
/// with a hierarchy of its own. The indirect light's error is estimated from its gradient's
/// jumps.
pub fn refine_hierarchically(
    scene: &Scene,
    visibility: &Visibility,
    mesh: &mut SceneMesh,
    max_elements: usize,
    options: &RefineOptions,
    solver_options: &SolverOptions,
    progress: &dyn Progress,
) -> Result<(RefineReport, Solution), SolveError> {
    let mut rounds = Vec::new();
    let mut stop = RefineStop::Rounds;
    let mut residual = ResidualSummary::default();
    let mut last_residuals = Vec::new();
    let mut limits = RoundLimits::new(max_elements, options, solver_options);
    let mut current = mesh.clone();
    let mut next_mesh = |r: &Round| -> Result<Option<SceneMesh>, SolveError> {
        let residuals = residuals_of(
            scene,
            r.direct_light,
            r.meshes,
            &r.direct,
            &r.radiosity,
            true,
            gradient_jump_estimate,
        );
        residual = summarize(scene, r.meshes, &r.radiosity, &residuals);
        limits.round = rounds.len();
        let (this, plan) = plan_round(scene, &current, &residuals, residual, 0, &limits);
        rounds.push(this);
        last_residuals = residuals;
        Ok(match plan {
            Plan::Stop(reason) => {
                stop = reason;
                None
            }
            Plan::Split(refined) => {
                current = (*refined).clone();
                Some(*refined)
            }
        })
    };
    let (refined, rounds_solution) = solve_hierarchical_refining(
        scene,
        mesh,
        visibility,
        solver_options,
        progress,
        &mut next_mesh,
    )?;
    *mesh = refined;
    // The rounds' hierarchy is the starting mesh's: its leaves reflect that coarse mesh's
    // interpolation of the direct light. The refined mesh is solved again, with its own.
    let early = &rounds_solution.stats;
    let solution = if early.remeshes == 0 {
        rounds_solution
    } else {
        let mut solution = solve_hierarchical(scene, mesh, visibility, solver_options, progress)?;
        let s = &mut solution.stats;
        s.remeshes = early.remeshes;
        s.gathered += early.gathered;
        s.direct_seconds += early.direct_seconds;
        s.shooting_seconds += early.shooting_seconds;
        s.gather_seconds += early.gather_seconds;
        s.rays_cast += early.rays_cast;
        solution
    };
    let report = RefineReport::new(options, rounds, stop, residual, last_residuals);
    Ok((report, solution))
}

/// What bounds a round.
struct RoundLimits<'o> {
    round: usize,
    max_elements: usize,
    options: &'o RefineOptions,
    solver: &'o SolverOptions,
}

impl<'o> RoundLimits<'o> {
    fn new(max_elements: usize, options: &'o RefineOptions, solver: &'o SolverOptions) -> Self {
        RoundLimits {
            round: 0,
            max_elements,
            options,
            solver,
        }
    }
}

/// What a round decides: to go on with a refined mesh, or to stop.
enum Plan {
    Split(Box<SceneMesh>),
    Stop(RefineStop),
}

/// One round of refinement of `mesh` from its triangles' `residuals`: the triangles over the
/// tolerance worst first, split within the budget; what the round did, and what comes next.
fn plan_round(
    scene: &Scene,
    mesh: &SceneMesh,
    residuals: &[Vec<f64>],
    residual: ResidualSummary,
    shots: usize,
    limits: &RoundLimits,
) -> (RefineRound, Plan) {
    let (options, max_elements) = (limits.options, limits.max_elements);
    let tolerance = options.tolerance * residual.mean_reflected_radiosity;
    let mut over: Vec<(f64, usize, usize)> = residuals
        .iter()
        .enumerate()
        .flat_map(|(s, r)| {
            r.iter()
                .enumerate()
                .filter(|&(_, &e)| e > tolerance)
                .map(move |(t, &e)| (e, s, t))
        })
        .collect();
    let mut this = RefineRound {
        triangles: mesh.triangle_count(),
        shots,
        residual,
        threshold: tolerance,
        over_tolerance: over.len(),
        split: 0,
        added: 0,
    };
    if over.is_empty() {
        return (this, Plan::Stop(RefineStop::Tolerance));
    }
    if limits.round == options.max_rounds {
        return (this, Plan::Stop(RefineStop::Rounds));
    }
    if let Some(reason) = limits.solver.stop_now() {
        let stop = if reason == penumbra_solver::StopReason::Interrupted {
            RefineStop::Interrupted
        } else {
            RefineStop::TimeBudget
        };
        return (this, Plan::Stop(stop));
    }
    // Only triangles worse than the mesh's typical (RMS) residual are split: refinement
    // spreads the error evenly instead of polishing large smooth triangles whose residual
    // is already below it. On the Cornell floor, direct light only, 30,000 triangles: RMS
    // error 0.092 %; splitting every triangle over a tolerance of 8e-5, 0.116 %.
    if over.iter().any(|o| o.0 > residual.rms) {
        over.retain(|o| o.0 > residual.rms);
    }
    // Largest share of the squared error (residual squared times area) first. A split adds
    // about two triangles and quality refinement a few more, so a round takes at most a
    // third of the room left, and halves that until it fits.
    for o in over.iter_mut() {
        o.0 = o.0 * o.0 * mesh.surfaces[o.1].triangle_area(o.2);
    }
    over.sort_by(|a, b| b.0.total_cmp(&a.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    let room = max_elements.saturating_sub(mesh.triangle_count());
    // The last sliver of the budget is not worth a round: 0.5 % of it when only the direct
    // light is solved, 2 % in full solutions, where a round also costs the new vertices'
    // gathering and the patches' new columns.
    let last = if limits.solver.direct_only { 200 } else { 50 };
    let mut take = if room * last < max_elements {
        0
    } else {
        over.len().min(room / 3)
    };
    let refined = loop {
        if take == 0 {
            break None;
        }
        let mut trial = mesh.clone();
        let mut by_surface = vec![Vec::new(); trial.surfaces.len()];
        for &(_, s, t) in &over[..take] {
            by_surface[s].push(t);
        }
        for (s, triangles) in by_surface.iter().enumerate() {
            if !triangles.is_empty() {
                trial.split_triangles(scene, s, triangles);
            }
        }
        if trial.triangle_count() <= max_elements {
            break Some(trial);
        }
        take /= 2;
    };
    this.split = take;
    match refined {
        Some(m) if m.triangle_count() > mesh.triangle_count() => {
            this.added = m.triangle_count() - mesh.triangle_count();
            (this, Plan::Split(Box::new(m)))
        }
        _ => (this, Plan::Stop(RefineStop::Budget)),
    }
}
