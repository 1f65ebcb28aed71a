//! Sharded runs: the direct light of one scene split over processes or machines by an existing
//! scheduler (a Slurm job array, GNU parallel), then joined.
//!
//! Shard `I` of `N` (`0 <= I < N`) lights the surfaces whose index in the scene is `I` modulo
//! `N`, so that each surface's mesh and values are those of the run not split, to the bit:
//!
//! - a large scene (its polygons alone need more triangles than the fitted budget's floor;
//!   [`meshed_alone`]) meshed by discontinuities (`--mesh discontinuity`): the shard finds the discontinuities of its own surfaces and meshes them
//!   alone, since each surface's share of the budget depends on nothing but the surface and the
//!   scene's polygons; the other surfaces get empty meshes;
//! - otherwise (an error-driven mesh, the default, a budget chosen with `--max-elements`, or a
//!   scene within the floor) the budget is spread over all surfaces, and each one's share depends
//!   on every surface (an error-driven mesh splits the worst triangles of the whole scene first),
//!   so every shard finds the discontinuities of the whole scene and meshes every surface, and
//!   splits only the direct light at the vertices it did not measure while meshing;
//! - the direct light at a vertex is the same whichever other surfaces have a vertex at its
//!   point: the faces meeting there share one view of the light, taken from the point they round
//!   to ([`penumbra_solver::DirectLight::irradiance_group`]).
//!
//! Each shard writes [`SHARD_FILE`] (its surfaces' part of `solution.json`, its report and a
//! fingerprint of the scene and the options) and the SVGs of its surfaces; [`merge`] checks
//! that the shards belong to one run, that none is missing or twice, and joins them into the
//! `solution.json` the run would have written, byte for byte, with the report's figures of the
//! discontinuities and the mesh summed over the shards that meshed alone.
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
use crate::export::{ExportFormat, ExportSource, export};
use crate::fingerprint::hex;
pub use crate::fingerprint::scene_fingerprint;
pub use crate::options::{Shard, ShardError, meshed_alone};
use crate::outputs::{
    DEFAULT_SVG_SURFACES, SVG_DIR, Staging, SurfaceSolution, SvgSelection, report_json,
    solution_json_of, surface_solution, svg_name, worth_looking_at,
};
use crate::pipeline::RunResult;

/// The file a shard writes into its output directory.
pub const SHARD_FILE: &str = "shard.json";
/// The format of [`SHARD_FILE`].
pub const SHARD_FORMAT: &str = "penumbra-shard/1";

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
    pub report: serde_json::Value,
    /// The SVGs written beside this file, relative to its directory.
    pub svgs: Vec<String>,
    /// This shard's surfaces, each with its `index` in the scene, in the scene's order.
    pub surfaces: Vec<SurfaceSolution>,
}

/// The fingerprint of a run: its scene, and the options `report.json` records (the thread
/// count aside, which changes no output, and what shards that mesh alone find for their own
/// surfaces: the budget resolved and the mesh `auto` chose), the render's size and the SVG
/// selection.
fn run_fingerprint(report: &serde_json::Value, scene: &str, svgs: &SvgSelection) -> String {
    let mut method = report.get("method").cloned().unwrap_or_default();
    if let Some(m) = method.as_object_mut() {
        for found in ["threads", "max_elements", "mesh"] {
            m.remove(found);
        }
    }
    let render = report
        .get("render")
        .map(|r| (r.get("width"), r.get("height")));
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
    let report: serde_json::Value = serde_json::from_str(&report_json(result, svgs))?;
    let ours: Vec<SurfaceId> = svgs
        .surfaces(result)
        .into_iter()
        .filter(|&s| shard.contains(s))
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
            .filter(|&s| shard.contains(s))
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
    /// A shard file holds a surface that is not its shard's, or not in the scene.
    #[error("{}: surface {index} ({name:?}) is not this shard's, or not the scene's", .path.display())]
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
    for (dir, file) in &shards {
        if file.report.get("partial") == Some(&serde_json::Value::Bool(true)) {
            return Err(MergeError::Partial { dir: dir.clone() });
        }
        if let Some(s) = file.surfaces.iter().find(|s| {
            s.index
                .is_none_or(|i| i >= file.scene_surfaces || !file.shard.contains(i))
        }) {
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
    if first.meshed_alone {
        let reports: Vec<&serde_json::Value> = shards.iter().map(|(_, f)| &f.report).collect();
        sum_mesh_figures(&mut report, &reports);
    }
    let (width, height) = (first.render_width, first.render_height);
    let first_meshed_alone = first.meshed_alone;
    let warnings = first.warnings.clone();
    let count = first.shard.count;
    let scene = &loaded.scene;

    // Solutions in the scene's order; report figures summed.
    let mut surfaces: Vec<Option<SurfaceSolution>> = vec![None; scene.surfaces.len()];
    let mut svgs = Vec::new();
    let mut parts = Vec::new();
    // Patches lie within one surface, so what is left unshot, its magnitude and the ambient
    // term made from it (linear in it, when every shard has the whole mesh's area and mean
    // reflectance) add up over the shards, to rounding.
    let mut absorbed = Rgb::ZERO;
    let mut received = Rgb::ZERO;
    let mut unshot = Rgb::ZERO;
    let mut ambient = Rgb::ZERO;
    let mut residual = 0.0;
    let mut times = serde_json::Map::new();
    let emitted = rgb_at(&report, &["solver", "emitted"]);
    for (dir, file) in shards {
        absorbed += rgb_at(&file.report, &["solver", "absorbed"]);
        received += emitted - rgb_at(&file.report, &["solver", "escaped"]);
        unshot += rgb_at(&file.report, &["solver", "unshot"]);
        ambient += rgb_at(&file.report, &["render", "ambient"]);
        residual += file
            .report
            .pointer("/solver/residual")
            .and_then(serde_json::Value::as_f64)
            .unwrap_or(0.0);
        if let Some(t) = file.report.get("times_seconds").and_then(|t| t.as_object()) {
            for (stage, seconds) in t {
                let sum = times.get(stage).and_then(serde_json::Value::as_f64);
                let add = seconds.as_f64().unwrap_or(0.0);
                times.insert(stage.clone(), (sum.unwrap_or(0.0) + add).into());
            }
        }
        let vertices: usize = file.surfaces.iter().map(|s| s.vertices.len()).sum();
        parts.push(serde_json::json!({
            "shard": file.shard.to_string(),
            "directory": dir.display().to_string(),
            "surfaces": file.surfaces.len(),
            "vertices_lit": vertices,
            "threads": file.report.pointer("/method/threads"),
            "times_seconds": file.report.get("times_seconds"),
            "peak_bytes": file.report.pointer("/memory/peak_bytes"),
        }));
        for svg in file.svgs {
            svgs.push((dir.join(&svg), svg));
        }
        for s in file.surfaces {
            if let Some(i) = s.index
                && let Some(slot) = surfaces.get_mut(i)
            {
                *slot = Some(SurfaceSolution { index: None, ..s });
            }
        }
    }
    if first_meshed_alone {
        // Shards that meshed alone each knew only their own surfaces' area and reflectance.
        ambient = ambient_of(scene, unshot);
    }
    let surfaces: Vec<SurfaceSolution> = surfaces
        .into_iter()
        .enumerate()
        .map(|(i, s)| {
            s.ok_or_else(|| MergeError::Missing {
                missing: vec![i % count],
                count,
            })
        })
        .collect::<Result<_, _>>()?;
    svgs.sort_by(|a, b| a.1.cmp(&b.1));
    let auto = report
        .pointer("/svgs/selection")
        .and_then(serde_json::Value::as_str)
        == Some("auto");
    if first_meshed_alone && auto {
        // Each shard chose among its own surfaces (it knows no other's discontinuities); the
        // run's choice is among the shards' choices.
        let segments: Vec<usize> = surfaces.iter().map(|s| s.discontinuities.len()).collect();
        let chosen: std::collections::HashSet<String> =
            worth_looking_at(scene, &segments, DEFAULT_SVG_SURFACES)
                .into_iter()
                .map(|s| format!("{SVG_DIR}/{}", svg_name(s, &scene.surfaces[s].name)))
                .collect();
        svgs.retain(|(_, name)| chosen.contains(name));
    }

    // The render, from the joined meshes (their 3D vertices and triangles).
    let render_started = std::time::Instant::now();
    let mesh = joined_mesh(loaded, &surfaces)?;
    let display: Vec<Vec<Rgb>> = surfaces
        .iter()
        .zip(&scene.surfaces)
        .map(|(s, surface)| {
            s.radiosity
                .iter()
                .map(|&c| penumbra_solver::displayed(Rgb::from(c), surface.reflectance, ambient))
                .collect()
        })
        .collect();
    let render = penumbra_viz::render(
        scene,
        &mesh,
        &display,
        &penumbra_viz::RenderOptions {
            width,
            height,
            ..Default::default()
        },
    )?;
    let render_png = penumbra_viz::encode_png(&render.image)?;
    times.insert(
        "render".to_owned(),
        render_started.elapsed().as_secs_f64().into(),
    );

    // The report: the first shard's (its scene, options, discontinuities, mesh and counts are
    // every shard's), with the light's figures joined.
    let solver_absorbed = serde_json::to_value(absorbed).unwrap_or_default();
    let escaped = emitted - received;
    let energy = EnergyBalance::new(emitted, absorbed, escaped, unshot, None);
    let mut all_warnings = warnings;
    all_warnings.extend(energy.warning());
    let triangles = surfaces.iter().map(|s| s.triangles.len()).sum();
    let vertices = surfaces.iter().map(|s| s.vertices.len()).sum();
    if let Some(r) = report.as_object_mut() {
        r.insert("partial".to_owned(), false.into());
        // The first shard's command line would replay that shard alone.
        r.remove("invocation");
        if first_meshed_alone {
            let quality = quality_of(&mesh.surfaces);
            r.insert(
                "mesh_quality".to_owned(),
                serde_json::to_value(quality).unwrap_or_default(),
            );
        }
        // The joined meshes' quality, or the first shard's whole-scene mesh's.
        let quality_count = |key: &str| {
            r.get("mesh_quality")
                .and_then(|q| q.get(key))
                .and_then(serde_json::Value::as_u64)
                .unwrap_or(0) as usize
        };
        all_warnings.extend(crate::outputs::quality_warning(
            quality_count("triangles_below_min_angle"),
            quality_count("triangles"),
            false,
        ));
        r.insert("warnings".to_owned(), all_warnings.into());
        r.insert(
            "energy".to_owned(),
            serde_json::to_value(&energy).unwrap_or_default(),
        );
        if let Some(solver) = r.get_mut("solver").and_then(|s| s.as_object_mut()) {
            solver.insert("absorbed".to_owned(), solver_absorbed);
            solver.insert(
                "escaped".to_owned(),
                serde_json::to_value(escaped).unwrap_or_default(),
            );
            let json = |rgb: Rgb| serde_json::to_value(rgb).unwrap_or_default();
            solver.insert("unshot".to_owned(), json(unshot));
            solver.insert("unshot_fraction".to_owned(), residual.into());
            solver.insert("residual".to_owned(), residual.into());
            if let Some(t) = times.get("direct") {
                solver.insert("direct_seconds".to_owned(), t.clone());
            }
        }
        if let Some(render_summary) = r.get_mut("render").and_then(|s| s.as_object_mut()) {
            render_summary.insert("exposure".to_owned(), render.exposure.into());
            render_summary.insert(
                "ambient".to_owned(),
                serde_json::to_value(ambient).unwrap_or_default(),
            );
        }
        if let Some(s) = r.get_mut("svgs").and_then(|s| s.as_object_mut()) {
            let written: Vec<&String> = svgs.iter().map(|(_, name)| name).collect();
            s.insert(
                "written".to_owned(),
                serde_json::to_value(written).unwrap_or_default(),
            );
        }
        times.insert("merge".to_owned(), started.elapsed().as_secs_f64().into());
        r.insert("times_seconds".to_owned(), times.into());
        r.insert(
            "shards".to_owned(),
            serde_json::json!({"count": count, "parts": parts}),
        );
    }
    let mut report_json = serde_json::to_string_pretty(&report).unwrap_or_default();
    report_json.push('\n');
    Ok(Merged {
        scene_name: scene.name.clone(),
        shards: count,
        surfaces: surfaces.len(),
        triangles,
        vertices,
        solution_json: solution_json_of(&scene.name, &surfaces),
        report_json,
        render_png,
        svgs,
    })
}

/// The figures of shards that each meshed their own surfaces, joined into `report`: the
/// discontinuity search's, the mesh's counts and the budget resolved, summed (the largest of
/// those named `..._max`).
fn sum_mesh_figures(report: &mut serde_json::Value, shards: &[&serde_json::Value]) {
    let sum = |path: &str| -> serde_json::Value {
        let values: Vec<&serde_json::Value> =
            shards.iter().filter_map(|r| r.pointer(path)).collect();
        let floats = values.iter().filter_map(|v| v.as_f64());
        if path.ends_with("_max") {
            floats.fold(f64::NEG_INFINITY, f64::max).into()
        } else if values.iter().all(|v| v.is_u64()) {
            values.iter().filter_map(|v| v.as_u64()).sum::<u64>().into()
        } else {
            floats.sum::<f64>().into()
        }
    };
    let mut paths = vec![
        "/method/max_elements".to_owned(),
        "/counts/triangles".to_owned(),
        "/counts/vertices".to_owned(),
        "/counts/patches".to_owned(),
        "/counts/discontinuity_segments".to_owned(),
    ];
    if let Some(found) = report.get("discontinuities").and_then(|d| d.as_object()) {
        paths.extend(
            found
                .iter()
                .filter(|(_, v)| v.is_number())
                .map(|(key, _)| format!("/discontinuities/{key}")),
        );
    }
    for path in paths {
        let total = sum(&path);
        if let Some(slot) = report.pointer_mut(&path) {
            *slot = total;
        }
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

/// An RGB triple at `path` in a report, zero if absent.
fn rgb_at(report: &serde_json::Value, path: &[&str]) -> Rgb {
    path.iter()
        .try_fold(report, |v, key| v.get(key))
        .and_then(|v| serde_json::from_value::<Rgb>(v.clone()).ok())
        .unwrap_or(Rgb::ZERO)
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
        assert_eq!(
            s.surfaces(7),
            [false, true, false, false, true, false, false]
        );
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
