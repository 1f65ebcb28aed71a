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
    /// The scene's name; a scene file without one is named after the file.
    #[serde(default)]
    pub name: String,
    /// The view to render; without one, a default camera frames the scene.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<Camera>,
    /// Which way is up, for views and exports: glTF files are +y up; without it, +y when the
    /// lights face −y (as in most OBJ files), else +z.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<DVec3>,
    /// The unit of the coordinates, for exports to formats that fix one (glTF: metres);
    /// without it, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<LengthUnit>,
    /// The polygons, in the order their [`SurfaceId`]s count.
    pub surfaces: Vec<Surface>,
}

/// A unit of length, written as its symbol.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum LengthUnit {
    /// Micrometres.
    #[serde(rename = "um")]
    Micrometre,
    /// Millimetres.
    #[serde(rename = "mm")]
    Millimetre,
    /// Centimetres.
    #[serde(rename = "cm")]
    Centimetre,
    /// Metres.
    #[serde(rename = "m")]
    Metre,
    /// Kilometres.
    #[serde(rename = "km")]
    Kilometre,
    /// Inches.
    #[serde(rename = "in")]
    Inch,
    /// Feet.
    #[serde(rename = "ft")]
    Foot,
}

impl LengthUnit {
    /// Every unit, in the order above.
    pub const ALL: [LengthUnit; 7] = [
        LengthUnit::Micrometre,
        LengthUnit::Millimetre,
        LengthUnit::Centimetre,
        LengthUnit::Metre,
        LengthUnit::Kilometre,
        LengthUnit::Inch,
        LengthUnit::Foot,
    ];

    /// Its length in metres.
    pub fn metres(self) -> f64 {
        match self {
            LengthUnit::Micrometre => 1e-6,
            LengthUnit::Millimetre => 1e-3,
            LengthUnit::Centimetre => 1e-2,
            LengthUnit::Metre => 1.0,
            LengthUnit::Kilometre => 1e3,
            LengthUnit::Inch => 0.0254,
            LengthUnit::Foot => 0.3048,
        }
    }

    /// Its symbol, as scene files write it.
    pub fn symbol(self) -> &'static str {
        match self {
            LengthUnit::Micrometre => "um",
            LengthUnit::Millimetre => "mm",
            LengthUnit::Centimetre => "cm",
            LengthUnit::Metre => "m",
            LengthUnit::Kilometre => "km",
            LengthUnit::Inch => "in",
            LengthUnit::Foot => "ft",
        }
    }

    /// The unit whose symbol is `symbol`.
    pub fn from_symbol(symbol: &str) -> Option<LengthUnit> {
        LengthUnit::ALL.into_iter().find(|u| u.symbol() == symbol)
    }
}

/// One planar, simple polygon. Vertices run counter-clockwise seen from the front; light leaves
/// and arrives on the front only, and both sides block.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Surface {
    /// The surface's name in messages and outputs.
    pub name: String,
    /// The vertices, counter-clockwise seen from the front, without repeating the first.
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
    /// Where the camera stands.
    pub eye: DVec3,
    /// A point it looks at, in the middle of the image.
    pub target: DVec3,
    /// The direction that is up in the image (need not be at right angles to the view).
    pub up: DVec3,
    /// The vertical field of view in degrees, in (0, 180).
    pub fov_deg: f64,
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// The least coordinate on each axis.
    pub min: DVec3,
    /// The greatest coordinate on each axis.
    pub max: DVec3,
}

impl Bounds {
    /// The box of no points: `min` is +∞ and `max` −∞, so a union with it changes nothing.
    pub const EMPTY: Bounds = Bounds {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// The smallest box holding `points` ([`Bounds::EMPTY`] for none).
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> Bounds {
        points
            .into_iter()
            .fold(Bounds::EMPTY, |b, &p| b.including(p))
    }

    /// This box grown to hold `p`.
    pub fn including(self, p: DVec3) -> Bounds {
        Bounds {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The smallest box holding both boxes.
    pub fn union(self, o: Bounds) -> Bounds {
        Bounds {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// Whether the box holds no point (it is [`Bounds::EMPTY`], or has NaN corners).
    pub fn is_empty(&self) -> bool {
        !(self.min.cmple(self.max).all())
    }

    /// The box's centre.
    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// The length of the box's diagonal; 0 for an empty box.
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).length()
        }
    }

    /// Whether the boxes share a point (touching counts).
    pub fn overlaps(&self, o: &Bounds) -> bool {
        self.min.cmple(o.max).all() && o.min.cmple(self.max).all()
    }
}

impl Surface {
    /// A surface that reflects but does not emit.
    pub fn new(name: impl Into<String>, polygon: Vec<DVec3>, reflectance: Rgb) -> Surface {
        Surface {
            name: name.into(),
            polygon,
            emission: Rgb::ZERO,
            reflectance,
        }
    }

    /// The same surface emitting the exitance `emission` (W/m² per channel).
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

    /// The polygon's area.
    pub fn area(&self) -> f64 {
        0.5 * polygon::newell_normal(&self.polygon).length()
    }

    /// Emitted power per channel (exitance times area).
    pub fn emitted_power(&self) -> Rgb {
        self.emission * self.area()
    }

    /// The polygon's bounding box.
    pub fn bounds(&self) -> Bounds {
        Bounds::from_points(&self.polygon)
    }
}

impl Scene {
    /// The bounding box of every surface.
    pub fn bounds(&self) -> Bounds {
        self.surfaces
            .iter()
            .fold(Bounds::EMPTY, |b, s| b.union(s.bounds()))
    }

    /// The scene's length scale: every geometric tolerance is a multiple of it.
    pub fn diagonal(&self) -> f64 {
        self.bounds().diagonal()
    }

    /// The surfaces that emit, with their ids.
    pub fn emitters(&self) -> impl Iterator<Item = (SurfaceId, &Surface)> {
        self.surfaces
            .iter()
            .enumerate()
            .filter(|(_, s)| s.is_emitter())
    }

    /// The power all emitters give out per channel (exitance times area, summed).
    pub fn emitted_power(&self) -> Rgb {
        self.surfaces.iter().map(Surface::emitted_power).sum()
    }

    /// The sum of the surfaces' areas.
    pub fn total_area(&self) -> f64 {
        self.surfaces.iter().map(Surface::area).sum()
    }

    /// The id of the first surface called `name`.
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
