//! The plan stage: the element budgets and the memory a run will need, settled before anything
//! is built, so that what cannot fit is refused at once rather than killed later.

use penumbra_meshing::{ElementBudget, MeshError, SceneMesh, polygon_minimum};
use penumbra_scenes::Scene;

use crate::memory::{self, MemoryEstimate, MeshCounts};
use crate::options::RunOptions;
use crate::run_error::RunError;

/// The share of the element budget an error-driven mesh of a full solution starts from: the
/// discontinuity mesh refined evenly, for the light reflected more than once, which the direct
/// light's error does not see. Direct-only runs start from the least mesh.
pub const BASE_SHARE: f64 = 0.25;

/// What a run settles before it builds anything.
pub(crate) struct Plan {
    /// The triangles the run's budget resolves to, as far as the polygons alone tell.
    pub(crate) planned_elements: usize,
    /// The budget of the first mesh: the run's, or the share refinement starts from.
    pub(crate) initial_budget: ElementBudget,
    /// Bytes the run may use, if known.
    pub(crate) limit: Option<u64>,
    /// The memory the planned mesh needs.
    pub(crate) estimate: MemoryEstimate,
}

impl Plan {
    /// The plan of a run of `options` on `scene`: a cap below what the polygons alone need, or
    /// an estimate beyond the memory the run may use, is refused before anything is computed
    /// (finding the discontinuities of a large scene takes minutes); what the discontinuities
    /// add is checked once they are found, when the mesh is built.
    pub(crate) fn of(scene: &Scene, options: &RunOptions) -> Result<Plan, RunError> {
        let at_least = polygon_minimum(scene);
        let surfaces = scene.surfaces.len();
        let planned_elements = options.planned_elements(scene)?;
        let initial_budget = initial_budget(options);
        initial_budget
            .resolve(at_least, surfaces)
            .map_err(RunError::InitialBudget)?;
        let mut plan = Plan {
            planned_elements,
            initial_budget,
            limit: options.memory_limit.or_else(memory::available_bytes),
            estimate: MemoryEstimate::default(),
        };
        let counts =
            MeshCounts::predicted(scene, planned_elements, options.solver.elements_per_patch);
        plan.estimate = plan.check(scene, options, counts)?;
        Ok(plan)
    }

    /// The estimate for a mesh of `counts`, or [`RunError::Memory`] with what would fit when
    /// it exceeds the limit.
    pub(crate) fn check(
        &self,
        scene: &Scene,
        options: &RunOptions,
        counts: MeshCounts,
    ) -> Result<MemoryEstimate, RunError> {
        let estimate = memory::estimate(scene, options, counts);
        match self.limit {
            Some(limit) if estimate.total() > limit => Err(RunError::Memory {
                needed: estimate.total(),
                limit,
                suggestion: memory::largest_fitting_budget(
                    scene,
                    options,
                    self.planned_elements.max(counts.triangles as usize),
                    limit,
                ),
                link_tol: memory::least_fitting_link_tol(scene, options, counts, limit),
            }),
            _ => Ok(estimate),
        }
    }

    /// The estimate once `mesh` is built, before the solver allocates: its real counts, and
    /// with adaptive refinement the mesh grown to `budget` (the largest of those and the plan).
    pub(crate) fn check_built(
        &self,
        scene: &Scene,
        options: &RunOptions,
        mesh: &SceneMesh,
        budget: usize,
    ) -> Result<MemoryEstimate, RunError> {
        let per_patch = options.solver.elements_per_patch;
        let built = self.check(scene, options, MeshCounts::of_mesh(mesh, per_patch))?;
        if options.refine.is_none() {
            return Ok(built);
        }
        let grown = self.check(
            scene,
            options,
            MeshCounts::predicted(scene, budget, per_patch),
        )?;
        Ok([self.estimate.clone(), grown]
            .into_iter()
            .fold(
                built,
                |most, e| {
                    if e.total() > most.total() { e } else { most }
                },
            ))
    }

    /// The whole run's budget, resolved now that the first mesh and the scene's least mesh
    /// are known: the mesh's own, or what refinement may grow it to. A shard meshing some of a
    /// large scene's surfaces alone, `share` of the run's estimated cost, fits the budget to
    /// them ([`ElementBudget::part`]).
    pub(crate) fn final_budget(
        &self,
        options: &RunOptions,
        mesh: &SceneMesh,
        surfaces: usize,
        share: Option<f64>,
    ) -> Result<usize, RunError> {
        if options.refine.is_none() && !options.error_driven() {
            return Ok(mesh.budget);
        }
        let part = share
            .and_then(|share| (options.max_elements).part(mesh.minimum_triangles, surfaces, share));
        let resolved = match part {
            Some(part) => part,
            None => options.max_elements.resolve_for(
                mesh.minimum_triangles,
                surfaces,
                mesh.discontinuity_stats.is_some(),
            )?,
        };
        Ok(resolved.max(mesh.triangle_count()))
    }
}

/// The budget of the first mesh. Error-driven meshes start from a share of the run's budget
/// and spend the rest where the measured error is largest (the least mesh when that is more:
/// the final budget refuses what does not fit); adaptive refinement starts from its own
/// initial budget, or the scene's least mesh when that is more.
fn initial_budget(options: &RunOptions) -> ElementBudget {
    let share = if options.solver.direct_only {
        0.0
    } else {
        BASE_SHARE
    };
    match (&options.refine, options.max_elements) {
        (None, budget) if options.error_driven() => ElementBudget::Fit {
            at_least: (budget_floor(budget) as f64 * share) as usize,
            per_surface: 0,
        },
        (None, budget) => budget,
        (Some(r), ElementBudget::AtMost(n)) => ElementBudget::AtMost(r.initial_elements.min(n)),
        (Some(r), ElementBudget::Fit { .. }) => ElementBudget::Fit {
            at_least: r.initial_elements,
            per_surface: 0,
        },
    }
}

/// The triangles a budget asks for at least: its cap, or its floor.
fn budget_floor(budget: ElementBudget) -> usize {
    match budget {
        ElementBudget::AtMost(n) | ElementBudget::Fit { at_least: n, .. } => n,
    }
}

/// Whether meshing failed because the starting mesh of adaptive refinement does not fit its
/// budget, though the scene fits the run's.
pub(crate) fn initial_budget_too_small(options: &RunOptions, error: &MeshError) -> bool {
    matches!(error, MeshError::BudgetTooSmall { needed, .. }
        if options.refine.is_some()
            && options.max_elements.at_most().is_none_or(|n| *needed <= n))
}
