//! `penumbra.Solution`'s native half: a finished run, its arrays, its JSON and its files.

use std::borrow::Cow;
use std::path::PathBuf;
use std::sync::OnceLock;

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2};
use penumbra::RunResult;
use penumbra::export::{ExportFormat, export_run};
use penumbra::outputs::{SvgSelection, write_outputs};
use penumbra_meshing::TriangleLocator;
use penumbra_scenes::{Rgb, SurfaceId};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use crate::arrays::{array3, rgb_array, segment_arrays};
use crate::primitives::SurfaceLocator;
use crate::scene::Scene;

/// A finished run, held for its arrays, its report and its files.
#[pyclass(module = "penumbra._native", frozen)]
pub(crate) struct RunOutput {
    result: RunResult,
    /// The scene that was run, with its visibility index shared with the caller's `Scene`.
    scene: Scene,
    /// For `interpolate`, built on first use: each surface mesh's triangle finder.
    locators: OnceLock<Vec<TriangleLocator>>,
}

impl RunOutput {
    /// The output of a run of `scene`.
    pub(crate) fn new(result: RunResult, scene: Scene) -> RunOutput {
        RunOutput {
            result,
            scene,
            locators: OnceLock::new(),
        }
    }
}

/// The whole scene's mesh and light, surface after surface in the scene's order.
#[derive(Default)]
struct Concatenated {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    vertex_surface: Vec<u32>,
    triangle_surface: Vec<u32>,
    vertex_offsets: Vec<u64>,
    triangle_offsets: Vec<u64>,
    radiosity: Vec<Rgb>,
    direct: Vec<Rgb>,
    indirect: Vec<Rgb>,
    irradiance: Vec<Rgb>,
    direct_irradiance: Vec<Rgb>,
}

impl Concatenated {
    fn of(result: &RunResult) -> Concatenated {
        let solution = &result.solution;
        let mut all = Concatenated::default();
        for (s, mesh) in result.mesh.surfaces.iter().enumerate() {
            let first = all.vertices.len() as u32;
            all.vertex_offsets.push(u64::from(first));
            all.triangle_offsets.push(all.triangles.len() as u64);
            all.vertices
                .extend(mesh.points3.iter().map(|p| p.to_array()));
            all.triangles
                .extend(mesh.triangles.iter().map(|t| t.map(|i| i + first)));
            all.vertex_surface
                .extend(std::iter::repeat_n(s as u32, mesh.points3.len()));
            all.triangle_surface
                .extend(std::iter::repeat_n(s as u32, mesh.triangles.len()));
            let (direct, indirect) = result.reflected_parts(s);
            all.radiosity.extend_from_slice(&solution.radiosity[s]);
            all.irradiance.extend_from_slice(&solution.irradiance[s]);
            all.direct_irradiance
                .extend_from_slice(&solution.direct_irradiance[s]);
            all.direct.extend(direct);
            all.indirect.extend(indirect);
        }
        all.vertex_offsets.push(all.vertices.len() as u64);
        all.triangle_offsets.push(all.triangles.len() as u64);
        all
    }
}

/// `quantity` at surface `s`'s vertices: borrowed where the solution holds it.
fn quantity_at<'r>(result: &'r RunResult, quantity: &str, s: SurfaceId) -> Cow<'r, [Rgb]> {
    let solution = &result.solution;
    match quantity {
        "irradiance" => Cow::Borrowed(&solution.irradiance[s]),
        "direct_irradiance" => Cow::Borrowed(&solution.direct_irradiance[s]),
        "direct" => Cow::Owned(result.reflected_parts(s).0),
        "indirect" => Cow::Owned(result.reflected_parts(s).1),
        _ => Cow::Borrowed(&solution.radiosity[s]),
    }
}

/// `"auto"`, `"all"`, `"none"` or surface names: which surfaces get an SVG.
fn svg_selection(result: &RunResult, svg: &Bound<'_, PyAny>) -> PyResult<SvgSelection> {
    if let Ok(word) = svg.extract::<String>() {
        return match word.as_str() {
            "auto" => Ok(SvgSelection::Auto),
            "all" => Ok(SvgSelection::All),
            "none" => Ok(SvgSelection::None),
            _ => Err(PyValueError::new_err(format!(
                "svg: must be \"auto\", \"all\", \"none\" or a list of surface names, not {word:?}"
            ))),
        };
    }
    let names: Vec<String> = svg.extract()?;
    SvgSelection::named(&result.loaded.scene, &names).map_err(|unknown| {
        PyValueError::new_err(format!(
            "svg: the scene has no surface named {}",
            unknown.join(", ")
        ))
    })
}

#[pymethods]
impl RunOutput {
    /// Every array of the solution, as a dict (see `penumbra.Solution`).
    fn arrays<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let all = Concatenated::of(&self.result);
        let dict = PyDict::new(py);
        dict.set_item("vertices", array3(py, &all.vertices))?;
        dict.set_item("triangles", array3(py, &all.triangles))?;
        dict.set_item("surface_id", PyArray1::from_vec(py, all.vertex_surface))?;
        dict.set_item(
            "triangle_surface_id",
            PyArray1::from_vec(py, all.triangle_surface),
        )?;
        dict.set_item("vertex_offsets", PyArray1::from_vec(py, all.vertex_offsets))?;
        dict.set_item(
            "triangle_offsets",
            PyArray1::from_vec(py, all.triangle_offsets),
        )?;
        dict.set_item("radiosity", rgb_array(py, &all.radiosity))?;
        dict.set_item("direct", rgb_array(py, &all.direct))?;
        dict.set_item("indirect", rgb_array(py, &all.indirect))?;
        dict.set_item("irradiance", rgb_array(py, &all.irradiance))?;
        dict.set_item("direct_irradiance", rgb_array(py, &all.direct_irradiance))?;
        dict.set_item(
            "discontinuities",
            segment_arrays(py, &self.result.mesh.discontinuities)?,
        )?;
        Ok(dict)
    }

    /// `report.json` as `write` with the SVGs chosen automatically writes it, as text.
    fn report_json(&self) -> String {
        penumbra::outputs::report_json(&self.result, &SvgSelection::Auto)
    }

    /// `solution.json`, as text.
    fn solution_json(&self) -> String {
        penumbra::outputs::solution_json(&self.result)
    }

    /// Writes the command line's files into `directory`, all or nothing; returns their paths.
    #[pyo3(signature = (directory, svg, convergence, export))]
    fn write(
        &self,
        py: Python<'_>,
        directory: PathBuf,
        svg: &Bound<'_, PyAny>,
        convergence: bool,
        export: &str,
    ) -> PyResult<Vec<PathBuf>> {
        let svgs = svg_selection(&self.result, svg)?;
        let formats = ExportFormat::parse_list(export).map_err(|name| {
            PyValueError::new_err(format!(
                "export: {name:?} is not a format; give vtp, ply, glb, obj, html, \"all\" or \"none\""
            ))
        })?;
        let result = &self.result;
        let (written, exported) = py.detach(|| {
            // The run's own files are written even when its exports cannot be.
            let exported = export_run(result, &svgs, &formats);
            let written = (|| {
                let mut extra = match convergence {
                    true => penumbra::outputs::convergence_files(result)?,
                    false => Vec::new(),
                };
                if let Ok(files) = &exported {
                    extra.extend(files.iter().cloned());
                }
                write_outputs(result, &directory, &svgs, extra)
            })();
            (written, exported)
        });
        let written = written.map_err(|e| PyOSError::new_err(format!("{e:#}")))?;
        exported.map_err(|e| {
            PyValueError::new_err(format!("wrote the run's files, but not its exports: {e}"))
        })?;
        Ok(written)
    }

    /// `quantity` at `points` on the surfaces `surfaces` names, linear over the mesh's
    /// triangles as the sweep measures it; NaN for a point off its surface (or given -1).
    #[pyo3(signature = (points, surfaces, quantity))]
    fn interpolate<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        surfaces: Vec<i64>,
        quantity: &str,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let at = crate::arrays::points(&points, "points")?;
        if surfaces.len() != at.len() {
            return Err(PyValueError::new_err(format!(
                "surfaces: {} ids for {} points",
                surfaces.len(),
                at.len()
            )));
        }
        let result = &self.result;
        const QUANTITIES: [&str; 5] = [
            "radiosity",
            "direct",
            "indirect",
            "irradiance",
            "direct_irradiance",
        ];
        if !QUANTITIES.contains(&quantity) {
            return Err(PyValueError::new_err(format!(
                "quantity: must be one of {QUANTITIES:?}, not {quantity:?}"
            )));
        }
        let per_surface: Vec<Cow<'_, [Rgb]>> = (0..result.mesh.surfaces.len())
            .map(|s| quantity_at(result, quantity, s))
            .collect();
        let meshes = &result.mesh.surfaces;
        let count = meshes.len() as i64;
        if let Some(bad) = surfaces.iter().find(|&&s| s < -1 || s >= count) {
            return Err(PyValueError::new_err(format!(
                "surfaces: {bad} is no surface id (0 to {}, or -1)",
                count - 1
            )));
        }
        let values = py.detach(|| {
            let locators = self
                .locators
                .get_or_init(|| meshes.iter().map(TriangleLocator::new).collect());
            let shared = self.scene.shared();
            let on = SurfaceLocator::new(shared.data(), shared.visibility());
            at.par_iter()
                .zip(&surfaces)
                .map(|(&p, &s)| match usize::try_from(s) {
                    Ok(s) if on.holds(s, p) => locators[s]
                        .interpolate(&meshes[s], &per_surface[s], p)
                        .to_array(),
                    _ => [f64::NAN; 3],
                })
                .collect::<Vec<[f64; 3]>>()
        });
        Ok(array3(py, &values))
    }

    /// The render from the scene's camera, (height, width, 3) uint8 sRGB.
    fn render<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let image = &self.result.render.image;
        let (width, height) = (image.width() as usize, image.height() as usize);
        let pixels = PyArray1::from_vec(py, image.as_raw().clone());
        Ok(pixels.reshape([height, width, 3])?.into_any())
    }

    /// The scene that was run.
    #[getter]
    fn scene(&self) -> Scene {
        self.scene.clone()
    }
}
