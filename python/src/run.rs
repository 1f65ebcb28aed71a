//! `penumbra.run`: the command line's run, its options and defaults, with the GIL released
//! while it computes and Ctrl-C or an [`Interrupt`] stopping it with the best solution so far.

use std::sync::Arc;

use penumbra::adaptive::{DEFAULT_MAX_ROUNDS, RefineOptions};
use penumbra::{MeshMethod, RunOptions};
use penumbra_meshing::ElementBudget;
use penumbra_meshing::discontinuity::{DEFAULT_EVENT_TOLERANCE, DiscontinuityOptions, EventSet};
use penumbra_solver::coupling::FormFactorMethod;
use penumbra_solver::estimate::IndirectEstimate;
use penumbra_solver::hierarchical::DEFAULT_LINK_TOL;
use penumbra_solver::{NoProgress, SolveError, SolverMethod, SolverOptions};
use penumbra_viz::RenderOptions;
use pyo3::prelude::*;

use crate::errors::{bad_argument, invalid_option, run_error};
use crate::progress::Callback;
use crate::scene::Scene;
use crate::solution::RunOutput;
use crate::worker::{thread_pool, without_gil};

/// Asks a run to stop, from any thread: the run then returns the best solution so far, marked
/// partial.
#[pyclass(module = "penumbra._native", frozen)]
#[derive(Clone, Default)]
pub(crate) struct Interrupt(penumbra_solver::Interrupt);

#[pymethods]
impl Interrupt {
    #[new]
    fn new() -> Interrupt {
        Interrupt::default()
    }

    /// Asks the runs given this interrupt to stop.
    fn set(&self) {
        self.0.set();
    }

    /// Lets runs given this interrupt go on again (a set interrupt stops the next run at once).
    fn clear(&self) {
        self.0.clear();
    }

    /// Whether `set` was called.
    #[getter]
    fn is_set(&self) -> bool {
        self.0.is_set()
    }
}

/// `penumbra.run`'s keyword arguments, checked for type on the Python side; `None` is the
/// command line's default.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct RunArguments {
    mesh: Option<String>,
    max_elements: Option<usize>,
    tol: Option<f64>,
    min_angle: Option<f64>,
    penumbra_density: Option<f64>,
    eee: bool,
    events: Option<String>,
    event_tol: Option<f64>,
    refine_tol: Option<f64>,
    initial_elements: Option<usize>,
    refine_indirect: Option<String>,
    refine_rounds: Option<usize>,
    solver: Option<String>,
    link_tol: Option<f64>,
    photons: Option<usize>,
    gather_photons: Option<usize>,
    final_gather: Option<usize>,
    form_factors: Option<String>,
    ff_samples: Option<usize>,
    hemicube_resolution: Option<usize>,
    epsilon: Option<f64>,
    max_shots: Option<usize>,
    direct_only: bool,
    rays: Option<usize>,
    elements_per_patch: Option<usize>,
    seed: Option<u64>,
    time_budget: Option<f64>,
    memory_limit: Option<f64>,
    width: Option<u32>,
    height: Option<u32>,
}

/// One of an argument's names, or a `ValueError` listing them.
fn choice<T: Copy>(
    name: &str,
    value: Option<&str>,
    default: T,
    choices: &[(&str, T)],
) -> PyResult<T> {
    let Some(value) = value else {
        return Ok(default);
    };
    match choices.iter().find(|(n, _)| *n == value) {
        Some(&(_, t)) => Ok(t),
        None => {
            let names: Vec<String> = choices.iter().map(|(n, _)| format!("{n:?}")).collect();
            Err(bad_argument(
                name,
                format!("must be one of {}, not {value:?}", names.join(", ")),
            ))
        }
    }
}

impl RunArguments {
    /// The run options these arguments ask for, as `penumbra run` resolves its flags.
    fn options(&self, interrupt: &penumbra_solver::Interrupt) -> PyResult<RunOptions> {
        let method = choice(
            "solver",
            self.solver.as_deref(),
            SolverMethod::Hierarchical,
            &[
                ("hierarchical", SolverMethod::Hierarchical),
                ("progressive", SolverMethod::Progressive),
                ("jacobi", SolverMethod::Jacobi),
                ("gauss-seidel", SolverMethod::GaussSeidel),
                ("direct", SolverMethod::Direct),
                ("photon-map", SolverMethod::PhotonMap),
            ],
        )?;
        let mesh = choice(
            "mesh",
            self.mesh.as_deref(),
            MeshMethod::Auto,
            &[
                ("auto", MeshMethod::Auto),
                ("uniform", MeshMethod::Uniform),
                ("discontinuity", MeshMethod::Discontinuity),
            ],
        )?;
        let events = choice(
            "events",
            self.events.as_deref(),
            EventSet::Complete,
            &[
                ("complete", EventSet::Complete),
                ("extremal", EventSet::Extremal),
            ],
        )?;
        let indirect = choice(
            "refine_indirect",
            self.refine_indirect.as_deref(),
            IndirectEstimate::GradientJumps,
            &[
                ("gradient", IndirectEstimate::GradientJumps),
                ("gathered", IndirectEstimate::Gathered),
            ],
        )?;
        let refine = self.refine_tol.map(|tolerance| RefineOptions {
            tolerance,
            initial_elements: self
                .initial_elements
                .unwrap_or(penumbra::default_initial_elements(self.max_elements)),
            max_rounds: self.refine_rounds.unwrap_or(DEFAULT_MAX_ROUNDS),
            indirect,
        });
        let render = RenderOptions::default();
        Ok(RunOptions {
            mesh,
            max_elements: self.max_elements.map_or(
                penumbra::default_budget(method, self.direct_only),
                ElementBudget::AtMost,
            ),
            penumbra_density: self
                .penumbra_density
                .unwrap_or(penumbra::default_penumbra_density(refine.is_some())),
            discontinuity: DiscontinuityOptions {
                eee: self.eee,
                events,
                event_tolerance: self.event_tol.unwrap_or(DEFAULT_EVENT_TOLERANCE),
                ..DiscontinuityOptions::default()
            },
            refine,
            tolerance: self.tol.unwrap_or(penumbra::error_mesh::DEFAULT_TOLERANCE),
            min_angle: self.min_angle.unwrap_or(penumbra::DEFAULT_MIN_ANGLE_DEG),
            time_budget: self.time_budget,
            solver: self.solver_options(interrupt)?,
            method,
            render: RenderOptions {
                width: self.width.unwrap_or(render.width),
                height: self.height.unwrap_or(render.height),
                ..render
            },
            memory_limit: match self.memory_limit {
                None => None,
                Some(mib) if mib > 0.0 && mib.is_finite() => Some((mib * 1024.0 * 1024.0) as u64),
                Some(mib) => {
                    return Err(bad_argument(
                        "memory_limit",
                        format!("must be a positive number of MiB, not {mib}"),
                    ));
                }
            },
            shard: None,
        })
    }

    fn solver_options(&self, interrupt: &penumbra_solver::Interrupt) -> PyResult<SolverOptions> {
        let defaults = SolverOptions::default();
        let form_factors = choice(
            "form_factors",
            self.form_factors.as_deref(),
            "analytic",
            &[
                ("analytic", "analytic"),
                ("monte-carlo", "monte-carlo"),
                ("hemicube", "hemicube"),
            ],
        )?;
        Ok(SolverOptions {
            epsilon: self.epsilon.unwrap_or(defaults.epsilon),
            max_shots: self.max_shots.unwrap_or(defaults.max_shots),
            visibility_rays: self.rays.unwrap_or(defaults.visibility_rays),
            link_tol: self.link_tol.unwrap_or(DEFAULT_LINK_TOL),
            photon_map: penumbra_solver::photon_map::PhotonMapOptions {
                photons: self.photons.unwrap_or(defaults.photon_map.photons),
                gather_photons: self
                    .gather_photons
                    .unwrap_or(defaults.photon_map.gather_photons),
                final_gather: self
                    .final_gather
                    .unwrap_or(defaults.photon_map.final_gather),
            },
            form_factors: match form_factors {
                "monte-carlo" => FormFactorMethod::MonteCarlo {
                    samples: self.ff_samples.unwrap_or(penumbra::DEFAULT_FF_SAMPLES),
                },
                "hemicube" => FormFactorMethod::Hemicube {
                    resolution: self
                        .hemicube_resolution
                        .unwrap_or(penumbra::DEFAULT_HEMICUBE_RESOLUTION),
                },
                _ => FormFactorMethod::Analytic,
            },
            elements_per_patch: self
                .elements_per_patch
                .unwrap_or(defaults.elements_per_patch),
            direct_only: self.direct_only,
            seed: self.seed.unwrap_or(defaults.seed),
            interrupt: Some(interrupt.clone()),
            ..defaults
        })
    }
}

/// Runs the pipeline on `scene`. Returns the run's output (`None` when it was stopped before a
/// solution existed) and the exception of the signal that stopped it, if one did (the Python
/// side raises `RunInterrupted` for Ctrl-C, and a signal handler's own exception as it is).
#[pyfunction]
#[pyo3(signature = (scene, arguments, threads = None, interrupt = None, progress = None))]
pub(crate) fn run(
    py: Python<'_>,
    scene: &Scene,
    arguments: RunArguments,
    threads: Option<usize>,
    interrupt: Option<&Interrupt>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Option<RunOutput>, Option<Py<PyAny>>)> {
    let interrupt = interrupt.cloned().unwrap_or_default().0;
    let options = arguments.options(&interrupt)?;
    options.validate().map_err(|e| invalid_option(&e))?;
    let pool = thread_pool(threads)?;
    let loaded = scene.loaded().clone();
    let callback = progress.map(|p| Arc::new(Callback::new(p)));
    let reporter = callback.clone();
    let (outcome, signal) = without_gil(py, pool, &interrupt, move || match &reporter {
        Some(callback) => penumbra::run(loaded, &options, callback.as_ref()),
        None => penumbra::run(loaded, &options, &NoProgress),
    })?;
    if let Some(e) = callback.and_then(|c| c.error()) {
        return Err(e);
    }
    let signal = signal.map(|e| e.into_value(py).into_any());
    match outcome {
        Ok(result) => Ok((Some(RunOutput::new(result, scene.clone())), signal)),
        Err(penumbra::RunError::Solve(SolveError::Interrupted)) => Ok((None, signal)),
        Err(e) => Err(run_error(e)),
    }
}
