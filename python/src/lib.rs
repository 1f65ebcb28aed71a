//! The native half of the `penumbra` Python package (`penumbra._native`). The public API, its
//! argument checks and its documentation live in `python/penumbra/`; this module turns checked
//! arguments into the library's calls, releases the GIL while they run, and hands the results
//! back as numpy arrays. Errors become the package's exceptions here, told in the Python
//! arguments' names.

// pyo3 hands `#[pyfunction]` arguments over by value, whether or not they are consumed.
#![allow(clippy::needless_pass_by_value)]

mod arrays;
mod errors;
mod primitives;
mod progress;
mod run;
mod scene;
mod solution;
mod worker;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SceneError", py.get_type::<errors::SceneError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<run::Interrupt>()?;
    m.add_class::<solution::RunOutput>()?;
    m.add_function(wrap_pyfunction!(scene::builtin_scenes, m)?)?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(primitives::direct_light, m)?)?;
    m.add_function(wrap_pyfunction!(primitives::discontinuities, m)?)?;
    m.add_function(wrap_pyfunction!(primitives::reference, m)?)?;
    m.add_function(wrap_pyfunction!(primitives::locate, m)?)?;
    Ok(())
}
