//! # penumbra-viz
//!
//! Pictures of radiosity solutions, and charts of how they converge.
//!
//! - [`render()`] draws the meshed scene from its camera ([`default_camera`] frames a scene
//!   without one; [`camera_looking`] aims one), shaded with the radiosity at the mesh vertices,
//!   into a [`Render`]; [`encode_png`] writes it out. The renderer is a z-buffered rasterizer in
//!   `f64`: near-plane clipping so the camera may stand inside the scene, perspective-correct
//!   interpolation, a fill rule that leaves no cracks between triangles, and automatic exposure
//!   through the sRGB curve ([`srgb_encode`]). Its output does not depend on the number of
//!   threads.
//! - [`surface_svg()`] draws one surface's mesh in its own plane, filled with its radiosity, with
//!   its discontinuity segments coloured by the boundary they are and a legend.
//! - [`LogLogChart`] plots [`Series`] on logarithmic axes, as SVG or PNG: error against time or
//!   against element count.
//!
//! Inputs that do not fit together (a radiosity list per surface that does not match the mesh,
//! an image too large) give a [`VizError`].
//!
//! ## Example
//!
//! Solve the direct light of the textbook scene on a small mesh and draw it:
//!
//! ```
//! use penumbra_scenes::{Visibility, builtin};
//! use penumbra_solver::{NoProgress, SolverOptions, solve_progressive};
//! use penumbra_viz::{LogLogChart, RenderOptions, Series, encode_png, render, surface_svg};
//!
//! let scene = builtin::textbook();
//! let visibility = Visibility::build(&scene);
//! let mesh = penumbra_meshing::mesh_scene_uniform(&scene, 300).unwrap();
//! let options = SolverOptions { direct_only: true, ..SolverOptions::default() };
//! let solution = solve_progressive(&scene, &mesh, &visibility, &options, &NoProgress).unwrap();
//!
//! let size = RenderOptions { width: 48, height: 32, ..RenderOptions::default() };
//! let picture = render(&scene, &mesh, &solution.radiosity, &size).unwrap();
//! assert_eq!(picture.image.dimensions(), (48, 32));
//! assert!(picture.exposure > 0.0);
//! assert!(picture.image.pixels().any(|p| p.0 != [0, 0, 0]));
//! assert!(encode_png(&picture.image).unwrap().starts_with(b"\x89PNG"));
//!
//! let floor = scene.surface_id("floor").unwrap();
//! let svg = surface_svg(&scene, &mesh.surfaces[floor], Some(&solution.radiosity[floor]), &[]);
//! assert!(svg.contains("<svg") && svg.contains("floor"));
//!
//! let chart = LogLogChart {
//!     title: "one over n".into(),
//!     x_label: "n".into(),
//!     y_label: "1/n".into(),
//!     series: vec![Series {
//!         name: "exact".into(),
//!         points: (1..=10).map(|n| (f64::from(n), 1.0 / f64::from(n))).collect(),
//!     }],
//! };
//! assert!(chart.svg().unwrap().contains("one over n"));
//! ```

#![warn(missing_docs)]

mod camera;
mod chart;
mod clip;
mod error;
mod raster;
mod render;
mod surface_svg;
mod svg_plot;
mod tonemap;

pub use camera::{
    DEFAULT_FOV_DEG, DEFAULT_VIEW_DIRECTION, camera_looking, default_camera, scene_up,
};
pub use chart::{LogLogChart, Series};
pub use error::VizError;
pub use render::{MAX_PIXELS, Render, RenderOptions, encode_png, render};
pub use surface_svg::surface_svg;
pub use tonemap::{luminance, srgb_encode, to_srgb8};
