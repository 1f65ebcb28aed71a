//! Progress reporting from long computations (shared with the meshing crate).

pub use penumbra_meshing::{Interrupt, NoProgress, Progress};
