#![warn(missing_docs)]
//! # penumbra
//!
//! Radiosity for diffuse polygon scenes lit by polygonal area lights, with the shadows' edges
//! built into the mesh. This crate is the pipeline that joins the library crates, and the files
//! it writes; the `penumbra` binary is a thin command line around it.
//!
//! A run ([`run`]) takes a loaded, validated scene ([`penumbra_scenes::load_scene`]) through
//! these stages:
//!
//! 1. **visibility**: a BVH over the scene's polygons answers every ray and box query;
//! 2. **discontinuities**: where the direct light of each emitter changes its analytic form on
//!    each receiver (EV, VE and EEE events, contact lines; Heckbert 1992, Lischinski, Tampieri &
//!    Greenberg 1992), skipped for uniform meshes;
//! 3. **mesh**: each surface triangulated in its plane within the element budget, the
//!    discontinuities as edges, smaller triangles in penumbrae;
//! 4. **direct light**: exact at every vertex, by backprojection and Lambert's contour formula;
//! 5. **solve**: the light's further bounces, by the solver [`RunOptions::method`] names (or
//!    none, with `solver.direct_only`), optionally refining the mesh where its linear
//!    interpolation misses the solution ([`adaptive`]);
//! 6. **render**: a Gouraud-shaded image from the scene's camera;
//! 7. **outputs**: `solution.json`, `report.json`, `render.png` and one SVG per surface worth
//!    looking at ([`outputs::write_outputs`]).
//!
//! Radiosity is in W/m² per channel (the units of the scene's `emission`), powers in W/m² times
//! the scene's units squared, times in seconds and memory in bytes.
//!
//! ## Main entry points
//!
//! - [`run`] runs the pipeline on a [`penumbra_scenes::LoadedScene`] and returns a
//!   [`RunResult`]: the mesh, the [`penumbra_solver::Solution`] (radiosity at every vertex and
//!   the solver's figures), the render, stage times and memory.
//! - [`RunOptions`] says what to do. [`RunOptions::default`] is the command line's default full
//!   run: a discontinuity mesh where the scene casts shadows (else uniform) of 25,000 triangles
//!   fitted to the scene ([`HIERARCHICAL_MAX_ELEMENTS`]: more when its polygons need more),
//!   solved by hierarchical radiosity. [`default_budget`] gives the default budget for another
//!   solver or a direct-only run (10,000, [`DEFAULT_MAX_ELEMENTS`]).
//!   [`RunOptions::validate`] checks every option's range; [`run`] calls it first, and front
//!   ends call it to refuse bad input before loading a scene.
//! - [`outputs::write_outputs`] writes a run's files into a directory, all or nothing;
//!   [`outputs::solution_json`] and [`outputs::report_json`] give the two JSON files as strings
//!   (`docs/schemas/` holds their JSON schemas).
//! - [`experiments::sweep`] measures the speed/accuracy trade over meshing methods and budgets;
//!   [`experiments::form_factors`] measures the form-factor methods against closed forms.
//! - [`shard`] splits a direct-light run over processes by surface, and merges the parts.
//! - [`energy::EnergyBalance`] is a run's energy account; [`memory`] its estimates and peaks.
//!
//! ## Errors
//!
//! [`run`] returns a [`RunError`]: an [`InvalidOption`] (which names the option in words, such
//! as `"penumbra density"`, for a front end to map to its own spelling), a mesh that cannot fit
//! its budget, a run that would not fit in memory, an interrupt, or a failure of a stage.
//! [`RunError::is_usage`] tells the user's mistakes from the run's failures. Library code
//! panics only on its own bugs.
//!
//! ## Example
//!
//! The textbook scene: a unit square light of exitance 1 W/m² at height 3, facing down, over a
//! unit square blocker at height 1, over a 6 × 6 floor. Its direct light alone, on a small
//! mesh:
//!
//! ```
//! use penumbra::{RunOptions, run};
//! use penumbra_scenes::load_scene;
//! use penumbra_solver::{NoProgress, SolverOptions};
//! use penumbra_viz::RenderOptions;
//!
//! let loaded = load_scene("textbook")?;
//! let options = RunOptions {
//!     max_elements: 2_000.into(),
//!     solver: SolverOptions {
//!         direct_only: true,
//!         ..SolverOptions::default()
//!     },
//!     render: RenderOptions {
//!         width: 64,
//!         height: 48,
//!         ..RenderOptions::default()
//!     },
//!     ..RunOptions::default()
//! };
//! let result = run(loaded, &options, &NoProgress)?;
//! assert!(result.mesh.triangle_count() <= 2_000);
//!
//! // The light emits its area times its exitance: 1 W per channel.
//! let emitted = result.solution.stats.emitted;
//! assert!((emitted.mean() - 1.0).abs() < 1e-9);
//!
//! // Every radiosity is finite and not negative.
//! for b in result.solution.radiosity.iter().flatten() {
//!     assert!([b.r, b.g, b.b].iter().all(|c| c.is_finite() && *c >= 0.0));
//! }
//!
//! // On the floor, the blocker's umbra is the square under it (|x|, |y| < 0.5), its penumbra
//! // reaches |x| or |y| = 1, and beyond that the whole light is seen.
//! let floor = result.loaded.scene.surface_id("floor").expect("the textbook has a floor");
//! let mesh = &result.mesh.surfaces[floor];
//! let radiosity = &result.solution.radiosity[floor];
//! let (mut umbra, mut lit) = (0, 0);
//! for (p, b) in mesh.points3.iter().zip(radiosity) {
//!     let reach = p.x.abs().max(p.y.abs());
//!     if reach < 0.49 {
//!         assert!(b.mean() < 1e-12, "light in the umbra at {p}: {b:?}");
//!         umbra += 1;
//!     } else if reach > 1.01 {
//!         assert!(b.mean() > 0.0, "no light at {p}");
//!         lit += 1;
//!     }
//! }
//! assert!(umbra > 0 && lit > 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod adaptive;
pub mod energy;
pub mod error_mesh;
pub mod experiments;
pub mod export;
mod fingerprint;
#[doc(hidden)] // Support for the fuzz targets and their tests, not an API.
pub mod fuzzing;
mod json_text;
pub mod memory;
pub mod options;
pub mod outputs;
pub mod pipeline;
pub mod reflected_mesh;
pub mod report;
pub mod run_error;
pub mod run_result;
pub mod shard;
pub mod svg_selection;

pub use options::{
    DEFAULT_BUDGET, DEFAULT_FF_SAMPLES, DEFAULT_HEMICUBE_RESOLUTION, DEFAULT_MAX_ELEMENTS,
    DEFAULT_MIN_ANGLE_DEG, HIERARCHICAL_MAX_ELEMENTS, InvalidOption, MeshMethod, OptionId,
    RunOptions, default_budget, default_initial_elements, default_penumbra_density,
};
pub use pipeline::{RunError, RunResult, run};
