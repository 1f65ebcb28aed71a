//! The library's errors as Python exceptions, told in the Python arguments' names.

use penumbra::{InvalidOption, RunError};
use penumbra_meshing::MeshError;
use pyo3::exceptions::{
    PyFileNotFoundError, PyMemoryError, PyOSError, PyRuntimeError, PyValueError,
};
use pyo3::prelude::*;

pyo3::create_exception!(
    penumbra,
    SceneError,
    PyValueError,
    "A scene that cannot be read or is not valid. `problems` lists every problem validation \
     found (as `penumbra check` reports them), `warnings` what loading repaired first."
);

/// A scene that could not be loaded: a missing file is `FileNotFoundError`, an unreadable one
/// `OSError`, anything else a `SceneError` carrying every problem.
pub(crate) fn scene_error(py: Python<'_>, e: penumbra_scenes::SceneError) -> PyErr {
    use penumbra_scenes::SceneError as E;
    let message = e.to_string();
    match e {
        E::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(message)
        }
        E::Io { .. } => PyOSError::new_err(message),
        E::Invalid {
            problems, warnings, ..
        } => {
            let problems: Vec<String> = problems.iter().map(ToString::to_string).collect();
            with_details(py, message, problems, warnings)
        }
        _ => with_details(py, message, Vec::new(), Vec::new()),
    }
}

fn with_details(
    py: Python<'_>,
    message: String,
    problems: Vec<String>,
    warnings: Vec<String>,
) -> PyErr {
    let error = SceneError::new_err(message);
    let value = error.value(py);
    match value
        .setattr("problems", problems)
        .and_then(|()| value.setattr("warnings", warnings))
    {
        Ok(()) => error,
        Err(e) => e,
    }
}

/// An option the library refused, as a `ValueError` naming the argument.
pub(crate) fn invalid_option(e: &InvalidOption) -> PyErr {
    PyValueError::new_err(format!(
        "invalid {} ({}): {}",
        e.option.argument(),
        e.option,
        e.reason
    ))
}

/// A failed run: bad options and budgets are `ValueError`s naming the argument, a run that
/// would not fit in memory a `MemoryError` saying what would, anything else a `RuntimeError`.
pub(crate) fn run_error(e: RunError) -> PyErr {
    match e {
        RunError::InvalidOption(e) => invalid_option(&e),
        RunError::Solve(e @ penumbra_solver::SolveError::InvalidOption { .. }) => {
            invalid_option(&InvalidOption::from(e))
        }
        RunError::Mesh(e @ MeshError::BudgetTooSmall { .. }) => {
            PyValueError::new_err(format!("max_elements: {e}"))
        }
        RunError::InitialBudget(e @ MeshError::BudgetTooSmall { .. }) => {
            PyValueError::new_err(format!("initial_elements: {e}"))
        }
        e @ RunError::Memory { .. } => PyMemoryError::new_err(format!(
            "{e} (max_elements, link_tol and memory_limit set these)"
        )),
        e if e.is_usage() => PyValueError::new_err(e.to_string()),
        e => PyRuntimeError::new_err(e.to_string()),
    }
}

/// A value outside what an argument takes.
pub(crate) fn bad_argument(name: &str, reason: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{name}: {reason}"))
}
