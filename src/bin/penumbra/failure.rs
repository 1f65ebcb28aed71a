//! Failures, the exit code each gets, and their messages in terms of the flags that set them:
//! the library's errors describe the data; only here do they learn the command line's spelling.

use penumbra::{InvalidOption, OptionId, RunError};
use penumbra_meshing::MeshError;

/// A failure, and whether it was the user's input (exit 2) or the run (exit 1).
pub(crate) struct Failure {
    pub(crate) error: anyhow::Error,
    pub(crate) usage: bool,
}

impl<E: Into<anyhow::Error>> From<E> for Failure {
    fn from(e: E) -> Self {
        Failure {
            error: e.into(),
            usage: false,
        }
    }
}

/// The user's input was wrong: exit 2.
pub(crate) fn usage(error: impl Into<anyhow::Error>) -> Failure {
    Failure {
        error: error.into(),
        usage: true,
    }
}

/// A failure's message: the error and its causes, each cause once (an error that already
/// quotes its cause is not followed by it again).
pub(crate) fn message(error: &anyhow::Error) -> String {
    let mut text = error.to_string();
    for cause in error.chain().skip(1) {
        let cause = cause.to_string();
        if !text.contains(&cause) {
            text.push_str(": ");
            text.push_str(&cause);
        }
    }
    text
}

/// Which command's options a failure is told in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Command {
    /// `run`: `--max-elements`, `--initial-elements`, ...
    Run,
    /// `sweep`: `--budgets`, `--initial-fraction`, ...
    Sweep,
    /// `form-factors`: `--samples`, `--resolutions`, ...
    FormFactors,
}

/// The flag that sets `option` in `command`: `run`'s ([`OptionId::flag`]), but for the options
/// `sweep` and `form-factors` spell their own way (none for the solver a study chooses itself).
fn flag(option: OptionId, command: Command) -> Option<&'static str> {
    use OptionId as O;
    Some(match (option, command) {
        (O::MaxElements, Command::Sweep) => "--budgets",
        (O::InitialElements, Command::Sweep) => "--initial-fraction",
        (O::Solver, Command::Sweep) => "--solvers",
        (O::FormFactorSamples, Command::FormFactors) => "--samples",
        (O::HemicubeResolution, Command::FormFactors) => "--resolutions",
        (O::Solver, Command::FormFactors) => return None,
        (option, _) => option.flag(),
    })
}

/// An option the library refused, told by the flag that set it.
pub(crate) fn invalid_option(e: &InvalidOption, command: Command) -> Failure {
    usage(match flag(e.option, command) {
        Some(flag) => anyhow::anyhow!("invalid {flag} ({}): {}", e.option, e.reason),
        None => anyhow::anyhow!("{e}"),
    })
}

/// A pipeline error: the user's (exit 2) when it comes from bad options, else the run's.
pub(crate) fn run_failure(e: RunError, command: Command) -> Failure {
    if let Some(message) = budget_message(&e, command) {
        return usage(anyhow::anyhow!(message));
    }
    match e {
        RunError::InvalidOption(e) => invalid_option(&e, command),
        RunError::Solve(e @ penumbra_solver::SolveError::InvalidOption { .. }) => {
            invalid_option(&InvalidOption::from(e), command)
        }
        RunError::Memory {
            needed,
            limit,
            suggestion,
            link_tol,
        } => usage(anyhow::anyhow!(memory_message(
            needed, limit, suggestion, link_tol
        ))),
        e if e.is_usage() => usage(e),
        e => Failure::from(e),
    }
}

/// A run too large for memory, with the flags that would make it fit.
fn memory_message(
    needed: u64,
    limit: u64,
    suggestion: Option<usize>,
    link_tol: Option<f64>,
) -> String {
    use penumbra::memory::human;
    let head = format!(
        "this run would need about {} of memory, and {} is available",
        human(needed),
        human(limit)
    );
    let links = link_tol.map_or(String::new(), |t| {
        format!(", or --link-tol {t:.1e} or more")
    });
    match (suggestion, link_tol) {
        (Some(n), _) => format!(
            "{head}; use --max-elements {n} or fewer{links} (or --memory-limit, if more is free)"
        ),
        (None, Some(t)) => {
            format!("{head}; use --link-tol {t:.1e} or more (or --memory-limit, if more is free)")
        }
        (None, None) => format!(
            "{head}; even the coarsest mesh of this scene does not fit (options: --direct-only, \
             --solver progressive, smaller --width/--height, or a machine with more memory)"
        ),
    }
}

/// An element budget too small for the scene, told in terms of the option that set it.
fn budget_message(e: &RunError, command: Command) -> Option<String> {
    let (initial, source) = match e {
        RunError::Mesh(source) => (false, source),
        RunError::InitialBudget(source) => (true, source),
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
    Some(match (command, initial) {
        (Command::Run, false) => format!(
            "--max-elements {max_elements} is too small: {need}; use --max-elements {needed} or \
             more (or leave it out: by default the budget fits the scene)"
        ),
        (Command::Run, true) => format!(
            "--initial-elements {max_elements} is too small for the starting mesh of adaptive \
             refinement (by default a tenth of --max-elements): {need}; use --initial-elements \
             {needed} or more"
        ),
        (Command::Sweep, false) => format!(
            "--budgets: {max_elements} is too small: {need}; use budgets of {needed} or more"
        ),
        (Command::Sweep, true) => format!(
            "--initial-fraction: the starting mesh of adaptive refinement, {max_elements} \
             triangles, is too small: {need}; use a larger --initial-fraction, or larger budgets"
        ),
        // The study meshes built-in scenes of its own choosing.
        (Command::FormFactors, _) => return None,
    })
}
