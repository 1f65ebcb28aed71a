//! Errors of scene loading and validation.

use std::path::PathBuf;

use crate::validate::Problem;

/// Why a scene could not be loaded. Every variant names the file or scene it concerns.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    #[error("cannot read {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}:{line}:{column}: {message}", path.display())]
    Json {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{}: {message}", path.display())]
    Obj { path: PathBuf, message: String },
    #[error("{}: unsupported file type; scenes are .json or .obj files", path.display())]
    UnsupportedFormat { path: PathBuf },
    #[error(
        "\"{name}\" is neither a scene file nor a built-in scene; built-in scenes are: {}",
        available.join(", ")
    )]
    UnknownScene {
        name: String,
        available: Vec<&'static str>,
    },
    #[error("{source_name}: {} problem{}:\n{}", problems.len(), if problems.len() == 1 { "" } else { "s" },
        problems.iter().map(|p| format!("  - {p}")).collect::<Vec<_>>().join("\n"))]
    Invalid {
        source_name: String,
        problems: Vec<Problem>,
        /// What loading repaired before validation refused the scene (OBJ only), one line each:
        /// often the explanation of the problems, so callers should show them first.
        warnings: Vec<String>,
    },
}
