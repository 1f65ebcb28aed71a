//! The pipeline: from a loaded scene, build visibility, find the discontinuities, mesh, light
//! and solve, render. Pure computation; writing the results is [`crate::outputs`]' job.

use std::time::Instant;

use crate::adaptive::{RefineReport, refine_adaptively, refine_hierarchically};
use crate::error_mesh::{MeshErrorReport, StopWhen, refine_by_error};
use crate::memory::{self, MeshCounts};
use crate::options::ShardError;
use crate::options::{InvalidOption, MeshMethod, RunOptions};
use crate::reflected_mesh::refine_reflected;
use penumbra_meshing::discontinuity::{
    Boundary, DiscontinuityOptions, find_discontinuities_reporting,
};
use penumbra_meshing::{
    ElementBudget, MeshError, SceneMesh, mesh_scene_discontinuity_on, mesh_scene_uniform,
    polygon_minimum,
};
use penumbra_scenes::{LoadedScene, Rgb, SurfaceId, Visibility};
use penumbra_solver::photon_map::solve_photon_map;
use penumbra_solver::{
    Progress, Solution, SolveError, SolverMethod, SolverOptions, solve_direct_on, solve_gathering,
    solve_hierarchical, solve_progressive,
};
use penumbra_viz::{Render, VizError};
use serde::Serialize;

/// Wall-clock seconds per stage (`times_seconds` in `report.json`).
#[derive(Clone, Debug, Default, Serialize)]
pub struct StageTimes {
    /// Building the visibility index (the BVH).
    pub visibility: f64,
    /// The discontinuity search (0 for uniform meshes).
    pub discontinuities: f64,
    /// Meshing.
    pub mesh: f64,
    /// Adaptive refinement's own work, residuals and splits (its solving is counted in
    /// `direct`, `shooting` and `gather`); 0 without refinement.
    pub refine: f64,
    /// The exact direct light.
    pub direct: f64,
    /// Solving after the direct light: shooting, sweeps, the hierarchical solver's links.
    pub shooting: f64,
    /// Vertices gathering light: new vertices of refined meshes gathering what was shot
    /// before, the hierarchical solver's final gather.
    pub gather: f64,
    /// Rendering `render.png`.
    pub render: f64,
    /// The whole run, from its start to the end of the render (writing the files aside).
    pub total: f64,
}

/// The most memory the process had held (its peak resident set, in bytes) by the end of each
/// stage; `None` where the system does not say ([`memory::peak_resident_bytes`]). The peak
/// is the whole process's, so it includes whatever the caller held before the run.
#[derive(Clone, Debug, Default, Serialize)]
pub struct StagePeaks {
    /// After building the visibility index.
    pub visibility: Option<u64>,
    /// After the discontinuity search.
    pub discontinuities: Option<u64>,
    /// After meshing.
    pub mesh: Option<u64>,
    /// After solving (adaptive refinement included).
    pub solve: Option<u64>,
    /// After rendering.
    pub render: Option<u64>,
}

/// What the run was expected to need, what it could have, and what it used (`memory` in
/// `report.json`).
#[derive(Clone, Debug, Serialize)]
pub struct MemoryReport {
    /// Bytes the run could use: [`RunOptions::memory_limit`], or what the machine had
    /// available when the run started ([`memory::available_bytes`]); `None` where the system
    /// does not say.
    pub limit_bytes: Option<u64>,
    /// Bytes the run was estimated to need in all (`estimate`'s parts and a fixed base): from
    /// the mesh that was built or, with adaptive refinement, the most of that and of the mesh
    /// grown to the budget.
    pub estimate_bytes: u64,
    /// The estimate's parts, in bytes.
    pub estimate: memory::MemoryEstimate,
    /// Bytes allowed for the progressive solver's cache of vertex–patch form factors: what
    /// [`penumbra_solver::SolverOptions::cache_bytes`] asks for, within half of what the
    /// estimate leaves of `limit_bytes`.
    pub cache_bytes: usize,
    /// The process's peak resident set by the end of each stage, in bytes.
    pub peak_bytes: StagePeaks,
}

/// Everything a run computes: what [`crate::outputs`] writes, in memory.
#[derive(Debug)]
pub struct RunResult {
    /// The scene that was run, with its source and the loader's warnings.
    pub loaded: LoadedScene,
    /// The options the run was given (before [`run`] resolved the budget and the deadline).
    pub options: RunOptions,
    /// The final mesh: per surface, its triangles and vertices, and the discontinuity segments
    /// built into it (the discontinuity search's figures, if one was made).
    pub mesh: SceneMesh,
    /// What adaptive refinement did, if it was asked for.
    pub refinement: Option<RefineReport>,
    /// What error-driven refinement of the mesh did, and the error it measured, if the mesh is
    /// error-driven ([`RunOptions::error_driven`]).
    pub mesh_error: Option<MeshErrorReport>,
    /// The element budget used, in triangles for the whole scene, resolved: the mesh's, or the
    /// cap of adaptive refinement. The mesh may have fewer.
    pub budget: usize,
    /// Radiosity (W/m² per channel) and irradiance at every vertex of `mesh`, per surface in
    /// the scene's order, with the solver's figures. It leaves out the display-only ambient
    /// term (`solution.ambient`), which only `render` adds.
    pub solution: Solution,
    /// The image from the scene's camera, and the exposure it was made with.
    pub render: Render,
    /// Wall-clock seconds per stage.
    pub times: StageTimes,
    /// The memory the run was expected to need, what it could have, and what it used.
    pub memory: MemoryReport,
    /// The command line that asked for the run, if one did (set by the front end; recorded in
    /// `report.json`).
    pub invocation: Option<crate::options::Invocation>,
}

impl RunResult {
    /// The light surface `s` reflects at its vertices, in two parts: straight from the lights,
    /// ρ·H_direct, and after more bounces, ρ·(H − H_direct).
    pub fn reflected_parts(&self, s: SurfaceId) -> (Vec<Rgb>, Vec<Rgb>) {
        let rho = self.loaded.scene.surfaces[s].reflectance;
        let (h, hd) = (
            &self.solution.irradiance[s],
            &self.solution.direct_irradiance[s],
        );
        let direct = hd.iter().map(|&d| rho.mul_rgb(d)).collect();
        let indirect = h
            .iter()
            .zip(hd)
            .map(|(&h, &d)| rho.mul_rgb(h - d))
            .collect();
        (direct, indirect)
    }
}

/// Why a run failed. [`RunError::is_usage`] tells the errors a user fixes by changing the
/// options (a bad option, a budget or memory too small) from failures of the run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// An option out of its range, or options that do not go together
    /// ([`RunOptions::validate`]).
    #[error(transparent)]
    InvalidOption(#[from] InvalidOption),
    /// Meshing failed, or the scene's least mesh does not fit a capped element budget
    /// ([`MeshError::BudgetTooSmall`]).
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The starting mesh of adaptive refinement does not fit its budget
    /// ([`RefineOptions::initial_elements`](crate::adaptive::RefineOptions::initial_elements)),
    /// though the scene fits the run's budget.
    #[error("the starting mesh of adaptive refinement: {0}")]
    InitialBudget(MeshError),
    /// Solving failed, or the run was interrupted ([`SolveError::Interrupted`]) before a
    /// solution existed.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The render failed.
    #[error(transparent)]
    Render(#[from] VizError),
    /// The options cannot be split into shards ([`crate::options::Shard::check`]).
    #[error(transparent)]
    Shard(#[from] ShardError),
    /// The run's estimated memory exceeds what it may use; refused before the stage that would
    /// allocate it. The message says what would fit.
    #[error("{}", memory_message(.needed, .limit, .suggestion, .link_tol))]
    Memory {
        /// Bytes the run was estimated to need.
        needed: u64,
        /// Bytes the run may use.
        limit: u64,
        /// The largest element budget that would fit, if any.
        suggestion: Option<usize>,
        /// With the hierarchical solver: the least link tolerance that would fit, if any.
        link_tol: Option<f64>,
    },
}

fn memory_message(
    needed: &u64,
    limit: &u64,
    suggestion: &Option<usize>,
    link_tol: &Option<f64>,
) -> String {
    let head = format!(
        "this run would need about {} of memory, and {} is available",
        memory::human(*needed),
        memory::human(*limit)
    );
    match (suggestion, link_tol) {
        (None, None) => format!("{head}; even the coarsest mesh of this scene does not fit"),
        _ => {
            let budget = suggestion.map(|n| format!("an element budget of {n} or fewer"));
            let links = link_tol.map(|t| format!("a link tolerance of {t:.1e} or more"));
            let fits: Vec<String> = budget.into_iter().chain(links).collect();
            format!("{head}; {} would fit", fits.join(", or "))
        }
    }
}

impl RunError {
    /// Whether the error is the user's to fix (bad options) rather than a failure of the run.
    pub fn is_usage(&self) -> bool {
        matches!(
            self,
            RunError::Mesh(MeshError::BudgetTooSmall { .. })
                | RunError::InitialBudget(MeshError::BudgetTooSmall { .. })
                | RunError::InvalidOption(_)
                | RunError::Solve(SolveError::InvalidOption { .. })
                | RunError::Memory { .. }
                | RunError::Shard(_)
        )
    }
}

/// The share of the element budget an error-driven mesh of a full solution starts from: the
/// discontinuity mesh refined evenly, for the light reflected more than once, which the direct
/// light's error does not see. Direct-only runs start from the least mesh.
pub const BASE_SHARE: f64 = 0.25;

/// [`BASE_SHARE`] for full solutions, nothing for direct-only runs.
fn base_share(direct_only: bool) -> f64 {
    if direct_only { 0.0 } else { BASE_SHARE }
}

/// The triangles a budget asks for at least: its cap, or its floor.
fn budget_floor(budget: ElementBudget) -> usize {
    match budget {
        ElementBudget::AtMost(n) | ElementBudget::Fit { at_least: n, .. } => n,
    }
}

/// The budget the mesh will have, as far as the polygons alone tell (at least one triangle).
fn planned_budget(scene: &penumbra_scenes::Scene, options: &RunOptions) -> usize {
    let least = polygon_minimum(scene);
    options
        .max_elements
        .resolve(least, scene.surfaces.len())
        .unwrap_or(least)
        .max(1)
}

/// Runs the whole pipeline on a loaded scene: validates `options`, then builds visibility,
/// finds the discontinuities, meshes, solves and renders, reporting each long stage to
/// `progress`.
///
/// Memory is checked before it is spent: from the scene and the budget before anything is
/// built, then from the mesh's real counts before the solver allocates ([`RunError::Memory`]).
/// A time budget ([`RunOptions::time_budget`]) cuts the discontinuity search and the solve short
/// and keeps the best so far. An interrupt
/// ([`SolverOptions::interrupt`](penumbra_solver::SolverOptions::interrupt)) ends the run with
/// [`SolveError::Interrupted`] while no solution exists yet, and like the time budget after
/// that; `solution.stats.stop` says why a solve stopped.
pub fn run(
    loaded: LoadedScene,
    options: &RunOptions,
    progress: &dyn Progress,
) -> Result<RunResult, RunError> {
    options.validate()?;
    if let Some(shard) = options.shard {
        shard.check(options)?;
    }
    let started = Instant::now();
    // An anytime run: everything after meshing stops at the deadline.
    let solver = SolverOptions {
        deadline: options
            .time_budget
            .and_then(|seconds| std::time::Duration::try_from_secs_f64(seconds.max(0.0)).ok())
            .and_then(|budget| started.checked_add(budget)),
        ..options.solver.clone()
    };
    let mut times = StageTimes::default();
    let mut peaks = StagePeaks::default();
    let scene = &loaded.scene;

    // A cap below what the polygons alone need is refused before anything is computed (finding
    // the discontinuities of a large scene takes minutes); what they add is checked once they
    // are found, when the mesh is built.
    let at_least = polygon_minimum(scene);
    let surfaces = scene.surfaces.len();
    let planned_elements = options.max_elements.resolve(at_least, surfaces)?;
    let error_driven = options.error_driven();
    let base_share = base_share(options.solver.direct_only);
    let initial_budget = match (&options.refine, options.max_elements) {
        // Error-driven meshes start from a share of the budget and spend the rest where the
        // measured error is largest.
        // (the least mesh when that is more: the final budget refuses what does not fit).
        (None, budget) if error_driven => ElementBudget::Fit {
            at_least: (budget_floor(budget) as f64 * base_share) as usize,
            per_surface: 0,
        },
        (None, budget) => budget,
        (Some(r), ElementBudget::AtMost(n)) => ElementBudget::AtMost(r.initial_elements.min(n)),
        // Refinement starts from the scene's least mesh when that is more than it asks for,
        // and spends up to the fitted budget.
        (Some(r), ElementBudget::Fit { .. }) => ElementBudget::Fit {
            at_least: r.initial_elements,
            per_surface: 0,
        },
    };
    initial_budget
        .resolve(at_least, surfaces)
        .map_err(RunError::InitialBudget)?;

    // Refuse at once what cannot fit, rather than be killed later.
    let limit = options.memory_limit.or_else(memory::available_bytes);
    let check = |counts: MeshCounts| -> Result<memory::MemoryEstimate, RunError> {
        let estimate = memory::estimate(scene, options, counts);
        match limit {
            Some(limit) if estimate.total() > limit => Err(RunError::Memory {
                needed: estimate.total(),
                limit,
                suggestion: memory::largest_fitting_budget(
                    scene,
                    options,
                    planned_elements.max(counts.triangles as usize),
                    limit,
                ),
                link_tol: memory::least_fitting_link_tol(scene, options, counts, limit),
            }),
            _ => Ok(estimate),
        }
    };
    let planned = check(MeshCounts::predicted(
        scene,
        planned_elements,
        options.solver.elements_per_patch,
    ))?;

    // Before a solution exists an interrupt ends the run between stages (and within the
    // direct light and form factors), with nothing to write.
    let interrupted = || match &options.solver.interrupt {
        Some(i) if i.is_set() => Err(RunError::Solve(SolveError::Interrupted)),
        _ => Ok(()),
    };

    let t = Instant::now();
    let visibility = Visibility::build(scene);
    times.visibility = t.elapsed().as_secs_f64();
    peaks.visibility = memory::peak_resident_bytes();

    // A shard of a large scene finds the discontinuities of its own surfaces and meshes them
    // alone: each one's share of a fitted budget then depends on nothing else.
    let shard_surfaces = options
        .shard
        .filter(|_| crate::options::meshed_alone(scene, options))
        .map(|shard| shard.surfaces(surfaces));
    let t = Instant::now();
    let found = match options.mesh {
        MeshMethod::Uniform => None,
        MeshMethod::Discontinuity | MeshMethod::Auto => Some(find_discontinuities_reporting(
            scene,
            &visibility,
            &DiscontinuityOptions {
                element_area: Some(scene.total_area() / planned_budget(scene, options) as f64),
                deadline: solver.deadline,
                interrupt: options.solver.interrupt.clone(),
                receivers: shard_surfaces.as_deref().map(Into::into),
                horizons_near_edges: error_driven,
                ..options.discontinuity.clone()
            },
            progress,
        )),
    };
    // Error-driven meshes keep the lines that carry a real jump; refinement finds the rest.
    let found = match found {
        Some(mut found) if error_driven => {
            for segments in &mut found.segments {
                segments.retain(|g| g.boundary != Boundary::Inner);
            }
            Some(found)
        }
        found => found,
    };
    times.discontinuities = t.elapsed().as_secs_f64();
    peaks.discontinuities = memory::peak_resident_bytes();
    interrupted()?;

    let t = Instant::now();
    progress.start("meshing", 1);
    let meshed = match found {
        Some(found)
            if options.mesh == MeshMethod::Discontinuity
                || error_driven
                || found.stats.segments > 0
                || found.stats.pairs_skipped > 0 =>
        {
            mesh_scene_discontinuity_on(
                scene,
                &visibility,
                found,
                initial_budget,
                if error_driven {
                    1.0
                } else {
                    options.penumbra_density
                },
                options.min_angle,
                shard_surfaces.as_deref(),
            )
        }
        _ => mesh_scene_uniform(scene, initial_budget),
    };
    let mut mesh = match meshed {
        // The scene fits the run's budget but not the starting mesh's.
        Err(e @ MeshError::BudgetTooSmall { needed, .. })
            if options.refine.is_some()
                && options.max_elements.at_most().is_none_or(|n| needed <= n) =>
        {
            return Err(RunError::InitialBudget(e));
        }
        meshed => meshed?,
    };
    // Adaptive refinement grows the mesh up to the run's budget, resolved now that the scene's
    // least mesh is known.
    let budget = match options.refine {
        None if !error_driven => mesh.budget,
        _ => options
            .max_elements
            .resolve_for(
                mesh.minimum_triangles,
                surfaces,
                mesh.discontinuity_stats.is_some(),
            )?
            .max(mesh.triangle_count()),
    };
    progress.finish();
    let mut mesh_error = error_driven.then(|| {
        let stop = StopWhen {
            deadline: solver.deadline,
            interrupt: options.solver.interrupt.clone(),
        };
        refine_by_error(
            scene,
            &visibility,
            &mut mesh,
            budget,
            options.tolerance,
            &stop,
            progress,
        )
    });
    times.mesh = t.elapsed().as_secs_f64();
    peaks.mesh = memory::peak_resident_bytes();
    interrupted()?;

    // Again with the real counts, before the solver allocates; the column cache gets what is
    // left.
    let built = check(MeshCounts::of_mesh(
        &mesh,
        options.solver.elements_per_patch,
    ))?;
    // Adaptive refinement grows the mesh up to the budget: the plan for that holds for it.
    let estimate = match options.refine {
        Some(_) => {
            let grown = check(MeshCounts::predicted(
                scene,
                budget,
                options.solver.elements_per_patch,
            ))?;
            [planned, grown].into_iter().fold(built, |most, e| {
                if e.total() > most.total() { e } else { most }
            })
        }
        None => built,
    };
    let solver = SolverOptions {
        cache_bytes: limit.map_or(solver.cache_bytes, |limit| {
            memory::cache_bytes(solver.cache_bytes, estimate.total(), limit)
        }),
        ..solver
    };

    let t = Instant::now();
    let (refinement, solution) = match &options.refine {
        Some(refine) => {
            let refine_with = if options.method == SolverMethod::Hierarchical && !solver.direct_only
            {
                refine_hierarchically
            } else {
                refine_adaptively
            };
            let (report, solution) = refine_with(
                scene,
                &visibility,
                &mut mesh,
                budget,
                refine,
                &solver,
                progress,
            )?;
            (Some(report), solution)
        }
        // Every surface is meshed as in a whole run (each one's share of the budget depends on
        // all of them, and the direct light at a point shared by several surfaces is evaluated
        // once for all); only the shard's vertices are lit.
        None if options.shard.is_some() => {
            let on = options
                .shard
                .map(|shard| shard.surfaces(scene.surfaces.len()))
                .unwrap_or_default();
            (
                None,
                solve_direct_on(scene, &mesh, &visibility, &solver, &on, progress)?,
            )
        }
        None if solver.direct_only || options.method == SolverMethod::Progressive => (
            None,
            solve_progressive(scene, &mesh, &visibility, &solver, progress)?,
        ),
        // Error-driven meshes are refined again for the light reflected more than once.
        None if options.method == SolverMethod::Hierarchical && error_driven => {
            let (done, solution) = refine_reflected(
                scene,
                &visibility,
                &mut mesh,
                budget,
                options.tolerance,
                &solver,
                progress,
            )?;
            if let Some(report) = mesh_error.as_mut() {
                report.reflected_refinement = Some(done);
            }
            (None, solution)
        }
        None if options.method == SolverMethod::Hierarchical => (
            None,
            solve_hierarchical(scene, &mesh, &visibility, &solver, progress)?,
        ),
        None if options.method == SolverMethod::PhotonMap => (
            None,
            solve_photon_map(scene, &mesh, &visibility, &solver, progress)?,
        ),
        None => (
            None,
            solve_gathering(scene, &mesh, &visibility, &solver, options.method, progress)?,
        ),
    };
    peaks.solve = memory::peak_resident_bytes();
    if let Some(report) = mesh_error.as_mut().filter(|_| !solver.direct_only) {
        report.estimate_reflected(scene, &mesh, &solution);
    }
    let stats = &solution.stats;
    times.direct = stats.direct_seconds;
    times.shooting = stats.shooting_seconds;
    times.gather = stats.gather_seconds;
    // Refinement's own work: residuals and splitting.
    times.refine = match refinement {
        Some(_) => {
            (t.elapsed().as_secs_f64() - times.direct - times.shooting - times.gather).max(0.0)
        }
        None => 0.0,
    };

    let t = Instant::now();
    // Cohen et al.'s ambient term, for display only: each surface reflects its share of the
    // light not shot yet.
    let display: Vec<Vec<Rgb>> = mesh
        .surfaces
        .iter()
        .zip(&solution.radiosity)
        .map(|(m, b)| {
            let rho = scene.surfaces[m.surface].reflectance;
            b.iter()
                .map(|&c| penumbra_solver::displayed(c, rho, solution.ambient))
                .collect()
        })
        .collect();
    let render = penumbra_viz::render(scene, &mesh, &display, &options.render)?;
    times.render = t.elapsed().as_secs_f64();
    times.total = started.elapsed().as_secs_f64();
    peaks.render = memory::peak_resident_bytes();

    Ok(RunResult {
        loaded,
        options: options.clone(),
        mesh,
        refinement,
        mesh_error,
        budget,
        solution,
        render,
        times,
        memory: MemoryReport {
            limit_bytes: limit,
            estimate_bytes: estimate.total(),
            estimate,
            cache_bytes: solver.cache_bytes,
            peak_bytes: peaks,
        },
        invocation: None,
    })
}
