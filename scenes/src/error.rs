//! Errors of scene loading and validation.

use std::path::PathBuf;

use crate::validate::Problem;

/// Why a scene could not be loaded. Every variant names the file or scene it concerns.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// A file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why it could not be read.
        #[source]
        source: std::io::Error,
    },
    /// A JSON scene is not valid JSON or does not follow the scene format.
    #[error("{}:{line}:{column}: {message}", path.display())]
    Json {
        /// The file (or the name given to the text).
        path: PathBuf,
        /// Where the parser stopped: line and column, from 1.
        line: usize,
        /// See `line`.
        column: usize,
        /// What is wrong there.
        message: String,
    },
    /// An OBJ file or one of its MTL libraries could not be read as a scene.
    #[error("{}: {message}", path.display())]
    Obj {
        /// The OBJ file.
        path: PathBuf,
        /// What is wrong, with the line where it can be told.
        message: String,
    },
    /// A glTF file or one of its buffers could not be read as a scene.
    #[error("{}: {message}", path.display())]
    Gltf {
        /// The `.gltf` or `.glb` file.
        path: PathBuf,
        /// What is wrong, naming the node, mesh or accessor where it can be told.
        message: String,
    },
    /// The file is none of `.json`, `.obj`, `.gltf` or `.glb`.
    #[error(
        "{}: unsupported file type; scenes are .json, .obj, .gltf or .glb files",
        path.display()
    )]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
    },
    /// The name is neither a file nor a built-in scene.
    #[error(
        "\"{name}\" is neither a scene file nor a built-in scene; built-in scenes are: {}",
        available.join(", ")
    )]
    UnknownScene {
        /// The name asked for.
        name: String,
        /// The names of the built-in scenes.
        available: Vec<&'static str>,
    },
    /// The scene was read but validation found problems ([`crate::validate`]).
    #[error("{source_name}: {} problem{}:\n{}", problems.len(), if problems.len() == 1 { "" } else { "s" },
        problems.iter().map(|p| format!("  - {p}")).collect::<Vec<_>>().join("\n"))]
    Invalid {
        /// Where the scene came from: a path, or `builtin:NAME`.
        source_name: String,
        /// Every problem found.
        problems: Vec<Problem>,
        /// What loading repaired before validation refused the scene (OBJ only), one line each:
        /// often the explanation of the problems, so callers should show them first.
        warnings: Vec<String>,
    },
}
