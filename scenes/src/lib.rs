//! # penumbra-scenes
//!
//! The scene model of penumbra: diffuse scenes of planar polygons, some of which emit light.
//! This crate loads scenes (our JSON format, or OBJ+MTL), validates them with messages that name
//! the surface and the fix, provides the built-in scenes, maps each surface between 3D and its own
//! 2D coordinates ([`PlaneFrame`]), and answers visibility queries with a BVH ([`Visibility`]).
//!
//! ```
//! use penumbra_scenes::{builtin, validate, Visibility};
//! let scene = builtin::textbook();
//! assert!(validate(&scene).is_empty());
//! let vis = Visibility::build(&scene);
//! // The blocker hides the light's centre from the floor's centre.
//! let floor = scene.surface_id("floor").unwrap();
//! let light = scene.surface_id("light").unwrap();
//! assert!(vis.occluded(glam::DVec3::ZERO, glam::DVec3::new(0.0, 0.0, 3.0), [floor, light]));
//! ```

pub mod builtin;
pub mod cie;
mod color;
mod coplanar;
mod error;
pub mod extremes;
mod frame;
#[doc(hidden)]
pub mod fuzzing;
mod load;
mod model;
mod obj;
pub mod polygon;
mod rng;
pub mod tessellated;
mod union_find;
mod validate;
mod visibility;
pub mod visibility_check;

pub use color::Rgb;
pub use error::SceneError;
pub use frame::PlaneFrame;
pub use load::{LoadedScene, load_scene, load_scene_with, parse_json, read_scene_file, to_json};
pub use model::{Bounds, Camera, Scene, Surface, SurfaceId};
pub use obj::{MAX_OBJ_REFLECTANCE, ObjOptions, parse_obj_text, parse_obj_text_with};
pub use rng::SplitMix64;
pub use union_find::UnionFind;
pub use validate::{Problem, ProblemKind, polygon_problem, validate};
pub use visibility::{CONTACT_TOLERANCE, Hit, IndexBox, SceneTriangle, Visibility};
