//! `report.json`: how a run was made, what it built, where its time and memory went, the
//! solver's figures, the energy balance, mesh quality and warnings. [`Report`] is the one type
//! of the file: a run writes it ([`Report::of_run`]), `merge` joins shards' reports, `export`
//! and `replay` read it ([`Report::parse`]), and `docs/schemas/report.schema.json` describes
//! it (tests/schemas.rs checks that the two name the same fields).

use glam::DVec3;
use penumbra_meshing::discontinuity::{DiscontinuityStats, EventSet};
use penumbra_meshing::{ElementBudget, MeshQuality};
use penumbra_scenes::{Camera, LengthUnit, Rgb};
use penumbra_solver::coupling::FormFactorMethod;
use penumbra_solver::{SolveStats, SolverMethod, StopReason};
use serde::{Deserialize, Serialize};

use crate::adaptive::RefineReport;
use crate::energy::EnergyBalance;
use crate::error_mesh::{ErrorStop, MeshErrorReport};
use crate::options::{Invocation, MeshMethod};
use crate::run_result::{MemoryReport, RunResult, StagePeaks, StageTimes, Stopped};
use crate::svg_selection::{SVG_DIR, SvgSelection, svg_name};

/// The `format` of `report.json`, and its version (`docs/schemas/report.schema.json`).
pub const REPORT_FORMAT: &str = "penumbra-report/1";

/// The version of penumbra that wrote a report.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// `report.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Report {
    /// [`REPORT_FORMAT`].
    pub format: String,
    /// The version of penumbra that made the run.
    pub version: String,
    /// The command line and every option, when the run came from one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub invocation: Option<Invocation>,
    /// The run was cut short (interrupted, or its time budget spent): the solution is the best
    /// so far, not a converged one, or its mesh lacks the events of the emitter–receiver pairs
    /// the discontinuity search had no time for.
    pub partial: bool,
    /// Where and why the run stopped before it was done, and what its outputs hold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stopped: Option<Stopped>,
    /// The scene that was run.
    pub scene: SceneSummary,
    /// The loader's warnings, then the run's (an energy balance that does not close).
    pub warnings: Vec<String>,
    /// How the run was made: the mesh, the solver and every option.
    pub method: Method,
    /// The sizes of what was built.
    pub counts: Counts,
    /// The discontinuity search's figures (none for uniform meshes).
    pub discontinuities: Option<DiscontinuityStats>,
    /// Adaptive refinement: rounds, residuals and why it stopped (absent when not asked for).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refinement: Option<RefineReport>,
    /// Error-driven meshes: the interpolation error of the direct light measured at every
    /// triangle's check points, per surface and for the scene, and why refinement stopped
    /// (absent for other meshes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh_error: Option<MeshErrorReport>,
    /// Wall-clock seconds per stage.
    pub times_seconds: StageTimes,
    /// Estimated need, the limit it was checked against, and the peak after each stage.
    pub memory: MemoryReport,
    /// The solver's figures.
    pub solver: SolveStats,
    /// Where the emitted power went.
    pub energy: EnergyBalance,
    /// The mesh's triangle shapes.
    pub mesh_quality: MeshQuality,
    /// How `render.png` was made.
    pub render: RenderSummary,
    /// Which surfaces got an SVG.
    pub svgs: SvgSummary,
    /// Only in a report written by `penumbra merge`: the shards joined.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shards: Option<ShardsSummary>,
}

/// The scene a report is of (`scene` in `report.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSummary {
    /// The scene's name.
    pub name: String,
    /// Where it came from: a built-in name or a path.
    pub source: String,
    /// A hash of every number of the scene as loaded: a replay checks it found the same scene.
    pub fingerprint: String,
    /// Surfaces in the scene.
    pub surfaces: usize,
    /// Of those, the emitters.
    pub emitters: usize,
    /// The diagonal of the scene's bounding box, in scene units.
    pub bounding_box_diagonal: f64,
    /// Which way is up ([`penumbra_viz::scene_up`]), for exports; `None` in older reports.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<DVec3>,
    /// The unit of the coordinates (metres unless the scene or `--unit` says); `None` in older
    /// reports.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<LengthUnit>,
}

/// How a run was made (`method` in `report.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Method {
    /// The mesh that was built: `error-driven`, `discontinuity` or `uniform` (`auto` chooses).
    pub mesh: String,
    /// The mesh asked for.
    pub mesh_requested: MeshMethod,
    /// The solver, as [`solver_name`] names it.
    pub solver: String,
    /// The element budget used: the mesh's, or the cap of adaptive refinement.
    pub max_elements: usize,
    /// What was asked for: `"fit"` (the default: what the scene needs) or a number.
    pub max_elements_requested: BudgetRequested,
    /// Graded discontinuity meshes' density in penumbrae.
    pub penumbra_density: f64,
    /// Error-driven meshes' tolerance, relative to the scene's mean reflected direct light.
    pub tolerance: f64,
    /// The smallest angle discontinuity and error-driven meshes aimed for (0: none).
    pub min_angle: f64,
    /// Whether EEE events were searched for.
    pub eee: bool,
    /// Which EV and VE events: `complete` or `extremal`.
    pub events: EventSet,
    /// The EEE search's tolerance.
    pub eee_tolerance: f64,
    /// The event search's tolerance.
    pub event_tolerance: f64,
    /// Seconds the run was allowed (absent: no limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_budget: Option<f64>,
    /// The progressive solver's convergence threshold.
    pub epsilon: f64,
    /// The progressive solver's most shots.
    pub max_shots: usize,
    /// Rays per visibility estimate.
    pub visibility_rays: usize,
    /// How form factors were computed.
    pub form_factors: FormFactorMethod,
    /// Mesh elements per patch of the progressive solver.
    pub elements_per_patch: usize,
    /// Whether only the direct light was computed.
    pub direct_only: bool,
    /// The random seed.
    pub seed: u64,
    /// Worker threads.
    pub threads: usize,
}

/// The sizes of what a run built (`counts` in `report.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Counts {
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// The solver's patches.
    pub patches: usize,
    /// Discontinuity segments built into the mesh.
    pub discontinuity_segments: usize,
}

/// The element budget as asked for: `"fit"` or a number.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum BudgetRequested {
    /// `"fit"`: what the scene needs.
    Fit(String),
    /// At most this many triangles.
    AtMost(usize),
}

impl From<ElementBudget> for BudgetRequested {
    fn from(b: ElementBudget) -> Self {
        match b {
            ElementBudget::AtMost(n) => BudgetRequested::AtMost(n),
            ElementBudget::Fit { .. } => BudgetRequested::Fit("fit".to_owned()),
        }
    }
}

/// How `render.png` was made (`render` in `report.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderSummary {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The exposure the radiosity was scaled by.
    pub exposure: f64,
    /// The display-only ambient term added to every surface's light.
    pub ambient: Rgb,
    /// The camera the image was made from: the scene's, or one that frames it (absent from
    /// reports of earlier versions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<Camera>,
}

/// Which surfaces got an SVG, and why (`svgs` in `report.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SvgSummary {
    /// `auto` (the surfaces worth looking at), `all`, `none` or `named`.
    pub selection: String,
    /// The files written, relative to the output directory, in surface order.
    pub written: Vec<String>,
}

/// The shards a merged report joined (`shards` in `report.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardsSummary {
    /// N, the number of shards of the run.
    pub count: usize,
    /// Each shard, in shard order.
    pub parts: Vec<ShardPart>,
}

/// One shard of a merged run.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardPart {
    /// The shard as `I/N`.
    pub shard: String,
    /// The shard's output directory, as given to `penumbra merge`.
    pub directory: String,
    /// Surfaces the shard lit.
    pub surfaces: usize,
    /// Vertices of those surfaces.
    pub vertices_lit: usize,
    /// Worker threads the shard used.
    pub threads: usize,
    /// The shard's own stage times.
    pub times_seconds: StageTimes,
    /// The shard's own memory peaks.
    pub peak_bytes: StagePeaks,
}

/// Why `report.json` could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// Not JSON, or not a report of this version's shape.
    #[error("not a report.json of penumbra {VERSION}: {0}")]
    Malformed(#[from] serde_json::Error),
    /// A JSON document of another kind, or another version of the format.
    #[error("its format is {}, not {REPORT_FORMAT:?}", quoted_or_none(.found))]
    Format {
        /// The `format` it has, if any.
        found: Option<String>,
    },
}

/// `"text"`, or `none` when there is no text.
fn quoted_or_none(text: &Option<String>) -> String {
    text.as_deref()
        .map_or("none".to_owned(), |t| format!("{t:?}"))
}

impl Report {
    /// The report of `result`, whose SVGs `svgs` chose.
    pub fn of_run(result: &RunResult, svgs: &SvgSelection) -> Report {
        let scene = &result.loaded.scene;
        let stats = &result.solution.stats;
        let energy = EnergyBalance::of(stats);
        let mesh_quality = result.mesh.quality();
        Report {
            format: REPORT_FORMAT.to_owned(),
            version: VERSION.to_owned(),
            invocation: result.invocation.clone(),
            partial: is_partial(result),
            stopped: result.stopped,
            scene: SceneSummary {
                name: scene.name.clone(),
                source: result.loaded.source.clone(),
                fingerprint: crate::fingerprint::scene_fingerprint(&result.loaded),
                surfaces: scene.surfaces.len(),
                emitters: scene.emitters().count(),
                bounding_box_diagonal: scene.diagonal(),
                up: Some(penumbra_viz::scene_up(scene)),
                unit: Some(scene.unit.unwrap_or(LengthUnit::Metre)),
            },
            warnings: run_warnings(result, &energy, &mesh_quality),
            method: Method::of_run(result),
            counts: Counts {
                triangles: result.mesh.triangle_count(),
                vertices: result.mesh.vertex_count(),
                patches: stats.patches,
                discontinuity_segments: result.mesh.segment_count(),
            },
            discontinuities: result.mesh.discontinuity_stats.clone(),
            refinement: result.refinement.clone(),
            mesh_error: result.mesh_error.clone(),
            times_seconds: result.times.clone(),
            memory: result.memory.clone(),
            solver: stats.clone(),
            energy,
            mesh_quality,
            render: RenderSummary {
                width: result.render.image.width(),
                height: result.render.image.height(),
                exposure: result.render.exposure,
                ambient: result.solution.ambient,
                camera: Some(
                    scene
                        .camera
                        .unwrap_or_else(|| penumbra_viz::default_camera(scene)),
                ),
            },
            svgs: SvgSummary {
                selection: svgs.name().to_owned(),
                written: svgs
                    .surfaces(result)
                    .into_iter()
                    .map(|i| format!("{SVG_DIR}/{}", svg_name(i, &scene.surfaces[i].name)))
                    .collect(),
            },
            shards: None,
        }
    }

    /// A report from the text of `report.json`: of this format, and of this version's shape.
    pub fn parse(text: &str) -> Result<Report, ReportError> {
        #[derive(Deserialize)]
        struct Format {
            format: Option<String>,
        }
        let found = serde_json::from_str::<Format>(text)?.format;
        if found.as_deref() != Some(REPORT_FORMAT) {
            return Err(ReportError::Format { found });
        }
        Ok(serde_json::from_str(text)?)
    }

    /// The text of `report.json`: pretty-printed, with a final newline.
    pub fn to_json(&self) -> String {
        crate::json_text::to_json(self)
    }
}

impl Method {
    /// How `result`'s run was made.
    fn of_run(result: &RunResult) -> Method {
        let opts = &result.options;
        let mesh = if result.mesh_error.is_some() {
            "error-driven"
        } else if result.mesh.discontinuity_stats.is_some() {
            "discontinuity"
        } else {
            "uniform"
        };
        Method {
            mesh: mesh.to_owned(),
            mesh_requested: opts.mesh,
            solver: solver_name(opts.solver.direct_only, opts.method).to_owned(),
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
        }
    }
}

/// Whether `result` is not the whole of what was asked: its solve or meshing was cut short,
/// or its mesh lacks the events the discontinuity search had no time for.
fn is_partial(result: &RunResult) -> bool {
    matches!(
        result.solution.stats.stop,
        StopReason::Interrupted | StopReason::TimeBudget
    ) || result.stopped.is_some()
        || result
            .mesh
            .discontinuity_stats
            .as_ref()
            .is_some_and(|d| d.pairs_skipped > 0)
}

/// The loader's warnings, then the run's: an energy balance that does not close, direct light
/// estimated by rays, triangles below the quality aim, surfaces above the error tolerance.
fn run_warnings(result: &RunResult, energy: &EnergyBalance, quality: &MeshQuality) -> Vec<String> {
    let mut warnings = result.loaded.warnings.clone();
    warnings.extend(energy.warning());
    warnings.extend(estimated_direct_warning(&result.solution.stats));
    // Error-driven meshes choose their triangles' shapes by the error they measure.
    if result.mesh_error.is_none() {
        warnings.extend(quality_warning(
            quality.triangles_below_min_angle,
            quality.triangles,
            result.refinement.is_some(),
        ));
    }
    warnings.extend(result.mesh_error.as_ref().and_then(mesh_error_warning));
    warnings
}

/// The solver as `report.json` names it: "direct" has always meant the direct light only, so
/// the dense solve of the full system is "dense-direct".
pub fn solver_name(direct_only: bool, method: SolverMethod) -> &'static str {
    match (direct_only, method) {
        (true, _) => "direct",
        (false, SolverMethod::Direct) => "dense-direct",
        (false, method) => method.name(),
    }
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
pub fn mesh_error_warning(report: &MeshErrorReport) -> Option<String> {
    let above = report.above_tolerance();
    if report.stop == ErrorStop::Tolerance || above.is_empty() {
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
        ErrorStop::Budget => "the element budget ran out (--max-elements)",
        ErrorStop::TimeBudget => "the time budget ran out",
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
