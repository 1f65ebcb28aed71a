//! A run's solution in the formats other tools read: VTK XML PolyData for ParaView
//! ([`vtp`]), binary PLY for MeshLab and Blender ([`ply`]), glTF binary for browsers and
//! Blender ([`glb`]), OBJ + MTL for any tool ([`obj`]), and a self-contained viewer page
//! ([`viewer`]).
//!
//! Every export is made from what `solution.json` and `report.json` hold ([`ExportSource`]),
//! so `penumbra export DIR` on a finished run writes the same bytes as `penumbra run
//! --export`. Colours are tone-mapped as in `render.png`: the radiosity plus the surface's share
//! of the display-only ambient term (ρ·ambient), times the render's exposure, through the sRGB
//! curve.

mod glb;
mod mesh;
mod obj;
mod ply;
mod viewer;
mod vtp;

use std::path::Path;

use penumbra_meshing::discontinuity::Boundary;
use penumbra_scenes::{Camera, Rgb};
use serde::Deserialize;

use crate::outputs::{SOLUTION_FORMAT, SurfaceSolution, SvgSelection, surface_solution};
use crate::pipeline::RunResult;
use crate::report::Report;

use mesh::{FlatMesh, Line};
pub use viewer::VIEWER_FORMAT;

/// An export format (`--export`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ExportFormat {
    /// `solution.vtp`: VTK XML PolyData.
    Vtp,
    /// `solution.ply`: binary little-endian PLY.
    Ply,
    /// `solution.glb`: glTF 2.0 binary.
    Glb,
    /// `solution.obj` and `solution.mtl`.
    Obj,
    /// `index.html`: the viewer page.
    Html,
}

impl ExportFormat {
    /// Every format, in the order files are written.
    pub const ALL: [ExportFormat; 5] = [
        ExportFormat::Vtp,
        ExportFormat::Ply,
        ExportFormat::Glb,
        ExportFormat::Obj,
        ExportFormat::Html,
    ];

    /// The format's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ExportFormat::Vtp => "vtp",
            ExportFormat::Ply => "ply",
            ExportFormat::Glb => "glb",
            ExportFormat::Obj => "obj",
            ExportFormat::Html => "html",
        }
    }

    /// The format named `name` (as [`ExportFormat::name`] gives it).
    pub fn from_name(name: &str) -> Option<ExportFormat> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }

    /// A comma-separated list of format names, `all` or `none`, each once, in
    /// [`ExportFormat::ALL`]'s order; `Err` with the first name that is not a format.
    pub fn parse_list(list: &str) -> Result<Vec<ExportFormat>, String> {
        let mut formats = Vec::new();
        for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            match name.to_ascii_lowercase().as_str() {
                "all" => formats.extend(Self::ALL),
                "none" => {}
                other => formats.push(Self::from_name(other).ok_or_else(|| name.to_owned())?),
            }
        }
        formats.sort_unstable();
        formats.dedup();
        Ok(formats)
    }
}

/// Why a solution cannot be exported.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// A file of the run could not be read.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// A file of the run is not what penumbra writes.
    #[error("{path} is not a penumbra {what}: {reason}")]
    Malformed {
        /// The file.
        path: String,
        /// `solution.json` or `report.json`.
        what: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// A surface lacks data the exports need: files of earlier versions did not write it.
    #[error(
        "surface {surface:?} of solution.json has no {field} (it was written by an earlier \
         version of penumbra); run the scene again to export it"
    )]
    Missing {
        /// The surface's name.
        surface: String,
        /// The missing field.
        field: &'static str,
    },
    /// The solution's parts do not fit together.
    #[error("surface {surface:?} of solution.json: {reason}")]
    Inconsistent {
        /// The surface's name.
        surface: String,
        /// What does not fit.
        reason: String,
    },
    /// The solution has no triangles: nothing to show.
    #[error("solution.json has no triangles to export")]
    Empty,
    /// A format's encoder refused the data.
    #[error("cannot encode {format}: {reason}")]
    Encode {
        /// The format's name.
        format: &'static str,
        /// Why.
        reason: String,
    },
    /// The solution is too large for the format.
    #[error("{format} cannot hold this solution: {reason}")]
    TooLarge {
        /// The format's name.
        format: &'static str,
        /// What is too large.
        reason: String,
    },
}

/// How values are shown as colours, as `render.png` shows them (`report.json`'s `render`): each
/// surface adds its share of the display-only ambient term, ρ·ambient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Display {
    /// The render's exposure: displayed value = (radiosity + ρ·ambient) × exposure.
    pub exposure: f64,
    /// The display-only ambient term, W/m² per channel.
    pub ambient: Rgb,
}

impl Display {
    /// What `render.png` shows for radiosity `b` on a surface of reflectance `rho`, before the
    /// exposure: `b` plus the surface's share of the ambient term, ρ·ambient.
    fn shown(&self, b: [f64; 3], rho: [f64; 3]) -> Rgb {
        penumbra_solver::displayed(Rgb::from(b), Rgb::from(rho), self.ambient)
    }

    /// The 8-bit sRGB colour `render.png` gives radiosity `b` on a surface of reflectance
    /// `rho`.
    pub fn srgb8(&self, b: [f64; 3], rho: [f64; 3]) -> [u8; 3] {
        penumbra_viz::to_srgb8(self.shown(b, rho), self.exposure)
    }

    /// The linear display value of radiosity `b` on a surface of reflectance `rho` (its share
    /// of the ambient term added, times the exposure), each channel clamped to `[0, 1]`: what
    /// glTF's linear `COLOR_0` takes.
    pub fn linear(&self, b: [f64; 3], rho: [f64; 3]) -> [f64; 3] {
        let c = self.shown(b, rho);
        [c.r, c.g, c.b].map(|v| {
            let v = v * self.exposure;
            if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) }
        })
    }
}

/// What the exports are made from: a run's `solution.json` and `report.json`.
#[derive(Clone, Debug)]
pub struct ExportSource {
    /// The scene's name.
    pub scene: String,
    /// The surfaces, as `solution.json` gives them.
    pub surfaces: Vec<SurfaceSolution>,
    /// `report.json`.
    pub report: Report,
}

#[derive(Deserialize)]
struct SolutionFile {
    format: String,
    scene: String,
    surfaces: Vec<SurfaceSolution>,
}

impl ExportSource {
    /// What `solution.json` and `report.json` of `result` hold (its SVGs chosen by `svgs`).
    pub fn of_run(result: &RunResult, svgs: &SvgSelection) -> ExportSource {
        let surfaces = (0..result.mesh.surfaces.len())
            .map(|s| surface_solution(result, s))
            .collect();
        ExportSource {
            scene: result.loaded.scene.name.clone(),
            surfaces,
            report: Report::of_run(result, svgs),
        }
    }

    /// A finished run's `solution.json` and `report.json` in `dir`.
    pub fn read_run(dir: &Path) -> Result<ExportSource, ExportError> {
        let read = |name: &str| {
            let path = dir.join(name);
            std::fs::read_to_string(&path).map_err(|source| ExportError::Read {
                path: path.display().to_string(),
                source,
            })
        };
        Self::parse(&read("solution.json")?, &read("report.json")?, dir)
    }

    /// `solution.json` and `report.json` from their text; `dir` is where they are, for
    /// messages.
    pub fn parse(solution: &str, report: &str, dir: &Path) -> Result<ExportSource, ExportError> {
        let malformed = |name: &str, what, reason: String| ExportError::Malformed {
            path: dir.join(name).display().to_string(),
            what,
            reason,
        };
        let solution: SolutionFile = serde_json::from_str(solution)
            .map_err(|e| malformed("solution.json", "solution", e.to_string()))?;
        if solution.format != SOLUTION_FORMAT {
            let reason = format!(
                "its format is {:?}, not {SOLUTION_FORMAT:?}",
                solution.format
            );
            return Err(malformed("solution.json", "solution", reason));
        }
        let report =
            Report::parse(report).map_err(|e| malformed("report.json", "report", e.to_string()))?;
        if report.scene.name != solution.scene || report.scene.surfaces != solution.surfaces.len() {
            let reason = format!(
                "it is not the report of solution.json's run (scene {:?} of {} surfaces)",
                solution.scene,
                solution.surfaces.len()
            );
            return Err(malformed("report.json", "report", reason));
        }
        let source = ExportSource {
            scene: solution.scene,
            surfaces: solution.surfaces,
            report,
        };
        source
            .display()
            .map_err(|reason| malformed("report.json", "report", reason))?;
        Ok(source)
    }

    /// How `render.png` showed values: `report.json`'s `render.exposure` and
    /// `render.ambient`.
    pub fn display(&self) -> Result<Display, String> {
        let render = &self.report.render;
        if !(render.exposure.is_finite() && render.exposure > 0.0) {
            return Err("its render.exposure is not a positive number".into());
        }
        if !render.ambient.is_finite() {
            return Err("its render.ambient is not an RGB colour".into());
        }
        Ok(Display {
            exposure: render.exposure,
            ambient: render.ambient,
        })
    }

    /// The camera `render.png` was made from (`report.json`'s `render.camera`), if recorded
    /// and usable: finite, looking somewhere, with a field of view in (0, 180) degrees.
    pub fn camera(&self) -> Option<Camera> {
        let camera = self.report.render.camera?;
        let view = camera.target - camera.eye;
        let finite = camera.eye.is_finite() && view.is_finite() && camera.up.is_finite();
        let upright = view.cross(camera.up).length_squared() > 0.0;
        let fov = camera.fov_deg > 0.0 && camera.fov_deg < 180.0;
        (finite && upright && fov).then_some(camera)
    }
}

/// The files of `formats` for `result` (whose SVGs `svgs` chooses): nothing, and no work, for
/// no formats.
pub fn export_run(
    result: &RunResult,
    svgs: &SvgSelection,
    formats: &[ExportFormat],
) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    if formats.is_empty() {
        return Ok(Vec::new());
    }
    export(&ExportSource::of_run(result, svgs), formats)
}

/// The files of `formats` for `source`: (file name, bytes), in the order of
/// [`ExportFormat::ALL`].
pub fn export(
    source: &ExportSource,
    formats: &[ExportFormat],
) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    if formats.is_empty() {
        return Ok(Vec::new());
    }
    let mesh = FlatMesh::of(&source.surfaces)?;
    let display = source.display().map_err(|reason| ExportError::Malformed {
        path: "report.json".into(),
        what: "report",
        reason,
    })?;
    let mut files = Vec::new();
    for format in ExportFormat::ALL
        .into_iter()
        .filter(|f| formats.contains(f))
    {
        match format {
            ExportFormat::Vtp => files.push(("solution.vtp".into(), vtp::vtp(&mesh))),
            ExportFormat::Ply => files.push(("solution.ply".into(), ply::ply(&mesh, &display)?)),
            ExportFormat::Glb => {
                let names: Vec<&str> = source.surfaces.iter().map(|s| s.name.as_str()).collect();
                let scene = &source.report.scene;
                let frame = glb::Frame {
                    up: scene.up,
                    unit: scene.unit,
                };
                files.push((
                    "solution.glb".into(),
                    glb::glb(&mesh, &names, &display, frame)?,
                ));
            }
            ExportFormat::Obj => {
                let (obj, mtl) = obj::obj(&mesh, &source.surfaces, &display);
                files.push(("solution.obj".into(), obj.into_bytes()));
                files.push(("solution.mtl".into(), mtl.into_bytes()));
            }
            ExportFormat::Html => {
                let page = viewer::page(source, &mesh, &display);
                files.push(("index.html".into(), page.into_bytes()));
            }
        }
    }
    Ok(files)
}

/// The colour of a discontinuity line, by its boundary, as 8-bit sRGB: umbra purple, penumbra
/// orange, inner green, as in the surfaces' SVGs.
pub(crate) fn line_colour(line: &Line) -> [u8; 3] {
    match Boundary::ALL.get(usize::from(line.boundary)) {
        Some(Boundary::Umbra) => [0x6a, 0x1b, 0x9a],
        Some(Boundary::Penumbra) => [0xe6, 0x51, 0x00],
        _ => [0x2e, 0x7d, 0x32],
    }
}
