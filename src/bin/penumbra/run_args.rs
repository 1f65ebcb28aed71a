//! `penumbra run`'s options, and the run options they make. The options are recorded in
//! `report.json` as they were resolved, so that `--replay` can run them again.

use std::path::PathBuf;

use clap::ValueEnum;
use penumbra::{MeshMethod, RunOptions};
use penumbra_meshing::ElementBudget;
use penumbra_meshing::discontinuity::{DiscontinuityOptions, EventSet};
use penumbra_solver::DEFAULT_EPSILON;
use penumbra_solver::{Interrupt, SolverOptions};
use serde::{Deserialize, Serialize};

const INPUT: &str = "Input";
const MESH: &str = "Mesh";
const REFINE: &str = "Adaptive refinement";
const SOLVER: &str = "Solver";
const OUTPUT: &str = "Output and render";
const LIMITS: &str = "Limits";

/// What `--export` writes unless told otherwise: the viewer page.
const DEFAULT_EXPORT: &str = "html";

fn default_export() -> String {
    DEFAULT_EXPORT.to_owned()
}

// Reports written before --min-angle replay with its default.
fn default_min_angle() -> f64 {
    penumbra::DEFAULT_MIN_ANGLE_DEG
}

// Reports written before error-driven meshes replay with their default tolerance.
fn default_tol() -> f64 {
    penumbra::error_mesh::DEFAULT_TOLERANCE
}

// Reports written before photon mapping replay with its defaults.
fn default_photons() -> usize {
    penumbra_solver::photon_map::DEFAULT_PHOTONS
}

fn default_gather_photons() -> usize {
    penumbra_solver::photon_map::DEFAULT_GATHER_PHOTONS
}

fn default_final_gather() -> usize {
    penumbra_solver::photon_map::DEFAULT_FINAL_GATHER
}

/// `penumbra run --help`'s examples.
pub(crate) const EXAMPLES: &str = "\
Examples:
  penumbra run cornell                          the Cornell box, default settings, into out/
  penumbra run myscene.json --out myscene       a scene of your own (penumbra scenes --dump cornell)
  penumbra run room.obj --eye 0,1.6,4 --target 0,1,0 --up 0,1,0
                                                an OBJ file, rendered from where you stand
  penumbra run cornell --direct-only --mesh uniform --max-elements 2000
                                                the exact direct light on a uniform mesh
  penumbra run cornell --refine-tol 0.002 --max-elements 40000
                                                adaptive refinement up to 40,000 triangles
  penumbra run cornell --solver progressive --time-budget 5
                                                anytime: the best solution after 5 s
  penumbra run --replay out/report.json --out again
                                                the same run again, from its recorded options";

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum MeshArg {
    /// Constrained Delaunay triangulation of each polygon, refined to a uniform size.
    Uniform,
    /// The same, with the umbra and penumbra boundaries of the direct light as mesh edges.
    Discontinuity,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum EventsArg {
    /// Every EV and VE event: each light edge with each blocker vertex on the blocker's outline,
    /// each light vertex with each blocker edge on it, each blocker vertex with an edge of
    /// another blocker in a plane through the light.
    Complete,
    /// Only the umbra and outer penumbra boundaries (and contact lines, and EEE events).
    Extremal,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum FormFactorArg {
    Analytic,
    MonteCarlo,
    Hemicube,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum SolverArg {
    Progressive,
    Jacobi,
    GaussSeidel,
    Direct,
    Hierarchical,
    PhotonMap,
}

impl From<SolverArg> for penumbra_solver::SolverMethod {
    fn from(a: SolverArg) -> Self {
        match a {
            SolverArg::Progressive => Self::Progressive,
            SolverArg::Jacobi => Self::Jacobi,
            SolverArg::GaussSeidel => Self::GaussSeidel,
            SolverArg::Direct => Self::Direct,
            SolverArg::Hierarchical => Self::Hierarchical,
            SolverArg::PhotonMap => Self::PhotonMap,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum IndirectArg {
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

#[derive(clap::Args, Debug, Serialize, Deserialize)]
#[command(after_help = EXAMPLES)]
pub(crate) struct RunArgs {
    /// A .json, .obj, .gltf or .glb file, or the name of a built-in scene (see `penumbra scenes`).
    #[arg(required_unless_present = "replay")]
    pub(crate) scene: Option<String>,
    /// Run again the run that wrote this report.json, with the options, scene and seed it
    /// records; only --out and --quiet may be given with it.
    #[arg(long, help_heading = INPUT, value_name = "REPORT")]
    #[serde(skip)]
    pub(crate) replay: Option<PathBuf>,
    /// OBJ and glTF files: keep every face as its own surface (by default coplanar adjacent faces
    /// of one material are merged where the union is a simple polygon).
    #[arg(help_heading = INPUT, long)]
    pub(crate) no_merge: bool,
    /// The unit of the scene's coordinates, which solution.glb turns into metres: um, mm, cm,
    /// m, km, in or ft (default: the scene's "unit", else metres; glTF files are in metres).
    #[arg(help_heading = INPUT, long, value_name = "UNIT")]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) unit: Option<String>,
    /// How surfaces are meshed (default: error-driven, along the umbra and penumbra boundaries
    /// and contact lines, refined where the interpolation of the exact direct light is
    /// measured worst, up to --max-elements or --tol; with --refine-tol, discontinuity where
    /// the scene casts shadows, else uniform).
    #[arg(help_heading = MESH, long, value_enum)]
    pub(crate) mesh: Option<MeshArg>,
    /// Error-driven meshes (the default): split triangles until each surface's RMS error of the
    /// direct light, estimated from the exact light at its triangles' edge midpoints, is within
    /// this fraction of its mean reflected direct light, or --max-elements is reached; full
    /// solutions with the hierarchical solver then split again until the light reflected more
    /// than once (its error estimated from its gradient's jumps) is within it of each surface's
    /// mean reflected light.
    #[arg(help_heading = MESH, long, default_value_t = penumbra::error_mesh::DEFAULT_TOLERANCE)]
    #[serde(default = "default_tol")]
    pub(crate) tol: f64,
    /// Discontinuity and error-driven meshes: the smallest angle, in degrees, that quality
    /// refinement aims for where the discontinuities do not force a smaller one (0: no quality
    /// refinement; at most 30).
    #[arg(help_heading = MESH, long, value_name = "DEG", default_value_t = penumbra::DEFAULT_MIN_ANGLE_DEG)]
    #[serde(default = "default_min_angle")]
    pub(crate) min_angle: f64,
    /// Cap on triangles for the whole scene, spread over the surfaces by area. Default: what the
    /// scene needs: 25,000 with the hierarchical solver (its cost grows about linearly with the
    /// vertices), 10,000 with the others or --direct-only, or, when that is too few, the least
    /// mesh of its polygons with their discontinuities as edges and 1 triangle more per surface;
    /// with --direct-only, error-driven refinement that spends it goes on splitting at the
    /// points it measured, with no new evaluations, up to twice as many.
    #[arg(help_heading = MESH, long)]
    pub(crate) max_elements: Option<usize>,
    /// Discontinuity meshes: how many times smaller in area triangles are in partial shadow than
    /// in full light or full shadow (1: no grading). Default: 8, or 1 with --refine-tol, where
    /// refinement finds the penumbrae itself.
    #[arg(help_heading = MESH, long)]
    pub(crate) penumbra_density: Option<f64>,
    /// Discontinuity meshes: leave out EEE events (emitter edge with two blocker edges).
    #[arg(help_heading = MESH, long)]
    pub(crate) no_eee: bool,
    /// Discontinuity meshes: which EV and VE events become mesh edges.
    #[arg(help_heading = MESH, long, value_enum, default_value_t = EventsArg::Complete)]
    pub(crate) events: EventsArg,
    /// Discontinuity meshes: blockers (flat patches of faces) that can hide less than this
    /// fraction of a light from a receiver start no events there; adaptive refinement and the
    /// penumbra grading mesh their shadows instead.
    #[arg(help_heading = MESH, long, default_value_t = penumbra_meshing::discontinuity::DEFAULT_EVENT_TOLERANCE)]
    pub(crate) event_tol: f64,
    /// Adaptive refinement: start from a coarser mesh and split, round after round, the triangles
    /// whose interpolation misses the exact direct light by more than this fraction of the
    /// mean reflected radiosity (B - E over the surfaces that reflect: a bright lamp does not
    /// loosen it on the floor it lights), up to --max-elements.
    #[arg(help_heading = REFINE, long)]
    pub(crate) refine_tol: Option<f64>,
    /// With --refine-tol: triangles of the starting mesh (default: a tenth of --max-elements;
    /// without --max-elements, a tenth of 10,000, or the scene's least mesh if that is more).
    #[arg(help_heading = REFINE, long)]
    pub(crate) initial_elements: Option<usize>,
    /// With --refine-tol, in full solutions: how the indirect light's interpolation error is
    /// estimated: from its gradient's jumps across edges (free), or gathered at each triangle's
    /// centroid from the patches shot so far (a form factor per shooter and triangle).
    #[arg(help_heading = REFINE, long, value_enum, default_value_t = IndirectArg::Gradient)]
    pub(crate) refine_indirect: IndirectArg,
    /// With --refine-tol: rounds of refinement at most.
    #[arg(help_heading = REFINE, long, default_value_t = penumbra::adaptive::DEFAULT_MAX_ROUNDS)]
    pub(crate) refine_rounds: usize,
    /// How the radiosity system is solved: hierarchical radiosity with clustering (links refined
    /// to --link-tol, then a final gather at every vertex), progressive refinement (shooting: an
    /// image at any moment), Jacobi or Gauss–Seidel gathering over the patch form-factor matrix,
    /// or its dense direct solve (the discrete system's exact answer), or photon mapping (the
    /// light reflected more than once from --photons photons, the direct light exact).
    /// Hierarchical, gathering and direct solves stop at a relative residual of --epsilon, or
    /// after --max-shots sweeps; progressive refinement when the unshot power is below
    /// --epsilon.
    #[arg(help_heading = SOLVER, long, value_enum, default_value_t = SolverArg::Hierarchical)]
    pub(crate) solver: SolverArg,
    /// With --solver hierarchical: the light a link may carry wrongly, as a fraction of the
    /// light the surfaces reflect of the direct light; smaller is finer and slower.
    #[arg(help_heading = SOLVER, long, default_value_t = penumbra_solver::hierarchical::DEFAULT_LINK_TOL)]
    pub(crate) link_tol: f64,
    /// With --solver photon-map: photons emitted, shared among the lights by power.
    #[arg(help_heading = SOLVER, long, default_value_t = penumbra_solver::photon_map::DEFAULT_PHOTONS)]
    #[serde(default = "default_photons")]
    pub(crate) photons: usize,
    /// With --solver photon-map: photons each estimate of the indirect light gathers.
    #[arg(help_heading = SOLVER, long, default_value_t = penumbra_solver::photon_map::DEFAULT_GATHER_PHOTONS)]
    #[serde(default = "default_gather_photons")]
    pub(crate) gather_photons: usize,
    /// With --solver photon-map: rays per vertex of the final gather, which reads the photon
    /// map where they land instead of at the vertex (0: none).
    #[arg(help_heading = SOLVER, long, value_name = "RAYS", default_value_t = penumbra_solver::photon_map::DEFAULT_FINAL_GATHER)]
    #[serde(default = "default_final_gather")]
    pub(crate) final_gather: usize,
    /// How vertex-to-patch form factors are computed: Lambert's formula times a ray-sampled
    /// visibility fraction, Monte Carlo over each patch (--ff-samples points, each with a ray),
    /// or a hemicube z-buffer at each vertex (--hemicube-resolution; not with --refine-tol).
    #[arg(help_heading = SOLVER, long, value_enum, default_value_t = FormFactorArg::Analytic)]
    pub(crate) form_factors: FormFactorArg,
    /// With --form-factors monte-carlo: samples per vertex and patch.
    #[arg(help_heading = SOLVER, long, default_value_t = penumbra::DEFAULT_FF_SAMPLES)]
    pub(crate) ff_samples: usize,
    /// With --form-factors hemicube: pixels across the hemicube's top face (even; the side
    /// faces are half as tall).
    #[arg(help_heading = SOLVER, long, default_value_t = penumbra::DEFAULT_HEMICUBE_RESOLUTION)]
    pub(crate) hemicube_resolution: usize,
    /// The solver's stopping tolerance: progressive refinement stops when the unshot power is
    /// below this fraction of the emitted power; the other solvers when their relative residual
    /// (hierarchical: the relative change of a sweep) is below it.
    #[arg(help_heading = SOLVER, long, default_value_t = DEFAULT_EPSILON)]
    pub(crate) epsilon: f64,
    /// Stop after this many patch shots, converged or not.
    #[arg(help_heading = SOLVER, long, default_value_t = SolverOptions::default().max_shots)]
    pub(crate) max_shots: usize,
    /// One exact bounce of direct light only: B = E + rho * H_direct.
    #[arg(help_heading = SOLVER, long)]
    pub(crate) direct_only: bool,
    /// Visibility rays per vertex-patch pair (1 to 4096).
    #[arg(help_heading = SOLVER, long, default_value_t = SolverOptions::default().visibility_rays)]
    pub(crate) rays: usize,
    /// Mesh elements grouped into one shooting patch.
    #[arg(help_heading = SOLVER, long, default_value_t = SolverOptions::default().elements_per_patch)]
    pub(crate) elements_per_patch: usize,
    /// Seed of the visibility sampling.
    #[arg(help_heading = SOLVER, long, default_value_t = SolverOptions::default().seed)]
    pub(crate) seed: u64,
    /// Output directory.
    #[arg(help_heading = OUTPUT, long, default_value = "out")]
    pub(crate) out: PathBuf,
    /// Also write the solver's residual against iterations and against time: convergence.csv,
    /// convergence-iterations.svg/.png and convergence-time.svg/.png.
    #[arg(help_heading = OUTPUT, long)]
    pub(crate) convergence: bool,
    /// Render width in pixels.
    #[arg(help_heading = OUTPUT, long, default_value_t = 640)]
    pub(crate) width: u32,
    /// Render height in pixels.
    #[arg(help_heading = OUTPUT, long, default_value_t = 640)]
    pub(crate) height: u32,
    /// Where the render looks from and at, as EX,EY,EZ:TX,TY,TZ, with the vertical field of view
    /// in degrees after a third colon (default 45); upright as the default view. It replaces
    /// the scene's own camera, and the default one that frames the whole scene.
    #[arg(help_heading = OUTPUT, long, value_name = "EYE:TARGET[:FOV]", allow_hyphen_values = true)]
    pub(crate) camera: Option<String>,
    /// Where the render looks from, X,Y,Z (default: the scene's camera, or a view that frames
    /// the whole scene). --eye, --target, --up and --fov each replace one part of that camera.
    #[arg(long, help_heading = OUTPUT, value_name = "X,Y,Z", allow_hyphen_values = true, conflicts_with = "camera")]
    pub(crate) eye: Option<String>,
    /// The point the render looks at, X,Y,Z.
    #[arg(long, help_heading = OUTPUT, value_name = "X,Y,Z", allow_hyphen_values = true, conflicts_with = "camera")]
    pub(crate) target: Option<String>,
    /// The direction that is up in the render, X,Y,Z: 0,1,0 for OBJ files from y-up tools
    /// (Blender's exports, most scanned models).
    #[arg(long, help_heading = OUTPUT, value_name = "X,Y,Z", allow_hyphen_values = true, conflicts_with = "camera")]
    pub(crate) up: Option<String>,
    /// The render's vertical field of view in degrees.
    #[arg(long, help_heading = OUTPUT, value_name = "DEG", conflicts_with = "camera")]
    pub(crate) fov: Option<f64>,
    /// Which surfaces get an SVG in OUT/surfaces: `auto` (every surface of a scene of at most 24,
    /// else the 24 with the most discontinuity segments, then the largest), `all`, `none`, or
    /// surface names, comma-separated.
    #[arg(help_heading = OUTPUT, long, default_value = "auto", value_name = "auto|all|none|NAME,...")]
    pub(crate) svg: String,
    /// Also write the solution for other tools, comma-separated: `vtp` (solution.vtp, for
    /// ParaView), `ply` (MeshLab, Blender), `glb` (glTF: browsers, Blender), `obj` (with
    /// solution.mtl), `html` (index.html, a page to turn the solution around in a browser);
    /// `all`, or `none`.
    #[arg(help_heading = OUTPUT, long, default_value = DEFAULT_EXPORT, value_name = "FORMAT,...")]
    #[serde(default = "default_export")]
    pub(crate) export: String,
    /// No progress bars, no summary and no warnings.
    #[arg(help_heading = OUTPUT, long)]
    pub(crate) quiet: bool,
    /// Stop after this many seconds (from the start of the run) and write the best solution so
    /// far; report.json says so. The discontinuity search skips the pairs left, the direct light
    /// estimates the vertices left by rays, and refinement and shooting stop.
    #[arg(help_heading = LIMITS, long)]
    pub(crate) time_budget: Option<f64>,
    /// Worker threads (default: one per core).
    #[arg(help_heading = LIMITS, long)]
    pub(crate) threads: Option<usize>,
    /// Memory the run may use, in MiB (default: what the machine has available). A run that
    /// would need more stops before it starts, with the largest --max-elements that fits.
    #[arg(help_heading = LIMITS, long)]
    pub(crate) memory_limit: Option<f64>,
    /// With --direct-only: light only shard I of N (I from 0 to N - 1), the I-th of N runs of
    /// consecutive surfaces of about equal estimated cost (the triangles each surface is
    /// expected to have to light), and write OUT/shard.json and their SVGs for `penumbra merge`. In a
    /// scene whose polygons need more than the budget's floor, with the fitted budget, the shard
    /// also finds the discontinuities of its own surfaces and meshes them alone (an error-driven
    /// mesh spends their share of the budget on them); otherwise it meshes the whole scene
    /// (each surface's share of the budget depends on all of them).
    #[arg(help_heading = LIMITS, long, value_name = "I/N")]
    pub(crate) shard: Option<String>,
}

impl RunArgs {
    /// The run options these arguments ask for; the library checks their ranges
    /// ([`RunOptions::validate`]).
    pub(crate) fn options(&self, interrupt: &Interrupt) -> RunOptions {
        let method = self.solver.into();
        RunOptions {
            method,
            mesh: match self.mesh {
                None => MeshMethod::Auto,
                Some(MeshArg::Uniform) => MeshMethod::Uniform,
                Some(MeshArg::Discontinuity) => MeshMethod::Discontinuity,
            },
            max_elements: self.max_elements.map_or(
                penumbra::default_budget(method, self.direct_only),
                ElementBudget::AtMost,
            ),
            penumbra_density: self
                .penumbra_density
                .unwrap_or(penumbra::default_penumbra_density(
                    self.refine_tol.is_some(),
                )),
            time_budget: self.time_budget,
            tolerance: self.tol,
            min_angle: self.min_angle,
            refine: self
                .refine_tol
                .map(|tolerance| penumbra::adaptive::RefineOptions {
                    tolerance,
                    initial_elements: self
                        .initial_elements
                        .unwrap_or(penumbra::default_initial_elements(self.max_elements)),
                    max_rounds: self.refine_rounds,
                    indirect: self.refine_indirect.into(),
                }),
            discontinuity: DiscontinuityOptions {
                eee: !self.no_eee,
                events: match self.events {
                    EventsArg::Complete => EventSet::Complete,
                    EventsArg::Extremal => EventSet::Extremal,
                },
                event_tolerance: self.event_tol,
                ..Default::default()
            },
            solver: self.solver_options(interrupt),
            render: penumbra_viz::RenderOptions {
                width: self.width,
                height: self.height,
                ..Default::default()
            },
            // Whole bytes; a negative or NaN limit is refused before this (`memory_limit`).
            memory_limit: self.memory_limit.map(|mib| (mib * 1024.0 * 1024.0) as u64),
            shard: None,
        }
    }

    fn solver_options(&self, interrupt: &Interrupt) -> SolverOptions {
        use penumbra_solver::coupling::FormFactorMethod;
        SolverOptions {
            epsilon: self.epsilon,
            max_shots: self.max_shots,
            visibility_rays: self.rays,
            link_tol: self.link_tol,
            photon_map: penumbra_solver::photon_map::PhotonMapOptions {
                photons: self.photons,
                gather_photons: self.gather_photons,
                final_gather: self.final_gather,
            },
            form_factors: match self.form_factors {
                FormFactorArg::Analytic => FormFactorMethod::Analytic,
                FormFactorArg::MonteCarlo => FormFactorMethod::MonteCarlo {
                    samples: self.ff_samples,
                },
                FormFactorArg::Hemicube => FormFactorMethod::Hemicube {
                    resolution: self.hemicube_resolution,
                },
            },
            elements_per_patch: self.elements_per_patch,
            direct_only: self.direct_only,
            seed: self.seed,
            interrupt: Some(interrupt.clone()),
            ..SolverOptions::default()
        }
    }
}
