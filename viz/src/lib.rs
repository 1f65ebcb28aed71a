//! # penumbra-viz
//!
//! Pictures of radiosity solutions: a software-rendered image of the meshed scene shaded with
//! its vertex radiosity ([`render()`], written out with [`encode_png`]), and an SVG figure of each
//! surface's mesh in its own plane ([`surface_svg()`]).
//!
//! The renderer is a z-buffered rasterizer in `f64`: near-plane clipping so the camera may stand
//! inside the scene, perspective-correct interpolation, a fill rule that leaves no cracks
//! between triangles, and automatic exposure through the sRGB curve. Its output does not depend
//! on the number of threads.
//!
//! ```
//! use penumbra_scenes::{builtin, Rgb};
//! use penumbra_viz::{RenderOptions, encode_png, render, surface_svg};
//!
//! let scene = builtin::textbook();
//! let mesh = penumbra_meshing::mesh_scene_uniform(&scene, 200).unwrap();
//! // Stand-in radiosity: emission plus reflectance, the same at every vertex of a surface.
//! let radiosity: Vec<Vec<Rgb>> = mesh
//!     .surfaces
//!     .iter()
//!     .map(|m| {
//!         let s = &scene.surfaces[m.surface];
//!         vec![s.emission + s.reflectance; m.vertex_count()]
//!     })
//!     .collect();
//! let options = RenderOptions { width: 48, height: 32, ..RenderOptions::default() };
//! let out = render(&scene, &mesh, &radiosity, &options).unwrap();
//! assert_eq!(out.image.dimensions(), (48, 32));
//! assert!(encode_png(&out.image).unwrap().starts_with(b"\x89PNG"));
//! let svg = surface_svg(&scene, &mesh.surfaces[2], Some(&radiosity[2]), &[]);
//! assert!(svg.contains("floor"));
//! ```

mod camera;
mod chart;
mod clip;
mod error;
mod raster;
mod render;
mod surface_svg;
mod svg_plot;
mod tonemap;

pub use camera::{camera_looking, default_camera};
pub use chart::{LogLogChart, Series};
pub use error::VizError;
pub use render::{Render, RenderOptions, encode_png, render};
pub use surface_svg::surface_svg;
pub use tonemap::srgb_encode;
