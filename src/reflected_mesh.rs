//! Refinement for the light reflected more than once. Error-driven meshes follow the exact
//! direct light; in a full solution the light that comes back from the other surfaces needs
//! triangles of its own where it bends (under a lit sphere, across a wall the sphere lights).
//! After the first solve, each round estimates every triangle's interpolation error of that
//! light from the jumps of its gradient across the triangle's edges, splits the worst (largest
//! squared error over the area) by conforming longest-edge bisection, and hands the mesh back to
//! the hierarchical solver, whose links stay and whose new vertices get the exact direct light
//! and gather along them.
//!
//! The reflected light is smooth, so no triangle smaller than the budget's typical element is
//! split for it, and slivers (which the direct light's discontinuities leave, and whose
//! gradients read the gather's noise) are not judged: the error falls as the budget grows, and
//! the noise is not chased.

use penumbra_meshing::{BisectionMesh, SceneMesh, Split, SurfaceMesh};
use penumbra_scenes::{Rgb, Scene, Visibility};
use penumbra_solver::estimate::gradient_jump_estimate;
use penumbra_solver::hierarchical::{Round, solve_hierarchical_refining};
use penumbra_solver::{Progress, Solution, SolveError, SolverOptions};
use serde::Serialize;

/// Rounds of refinement at most: each takes at most a third of the room left.
const MAX_ROUNDS: usize = 4;

/// A round is not worth its new discretization and gather with less room than this share of
/// the budget, or fewer triangles to split than [`LEAST_SPLITS_SHARE`] of it (CornellBox-Lucy's
/// last few: a round for three splits took 130 MB more).
const LEAST_ROUND_SHARE: f64 = 0.01;
const LEAST_SPLITS_SHARE: f64 = 0.002;

/// A surface whose light is darker than this share of the scene's mean is held to the
/// tolerance of one that bright (as for the direct light).
const DARK_SHARE: f64 = 0.1;

/// What refinement for the reflected light did (`mesh_error.reflected` in `report.json`).
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct ReflectedRefinement {
    /// Rounds that split triangles.
    pub rounds: usize,
    /// Triangles split for the reflected light (each split adds two or more).
    pub split: usize,
    /// Triangles before.
    pub triangles_before: usize,
    /// Triangles after.
    pub triangles: usize,
}

/// Solves `mesh` with the hierarchical solver, then refines it where the light reflected more
/// than once is interpolated worst, up to `budget` triangles or until every surface's estimated
/// RMS error of that light is within `tolerance` of its mean reflected light (B − E). `mesh`
/// becomes the refined mesh.
pub fn refine_reflected(
    scene: &Scene,
    visibility: &Visibility,
    mesh: &mut SceneMesh,
    budget: usize,
    tolerance: f64,
    options: &SolverOptions,
    progress: &dyn Progress,
) -> Result<(ReflectedRefinement, Solution), SolveError> {
    let mut done = ReflectedRefinement {
        triangles_before: mesh.triangle_count(),
        ..ReflectedRefinement::default()
    };
    let element = reflecting_area(scene, mesh) / budget.max(1) as f64;
    let first: &SceneMesh = mesh;
    // The latest round's mesh, once one was refined.
    let mut latest: Option<SceneMesh> = None;
    let mut next = |round: &Round| -> Result<Option<SceneMesh>, SolveError> {
        let current = latest.as_ref().unwrap_or(first);
        let room = budget.saturating_sub(current.triangle_count());
        if done.rounds == MAX_ROUNDS
            || options.stop_now().is_some()
            || (room as f64) < LEAST_ROUND_SHARE * budget as f64
        {
            return Ok(None);
        }
        let worst = worst_triangles(scene, round, tolerance, element);
        if (worst.len() as f64) < LEAST_SPLITS_SHARE * budget as f64 {
            return Ok(None);
        }
        // A split adds two triangles and its propagation a few more: a round takes at most a
        // third of the room, and halves that until it fits.
        let mut take = worst.len().min(room / 3);
        let (refined, split) = loop {
            if take == 0 {
                return Ok(None);
            }
            let (refined, split) = split_worst(current, &worst[..take]);
            if refined.triangle_count() <= budget {
                break (refined, split);
            }
            take /= 2;
        };
        if split == 0 {
            return Ok(None);
        }
        done.rounds += 1;
        done.split += split;
        latest = Some(refined.clone());
        Ok(Some(refined))
    };
    let (refined, solution) =
        solve_hierarchical_refining(scene, first, visibility, options, progress, &mut next)?;
    *mesh = refined;
    done.triangles = mesh.triangle_count();
    Ok((done, solution))
}

/// The area of the surfaces that reflect.
fn reflecting_area(scene: &Scene, mesh: &SceneMesh) -> f64 {
    mesh.surfaces
        .iter()
        .filter(|m| scene.surfaces[m.surface].reflectance.mean() > 0.0)
        .map(SurfaceMesh::area)
        .sum()
}

/// The triangles worth splitting, worst first, as (surface, triangle): those of surfaces whose
/// estimated RMS error of the reflected light is over `tolerance` of their mean, no smaller than
/// `element`, and not slivers.
fn worst_triangles(
    scene: &Scene,
    round: &Round,
    tolerance: f64,
    element: f64,
) -> Vec<(usize, usize)> {
    let estimates: Vec<SurfaceEstimate> = round
        .meshes
        .iter()
        .filter(|m| scene.surfaces[m.surface].reflectance.mean() > 0.0)
        .map(|m| {
            let s = m.surface;
            SurfaceEstimate::of(scene, m, &round.radiosity[s], &round.direct[s])
        })
        .collect();
    let (light, area) = estimates
        .iter()
        .fold((0.0, 0.0), |(l, a), e| (l + e.mean * e.area, a + e.area));
    let dark = DARK_SHARE * light / area.max(f64::MIN_POSITIVE);
    let mut worst: Vec<(f64, usize, usize)> = Vec::new();
    for e in &estimates {
        let target = tolerance * e.mean.max(dark);
        let squared: f64 = e.squared.iter().sum();
        if squared <= target * target * e.area {
            continue;
        }
        let m = &round.meshes[e.surface];
        worst.extend(
            (0..m.triangle_count())
                .filter(|&t| e.squared[t] > 0.0 && m.triangle_area(t) >= element)
                .map(|t| (e.squared[t], e.surface, t)),
        );
    }
    worst.sort_by(|a, b| b.0.total_cmp(&a.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    worst.into_iter().map(|(_, s, t)| (s, t)).collect()
}

/// One surface's reflected light and its estimated interpolation error.
pub(crate) struct SurfaceEstimate {
    pub surface: usize,
    /// The mean of the light it reflects (B − E, channel mean), W/m².
    pub mean: f64,
    pub area: f64,
    /// Each triangle's squared error of the light reflected more than once, integrated over
    /// it: its gradient's largest jump across the triangle's edges times the edge's length over
    /// 8 ([`gradient_jump_estimate`]), squared, times the area.
    pub squared: Vec<f64>,
}

impl SurfaceEstimate {
    /// From the radiosity `b` at the vertices of `m` and its direct part `direct`
    /// (E + ρ H_direct).
    pub(crate) fn of(scene: &Scene, m: &SurfaceMesh, b: &[Rgb], direct: &[Rgb]) -> Self {
        let emission = scene.surfaces[m.surface].emission;
        let again: Vec<f64> = b
            .iter()
            .zip(direct)
            .map(|(&b, &d)| (b - d).mean())
            .collect();
        let jumps = gradient_jump_estimate(m, &again);
        let (mut sum, mut area) = (0.0, 0.0);
        let squared = (0..m.triangle_count())
            .map(|t| {
                let a = m.triangle_area(t);
                let tri = m.triangles[t];
                sum += a * tri
                    .iter()
                    .map(|&v| (b[v as usize] - emission).mean())
                    .sum::<f64>()
                    / 3.0;
                area += a;
                jumps[t] * jumps[t] * a
            })
            .collect();
        SurfaceEstimate {
            surface: m.surface,
            mean: sum / area.max(f64::MIN_POSITIVE),
            area,
            squared,
        }
    }
}

/// `mesh` with the `worst` triangles split (a triangle a split before it cut down is passed
/// over), and how many were.
fn split_worst(mesh: &SceneMesh, worst: &[(usize, usize)]) -> (SceneMesh, usize) {
    let mut refined = mesh.clone();
    let mut by_surface: Vec<Vec<usize>> = vec![Vec::new(); mesh.surfaces.len()];
    for &(s, t) in worst {
        by_surface[s].push(t);
    }
    let mut split = 0;
    for (s, triangles) in by_surface.into_iter().enumerate() {
        if triangles.is_empty() {
            continue;
        }
        let mut bisection = BisectionMesh::new(mesh.surfaces[s].clone());
        let mut changed = vec![false; mesh.surfaces[s].triangle_count()];
        let mut out = Split::default();
        for t in triangles {
            if changed[t] || bisection.too_small(t) {
                continue;
            }
            out.triangles.clear();
            bisection.split(t, &mut out);
            split += 1;
            for &c in &out.triangles {
                if let Some(flag) = changed.get_mut(c as usize) {
                    *flag = true;
                }
            }
        }
        refined.surfaces[s] = bisection.into_mesh();
    }
    (refined, split)
}
