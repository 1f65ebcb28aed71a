//! `penumbra`: radiosity with exact direct light from area sources, from the command line.
//!
//! Exit codes: 0 success, 1 the run failed, 2 bad input or usage.
#![allow(clippy::print_stdout, clippy::print_stderr)]

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use anyhow::Context;
use clap::{Parser, Subcommand, ValueEnum};
use penumbra::outputs::{DEFAULT_SVG_SURFACES, SvgSelection, write_outputs};
use penumbra::progress_bar::Bars;
use penumbra::{DEFAULT_MAX_ELEMENTS, MeshMethod, RunOptions};
use penumbra_meshing::grading::DEFAULT_PENUMBRA_DENSITY;
use penumbra_meshing::{ElementBudget, FIT_TRIANGLES_PER_SURFACE, MeshError};
use penumbra_scenes::{ObjOptions, SceneError, builtin, load_scene_with};
use penumbra_solver::progressive::DEFAULT_EPSILON;
use penumbra_solver::{Interrupt, SolverOptions};

// The help texts below give these figures in words.
const _: () = assert!(
    DEFAULT_MAX_ELEMENTS == 10_000
        && penumbra::HIERARCHICAL_MAX_ELEMENTS == 25_000
        && FIT_TRIANGLES_PER_SURFACE == 1
        && DEFAULT_SVG_SURFACES == 24
);

#[derive(Parser, Debug)]
#[command(version, about = "Radiosity meshes that respect where shadows change")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Mesh, solve and render a scene; write solution.json, report.json, render.png and the
    /// SVGs of the surfaces worth looking at (--svg).
    Run(RunArgs),
    /// Run uniform, uniform + adaptive, discontinuity and discontinuity + adaptive meshes over a
    /// ladder of element budgets and score each against a reference; write sweep.csv and
    /// sweep.json.
    Sweep(SweepArgs),
    /// Measure every form-factor method (analytic, Monte Carlo, hemicube) against closed forms:
    /// error against cost, point by point, the hemicube's aliasing, the 1 x 2 x 3 box's face
    /// factors and dense solutions of a unit cube; write form-factors.json and print the tables.
    FormFactors(FormFactorArgs),
    /// Join the outputs of the shards of a run (`run --shard I/N`) into one: solution.json as
    /// the run not split would have written it, report.json with the shards' figures joined,
    /// render.png and the shards' SVGs.
    Merge(MergeArgs),
    /// List the built-in scenes.
    Scenes,
    /// Load and validate a scene, reporting every problem at once.
    Check {
        /// A .json or .obj file, or the name of a built-in scene.
        scene: String,
        /// OBJ files: keep every face as its own surface (by default coplanar adjacent faces of
        /// one material are merged where the union is a simple polygon).
        #[arg(long)]
        no_merge: bool,
    },
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum MeshArg {
    /// Constrained Delaunay triangulation of each polygon, refined to a uniform size.
    Uniform,
    /// The same, with the umbra and penumbra boundaries of the direct light as mesh edges.
    Discontinuity,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum EventsArg {
    /// Every EV and VE event: each light edge with each blocker vertex on the blocker's outline,
    /// each light vertex with each blocker edge on it, each blocker vertex with an edge of
    /// another blocker in a plane through the light.
    Complete,
    /// Only the umbra and outer penumbra boundaries (and contact lines, and EEE events).
    Extremal,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum FormFactorArg {
    Analytic,
    MonteCarlo,
    Hemicube,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum SolverArg {
    Progressive,
    Jacobi,
    GaussSeidel,
    Direct,
    Hierarchical,
}

impl From<SolverArg> for penumbra_solver::SolverMethod {
    fn from(a: SolverArg) -> Self {
        match a {
            SolverArg::Progressive => Self::Progressive,
            SolverArg::Jacobi => Self::Jacobi,
            SolverArg::GaussSeidel => Self::GaussSeidel,
            SolverArg::Direct => Self::Direct,
            SolverArg::Hierarchical => Self::Hierarchical,
        }
    }
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum IndirectArg {
    /// From the jumps of the indirect light's gradient across each triangle's edges.
    Gradient,
    /// Gathered at each triangle's centroid from the patches shot so far.
    Gathered,
}

impl From<IndirectArg> for penumbra_solver::estimate::IndirectEstimate {
    fn from(a: IndirectArg) -> Self {
        match a {
            IndirectArg::Gradient => Self::GradientJumps,
            IndirectArg::Gathered => Self::Gathered,
        }
    }
}

#[derive(clap::Args, Debug)]
struct RunArgs {
    /// A .json or .obj file, or the name of a built-in scene (see `penumbra scenes`).
    scene: String,
    /// OBJ files: keep every face as its own surface (by default coplanar adjacent faces of one
    /// material are merged where the union is a simple polygon).
    #[arg(long)]
    no_merge: bool,
    /// Output directory.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// How surfaces are meshed (default: discontinuity where the scene casts shadows, else
    /// uniform).
    #[arg(long, value_enum)]
    mesh: Option<MeshArg>,
    /// Cap on triangles for the whole scene, spread over the surfaces by area. Default: what the
    /// scene needs: 25,000 with the hierarchical solver (its cost grows about linearly with the
    /// vertices), 10,000 with the others or --direct-only, or, when that is too few, the least
    /// mesh of its polygons with their discontinuities as edges and 1 triangle more per surface.
    #[arg(long)]
    max_elements: Option<usize>,
    /// Discontinuity meshes: how many times smaller in area triangles are in partial shadow than
    /// in full light or full shadow (1: no grading). Default: 8, or 1 with --refine-tol, where
    /// refinement finds the penumbrae itself.
    #[arg(long)]
    penumbra_density: Option<f64>,
    /// Adaptive refinement: start from a coarser mesh and split, round after round, the triangles
    /// whose interpolation misses the exact direct light by more than this fraction of the
    /// scene's mean radiosity, up to --max-elements.
    #[arg(long)]
    refine_tol: Option<f64>,
    /// With --refine-tol: triangles of the starting mesh (default: a tenth of --max-elements;
    /// without --max-elements, a tenth of 10,000, or the scene's least mesh if that is more).
    #[arg(long)]
    initial_elements: Option<usize>,
    /// With --refine-tol, in full solutions: how the indirect light's interpolation error is
    /// estimated: from its gradient's jumps across edges (free), or gathered at each triangle's
    /// centroid from the patches shot so far (a form factor per shooter and triangle).
    #[arg(long, value_enum, default_value_t = IndirectArg::Gradient)]
    refine_indirect: IndirectArg,
    /// With --refine-tol: rounds of refinement at most.
    #[arg(long, default_value_t = penumbra::adaptive::DEFAULT_MAX_ROUNDS)]
    refine_rounds: usize,
    /// How the radiosity system is solved: hierarchical radiosity with clustering (links refined
    /// to --link-tol, then a final gather at every vertex), progressive refinement (shooting: an
    /// image at any moment), Jacobi or Gauss–Seidel gathering over the patch form-factor matrix,
    /// or its dense direct solve (the discrete system's exact answer). Hierarchical, gathering
    /// and direct solves stop at a relative residual of --epsilon, or after --max-shots sweeps;
    /// progressive refinement when the unshot power is below --epsilon.
    #[arg(long, value_enum, default_value_t = SolverArg::Hierarchical)]
    solver: SolverArg,
    /// With --solver hierarchical: the light a link may carry wrongly, as a fraction of the
    /// light the surfaces reflect of the direct light; smaller is finer and slower.
    #[arg(long, default_value_t = penumbra_solver::hierarchical::DEFAULT_LINK_TOL)]
    link_tol: f64,
    /// How vertex-to-patch form factors are computed: Lambert's formula times a ray-sampled
    /// visibility fraction, Monte Carlo over each patch (--ff-samples points, each with a ray),
    /// or a hemicube z-buffer at each vertex (--hemicube-resolution; not with --refine-tol).
    #[arg(long, value_enum, default_value_t = FormFactorArg::Analytic)]
    form_factors: FormFactorArg,
    /// With --form-factors monte-carlo: samples per vertex and patch.
    #[arg(long, default_value_t = 256)]
    ff_samples: usize,
    /// With --form-factors hemicube: pixels across the hemicube's top face (even; the side
    /// faces are half as tall).
    #[arg(long, default_value_t = 128)]
    hemicube_resolution: usize,
    /// Also write the solver's residual against iterations and against time: convergence.csv,
    /// convergence-iterations.svg/.png and convergence-time.svg/.png.
    #[arg(long)]
    convergence: bool,
    /// Stop after this many seconds (from the start of the run) and write the best solution so
    /// far; report.json says so. The discontinuity search skips the pairs left, the direct light
    /// estimates the vertices left by rays, and refinement and shooting stop.
    #[arg(long)]
    time_budget: Option<f64>,
    /// Discontinuity meshes: leave out EEE events (emitter edge with two blocker edges).
    #[arg(long)]
    no_eee: bool,
    /// Discontinuity meshes: which EV and VE events become mesh edges.
    #[arg(long, value_enum, default_value_t = EventsArg::Complete)]
    events: EventsArg,
    /// Discontinuity meshes: blockers (flat patches of faces) that can hide less than this
    /// fraction of a light from a receiver start no events there; adaptive refinement and the
    /// penumbra grading mesh their shadows instead.
    #[arg(long, default_value_t = penumbra_meshing::discontinuity::DEFAULT_EVENT_TOLERANCE)]
    event_tol: f64,
    /// Stop shooting when the unshot power is below this fraction of the emitted power.
    #[arg(long, default_value_t = DEFAULT_EPSILON)]
    epsilon: f64,
    /// Stop after this many patch shots, converged or not.
    #[arg(long, default_value_t = SolverOptions::default().max_shots)]
    max_shots: usize,
    /// One exact bounce of direct light only: B = E + rho * H_direct.
    #[arg(long)]
    direct_only: bool,
    /// Visibility rays per vertex-patch pair.
    #[arg(long, default_value_t = SolverOptions::default().visibility_rays)]
    rays: usize,
    /// Mesh elements grouped into one shooting patch.
    #[arg(long, default_value_t = SolverOptions::default().elements_per_patch)]
    elements_per_patch: usize,
    /// Seed of the visibility sampling.
    #[arg(long, default_value_t = SolverOptions::default().seed)]
    seed: u64,
    /// Worker threads (default: one per core).
    #[arg(long)]
    threads: Option<usize>,
    /// Memory the run may use, in MiB (default: what the machine has available). A run that
    /// would need more stops before it starts, with the largest --max-elements that fits.
    #[arg(long)]
    memory_limit: Option<f64>,
    /// Render width in pixels.
    #[arg(long, default_value_t = 640)]
    width: u32,
    /// Render height in pixels.
    #[arg(long, default_value_t = 640)]
    height: u32,
    /// Where the render looks from and at, as EX,EY,EZ:TX,TY,TZ, with the vertical field of view
    /// in degrees after a third colon (default 45); upright as the default view. It replaces
    /// the scene's own camera, and the default one that frames the whole scene.
    #[arg(long, value_name = "EYE:TARGET[:FOV]", allow_hyphen_values = true)]
    camera: Option<String>,
    /// Which surfaces get an SVG in OUT/surfaces: `auto` (every surface of a scene of at most 24,
    /// else the 24 with the most discontinuity segments, then the largest), `all`, `none`, or
    /// surface names, comma-separated.
    #[arg(long, default_value = "auto", value_name = "auto|all|none|NAME,...")]
    svg: String,
    /// No progress bars, no summary and no warnings.
    #[arg(long)]
    quiet: bool,
    /// With --direct-only: light only shard I of N (I from 0 to N - 1), the surfaces whose
    /// index is I modulo N, and write OUT/shard.json and their SVGs for `penumbra merge`. In a
    /// scene whose polygons need more than the budget's floor, with the fitted budget, the shard
    /// also finds the discontinuities of its own surfaces and meshes them alone; otherwise it
    /// meshes the whole scene (each surface's share of the budget depends on all of them).
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
}

#[derive(clap::Args, Debug)]
struct MergeArgs {
    /// The output directories of the shards (`run --shard I/N --out DIR`), every shard once.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// The scene the shards were run on, to render the joined solution (default: as the shards
    /// were given it; checked against their fingerprint).
    #[arg(long)]
    scene: Option<String>,
    /// No summary.
    #[arg(long)]
    quiet: bool,
}

#[derive(clap::Args, Debug)]
struct SweepArgs {
    /// A .json or .obj file, or the name of a built-in scene.
    scene: String,
    /// Output directory.
    #[arg(long, default_value = "sweep")]
    out: PathBuf,
    /// Element budgets, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [2500, 5000, 10000, 20000, 30000])]
    budgets: Vec<usize>,
    /// Tolerance of the adaptive runs at the first budget, relative to the scene's mean
    /// radiosity; it shrinks in proportion as the budget grows, so that larger budgets are spent.
    #[arg(long, default_value_t = 1e-3)]
    refine_tol: f64,
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
    /// The methods to run (comma-separated; default: the first four). `discontinuity` meshes the
    /// default events (complete); `discontinuity-complete` and `discontinuity-extremal` name
    /// them (`run --events complete|extremal`).
    #[arg(long, value_delimiter = ',', value_parser = ["uniform", "uniform+adaptive", "discontinuity", "discontinuity+adaptive", "discontinuity-complete", "discontinuity-extremal"])]
    methods: Vec<String>,
    /// The solvers to compare, comma-separated (default: progressive). Adaptive runs use
    /// progressive refinement or the hierarchical solver.
    #[arg(long, value_delimiter = ',', value_enum)]
    solvers: Vec<SolverArg>,
    /// The adaptive runs start from this fraction of the budget (their initial meshes are not
    /// graded: refinement finds the penumbrae).
    #[arg(long, default_value_t = penumbra::adaptive::INITIAL_FRACTION)]
    initial_fraction: f64,
    /// Stop shooting when the unshot power falls below this fraction of the emitted power.
    #[arg(long, default_value_t = SolverOptions::default().epsilon)]
    epsilon: f64,
    /// Rays per vertex–patch pair for visibility.
    #[arg(long, default_value_t = SolverOptions::default().visibility_rays)]
    rays: usize,
    /// With --solvers hierarchical: the light a link may carry wrongly, as a fraction of the
    /// light the surfaces reflect of the direct light.
    #[arg(long, default_value_t = penumbra_solver::hierarchical::DEFAULT_LINK_TOL)]
    link_tol: f64,
    /// No progress bar and no table.
    #[arg(long)]
    quiet: bool,
}

#[derive(clap::Args, Debug)]
struct FormFactorArgs {
    /// Output directory (created if missing).
    #[arg(long, default_value = "out/form-factors")]
    out: PathBuf,
    /// Rays per point–patch pair for the analytic method's visibility fraction.
    #[arg(long, default_value_t = SolverOptions::default().visibility_rays)]
    rays: usize,
    /// Monte Carlo sample counts to measure (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [64, 256, 4096])]
    samples: Vec<usize>,
    /// Hemicube resolutions to measure (comma-separated, even).
    #[arg(long, value_delimiter = ',', default_values_t = [32, 64, 128, 256, 512])]
    resolutions: Vec<usize>,
    /// Independent random streams the stochastic methods' errors are averaged over.
    #[arg(long, default_value_t = 16)]
    streams: usize,
    /// Triangles of the unit cube's mesh.
    #[arg(long, default_value_t = 2400)]
    cube_elements: usize,
}

/// A failure, and whether it was the user's input (exit 2) or the run (exit 1).
struct Failure {
    error: anyhow::Error,
    usage: bool,
}

impl<E: Into<anyhow::Error>> From<E> for Failure {
    fn from(e: E) -> Self {
        Failure {
            error: e.into(),
            usage: false,
        }
    }
}

/// Which command's options set the element budget, for messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum BudgetOptions {
    /// `run`: `--max-elements` and `--initial-elements`.
    Run,
    /// `sweep`: `--budgets` and `--initial-fraction`.
    Sweep,
}

/// A pipeline error: the user's (exit 2) when it comes from bad options, else the run's.
fn run_failure(e: penumbra::RunError, options: BudgetOptions) -> Failure {
    if let Some(message) = budget_message(&e, options) {
        return usage(anyhow::anyhow!(message));
    }
    if let penumbra::RunError::Solve(e) = e {
        return solve_failure(e);
    }
    if e.is_usage() {
        usage(e)
    } else {
        Failure::from(e)
    }
}

/// A solver error; a bad option is told by the flag that set it.
fn solve_failure(e: penumbra_solver::SolveError) -> Failure {
    use penumbra_solver::SolveError;
    let flag = |option: &str| match option {
        "epsilon" => Some("--epsilon"),
        "link tolerance" => Some("--link-tol"),
        "visibility rays" => Some("--rays"),
        "elements per patch" => Some("--elements-per-patch"),
        "form-factor samples" => Some("--ff-samples"),
        "form factors" => Some("--form-factors"),
        "solver" => Some("--solver"),
        "direct only" => Some("--direct-only"),
        "refine indirect" => Some("--refine-indirect"),
        _ => None,
    };
    match e {
        SolveError::InvalidOption { option, reason } => usage(match flag(option) {
            Some(flag) => anyhow::anyhow!("invalid {flag} ({option}): {reason}"),
            None => anyhow::anyhow!("invalid {option}: {reason}"),
        }),
        e => Failure::from(penumbra::RunError::Solve(e)),
    }
}

/// An element budget too small for the scene, told in terms of the option that set it.
fn budget_message(e: &penumbra::RunError, options: BudgetOptions) -> Option<String> {
    let (initial, source) = match e {
        penumbra::RunError::Mesh(source) => (false, source),
        penumbra::RunError::InitialBudget(source) => (true, source),
        _ => return None,
    };
    let MeshError::BudgetTooSmall {
        max_elements,
        needed,
        discontinuities,
    } = source
    else {
        return None;
    };
    let what = if *discontinuities {
        "the scene's polygons, with their discontinuities as edges,"
    } else {
        "the scene's polygons"
    };
    let need = format!("{what} need at least {needed} triangles");
    Some(match (options, initial) {
        (BudgetOptions::Run, false) => format!(
            "--max-elements {max_elements} is too small: {need}; use --max-elements {needed} or \
             more (or leave it out: by default the budget fits the scene)"
        ),
        (BudgetOptions::Run, true) => format!(
            "--initial-elements {max_elements} is too small for the starting mesh of adaptive \
             refinement (by default a tenth of --max-elements): {need}; use --initial-elements \
             {needed} or more"
        ),
        (BudgetOptions::Sweep, false) => format!(
            "--budgets: {max_elements} is too small: {need}; use budgets of {needed} or more"
        ),
        (BudgetOptions::Sweep, true) => format!(
            "--initial-fraction: the starting mesh of adaptive refinement, {max_elements} \
             triangles, is too small: {need}; use a larger --initial-fraction, or larger budgets"
        ),
    })
}

fn usage(error: impl Into<anyhow::Error>) -> Failure {
    Failure {
        error: error.into(),
        usage: true,
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match dispatch(cli) {
        Ok(code) => code,
        Err(f) => {
            eprintln!("error: {:#}", f.error);
            ExitCode::from(if f.usage { 2 } else { 1 })
        }
    }
}

fn dispatch(cli: Cli) -> Result<ExitCode, Failure> {
    match cli.command {
        Command::Scenes => {
            for (name, description) in builtin::NAMES {
                println!("{name:<10} {description}");
            }
        }
        Command::Check { scene, no_merge } => check(&scene, obj_options(no_merge))?,
        Command::Run(args) => return run(&args),
        Command::Sweep(args) => sweep(&args)?,
        Command::Merge(args) => merge(&args)?,
        Command::FormFactors(args) => form_factors(&args)?,
    }
    Ok(ExitCode::SUCCESS)
}

/// Ctrl-C (SIGINT) and SIGTERM set `interrupt`, so that the run stops shooting and writes what
/// it has; a second one ends the process at once. Returns the cell that records which signal
/// came.
fn catch_interrupts(interrupt: &Interrupt) -> std::io::Result<Arc<AtomicUsize>> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let received = Arc::new(AtomicUsize::new(0));
    for signal in [SIGINT, SIGTERM] {
        // Registered first, so it sees the flag as it was before this signal set it.
        signal_hook::flag::register_conditional_shutdown(signal, 128 + signal, interrupt.flag())?;
        signal_hook::flag::register(signal, interrupt.flag())?;
        signal_hook::flag::register_usize(signal, Arc::clone(&received), signal as usize)?;
    }
    Ok(received)
}

fn form_factors(args: &FormFactorArgs) -> Result<(), Failure> {
    let options = penumbra::form_factor_study::StudyOptions {
        rays: args.rays,
        samples: args.samples.clone(),
        resolutions: args.resolutions.clone(),
        streams: args.streams,
        cube_elements: args.cube_elements,
    };
    let study = penumbra::form_factor_study::run_study(&options).map_err(usage)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let path = args.out.join("form-factors.json");
    let json = serde_json::to_vec_pretty(&study)?;
    penumbra::outputs::write_atomic(&path, &json)
        .with_context(|| format!("cannot write {}", path.display()))?;
    #[allow(clippy::print_stdout)] // the tables are this command's output
    {
        println!("{}", study.markdown());
    }
    eprintln!("wrote {}", path.display());
    Ok(())
}

fn sweep(args: &SweepArgs) -> Result<(), Failure> {
    let sample_count = args
        .samples
        .unwrap_or(if args.direct_only { 4000 } else { 1000 });
    if args.budgets.is_empty() || sample_count == 0 {
        return Err(usage(anyhow::anyhow!(
            "--budgets and --samples must not be empty"
        )));
    }
    if !(args.refine_tol > 0.0 && args.refine_tol.is_finite()) {
        return Err(usage(anyhow::anyhow!(
            "--refine-tol must be a positive number, not {}",
            args.refine_tol
        )));
    }
    if !(args.initial_fraction > 0.0 && args.initial_fraction <= 1.0) {
        return Err(usage(anyhow::anyhow!(
            "--initial-fraction must be in (0, 1], not {}",
            args.initial_fraction
        )));
    }
    let loaded = load(&args.scene, ObjOptions::default())?;
    let mut surfaces = Vec::new();
    for name in &args.surfaces {
        surfaces.push(loaded.scene.surface_id(name).ok_or_else(|| {
            usage(anyhow::anyhow!(
                "--surfaces: the scene has no surface named {name:?}"
            ))
        })?);
    }
    let methods = match args.methods.is_empty() {
        true => penumbra::sweep::SweepMethod::DEFAULT.to_vec(),
        false => penumbra::sweep::SweepMethod::ALL
            .into_iter()
            .filter(|m| args.methods.iter().any(|n| n == m.name()))
            .collect(),
    };
    let options = penumbra::sweep::SweepOptions {
        budgets: args.budgets.clone(),
        methods,
        surfaces: args.surfaces.clone(),
        refine_tol: args.refine_tol,
        initial_fraction: args.initial_fraction,
        samples: sample_count,
        seed: args.seed,
        solver: SolverOptions {
            direct_only: args.direct_only,
            epsilon: args.epsilon,
            visibility_rays: args.rays,
            link_tol: args.link_tol,
            ..SolverOptions::default()
        },
        solvers: args.solvers.iter().map(|&s| s.into()).collect(),
    };
    options.solver.validate().map_err(solve_failure)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let scene = &loaded.scene;
    let visibility = penumbra_scenes::Visibility::build(scene);
    let samples =
        penumbra::sweep::sample_points(scene, &visibility, &surfaces, sample_count, args.seed);
    if samples.is_empty() {
        return Err(usage(anyhow::anyhow!(
            "no sample points: the surfaces scored must not all be emitters"
        )));
    }
    let reference = if args.direct_only {
        penumbra::sweep::Reference::ExactDirect
    } else {
        penumbra::sweep::Reference::PathTraced(traced_reference(
            args,
            &loaded,
            &visibility,
            &samples,
        )?)
    };
    let bars = Bars::new(args.quiet);
    let result = penumbra::sweep::sweep(&loaded, &options, &samples, &reference, &bars)
        .map_err(|e| run_failure(e, BudgetOptions::Sweep))?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let csv = penumbra::sweep::sweep_csv(&result);
    penumbra::outputs::write_atomic(&args.out.join("sweep.csv"), csv.as_bytes())?;
    let json = serde_json::to_string_pretty(&result)?;
    penumbra::outputs::write_atomic(&args.out.join("sweep.json"), json.as_bytes())?;
    for (stem, chart) in penumbra::sweep::sweep_charts(&result) {
        penumbra::outputs::write_atomic(
            &args.out.join(format!("{stem}.svg")),
            chart.svg().as_bytes(),
        )?;
        penumbra::outputs::write_atomic(&args.out.join(format!("{stem}.png")), &chart.png()?)?;
    }
    if !args.quiet {
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
            "{:<24} {:<13} {:>8} {:>9} {:>9} {:>10} {:>10} {:>12}",
            "method", "solver", "budget", "triangles", "seconds", "rms", "max", "penumbra rms"
        );
        for r in &result.rows {
            println!(
                "{:<24} {:<13} {:>8} {:>9} {:>9.3} {:>9.4}% {:>9.3}% {:>11.4}%",
                r.method,
                r.solver,
                r.max_elements,
                r.triangles,
                r.seconds,
                100.0 * r.rms,
                100.0 * r.max,
                100.0 * r.penumbra_rms
            );
        }
        println!(
            "wrote sweep.csv, sweep.json and the charts error-vs-elements and error-vs-time (SVG, PNG) to {}",
            args.out.display()
        );
    }
    Ok(())
}

/// The path-traced reference at the sweep's samples: read from `reference.json` in the output
/// directory when it was traced for the same scene, samples, seed and paths, else traced and
/// written there.
fn traced_reference(
    args: &SweepArgs,
    loaded: &penumbra_scenes::LoadedScene,
    visibility: &penumbra_scenes::Visibility,
    samples: &[penumbra::sweep::Sample],
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

/// `--camera EX,EY,EZ:TX,TY,TZ[:FOV]`.
fn camera_of(
    text: &str,
    scene: &penumbra_scenes::Scene,
) -> Result<penumbra_scenes::Camera, String> {
    let parts: Vec<&str> = text.split(':').collect();
    let point = |part: &str, what: &str| -> Result<glam::DVec3, String> {
        let numbers: Result<Vec<f64>, _> = part.split(',').map(|n| n.trim().parse()).collect();
        match numbers.as_deref() {
            Ok(&[x, y, z]) if [x, y, z].iter().all(|v| v.is_finite()) => {
                Ok(glam::DVec3::new(x, y, z))
            }
            _ => Err(format!(
                "the {what} must be three finite numbers x,y,z, not {part:?}"
            )),
        }
    };
    let (eye, target, fov) = match parts.as_slice() {
        [eye, target] => (point(eye, "eye")?, point(target, "target")?, None),
        [eye, target, fov] => {
            let fov: f64 = fov
                .trim()
                .parse()
                .map_err(|_| format!("the field of view must be a number, not {fov:?}"))?;
            (point(eye, "eye")?, point(target, "target")?, Some(fov))
        }
        _ => return Err("write it EX,EY,EZ:TX,TY,TZ or EX,EY,EZ:TX,TY,TZ:FOV".into()),
    };
    if eye == target {
        return Err("the eye and the target are the same point".into());
    }
    if fov.is_some_and(|f| !(f > 0.0 && f < 180.0)) {
        return Err("the field of view must lie between 0 and 180 degrees".into());
    }
    Ok(penumbra_viz::camera_looking(scene, eye, target, fov))
}

fn obj_options(no_merge: bool) -> ObjOptions {
    ObjOptions {
        merge_coplanar: !no_merge,
    }
}

fn load(spec: &str, options: ObjOptions) -> Result<penumbra_scenes::LoadedScene, Failure> {
    // Every scene error (unreadable, malformed, invalid) is the input's: exit code 2.
    load_scene_with(spec, &options).map_err(|e| {
        // What loading repaired often explains what validation then refused.
        if let SceneError::Invalid { warnings, .. } = &e {
            for w in warnings {
                eprintln!("warning: {w}");
            }
        }
        usage(e)
    })
}

fn check(spec: &str, options: ObjOptions) -> Result<(), Failure> {
    let loaded = load(spec, options)?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let s = &loaded.scene;
    println!(
        "{}: valid scene \"{}\": {} surfaces, {} emitting, total area {:.6e}, bounding-box diagonal {:.6e}",
        loaded.source,
        s.name,
        s.surfaces.len(),
        s.emitters().count(),
        s.total_area(),
        s.diagonal()
    );
    Ok(())
}

/// `--svg`: `auto`, `all`, `none`, or surface names of `scene`, comma-separated.
fn svg_selection(spec: &str, scene: &penumbra_scenes::Scene) -> Result<SvgSelection, Failure> {
    match spec.trim() {
        "auto" => return Ok(SvgSelection::Auto),
        "all" => return Ok(SvgSelection::All),
        "none" => return Ok(SvgSelection::None),
        _ => {}
    }
    let names: Vec<String> = spec.split(',').map(|n| n.trim().to_owned()).collect();
    if names.iter().any(String::is_empty) {
        return Err(usage(anyhow::anyhow!(
            "--svg takes auto, all, none or surface names separated by commas, not {spec:?}"
        )));
    }
    SvgSelection::named(scene, &names).map_err(|unknown| {
        let shown: Vec<String> = unknown.iter().take(10).map(|n| format!("{n:?}")).collect();
        let more = match unknown.len().saturating_sub(shown.len()) {
            0 => String::new(),
            n => format!(" and {n} more"),
        };
        usage(anyhow::anyhow!(
            "--svg: the scene has no surface named {}{more} (names are exact; `penumbra check` \
             counts the surfaces, report.json and solution.json list them)",
            shown.join(", ")
        ))
    })
}

/// `--shard I/N`, checked against the other options of `run`.
fn shard_of(text: &str, args: &RunArgs) -> Result<penumbra::shard::Shard, Failure> {
    use penumbra::shard::{Shard, ShardError};
    let shard = Shard::parse(text).map_err(|e| usage(anyhow::anyhow!("--shard: {e}")))?;
    let refused = |flag: &str, e: ShardError| usage(anyhow::anyhow!("--shard with {flag}: {e}"));
    if !args.direct_only {
        return Err(usage(anyhow::anyhow!(
            "--shard needs --direct-only: {}",
            ShardError::NeedsDirectOnly
        )));
    }
    if args.refine_tol.is_some() {
        return Err(refused("--refine-tol", ShardError::Refinement));
    }
    if args.time_budget.is_some() {
        return Err(refused("--time-budget", ShardError::TimeBudget));
    }
    if args.convergence {
        return Err(usage(anyhow::anyhow!(
            "--shard with --convergence: a direct-only run does not iterate, so there is no \
             convergence to write"
        )));
    }
    Ok(shard)
}

fn merge(args: &MergeArgs) -> Result<(), Failure> {
    use penumbra::shard::{MergeError, check_shards, merge, read_shard, write_merged};
    let fail = |e: MergeError| {
        if e.is_usage() {
            usage(e)
        } else {
            Failure::from(e)
        }
    };
    let mut shards = Vec::with_capacity(args.dirs.len());
    for dir in &args.dirs {
        shards.push((dir.clone(), read_shard(dir).map_err(fail)?));
    }
    let shards = check_shards(shards).map_err(fail)?;
    let origin = shards
        .first()
        .map(|(_, f)| f.scene.clone())
        .ok_or_else(|| fail(MergeError::Nothing))?;
    let spec = args.scene.clone().unwrap_or(origin.spec);
    let mut loaded = load_scene_with(&spec, &obj_options(origin.no_merge)).map_err(|e| {
        usage(anyhow::anyhow!(
            "{}; give the scene with --scene",
            MergeError::Scene(e)
        ))
    })?;
    if origin.camera.is_some() {
        loaded.scene.camera = origin.camera;
    }
    let merged = merge(shards, &loaded).map_err(|e| match e {
        MergeError::SceneChanged { .. } if args.scene.is_none() => usage(anyhow::anyhow!(
            "{e}; give the scene the shards were run on with --scene"
        )),
        e => fail(e),
    })?;
    let written = write_merged(&merged, &args.out)?;
    if !args.quiet {
        println!(
            "{}: {} shards joined: {} surfaces, {} triangles, {} vertices",
            merged.scene_name, merged.shards, merged.surfaces, merged.triangles, merged.vertices
        );
        println!("wrote {} files to {}", written.len(), args.out.display());
    }
    Ok(())
}

fn run(args: &RunArgs) -> Result<ExitCode, Failure> {
    if let Some(n) = args.threads {
        if n == 0 {
            return Err(usage(anyhow::anyhow!("--threads must be at least 1")));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("cannot start the worker threads")?;
    }
    let penumbra_density = args
        .penumbra_density
        .unwrap_or(if args.refine_tol.is_some() {
            1.0
        } else {
            DEFAULT_PENUMBRA_DENSITY
        });
    if !(1.0..=1e6).contains(&penumbra_density) {
        return Err(usage(anyhow::anyhow!(
            "--penumbra-density must be between 1 and 1e6, not {penumbra_density}"
        )));
    }
    if let Some(t) = args.time_budget
        && !(t > 0.0 && t.is_finite())
    {
        return Err(usage(anyhow::anyhow!(
            "--time-budget must be a positive number of seconds, not {t}"
        )));
    }
    if let Some(tol) = args.refine_tol
        && !(tol > 0.0 && tol.is_finite())
    {
        return Err(usage(anyhow::anyhow!(
            "--refine-tol must be a positive number, not {tol}"
        )));
    }
    if let Some(mib) = args.memory_limit
        && !(mib > 0.0 && mib.is_finite())
    {
        return Err(usage(anyhow::anyhow!(
            "--memory-limit must be a positive number of MiB, not {mib}"
        )));
    }
    if !(0.0..=1.0).contains(&args.event_tol) {
        return Err(usage(anyhow::anyhow!(
            "--event-tol must be a fraction between 0 and 1, not {}",
            args.event_tol
        )));
    }
    if args.width == 0 || args.height == 0 {
        return Err(usage(anyhow::anyhow!(
            "--width and --height must be at least 1"
        )));
    }
    let shard = args
        .shard
        .as_deref()
        .map(|text| shard_of(text, args))
        .transpose()?;
    let mut loaded = load(&args.scene, obj_options(args.no_merge))?;
    if let Some(text) = &args.camera {
        let camera = camera_of(text, &loaded.scene)
            .map_err(|e| usage(anyhow::anyhow!("--camera {text:?}: {e}")))?;
        loaded.scene.camera = Some(camera);
    }
    if !args.quiet {
        for w in &loaded.warnings {
            eprintln!("warning: {w}");
        }
    }
    let svgs = svg_selection(&args.svg, &loaded.scene)?;
    let interrupt = Interrupt::default();
    let received = catch_interrupts(&interrupt).context("cannot catch Ctrl-C")?;
    let options = RunOptions {
        method: args.solver.into(),
        mesh: match args.mesh {
            None => MeshMethod::Auto,
            Some(MeshArg::Uniform) => MeshMethod::Uniform,
            Some(MeshArg::Discontinuity) => MeshMethod::Discontinuity,
        },
        max_elements: args.max_elements.map_or(
            penumbra::default_budget(args.solver.into(), args.direct_only),
            ElementBudget::AtMost,
        ),
        penumbra_density,
        time_budget: args.time_budget,
        refine: args
            .refine_tol
            .map(|tolerance| penumbra::adaptive::RefineOptions {
                tolerance,
                initial_elements: args.initial_elements.unwrap_or(
                    (args.max_elements.unwrap_or(DEFAULT_MAX_ELEMENTS) as f64
                        * penumbra::adaptive::INITIAL_FRACTION) as usize,
                ),
                max_rounds: args.refine_rounds,
                indirect: args.refine_indirect.into(),
            }),
        discontinuity: penumbra_meshing::discontinuity::DiscontinuityOptions {
            eee: !args.no_eee,
            events: match args.events {
                EventsArg::Complete => penumbra_meshing::discontinuity::EventSet::Complete,
                EventsArg::Extremal => penumbra_meshing::discontinuity::EventSet::Extremal,
            },
            event_tolerance: args.event_tol,
            ..Default::default()
        },
        solver: SolverOptions {
            epsilon: args.epsilon,
            max_shots: args.max_shots,
            visibility_rays: args.rays,
            link_tol: args.link_tol,
            form_factors: match args.form_factors {
                FormFactorArg::Analytic => penumbra_solver::coupling::FormFactorMethod::Analytic,
                FormFactorArg::MonteCarlo => {
                    penumbra_solver::coupling::FormFactorMethod::MonteCarlo {
                        samples: args.ff_samples,
                    }
                }
                FormFactorArg::Hemicube => penumbra_solver::coupling::FormFactorMethod::Hemicube {
                    resolution: args.hemicube_resolution,
                },
            },
            elements_per_patch: args.elements_per_patch,
            direct_only: args.direct_only,
            seed: args.seed,
            interrupt: Some(interrupt.clone()),
            ..SolverOptions::default()
        },
        render: penumbra_viz::RenderOptions {
            width: args.width,
            height: args.height,
            ..Default::default()
        },
        memory_limit: args.memory_limit.map(|mib| (mib * 1024.0 * 1024.0) as u64),
        shard,
    };
    let bars = Bars::new(args.quiet);
    // The conventional status of a process ended by a signal: 130 for SIGINT, 143 for SIGTERM.
    let signal_status = || ExitCode::from(128 + received.load(Ordering::Relaxed).min(127) as u8);
    let result = match penumbra::run(loaded, &options, &bars) {
        Ok(result) => result,
        Err(penumbra::RunError::Solve(penumbra_solver::SolveError::Interrupted)) => {
            drop(bars);
            eprintln!(
                "interrupted before a solution existed: nothing written, {} left as it was",
                args.out.display()
            );
            return Ok(signal_status());
        }
        Err(e) => return Err(run_failure(e, BudgetOptions::Run)),
    };
    if !args.quiet {
        let stats = &result.solution.stats;
        let energy = penumbra::energy::EnergyBalance::of(stats).warning();
        for w in energy
            .into_iter()
            .chain(penumbra::outputs::estimated_direct_warning(stats))
        {
            eprintln!("warning: {w}");
        }
    }
    if let Some(shard) = shard {
        let origin = penumbra::shard::SceneOrigin {
            spec: args.scene.clone(),
            no_merge: args.no_merge,
            camera: args.camera.as_ref().and(result.loaded.scene.camera),
        };
        let written = penumbra::shard::write_shard(&result, shard, origin, &args.out, &svgs)?;
        if !args.quiet {
            let on = shard.surfaces(result.mesh.surfaces.len());
            let lit = |count: fn(&penumbra_meshing::SurfaceMesh) -> usize| -> usize {
                result
                    .mesh
                    .surfaces
                    .iter()
                    .zip(&on)
                    .filter(|(_, on)| **on)
                    .map(|(m, _)| count(m))
                    .sum()
            };
            println!(
                "{}: shard {shard}: {} of {} surfaces, {} triangles, {} vertices lit; direct light \
                 {:.2} s, {:.2} s in all",
                result.loaded.scene.name,
                on.iter().filter(|&&b| b).count(),
                on.len(),
                lit(penumbra_meshing::SurfaceMesh::triangle_count),
                lit(penumbra_meshing::SurfaceMesh::vertex_count),
                result.times.direct,
                result.times.total
            );
            println!(
                "wrote {} files to {} (join the shards with `penumbra merge`)",
                written.len(),
                args.out.display()
            );
        }
        if interrupt.is_set() {
            return Ok(signal_status());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let extra = if args.convergence {
        penumbra::outputs::convergence_files(&result)?
    } else {
        Vec::new()
    };
    let written = write_outputs(&result, &args.out, &svgs, extra)?;
    if !args.quiet {
        let stats = &result.solution.stats;
        println!(
            "{}: {} mesh, {} discontinuity segments, {} triangles, {} vertices, {} patches; {} iterations ({:?}), \
             residual {:.2e}; {:.2} s",
            result.loaded.scene.name,
            if result.mesh.discontinuity_stats.is_some() {
                "discontinuity"
            } else {
                "uniform"
            },
            result.mesh.segment_count(),
            result.mesh.triangle_count(),
            result.mesh.vertex_count(),
            stats.patches,
            stats.iterations,
            stats.stop,
            stats.residual,
            result.times.total
        );
        println!("wrote {} files to {}", written.len(), args.out.display());
    }
    if interrupt.is_set() {
        eprintln!(
            "interrupted: wrote the solution so far to {}, marked partial in report.json",
            args.out.display()
        );
        return Ok(signal_status());
    }
    Ok(ExitCode::SUCCESS)
}
