//! `penumbra.Scene`'s native half: a validated scene, from a file, a built-in name, JSON text or
//! arrays.

use std::path::Path;
use std::sync::{Arc, OnceLock};

use glam::DVec3;
use numpy::{PyArray2, PyReadonlyArray2};
use penumbra_scenes::{
    Camera, LoadedScene, ObjOptions, PlaneFrame, Rgb, Scene as SceneData, Surface, Visibility,
};
use pyo3::exceptions::PyFileNotFoundError;
use pyo3::prelude::*;

use crate::arrays::{array3, points, rgb_array, rows3};
use crate::errors::{bad_argument, scene_error};

/// A camera as Python gives it: eye, target, up and the vertical field of view in degrees.
type CameraParts = ([f64; 3], [f64; 3], [f64; 3], f64);

/// A validated scene and its visibility index, built when first needed and kept (the scene
/// never changes); shared by the Python object and the work it starts.
pub(crate) struct Shared {
    pub(crate) loaded: LoadedScene,
    visibility: OnceLock<Visibility>,
}

impl Shared {
    pub(crate) fn data(&self) -> &SceneData {
        &self.loaded.scene
    }

    /// The scene's visibility index (built on first use: call it without the GIL).
    pub(crate) fn visibility(&self) -> &Visibility {
        self.visibility
            .get_or_init(|| Visibility::build(&self.loaded.scene))
    }
}

/// A validated scene. Immutable: every constructor validates, so every `Scene` can be run.
#[pyclass(module = "penumbra._native", frozen)]
#[derive(Clone)]
pub(crate) struct Scene {
    shared: Arc<Shared>,
}

impl Scene {
    /// A scene made in memory, validated: every problem at once in the error.
    fn validated(
        py: Python<'_>,
        scene: SceneData,
        source: String,
        warnings: Vec<String>,
    ) -> PyResult<Scene> {
        let problems = penumbra_scenes::validate(&scene);
        if !problems.is_empty() {
            return Err(scene_error(
                py,
                penumbra_scenes::SceneError::Invalid {
                    source_name: source,
                    problems,
                    warnings,
                },
            ));
        }
        Ok(Scene::new(LoadedScene {
            scene,
            source,
            warnings,
        }))
    }

    pub(crate) fn new(loaded: LoadedScene) -> Scene {
        Scene {
            shared: Arc::new(Shared {
                loaded,
                visibility: OnceLock::new(),
            }),
        }
    }

    /// The scene and its index, for work on another thread.
    pub(crate) fn shared(&self) -> Arc<Shared> {
        Arc::clone(&self.shared)
    }

    pub(crate) fn loaded(&self) -> &LoadedScene {
        &self.shared.loaded
    }

    pub(crate) fn data(&self) -> &SceneData {
        self.shared.data()
    }
}

#[pymethods]
impl Scene {
    /// A `.json`, `.obj` (with its `.mtl` libraries), `.gltf` (with its buffers) or `.glb` file.
    #[staticmethod]
    #[pyo3(signature = (path, merge = true))]
    fn load(py: Python<'_>, path: &str, merge: bool) -> PyResult<Scene> {
        // A path, never a built-in name: a missing file is an error of its own.
        if !Path::new(path).is_file() {
            return Err(PyFileNotFoundError::new_err(format!(
                "no scene file at {path:?}"
            )));
        }
        let options = ObjOptions {
            merge_coplanar: merge,
        };
        let loaded = py
            .detach(|| penumbra_scenes::load_scene_with(path, &options))
            .map_err(|e| scene_error(py, e))?;
        Ok(Scene::new(loaded))
    }

    /// The built-in scene called `name`.
    #[staticmethod]
    fn builtin(py: Python<'_>, name: &str) -> PyResult<Scene> {
        match penumbra_scenes::builtin::builtin(name) {
            Some(scene) => Scene::validated(py, scene, format!("builtin:{name}"), Vec::new()),
            None => Err(scene_error(
                py,
                penumbra_scenes::SceneError::UnknownScene {
                    name: name.to_owned(),
                    available: penumbra_scenes::builtin::NAMES
                        .iter()
                        .map(|(n, _)| *n)
                        .collect(),
                },
            )),
        }
    }

    /// A scene in penumbra's JSON format, given as text.
    #[staticmethod]
    fn from_json(py: Python<'_>, text: &str) -> PyResult<Scene> {
        let scene = penumbra_scenes::parse_json(text, Path::new("<json>"))
            .map_err(|e| scene_error(py, e))?;
        Scene::validated(py, scene, "json".to_owned(), Vec::new())
    }

    /// Surfaces from arrays: `names` (S), `corners` (P, 3) with `counts` (S) corners each, in
    /// order; `reflectance` and `emission` (S, 3); a camera as (eye, target, up, fov_deg).
    #[staticmethod]
    #[allow(clippy::too_many_arguments)] // One argument per part of a scene, as Python gives them.
    #[pyo3(signature = (name, names, corners, counts, reflectance, emission, camera = None))]
    fn from_arrays(
        py: Python<'_>,
        name: String,
        names: Vec<String>,
        corners: PyReadonlyArray2<'_, f64>,
        counts: Vec<usize>,
        reflectance: PyReadonlyArray2<'_, f64>,
        emission: PyReadonlyArray2<'_, f64>,
        camera: Option<CameraParts>,
    ) -> PyResult<Scene> {
        let corners = points(&corners, "polygons")?;
        let reflectance = rows3(&reflectance, "reflectance")?;
        let emission = rows3(&emission, "emission")?;
        let surfaces = names.len();
        if counts.len() != surfaces || reflectance.len() != surfaces || emission.len() != surfaces {
            return Err(bad_argument(
                "polygons",
                format!(
                    "{surfaces} names, {} polygons, {} reflectances and {} emissions do not match",
                    counts.len(),
                    reflectance.len(),
                    emission.len()
                ),
            ));
        }
        if counts.iter().sum::<usize>() != corners.len() {
            return Err(bad_argument(
                "polygons",
                "the corner counts do not add up to the corners",
            ));
        }
        let mut next = corners.into_iter();
        let surfaces = names
            .into_iter()
            .zip(counts)
            .zip(reflectance.into_iter().zip(emission))
            .map(|((name, count), (rho, e))| {
                Surface::new(name, next.by_ref().take(count).collect(), Rgb::from(rho))
                    .with_emission(Rgb::from(e))
            })
            .collect();
        let camera = camera.map(|(eye, target, up, fov_deg)| Camera {
            eye: DVec3::from(eye),
            target: DVec3::from(target),
            up: DVec3::from(up),
            fov_deg,
        });
        let scene = SceneData {
            up: None,
            unit: None,
            name,
            camera,
            surfaces,
        };
        Scene::validated(py, scene, "python".to_owned(), Vec::new())
    }

    /// The scene in penumbra's JSON format.
    fn to_json(&self) -> String {
        penumbra_scenes::to_json(self.data())
    }

    #[getter]
    fn name(&self) -> &str {
        &self.data().name
    }

    /// Where the scene came from: a path, `builtin:NAME`, `json` or `python`.
    #[getter]
    fn source(&self) -> &str {
        &self.loaded().source
    }

    /// What loading repaired (OBJ files), one line each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.loaded().warnings.clone()
    }

    #[getter]
    fn surface_names(&self) -> Vec<String> {
        self.data()
            .surfaces
            .iter()
            .map(|s| s.name.clone())
            .collect()
    }

    /// Each surface's corners, (K, 3) arrays.
    #[getter]
    fn polygons<'py>(&self, py: Python<'py>) -> Vec<Bound<'py, PyArray2<f64>>> {
        self.data()
            .surfaces
            .iter()
            .map(|s| {
                let rows: Vec<[f64; 3]> = s.polygon.iter().map(|p| p.to_array()).collect();
                array3(py, &rows)
            })
            .collect()
    }

    #[getter]
    fn reflectance<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rho: Vec<Rgb> = self.data().surfaces.iter().map(|s| s.reflectance).collect();
        rgb_array(py, &rho)
    }

    #[getter]
    fn emission<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let e: Vec<Rgb> = self.data().surfaces.iter().map(|s| s.emission).collect();
        rgb_array(py, &e)
    }

    /// Each surface's unit normal, (S, 3).
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<[f64; 3]> = self
            .data()
            .surfaces
            .iter()
            .map(|s| s.normal().to_array())
            .collect();
        array3(py, &rows)
    }

    /// Each surface's area, in scene units squared.
    #[getter]
    fn areas(&self) -> Vec<f64> {
        self.data().surfaces.iter().map(Surface::area).collect()
    }

    /// The camera as (eye, target, up, fov_deg), if the scene has one.
    #[getter]
    fn camera(&self) -> Option<CameraParts> {
        self.data().camera.map(|c| {
            (
                c.eye.to_array(),
                c.target.to_array(),
                c.up.to_array(),
                c.fov_deg,
            )
        })
    }

    /// Each surface's plane frame: origin, u, v (unit, in the plane) and normal, as (4, 3)
    /// arrays; `None` for a polygon without one (validation refuses those).
    #[getter]
    fn frames<'py>(&self, py: Python<'py>) -> Vec<Option<Bound<'py, PyArray2<f64>>>> {
        self.data()
            .surfaces
            .iter()
            .map(|s| {
                PlaneFrame::of_polygon(&s.polygon)
                    .map(|f| array3(py, &[f.origin, f.u, f.v, f.normal].map(|d| d.to_array())))
            })
            .collect()
    }

    /// The same scene, seen through another camera: each part given replaces that part of
    /// the scene's camera (or of the default view that frames the scene), as `penumbra run
    /// --eye --target --up --fov` do; validated like the scene's own.
    #[pyo3(signature = (eye = None, target = None, up = None, fov_deg = None))]
    fn with_camera(
        &self,
        py: Python<'_>,
        eye: Option<[f64; 3]>,
        target: Option<[f64; 3]>,
        up: Option<[f64; 3]>,
        fov_deg: Option<f64>,
    ) -> PyResult<Scene> {
        let mut scene = self.data().clone();
        let base = scene
            .camera
            .unwrap_or_else(|| penumbra_viz::default_camera(&scene));
        scene.camera = Some(Camera {
            eye: eye.map_or(base.eye, DVec3::from),
            target: target.map_or(base.target, DVec3::from),
            up: up.map_or(base.up, DVec3::from),
            fov_deg: fov_deg.unwrap_or(base.fov_deg),
        });
        let loaded = self.loaded();
        Scene::validated(py, scene, loaded.source.clone(), loaded.warnings.clone())
    }

    /// A hash of the whole scene (its JSON form), as `report.json` records it.
    #[getter]
    fn fingerprint(&self) -> String {
        penumbra::shard::scene_fingerprint(self.loaded())
    }

    fn __len__(&self) -> usize {
        self.data().surfaces.len()
    }

    fn __eq__(&self, other: &Scene) -> bool {
        self.data() == other.data()
    }
}

/// The built-in scenes' names and one-line descriptions.
#[pyfunction]
pub(crate) fn builtin_scenes() -> Vec<(&'static str, &'static str)> {
    penumbra_scenes::builtin::NAMES.to_vec()
}
