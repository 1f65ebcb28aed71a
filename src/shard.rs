//! Sharded runs: the direct light of one scene split over processes or machines by an existing
//! scheduler (a Slurm job array, GNU parallel), then joined.
//!
//! Shard `I` of `N` (`0 <= I < N`) lights the `I`-th of `N` runs of consecutive surfaces of
//! about equal estimated cost ([`Shard::surfaces`]):
//!
//! - a large scene (its polygons alone need more triangles than the fitted budget's floor;
//!   [`meshed_alone`]): the shard finds the discontinuities of its own surfaces and meshes them
//!   alone, the other surfaces get empty meshes. Meshed by discontinuities
//!   (`--mesh discontinuity`), each surface's share of the budget depends on nothing but the
//!   surface and the scene's polygons, so its mesh and values are those of the run not split,
//!   to the bit. Error-driven (the default), the shard refines its own surfaces from their
//!   least mesh with its part (by estimated cost) of the fit's extra triangles, spent where
//!   its own surfaces' measured error is largest (the run not split spends the same budget
//!   where the whole scene's is), against the same scene mean; one shard is the run not split,
//!   more give a mesh of their own;
//! - otherwise (a budget chosen with `--max-elements`, or a scene within the floor) the budget
//!   is spread over all surfaces, and each one's share depends on every surface (an
//!   error-driven mesh splits the worst triangles of the whole scene first), so every shard
//!   finds the discontinuities of the whole scene and meshes every surface, and splits only the
//!   direct light at the vertices it did not measure while meshing: the joined result is the
//!   run not split, to the bit;
//! - the direct light at a vertex is the same whichever other surfaces have a vertex at its
//!   point: the faces meeting there share one view of the light, taken from the point they round
//!   to ([`penumbra_solver::DirectLight::irradiance_group`]).
//!
//! Each shard writes [`SHARD_FILE`] (its surfaces' part of `solution.json`, its report and a
//! fingerprint of the scene and the options) and the SVGs of its surfaces; [`merge`] checks
//! that the shards belong to one run, that none is missing or twice, and joins them into one
//! `solution.json` (the run not split would have written the same bytes, but for error-driven
//! shards that meshed alone), with the report's figures of the discontinuities and the mesh
//! joined over the shards that meshed alone.
//!
//! A full solution cannot be split this way: light bounces between all surfaces, so every
//! surface's radiosity depends on every other's. Adaptive refinement spends one budget over the
//! whole scene against its mean radiosity, and a time budget would cut shards short at
//! different points; shards refuse both ([`ShardError`]).

use std::path::{Path, PathBuf};

use penumbra_meshing::{SceneMesh, SurfaceMesh, quality_of};
use penumbra_scenes::{LoadedScene, PlaneFrame, Rgb, Scene, SceneError, SurfaceId};
use serde::{Deserialize, Serialize};

use crate::energy::EnergyBalance;
use crate::error_mesh::MeshErrorReport;
use crate::export::{ExportFormat, ExportSource, export};
use crate::fingerprint::hex;
pub use crate::fingerprint::scene_fingerprint;
pub use crate::options::{Shard, ShardError, meshed_alone};
use crate::outputs::{
    DEFAULT_SVG_SURFACES, SVG_DIR, Staging, SurfaceSolution, SvgSelection, solution_json_of,
    surface_solution, svg_name, worth_looking_at,
};
use crate::report::{
    Report, ShardPart, ShardsSummary, estimated_direct_warning, mesh_error_warning,
};
use crate::run_result::{RunResult, StageTimes};

/// The file a shard writes into its output directory.
pub const SHARD_FILE: &str = "shard.json";
/// The format of [`SHARD_FILE`].
pub const SHARD_FORMAT: &str = "penumbra-shard/2";

/// How the scene was given, so that `merge` can load it again to render the joined solution.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneOrigin {
    /// The scene as given on the command line: a built-in name or a path.
    pub spec: String,
    /// OBJ files: whether coplanar faces were left unmerged.
    pub no_merge: bool,
    /// The camera `--camera` gave, which replaced the scene's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<penumbra_scenes::Camera>,
    /// The unit `--unit` gave, which replaced the scene's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<penumbra_scenes::LengthUnit>,
}

/// [`SHARD_FILE`]: what a shard hands to [`merge`].
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardFile {
    /// [`SHARD_FORMAT`]; [`read_shard`] refuses any other.
    pub format: String,
    /// Which shard wrote the file.
    pub shard: Shard,
    /// Of the scene and every option that changes an output: shards of one run share it.
    pub fingerprint: String,
    /// Of the scene alone.
    pub scene_fingerprint: String,
    /// How the scene was given, for the merge to load it again.
    pub scene: SceneOrigin,
    /// Surfaces in the scene.
    pub scene_surfaces: usize,
    /// The render's width in pixels, for the merge's render.
    pub render_width: u32,
    /// The render's height in pixels.
    pub render_height: u32,
    /// The loader's warnings.
    pub warnings: Vec<String>,
    /// Whether the shard found the discontinuities of its own surfaces and meshed them alone
    /// ([`meshed_alone`]); else it meshed the whole scene.
    #[serde(default)]
    pub meshed_alone: bool,
    /// The shard's `report.json`: the discontinuities, mesh and counts of the surfaces it meshed
    /// (its own, or the whole scene's), and the power its surfaces absorbed and received.
    pub report: Report,
    /// The SVGs written beside this file, relative to its directory.
    pub svgs: Vec<String>,
    /// This shard's surfaces, each with its `index` in the scene, in the scene's order.
    pub surfaces: Vec<SurfaceSolution>,
}

/// The fingerprint of a run: its scene, and the options `report.json` records (the thread
/// count aside, which changes no output, and what shards that mesh alone find for their own
/// surfaces: the budget resolved and the mesh `auto` chose), the render's size and the SVG
/// selection.
fn run_fingerprint(report: &Report, scene: &str, svgs: &SvgSelection) -> String {
    let mut method = serde_json::to_value(&report.method).unwrap_or_default();
    if let Some(m) = method.as_object_mut() {
        for found in ["threads", "max_elements", "mesh"] {
            m.remove(found);
        }
    }
    let render = (report.render.width, report.render.height);
    let key = serde_json::json!({
        "scene": scene,
        "method": method,
        "render": render,
        "svgs": format!("{svgs:?}"),
    });
    hex(key.to_string().as_bytes())
}

/// Writes a shard's outputs into `dir` (created if needed): [`SHARD_FILE`] and the SVGs of its
/// surfaces that `svgs` chooses (the selection is the whole run's), all or nothing. Returns the
/// paths written.
pub fn write_shard(
    result: &RunResult,
    shard: Shard,
    origin: SceneOrigin,
    dir: &Path,
    svgs: &SvgSelection,
) -> anyhow::Result<Vec<PathBuf>> {
    use anyhow::Context;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let scene = &result.loaded.scene;
    let report = Report::of_run(result, svgs);
    let on = result.surfaces_of(shard);
    let ours: Vec<SurfaceId> = svgs
        .surfaces(result)
        .into_iter()
        .filter(|&s| on[s])
        .collect();
    let svg_dir = dir.join(SVG_DIR);
    if !ours.is_empty() {
        std::fs::create_dir_all(&svg_dir)
            .with_context(|| format!("cannot create {}", svg_dir.display()))?;
    }
    let mut staging = Staging::default();
    let mut written = Vec::new();
    for &s in &ours {
        let svg = penumbra_viz::surface_svg(
            scene,
            &result.mesh.surfaces[s],
            Some(&result.solution.radiosity[s]),
            &result.mesh.discontinuities[s],
        );
        let name = svg_name(s, &scene.surfaces[s].name);
        staging.stage(svg_dir.join(&name), svg.as_bytes())?;
        written.push(format!("{SVG_DIR}/{name}"));
    }
    let scene_print = scene_fingerprint(&result.loaded);
    let file = ShardFile {
        format: SHARD_FORMAT.to_owned(),
        shard,
        fingerprint: run_fingerprint(&report, &scene_print, svgs),
        scene_fingerprint: scene_print,
        scene: origin,
        scene_surfaces: scene.surfaces.len(),
        render_width: result.render.image.width(),
        render_height: result.render.image.height(),
        warnings: result.loaded.warnings.clone(),
        meshed_alone: meshed_alone(scene, &result.options),
        report,
        svgs: written,
        surfaces: (0..scene.surfaces.len())
            .filter(|&s| on[s])
            .map(|s| SurfaceSolution {
                index: Some(s),
                ..surface_solution(result, s)
            })
            .collect(),
    };
    let mut json = serde_json::to_string(&file)?;
    json.push('\n');
    staging.stage(dir.join(SHARD_FILE), json.as_bytes())?;
    staging.commit()
}

/// Why shards cannot be joined.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MergeError {
    /// No shard directory was given.
    #[error("no shard directories given")]
    Nothing,
    /// A shard file could not be read.
    #[error("cannot read {}: {source} (is it the output directory of a sharded run?)", .path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why it could not be read.
        source: std::io::Error,
    },
    /// A file is not a shard file of this format: not its JSON, another format, or a shard
    /// number out of range.
    #[error("{} is not a shard file: {message}", .path.display())]
    NotAShard {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// Two shards are of different runs: their scenes, options or shard counts differ.
    #[error("{} is not from the same run as {}: {what} differ", .dir.display(), .first.display())]
    Mixed {
        /// The first shard's directory.
        first: PathBuf,
        /// The directory of the shard that differs from it.
        dir: PathBuf,
        /// What differs, in words (`"their options"`).
        what: &'static str,
    },
    /// A shard is given twice.
    #[error("shard {shard} is given twice: {} and {}", .first.display(), .second.display())]
    Duplicate {
        /// The shard.
        shard: Shard,
        /// One directory that holds it.
        first: PathBuf,
        /// Another.
        second: PathBuf,
    },
    /// Shards of the run are missing.
    #[error("missing {} {} of {count}", if .missing.len() == 1 { "shard" } else { "shards" }, list(.missing))]
    Missing {
        /// Their indices.
        missing: Vec<usize>,
        /// The count of shards of the run.
        count: usize,
    },
    /// No shard holds this surface of the scene.
    #[error("surface {index} is in none of the shards")]
    Uncovered {
        /// The surface's index in the scene.
        index: usize,
    },
    /// A shard file holds a surface that another shard holds too, or that is not in the scene.
    #[error("{}: surface {index} ({name:?}) is another shard's too, or not the scene's", .path.display())]
    StraySurface {
        /// The shard file.
        path: PathBuf,
        /// The surface's index as the file gives it (`usize::MAX` when it gives none).
        index: usize,
        /// The surface's name.
        name: String,
    },
    /// A shard was cut short.
    #[error(
        "{} was cut short (interrupted: its discontinuity search skipped pairs), so its mesh is \
         not the run's; run that shard again",
        .dir.display()
    )]
    Partial {
        /// The shard's directory.
        dir: PathBuf,
    },
    /// The scene the shards were run on could not be loaded again.
    #[error("cannot load the scene to render the joined solution: {0}")]
    Scene(#[source] SceneError),
    /// The scene loaded is not the one the shards were run on (its fingerprint differs).
    #[error(
        "the scene loaded from {spec:?} is not the one the shards were run on (it has changed, \
         or names another file from here)"
    )]
    SceneChanged {
        /// The scene as given on the command line.
        spec: String,
    },
    /// The joined solution could not be rendered.
    #[error(transparent)]
    Render(#[from] penumbra_viz::VizError),
}

fn list(indices: &[usize]) -> String {
    let shown: Vec<String> = indices.iter().take(20).map(usize::to_string).collect();
    match indices.len().saturating_sub(shown.len()) {
        0 => shown.join(", "),
        more => format!("{} and {more} more", shown.join(", ")),
    }
}

impl MergeError {
    /// Whether the error is the user's to fix (wrong or missing directories, mixed runs) rather
    /// than a failure of the merge.
    pub fn is_usage(&self) -> bool {
        !matches!(self, MergeError::Render(_))
    }
}

/// Reads the [`SHARD_FILE`] of a shard's output directory.
pub fn read_shard(dir: &Path) -> Result<ShardFile, MergeError> {
    let path = dir.join(SHARD_FILE);
    let text = std::fs::read_to_string(&path).map_err(|source| MergeError::Read {
        path: path.clone(),
        source,
    })?;
    let file: ShardFile = serde_json::from_str(&text).map_err(|e| MergeError::NotAShard {
        path: path.clone(),
        message: e.to_string(),
    })?;
    if file.format != SHARD_FORMAT {
        return Err(MergeError::NotAShard {
            path,
            message: format!("its format is {:?}, not {SHARD_FORMAT:?}", file.format),
        });
    }
    if let Err(e) = Shard::new(file.shard.index, file.shard.count) {
        return Err(MergeError::NotAShard {
            path,
            message: e.to_string(),
        });
    }
    Ok(file)
}

/// Checks that the shards are of one run, each once, none missing; returns them in shard order.
pub fn check_shards(
    mut shards: Vec<(PathBuf, ShardFile)>,
) -> Result<Vec<(PathBuf, ShardFile)>, MergeError> {
    let Some((first_dir, first)) = shards.first() else {
        return Err(MergeError::Nothing);
    };
    for (dir, file) in &shards[1..] {
        let mixed = |what| MergeError::Mixed {
            first: first_dir.clone(),
            dir: dir.clone(),
            what,
        };
        if file.scene_fingerprint != first.scene_fingerprint {
            return Err(mixed("their scenes"));
        }
        if file.fingerprint != first.fingerprint {
            return Err(mixed("their options"));
        }
        if file.shard.count != first.shard.count {
            return Err(mixed("their shard counts"));
        }
    }
    let count = first.shard.count;
    shards.sort_by_key(|(_, f)| f.shard.index);
    for pair in shards.windows(2) {
        if pair[0].1.shard.index == pair[1].1.shard.index {
            return Err(MergeError::Duplicate {
                shard: pair[0].1.shard,
                first: pair[0].0.clone(),
                second: pair[1].0.clone(),
            });
        }
    }
    let missing: Vec<usize> = (0..count)
        .filter(|&i| {
            shards
                .binary_search_by_key(&i, |(_, f)| f.shard.index)
                .is_err()
        })
        .collect();
    if !missing.is_empty() {
        return Err(MergeError::Missing { missing, count });
    }
    // Each surface in one shard only.
    let mut claimed = vec![false; shards[0].1.scene_surfaces];
    for (dir, file) in &shards {
        if file.report.partial {
            return Err(MergeError::Partial { dir: dir.clone() });
        }
        let mut claim = |i: usize| {
            claimed
                .get_mut(i)
                .is_some_and(|c| !std::mem::replace(c, true))
        };
        if let Some(s) = file
            .surfaces
            .iter()
            .find(|s| s.index.is_none_or(|i| !claim(i)))
        {
            return Err(MergeError::StraySurface {
                path: dir.join(SHARD_FILE),
                index: s.index.unwrap_or(usize::MAX),
                name: s.name.clone(),
            });
        }
    }
    Ok(shards)
}

/// Shards joined: the files of the run they were split from.
#[derive(Debug)]
pub struct Merged {
    /// The scene's name.
    pub scene_name: String,
    /// Shards joined.
    pub shards: usize,
    /// Surfaces of the scene.
    pub surfaces: usize,
    /// Triangles of the joined mesh, over all surfaces.
    pub triangles: usize,
    /// Vertices of the joined mesh, over all surfaces.
    pub vertices: usize,
    /// `solution.json`, as the run not split would have written it.
    pub solution_json: String,
    /// `report.json`: the first shard's, with the light's figures joined over the shards, the
    /// mesh's summed where the shards meshed alone, and a `shards` section.
    pub report_json: String,
    /// `render.png` of the joined solution, encoded.
    pub render_png: Vec<u8>,
    /// Each SVG: where a shard wrote it, and its place relative to the output directory.
    pub svgs: Vec<(PathBuf, String)>,
}

/// What the shards' light adds up to: patches lie within one surface, so what is left
/// unshot, its magnitude and the ambient term made from it (linear in it, when every shard has
/// the whole mesh's area and mean reflectance) add up over the shards, to rounding.
#[derive(Default)]
struct LightSums {
    absorbed: Rgb,
    received: Rgb,
    unshot: Rgb,
    ambient: Rgb,
    residual: f64,
    times: StageTimes,
    /// Vertices lit, and of those estimated by rays (and for being beyond the overlay's cap).
    receivers: usize,
    estimated: usize,
    beyond_cap: usize,
}

impl LightSums {
    /// Adds a shard's figures; `emitted` is the scene's, every shard's.
    fn add(&mut self, report: &Report, emitted: Rgb) {
        let solver = &report.solver;
        self.absorbed += solver.absorbed;
        self.received += emitted - solver.escaped;
        self.unshot += solver.unshot;
        self.ambient += report.render.ambient;
        self.residual += solver.residual;
        self.times += &report.times_seconds;
        self.receivers += solver.receivers;
        self.estimated += solver.direct_estimated;
        self.beyond_cap += solver.direct_beyond_cap;
    }
}

/// The shards' parts joined: the surfaces in the scene's order, the SVGs and each shard's
/// figures.
struct Parts {
    surfaces: Vec<SurfaceSolution>,
    svgs: Vec<(PathBuf, String)>,
    parts: Vec<ShardPart>,
    light: LightSums,
}

/// Joins the shards' surfaces, SVGs and light; every surface of the scene must be in one.
fn join_parts(
    shards: Vec<(PathBuf, ShardFile)>,
    surfaces: usize,
    emitted: Rgb,
) -> Result<Parts, MergeError> {
    let mut joined: Vec<Option<SurfaceSolution>> = vec![None; surfaces];
    let (mut svgs, mut parts, mut light) = (Vec::new(), Vec::new(), LightSums::default());
    for (dir, file) in shards {
        light.add(&file.report, emitted);
        parts.push(ShardPart {
            shard: file.shard.to_string(),
            directory: dir.display().to_string(),
            surfaces: file.surfaces.len(),
            vertices_lit: file.surfaces.iter().map(|s| s.vertices.len()).sum(),
            threads: file.report.method.threads,
            times_seconds: file.report.times_seconds.clone(),
            peak_bytes: file.report.memory.peak_bytes.clone(),
        });
        svgs.extend(file.svgs.into_iter().map(|svg| (dir.join(&svg), svg)));
        for s in file.surfaces {
            if let Some(slot) = s.index.and_then(|i| joined.get_mut(i)) {
                *slot = Some(SurfaceSolution { index: None, ..s });
            }
        }
    }
    let surfaces = joined
        .into_iter()
        .enumerate()
        .map(|(i, s)| s.ok_or(MergeError::Uncovered { index: i }))
        .collect::<Result<_, _>>()?;
    svgs.sort_by(|a, b| a.1.cmp(&b.1));
    Ok(Parts {
        surfaces,
        svgs,
        parts,
        light,
    })
}

/// Joins checked shards ([`check_shards`]). `loaded` is the scene they were run on (checked
/// against their fingerprint), needed to render the joined solution.
pub fn merge(
    shards: Vec<(PathBuf, ShardFile)>,
    loaded: &LoadedScene,
) -> Result<Merged, MergeError> {
    let started = std::time::Instant::now();
    let Some((_, first)) = shards.first() else {
        return Err(MergeError::Nothing);
    };
    if scene_fingerprint(loaded) != first.scene_fingerprint {
        return Err(MergeError::SceneChanged {
            spec: first.scene.spec.clone(),
        });
    }
    let mut report = first.report.clone();
    let meshed_alone = first.meshed_alone;
    let mut warnings = first.warnings.clone();
    if meshed_alone {
        let reports: Vec<&Report> = shards.iter().map(|(_, f)| &f.report).collect();
        sum_mesh_figures(&mut report, &reports);
        join_mesh_errors(&mut report, &mut warnings, &reports, &loaded.scene);
    }
    let (width, height) = (first.render_width, first.render_height);
    let count = first.shard.count;
    let scene = &loaded.scene;
    let emitted = report.solver.emitted;
    let mut parts = join_parts(shards, scene.surfaces.len(), emitted)?;
    if meshed_alone {
        // Shards that meshed alone each knew only their own surfaces' area and reflectance.
        parts.light.ambient = ambient_of(scene, parts.light.unshot);
        if report.svgs.selection == "auto" {
            keep_svgs_worth_looking_at(scene, &mut parts);
        }
    }

    let render_started = std::time::Instant::now();
    let mesh = joined_mesh(loaded, &parts.surfaces)?;
    let render = render_joined(scene, &mesh, &parts, width, height)?;
    let render_png = penumbra_viz::encode_png(&render.image)?;
    parts.light.times.render = render_started.elapsed().as_secs_f64();

    report.partial = false;
    // The first shard's command line would replay that shard alone.
    report.invocation = None;
    if meshed_alone {
        report.mesh_quality = quality_of(&mesh.surfaces);
    }
    let first_estimate = estimated_direct_warning(&report.solver);
    let solver = &mut report.solver;
    (solver.direct_estimated, solver.direct_beyond_cap) =
        (parts.light.estimated, parts.light.beyond_cap);
    if meshed_alone {
        // Each shard lit only its own surfaces' vertices.
        solver.receivers = parts.light.receivers;
    }
    let joined_estimate = estimated_direct_warning(&report.solver);
    replace_warning(&mut warnings, first_estimate.as_deref(), joined_estimate);
    join_light(&mut report, &parts, warnings, render.exposure);
    report.svgs.written = parts.svgs.iter().map(|(_, name)| name.clone()).collect();
    report.times_seconds = parts.light.times.clone();
    report.times_seconds.merge = Some(started.elapsed().as_secs_f64());
    report.shards = Some(ShardsSummary {
        count,
        parts: std::mem::take(&mut parts.parts),
    });
    Ok(Merged {
        scene_name: scene.name.clone(),
        shards: count,
        surfaces: parts.surfaces.len(),
        triangles: parts.surfaces.iter().map(|s| s.triangles.len()).sum(),
        vertices: parts.surfaces.iter().map(|s| s.vertices.len()).sum(),
        solution_json: solution_json_of(&scene.name, &parts.surfaces),
        report_json: report.to_json(),
        render_png,
        svgs: parts.svgs,
    })
}

/// Shards that meshed alone each chose SVGs among their own surfaces (each knows no other's
/// discontinuities): the run's choice is among theirs.
fn keep_svgs_worth_looking_at(scene: &Scene, parts: &mut Parts) {
    let segments: Vec<usize> = parts
        .surfaces
        .iter()
        .map(|s| s.discontinuities.len())
        .collect();
    let chosen: std::collections::HashSet<String> =
        worth_looking_at(scene, &segments, DEFAULT_SVG_SURFACES)
            .into_iter()
            .map(|s| format!("{SVG_DIR}/{}", svg_name(s, &scene.surfaces[s].name)))
            .collect();
    parts.svgs.retain(|(_, name)| chosen.contains(name));
}

/// The render of the joined meshes (their 3D vertices and triangles).
fn render_joined(
    scene: &Scene,
    mesh: &SceneMesh,
    parts: &Parts,
    width: u32,
    height: u32,
) -> Result<penumbra_viz::Render, MergeError> {
    let display: Vec<Vec<Rgb>> = parts
        .surfaces
        .iter()
        .zip(&scene.surfaces)
        .map(|(s, surface)| {
            s.radiosity
                .iter()
                .map(|&c| {
                    penumbra_solver::displayed(
                        Rgb::from(c),
                        surface.reflectance,
                        parts.light.ambient,
                    )
                })
                .collect()
        })
        .collect();
    let options = penumbra_viz::RenderOptions {
        width,
        height,
        ..Default::default()
    };
    Ok(penumbra_viz::render(scene, mesh, &display, &options)?)
}

/// The light's figures joined over the shards into the first shard's `report` (its scene,
/// options, discontinuities, mesh and counts are every shard's), with the warnings they call
/// for.
fn join_light(report: &mut Report, parts: &Parts, warnings: Vec<String>, exposure: f64) {
    let light = &parts.light;
    let emitted = report.solver.emitted;
    let escaped = emitted - light.received;
    let energy = EnergyBalance::new(emitted, light.absorbed, escaped, light.unshot, None);
    report.warnings = warnings;
    report.warnings.extend(energy.warning());
    // The joined meshes' quality, or the first shard's whole-scene mesh's.
    report.warnings.extend(crate::outputs::quality_warning(
        report.mesh_quality.triangles_below_min_angle,
        report.mesh_quality.triangles,
        false,
    ));
    report.energy = energy;
    let solver = &mut report.solver;
    solver.absorbed = light.absorbed;
    solver.escaped = escaped;
    solver.unshot = light.unshot;
    solver.unshot_fraction = light.residual;
    solver.residual = light.residual;
    solver.direct_seconds = light.times.direct;
    report.render.exposure = exposure;
    report.render.ambient = light.ambient;
}

/// The figures of shards that each meshed their own surfaces, joined into `report`: the
/// discontinuity search's, the mesh's counts and the budget resolved, summed (the largest of
/// those named `..._max`).
fn sum_mesh_figures(report: &mut Report, shards: &[&Report]) {
    report.method.max_elements = shards.iter().map(|r| r.method.max_elements).sum();
    let counts = &mut report.counts;
    counts.triangles = shards.iter().map(|r| r.counts.triangles).sum();
    counts.vertices = shards.iter().map(|r| r.counts.vertices).sum();
    counts.patches = shards.iter().map(|r| r.counts.patches).sum();
    counts.discontinuity_segments = shards.iter().map(|r| r.counts.discontinuity_segments).sum();
    let found: Vec<serde_json::Value> = shards
        .iter()
        .filter_map(|r| r.discontinuities.as_ref())
        .filter_map(|d| serde_json::to_value(d).ok())
        .collect();
    if let Some(mut sum) = report
        .discontinuities
        .as_ref()
        .and_then(|d| serde_json::to_value(d).ok())
    {
        sum_numbers(&mut sum, &found);
        report.discontinuities = serde_json::from_value(sum).ok();
    }
}

/// The error-driven refinement of shards that each refined their own surfaces, joined into
/// `report`, and the warning of surfaces left above the tolerance made again from all of them.
fn join_mesh_errors(
    report: &mut Report,
    warnings: &mut Vec<String>,
    shards: &[&Report],
    scene: &Scene,
) {
    let parts: Vec<&MeshErrorReport> = shards
        .iter()
        .filter_map(|r| r.mesh_error.as_ref())
        .collect();
    let area = (scene.surfaces.iter())
        .filter(|s| s.reflectance.mean() > 0.0)
        .map(|s| s.area())
        .sum();
    let Some(joined) = MeshErrorReport::join(&parts, area) else {
        return;
    };
    let first = report.mesh_error.as_ref().and_then(mesh_error_warning);
    replace_warning(warnings, first.as_deref(), mesh_error_warning(&joined));
    report.mesh_error = Some(joined);
}

/// The first shard's warning `first` (if it gave one) replaced by the joined shards' `joined`.
fn replace_warning(warnings: &mut Vec<String>, first: Option<&str>, joined: Option<String>) {
    warnings.retain(|w| Some(w.as_str()) != first);
    warnings.extend(joined);
}

/// Each number field of the object `sum` made the sum of that field over `all` (the largest
/// for fields named `..._max`): counts stay integers.
fn sum_numbers(sum: &mut serde_json::Value, all: &[serde_json::Value]) {
    let Some(fields) = sum.as_object_mut() else {
        return;
    };
    for (key, slot) in fields.iter_mut().filter(|(_, v)| v.is_number()) {
        let values: Vec<&serde_json::Value> = all.iter().filter_map(|r| r.get(key)).collect();
        let floats = values.iter().filter_map(|v| v.as_f64());
        *slot = if key.ends_with("_max") {
            floats.fold(f64::NEG_INFINITY, f64::max).into()
        } else if values.iter().all(|v| v.is_u64()) {
            values.iter().filter_map(|v| v.as_u64()).sum::<u64>().into()
        } else {
            floats.sum::<f64>().into()
        };
    }
}

/// The ambient term of a solution that left `unshot` power unshot, over the scene's polygons
/// (which the solver's elements cover).
fn ambient_of(scene: &Scene, unshot: Rgb) -> Rgb {
    let area: f64 = scene.surfaces.iter().map(|s| s.area()).sum();
    let mean_reflectance = scene
        .surfaces
        .iter()
        .map(|s| s.reflectance * s.area())
        .sum::<Rgb>()
        / area;
    penumbra_solver::ambient_term(unshot, area, mean_reflectance)
}

/// Meshes to render, from the joined surfaces' 3D vertices and triangles (in each surface's
/// plane frame; the render uses the 3D positions).
fn joined_mesh(
    loaded: &LoadedScene,
    surfaces: &[SurfaceSolution],
) -> Result<SceneMesh, MergeError> {
    let scene = &loaded.scene;
    let meshes = surfaces
        .iter()
        .zip(&scene.surfaces)
        .enumerate()
        .map(|(id, (s, surface))| {
            // A loaded scene is validated: every polygon has a frame.
            let frame = PlaneFrame::of_polygon(&surface.polygon).ok_or_else(|| {
                MergeError::SceneChanged {
                    spec: loaded.source.clone(),
                }
            })?;
            let points3: Vec<glam::DVec3> =
                s.vertices.iter().map(|&p| glam::DVec3::from(p)).collect();
            Ok(SurfaceMesh {
                surface: id,
                frame,
                scale: 1.0,
                local: points3.iter().map(|&p| frame.to_2d(p)).collect(),
                points3,
                triangles: s.triangles.clone(),
                boundary: Vec::new(),
                constraints: Vec::new(),
                polygon_area: surface.area(),
            })
        })
        .collect::<Result<Vec<_>, MergeError>>()?;
    let n = meshes.len();
    Ok(SceneMesh {
        surfaces: meshes,
        refinable: Vec::new(),
        discontinuities: vec![Vec::new(); n],
        hovering: vec![Vec::new(); n],
        discontinuity_stats: None,
        budget: 0,
        minimum_triangles: 0,
        measured_direct: Vec::new(),
    })
}

/// Writes the joined run into `dir` (created if needed), all or nothing; returns the paths
/// written.
pub fn write_merged(merged: &Merged, dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    use anyhow::Context;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    if !merged.svgs.is_empty() {
        let svg_dir = dir.join(SVG_DIR);
        std::fs::create_dir_all(&svg_dir)
            .with_context(|| format!("cannot create {}", svg_dir.display()))?;
    }
    let mut staging = Staging::default();
    staging.stage(dir.join("solution.json"), merged.solution_json.as_bytes())?;
    staging.stage(dir.join("report.json"), merged.report_json.as_bytes())?;
    staging.stage(dir.join("render.png"), &merged.render_png)?;
    // The viewer page goes with the render, as in a run not split.
    let source = ExportSource::parse(&merged.solution_json, &merged.report_json, dir)?;
    for (name, bytes) in export(&source, &[ExportFormat::Html])? {
        staging.stage(dir.join(name), &bytes)?;
    }
    for (from, name) in &merged.svgs {
        let bytes =
            std::fs::read(from).with_context(|| format!("cannot read {}", from.display()))?;
        staging.stage(dir.join(name), &bytes)?;
    }
    staging.commit()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::RunOptions;

    /// A mesh with a triangle of no area has an infinite largest aspect ratio, which JSON
    /// writes `null`: a shard's report holding one reads back (Sponza's and Crytek's do).
    #[test]
    fn an_infinite_aspect_ratio_reads_back() {
        let quality = penumbra_meshing::MeshQuality {
            aspect_ratio_max: f64::INFINITY,
            ..Default::default()
        };
        let text = serde_json::to_string(&quality).expect("writes");
        assert!(text.contains("\"aspect_ratio_max\":null"), "{text}");
        let back: penumbra_meshing::MeshQuality = serde_json::from_str(&text).expect("reads");
        assert_eq!(back.aspect_ratio_max, f64::INFINITY);
    }

    #[test]
    fn shards_are_parsed_and_checked() {
        assert_eq!(Shard::parse("0/1"), Ok(Shard { index: 0, count: 1 }));
        assert_eq!(Shard::parse(" 7/8 "), Ok(Shard { index: 7, count: 8 }));
        assert_eq!(
            Shard::parse("8/8"),
            Err(ShardError::OutOfRange { index: 8, count: 8 })
        );
        assert_eq!(Shard::parse("0/0"), Err(ShardError::NoShards));
        for bad in ["", "1", "1/", "/2", "-1/2", "a/b", "1/2/3", "1.0/2"] {
            assert_eq!(Shard::parse(bad), Err(ShardError::Syntax(bad.to_owned())));
        }
        let s = Shard::new(1, 3).expect("valid");
        assert_eq!(s.to_string(), "1/3");
    }

    #[test]
    fn only_direct_light_is_split() {
        let shard = Shard::new(0, 2).expect("valid");
        let mut options = RunOptions::default();
        assert_eq!(shard.check(&options), Err(ShardError::NeedsDirectOnly));
        options.solver.direct_only = true;
        assert_eq!(shard.check(&options), Ok(()));
        options.time_budget = Some(10.0);
        assert_eq!(shard.check(&options), Err(ShardError::TimeBudget));
    }
}
