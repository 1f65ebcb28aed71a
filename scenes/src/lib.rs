//! # penumbra-scenes
//!
//! The scene model of penumbra: diffuse scenes of planar polygons, some of which emit light.
//! This crate loads scenes (penumbra's JSON format, or OBJ+MTL), validates them with messages
//! that name the surface and the fix, provides the built-in scenes, maps each surface between 3D
//! and its own 2D coordinates, and answers visibility queries with a BVH.
//!
//! ## Main types
//!
//! - [`Scene`], [`Surface`] and [`Camera`]: the model. A surface is one planar, simple polygon
//!   whose vertices run counter-clockwise seen from its front; light leaves and arrives on the
//!   front only, and both sides block. [`Rgb`] holds one value per channel: `emission` is the
//!   surface's own exitance in W/m², `reflectance` a fraction in [0, 1).
//! - [`load_scene`] turns a path or a built-in name into a validated [`LoadedScene`];
//!   [`parse_json`] and [`parse_obj_text`] read text, [`read_scene_file`] reads a file without
//!   validating it, and [`to_json`] writes a scene back.
//! - [`validate`] lists every [`Problem`] of a scene at once. Its thresholds guard numerical
//!   degeneracy, not physical size: they are relative to the scene's bounding-box diagonal
//!   ([`Scene::diagonal`]) or to the polygon's own size.
//! - [`builtin`] holds the built-in scenes (the measured Cornell box among them); [`cie`],
//!   [`extremes`] and [`tessellated`] hold test scenes with known answers.
//! - [`PlaneFrame`] gives each surface its own 2D coordinates; [`polygon`] has the planar
//!   geometry (normals, areas, exact orientation, triangulation, clipping) the crates share.
//! - [`Visibility`] indexes the triangulated surfaces in a BVH and answers segment and ray
//!   queries in `f64` with a watertight test; [`visibility_check`] compares it with exhaustive
//!   search.
//! - [`SplitMix64`] is the seeded generator behind every random choice in penumbra, and
//!   [`UnionFind`] the disjoint sets the meshing and solving crates group surfaces with.
//!
//! ## Example
//!
//! Read a scene in the JSON format, check it, and ask what a point sees:
//!
//! ```
//! use std::path::Path;
//!
//! use glam::DVec3;
//! use penumbra_scenes::{ProblemKind, Rgb, Visibility, builtin, parse_json, validate};
//!
//! let text = r#"{
//!   "name": "small",
//!   "surfaces": [
//!     {"name": "light", "polygon": [[-0.5, -0.5, 2], [-0.5, 0.5, 2], [0.5, 0.5, 2], [0.5, -0.5, 2]],
//!      "emission": [10, 10, 10], "reflectance": [0, 0, 0]},
//!     {"name": "floor", "polygon": [[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]],
//!      "reflectance": [0.7, 0.7, 0.7]}
//!   ]
//! }"#;
//! let scene = parse_json(text, Path::new("small.json")).unwrap();
//! assert!(validate(&scene).is_empty());
//! assert_eq!(scene.emitters().count(), 1);
//! assert!((scene.surfaces[1].area() - 36.0).abs() < 1e-12);
//! // The light's vertices run clockwise seen from above: it faces down, towards the floor.
//! assert!((scene.surfaces[0].normal() - DVec3::NEG_Z).length() < 1e-12);
//!
//! // A floor that reflected all the light it receives is refused, with the fix in the message.
//! let mut white = scene.clone();
//! white.surfaces[1].reflectance = Rgb::splat(1.0);
//! let problems = validate(&white);
//! assert_eq!(problems.len(), 3); // one per channel
//! assert!(matches!(problems[0].kind, ProblemKind::ReflectanceOutOfRange { channel: "r", .. }));
//! assert!(problems[0].to_string().starts_with("surface \"floor\": reflectance 1"));
//!
//! // In the built-in textbook scene a blocker hides the light's centre from the floor's centre.
//! let textbook = builtin::textbook();
//! let visibility = Visibility::build(&textbook);
//! let floor = textbook.surface_id("floor").unwrap();
//! let light = textbook.surface_id("light").unwrap();
//! assert!(visibility.occluded(DVec3::ZERO, DVec3::new(0.0, 0.0, 3.0), [floor, light]));
//! ```

#![warn(missing_docs)]

mod area_sampler;
pub mod builtin;
pub mod cie;
mod color;
mod coplanar;
mod error;
pub mod extremes;
mod frame;
#[doc(hidden)]
pub mod fuzzing;
mod gltf_file;
mod load;
mod mesh_file;
mod model;
mod obj;
pub mod polygon;
mod rng;
pub mod tessellated;
mod union_find;
mod validate;
mod visibility;
pub mod visibility_check;

pub use area_sampler::AreaSampler;
pub use color::Rgb;
pub use error::SceneError;
pub use frame::PlaneFrame;
pub use load::{LoadedScene, load_scene, load_scene_with, parse_json, read_scene_file, to_json};
pub use model::{Bounds, Camera, LengthUnit, Scene, Surface, SurfaceId};
pub use obj::{MAX_OBJ_REFLECTANCE, ObjOptions, parse_obj_text, parse_obj_text_with};
pub use rng::SplitMix64;
pub use union_find::UnionFind;
pub use validate::{
    MIN_RELATIVE_SIZE, MIN_THINNESS, PLANARITY_TOLERANCE, Problem, ProblemKind,
    SAME_POINT_TOLERANCE, polygon_problem, validate,
};
pub use visibility::{
    CONTACT_TOLERANCE, Hit, IndexBox, JUNCTION_OFFSET, SceneTriangle, Visibility,
};
