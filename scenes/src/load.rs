//! Loading scenes: built-in names, our JSON format, OBJ+MTL, and glTF 2.0.

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::builtin;
use crate::error::SceneError;
use crate::gltf_file;
use crate::model::Scene;
use crate::obj::{self, ObjOptions};
use crate::validate::validate;

/// A validated scene and what loading it had to repair.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The scene, valid.
    pub scene: Scene,
    /// Where it came from: a path, or `builtin:NAME`.
    pub source: String,
    /// Repairs made while loading (OBJ only), one line each.
    pub warnings: Vec<String>,
}

/// Loads `spec` — a path to a `.json` or `.obj` file, or the name of a built-in scene — and
/// validates it. Every problem is reported at once.
pub fn load_scene(spec: &str) -> Result<LoadedScene, SceneError> {
    load_scene_with(spec, &ObjOptions::default())
}

/// [`load_scene`] with choices for OBJ files. When validation refuses the scene, the error
/// carries the loader's warnings too: they often explain the problems.
pub fn load_scene_with(spec: &str, options: &ObjOptions) -> Result<LoadedScene, SceneError> {
    let path = Path::new(spec);
    // A file that exists wins; then a built-in name (some have dots: "cie-5.3"); then anything
    // that looks like a path is read as one, for its error.
    let looks_like_path = spec.contains(std::path::MAIN_SEPARATOR)
        || spec.contains('/')
        || path.extension().is_some();
    // A directory named like a built-in scene (an output directory, say) does not hide it.
    let builtin_scene = if path.is_file() {
        None
    } else {
        builtin::builtin(spec)
    };
    let (scene, source, warnings) = if let Some(scene) = builtin_scene {
        (scene, format!("builtin:{spec}"), Vec::new())
    } else if path.is_file() || looks_like_path {
        let (scene, warnings) = read_scene_file_with(path, options)?;
        (scene, path.display().to_string(), warnings)
    } else {
        return Err(SceneError::UnknownScene {
            name: spec.to_string(),
            available: builtin::NAMES.iter().map(|(n, _)| *n).collect(),
        });
    };
    let problems = validate(&scene);
    if !problems.is_empty() {
        return Err(SceneError::Invalid {
            source_name: source,
            problems,
            warnings,
        });
    }
    Ok(LoadedScene {
        scene,
        source,
        warnings,
    })
}

/// Reads a scene file without validating it.
pub fn read_scene_file(path: &Path) -> Result<(Scene, Vec<String>), SceneError> {
    read_scene_file_with(path, &ObjOptions::default())
}

/// Reads a scene file without validating it, with choices for OBJ files.
pub(crate) fn read_scene_file_with(
    path: &Path,
    options: &ObjOptions,
) -> Result<(Scene, Vec<String>), SceneError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("json") => {
            let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
                path: path.to_path_buf(),
                source,
            })?;
            let scene = parse_json(&text, path)?;
            Ok((scene, Vec::new()))
        }
        Some("obj") => obj::read_obj_with(path, options),
        Some("gltf" | "glb") => gltf_file::read_gltf_with(path, options),
        _ => Err(SceneError::UnsupportedFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// Parses the JSON scene format; `path` only names the source in errors.
pub fn parse_json(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let mut scene: Scene = serde_json::from_str(text).map_err(|e| SceneError::Json {
        path: PathBuf::from(path),
        line: e.line(),
        column: e.column(),
        message: strip_position(&e.to_string()),
    })?;
    if scene.name.is_empty() {
        scene.name = scene_name(path);
    }
    for s in &mut scene.surfaces {
        drop_repeated_vertices(&mut s.polygon);
    }
    Ok(scene)
}

/// A scene file's name for a scene that has none of its own: the file's stem.
pub(crate) fn scene_name(path: &Path) -> String {
    path.file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene")
        .to_string()
}

/// The bytes of a scene file (or of a file it names), or an error naming it.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, SceneError> {
    std::fs::read(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// serde_json appends " at line L column C"; the error already says where.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message.to_string(),
    }
}

/// Removes vertices exactly equal to their predecessor, and a closing vertex equal to the first:
/// both are common ways of writing a polygon and neither changes its shape.
pub(crate) fn drop_repeated_vertices(polygon: &mut Vec<DVec3>) {
    polygon.dedup();
    while polygon.len() > 1 && polygon.first() == polygon.last() {
        polygon.pop();
    }
}

/// Writes a scene in the JSON format: indented, each point or colour on one line, ending with a
/// newline; [`parse_json`] reads it back to the same scene.
pub fn to_json(scene: &Scene) -> String {
    let pretty = serde_json::to_string_pretty(scene)
        .unwrap_or_else(|e| format!("{{\"error\": {:?}}}", e.to_string()));
    let mut out = String::with_capacity(pretty.len());
    let mut lines = pretty.lines().peekable();
    while let Some(line) = lines.next() {
        out.push_str(line);
        if line.ends_with('[') {
            // An array of numbers (a point, a colour) goes on its opening line.
            let mut numbers = Vec::new();
            while let Some(next) = lines.peek() {
                let item = next.trim().trim_end_matches(',');
                if item.parse::<f64>().is_err() {
                    break;
                }
                numbers.push(item.to_owned());
                lines.next();
            }
            if !numbers.is_empty() {
                out.push_str(&numbers.join(", "));
                if let Some(close) = lines.next() {
                    out.push_str(close.trim_start());
                }
            }
        }
        out.push('\n');
    }
    out
}
