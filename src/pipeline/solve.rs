//! The solve stage's choice of solver, and the least mesh a run keeps when it stops before
//! any mesh has values.

use std::time::{Duration, Instant};

use penumbra_meshing::{ElementBudget, SceneMesh, mesh_scene_uniform, polygon_minimum};
use penumbra_scenes::{Scene, Visibility};
use penumbra_solver::photon_map::solve_photon_map;
use penumbra_solver::{
    NoProgress, Progress, Solution, SolverMethod, SolverOptions, solve_direct_on, solve_gathering,
    solve_hierarchical, solve_progressive,
};

use crate::adaptive::{RefineReport, refine_adaptively, refine_hierarchically};
use crate::error_mesh::MeshErrorReport;
use crate::options::RunOptions;
use crate::reflected_mesh::refine_reflected;
use crate::run_error::RunError;

/// A mesh, the budget it may grow to, and what error-driven refinement measured of it.
pub(crate) struct Meshed {
    /// The mesh.
    pub(crate) mesh: SceneMesh,
    /// The run's element budget, resolved.
    pub(crate) budget: usize,
    /// Error-driven meshes: what refinement did and measured.
    pub(crate) mesh_error: Option<MeshErrorReport>,
}

/// A solution, and what adaptive refinement did to reach it.
pub(crate) struct Solved {
    /// The solution.
    pub(crate) solution: Solution,
    /// Adaptive refinement's report, if it was asked for.
    pub(crate) refinement: Option<RefineReport>,
}

/// Solves on `meshed` with the solver `options` choose, refining the mesh where they ask for
/// it (adaptive refinement; error-driven meshes again for the light reflected more than once).
/// A shard lights only its own surfaces, `shard_surfaces`.
pub(crate) fn solve_with(
    scene: &Scene,
    visibility: &Visibility,
    meshed: &mut Meshed,
    options: &RunOptions,
    shard_surfaces: Option<&[bool]>,
    solver: &SolverOptions,
    progress: &dyn Progress,
) -> Result<Solved, RunError> {
    let mesh = &mut meshed.mesh;
    let plain = |solution| Solved {
        solution,
        refinement: None,
    };
    let hierarchical = options.method == SolverMethod::Hierarchical && !solver.direct_only;
    if let Some(refine) = &options.refine {
        let refine_with = match hierarchical {
            true => refine_hierarchically,
            false => refine_adaptively,
        };
        let (report, solution) = refine_with(
            scene,
            visibility,
            mesh,
            meshed.budget,
            refine,
            solver,
            progress,
        )?;
        return Ok(Solved {
            solution,
            refinement: Some(report),
        });
    }
    if let Some(on) = shard_surfaces {
        // Every surface is meshed as in a whole run (each one's share of the budget depends on
        // all of them, and the direct light at a point shared by several surfaces is evaluated
        // once for all); only the shard's vertices are lit.
        let solution = solve_direct_on(scene, mesh, visibility, solver, on, progress)?;
        return Ok(plain(solution));
    }
    let solution = match options.method {
        _ if solver.direct_only => solve_progressive(scene, mesh, visibility, solver, progress)?,
        SolverMethod::Progressive => solve_progressive(scene, mesh, visibility, solver, progress)?,
        // Error-driven meshes are refined again for the light reflected more than once.
        SolverMethod::Hierarchical if options.error_driven() => {
            let (done, solution) = refine_reflected(
                scene,
                visibility,
                mesh,
                meshed.budget,
                options.tolerance,
                solver,
                progress,
            )?;
            if let Some(report) = meshed.mesh_error.as_mut() {
                report.reflected_refinement = Some(done);
            }
            solution
        }
        SolverMethod::Hierarchical => {
            solve_hierarchical(scene, mesh, visibility, solver, progress)?
        }
        SolverMethod::PhotonMap => solve_photon_map(scene, mesh, visibility, solver, progress)?,
        method => solve_gathering(scene, mesh, visibility, solver, method, progress)?,
    };
    Ok(plain(solution))
}

/// Seconds the exact direct light of the least mesh may take when a run stops before any mesh
/// has values: what is left then is estimated with rays, so that the outputs are written within
/// the second an interrupt allows.
pub const LEAST_MESH_SECONDS: f64 = 0.25;

/// The scene's least mesh (its polygons' triangles) with the direct light only: what a run
/// stopped before any mesh had values keeps. Neither the interrupt nor the run's time budget
/// stop it; [`LEAST_MESH_SECONDS`] bounds its exact part.
pub(crate) fn least_mesh_lit(
    scene: &Scene,
    visibility: &Visibility,
    solver: &SolverOptions,
) -> Result<(Meshed, Solution), RunError> {
    let least = polygon_minimum(scene);
    let mesh = mesh_scene_uniform(scene, ElementBudget::AtMost(least))?;
    let solver = SolverOptions {
        direct_only: true,
        interrupt: None,
        deadline: Instant::now().checked_add(Duration::from_secs_f64(LEAST_MESH_SECONDS)),
        ..solver.clone()
    };
    let solution = solve_progressive(scene, &mesh, visibility, &solver, &NoProgress)?;
    let meshed = Meshed {
        budget: mesh.budget,
        mesh,
        mesh_error: None,
    };
    Ok((meshed, solution))
}
