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
pub mod color;
pub mod coplanar;
pub mod error;
pub mod extremes;
pub mod frame;
pub mod fuzzing;
pub mod load;
pub mod model;
pub mod obj;
pub mod polygon;
pub mod rng;
pub mod tessellated;
pub mod union_find;
pub mod validate;
pub mod visibility;
pub mod visibility_check;

pub use color::Rgb;
pub use error::SceneError;
pub use frame::PlaneFrame;
pub use load::{LoadedScene, load_scene, load_scene_with};
pub use model::{Bounds, Camera, Scene, Surface, SurfaceId};
pub use obj::ObjOptions;
pub use validate::{Problem, ProblemKind, validate};
pub use visibility::{CONTACT_TOLERANCE, Hit, IndexBox, SceneTriangle, Visibility};
