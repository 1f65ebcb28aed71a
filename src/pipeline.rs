//! The pipeline: from a loaded scene, through its stages ([`Stage`]): plan, visibility,
//! discontinuities, mesh, direct light and solve (with refinement), render. Each stage keeps its
//! own time and progress and honours the interrupt and the time budget. Pure computation;
//! writing the results is [`crate::outputs`]' job.

mod abandon;
mod first_mesh;
mod plan;
mod solve;

use std::sync::Arc;
use std::time::Instant;

use penumbra_meshing::discontinuity::{
    Boundary, Discontinuities, DiscontinuityOptions, find_discontinuities_reporting,
};
use penumbra_meshing::{ElementBudget, MeshError, SceneMesh};
use penumbra_scenes::{LoadedScene, Rgb, Scene, Visibility};
use penumbra_solver::{Progress, SolveError, SolverOptions, StopReason};
use penumbra_viz::Render;

use crate::error_mesh::{ErrorBudget, MeshErrorReport, StopWhen, refine_by_error};
use crate::memory::{self, MemoryEstimate};
use crate::options::{MeshMethod, RunOptions, ShardPart};
pub use crate::run_error::RunError;
pub use crate::run_result::{
    Kept, MemoryReport, RunResult, Stage, StagePeaks, StageTimes, Stopped,
};
use abandon::abandoned_on;
use first_mesh::FirstMesh;
pub use plan::BASE_SHARE;
use plan::{Plan, initial_budget_too_small};
pub use solve::LEAST_MESH_SECONDS;
use solve::{Meshed, Solved, least_mesh_lit, solve_with};

/// Runs the whole pipeline on a loaded scene: validates `options`, then builds visibility,
/// finds the discontinuities, meshes, solves and renders, reporting each long stage to
/// `progress`.
///
/// Memory is checked before it is spent: from the scene and the budget before anything is
/// built, then from the mesh's real counts before the solver allocates ([`RunError::Memory`]).
/// A time budget ([`RunOptions::time_budget`]) cuts the discontinuity search, error-driven
/// meshing and the solve short and keeps the best so far. An interrupt
/// ([`SolverOptions::interrupt`](penumbra_solver::SolverOptions::interrupt)) stops the stage it
/// lands in: a solve keeps its solution so far; a run stopped before any mesh has values keeps
/// the scene's least mesh with the direct light ([`Kept::LeastMeshDirect`]).
/// [`RunResult::stopped`] says where and why a run stopped.
pub fn run(
    loaded: LoadedScene,
    options: &RunOptions,
    progress: &dyn Progress,
) -> Result<RunResult, RunError> {
    let LoadedScene {
        scene,
        source,
        warnings,
    } = loaded;
    let scene = Arc::new(scene);
    let mut stages = Stages::new(&scene, options, progress)?;
    let plan = Plan::of(&scene, options)?;
    let visibility = Arc::new(stages.visibility());
    let lit = match stages.mesh_and_solve(&visibility, &plan) {
        Err(e) if is_interrupt(&e) => stages.least_mesh(&visibility, &plan)?,
        lit => lit?,
    };
    let render = stages.render(&lit)?;
    let shard_surfaces = stages.shard_part.take().map(|part| part.surfaces);
    let figures = stages.figures();
    // Abandoned meshing may hold the scene a moment longer.
    let scene = Arc::try_unwrap(scene).unwrap_or_else(|shared| Scene::clone(&shared));
    let loaded = LoadedScene {
        scene,
        source,
        warnings,
    };
    Ok(assemble(
        loaded,
        options,
        lit,
        render,
        &plan,
        figures,
        shard_surfaces,
    ))
}

/// Whether `error` is the interrupt, before a solution existed.
fn is_interrupt(error: &RunError) -> bool {
    matches!(
        error,
        RunError::Solve(SolveError::Interrupted) | RunError::Mesh(MeshError::Interrupted)
    )
}

/// A mesh with values: what the solve stage (or the least mesh) leaves for the render.
struct Lit {
    meshed: Meshed,
    solved: Solved,
    /// The memory estimate the solve was checked against.
    estimate: MemoryEstimate,
    /// The bytes the solver's form factor cache was allowed.
    cache_bytes: usize,
    stopped: Option<Stopped>,
}

/// A run in progress: what every stage reads, and the figures each leaves behind.
struct Stages<'a> {
    scene: &'a Arc<Scene>,
    options: &'a RunOptions,
    progress: &'a dyn Progress,
    /// The solver's options, with the run's deadline.
    solver: SolverOptions,
    started: Instant,
    /// The stage the run is in, and when it started.
    stage: Stage,
    stage_started: Instant,
    times: StageTimes,
    peaks: StagePeaks,
    /// The shard this run is, if it is one: its surfaces and part of the budget, settled once.
    shard_part: Option<ShardPart>,
}

impl<'a> Stages<'a> {
    /// A run of `options` on `scene`, which are checked first.
    fn new(
        scene: &'a Arc<Scene>,
        options: &'a RunOptions,
        progress: &'a dyn Progress,
    ) -> Result<Self, RunError> {
        options.validate()?;
        if let Some(shard) = options.shard {
            shard.check(options)?;
        }
        let started = Instant::now();
        // An anytime run: everything after the plan stops at the deadline.
        let deadline = options
            .time_budget
            .and_then(|seconds| std::time::Duration::try_from_secs_f64(seconds.max(0.0)).ok())
            .and_then(|budget| started.checked_add(budget));
        Ok(Stages {
            scene,
            options,
            progress,
            solver: SolverOptions {
                deadline,
                ..options.solver.clone()
            },
            started,
            stage: Stage::Plan,
            stage_started: started,
            times: StageTimes::default(),
            peaks: StagePeaks::default(),
            shard_part: options.shard.map(|shard| shard.part(scene, options)),
        })
    }

    /// Starts `stage`.
    fn enter(&mut self, stage: Stage) {
        self.stage = stage;
        self.stage_started = Instant::now();
    }

    /// The time of the stage the run stopped in, up to now.
    fn time_stopped_stage(&mut self) {
        let seconds = self.stage_started.elapsed().as_secs_f64();
        match self.stage {
            Stage::Visibility => self.times.visibility = seconds,
            Stage::Discontinuities => self.times.discontinuities = seconds,
            Stage::Mesh => self.times.mesh = seconds,
            Stage::Direct => self.times.direct = seconds,
            Stage::Solve => self.times.shooting = seconds,
            Stage::Refine => self.times.refine = seconds,
            Stage::Plan | Stage::Render => {}
        }
    }

    /// [`RunError`] for the interrupt, if it is set: between stages, before a solution exists.
    fn check_interrupt(&self) -> Result<(), RunError> {
        match &self.options.solver.interrupt {
            Some(i) if i.is_set() => Err(RunError::Solve(SolveError::Interrupted)),
            _ => Ok(()),
        }
    }

    /// The visibility stage: the scene's BVH.
    fn visibility(&mut self) -> Visibility {
        self.enter(Stage::Visibility);
        let t = Instant::now();
        let visibility = Visibility::build(self.scene);
        self.times.visibility = t.elapsed().as_secs_f64();
        self.peaks.visibility = memory::peak_resident_bytes();
        visibility
    }

    /// The stages from the discontinuities to the solve.
    fn mesh_and_solve(
        &mut self,
        visibility: &Arc<Visibility>,
        plan: &Plan,
    ) -> Result<Lit, RunError> {
        let found = self.discontinuities(visibility, plan);
        self.check_interrupt()?;
        let mut meshed = self.mesh(visibility, found, plan)?;
        self.check_interrupt()?;
        let estimate = plan.check_built(self.scene, self.options, &meshed.mesh, meshed.budget)?;
        // The column cache gets what the estimate leaves.
        let cache_bytes = plan.limit.map_or(self.solver.cache_bytes, |limit| {
            memory::cache_bytes(self.solver.cache_bytes, estimate.total(), limit)
        });
        let solved = self.solve(visibility, &mut meshed, cache_bytes)?;
        let stopped = self.stopped_solve(&solved);
        Ok(Lit {
            meshed,
            solved,
            estimate,
            cache_bytes,
            stopped,
        })
    }

    /// The discontinuity stage (none for uniform meshes). A shard of a large scene finds the
    /// discontinuities of its own surfaces only (it meshes them alone); error-driven meshes keep
    /// the lines that carry a real jump, and refinement finds the rest.
    fn discontinuities(&mut self, visibility: &Visibility, plan: &Plan) -> Option<Discontinuities> {
        if self.options.mesh == MeshMethod::Uniform {
            return None;
        }
        self.enter(Stage::Discontinuities);
        let t = Instant::now();
        let (scene, options) = (self.scene, self.options);
        let search = DiscontinuityOptions {
            element_area: Some(scene.total_area() / plan.planned_elements.max(1) as f64),
            deadline: self.solver.deadline,
            interrupt: options.solver.interrupt.clone(),
            receivers: self.shard_surfaces().as_deref().map(Into::into),
            horizons_near_edges: options.error_driven(),
            ..options.discontinuity.clone()
        };
        let mut found = find_discontinuities_reporting(scene, visibility, &search, self.progress);
        if options.error_driven() {
            for segments in &mut found.segments {
                segments.retain(|g| g.boundary != Boundary::Inner);
            }
        }
        self.times.discontinuities = t.elapsed().as_secs_f64();
        self.peaks.discontinuities = memory::peak_resident_bytes();
        Some(found)
    }

    /// The part of a large scene this run is, if it is a shard meshing its own surfaces alone.
    fn shard_alone(&self) -> Option<&ShardPart> {
        (self.shard_part.as_ref())
            .filter(|_| crate::options::meshed_alone(self.scene, self.options))
    }

    /// The surfaces a shard of a large scene meshes alone, if it does.
    fn shard_surfaces(&self) -> Option<Vec<bool>> {
        (self.shard_alone()).map(|part| part.surfaces.clone())
    }

    /// The mesh stage: the first mesh, then, for error-driven meshes, refinement where the
    /// direct light's interpolation error is largest.
    fn mesh(
        &mut self,
        visibility: &Arc<Visibility>,
        found: Option<Discontinuities>,
        plan: &Plan,
    ) -> Result<Meshed, RunError> {
        self.enter(Stage::Mesh);
        let t = Instant::now();
        self.progress.start("meshing", 1);
        let mut mesh = self.first_mesh(visibility, found, plan)?;
        let (scene, options) = (self.scene, self.options);
        // A shard meshing its own surfaces alone gets their part of the budget.
        let share = (self.shard_alone()).map(|part| part.budget_share);
        let budget = plan.final_budget(options, &mesh, scene.surfaces.len(), share)?;
        self.progress.finish();
        // Judged by no larger an element than the whole scene's, whatever its part of the budget.
        let error_budget = match share {
            Some(_) => ErrorBudget::for_shard(
                budget,
                scene.total_area(),
                options.planned_elements(scene).unwrap_or(budget),
            ),
            None => ErrorBudget::triangles(budget),
        };
        // Where only the direct light is wanted, a vertex made at a point measured costs
        // nothing: a fitted budget (not one asked for) grows by those.
        let error_budget = match options.max_elements {
            ElementBudget::Fit { .. } if options.solver.direct_only => {
                error_budget.splitting_measured()
            }
            _ => error_budget,
        };
        let mesh_error = self
            .options
            .error_driven()
            .then(|| self.refine_by_error(visibility, &mut mesh, error_budget));
        self.times.mesh = t.elapsed().as_secs_f64();
        self.peaks.mesh = memory::peak_resident_bytes();
        Ok(Meshed {
            mesh,
            budget,
            mesh_error,
        })
    }

    /// The mesh of the plan's first budget: by discontinuities where there are any (or they
    /// were asked for), else uniform. An interrupt abandons it at once ([`abandoned_on`]).
    fn first_mesh(
        &self,
        visibility: &Arc<Visibility>,
        found: Option<Discontinuities>,
        plan: &Plan,
    ) -> Result<SceneMesh, RunError> {
        let options = self.options;
        let error_driven = options.error_driven();
        let found = found.filter(|found| {
            options.mesh == MeshMethod::Discontinuity
                || error_driven
                || found.stats.segments > 0
                || found.stats.pairs_skipped > 0
        });
        let first = FirstMesh {
            scene: Arc::clone(self.scene),
            visibility: Arc::clone(visibility),
            found,
            budget: plan.initial_budget,
            penumbra_density: match error_driven {
                true => 1.0,
                false => options.penumbra_density,
            },
            min_angle_deg: options.min_angle,
            on: self.shard_surfaces(),
        };
        let meshed = match &options.solver.interrupt {
            Some(interrupt) => abandoned_on(interrupt, move |own| first.make(Some(own))),
            None => first.make(None),
        };
        meshed.map_err(|e| match initial_budget_too_small(options, &e) {
            true => RunError::InitialBudget(e),
            false => RunError::Mesh(e),
        })
    }

    /// Error-driven refinement of `mesh` up to `budget`, stopped by the deadline or the
    /// interrupt.
    fn refine_by_error(
        &self,
        visibility: &Visibility,
        mesh: &mut SceneMesh,
        budget: ErrorBudget,
    ) -> MeshErrorReport {
        let stop = StopWhen {
            deadline: self.solver.deadline,
            interrupt: self.options.solver.interrupt.clone(),
        };
        let tolerance = self.options.tolerance;
        refine_by_error(
            self.scene,
            visibility,
            mesh,
            budget,
            tolerance,
            &stop,
            self.progress,
        )
    }

    /// The direct light and solve stages (every solver starts with the exact direct light at
    /// the vertices), with refinement where it was asked for.
    fn solve(
        &mut self,
        visibility: &Visibility,
        meshed: &mut Meshed,
        cache_bytes: usize,
    ) -> Result<Solved, RunError> {
        self.enter(Stage::Direct);
        let t = Instant::now();
        let solver = SolverOptions {
            cache_bytes,
            ..self.solver.clone()
        };
        let (scene, options) = (self.scene, self.options);
        let on = (self.shard_part.as_ref()).map(|part| part.surfaces.as_slice());
        let solved = solve_with(
            scene,
            visibility,
            meshed,
            options,
            on,
            &solver,
            self.progress,
        )?;
        self.peaks.solve = memory::peak_resident_bytes();
        if let Some(report) = meshed.mesh_error.as_mut().filter(|_| !solver.direct_only) {
            report.estimate_reflected(scene, &meshed.mesh, &solved.solution);
        }
        let stats = &solved.solution.stats;
        self.times.direct = stats.direct_seconds;
        self.times.shooting = stats.shooting_seconds;
        self.times.gather = stats.gather_seconds;
        // Refinement's own work: residuals and splitting.
        if solved.refinement.is_some() {
            let solving = self.times.direct + self.times.shooting + self.times.gather;
            self.times.refine = (t.elapsed().as_secs_f64() - solving).max(0.0);
        }
        self.stage = match (&solved.refinement, solver.direct_only) {
            (Some(_), _) => Stage::Refine,
            (None, true) => Stage::Direct,
            (None, false) => Stage::Solve,
        };
        Ok(solved)
    }

    /// Where the solve stopped, if it was cut short.
    fn stopped_solve(&self, solved: &Solved) -> Option<Stopped> {
        let reason = solved.solution.stats.stop;
        matches!(reason, StopReason::Interrupted | StopReason::TimeBudget).then_some(Stopped {
            stage: self.stage,
            reason,
            kept: Kept::SolutionSoFar,
        })
    }

    /// What a run interrupted before any mesh had values keeps: the scene's least mesh with the
    /// direct light, the stage it stopped in named.
    fn least_mesh(&mut self, visibility: &Visibility, plan: &Plan) -> Result<Lit, RunError> {
        let stage = self.stage;
        self.time_stopped_stage();
        let (meshed, mut solution) = least_mesh_lit(self.scene, visibility, &self.solver)?;
        self.times.direct += solution.stats.direct_seconds;
        solution.stats.stop = StopReason::Interrupted;
        Ok(Lit {
            meshed,
            solved: Solved {
                solution,
                refinement: None,
            },
            estimate: plan.estimate.clone(),
            cache_bytes: self.solver.cache_bytes,
            stopped: Some(Stopped {
                stage,
                reason: StopReason::Interrupted,
                kept: Kept::LeastMeshDirect,
            }),
        })
    }

    /// The render stage: the image from the scene's camera, with Cohen et al.'s ambient term
    /// for display (each surface reflects its share of the light not shot yet).
    fn render(&mut self, lit: &Lit) -> Result<Render, RunError> {
        if lit.stopped.is_none() {
            self.enter(Stage::Render);
        }
        let t = Instant::now();
        let solution = &lit.solved.solution;
        let display: Vec<Vec<Rgb>> = lit
            .meshed
            .mesh
            .surfaces
            .iter()
            .zip(&solution.radiosity)
            .map(|(m, b)| {
                let rho = self.scene.surfaces[m.surface].reflectance;
                b.iter()
                    .map(|&c| penumbra_solver::displayed(c, rho, solution.ambient))
                    .collect()
            })
            .collect();
        let mesh = &lit.meshed.mesh;
        let render = penumbra_viz::render(self.scene, mesh, &display, &self.options.render)?;
        self.times.render = t.elapsed().as_secs_f64();
        self.times.total = self.started.elapsed().as_secs_f64();
        self.peaks.render = memory::peak_resident_bytes();
        Ok(render)
    }

    /// The stage times and memory peaks, once the run is done.
    fn figures(self) -> (StageTimes, StagePeaks) {
        (self.times, self.peaks)
    }
}

/// Everything the run computed.
fn assemble(
    loaded: LoadedScene,
    options: &RunOptions,
    lit: Lit,
    render: Render,
    plan: &Plan,
    (times, peaks): (StageTimes, StagePeaks),
    shard_surfaces: Option<Vec<bool>>,
) -> RunResult {
    RunResult {
        loaded,
        options: options.clone(),
        mesh: lit.meshed.mesh,
        refinement: lit.solved.refinement,
        mesh_error: lit.meshed.mesh_error,
        budget: lit.meshed.budget,
        solution: lit.solved.solution,
        render,
        times,
        memory: MemoryReport {
            limit_bytes: plan.limit,
            estimate_bytes: lit.estimate.total(),
            estimate: lit.estimate,
            cache_bytes: lit.cache_bytes,
            peak_bytes: peaks,
        },
        stopped: lit.stopped,
        invocation: None,
        shard_surfaces,
    }
}
