//! Memory: what a run will need, what the machine can give it, and what the run used.
//!
//! A run that needs more memory than there is fails before the work starts, with the estimate
//! and the largest `--max-elements` that would fit, instead of being killed half-way. The
//! estimate is checked twice: from the scene and the budget before anything is built, then from
//! the mesh's real counts before the solver allocates its form factors.
//!
//! The per-item costs are measured peaks (`docs/benchmarks.md`, "Large scenes"), rounded up;
//! the form-factor terms are upper bounds from the data structures (every vertex seeing every
//! patch).

use penumbra_meshing::SceneMesh;
use penumbra_scenes::Scene;
use penumbra_solver::SolverMethod;
use penumbra_solver::coupling::FormFactorMethod;
use serde::Serialize;

use crate::options::RunOptions;

/// The process itself, its buffers and the allocator's slack.
const BASE_BYTES: u64 = 32 << 20;
/// Per scene polygon: the polygon, its BVH triangles, its discontinuity lists and its mesh's
/// fixed parts.
const BYTES_PER_POLYGON: u64 = 4 << 10;
/// Per mesh triangle, with its share of vertices: the constrained triangulation, the mesh, the
/// solver's per-vertex and per-element state.
const BYTES_PER_TRIANGLE: u64 = 2 << 10;
/// Per rendered pixel: colour, depth and surface buffers.
const BYTES_PER_PIXEL: u64 = 64;

/// How big a mesh is, for the estimate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct MeshCounts {
    /// Triangles over all surfaces.
    pub triangles: u64,
    /// Vertices over all surfaces (the solver's receivers).
    pub vertices: u64,
    /// The solver's shooting patches: groups of `elements_per_patch` triangles of a surface.
    pub patches: u64,
}

impl MeshCounts {
    /// Roughly the mesh of `max_elements` triangles over `scene`, before it is built:
    /// every polygon gets at least its own triangles, and split vertices along contact lines
    /// can make vertices outnumber triangles.
    pub fn predicted(scene: &Scene, max_elements: usize, elements_per_patch: usize) -> MeshCounts {
        let polygons = scene.surfaces.len() as u64;
        let minimum = penumbra_meshing::polygon_minimum(scene) as u64;
        let triangles = (max_elements as u64).max(minimum);
        MeshCounts {
            triangles,
            vertices: triangles + 2 * polygons,
            patches: triangles / elements_per_patch.max(1) as u64 + polygons,
        }
    }

    /// The counts of a built mesh; patches as the solver groups triangles, before the rare
    /// extra patches where a group falls apart along a contact line.
    pub fn of_mesh(mesh: &SceneMesh, elements_per_patch: usize) -> MeshCounts {
        MeshCounts {
            triangles: mesh.triangle_count() as u64,
            vertices: mesh.vertex_count() as u64,
            patches: mesh
                .surfaces
                .iter()
                .map(|m| {
                    m.triangle_count()
                        .div_ceil(elements_per_patch.max(1))
                        .max(1) as u64
                })
                .sum(),
        }
    }
}

/// Bytes a run needs, in parts (`memory.estimate` in `report.json`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct MemoryEstimate {
    /// The scene: a fixed amount per surface (its polygon, BVH triangles, discontinuity lists
    /// and mesh's fixed parts).
    pub scene: u64,
    /// The mesh and the solver's data for it: a fixed amount per triangle.
    pub mesh: u64,
    /// Form factors kept by the solver: the hemicube's rows (progressive refinement with a
    /// hemicube), the patch matrix (gathering and dense solves), the hierarchical solver's
    /// links; 0 for direct light only and for progressive refinement otherwise, whose column
    /// cache only takes what is left
    /// ([`MemoryReport::cache_bytes`](crate::pipeline::MemoryReport::cache_bytes)).
    pub form_factors: u64,
    /// The render: a fixed amount per pixel.
    pub render: u64,
}

impl MemoryEstimate {
    /// Bytes in all: the parts, and a fixed base for the process itself, its buffers and the
    /// allocator's slack. Saturates rather than overflows.
    pub fn total(&self) -> u64 {
        BASE_BYTES
            .saturating_add(self.scene)
            .saturating_add(self.mesh)
            .saturating_add(self.form_factors)
            .saturating_add(self.render)
    }
}

/// What a run of `options` over `scene` with a mesh of `counts` needs, in bytes: [`crate::run`]
/// checks it against the memory limit with [`MeshCounts::predicted`] before meshing, and with
/// [`MeshCounts::of_mesh`] before solving. The progressive solver's column cache is left out:
/// it only uses what is left.
pub fn estimate(scene: &Scene, options: &RunOptions, counts: MeshCounts) -> MemoryEstimate {
    let solver = &options.solver;
    let (v, p) = (counts.vertices, counts.patches);
    let form_factors = if solver.direct_only {
        0
    } else {
        // Sparse columns: a vertex and factor (8 bytes) for each pair that sees each other.
        let columns = |seen_per_vertex: u64| v.saturating_mul(seen_per_vertex).saturating_mul(8);
        let matrix = p.saturating_mul(p).saturating_mul(8);
        match (options.method, solver.form_factors) {
            (SolverMethod::Progressive, FormFactorMethod::Hemicube { resolution }) => {
                // No more patches than pixels can be seen from a vertex.
                let r = resolution as u64;
                columns(p.min(3 * r * r))
            }
            (SolverMethod::Progressive, _) => 0,
            (SolverMethod::Hierarchical, _) => penumbra_solver::hierarchical::estimated_bytes(
                counts.triangles,
                scene.surfaces.len() as u64,
                solver.link_tol,
            ),
            // About two landings per photon, each a position, a power and its tree's share, and
            // for a final gather an estimate made in advance at every fourth.
            (SolverMethod::PhotonMap, _) => {
                let per_photon = if solver.photon_map.final_gather > 0 {
                    180
                } else {
                    144
                };
                (solver.photon_map.photons as u64).saturating_mul(per_photon)
            }
            // K per channel, plus its copy under elimination.
            (SolverMethod::Direct, _) => columns(p).saturating_add(matrix.saturating_mul(4)),
            _ => columns(p).saturating_add(matrix.saturating_mul(3)),
        }
    };
    let pixels = u64::from(options.render.width) * u64::from(options.render.height);
    MemoryEstimate {
        scene: (scene.surfaces.len() as u64).saturating_mul(BYTES_PER_POLYGON),
        mesh: counts.triangles.saturating_mul(BYTES_PER_TRIANGLE),
        form_factors,
        render: pixels.saturating_mul(BYTES_PER_PIXEL),
    }
}

/// The progressive solver's column cache: what it asks for, within half of what the estimate
/// leaves of `limit`.
pub(crate) fn cache_bytes(requested: usize, needed: u64, limit: u64) -> usize {
    let spare = limit.saturating_sub(needed) / 2;
    usize::try_from(spare).map_or(requested, |spare| requested.min(spare))
}

/// With the hierarchical solver, the least link tolerance (above the run's) at which the
/// estimate for a mesh of `counts` fits in `limit`, rounded up to two digits; `None` for other
/// solvers, or when even the coarsest links do not fit (the nodes and the mesh alone are too
/// many).
pub(crate) fn least_fitting_link_tol(
    scene: &Scene,
    options: &RunOptions,
    counts: MeshCounts,
    limit: u64,
) -> Option<f64> {
    if options.method != SolverMethod::Hierarchical || options.solver.direct_only {
        return None;
    }
    let fits = |link_tol: f64| {
        let trial = RunOptions {
            solver: penumbra_solver::SolverOptions {
                link_tol,
                ..options.solver.clone()
            },
            ..options.clone()
        };
        estimate(scene, &trial, counts).total() <= limit
    };
    let (mut lo, mut hi) = (options.solver.link_tol, 0.5);
    if !fits(hi) {
        return None;
    }
    // The estimate falls as the tolerance grows: bisect on its logarithm.
    for _ in 0..50 {
        let mid = (lo * hi).sqrt();
        if fits(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let digits = 10f64.powi(hi.log10().floor() as i32 - 1);
    Some((hi / digits).ceil() * digits)
}

/// The largest element budget at most `max_elements` whose predicted estimate fits in `limit`,
/// if any does.
pub(crate) fn largest_fitting_budget(
    scene: &Scene,
    options: &RunOptions,
    max_elements: usize,
    limit: u64,
) -> Option<usize> {
    let fits = |elements: usize| {
        let counts = MeshCounts::predicted(scene, elements, options.solver.elements_per_patch);
        estimate(scene, options, counts).total() <= limit
    };
    if !fits(1) {
        return None;
    }
    let (mut lo, mut hi) = (1usize, max_elements.max(1));
    if fits(hi) {
        return Some(hi);
    }
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if fits(mid) { lo = mid } else { hi = mid }
    }
    // A round number a user would type.
    Some(round_down(lo))
}

/// `n` with only its two leading digits kept.
fn round_down(n: usize) -> usize {
    let mut unit = 1;
    while n / unit >= 100 {
        unit *= 10;
    }
    n / unit * unit
}

/// Bytes this process may still use: the machine's available memory, or its control group's
/// limit when that is lower. `None` where the system does not say (not Linux).
pub fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let machine = kib_field(&meminfo, "MemAvailable:")?;
    let group = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|max| max.trim().parse::<u64>().ok())
        .map(|max| {
            let used = std::fs::read_to_string("/sys/fs/cgroup/memory.current")
                .ok()
                .and_then(|c| c.trim().parse::<u64>().ok())
                .unwrap_or(0);
            max.saturating_sub(used)
        });
    Some(group.map_or(machine, |g| g.min(machine)))
}

/// The most memory this process has held so far (its peak resident set), if the system says.
pub fn peak_resident_bytes() -> Option<u64> {
    kib_field(
        &std::fs::read_to_string("/proc/self/status").ok()?,
        "VmHWM:",
    )
}

/// A `NAME: <n> kB` line of a /proc file, in bytes.
fn kib_field(text: &str, name: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kib: u64 = line[name.len()..]
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    kib.checked_mul(1024)
}

/// Bytes as a person reads them: "1.5 GiB", "340 MiB".
pub fn human(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if value >= 100.0 || unit == 0 {
        format!("{value:.0} {}", UNITS[unit])
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_of_proc_files_are_read_in_bytes() {
        let text = "MemTotal:       24000000 kB\nMemAvailable:   1000 kB\n";
        assert_eq!(kib_field(text, "MemAvailable:"), Some(1_024_000));
        assert_eq!(kib_field(text, "Missing:"), None);
        assert_eq!(kib_field("VmHWM: x kB", "VmHWM:"), None);
    }

    #[test]
    fn suggestions_are_round_and_below_the_number() {
        assert_eq!(round_down(123_456), 120_000);
        assert_eq!(round_down(99), 99);
        assert_eq!(round_down(1_000), 1_000);
        assert_eq!(human(3 << 30), "3.0 GiB");
        assert_eq!(human(512), "512 B");
    }

    #[test]
    fn the_suggested_budget_fits_and_a_larger_one_does_not() {
        let scene = penumbra_scenes::builtin::builtin("cornell").expect("built in");
        let options = RunOptions {
            method: SolverMethod::GaussSeidel,
            ..RunOptions::default()
        };
        let limit = 2u64 << 30;
        let fits = |n: usize| {
            let counts = MeshCounts::predicted(&scene, n, options.solver.elements_per_patch);
            estimate(&scene, &options, counts).total() <= limit
        };
        let best = largest_fitting_budget(&scene, &options, 10_000_000, limit)
            .expect("a mesh fits in 2 GiB");
        assert!(fits(best) && !fits(best * 11 / 10), "{best}");
        // Gathering keeps every vertex-patch factor, which grows as the square of the mesh:
        // it fits far fewer elements than shooting.
        let shooting = RunOptions {
            method: SolverMethod::Progressive,
            ..options.clone()
        };
        let most = largest_fitting_budget(&scene, &shooting, 10_000_000, limit).expect("fits");
        assert!(most > 5 * best, "{most} vs {best}");
        assert_eq!(
            largest_fitting_budget(&scene, &options, 10_000_000, 1 << 20),
            None
        );
    }
}
