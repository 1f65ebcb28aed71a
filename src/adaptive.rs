//! Adaptive refinement: split the triangles whose linear interpolation misses the exact direct
//! radiosity by more than a tolerance, round after round, within the element budget.
//!
//! Each round solves the direct light exactly at every vertex, measures each triangle's residual
//! at its edge midpoints and centroid ([`penumbra_solver::estimate`]), and splits the triangles
//! over the tolerance, largest share of the squared error first, by longest-edge bisection in the surface's constrained
//! triangulation: never across a discontinuity, with quality restored around the splits.

use penumbra_meshing::SceneMesh;
use penumbra_scenes::{Scene, Visibility};
use penumbra_solver::estimate::{ResidualSummary, direct_residuals, summarize};
use penumbra_solver::{DirectLight, NoProgress, SolveError, SolverOptions, solve_progressive};
use serde::Serialize;

/// How adaptive refinement runs.
#[derive(Clone, Debug, PartialEq)]
pub struct RefineOptions {
    /// Split triangles whose residual exceeds this fraction of the scene's mean radiosity.
    pub tolerance: f64,
    /// Triangles of the mesh refinement starts from (the budget caps where it ends).
    pub initial_elements: usize,
    /// Rounds at most.
    pub max_rounds: usize,
}

/// Why refinement stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
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
}

/// One round: the residuals found, and what was split.
#[derive(Clone, Debug, Serialize)]
pub struct RefineRound {
    pub triangles: usize,
    pub residual: ResidualSummary,
    /// Triangles over the tolerance, and how many of them were split.
    pub over_tolerance: usize,
    pub split: usize,
}

/// What adaptive refinement did.
#[derive(Clone, Debug, Serialize)]
pub struct RefineReport {
    pub tolerance: f64,
    pub rounds: Vec<RefineRound>,
    pub stop: RefineStop,
    /// The residuals of the final mesh.
    pub residual: ResidualSummary,
}

/// Refines `mesh` adaptively within `max_elements` triangles.
pub fn refine_adaptively(
    scene: &Scene,
    visibility: &Visibility,
    mesh: &mut SceneMesh,
    max_elements: usize,
    options: &RefineOptions,
    solver: &SolverOptions,
) -> Result<RefineReport, SolveError> {
    let direct = DirectLight::new(scene, visibility);
    let direct_only = SolverOptions {
        direct_only: true,
        ..solver.clone()
    };
    let mut rounds = Vec::new();
    let mut stop = RefineStop::Rounds;
    let mut residual = ResidualSummary::default();
    for round in 0..=options.max_rounds {
        let solution = solve_progressive(scene, mesh, visibility, &direct_only, &NoProgress)?;
        let residuals: Vec<Vec<f64>> = mesh
            .surfaces
            .iter()
            .map(|m| direct_residuals(scene, &direct, m, &solution.radiosity[m.surface]))
            .collect();
        residual = summarize(&mesh.surfaces, &solution.radiosity, &residuals);
        let tolerance = options.tolerance * residual.mean_radiosity;
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
            residual,
            over_tolerance: over.len(),
            split: 0,
        };
        if over.is_empty() {
            rounds.push(this);
            stop = RefineStop::Tolerance;
            break;
        }
        if round == options.max_rounds {
            rounds.push(this);
            break;
        }
        if solver
            .deadline
            .is_some_and(|d| std::time::Instant::now() >= d)
        {
            rounds.push(this);
            stop = RefineStop::TimeBudget;
            break;
        }
        // Largest share of the squared error (residual squared times area) first. A split adds
        // about two triangles and quality refinement a few more, so a round takes at most a
        // third of the room left, and halves that until it fits.
        for o in over.iter_mut() {
            o.0 = o.0 * o.0 * mesh.surfaces[o.1].triangle_area(o.2);
        }
        over.sort_by(|a, b| b.0.total_cmp(&a.0).then((a.1, a.2).cmp(&(b.1, b.2))));
        let room = max_elements.saturating_sub(mesh.triangle_count());
        let mut take = over.len().min(room / 3);
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
        rounds.push(this);
        match refined {
            Some(m) if m.triangle_count() > mesh.triangle_count() => *mesh = m,
            _ => {
                stop = RefineStop::Budget;
                break;
            }
        }
    }
    Ok(RefineReport {
        tolerance: options.tolerance,
        rounds,
        stop,
        residual,
    })
}
