//! Scenes after the analytic test cases of CIE 171:2006 ("Test cases to assess the accuracy of
//! lighting computer programs") that fit diffuse polygon scenes. Units are metres and lumens, so
//! irradiance is illuminance in lux and exitance is in lm/m².
//!
//! - 5.3, an area source: a 1 m square Lambertian source in the middle of the ceiling of a
//!   4 m × 4 m × 3 m room with black surfaces; the illuminance it gives at floor and wall points.
//! - 5.6, diffuse reflection: the floor of the same room, uniformly lit, reflects onto the walls
//!   and the ceiling (black); a uniformly lit Lambertian floor is a uniform emitter of exitance
//!   ρ E, which is how it is modelled.
//! - 5.8, inter-reflection: a 4 m cube whose faces all reflect ρ, lit by a point source of
//!   10,000 lm at its centre, modelled as a small emitting box (2 cm, black); the reflected
//!   illuminance is Φ ρ / (S (1 − ρ)) with S = 96 m² the cube's area.
//!
//! The references are closed forms of the geometry (corner-rectangle form factors, and for 5.8
//! the flux balance of an enclosure); the test cases in `tests/cie.rs` hold the solver to them
//! with the CIE's pass criteria.

use glam::DVec3;

use crate::color::Rgb;
use crate::model::{Camera, Scene, Surface};

/// The rooms of 5.3 and 5.6: x and y in [0, 4], z in [0, 3].
pub const ROOM: DVec3 = DVec3::new(4.0, 4.0, 3.0);
/// 5.3: the side of the square source, in metres.
pub const SOURCE_SIDE: f64 = 1.0;
/// 5.3: the source's exitance in lm/m² (a luminance of 1000 cd/m², times π).
pub const SOURCE_EXITANCE: f64 = std::f64::consts::PI * 1000.0;
/// 5.6: the floor's exitance ρ E: reflectance 0.5 under a uniform 1,000 lux.
pub const FLOOR_EXITANCE: f64 = 500.0;
/// 5.8: the cube's side, in metres.
pub const CUBE_SIDE: f64 = 4.0;
/// 5.8: the point source's flux in lumens.
pub const CUBE_FLUX: f64 = 10_000.0;
/// 5.8: the side of the small emitting box that stands in for the point source, in metres.
pub const SOURCE_BOX: f64 = 0.02;

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// An axis-aligned rectangle `lo..hi` (flat along one axis), its front toward `toward`.
fn rect(name: &str, lo: DVec3, hi: DVec3, toward: DVec3, reflectance: f64) -> Surface {
    let d = hi - lo;
    let flat = if d.x == 0.0 {
        0
    } else if d.y == 0.0 {
        1
    } else {
        2
    };
    let (a, b) = match flat {
        0 => (v(0.0, d.y, 0.0), v(0.0, 0.0, d.z)),
        1 => (v(d.x, 0.0, 0.0), v(0.0, 0.0, d.z)),
        _ => (v(d.x, 0.0, 0.0), v(0.0, d.y, 0.0)),
    };
    let mut polygon = vec![lo, lo + a, lo + a + b, lo + b];
    let n = a.cross(b);
    if n.dot(toward - lo) < 0.0 {
        polygon.reverse();
    }
    Surface::new(name, polygon, Rgb::splat(reflectance))
}

/// The six faces of the box `[0, size]`, facing in, each reflecting `reflectance`; the ceiling
/// left out when `ceiling` is false.
fn room_faces(size: DVec3, reflectance: f64, ceiling: bool) -> Vec<Surface> {
    let c = size / 2.0;
    let (x, y, z) = (size.x, size.y, size.z);
    let mut faces = vec![
        rect("floor", v(0.0, 0.0, 0.0), v(x, y, 0.0), c, reflectance),
        rect("wall_x0", v(0.0, 0.0, 0.0), v(0.0, y, z), c, reflectance),
        rect("wall_x1", v(x, 0.0, 0.0), v(x, y, z), c, reflectance),
        rect("wall_y0", v(0.0, 0.0, 0.0), v(x, 0.0, z), c, reflectance),
        rect("wall_y1", v(0.0, y, 0.0), v(x, y, z), c, reflectance),
    ];
    if ceiling {
        faces.push(rect("ceiling", v(0.0, 0.0, z), v(x, y, z), c, reflectance));
    }
    faces
}

fn camera(size: DVec3) -> Camera {
    Camera {
        eye: v(size.x * 0.5, 0.05 * size.y, size.z * 0.5),
        target: v(size.x * 0.5, size.y, size.z * 0.45),
        up: v(0.0, 0.0, 1.0),
        fov_deg: 100.0,
    }
}

/// 5.3: the 1 m square source fills a hole in the middle of the ceiling (the ceiling is the four
/// rectangles around it), facing down; every surface is black.
pub fn area_source() -> Scene {
    let (x, y, z) = (ROOM.x, ROOM.y, ROOM.z);
    let (s0, s1) = ((x - SOURCE_SIDE) / 2.0, (x + SOURCE_SIDE) / 2.0);
    let (t0, t1) = ((y - SOURCE_SIDE) / 2.0, (y + SOURCE_SIDE) / 2.0);
    let down = v(x / 2.0, y / 2.0, 0.0);
    let mut surfaces = room_faces(ROOM, 0.0, false);
    surfaces.extend([
        rect("ceiling_x0", v(0.0, 0.0, z), v(s0, y, z), down, 0.0),
        rect("ceiling_x1", v(s1, 0.0, z), v(x, y, z), down, 0.0),
        rect("ceiling_y0", v(s0, 0.0, z), v(s1, t0, z), down, 0.0),
        rect("ceiling_y1", v(s0, t1, z), v(s1, y, z), down, 0.0),
        rect("source", v(s0, t0, z), v(s1, t1, z), down, 0.0)
            .with_emission(Rgb::splat(SOURCE_EXITANCE)),
    ]);
    Scene {
        up: None,
        unit: None,
        name: "cie-5.3".into(),
        camera: Some(camera(ROOM)),
        surfaces,
    }
}

/// 5.6: the floor, a uniformly lit diffuse reflector, is a uniform emitter of exitance
/// [`FLOOR_EXITANCE`]; the walls and the ceiling are black.
pub fn floor_reflection() -> Scene {
    let mut surfaces = room_faces(ROOM, 0.0, true);
    surfaces[0].emission = Rgb::splat(FLOOR_EXITANCE);
    Scene {
        up: None,
        unit: None,
        name: "cie-5.6".into(),
        camera: Some(camera(ROOM)),
        surfaces,
    }
}

/// 5.8: the 4 m cube, every face reflecting `reflectance`, and at its centre a black box of side
/// [`SOURCE_BOX`] whose six faces emit [`CUBE_FLUX`] in all.
pub fn reflecting_cube(reflectance: f64) -> Scene {
    let size = DVec3::splat(CUBE_SIDE);
    let mut surfaces = room_faces(size, reflectance, true);
    let (lo, hi) = (size / 2.0 - SOURCE_BOX / 2.0, size / 2.0 + SOURCE_BOX / 2.0);
    let exitance = CUBE_FLUX / (6.0 * SOURCE_BOX * SOURCE_BOX);
    let centre = size / 2.0;
    // Each face of the small box faces away from its centre: toward a point just outside it.
    for axis in 0..3 {
        for (side, sign) in [(0, -1.0), (1, 1.0)] {
            let (mut a, mut b) = (lo, hi);
            a[axis] = if side == 0 { lo[axis] } else { hi[axis] };
            b[axis] = a[axis];
            let mut out = DVec3::ZERO;
            out[axis] = sign;
            let name = format!("source_{}{side}", ["x", "y", "z"][axis]);
            surfaces.push(
                rect(&name, a, b, centre + out * SOURCE_BOX, 0.0)
                    .with_emission(Rgb::splat(exitance)),
            );
        }
    }
    Scene {
        up: None,
        unit: None,
        name: "cie-5.8".into(),
        camera: Some(camera(size)),
        surfaces,
    }
}

/// 5.8's reference: the mean reflected illuminance of an enclosure whose surfaces (area `S`)
/// all reflect ρ, lit by Φ: Φ ρ / (S (1 − ρ)). Every lumen is absorbed in the end, and
/// (1 − ρ) × the mean total illuminance × S = Φ.
pub fn reflected_illuminance(flux: f64, area: f64, reflectance: f64) -> f64 {
    flux * reflectance / (area * (1.0 - reflectance))
}
