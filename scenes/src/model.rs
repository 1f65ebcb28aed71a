//! The scene model: named planar polygons with emission and reflectance, and an optional camera.

use glam::{DAffine3, DVec3};
use serde::{Deserialize, Serialize};

use crate::color::Rgb;
use crate::polygon;

/// Index of a surface in [`Scene::surfaces`].
pub type SurfaceId = usize;

/// A diffuse scene of planar polygons lit by the polygons that emit.
///
/// The JSON form is the scene format of the design document; unknown keys are errors.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    #[serde(default)]
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<Camera>,
    pub surfaces: Vec<Surface>,
}

/// One planar, simple polygon. Vertices run counter-clockwise seen from the front; light leaves
/// and arrives on the front only, and both sides block.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Surface {
    pub name: String,
    pub polygon: Vec<DVec3>,
    /// The surface's own exitance E in W/m^2 per channel.
    #[serde(default, skip_serializing_if = "Rgb::is_zero")]
    pub emission: Rgb,
    /// Diffuse reflectance per channel, in [0, 1).
    pub reflectance: Rgb,
}

/// A pinhole camera; `fov_deg` is the vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    pub fov_deg: f64,
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub min: DVec3,
    pub max: DVec3,
}

impl Bounds {
    pub const EMPTY: Bounds = Bounds {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> Bounds {
        points
            .into_iter()
            .fold(Bounds::EMPTY, |b, &p| b.including(p))
    }

    pub fn including(self, p: DVec3) -> Bounds {
        Bounds {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    pub fn union(self, o: Bounds) -> Bounds {
        Bounds {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    pub fn is_empty(&self) -> bool {
        !(self.min.cmple(self.max).all())
    }

    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).length()
        }
    }

    pub fn overlaps(&self, o: &Bounds) -> bool {
        self.min.cmple(o.max).all() && o.min.cmple(self.max).all()
    }
}

impl Surface {
    pub fn new(name: impl Into<String>, polygon: Vec<DVec3>, reflectance: Rgb) -> Surface {
        Surface {
            name: name.into(),
            polygon,
            emission: Rgb::ZERO,
            reflectance,
        }
    }

    pub fn with_emission(mut self, emission: Rgb) -> Surface {
        self.emission = emission;
        self
    }

    /// True when the surface emits light in some channel.
    pub fn is_emitter(&self) -> bool {
        self.emission.max_channel() > 0.0
    }

    /// Unit normal by the right-hand rule (Newell's method, robust for non-convex polygons).
    pub fn normal(&self) -> DVec3 {
        polygon::newell_normal(&self.polygon).normalize_or_zero()
    }

    pub fn area(&self) -> f64 {
        0.5 * polygon::newell_normal(&self.polygon).length()
    }

    /// Emitted power per channel (exitance times area).
    pub fn emitted_power(&self) -> Rgb {
        self.emission * self.area()
    }

    pub fn bounds(&self) -> Bounds {
        Bounds::from_points(&self.polygon)
    }
}

impl Scene {
    pub fn bounds(&self) -> Bounds {
        self.surfaces
            .iter()
            .fold(Bounds::EMPTY, |b, s| b.union(s.bounds()))
    }

    /// The scene's length scale: every geometric tolerance is a multiple of it.
    pub fn diagonal(&self) -> f64 {
        self.bounds().diagonal()
    }

    pub fn emitters(&self) -> impl Iterator<Item = (SurfaceId, &Surface)> {
        self.surfaces
            .iter()
            .enumerate()
            .filter(|(_, s)| s.is_emitter())
    }

    pub fn emitted_power(&self) -> Rgb {
        self.surfaces.iter().map(Surface::emitted_power).sum()
    }

    pub fn total_area(&self) -> f64 {
        self.surfaces.iter().map(Surface::area).sum()
    }

    pub fn surface_id(&self, name: &str) -> Option<SurfaceId> {
        self.surfaces.iter().position(|s| s.name == name)
    }

    /// The same scene moved by a similarity transform (rotation, uniform scale, translation).
    /// Radiosity is invariant under such maps, which makes them a test of every algorithm.
    pub fn transformed(&self, map: &DAffine3) -> Scene {
        let mut out = self.clone();
        for s in &mut out.surfaces {
            for p in &mut s.polygon {
                *p = map.transform_point3(*p);
            }
        }
        if let Some(c) = &mut out.camera {
            c.eye = map.transform_point3(c.eye);
            c.target = map.transform_point3(c.target);
            c.up = map.transform_vector3(c.up).normalize_or_zero();
        }
        out
    }
}
