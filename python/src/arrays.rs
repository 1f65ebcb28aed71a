//! numpy arrays in and out: rows of three numbers become points and colours, and back.

use glam::DVec3;
use numpy::ndarray::Array2;
use numpy::{Element, IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2};
use penumbra_meshing::discontinuity::DiscontinuitySegment;
use penumbra_scenes::Rgb;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::bad_argument;

/// The rows of an (N, 3) float64 array, each finite.
pub(crate) fn rows3(array: &PyReadonlyArray2<'_, f64>, name: &str) -> PyResult<Vec<[f64; 3]>> {
    let view = array.as_array();
    if view.ncols() != 3 {
        return Err(bad_argument(
            name,
            format!("must have shape (N, 3), not {:?}", view.shape()),
        ));
    }
    view.rows()
        .into_iter()
        .enumerate()
        .map(|(i, row)| {
            let r = [row[0], row[1], row[2]];
            match r.iter().all(|c| c.is_finite()) {
                true => Ok(r),
                false => Err(bad_argument(name, format!("row {i} is not finite: {r:?}"))),
            }
        })
        .collect()
}

/// The rows of an (N, 3) float64 array as points.
pub(crate) fn points(array: &PyReadonlyArray2<'_, f64>, name: &str) -> PyResult<Vec<DVec3>> {
    Ok(rows3(array, name)?.into_iter().map(DVec3::from).collect())
}

/// An (N, 3) array from rows.
pub(crate) fn array3<'py, T: Element + Copy>(
    py: Python<'py>,
    rows: &[[T; 3]],
) -> Bound<'py, PyArray2<T>> {
    let flat: Vec<T> = rows.iter().flatten().copied().collect();
    match Array2::from_shape_vec((rows.len(), 3), flat) {
        Ok(array) => array.into_pyarray(py),
        // The shape is the data's own: this cannot happen.
        Err(_) => PyArray2::zeros(py, [0, 3], false),
    }
}

/// An (N, 3) float64 array of colours.
pub(crate) fn rgb_array<'py>(py: Python<'py>, colours: &[Rgb]) -> Bound<'py, PyArray2<f64>> {
    let rows: Vec<[f64; 3]> = colours.iter().map(|c| c.to_array()).collect();
    array3(py, &rows)
}

/// Discontinuity segments, per surface, as a dict of arrays: `segments` (K, 2, 3) float64,
/// `surface_id` and `emitter` (K,) uint32, `order` (K,) uint8, and `event` and `boundary` as
/// lists of names (the Python side makes them string arrays).
pub(crate) fn segment_arrays<'py>(
    py: Python<'py>,
    per_surface: &[Vec<DiscontinuitySegment>],
) -> PyResult<Bound<'py, PyDict>> {
    let all: Vec<&DiscontinuitySegment> = per_surface.iter().flatten().collect();
    let ends: Vec<f64> = all
        .iter()
        .flat_map(|g| g.from.to_array().into_iter().chain(g.to.to_array()))
        .collect();
    let segments = PyArray1::from_vec(py, ends).reshape([all.len(), 2, 3])?;
    let ids = |f: fn(&DiscontinuitySegment) -> usize| -> Vec<u32> {
        all.iter().map(|g| f(g) as u32).collect()
    };
    let dict = PyDict::new(py);
    dict.set_item("segments", segments)?;
    dict.set_item("surface_id", PyArray1::from_vec(py, ids(|g| g.surface)))?;
    dict.set_item("emitter", PyArray1::from_vec(py, ids(|g| g.emitter)))?;
    let order: Vec<u8> = all.iter().map(|g| g.order).collect();
    dict.set_item("order", PyArray1::from_vec(py, order))?;
    let event: Vec<&str> = all.iter().map(|g| g.event.name()).collect();
    dict.set_item("event", event)?;
    let boundary: Vec<&str> = all.iter().map(|g| g.boundary.name()).collect();
    dict.set_item("boundary", boundary)?;
    Ok(dict)
}
