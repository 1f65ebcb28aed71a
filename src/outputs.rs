//! The files a run writes: `solution.json`, `report.json`, `render.png` and SVGs of the
//! surfaces worth looking at ([`SvgSelection`]). Each file is written to a temporary name in the
//! output directory and renamed into place, so a reader never sees half a file.

use std::io::Write;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use penumbra_meshing::{ElementBudget, MeshQuality};
use penumbra_scenes::{Rgb, Scene, SurfaceId};
use penumbra_solver::SolveStats;
use penumbra_solver::{SolverMethod, StopReason};
use serde::Serialize;

use crate::energy::EnergyBalance;
pub use crate::options::Invocation;
use crate::pipeline::{RunResult, StageTimes};

/// The `format` of `solution.json`, and its version (`docs/schemas/solution.schema.json`).
pub const SOLUTION_FORMAT: &str = "penumbra-solution/1";
/// The `format` of `report.json`, and its version (`docs/schemas/report.schema.json`).
pub const REPORT_FORMAT: &str = "penumbra-report/1";

#[derive(Serialize)]
struct SolutionFile<'a> {
    format: &'static str,
    scene: &'a str,
    surfaces: &'a [SurfaceSolution],
}

/// One surface of `solution.json`. A shard's part ([`crate::shard`]) carries each surface's
/// `index` in the scene as well; `solution.json` leaves it out.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSolution {
    /// The surface's index in the scene: in a shard's part only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub index: Option<SurfaceId>,
    /// The surface's name in the scene, unique within it.
    pub name: String,
    /// The surface's own exitance E, `[r, g, b]` in W/m² (zero unless it is a light). Absent
    /// from files of earlier versions, as are `reflectance` and `direct`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<[f64; 3]>,
    /// The surface's diffuse reflectance ρ, `[r, g, b]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reflectance: Option<[f64; 3]>,
    /// The mesh's vertices, in 3D scene coordinates and units. The two sides of a value
    /// discontinuity (a blocker touching the surface) each have their own vertex at the same
    /// position.
    pub vertices: Vec<[f64; 3]>,
    /// The mesh's triangles, as indices into `vertices`, counter-clockwise seen from the
    /// surface's front.
    pub triangles: Vec<[u32; 3]>,
    /// Radiosity B at each vertex, `[r, g, b]` in W/m², in the order of `vertices`: the
    /// surface's own emission included, the display-only ambient term left out.
    pub radiosity: Vec<[f64; 3]>,
    /// The direct light's part of the radiosity at each vertex, ρ·H_direct: what the surface
    /// reflects straight from the lights, exact. The rest of the reflected light, `radiosity`
    /// − `emission` − `direct`, came by more bounces.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direct: Option<Vec<[f64; 3]>>,
    /// Adaptive runs only: each triangle's error indicator in the last round of refinement, in
    /// W/m² (the residual the refinement split by), in the order of `triangles`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_indicator: Option<Vec<f64>>,
    /// The discontinuity segments of the direct light built into the mesh as edges (none for
    /// uniform meshes, for surfaces no shadow falls on, and for emitters).
    pub discontinuities: Vec<Discontinuity>,
}

/// A straight segment of a discontinuity line of the direct light on a surface, as
/// `solution.json` gives it (curved EEE lines come as several segments).
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Discontinuity {
    /// The segment's first end, in 3D scene coordinates, on the surface.
    pub from: [f64; 3],
    /// The segment's second end.
    pub to: [f64; 3],
    /// The visual event that makes the line: `EV`, `VE`, `EEE`, `contact`, `blocker-EV` or
    /// `horizon` ([`Event::name`](penumbra_meshing::discontinuity::Event::name)).
    pub event: String,
    /// What the line bounds: `umbra` (one side sees none of the emitter), `penumbra` (one side
    /// sees all of it) or `inner` (both sides see part of it).
    pub boundary: String,
    /// Which derivative of the direct light jumps across the line: 0 the value (contact
    /// lines), 1 the slope, 2 the curvature.
    pub order: u8,
}

/// Surface `s` of a run as `solution.json` gives it.
pub fn surface_solution(result: &RunResult, s: SurfaceId) -> SurfaceSolution {
    let m = &result.mesh.surfaces[s];
    let surface = &result.loaded.scene.surfaces[s];
    let rgb = |values: &[Rgb]| values.iter().map(|c| c.to_array()).collect();
    SurfaceSolution {
        index: None,
        name: surface.name.clone(),
        emission: Some(surface.emission.to_array()),
        reflectance: Some(surface.reflectance.to_array()),
        vertices: m.points3.iter().map(|p| p.to_array()).collect(),
        triangles: m.triangles.clone(),
        radiosity: rgb(&result.solution.radiosity[s]),
        direct: Some(rgb(&result.reflected_parts(s).0)),
        error_indicator: result
            .refinement
            .as_ref()
            .and_then(|r| r.triangle_residuals.get(s).cloned()),
        discontinuities: result.mesh.discontinuities[m.surface]
            .iter()
            .map(|g| Discontinuity {
                from: g.from.to_array(),
                to: g.to.to_array(),
                event: g.event.name().to_owned(),
                boundary: g.boundary.name().to_owned(),
                order: g.order,
            })
            .collect(),
    }
}

/// `solution.json`: per surface in the scene's order, its mesh's vertices and triangles, the
/// radiosity at every vertex (no display-only ambient term) and its discontinuity segments;
/// pretty-printed, with a final newline.
pub fn solution_json(result: &RunResult) -> String {
    let surfaces: Vec<SurfaceSolution> = (0..result.mesh.surfaces.len())
        .map(|s| surface_solution(result, s))
        .collect();
    solution_json_of(&result.loaded.scene.name, &surfaces)
}

/// `solution.json` of scene `scene` from its surfaces, in the scene's order.
pub fn solution_json_of(scene: &str, surfaces: &[SurfaceSolution]) -> String {
    to_json(&SolutionFile {
        format: SOLUTION_FORMAT,
        scene,
        surfaces,
    })
}

/// The version of penumbra that wrote a report.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

#[derive(Serialize)]
struct Report<'a> {
    format: &'static str,
    /// The version of penumbra that made the run.
    version: &'static str,
    /// The command line and every option, when the run came from one.
    #[serde(skip_serializing_if = "Option::is_none")]
    invocation: Option<&'a Invocation>,
    /// The run was cut short (interrupted, or its time budget spent): the solution is the best
    /// so far, not a converged one, or its mesh lacks the events of the emitter–receiver pairs
    /// the discontinuity search had no time for.
    partial: bool,
    scene: SceneSummary<'a>,
    /// The loader's warnings, then the run's (an energy balance that does not close).
    warnings: Vec<String>,
    method: Method,
    counts: Counts,
    discontinuities: Option<&'a penumbra_meshing::discontinuity::DiscontinuityStats>,
    /// Adaptive refinement: rounds, residuals and why it stopped (absent when not asked for).
    #[serde(skip_serializing_if = "Option::is_none")]
    refinement: Option<&'a crate::adaptive::RefineReport>,
    /// Error-driven meshes: the interpolation error of the direct light measured at every
    /// triangle's check points, per surface and for the scene, and why refinement stopped
    /// (absent for other meshes).
    #[serde(skip_serializing_if = "Option::is_none")]
    mesh_error: Option<&'a crate::error_mesh::MeshErrorReport>,
    times_seconds: &'a StageTimes,
    /// Estimated need, the limit it was checked against, and the peak after each stage.
    memory: &'a crate::pipeline::MemoryReport,
    solver: &'a SolveStats,
    energy: EnergyBalance,
    mesh_quality: MeshQuality,
    render: RenderSummary,
    svgs: SvgSummary,
}

/// Which surfaces got an SVG, and why.
#[derive(Serialize)]
struct SvgSummary {
    /// `auto` (the surfaces worth looking at), `all`, `none` or `named`.
    selection: &'static str,
    /// The files written, relative to the output directory, in surface order.
    written: Vec<String>,
}

#[derive(Serialize)]
struct SceneSummary<'a> {
    name: &'a str,
    source: &'a str,
    /// A hash of every number of the scene as loaded: a replay checks it found the same scene.
    fingerprint: String,
    surfaces: usize,
    emitters: usize,
    bounding_box_diagonal: f64,
}

#[derive(Serialize)]
struct Method {
    /// The mesh that was built (`auto` chooses by whether the scene casts shadows).
    mesh: &'static str,
    mesh_requested: crate::options::MeshMethod,
    solver: &'static str,
    /// The element budget used: the mesh's, or the cap of adaptive refinement.
    max_elements: usize,
    /// What was asked for: `"fit"` (the default: what the scene needs) or a number.
    max_elements_requested: BudgetRequested,
    penumbra_density: f64,
    /// Error-driven meshes' tolerance, relative to the scene's mean reflected direct light.
    tolerance: f64,
    /// The smallest angle discontinuity and error-driven meshes aimed for (0: none).
    min_angle: f64,
    eee: bool,
    /// Which EV and VE events: `complete` or `extremal`.
    events: penumbra_meshing::discontinuity::EventSet,
    eee_tolerance: f64,
    event_tolerance: f64,
    /// Seconds the run was allowed (absent: no limit).
    #[serde(skip_serializing_if = "Option::is_none")]
    time_budget: Option<f64>,
    epsilon: f64,
    max_shots: usize,
    visibility_rays: usize,
    form_factors: penumbra_solver::coupling::FormFactorMethod,
    elements_per_patch: usize,
    direct_only: bool,
    seed: u64,
    threads: usize,
}

#[derive(Serialize)]
struct Counts {
    triangles: usize,
    vertices: usize,
    patches: usize,
    discontinuity_segments: usize,
}

/// The element budget as asked for: `"fit"` or a number.
#[derive(Serialize)]
#[serde(untagged)]
enum BudgetRequested {
    Fit(&'static str),
    AtMost(usize),
}

impl From<ElementBudget> for BudgetRequested {
    fn from(b: ElementBudget) -> Self {
        match b {
            ElementBudget::AtMost(n) => BudgetRequested::AtMost(n),
            ElementBudget::Fit { .. } => BudgetRequested::Fit("fit"),
        }
    }
}

#[derive(Serialize)]
struct RenderSummary {
    width: u32,
    height: u32,
    exposure: f64,
    ambient: Rgb,
    /// The camera the image was made from: the scene's, or one that frames it.
    camera: penumbra_scenes::Camera,
}

/// What to say when the direct light at some vertices is an estimate by rays, not exact.
pub fn estimated_direct_warning(stats: &SolveStats) -> Option<String> {
    let late = stats.direct_estimated - stats.direct_beyond_cap;
    let mut causes = Vec::new();
    if late > 0 {
        causes.push(format!("{late} left when the time budget ran out"));
    }
    if stats.direct_beyond_cap > 0 {
        causes.push(format!(
            "{} whose view of a light needs a polygon difference too large to hold \
             (solver.direct_beyond_cap)",
            stats.direct_beyond_cap
        ));
    }
    (!causes.is_empty()).then(|| {
        format!(
            "the direct light at {} of {} vertices is estimated with rays, not exact \
             (solver.direct_estimated): {}",
            stats.direct_estimated,
            stats.receivers,
            causes.join("; ")
        )
    })
}

/// A warning when `below` of the mesh's `triangles` have angles under the aim of quality
/// refinement that the input does not force: the budget could not hold some surface's least
/// mesh at that angle, or adaptive splits (which restore smaller angles only) made them.
pub fn quality_warning(below: usize, triangles: usize, adaptive: bool) -> Option<String> {
    (below > 0).then(|| {
        let cause = if adaptive {
            format!(
                "adaptive splits restore angles of {} degrees only",
                penumbra_meshing::SPLIT_MIN_ANGLE_DEG
            )
        } else {
            "the element budget cannot hold the least mesh at that angle of every surface".into()
        };
        format!(
            "{below} of {} triangles have an angle under {} degrees that the input does not \
             force (mesh_quality.triangles_below_min_angle): {cause}",
            triangles,
            penumbra_meshing::FORCING_WEDGE_DEG
        )
    })
}

/// A warning naming the surfaces left above the tolerance when error-driven refinement stopped
/// before meeting it (the budget or the time ran out).
pub fn mesh_error_warning(report: &crate::error_mesh::MeshErrorReport) -> Option<String> {
    let above = report.above_tolerance();
    if report.stop == crate::error_mesh::ErrorStop::Tolerance || above.is_empty() {
        return None;
    }
    const NAMED: usize = 5;
    let mut names: Vec<String> = above
        .iter()
        .take(NAMED)
        .map(|s| format!("{} ({:.2} % RMS)", s.surface, 100.0 * s.rms))
        .collect();
    if above.len() > NAMED {
        names.push(format!("and {} more", above.len() - NAMED));
    }
    let why = match report.stop {
        crate::error_mesh::ErrorStop::Budget => "the element budget ran out (--max-elements)",
        crate::error_mesh::ErrorStop::TimeBudget => "the time budget ran out",
        _ => "the run was interrupted",
    };
    Some(format!(
        "{why} before the direct light's interpolation error met the tolerance of {} (RMS, \
         relative to each surface's mean) on {} surface(s): {} (mesh_error.surfaces)",
        report.tolerance,
        above.len(),
        names.join(", ")
    ))
}

/// `report.json`, for a run whose SVGs are chosen by `svgs`: how the run was made, what it
/// built, stage times, memory, the solver's figures, the energy balance, mesh quality and the
/// warnings of the loader and the run (`docs/schemas/report.schema.json`).
pub fn report_json(result: &RunResult, svgs: &SvgSelection) -> String {
    let scene = &result.loaded.scene;
    let stats = &result.solution.stats;
    let opts = &result.options;
    let energy = EnergyBalance::of(stats);
    let mut warnings = result.loaded.warnings.clone();
    warnings.extend(energy.warning());
    warnings.extend(estimated_direct_warning(stats));
    let mesh_quality = result.mesh.quality();
    // Error-driven meshes choose their triangles' shapes by the error they measure.
    if result.mesh_error.is_none() {
        warnings.extend(quality_warning(
            mesh_quality.triangles_below_min_angle,
            mesh_quality.triangles,
            result.refinement.is_some(),
        ));
    }
    warnings.extend(result.mesh_error.as_ref().and_then(mesh_error_warning));
    let report = Report {
        format: REPORT_FORMAT,
        version: VERSION,
        invocation: result.invocation.as_ref(),
        partial: matches!(stats.stop, StopReason::Interrupted | StopReason::TimeBudget)
            || result
                .mesh
                .discontinuity_stats
                .as_ref()
                .is_some_and(|d| d.pairs_skipped > 0),
        scene: SceneSummary {
            name: &scene.name,
            source: &result.loaded.source,
            fingerprint: crate::fingerprint::scene_fingerprint(&result.loaded),
            surfaces: scene.surfaces.len(),
            emitters: scene.emitters().count(),
            bounding_box_diagonal: scene.diagonal(),
        },
        warnings,
        method: Method {
            mesh: if result.mesh_error.is_some() {
                "error-driven"
            } else if result.mesh.discontinuity_stats.is_some() {
                "discontinuity"
            } else {
                "uniform"
            },
            mesh_requested: opts.mesh,
            solver: report_solver_name(result),
            max_elements: result.budget,
            max_elements_requested: opts.max_elements.into(),
            penumbra_density: opts.penumbra_density,
            tolerance: opts.tolerance,
            min_angle: opts.min_angle,
            eee: opts.discontinuity.eee,
            events: opts.discontinuity.events,
            eee_tolerance: opts.discontinuity.eee_tolerance,
            event_tolerance: opts.discontinuity.event_tolerance,
            time_budget: opts.time_budget,
            epsilon: opts.solver.epsilon,
            max_shots: opts.solver.max_shots,
            visibility_rays: opts.solver.visibility_rays,
            form_factors: opts.solver.form_factors,
            elements_per_patch: opts.solver.elements_per_patch,
            direct_only: opts.solver.direct_only,
            seed: opts.solver.seed,
            threads: rayon::current_num_threads(),
        },
        counts: Counts {
            triangles: result.mesh.triangle_count(),
            vertices: result.mesh.vertex_count(),
            patches: stats.patches,
            discontinuity_segments: result.mesh.segment_count(),
        },
        discontinuities: result.mesh.discontinuity_stats.as_ref(),
        refinement: result.refinement.as_ref(),
        mesh_error: result.mesh_error.as_ref(),
        times_seconds: &result.times,
        memory: &result.memory,
        solver: stats,
        energy,
        mesh_quality,
        render: RenderSummary {
            width: result.render.image.width(),
            height: result.render.image.height(),
            exposure: result.render.exposure,
            ambient: result.solution.ambient,
            camera: scene
                .camera
                .unwrap_or_else(|| penumbra_viz::default_camera(scene)),
        },
        svgs: SvgSummary {
            selection: svgs.name(),
            written: svgs
                .surfaces(result)
                .into_iter()
                .map(|i| format!("{SVG_DIR}/{}", svg_name(i, &scene.surfaces[i].name)))
                .collect(),
        },
    };
    to_json(&report)
}

fn to_json<T: Serialize>(value: &T) -> String {
    // Serializing plain structs of numbers and strings cannot fail.
    let mut s = serde_json::to_string_pretty(value).expect("serializable output (this is a bug)");
    s.push('\n');
    s
}

/// The directory, inside the output directory, of the surfaces' SVGs.
pub const SVG_DIR: &str = "surfaces";

/// Surfaces that get an SVG by default, at most: a figure a person can look through, not one
/// per face of a scanned statue or a cathedral (75,000 of them).
pub const DEFAULT_SVG_SURFACES: usize = 24;

/// Which surfaces get an SVG (`--svg`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum SvgSelection {
    /// The surfaces worth looking at: every surface of a scene of at most
    /// [`DEFAULT_SVG_SURFACES`]; else that many, those with the most discontinuity segments
    /// first, then the largest, then the first in the scene.
    #[default]
    Auto,
    /// Every surface.
    All,
    /// No surface.
    None,
    /// These surfaces, by index.
    Named(Vec<SurfaceId>),
}

impl SvgSelection {
    /// The surfaces of `scene` named in `names` (exact names), or the names it does not have.
    pub fn named(scene: &Scene, names: &[String]) -> Result<SvgSelection, Vec<String>> {
        let mut ids = Vec::new();
        let mut unknown = Vec::new();
        for name in names {
            match scene.surface_id(name) {
                Some(id) => ids.push(id),
                None => unknown.push(name.clone()),
            }
        }
        if !unknown.is_empty() {
            return Err(unknown);
        }
        ids.sort_unstable();
        ids.dedup();
        Ok(SvgSelection::Named(ids))
    }

    /// How `report.json` names the selection.
    pub fn name(&self) -> &'static str {
        match self {
            SvgSelection::Auto => "auto",
            SvgSelection::All => "all",
            SvgSelection::None => "none",
            SvgSelection::Named(_) => "named",
        }
    }

    /// The surfaces that get an SVG, in the scene's order.
    pub fn surfaces(&self, result: &RunResult) -> Vec<SurfaceId> {
        let scene = &result.loaded.scene;
        match self {
            SvgSelection::All => (0..scene.surfaces.len()).collect(),
            SvgSelection::None => Vec::new(),
            SvgSelection::Named(ids) => ids.clone(),
            SvgSelection::Auto => {
                let segments: Vec<usize> =
                    result.mesh.discontinuities.iter().map(Vec::len).collect();
                worth_looking_at(scene, &segments, DEFAULT_SVG_SURFACES)
            }
        }
    }
}

/// At most `count` surfaces of `scene`, in its order: those with the most discontinuity
/// segments (`segments[s]`), then the largest, then the first.
pub fn worth_looking_at(scene: &Scene, segments: &[usize], count: usize) -> Vec<SurfaceId> {
    let areas: Vec<f64> = scene
        .surfaces
        .iter()
        .map(penumbra_scenes::Surface::area)
        .collect();
    let mut ranked: Vec<SurfaceId> = (0..scene.surfaces.len()).collect();
    let segments_of = |s: SurfaceId| segments.get(s).copied().unwrap_or(0);
    ranked.sort_by(|&a, &b| {
        segments_of(b)
            .cmp(&segments_of(a))
            .then(areas[b].total_cmp(&areas[a]))
            .then(a.cmp(&b))
    });
    ranked.truncate(count);
    ranked.sort_unstable();
    ranked
}

/// A file name for a surface's SVG: its index (names may clash once sanitized) and its name.
pub fn svg_name(index: usize, name: &str) -> String {
    format!("{}.svg", file_safe_name(index, name))
}

/// A name for surface `index` called `name` that is safe in file names and OBJ materials: its
/// index, then its name with every character but ASCII letters, digits, `-` and `_` made `_`.
pub fn file_safe_name(index: usize, name: &str) -> String {
    let clean: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{index:03}-{clean}")
}

/// A temporary file name in the same directory as `path` (so that renaming it is atomic).
fn temporary_beside(path: &Path) -> PathBuf {
    let dir = path.parent().unwrap_or(Path::new("."));
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dir.join(format!(".{file_name}.tmp-{}", std::process::id()))
}

/// Writes `bytes` to a temporary file beside `path` ([`temporary_beside`]) and syncs it;
/// returns the temporary's path, for a rename into place. On failure the temporary is removed.
fn write_temporary(path: &Path, bytes: &[u8]) -> std::io::Result<PathBuf> {
    let tmp = temporary_beside(path);
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    })();
    match written {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, then a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = write_temporary(path, bytes)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

/// The solver's convergence as CSV (iteration, residual, seconds) and as log–log charts against
/// iterations and against time; returns (file name, bytes) pairs.
pub fn convergence_files(result: &RunResult) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let history = &result.solution.convergence;
    let mut csv = String::from("iteration,residual,seconds\n");
    for p in history {
        csv += &format!("{},{:.6e},{:.6}\n", p.iteration, p.residual, p.seconds);
    }
    let mut files = vec![("convergence.csv".to_owned(), csv.into_bytes())];
    let name = report_solver_name(result);
    let y_label = "residual, relative to the light put in".to_owned();
    let charts = [
        (
            "convergence-iterations",
            "iterations",
            history
                .iter()
                .map(|p| (p.iteration as f64, p.residual))
                .collect::<Vec<_>>(),
        ),
        (
            "convergence-time",
            "seconds",
            history.iter().map(|p| (p.seconds, p.residual)).collect(),
        ),
    ];
    for (stem, x_label, points) in charts {
        let chart = penumbra_viz::LogLogChart {
            title: format!("{}: {name} convergence", result.loaded.scene.name),
            x_label: x_label.to_owned(),
            y_label: y_label.clone(),
            series: vec![penumbra_viz::Series {
                name: name.to_owned(),
                points,
            }],
        };
        files.push((format!("{stem}.svg"), chart.svg()?.into_bytes()));
        files.push((format!("{stem}.png"), chart.png()?));
    }
    Ok(files)
}

/// The solver as `report.json` names it: "direct" has always meant the direct light only, so
/// the dense solve of the full system is "dense-direct".
fn report_solver_name(result: &RunResult) -> &'static str {
    match (result.options.solver.direct_only, result.options.method) {
        (true, _) => "direct",
        (false, SolverMethod::Direct) => "dense-direct",
        (false, method) => method.name(),
    }
}

/// Files written all or nothing, as far as the file system allows: each is staged as a
/// temporary beside its place, and only [`Staging::commit`] renames them into place. Dropped
/// before that (a later file failed), it removes its temporaries and the old files stay as they
/// were.
#[derive(Debug, Default)]
pub struct Staging {
    /// (temporary, place) of every file staged.
    staged: Vec<(PathBuf, PathBuf)>,
}

impl Staging {
    /// Writes `bytes` to a temporary file beside `path`, to be renamed into place by
    /// [`Staging::commit`]. If that fails (the file cannot be written, or a directory stands at
    /// `path`), the temporary is removed; what was staged before stays staged.
    pub fn stage(&mut self, path: PathBuf, bytes: &[u8]) -> anyhow::Result<()> {
        use anyhow::Context;
        // A directory in the file's place would fail its rename after others were done.
        if path.is_dir() {
            anyhow::bail!("cannot write {}: a directory is in the way", path.display());
        }
        let tmp = write_temporary(&path, bytes)
            .with_context(|| format!("cannot write {}", path.display()))?;
        self.staged.push((tmp, path));
        Ok(())
    }

    /// Renames every staged file into place; returns their places.
    pub fn commit(mut self) -> anyhow::Result<Vec<PathBuf>> {
        use anyhow::Context;
        let staged = std::mem::take(&mut self.staged);
        let mut places = Vec::with_capacity(staged.len());
        for (i, (tmp, path)) in staged.iter().enumerate() {
            if let Err(e) = std::fs::rename(tmp, path) {
                // What was not renamed yet is dropped with the rest.
                self.staged = staged[i..].to_vec();
                return Err(e).with_context(|| format!("cannot write {}", path.display()));
            }
            places.push(path.clone());
        }
        Ok(places)
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        for (tmp, _) in &self.staged {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// Writes a set of files all or nothing (see [`Staging`]).
pub fn write_all_atomic(files: &[(PathBuf, Vec<u8>)]) -> anyhow::Result<()> {
    let mut staging = Staging::default();
    for (path, bytes) in files {
        staging.stage(path.clone(), bytes)?;
    }
    staging.commit().map(|_| ())
}

/// Surface SVGs made at once, then written: a bound on the memory they hold (a scene may have
/// tens of thousands of surfaces).
const SVG_BATCH: usize = 256;

/// Writes every output of a run into `dir` (created if needed): `solution.json`, `report.json`,
/// `render.png`, the SVGs of the surfaces `svgs` chooses in `dir/surfaces` ([`SVG_DIR`],
/// named by [`svg_name`]), and `extra` files (name and bytes) beside them, all or nothing (see
/// [`Staging`]); returns the paths written.
pub fn write_outputs(
    result: &RunResult,
    dir: &Path,
    svgs: &SvgSelection,
    extra: Vec<(String, Vec<u8>)>,
) -> anyhow::Result<Vec<PathBuf>> {
    use anyhow::Context;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let surfaces = svgs.surfaces(result);
    let svg_dir = dir.join(SVG_DIR);
    if !surfaces.is_empty() {
        std::fs::create_dir_all(&svg_dir)
            .with_context(|| format!("cannot create {}", svg_dir.display()))?;
    }
    let mut staging = Staging::default();
    staging.stage(dir.join("solution.json"), solution_json(result).as_bytes())?;
    staging.stage(
        dir.join("report.json"),
        report_json(result, svgs).as_bytes(),
    )?;
    staging.stage(
        dir.join("render.png"),
        &penumbra_viz::encode_png(&result.render.image)?,
    )?;
    let scene = &result.loaded.scene;
    for batch in surfaces.chunks(SVG_BATCH) {
        let svgs: Vec<String> = batch
            .par_iter()
            .map(|&i| {
                penumbra_viz::surface_svg(
                    scene,
                    &result.mesh.surfaces[i],
                    Some(&result.solution.radiosity[i]),
                    &result.mesh.discontinuities[i],
                )
            })
            .collect();
        for (&i, svg) in batch.iter().zip(svgs) {
            let name = svg_name(i, &scene.surfaces[i].name);
            staging.stage(svg_dir.join(name), svg.as_bytes())?;
        }
    }
    for (name, bytes) in extra {
        staging.stage(dir.join(name), &bytes)?;
    }
    staging.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
        let mut all: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
            .expect("readable")
            .map(|e| {
                let e = e.expect("entry");
                let bytes = std::fs::read(e.path()).unwrap_or_default();
                (e.file_name().to_string_lossy().into_owned(), bytes)
            })
            .collect();
        all.sort();
        all
    }

    /// The default SVGs: most discontinuity segments first, then the largest surface, then the
    /// first; in the scene's order; all of a small scene.
    #[test]
    fn the_surfaces_worth_looking_at_are_ranked_by_segments_then_area() {
        let scene = penumbra_scenes::builtin::boxworld(10, 1);
        let id = |name: &str| scene.surface_id(name).expect("named");
        let mut segments = vec![0; scene.surfaces.len()];
        segments[id("box7_side1")] = 5;
        segments[id("box3_top")] = 5;
        segments[id("box2_side0")] = 2;
        let picked = worth_looking_at(&scene, &segments, 4);
        // The floor is the largest surface without segments.
        let mut expected = vec![
            id("box7_side1"),
            id("box3_top"),
            id("box2_side0"),
            id("floor"),
        ];
        expected.sort_unstable();
        assert_eq!(picked, expected);
        // The textbook scene: the floor is largest; the light and the blocker are unit squares,
        // equal in area to rounding at most, and the first in the scene wins the tie.
        let textbook = penumbra_scenes::builtin::textbook();
        assert_eq!(textbook.surfaces[0].area(), textbook.surfaces[1].area());
        assert_eq!(worth_looking_at(&textbook, &[0, 0, 0], 2), [0, 2]);
        assert_eq!(
            worth_looking_at(&scene, &segments, 1000),
            (0..scene.surfaces.len()).collect::<Vec<_>>()
        );
        assert!(worth_looking_at(&scene, &[], 0).is_empty());
    }

    /// A set of files whose last one cannot be written (its directory is missing, or a directory
    /// stands in its place) changes nothing, and leaves no temporary behind.
    #[test]
    fn a_failed_write_leaves_the_old_files() {
        let dir = tempfile::tempdir().expect("temp dir");
        let d = dir.path();
        std::fs::write(d.join("a.json"), b"old a").expect("writes");
        std::fs::write(d.join("b.json"), b"old b").expect("writes");
        std::fs::create_dir(d.join("c.png")).expect("mkdir");
        let before = contents(d);
        for last in [d.join("missing").join("c.png"), d.join("c.png")] {
            let files = vec![
                (d.join("a.json"), b"new a".to_vec()),
                (d.join("b.json"), b"new b".to_vec()),
                (last, b"new c".to_vec()),
            ];
            assert!(write_all_atomic(&files).is_err());
            assert_eq!(contents(d), before);
        }
        let files = vec![
            (d.join("a.json"), b"new a".to_vec()),
            (d.join("b.json"), b"new b".to_vec()),
        ];
        write_all_atomic(&files).expect("writes");
        assert_eq!(std::fs::read(d.join("a.json")).expect("reads"), b"new a");
    }
}
