//! The files a run writes: `solution.json`, `report.json`, `render.png` and SVGs of the
//! surfaces worth looking at ([`SvgSelection`]). Each file is written to a temporary name in the
//! output directory and renamed into place, so a reader never sees half a file.

use std::io::Write;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use penumbra_scenes::{Rgb, SurfaceId};
use serde::Serialize;

pub(crate) use crate::json_text::to_json;
pub use crate::options::Invocation;
pub use crate::report::{
    REPORT_FORMAT, VERSION, estimated_direct_warning, mesh_error_warning, quality_warning,
};
use crate::report::{Report, solver_name};
use crate::run_result::RunResult;
pub use crate::svg_selection::{
    DEFAULT_SVG_SURFACES, SVG_DIR, SvgSelection, file_safe_name, svg_name, worth_looking_at,
};

/// The `format` of `solution.json`, and its version (`docs/schemas/solution.schema.json`).
pub const SOLUTION_FORMAT: &str = "penumbra-solution/1";

#[derive(Serialize)]
struct SolutionFile<'a> {
    format: &'static str,
    scene: &'a str,
    surfaces: &'a [SurfaceSolution],
}

/// One surface of `solution.json`. A shard's part ([`crate::shard`]) carries each surface's
/// `index` in the scene as well; `solution.json` leaves it out.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSolution {
    /// The surface's index in the scene: in a shard's part only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub index: Option<SurfaceId>,
    /// The surface's name in the scene, unique within it.
    pub name: String,
    /// The surface's own exitance E, `[r, g, b]` in W/m² (zero unless it is a light). Absent
    /// from files of earlier versions, as are `reflectance` and `direct`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<[f64; 3]>,
    /// The surface's diffuse reflectance ρ, `[r, g, b]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reflectance: Option<[f64; 3]>,
    /// The mesh's vertices, in 3D scene coordinates and units. The two sides of a value
    /// discontinuity (a blocker touching the surface) each have their own vertex at the same
    /// position.
    pub vertices: Vec<[f64; 3]>,
    /// The mesh's triangles, as indices into `vertices`, counter-clockwise seen from the
    /// surface's front.
    pub triangles: Vec<[u32; 3]>,
    /// Radiosity B at each vertex, `[r, g, b]` in W/m², in the order of `vertices`: the
    /// surface's own emission included, the display-only ambient term left out.
    pub radiosity: Vec<[f64; 3]>,
    /// The direct light's part of the radiosity at each vertex, ρ·H_direct: what the surface
    /// reflects straight from the lights, exact. The rest of the reflected light, `radiosity`
    /// − `emission` − `direct`, came by more bounces.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direct: Option<Vec<[f64; 3]>>,
    /// Adaptive runs only: each triangle's error indicator in the last round of refinement, in
    /// W/m² (the residual the refinement split by), in the order of `triangles`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_indicator: Option<Vec<f64>>,
    /// The discontinuity segments of the direct light built into the mesh as edges (none for
    /// uniform meshes, for surfaces no shadow falls on, and for emitters).
    pub discontinuities: Vec<Discontinuity>,
}

/// A straight segment of a discontinuity line of the direct light on a surface, as
/// `solution.json` gives it (curved EEE lines come as several segments).
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Discontinuity {
    /// The segment's first end, in 3D scene coordinates, on the surface.
    pub from: [f64; 3],
    /// The segment's second end.
    pub to: [f64; 3],
    /// The visual event that makes the line: `EV`, `VE`, `EEE`, `contact`, `blocker-EV` or
    /// `horizon` ([`Event::name`](penumbra_meshing::discontinuity::Event::name)).
    pub event: String,
    /// What the line bounds: `umbra` (one side sees none of the emitter), `penumbra` (one side
    /// sees all of it) or `inner` (both sides see part of it).
    pub boundary: String,
    /// Which derivative of the direct light jumps across the line: 0 the value (contact
    /// lines), 1 the slope, 2 the curvature.
    pub order: u8,
}

/// Surface `s` of a run as `solution.json` gives it.
pub fn surface_solution(result: &RunResult, s: SurfaceId) -> SurfaceSolution {
    let m = &result.mesh.surfaces[s];
    let surface = &result.loaded.scene.surfaces[s];
    let rgb = |values: &[Rgb]| values.iter().map(|c| c.to_array()).collect();
    SurfaceSolution {
        index: None,
        name: surface.name.clone(),
        emission: Some(surface.emission.to_array()),
        reflectance: Some(surface.reflectance.to_array()),
        vertices: m.points3.iter().map(|p| p.to_array()).collect(),
        triangles: m.triangles.clone(),
        radiosity: rgb(&result.solution.radiosity[s]),
        direct: Some(rgb(&result.reflected_parts(s).0)),
        error_indicator: result
            .refinement
            .as_ref()
            .and_then(|r| r.triangle_residuals.get(s).cloned()),
        discontinuities: result.mesh.discontinuities[m.surface]
            .iter()
            .map(|g| Discontinuity {
                from: g.from.to_array(),
                to: g.to.to_array(),
                event: g.event.name().to_owned(),
                boundary: g.boundary.name().to_owned(),
                order: g.order,
            })
            .collect(),
    }
}

/// `solution.json`: per surface in the scene's order, its mesh's vertices and triangles, the
/// radiosity at every vertex (no display-only ambient term) and its discontinuity segments;
/// pretty-printed, with a final newline.
pub fn solution_json(result: &RunResult) -> String {
    let surfaces: Vec<SurfaceSolution> = (0..result.mesh.surfaces.len())
        .map(|s| surface_solution(result, s))
        .collect();
    solution_json_of(&result.loaded.scene.name, &surfaces)
}

/// `solution.json` of scene `scene` from its surfaces, in the scene's order.
pub fn solution_json_of(scene: &str, surfaces: &[SurfaceSolution]) -> String {
    to_json(&SolutionFile {
        format: SOLUTION_FORMAT,
        scene,
        surfaces,
    })
}

/// `report.json`, for a run whose SVGs are chosen by `svgs` ([`Report::of_run`]).
pub fn report_json(result: &RunResult, svgs: &SvgSelection) -> String {
    Report::of_run(result, svgs).to_json()
}

/// A temporary file name in the same directory as `path` (so that renaming it is atomic).
fn temporary_beside(path: &Path) -> PathBuf {
    let dir = path.parent().unwrap_or(Path::new("."));
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dir.join(format!(".{file_name}.tmp-{}", std::process::id()))
}

/// Writes `bytes` to a temporary file beside `path` ([`temporary_beside`]) and syncs it;
/// returns the temporary's path, for a rename into place. On failure the temporary is removed.
fn write_temporary(path: &Path, bytes: &[u8]) -> std::io::Result<PathBuf> {
    let tmp = temporary_beside(path);
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    })();
    match written {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, then a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = write_temporary(path, bytes)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

/// The solver's convergence as CSV (iteration, residual, seconds) and as log–log charts against
/// iterations and against time; returns (file name, bytes) pairs.
pub fn convergence_files(result: &RunResult) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let history = &result.solution.convergence;
    let mut csv = String::from("iteration,residual,seconds\n");
    for p in history {
        csv += &format!("{},{:.6e},{:.6}\n", p.iteration, p.residual, p.seconds);
    }
    let mut files = vec![("convergence.csv".to_owned(), csv.into_bytes())];
    let name = solver_name(result.options.solver.direct_only, result.options.method);
    let y_label = "residual, relative to the light put in".to_owned();
    let charts = [
        (
            "convergence-iterations",
            "iterations",
            history
                .iter()
                .map(|p| (p.iteration as f64, p.residual))
                .collect::<Vec<_>>(),
        ),
        (
            "convergence-time",
            "seconds",
            history.iter().map(|p| (p.seconds, p.residual)).collect(),
        ),
    ];
    for (stem, x_label, points) in charts {
        let chart = penumbra_viz::LogLogChart {
            title: format!("{}: {name} convergence", result.loaded.scene.name),
            x_label: x_label.to_owned(),
            y_label: y_label.clone(),
            series: vec![penumbra_viz::Series {
                name: name.to_owned(),
                points,
            }],
        };
        files.push((format!("{stem}.svg"), chart.svg()?.into_bytes()));
        files.push((format!("{stem}.png"), chart.png()?));
    }
    Ok(files)
}

/// Files written all or nothing, as far as the file system allows: each is staged as a
/// temporary beside its place, and only [`Staging::commit`] renames them into place. Dropped
/// before that (a later file failed), it removes its temporaries and the old files stay as they
/// were.
#[derive(Debug, Default)]
pub struct Staging {
    /// (temporary, place) of every file staged.
    staged: Vec<(PathBuf, PathBuf)>,
}

impl Staging {
    /// Writes `bytes` to a temporary file beside `path`, to be renamed into place by
    /// [`Staging::commit`]. If that fails (the file cannot be written, or a directory stands at
    /// `path`), the temporary is removed; what was staged before stays staged.
    pub fn stage(&mut self, path: PathBuf, bytes: &[u8]) -> anyhow::Result<()> {
        use anyhow::Context;
        // A directory in the file's place would fail its rename after others were done.
        if path.is_dir() {
            anyhow::bail!("cannot write {}: a directory is in the way", path.display());
        }
        let tmp = write_temporary(&path, bytes)
            .with_context(|| format!("cannot write {}", path.display()))?;
        self.staged.push((tmp, path));
        Ok(())
    }

    /// Renames every staged file into place; returns their places.
    pub fn commit(mut self) -> anyhow::Result<Vec<PathBuf>> {
        use anyhow::Context;
        let staged = std::mem::take(&mut self.staged);
        let mut places = Vec::with_capacity(staged.len());
        for (i, (tmp, path)) in staged.iter().enumerate() {
            if let Err(e) = std::fs::rename(tmp, path) {
                // What was not renamed yet is dropped with the rest.
                self.staged = staged[i..].to_vec();
                return Err(e).with_context(|| format!("cannot write {}", path.display()));
            }
            places.push(path.clone());
        }
        Ok(places)
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        for (tmp, _) in &self.staged {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// Writes a set of files all or nothing (see [`Staging`]).
pub fn write_all_atomic(files: &[(PathBuf, Vec<u8>)]) -> anyhow::Result<()> {
    let mut staging = Staging::default();
    for (path, bytes) in files {
        staging.stage(path.clone(), bytes)?;
    }
    staging.commit().map(|_| ())
}

/// Surface SVGs made at once, then written: a bound on the memory they hold (a scene may have
/// tens of thousands of surfaces).
const SVG_BATCH: usize = 256;

/// Writes every output of a run into `dir` (created if needed): `solution.json`, `report.json`,
/// `render.png`, the SVGs of the surfaces `svgs` chooses in `dir/surfaces` ([`SVG_DIR`],
/// named by [`svg_name`]), and `extra` files (name and bytes) beside them, all or nothing (see
/// [`Staging`]); returns the paths written.
pub fn write_outputs(
    result: &RunResult,
    dir: &Path,
    svgs: &SvgSelection,
    extra: Vec<(String, Vec<u8>)>,
) -> anyhow::Result<Vec<PathBuf>> {
    use anyhow::Context;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let surfaces = svgs.surfaces(result);
    let svg_dir = dir.join(SVG_DIR);
    if !surfaces.is_empty() {
        std::fs::create_dir_all(&svg_dir)
            .with_context(|| format!("cannot create {}", svg_dir.display()))?;
    }
    let mut staging = Staging::default();
    staging.stage(dir.join("solution.json"), solution_json(result).as_bytes())?;
    staging.stage(
        dir.join("report.json"),
        report_json(result, svgs).as_bytes(),
    )?;
    staging.stage(
        dir.join("render.png"),
        &penumbra_viz::encode_png(&result.render.image)?,
    )?;
    let scene = &result.loaded.scene;
    for batch in surfaces.chunks(SVG_BATCH) {
        let svgs: Vec<String> = batch
            .par_iter()
            .map(|&i| {
                penumbra_viz::surface_svg(
                    scene,
                    &result.mesh.surfaces[i],
                    Some(&result.solution.radiosity[i]),
                    &result.mesh.discontinuities[i],
                )
            })
            .collect();
        for (&i, svg) in batch.iter().zip(svgs) {
            let name = svg_name(i, &scene.surfaces[i].name);
            staging.stage(svg_dir.join(name), svg.as_bytes())?;
        }
    }
    for (name, bytes) in extra {
        staging.stage(dir.join(name), &bytes)?;
    }
    staging.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
        let mut all: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
            .expect("readable")
            .map(|e| {
                let e = e.expect("entry");
                let bytes = std::fs::read(e.path()).unwrap_or_default();
                (e.file_name().to_string_lossy().into_owned(), bytes)
            })
            .collect();
        all.sort();
        all
    }

    /// A set of files whose last one cannot be written (its directory is missing, or a directory
    /// stands in its place) changes nothing, and leaves no temporary behind.
    #[test]
    fn a_failed_write_leaves_the_old_files() {
        let dir = tempfile::tempdir().expect("temp dir");
        let d = dir.path();
        std::fs::write(d.join("a.json"), b"old a").expect("writes");
        std::fs::write(d.join("b.json"), b"old b").expect("writes");
        std::fs::create_dir(d.join("c.png")).expect("mkdir");
        let before = contents(d);
        for last in [d.join("missing").join("c.png"), d.join("c.png")] {
            let files = vec![
                (d.join("a.json"), b"new a".to_vec()),
                (d.join("b.json"), b"new b".to_vec()),
                (last, b"new c".to_vec()),
            ];
            assert!(write_all_atomic(&files).is_err());
            assert_eq!(contents(d), before);
        }
        let files = vec![
            (d.join("a.json"), b"new a".to_vec()),
            (d.join("b.json"), b"new b".to_vec()),
        ];
        write_all_atomic(&files).expect("writes");
        assert_eq!(std::fs::read(d.join("a.json")).expect("reads"), b"new a");
    }
}
