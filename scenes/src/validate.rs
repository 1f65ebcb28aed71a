//! Scene validation: every problem at once, each naming the surface and what to change.
//!
//! The thresholds guard numerical degeneracy, not physical size: a light a millionth of the scene
//! or a scene measured in micrometres is legitimate. Every threshold is relative — to the scene's
//! bounding-box diagonal or to the polygon's own size.

use std::collections::HashMap;
use std::fmt;

use glam::DVec3;

use crate::frame::PlaneFrame;
use crate::model::{Scene, Surface};
use crate::polygon;

/// Vertices closer than this fraction of the scene diagonal are the same vertex.
pub const SAME_POINT_TOLERANCE: f64 = 1e-12;
/// Polygons smaller than this fraction of the scene diagonal are rounding noise, not geometry.
pub const MIN_RELATIVE_SIZE: f64 = 1e-10;
/// Polygons whose area is below this fraction of their diameter squared are slivers.
pub const MIN_THINNESS: f64 = 1e-9;
/// Largest distance of a vertex from the polygon's plane, relative to the polygon's diameter.
pub const PLANARITY_TOLERANCE: f64 = 1e-6;

/// One thing wrong with a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// The surface concerned, or `None` for scene-wide problems.
    pub surface: Option<String>,
    /// What is wrong.
    pub kind: ProblemKind,
}

/// What is wrong with a scene or one of its surfaces. Its `Display` (through [`Problem`]) says
/// what to change.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ProblemKind {
    /// The scene has no surfaces.
    NoSurfaces,
    /// A surface's name is empty.
    EmptyName,
    /// A number is NaN or infinite.
    NonFinite {
        /// The field that holds it: `polygon`, `emission` or `reflectance`.
        field: &'static str,
    },
    /// The polygon has fewer than 3 distinct vertices ([`SAME_POINT_TOLERANCE`]).
    TooFewVertices {
        /// How many distinct vertices it has.
        distinct: usize,
    },
    /// Two vertices coincide ([`SAME_POINT_TOLERANCE`]): the polygon touches itself.
    RepeatedVertex {
        /// The first vertex's index.
        first: usize,
        /// The second vertex's index.
        second: usize,
    },
    /// The polygon is negligibly small against the scene ([`MIN_RELATIVE_SIZE`]) or a sliver
    /// ([`MIN_THINNESS`]).
    TinyArea {
        /// The polygon's area.
        area: f64,
        /// Its largest vertex distance.
        diameter: f64,
        /// The scene's bounding-box diagonal.
        scene_diagonal: f64,
    },
    /// A vertex lies off the polygon's plane by more than [`PLANARITY_TOLERANCE`] of its
    /// diameter.
    NonPlanar {
        /// The vertex's distance from the plane through the centroid.
        deviation: f64,
        /// The vertex farthest from the plane.
        vertex: usize,
        /// The distance allowed.
        tolerance: f64,
    },
    /// Two edges of the polygon touch (edge `i` runs from vertex `i` to `i + 1`).
    SelfIntersecting {
        /// One edge.
        edge_a: usize,
        /// The other.
        edge_b: usize,
    },
    /// A reflectance channel is outside [0, 1).
    ReflectanceOutOfRange {
        /// `r`, `g` or `b`.
        channel: &'static str,
        /// The value given.
        value: f64,
    },
    /// An emission channel is negative.
    NegativeEmission {
        /// `r`, `g` or `b`.
        channel: &'static str,
        /// The value given.
        value: f64,
    },
    /// Two surfaces have the same name.
    DuplicateName {
        /// The first surface's index.
        first: usize,
        /// The second surface's index.
        second: usize,
    },
    /// No surface emits.
    NoEmitter,
    /// The camera cannot give a picture.
    BadCamera {
        /// Why, and what to change.
        reason: &'static str,
    },
    /// The scene's up direction is zero or not finite.
    BadUp,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(name) = &self.surface {
            write!(f, "surface \"{name}\": ")?;
        }
        use ProblemKind::*;
        match &self.kind {
            NoSurfaces => write!(
                f,
                "the scene has no surfaces; add at least an emitter and a receiver"
            ),
            EmptyName => write!(
                f,
                "a surface has an empty name; give every surface a unique name"
            ),
            NonFinite { field } => write!(
                f,
                "{field} contains a non-finite number (NaN or infinity); replace it with a finite value"
            ),
            TooFewVertices { distinct } => write!(
                f,
                "the polygon has {distinct} distinct vertices; a surface needs at least 3"
            ),
            RepeatedVertex { first, second } => write!(
                f,
                "vertices {first} and {second} coincide; remove the repeated vertex (a polygon may not touch itself)"
            ),
            TinyArea {
                area,
                diameter,
                scene_diagonal,
            } => write!(
                f,
                "the polygon has zero or negligible area ({area:.3e}, diameter {diameter:.3e}, scene diagonal \
                 {scene_diagonal:.3e}); remove it or give it a real extent (its vertices may be collinear)"
            ),
            NonPlanar {
                deviation,
                vertex,
                tolerance,
            } => write!(
                f,
                "the polygon is not planar: vertex {vertex} lies {deviation:.3e} from its plane (tolerance \
                 {tolerance:.3e}); split it into planar pieces, e.g. triangles"
            ),
            SelfIntersecting { edge_a, edge_b } => write!(
                f,
                "the polygon intersects itself (edges {edge_a} and {edge_b} touch); reorder its vertices or split it \
                 into simple polygons"
            ),
            ReflectanceOutOfRange { channel, value } => write!(
                f,
                "reflectance {value} in channel {channel} is outside [0, 1); a surface cannot reflect all the light it \
                 receives — use a value below 1"
            ),
            NegativeEmission { channel, value } => write!(
                f,
                "emission {value} in channel {channel} is negative; emission must be zero or positive"
            ),
            DuplicateName { first, second } => write!(
                f,
                "surfaces {first} and {second} share this name; give each surface a unique name"
            ),
            NoEmitter => write!(
                f,
                "no surface emits light; give at least one surface a positive \"emission\" (in OBJ files, \
                 a material with a positive Ke)"
            ),
            BadCamera { reason } => write!(f, "camera: {reason}"),
            BadUp => write!(
                f,
                "up: the direction is zero or not finite; give a direction such as [0, 0, 1]"
            ),
        }
    }
}

/// All the problems of a scene; empty when the scene is valid.
pub fn validate(scene: &Scene) -> Vec<Problem> {
    let mut problems = Vec::new();
    if scene.surfaces.is_empty() {
        problems.push(Problem {
            surface: None,
            kind: ProblemKind::NoSurfaces,
        });
        return problems;
    }
    let finite_points = scene
        .surfaces
        .iter()
        .filter(|s| s.polygon.iter().all(|p| p.is_finite()))
        .flat_map(|s| s.polygon.iter());
    let scene_diagonal = crate::model::Bounds::from_points(finite_points).diagonal();

    let mut seen: HashMap<&str, usize> = HashMap::new();
    for (index, surface) in scene.surfaces.iter().enumerate() {
        let mut report = |kind| {
            problems.push(Problem {
                surface: Some(surface.name.clone()),
                kind,
            });
        };
        if surface.name.is_empty() {
            report(ProblemKind::EmptyName);
        } else if let Some(&first) = seen.get(surface.name.as_str()) {
            report(ProblemKind::DuplicateName {
                first,
                second: index,
            });
        } else {
            seen.insert(&surface.name, index);
        }
        check_material(surface, &mut report);
        check_geometry(surface, scene_diagonal, &mut report);
    }

    let emits = scene
        .surfaces
        .iter()
        .any(|s| s.is_emitter() && s.emission.is_finite());
    if !emits {
        problems.push(Problem {
            surface: None,
            kind: ProblemKind::NoEmitter,
        });
    }
    if let Some(c) = &scene.camera
        && let Some(reason) = camera_problem(c)
    {
        problems.push(Problem {
            surface: None,
            kind: ProblemKind::BadCamera { reason },
        });
    }
    if let Some(up) = scene.up
        && !(up.is_finite() && up.length() > 0.0)
    {
        problems.push(Problem {
            surface: None,
            kind: ProblemKind::BadUp,
        });
    }
    problems
}

const CHANNELS: [&str; 3] = ["r", "g", "b"];

fn check_material(surface: &Surface, report: &mut impl FnMut(ProblemKind)) {
    if !surface.reflectance.is_finite() {
        report(ProblemKind::NonFinite {
            field: "reflectance",
        });
    } else {
        for (channel, value) in CHANNELS.into_iter().zip(surface.reflectance.to_array()) {
            if !(0.0..1.0).contains(&value) {
                report(ProblemKind::ReflectanceOutOfRange { channel, value });
            }
        }
    }
    if !surface.emission.is_finite() {
        report(ProblemKind::NonFinite { field: "emission" });
    } else {
        for (channel, value) in CHANNELS.into_iter().zip(surface.emission.to_array()) {
            if value < 0.0 {
                report(ProblemKind::NegativeEmission { channel, value });
            }
        }
    }
}

fn check_geometry(surface: &Surface, scene_diagonal: f64, report: &mut impl FnMut(ProblemKind)) {
    if let Some(kind) = polygon_problem(&surface.polygon, scene_diagonal) {
        report(kind);
    }
}

/// The first thing wrong with a polygon as a surface of a scene whose bounding-box diagonal is
/// `scene_diagonal`, or `None` when it is a valid surface. Importers call it to make sure a
/// polygon they build (a merged or repaired face) will pass validation.
pub fn polygon_problem(points: &[DVec3], scene_diagonal: f64) -> Option<ProblemKind> {
    if points.iter().any(|p| !p.is_finite()) {
        return Some(ProblemKind::NonFinite { field: "polygon" });
    }
    let same = SAME_POINT_TOLERANCE * scene_diagonal;
    let mut distinct: Vec<DVec3> = Vec::new();
    for &p in points {
        if distinct.len() < 3 && distinct.iter().all(|&q| q.distance(p) > same) {
            distinct.push(p);
        }
    }
    if distinct.len() < 3 {
        return Some(ProblemKind::TooFewVertices {
            distinct: distinct.len(),
        });
    }
    for i in 0..points.len() {
        for j in i + 1..points.len() {
            if points[i].distance(points[j]) <= same {
                return Some(ProblemKind::RepeatedVertex {
                    first: i,
                    second: j,
                });
            }
        }
    }
    let diameter = polygon::diameter(points);
    let area = 0.5 * polygon::newell_normal(points).length();
    let tiny = ProblemKind::TinyArea {
        area,
        diameter,
        scene_diagonal,
    };
    if diameter < MIN_RELATIVE_SIZE * scene_diagonal || area < MIN_THINNESS * diameter * diameter {
        return Some(tiny);
    }
    let Some(frame) = PlaneFrame::of_polygon(points) else {
        return Some(tiny);
    };
    // Distances are measured from the best-fit plane through the centroid, not the first vertex.
    let centroid = polygon::centroid(points);
    let tolerance = PLANARITY_TOLERANCE * diameter;
    if let Some((vertex, deviation)) = points
        .iter()
        .map(|&p| (p - centroid).dot(frame.normal).abs())
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .filter(|&(_, d)| d > tolerance)
    {
        return Some(ProblemKind::NonPlanar {
            deviation,
            vertex,
            tolerance,
        });
    }
    let flat: Vec<_> = points.iter().map(|&p| frame.to_2d(p)).collect();
    polygon::first_self_intersection(&flat)
        .map(|(edge_a, edge_b)| ProblemKind::SelfIntersecting { edge_a, edge_b })
}

fn camera_problem(c: &crate::model::Camera) -> Option<&'static str> {
    if !(c.eye.is_finite() && c.target.is_finite() && c.up.is_finite() && c.fov_deg.is_finite()) {
        return Some("contains a non-finite number; replace it with a finite value");
    }
    let view = c.target - c.eye;
    if view.length() == 0.0 {
        return Some("eye and target coincide; move the target in front of the eye");
    }
    if view.cross(c.up).length() <= 1e-9 * view.length() * c.up.length() {
        return Some(
            "up is zero or parallel to the view direction; choose an up vector across the view",
        );
    }
    if !(c.fov_deg > 0.0 && c.fov_deg < 180.0) {
        return Some("fov_deg must be between 0 and 180 degrees");
    }
    None
}
