#![warn(missing_docs)]
//! # penumbra
//!
//! The pipeline that turns a scene into a radiosity solution — mesh, visibility, exact direct
//! light, progressive refinement, render — and the files it writes. The `penumbra` binary is a
//! thin command line around it.

pub mod adaptive;
pub mod energy;
pub mod experiments;
#[doc(hidden)] // Support for the fuzz targets and their tests, not an API.
pub mod fuzzing;
pub mod memory;
pub mod options;
pub mod outputs;
pub mod pipeline;
pub mod shard;

pub use options::{
    DEFAULT_BUDGET, DEFAULT_MAX_ELEMENTS, HIERARCHICAL_MAX_ELEMENTS, InvalidOption, MeshMethod,
    RunOptions, default_budget,
};
pub use pipeline::{RunError, RunResult, run};
