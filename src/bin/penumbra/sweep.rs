//! `penumbra sweep`: error against elements and time, over methods and budgets.

use std::path::{Path, PathBuf};

use crate::progress_bar::Bars;
use anyhow::Context;
use penumbra::experiments::sweep::{Sweep, SweepOptions};
use penumbra_scenes::{ObjOptions, Scene, SurfaceId};
use penumbra_solver::SolverOptions;
use penumbra_solver::path_trace::MAX_PATHS;

use crate::failure::{Command, Failure, invalid_option, run_failure, usage};
use crate::load;
use crate::run_args::SolverArg;

#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  penumbra sweep textbook --direct-only                  exact direct light, four meshes, five budgets\n  penumbra sweep cornell --budgets 5000,10000,20000 --methods discontinuity \\\n      --solvers progressive,hierarchical                 solvers against a path-traced reference\n  penumbra sweep cornell --direct-only --surfaces floor  the floor's error alone"
)]
pub(crate) struct SweepArgs {
    /// A .json, .obj, .gltf or .glb file, or the name of a built-in scene.
    scene: String,
    /// Output directory.
    #[arg(long, default_value = "sweep")]
    out: PathBuf,
    /// Element budgets, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "2500,5000,10000,20000,30000"
    )]
    budgets: Vec<usize>,
    /// Fit each budget to the scene as a run's default budget is: at least that many triangles,
    /// or the scene's least mesh and a triangle more per surface when that is more.
    #[arg(long)]
    fitted: bool,
    /// Tolerance of the adaptive runs at the first budget, relative to the mean reflected
    /// radiosity (as `run --refine-tol`); it shrinks in proportion as the budget grows, so that larger budgets are spent.
    #[arg(long, default_value_t = 1e-3)]
    refine_tol: f64,
    /// Tolerance of the error-driven runs (as `run --tol`).
    #[arg(long, default_value_t = penumbra::error_mesh::DEFAULT_TOLERANCE)]
    tol: f64,
    /// Smallest angle of the discontinuity and error-driven meshes, in degrees (as `run
    /// --min-angle`).
    #[arg(long, value_name = "DEG", default_value_t = penumbra::DEFAULT_MIN_ANGLE_DEG)]
    min_angle: f64,
    /// Sample points the runs are scored at (default: 4000 with --direct-only, else 1000).
    #[arg(long)]
    samples: Option<usize>,
    /// Seed of the sample points.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Direct light only, scored against the exact evaluator. Without it, full solutions are
    /// scored against path tracing at the samples, cached in the output directory.
    #[arg(long)]
    direct_only: bool,
    /// Paths per sample of the path-traced reference (on the Cornell box, 100,000 paths give a
    /// standard error of about 0.2 % of the mean).
    #[arg(long, default_value_t = 100_000)]
    reference_paths: usize,
    /// Score on these surfaces only (names, comma-separated; default: every surface that does
    /// not emit).
    #[arg(long, value_delimiter = ',')]
    surfaces: Vec<String>,
    /// The methods to run (comma-separated; default: the first three): `error-driven` is a run's
    /// default mesh, `discontinuity` the discontinuity mesh graded by area alone. `discontinuity` meshes the
    /// default events (complete); `discontinuity-complete` and `discontinuity-extremal` name
    /// them (`run --events complete|extremal`).
    #[arg(long, value_delimiter = ',', value_parser = ["error-driven", "uniform", "uniform+adaptive", "discontinuity", "discontinuity+adaptive", "discontinuity-complete", "discontinuity-extremal"])]
    methods: Vec<String>,
    /// The solvers to compare, comma-separated (default: progressive). Adaptive runs use
    /// progressive refinement or the hierarchical solver.
    #[arg(long, value_delimiter = ',', value_enum)]
    solvers: Vec<SolverArg>,
    /// The adaptive runs start from this fraction of the budget (their initial meshes are not
    /// graded: refinement finds the penumbrae).
    #[arg(long, default_value_t = penumbra::adaptive::INITIAL_FRACTION)]
    initial_fraction: f64,
    /// The solvers' stopping tolerance, as `run --epsilon`: the unshot fraction of the emitted
    /// power for progressive refinement, the relative residual for the others.
    #[arg(long, default_value_t = SolverOptions::default().epsilon)]
    epsilon: f64,
    /// Rays per vertex–patch pair for visibility.
    #[arg(long, default_value_t = SolverOptions::default().visibility_rays)]
    rays: usize,
    /// With --solvers hierarchical: the light a link may carry wrongly, as a fraction of the
    /// light the surfaces reflect of the direct light.
    #[arg(long, default_value_t = penumbra_solver::hierarchical::DEFAULT_LINK_TOL)]
    link_tol: f64,
    /// With --solvers photon-map: its budgets, photons emitted (comma-separated), in place of
    /// --budgets.
    #[arg(long, value_delimiter = ',', default_values_t = penumbra::experiments::sweep::DEFAULT_PHOTON_BUDGETS)]
    photons: Vec<usize>,
    /// With --solvers photon-map: the element budget of its meshes.
    #[arg(long, default_value_t = penumbra::DEFAULT_MAX_ELEMENTS)]
    photon_elements: usize,
    /// With --solvers photon-map: photons each estimate of the indirect light gathers.
    #[arg(long, default_value_t = penumbra_solver::photon_map::DEFAULT_GATHER_PHOTONS)]
    gather_photons: usize,
    /// With --solvers photon-map: rays per vertex of the final gather (0: none); several,
    /// comma-separated, give a line of photon budgets each.
    #[arg(long, value_name = "RAYS", value_delimiter = ',', default_values_t = [penumbra_solver::photon_map::DEFAULT_FINAL_GATHER])]
    final_gather: Vec<usize>,
    /// No progress bar and no table.
    #[arg(long)]
    quiet: bool,
}

/// Runs the sweep the arguments ask for, scored against the exact direct light or a path-traced
/// reference, writes its files and prints its table.
pub(crate) fn sweep(args: &SweepArgs) -> Result<(), Failure> {
    let options = sweep_options(args);
    options
        .validate()
        .map_err(|e| invalid_option(&e, Command::Sweep))?;
    if !(1..=MAX_PATHS).contains(&args.reference_paths) {
        return Err(usage(anyhow::anyhow!(
            "--reference-paths must be from 1 to {MAX_PATHS}, not {}",
            args.reference_paths
        )));
    }
    let loaded = load(&args.scene, ObjOptions::default())?;
    let surfaces = scored_surfaces(&loaded.scene, &args.surfaces)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let scene = &loaded.scene;
    let visibility = penumbra_scenes::Visibility::build(scene);
    let samples = penumbra::experiments::sweep::sample_points(
        scene,
        &visibility,
        &surfaces,
        options.samples,
        args.seed,
    );
    if samples.is_empty() {
        return Err(usage(anyhow::anyhow!(
            "no sample points: the surfaces scored must not all be emitters"
        )));
    }
    let reference = if args.direct_only {
        penumbra::experiments::sweep::Reference::ExactDirect
    } else {
        penumbra::experiments::sweep::Reference::PathTraced(traced_reference(
            args,
            &loaded,
            &visibility,
            &samples,
        )?)
    };
    let bars = Bars::new(args.quiet);
    let result =
        penumbra::experiments::sweep::sweep(&loaded, &options, &samples, &reference, &bars)
            .map_err(|e| {
                photon_budget_failure(&e, args).unwrap_or_else(|| run_failure(e, Command::Sweep))
            })?;
    write_sweep(&args.out, &result)?;
    if !args.quiet {
        print_sweep(&result, &args.out);
    }
    Ok(())
}

/// The sweep the arguments ask for, not yet validated.
fn sweep_options(args: &SweepArgs) -> SweepOptions {
    let methods = match args.methods.is_empty() {
        true => penumbra::experiments::sweep::SweepMethod::DEFAULT.to_vec(),
        false => penumbra::experiments::sweep::SweepMethod::ALL
            .into_iter()
            .filter(|m| args.methods.iter().any(|n| n == m.name()))
            .collect(),
    };
    SweepOptions {
        budgets: args.budgets.clone(),
        fitted: args.fitted,
        methods,
        surfaces: args.surfaces.clone(),
        refine_tol: args.refine_tol,
        tolerance: args.tol,
        min_angle: args.min_angle,
        initial_fraction: args.initial_fraction,
        samples: args
            .samples
            .unwrap_or(if args.direct_only { 4000 } else { 1000 }),
        seed: args.seed,
        solver: SolverOptions {
            direct_only: args.direct_only,
            epsilon: args.epsilon,
            visibility_rays: args.rays,
            link_tol: args.link_tol,
            photon_map: penumbra_solver::photon_map::PhotonMapOptions {
                gather_photons: args.gather_photons,
                ..Default::default()
            },
            ..SolverOptions::default()
        },
        solvers: args.solvers.iter().map(|&s| s.into()).collect(),
        photons: distinct(&args.photons),
        final_gathers: distinct(&args.final_gather),
        photon_elements: args.photon_elements,
    }
}

/// The surfaces `--surfaces` names, or a usage error naming one the scene does not have.
fn scored_surfaces(scene: &Scene, names: &[String]) -> Result<Vec<SurfaceId>, Failure> {
    let mut surfaces = Vec::new();
    for name in names {
        surfaces.push(scene.surface_id(name).ok_or_else(|| {
            usage(anyhow::anyhow!(
                "--surfaces: the scene has no surface named {name:?}"
            ))
        })?);
    }
    Ok(surfaces)
}

/// Writes `sweep.csv`, `samples.csv`, `sweep.json` and the charts (SVG and PNG) to `out`.
fn write_sweep(out: &Path, result: &Sweep) -> Result<(), Failure> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let csv = penumbra::experiments::sweep::sweep_csv(result);
    penumbra::outputs::write_atomic(&out.join("sweep.csv"), csv.as_bytes())?;
    let samples = penumbra::experiments::sweep::samples_csv(result);
    penumbra::outputs::write_atomic(&out.join("samples.csv"), samples.as_bytes())?;
    let json = serde_json::to_string_pretty(result)?;
    penumbra::outputs::write_atomic(&out.join("sweep.json"), json.as_bytes())?;
    for (stem, chart) in penumbra::experiments::sweep::sweep_charts(result) {
        penumbra::outputs::write_atomic(&out.join(format!("{stem}.svg")), chart.svg()?.as_bytes())?;
        penumbra::outputs::write_atomic(&out.join(format!("{stem}.png")), &chart.png()?)?;
    }
    Ok(())
}

/// Prints the sweep's reference, a table of its rows and where it was written (`out`).
fn print_sweep(result: &Sweep, out: &Path) {
    println!(
        "{}: {} samples ({} in penumbrae), reference ({}) mean {:.4e}, standard error {:.3}%",
        result.scene,
        result.samples,
        result.penumbra_samples,
        result.reference,
        result.reference_mean,
        100.0 * result.reference_standard_error
    );
    println!(
        "{:<24} {:<13} {:>16} {:>9} {:>9} {:>10} {:>10} {:>12}",
        "method", "solver", "budget", "triangles", "seconds", "rms", "max", "penumbra rms"
    );
    for r in &result.rows {
        let budget = r.budget();
        println!(
            "{:<24} {:<13} {:>16} {:>9} {:>9.3} {:>9.4}% {:>9.3}% {:>11.4}%",
            r.method,
            r.solver,
            budget,
            r.triangles,
            r.seconds,
            100.0 * r.rms,
            100.0 * r.max,
            100.0 * r.penumbra_rms
        );
    }
    println!(
        "wrote sweep.csv, samples.csv, sweep.json and the charts error-vs-elements and error-vs-time (SVG, PNG) to {}",
        out.display()
    );
}

/// The path-traced reference at the sweep's samples: read from `reference.json` in the output
/// directory when it was traced for the same scene, samples, seed and paths, else traced and
/// written there.
fn traced_reference(
    args: &SweepArgs,
    loaded: &penumbra_scenes::LoadedScene,
    visibility: &penumbra_scenes::Visibility,
    samples: &[penumbra::experiments::sweep::Sample],
) -> Result<Vec<penumbra_solver::path_trace::ReferenceValue>, Failure> {
    #[derive(serde::Serialize, serde::Deserialize)]
    struct Cached {
        format: String,
        scene: String,
        source: String,
        samples: usize,
        seed: u64,
        paths: usize,
        #[serde(default)]
        surfaces: Vec<String>,
        values: Vec<penumbra_solver::path_trace::ReferenceValue>,
    }
    let path = args.out.join("reference.json");
    let wanted = |c: &Cached| {
        c.format == "penumbra-reference/1"
            && c.scene == loaded.scene.name
            && c.source == loaded.source
            && c.samples == samples.len()
            && c.seed == args.seed
            && c.paths == args.reference_paths
            && c.surfaces == args.surfaces
            && c.values.len() == samples.len()
    };
    if let Some(cached) = std::fs::read_to_string(&path)
        .ok()
        .and_then(|text| serde_json::from_str::<Cached>(&text).ok())
        .filter(|c| wanted(c))
    {
        return Ok(cached.values);
    }
    if !args.quiet {
        eprintln!(
            "tracing the reference: {} samples x {} paths (cached in {})",
            samples.len(),
            args.reference_paths,
            path.display()
        );
    }
    let tracer = penumbra_solver::path_trace::PathTracer::new(&loaded.scene, visibility);
    let points: Vec<_> = samples.iter().map(|s| (s.point, s.surface)).collect();
    let values = tracer.radiosity(
        &points,
        &penumbra_solver::path_trace::PathTraceOptions {
            paths: args.reference_paths,
            seed: args.seed,
        },
    );
    let cached = Cached {
        format: "penumbra-reference/1".into(),
        scene: loaded.scene.name.clone(),
        source: loaded.source.clone(),
        samples: samples.len(),
        seed: args.seed,
        paths: args.reference_paths,
        surfaces: args.surfaces.clone(),
        values,
    };
    penumbra::outputs::write_atomic(&path, serde_json::to_string(&cached)?.as_bytes())?;
    Ok(cached.values)
}

/// A photon-map mesh budget too small for the scene, told as `--photon-elements`.
fn photon_budget_failure(e: &penumbra::RunError, args: &SweepArgs) -> Option<Failure> {
    let penumbra::RunError::Mesh(penumbra_meshing::MeshError::BudgetTooSmall {
        max_elements,
        needed,
        ..
    }) = e
    else {
        return None;
    };
    (*max_elements == args.photon_elements && !args.budgets.contains(max_elements)).then(|| {
        usage(anyhow::anyhow!(
            "--photon-elements {max_elements} is too small: the scene needs at least {needed} \
             triangles; use --photon-elements {needed} or more"
        ))
    })
}

/// `values` without repeats, in the order given.
fn distinct(values: &[usize]) -> Vec<usize> {
    let mut seen = Vec::new();
    for &v in values {
        if !seen.contains(&v) {
            seen.push(v);
        }
    }
    seen
}
