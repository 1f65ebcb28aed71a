//! Arbitrary bytes turned into scene input, shared by the fuzz targets (`fuzz/`) and the seeded
//! property tests that run the same generators in the normal test command. Hidden from the
//! documentation: support for those, not part of the crate's API.

use std::path::Path;

use glam::DVec3;

use crate::color::Rgb;
use crate::model::{Scene, Surface};
use crate::{Problem, SceneError};

/// Parses `data` as a scene file by its first byte modulo 3: JSON, OBJ (with an MTL after the
/// first NUL byte) or glTF (JSON or GLB, its buffers inline), then validates it. Any input may
/// be rejected; the result says how.
pub fn parse_any(data: &[u8]) -> Result<Vec<Problem>, SceneError> {
    let Some((&kind, rest)) = data.split_first() else {
        return Ok(Vec::new());
    };
    let text = String::from_utf8_lossy(rest);
    let scene = match kind % 3 {
        0 => crate::load::parse_json(&text, Path::new("fuzz.json"))?,
        1 => {
            let (obj, mtl) = text.split_once('\0').unwrap_or((&text, ""));
            crate::obj::parse_obj_text(obj, mtl, Path::new("fuzz.obj"))?.0
        }
        _ => {
            // Buffers named by a path are looked for where there are none.
            let nowhere = Path::new("/nonexistent/penumbra-fuzz");
            crate::gltf_file::parse_gltf(rest, nowhere, "fuzz", &Default::default())
                .map_err(|message| SceneError::Gltf {
                    path: "fuzz.glb".into(),
                    message,
                })?
                .0
        }
    };
    Ok(crate::validate(&scene))
}

/// A small scene from `data`: up to six polygons, the first of them emitting, each a rectangle
/// (planar by construction) or a triangle, on a coarse grid so that touching, coplanar and
/// crossing polygons are common, at a scale from 1e-3 to 1e3. `None` when `data` is too short.
pub fn scene_from_bytes(data: &[u8]) -> Option<Scene> {
    let (&head, rest) = data.split_first()?;
    let scale = 10f64.powi(i32::from(head % 7) - 3);
    let count = 1 + usize::from(head / 7 % 6);
    // Grid coordinates in [-2, 2], 16 steps.
    let coordinate = |b: u8| (f64::from(b % 17) / 4.0 - 2.0) * scale;
    let point = |b: &[u8]| DVec3::new(coordinate(b[0]), coordinate(b[1]), coordinate(b[2]));
    let mut surfaces = Vec::new();
    for (i, c) in rest.chunks_exact(11).take(count).enumerate() {
        let polygon = if c[0] % 2 == 0 {
            vec![point(&c[1..4]), point(&c[4..7]), point(&c[7..10])]
        } else {
            // A rectangle: a corner, one side, and the other side made square to it.
            let corner = point(&c[1..4]);
            let side = point(&c[4..7]);
            let other = point(&c[7..10]);
            let other =
                other - side * (other.dot(side) / side.length_squared().max(f64::MIN_POSITIVE));
            vec![corner, corner + side, corner + side + other, corner + other]
        };
        let reflectance = f64::from(c[10] % 20) / 20.0;
        let mut surface = Surface::new(format!("s{i}"), polygon, Rgb::splat(reflectance));
        if i == 0 {
            surface = surface.with_emission(Rgb::splat(1.0 + f64::from(c[10] % 10)));
        }
        surfaces.push(surface);
    }
    (!surfaces.is_empty()).then(|| Scene {
        up: None,
        unit: None,
        name: "fuzz".into(),
        camera: None,
        surfaces,
    })
}
