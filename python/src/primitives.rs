//! The research primitives: the exact direct light at any points, the discontinuities without a
//! mesh, path-traced references, and which surface a point lies on.

use glam::{DVec2, DVec3};
use numpy::{PyArray1, PyReadonlyArray2};
use penumbra_meshing::discontinuity::{DiscontinuityOptions, EventSet, find_discontinuities};
use penumbra_scenes::{Bounds, PlaneFrame, Rgb, Scene as SceneData, SurfaceId, Visibility};
use penumbra_solver::path_trace::{MAX_PATHS, PathTraceOptions, PathTracer};
use penumbra_solver::{DirectLight, ReceivingPoint};
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use crate::arrays::{rgb_array, segment_arrays};
use crate::errors::bad_argument;
use crate::scene::Scene;
use crate::worker::{thread_pool, without_gil};

/// Finds the surfaces points lie on: within the scene's contact distance of a polygon, inside
/// it or on its outline.
pub(crate) struct SurfaceLocator<'s> {
    scene: &'s SceneData,
    visibility: &'s Visibility,
    frames: Vec<Option<PlaneFrame>>,
    /// Each polygon in its frame.
    outlines: Vec<Vec<DVec2>>,
    tol: f64,
}

impl<'s> SurfaceLocator<'s> {
    pub(crate) fn new(scene: &'s SceneData, visibility: &'s Visibility) -> SurfaceLocator<'s> {
        let frames: Vec<Option<PlaneFrame>> = scene
            .surfaces
            .iter()
            .map(|s| PlaneFrame::of_polygon(&s.polygon))
            .collect();
        let outlines = scene
            .surfaces
            .iter()
            .zip(&frames)
            .map(|(s, f)| match f {
                Some(f) => s.polygon.iter().map(|&p| f.to_2d(p)).collect(),
                None => Vec::new(),
            })
            .collect();
        SurfaceLocator {
            scene,
            visibility,
            frames,
            outlines,
            tol: visibility.contact_distance(),
        }
    }

    /// Whether `p` lies on surface `s`.
    pub(crate) fn holds(&self, s: SurfaceId, p: DVec3) -> bool {
        self.frames[s].is_some_and(|f| {
            let q = f.to_2d(p);
            f.height(p).abs() <= self.tol
                && penumbra_scenes::polygon::closest_point_in_polygon(&self.outlines[s], q)
                    .distance(q)
                    <= self.tol
        })
    }

    /// The surface `p` lies on, or `None`. Where several do (a point on a shared edge), the
    /// one whose normal is closest to `normal`, else the first in the scene.
    fn surface_at(&self, p: DVec3, normal: Option<DVec3>) -> Option<SurfaceId> {
        let mut near = Vec::new();
        let reach = DVec3::splat(self.tol);
        let triangles = self.visibility.triangles();
        self.visibility
            .triangles_overlapping(Bounds::from_points(&[p - reach, p + reach]), |t| {
                near.push(triangles[t].surface);
            });
        near.sort_unstable();
        near.dedup();
        let on = near.into_iter().filter(|&s| self.holds(s, p));
        match normal {
            None => on.min(),
            Some(n) => on
                .map(|s| (s, self.scene.surfaces[s].normal().dot(n)))
                .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
                .map(|(s, _)| s),
        }
    }

    /// [`Self::surface_at`] for every point.
    fn surfaces_at(&self, at: &[DVec3], normals: Option<&[DVec3]>) -> Vec<Option<SurfaceId>> {
        at.par_iter()
            .enumerate()
            .map(|(i, &p)| self.surface_at(p, normals.map(|n| n[i])))
            .collect()
    }
}

/// Surface ids from Python (`-1`: none) checked against the scene, or found from the points.
fn receivers(
    scene: &SceneData,
    visibility: &Visibility,
    at: &[DVec3],
    normals: Option<&[DVec3]>,
    given: Option<Vec<i64>>,
) -> PyResult<Vec<Option<SurfaceId>>> {
    let Some(given) = given else {
        return Ok(SurfaceLocator::new(scene, visibility).surfaces_at(at, normals));
    };
    if given.len() != at.len() {
        return Err(bad_argument(
            "surfaces",
            format!("has {} ids for {} points", given.len(), at.len()),
        ));
    }
    let count = scene.surfaces.len();
    given
        .into_iter()
        .enumerate()
        .map(|(i, id)| match id {
            -1 => Ok(None),
            id if (0..count as i64).contains(&id) => Ok(Some(id as SurfaceId)),
            id => Err(bad_argument(
                "surfaces",
                format!(
                    "entry {i} is {id}; ids run from 0 to {} (-1: none)",
                    count - 1
                ),
            )),
        })
        .collect()
}

/// Unit normals, each nonzero.
fn unit_normals(normals: &[DVec3]) -> PyResult<Vec<DVec3>> {
    normals
        .iter()
        .enumerate()
        .map(|(i, n)| {
            n.try_normalize()
                .ok_or_else(|| bad_argument("normals", format!("row {i} has no direction")))
        })
        .collect()
}

/// A Ctrl-C that stopped work with nothing to give back.
fn interrupted(signal: Option<PyErr>) -> PyErr {
    signal.unwrap_or_else(|| PyKeyboardInterrupt::new_err("interrupted"))
}

/// The exact direct irradiance (W/m² per channel) at `points` facing `normals`, each on the
/// surface `surfaces` gives (its own polygon casts no shadow on it), or free in space.
#[pyfunction]
#[pyo3(signature = (scene, points, normals, surfaces = None, threads = None))]
pub(crate) fn direct_light<'py>(
    py: Python<'py>,
    scene: &Scene,
    points: PyReadonlyArray2<'py, f64>,
    normals: PyReadonlyArray2<'py, f64>,
    surfaces: Option<Vec<i64>>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    let at = crate::arrays::points(&points, "points")?;
    let normals = unit_normals(&crate::arrays::points(&normals, "normals")?)?;
    if normals.len() != at.len() {
        return Err(bad_argument(
            "normals",
            format!("has {} rows for {} points", normals.len(), at.len()),
        ));
    }
    let pool = thread_pool(threads)?;
    let stop = penumbra_solver::Interrupt::default();
    let (shared, stopping) = (scene.shared(), stop.clone());
    let (values, signal) = without_gil(py, pool, &stop, move || {
        let (data, visibility) = (shared.data(), shared.visibility());
        let on = receivers(data, visibility, &at, Some(&normals), surfaces)?;
        let direct = DirectLight::new(data, visibility);
        // A surface id no surface has: nothing is left out of the occluders.
        let nowhere = data.surfaces.len();
        let values: Vec<Option<Rgb>> = at
            .par_iter()
            .zip(&normals)
            .zip(&on)
            .map(|((&p, &n), s)| {
                (!stopping.is_set()).then(|| {
                    direct.irradiance(&ReceivingPoint::interior(p, n), s.unwrap_or(nowhere))
                })
            })
            .collect();
        Ok::<_, PyErr>(values)
    })?;
    let values: Option<Vec<Rgb>> = values?.into_iter().collect();
    match values {
        Some(values) if signal.is_none() => Ok(rgb_array(py, &values).into_any()),
        _ => Err(interrupted(signal)),
    }
}

/// The discontinuities of the direct light on every surface, without meshing.
#[pyfunction]
#[pyo3(signature = (scene, eee = true, events = "complete", event_tol = None, max_elements = None, threads = None))]
pub(crate) fn discontinuities<'py>(
    py: Python<'py>,
    scene: &Scene,
    eee: bool,
    events: &str,
    event_tol: Option<f64>,
    max_elements: Option<usize>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let events = match events {
        "complete" => EventSet::Complete,
        "extremal" => EventSet::Extremal,
        other => {
            return Err(bad_argument(
                "events",
                format!("must be \"complete\" or \"extremal\", not {other:?}"),
            ));
        }
    };
    let event_tolerance =
        event_tol.unwrap_or(penumbra_meshing::discontinuity::DEFAULT_EVENT_TOLERANCE);
    if !(0.0..=1.0).contains(&event_tolerance) {
        return Err(bad_argument(
            "event_tol",
            format!("must be a fraction between 0 and 1, not {event_tolerance}"),
        ));
    }
    if max_elements == Some(0) {
        return Err(bad_argument("max_elements", "must be at least 1 triangle"));
    }
    let pool = thread_pool(threads)?;
    let stop = penumbra_solver::Interrupt::default();
    let shared = scene.shared();
    let options = DiscontinuityOptions {
        eee,
        events,
        event_tolerance,
        element_area: max_elements.map(|n| shared.data().total_area() / n as f64),
        interrupt: Some(stop.clone()),
        ..DiscontinuityOptions::default()
    };
    let (found, signal) = without_gil(py, pool, &stop, move || {
        find_discontinuities(shared.data(), shared.visibility(), &options)
    })?;
    if signal.is_some() {
        return Err(interrupted(signal));
    }
    let dict = segment_arrays(py, &found.segments)?;
    dict.set_item(
        "stats",
        pythonize_stats(py, &serde_json::to_string(&found.stats))?,
    )?;
    Ok(dict)
}

/// A serializable value as a Python object, through JSON.
fn pythonize_stats<'py>(
    py: Python<'py>,
    json: &serde_json::Result<String>,
) -> PyResult<Bound<'py, PyAny>> {
    let text = json
        .as_ref()
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Path-traced radiosity at `points` on the surfaces `surfaces` gives (or that they lie on),
/// with the standard error of each value's channel mean.
#[pyfunction]
#[pyo3(signature = (scene, points, surfaces = None, paths = 4096, seed = 1, threads = None))]
pub(crate) fn reference<'py>(
    py: Python<'py>,
    scene: &Scene,
    points: PyReadonlyArray2<'py, f64>,
    surfaces: Option<Vec<i64>>,
    paths: usize,
    seed: u64,
    threads: Option<usize>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let at = crate::arrays::points(&points, "points")?;
    if !(1..=MAX_PATHS).contains(&paths) {
        return Err(bad_argument(
            "paths",
            format!("must be from 1 to {MAX_PATHS}, not {paths}"),
        ));
    }
    let pool = thread_pool(threads)?;
    let stop = penumbra_solver::Interrupt::default();
    let (shared, stopping) = (scene.shared(), stop.clone());
    let (values, signal) = without_gil(py, pool, &stop, move || {
        let (data, visibility) = (shared.data(), shared.visibility());
        let given = surfaces.is_some();
        let on = receivers(data, visibility, &at, None, surfaces)?;
        let surface = SurfaceLocator::new(data, visibility);
        let located: Vec<(DVec3, SurfaceId)> = at
            .iter()
            .zip(&on)
            .enumerate()
            .map(|(i, (&p, s))| match *s {
                Some(s) if surface.holds(s, p) => Ok((p, s)),
                Some(s) => Err(bad_argument(
                    "surfaces",
                    format!("point {i} ({p}) does not lie on surface {s}"),
                )),
                None if given => Err(bad_argument(
                    "surfaces",
                    format!(
                        "point {i} has no surface (-1); the reference needs the one it lies on"
                    ),
                )),
                None => Err(bad_argument(
                    "points",
                    format!("point {i} ({p}) lies on no surface; give its surface in surfaces"),
                )),
            })
            .collect::<PyResult<_>>()?;
        let tracer = PathTracer::new(data, visibility);
        let options = PathTraceOptions { paths, seed };
        Ok::<_, PyErr>(tracer.radiosity_unless(&located, &options, Some(&stopping)))
    })?;
    let Some(values) = values? else {
        return Err(interrupted(signal));
    };
    if signal.is_some() {
        return Err(interrupted(signal));
    }
    let radiosity: Vec<Rgb> = values.iter().map(|v| v.radiosity).collect();
    let errors: Vec<f64> = values.iter().map(|v| v.standard_error).collect();
    Ok((
        rgb_array(py, &radiosity).into_any(),
        PyArray1::from_vec(py, errors).into_any(),
    ))
}

/// The surface each point lies on (-1: none), as [`SurfaceLocator`] finds it.
#[pyfunction]
#[pyo3(signature = (scene, points, normals = None))]
pub(crate) fn locate<'py>(
    py: Python<'py>,
    scene: &Scene,
    points: PyReadonlyArray2<'py, f64>,
    normals: Option<PyReadonlyArray2<'py, f64>>,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let at = crate::arrays::points(&points, "points")?;
    let normals = match normals {
        Some(n) => Some(crate::arrays::points(&n, "normals")?),
        None => None,
    };
    let shared = scene.shared();
    let found = py.detach(|| {
        SurfaceLocator::new(shared.data(), shared.visibility()).surfaces_at(&at, normals.as_deref())
    });
    let ids: Vec<i64> = found
        .into_iter()
        .map(|s| s.map_or(-1, |s| s as i64))
        .collect();
    Ok(PyArray1::from_vec(py, ids))
}
