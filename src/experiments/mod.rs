//! Measurements of the method rather than runs of it: the speed/accuracy sweep (`penumbra
//! sweep`) and the form-factor study (`penumbra form-factors`). They use the pipeline like any
//! caller, and the command line only parses their options and prints their tables.

pub mod form_factors;
pub mod sweep;
