//! The speed/accuracy trade, measured: the same scene meshed four ways (uniform, uniform +
//! adaptive, discontinuity, discontinuity + adaptive) over a ladder of element budgets, each run
//! timed and scored against a reference at fixed sample points.
//!
//! The samples are seeded random points spread over the scene's surfaces by area. For direct-only
//! runs the reference is the exact evaluator; for full solutions, path tracing at the samples
//! ([`penumbra_solver::path_trace`]). Samples where some emitter is partly hidden form the
//! penumbra subset, scored on its own.

use glam::DVec3;
use penumbra_meshing::discontinuity::{DiscontinuityOptions, EmitterProbe, EventSet};
use penumbra_meshing::{DEFAULT_PENUMBRA_DENSITY, ElementBudget, TriangleLocator};
use penumbra_scenes::{AreaSampler, SplitMix64};
use penumbra_scenes::{LoadedScene, Scene, SurfaceId, Visibility};
use penumbra_solver::path_trace::ReferenceValue;
use penumbra_solver::{
    DirectLight, OptionId, Progress, ReceivingPoint, SolverMethod, SolverOptions,
};
use penumbra_viz::{LogLogChart, Series};
use serde::Serialize;

use crate::adaptive::RefineOptions;
use crate::options::{InvalidOption, MeshMethod, RunOptions};
use crate::pipeline::{RunError, run};

/// A way of meshing that a sweep compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweepMethod {
    /// Error-driven meshes (the default of a run, [`MeshMethod::Auto`]).
    ErrorDriven,
    /// Uniform meshes of the budget.
    Uniform,
    /// Uniform meshes refined adaptively from a fraction of the budget up to it.
    UniformAdaptive,
    /// Discontinuity meshes of the default events ([`EventSet::Complete`]).
    Discontinuity,
    /// Discontinuity meshes refined adaptively from a fraction of the budget up to it, without
    /// penumbra grading (refinement places the small triangles).
    DiscontinuityAdaptive,
    /// Discontinuity meshes of every vertex–edge event ([`EventSet::Complete`]).
    DiscontinuityComplete,
    /// Discontinuity meshes of the umbra and outer penumbra boundaries ([`EventSet::Extremal`]).
    DiscontinuityExtremal,
}

impl SweepMethod {
    /// What a sweep runs unless told otherwise.
    pub const DEFAULT: [SweepMethod; 3] = [
        SweepMethod::ErrorDriven,
        SweepMethod::Uniform,
        SweepMethod::Discontinuity,
    ];
    /// Every method a sweep can run.
    pub const ALL: [SweepMethod; 7] = [
        SweepMethod::ErrorDriven,
        SweepMethod::Uniform,
        SweepMethod::UniformAdaptive,
        SweepMethod::Discontinuity,
        SweepMethod::DiscontinuityAdaptive,
        SweepMethod::DiscontinuityComplete,
        SweepMethod::DiscontinuityExtremal,
    ];

    /// The method's name in `--methods`, the CSV and the charts: `error-driven`, `uniform`,
    /// `uniform+adaptive`, `discontinuity`, `discontinuity+adaptive`, `discontinuity-complete`
    /// or `discontinuity-extremal`.
    pub fn name(self) -> &'static str {
        match self {
            SweepMethod::ErrorDriven => "error-driven",
            SweepMethod::Uniform => "uniform",
            SweepMethod::UniformAdaptive => "uniform+adaptive",
            SweepMethod::Discontinuity => "discontinuity",
            SweepMethod::DiscontinuityAdaptive => "discontinuity+adaptive",
            SweepMethod::DiscontinuityComplete => "discontinuity-complete",
            SweepMethod::DiscontinuityExtremal => "discontinuity-extremal",
        }
    }

    fn events(self) -> EventSet {
        match self {
            SweepMethod::DiscontinuityComplete => EventSet::Complete,
            SweepMethod::DiscontinuityExtremal => EventSet::Extremal,
            _ => EventSet::default(),
        }
    }

    fn mesh(self) -> MeshMethod {
        match self {
            SweepMethod::ErrorDriven => MeshMethod::Auto,
            SweepMethod::Uniform | SweepMethod::UniformAdaptive => MeshMethod::Uniform,
            _ => MeshMethod::Discontinuity,
        }
    }

    fn adaptive(self) -> bool {
        matches!(
            self,
            SweepMethod::UniformAdaptive | SweepMethod::DiscontinuityAdaptive
        )
    }
}

/// What a sweep runs.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    /// Element budgets (`--max-elements` of each run).
    pub budgets: Vec<usize>,
    /// Whether each budget is fitted as a run's default is ([`ElementBudget::fit`]: at least
    /// the budget, or the scene's least mesh and a triangle more per surface when that is
    /// more), rather than a cap.
    pub fitted: bool,
    /// The meshing methods compared; each runs at every budget.
    pub methods: Vec<SweepMethod>,
    /// Names of the surfaces scored, for the record (empty: all; the samples are chosen by
    /// [`sample_points`]).
    pub surfaces: Vec<String>,
    /// The adaptive runs start from this fraction of the budget.
    pub initial_fraction: f64,
    /// Tolerance of the adaptive runs at the first budget; it shrinks in proportion as the
    /// budget grows, so that larger budgets are spent.
    pub refine_tol: f64,
    /// The error-driven runs' tolerance ([`RunOptions::tolerance`]).
    pub tolerance: f64,
    /// The smallest angle of discontinuity and error-driven meshes ([`RunOptions::min_angle`]).
    pub min_angle: f64,
    /// Sample points the runs are scored at ([`sample_points`]).
    pub samples: usize,
    /// The seed of the sample points.
    pub seed: u64,
    /// The solver's options for every run (`direct_only` makes a direct-light sweep).
    pub solver: SolverOptions,
    /// The solvers to compare (each non-adaptive run is repeated with each, adaptive runs with
    /// progressive refinement and the hierarchical solver; direct-light sweeps use progressive
    /// refinement only).
    pub solvers: Vec<SolverMethod>,
    /// The photon-map solver's budgets: photons emitted. Its runs take these in place of
    /// `budgets`, each on the mesh of `photon_elements` triangles.
    pub photons: Vec<usize>,
    /// The photon-map solver's final gathers, rays per vertex (0: none): a line of photon
    /// budgets for each.
    pub final_gathers: Vec<usize>,
    /// The element budget of the photon-map runs' meshes.
    pub photon_elements: usize,
}

/// Photon budgets of a sweep unless told otherwise: a ladder up to twice the run's default.
pub const DEFAULT_PHOTON_BUDGETS: [usize; 5] = [250_000, 500_000, 1_000_000, 2_000_000, 4_000_000];

/// Most sample points a sweep scores at: the error of the error is long below a percent there.
pub const MAX_SAMPLES: usize = 10_000_000;

impl SweepOptions {
    /// Checks every option's range before anything is computed (a path-traced reference takes
    /// minutes), with the same names as [`RunOptions::validate`].
    pub fn validate(&self) -> Result<(), InvalidOption> {
        let bad = |option, reason: String| Err(InvalidOption { option, reason });
        if self.budgets.is_empty() || self.budgets.contains(&0) {
            return bad(
                OptionId::MaxElements,
                "every budget must be at least 1 triangle".into(),
            );
        }
        if !(1..=MAX_SAMPLES).contains(&self.samples) {
            return bad(
                OptionId::Samples,
                format!("must be from 1 to {MAX_SAMPLES}, not {}", self.samples),
            );
        }
        if !(self.refine_tol > 0.0 && self.refine_tol <= 1.0) {
            return bad(
                OptionId::RefineTolerance,
                format!("must be a fraction in (0, 1], not {}", self.refine_tol),
            );
        }
        if !(self.initial_fraction > 0.0 && self.initial_fraction <= 1.0) {
            return bad(
                OptionId::InitialElements,
                format!(
                    "the fraction must be in (0, 1], not {}",
                    self.initial_fraction
                ),
            );
        }
        if !self.solver.direct_only && self.solvers.contains(&SolverMethod::PhotonMap) {
            self.validate_photon_budgets()?;
        }
        self.solver.validate()?;
        if jobs(self).is_empty() {
            return bad(
                OptionId::Solver,
                "photon mapping runs only on meshes that are not refined: add a method without \
                 +adaptive"
                    .into(),
            );
        }
        Ok(())
    }

    /// The photon-map runs' options: each photon budget and each final gather as a run takes it.
    fn validate_photon_budgets(&self) -> Result<(), InvalidOption> {
        let bad = |option, reason: &str| {
            Err(InvalidOption {
                option,
                reason: reason.into(),
            })
        };
        if self.photon_elements == 0 {
            return bad(OptionId::PhotonElements, "must be at least 1 triangle");
        }
        if self.photons.is_empty() {
            return bad(OptionId::Photons, "give at least one photon budget");
        }
        if self.final_gathers.is_empty() {
            return bad(OptionId::FinalGather, "give at least one count of rays");
        }
        let mut solver = self.solver.clone();
        for &photons in &self.photons {
            solver.photon_map.photons = photons;
            solver.validate()?;
        }
        for &rays in &self.final_gathers {
            solver.photon_map.final_gather = rays;
            solver.validate()?;
        }
        Ok(())
    }
}

/// What the runs are scored against.
#[derive(Clone, Debug)]
pub enum Reference {
    /// The exact direct light (for direct-only runs).
    ExactDirect,
    /// Path-traced radiosity at the samples (for full solutions), in the samples' order.
    PathTraced(Vec<ReferenceValue>),
}

/// One run of a sweep: its size, its time and its error. Errors compare the channel means of
/// the run's interpolated radiosity and of the reference at the samples, relative to the mean of
/// the reference over the samples.
#[derive(Clone, Debug, Serialize)]
pub struct SweepRow {
    /// The meshing method ([`SweepMethod::name`]).
    pub method: &'static str,
    /// How the system was solved, as [`SolverMethod::name`] names it (`direct` is the dense
    /// solve); `progressive` in direct-light sweeps, which solve no system.
    pub solver: &'static str,
    /// The run's element budget, in triangles for the whole scene.
    pub max_elements: usize,
    /// The photon-map runs' budget: photons emitted; `None` for the other solvers.
    pub photons: Option<usize>,
    /// The photon-map runs' final gather, rays per vertex; `None` for the other solvers.
    pub final_gather: Option<usize>,
    /// The adaptive runs' tolerance (a fraction of the mean reflected radiosity); `None` for
    /// the others.
    pub refine_tol: Option<f64>,
    /// Triangles of the run's final mesh.
    pub triangles: usize,
    /// Vertices of the run's final mesh.
    pub vertices: usize,
    /// Wall-clock seconds of the run, rendering left out.
    pub seconds: f64,
    /// Root mean square error over the samples, relative to the reference's mean.
    pub rms: f64,
    /// Largest error over the samples, relative to the reference's mean.
    pub max: f64,
    /// Root mean square error over the penumbra samples, relative to the reference's mean over
    /// all samples (0 when there are none).
    pub penumbra_rms: f64,
    /// The sample with the largest error, to see where a method fails.
    pub worst: Option<WorstSample>,
    /// The run's radiosity (channel mean) at each sample, interpolated on its mesh
    /// (`samples.csv`).
    #[serde(skip)]
    pub values: Vec<f64>,
}

impl SweepRow {
    /// The run's budget as a table names it: triangles, or for photon-map runs photons and
    /// final-gather rays (`500000ph/64r`).
    pub fn budget(&self) -> String {
        match (self.photons, self.final_gather) {
            (Some(p), Some(rays)) => format!("{p}ph/{rays}r"),
            _ => self.max_elements.to_string(),
        }
    }
}

/// Where a run's error is largest.
#[derive(Clone, Debug, Serialize)]
pub struct WorstSample {
    /// The name of the surface the sample lies on.
    pub surface: String,
    /// The sample, in 3D scene coordinates.
    pub point: [f64; 3],
    /// The reference radiosity there, in W/m² (channel mean).
    pub reference: f64,
    /// The run's interpolated radiosity there, in W/m² (channel mean).
    pub value: f64,
}

/// A sweep's samples, reference and rows (`sweep.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Sweep {
    /// The format and its version: `penumbra-sweep/1`.
    pub format: &'static str,
    /// The scene's name.
    pub scene: String,
    /// The surfaces scored (empty: every surface that does not emit).
    pub surfaces: Vec<String>,
    /// What the runs were scored against: `exact direct light` or `path traced`.
    pub reference: &'static str,
    /// Root mean square of the reference's standard errors relative to the mean (zero for the
    /// exact direct light).
    pub reference_standard_error: f64,
    /// Sample points scored.
    pub samples: usize,
    /// Of those, the samples where some emitter is partly hidden.
    pub penumbra_samples: usize,
    /// The reference's mean over the samples, in W/m² (channel mean): the scale of every
    /// relative error.
    pub reference_mean: f64,
    /// Every run, budget by budget, method by method within a budget.
    pub rows: Vec<SweepRow>,
    /// Each sample's surface (by name), point and reference value (`samples.csv`).
    #[serde(skip)]
    pub points: Vec<(String, DVec3, f64)>,
}

/// A sample point on a surface, with the exact direct radiosity there (channel mean) and whether
/// some emitter is partly hidden from it.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// The point, in 3D scene coordinates.
    pub point: DVec3,
    /// The surface it lies on.
    pub surface: SurfaceId,
    /// The exact direct radiosity there, emission included, in W/m² (channel mean).
    pub direct: f64,
    /// Whether some emitter is partly hidden from the point.
    pub penumbra: bool,
}

/// One run of a sweep: how it meshes and solves, its element budget and, for photon mapping,
/// its photons and final-gather rays.
#[derive(Clone, Copy, Debug)]
struct Job {
    method: SweepMethod,
    solver: SolverMethod,
    budget: usize,
    photons: Option<(usize, usize)>,
}

/// The runs of a sweep: every method at every budget with every solver (adaptive methods with
/// the progressive and hierarchical solvers only); then photon mapping with every final gather
/// at every photon budget, on each non-adaptive method's mesh of `photon_elements` triangles.
fn jobs(options: &SweepOptions) -> Vec<Job> {
    let solvers: Vec<SolverMethod> = if options.solver.direct_only || options.solvers.is_empty() {
        vec![SolverMethod::Progressive]
    } else {
        options.solvers.clone()
    };
    let mut jobs = Vec::new();
    for &budget in &options.budgets {
        for &method in &options.methods {
            for &solver in &solvers {
                let allowed = match solver {
                    SolverMethod::PhotonMap => false,
                    SolverMethod::Progressive | SolverMethod::Hierarchical => true,
                    _ => !method.adaptive(),
                };
                if allowed {
                    jobs.push(Job {
                        method,
                        solver,
                        budget,
                        photons: None,
                    });
                }
            }
        }
    }
    if solvers.contains(&SolverMethod::PhotonMap) {
        for &rays in &options.final_gathers {
            for &photons in &options.photons {
                for &method in options.methods.iter().filter(|m| !m.adaptive()) {
                    jobs.push(Job {
                        method,
                        solver: SolverMethod::PhotonMap,
                        budget: options.photon_elements,
                        photons: Some((photons, rays)),
                    });
                }
            }
        }
    }
    jobs
}

/// Runs the sweep at `samples` (from [`sample_points`]) against `reference`: every method of
/// `options` at every budget (and, in full solutions, with every solver; adaptive methods with
/// the progressive and hierarchical solvers only; photon mapping at its photon budgets), each a
/// whole [`run`] with a 1 × 1 render. Fails with the first run that fails.
pub fn sweep(
    loaded: &LoadedScene,
    options: &SweepOptions,
    samples: &[Sample],
    reference: &Reference,
    progress: &dyn Progress,
) -> Result<Sweep, RunError> {
    let scene = &loaded.scene;
    let values: Vec<f64> = match reference {
        Reference::ExactDirect => samples.iter().map(|s| s.direct).collect(),
        Reference::PathTraced(v) => v.iter().map(|r| r.radiosity.mean()).collect(),
    };
    let n = samples.len().max(1) as f64;
    let mean = values.iter().sum::<f64>() / n;
    let reference_standard_error = match reference {
        Reference::ExactDirect => 0.0,
        Reference::PathTraced(v) => {
            (v.iter()
                .map(|r| r.standard_error * r.standard_error)
                .sum::<f64>()
                / n)
                .sqrt()
                / mean.max(f64::MIN_POSITIVE)
        }
    };
    let first = options.budgets.first().copied().unwrap_or(1);
    let jobs = jobs(options);
    let mut rows = Vec::new();
    progress.start("sweep", jobs.len() as u64);
    for job in jobs {
        let method = job.method;
        let mut solver = options.solver.clone();
        if let Some((photons, rays)) = job.photons {
            solver.photon_map.photons = photons;
            solver.photon_map.final_gather = rays;
        }
        let run_options = RunOptions {
            method: job.solver,
            mesh: method.mesh(),
            max_elements: match options.fitted {
                true => ElementBudget::fit(job.budget),
                false => job.budget.into(),
            },
            penumbra_density: if method.adaptive() {
                1.0
            } else {
                DEFAULT_PENUMBRA_DENSITY
            },
            refine: method.adaptive().then(|| RefineOptions {
                tolerance: options.refine_tol * first as f64 / job.budget.max(1) as f64,
                initial_elements: ((job.budget as f64 * options.initial_fraction) as usize).max(1),
                max_rounds: crate::adaptive::DEFAULT_MAX_ROUNDS,
                indirect: Default::default(),
            }),
            solver,
            tolerance: options.tolerance,
            min_angle: options.min_angle,
            render: penumbra_viz::RenderOptions {
                width: 1,
                height: 1,
                ..Default::default()
            },
            discontinuity: DiscontinuityOptions {
                events: method.events(),
                ..DiscontinuityOptions::default()
            },
            ..RunOptions::default()
        };
        let result = run(loaded.clone(), &run_options, &penumbra_solver::NoProgress)?;
        let score = Score::of(&result, scene, samples, &values);
        let scale = mean.max(f64::MIN_POSITIVE);
        rows.push(SweepRow {
            method: method.name(),
            solver: job.solver.name(),
            max_elements: job.budget,
            photons: job.photons.map(|p| p.0),
            final_gather: job.photons.map(|p| p.1),
            refine_tol: run_options.refine.as_ref().map(|r| r.tolerance),
            triangles: result.mesh.triangle_count(),
            vertices: result.mesh.vertex_count(),
            seconds: result.times.total - result.times.render,
            rms: (score.sum2 / n).sqrt() / scale,
            max: score.max / scale,
            penumbra_rms: (score.penumbra_sum2 / score.penumbra_count.max(1) as f64).sqrt() / scale,
            worst: score.worst,
            values: score.values,
        });
        progress.set(rows.len() as u64);
    }
    progress.finish();
    Ok(Sweep {
        format: "penumbra-sweep/1",
        scene: scene.name.clone(),
        surfaces: options.surfaces.clone(),
        reference: match reference {
            Reference::ExactDirect => "exact direct light",
            Reference::PathTraced(_) => "path traced",
        },
        reference_standard_error,
        samples: samples.len(),
        penumbra_samples: samples.iter().filter(|s| s.penumbra).count(),
        reference_mean: mean,
        rows,
        points: (samples.iter().zip(&values))
            .map(|(s, &v)| (scene.surfaces[s.surface].name.clone(), s.point, v))
            .collect(),
    })
}

/// A run's errors at the samples, in W/m² (channel mean).
struct Score {
    values: Vec<f64>,
    sum2: f64,
    max: f64,
    penumbra_sum2: f64,
    penumbra_count: usize,
    worst: Option<WorstSample>,
}

impl Score {
    /// The run's interpolated radiosity against `values`, the reference at `samples`.
    fn of(
        result: &crate::pipeline::RunResult,
        scene: &Scene,
        samples: &[Sample],
        values: &[f64],
    ) -> Score {
        let mut score = Score {
            values: Vec::with_capacity(samples.len()),
            sum2: 0.0,
            max: 0.0,
            penumbra_sum2: 0.0,
            penumbra_count: 0,
            worst: None,
        };
        let locators: Vec<TriangleLocator> = result
            .mesh
            .surfaces
            .iter()
            .map(TriangleLocator::new)
            .collect();
        for (s, &reference) in samples.iter().zip(values) {
            let value = locators[s.surface]
                .interpolate(
                    &result.mesh.surfaces[s.surface],
                    &result.solution.radiosity[s.surface],
                    s.point,
                )
                .mean();
            let e = value - reference;
            score.values.push(value);
            score.sum2 += e * e;
            if e.abs() > score.max {
                score.max = e.abs();
                score.worst = Some(WorstSample {
                    surface: scene.surfaces[s.surface].name.clone(),
                    point: s.point.to_array(),
                    reference,
                    value,
                });
            }
            if s.penumbra {
                score.penumbra_sum2 += e * e;
                score.penumbra_count += 1;
            }
        }
        score
    }
}

/// Seeded points spread over the scene's surfaces by area (emitters left out; only `surfaces`
/// if that is not empty), with the exact direct radiosity there and whether some emitter is
/// partly hidden.
pub fn sample_points(
    scene: &Scene,
    visibility: &Visibility,
    surfaces: &[SurfaceId],
    count: usize,
    seed: u64,
) -> Vec<Sample> {
    let triangles: Vec<_> = visibility
        .triangles()
        .iter()
        .filter(|t| !scene.surfaces[t.surface].is_emitter())
        .filter(|t| surfaces.is_empty() || surfaces.contains(&t.surface))
        .collect();
    let sampler = AreaSampler::new(triangles.iter().map(|t| {
        0.5 * (t.vertices[1] - t.vertices[0])
            .cross(t.vertices[2] - t.vertices[0])
            .length()
    }));
    let direct = DirectLight::new(scene, visibility);
    let probes: Vec<EmitterProbe> = scene
        .emitters()
        .map(|(e, _)| EmitterProbe::new(scene, e))
        .collect();
    let mut rng = SplitMix64::keyed(seed, &[]);
    (0..count)
        .filter_map(|_| {
            let (k, w) = sampler.pick(&mut rng)?;
            let t = triangles[k];
            let point: DVec3 = (0..3).map(|j| t.vertices[j] * w[j]).sum();
            let surface = &scene.surfaces[t.surface];
            let normal = surface.normal();
            let h = direct.irradiance(&ReceivingPoint::interior(point, normal), t.surface);
            let direct = (surface.emission + surface.reflectance.mul_rgb(h)).mean();
            let penumbra = probes.iter().any(|p| {
                let f = p.visible_fraction(visibility, point, normal, t.surface);
                f > 0.0 && f < 1.0
            });
            Some(Sample {
                point,
                surface: t.surface,
                direct,
                penumbra,
            })
        })
        .collect()
}

/// The sweep's log–log charts, one line per method: RMS error against triangles and against
/// seconds, with their file stems. Photon-map runs, whose budget is photons on one mesh, are
/// lines against seconds only.
pub fn sweep_charts(sweep: &Sweep) -> Vec<(&'static str, LogLogChart)> {
    // One line per method, or per method and solver when the sweep compares solvers, and per
    // final gather of the photon map.
    type Line<'a> = (&'a str, &'a str, Option<usize>);
    let line_of =
        |r: &SweepRow| -> (&str, &str, Option<usize>) { (r.method, r.solver, r.final_gather) };
    let mut lines: Vec<Line> = Vec::new();
    for r in &sweep.rows {
        if !lines.contains(&line_of(r)) {
            lines.push(line_of(r));
        }
    }
    let several_solvers = lines.iter().any(|l| l.1 != lines[0].1);
    let name = |&(m, solver, rays): &Line| match (several_solvers, rays) {
        (_, Some(rays)) => format!("{m} ({solver}, {rays} rays)"),
        (true, None) => format!("{m} ({solver})"),
        (false, None) => m.to_owned(),
    };
    let series = |x: fn(&SweepRow) -> f64, photons: bool| -> Vec<Series> {
        lines
            .iter()
            .filter(|l| photons || l.2.is_none())
            .map(|l| Series {
                name: name(l),
                points: sweep
                    .rows
                    .iter()
                    .filter(|r| line_of(r) == *l)
                    .map(|r| (x(r), 100.0 * r.rms))
                    .collect(),
            })
            .collect()
    };
    let y_label = format!("RMS error, % of mean ({})", sweep.reference);
    let scene = if sweep.surfaces.is_empty() {
        sweep.scene.clone()
    } else {
        format!("{} ({})", sweep.scene, sweep.surfaces.join(", "))
    };
    vec![
        (
            "error-vs-elements",
            LogLogChart {
                title: format!("{scene}: error against triangles"),
                x_label: "triangles in the scene".to_owned(),
                y_label: y_label.clone(),
                series: series(|r| r.triangles as f64, false),
            },
        ),
        (
            "error-vs-time",
            LogLogChart {
                title: format!("{scene}: error against time"),
                x_label: "seconds (mesh and solve, no render)".to_owned(),
                y_label,
                series: series(|r| r.seconds, true),
            },
        ),
    ]
}

/// Each sample as CSV, a line each: its surface, point and reference value, then each run's
/// interpolated value (a column per row of `sweep.csv`, named method/solver/budget), to see
/// where a run's error lies.
pub fn samples_csv(sweep: &Sweep) -> String {
    let mut out = String::from("surface,x,y,z,reference");
    for r in &sweep.rows {
        out += &format!(",{}/{}/{}", r.method, r.solver, r.budget());
    }
    out.push('\n');
    for (k, (surface, p, reference)) in sweep.points.iter().enumerate() {
        out += &format!(
            "{},{},{},{},{:e}",
            csv_field(surface),
            p.x,
            p.y,
            p.z,
            reference
        );
        for r in &sweep.rows {
            out += &format!(",{:e}", r.values.get(k).copied().unwrap_or(f64::NAN));
        }
        out.push('\n');
    }
    out
}

/// A CSV field: quoted when it holds a comma or a quote.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// The sweep as CSV, a row per run.
pub fn sweep_csv(sweep: &Sweep) -> String {
    let mut out = String::from(
        "method,max_elements,refine_tol,triangles,vertices,seconds,rms_relative,max_relative,penumbra_rms_relative,solver,photons,final_gather\n",
    );
    for r in &sweep.rows {
        out += &format!(
            "{},{},{},{},{},{:.6},{:.6e},{:.6e},{:.6e},{},{},{}\n",
            r.method,
            r.max_elements,
            r.refine_tol.map_or(String::new(), |t| format!("{t:e}")),
            r.triangles,
            r.vertices,
            r.seconds,
            r.rms,
            r.max,
            r.penumbra_rms,
            r.solver,
            r.photons.map_or(String::new(), |p| p.to_string()),
            r.final_gather.map_or(String::new(), |p| p.to_string())
        );
    }
    out
}
