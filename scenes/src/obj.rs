//! OBJ+MTL import: each face becomes a surface, `Kd` its reflectance and `Ke` its emission.
//!
//! Exported meshes are rarely clean. Repairs that cannot change the lighting are made and listed
//! as warnings: repeated vertices are merged, zero-area faces dropped, and non-planar faces split
//! into triangles. Anything else is left for validation to report.

use std::path::Path;

use glam::DVec3;

use crate::color::Rgb;
use crate::error::SceneError;
use crate::model::{Scene, Surface};
use crate::polygon;
use crate::validate::{MIN_THINNESS, PLANARITY_TOLERANCE};

/// Reflectance of faces without a material.
pub const DEFAULT_REFLECTANCE: f64 = 0.5;

/// Reads an OBJ file and the MTL files it names (beside it).
pub fn read_obj(path: &Path) -> Result<(Scene, Vec<String>), SceneError> {
    let file = std::fs::File::open(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    parse_obj(&mut std::io::BufReader::new(file), path, |mtl| {
        let text = std::fs::read(dir.join(mtl)).map_err(|_| tobj::LoadError::OpenFileFailed)?;
        load_mtl(&String::from_utf8_lossy(&text))
    })
}

/// Parses MTL text. tobj panics on a colour with fewer than three numbers, so such lines are
/// refused here first.
fn load_mtl(text: &str) -> tobj::MTLLoadResult {
    for line in text.lines() {
        let mut words = line.split_whitespace();
        if matches!(words.next(), Some("Ka" | "Kd" | "Ks" | "Ke")) && words.count() < 3 {
            return Err(tobj::LoadError::MaterialParseError);
        }
    }
    tobj::load_mtl_buf(&mut text.as_bytes())
}

/// Parses OBJ text; every `mtllib` it names reads as `mtl`. `path` only names the source.
pub fn parse_obj_text(
    obj: &str,
    mtl: &str,
    path: &Path,
) -> Result<(Scene, Vec<String>), SceneError> {
    parse_obj(&mut obj.as_bytes(), path, |_| load_mtl(mtl))
}

fn parse_obj(
    reader: &mut impl std::io::BufRead,
    path: &Path,
    load_mtl: impl Fn(&Path) -> tobj::MTLLoadResult,
) -> Result<(Scene, Vec<String>), SceneError> {
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, materials) =
        tobj::load_obj_buf(reader, &options, load_mtl).map_err(|e| SceneError::Obj {
            path: path.to_path_buf(),
            message: format!("{e}; check the file is a valid OBJ"),
        })?;
    let mut warnings = Vec::new();
    let materials = materials.unwrap_or_else(|e| {
        warnings.push(format!(
            "materials could not be read ({e}); faces get reflectance {DEFAULT_REFLECTANCE} and no emission"
        ));
        Vec::new()
    });

    let mut faces = Vec::new();
    let mut missing_material = 0usize;
    for model in &models {
        let mesh = &model.mesh;
        let position = |i: u32| {
            let i = i as usize * 3;
            DVec3::new(
                mesh.positions[i],
                mesh.positions[i + 1],
                mesh.positions[i + 2],
            )
        };
        let (reflectance, emission) = match mesh.material_id.and_then(|m| materials.get(m)) {
            Some(m) => (
                m.diffuse
                    .map(Rgb::from)
                    .unwrap_or(Rgb::splat(DEFAULT_REFLECTANCE)),
                m.emissive.map(Rgb::from).unwrap_or(Rgb::ZERO),
            ),
            None => {
                missing_material += 1;
                (Rgb::splat(DEFAULT_REFLECTANCE), Rgb::ZERO)
            }
        };
        let arities: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        let mut start = 0;
        for (face_index, arity) in arities.into_iter().enumerate() {
            let Some(indices) = mesh.indices.get(start..start + arity) else {
                break;
            };
            start += arity;
            let name = if model.name.is_empty() {
                format!("face{face_index}")
            } else {
                format!("{}/{face_index}", model.name)
            };
            faces.push((
                name,
                indices.iter().map(|&i| position(i)).collect::<Vec<_>>(),
                reflectance,
                emission,
            ));
        }
    }
    if missing_material > 0 {
        warnings.push(format!(
            "{missing_material} object(s) have no material; they get reflectance {DEFAULT_REFLECTANCE} and no emission"
        ));
    }

    let mut surfaces = Vec::new();
    let (mut merged, mut dropped, mut split) = (0usize, 0usize, 0usize);
    for (name, mut polygon, reflectance, emission) in faces {
        let before = polygon.len();
        crate::load::drop_repeated_vertices(&mut polygon);
        merged += before - polygon.len();
        let diameter = polygon::diameter(&polygon);
        let area = 0.5 * polygon::newell_normal(&polygon).length();
        if polygon.len() < 3 || !(area >= MIN_THINNESS * diameter * diameter) {
            dropped += 1;
            continue;
        }
        let pieces = if is_planar(&polygon, diameter) {
            vec![polygon]
        } else {
            split += 1;
            split_into_triangles(&polygon)
        };
        let count = pieces.len();
        for (k, piece) in pieces.into_iter().enumerate() {
            let name = if count == 1 {
                name.clone()
            } else {
                format!("{name}.{k}")
            };
            surfaces.push(Surface {
                name,
                polygon: piece,
                emission,
                reflectance,
            });
        }
    }
    if merged > 0 {
        warnings.push(format!("merged {merged} repeated vertices"));
    }
    if dropped > 0 {
        warnings.push(format!("dropped {dropped} faces with zero area"));
    }
    if split > 0 {
        warnings.push(format!("split {split} non-planar faces into triangles"));
    }
    let name = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene")
        .to_string();
    Ok((
        Scene {
            name,
            camera: None,
            surfaces,
        },
        warnings,
    ))
}

fn is_planar(polygon: &[DVec3], diameter: f64) -> bool {
    let normal = polygon::newell_normal(polygon).normalize_or_zero();
    let centroid = polygon::centroid(polygon);
    polygon
        .iter()
        .all(|&p| (p - centroid).dot(normal).abs() <= PLANARITY_TOLERANCE * diameter)
}

/// A fan from the vertex that gives the most even triangles; for quads, the shorter diagonal.
fn split_into_triangles(polygon: &[DVec3]) -> Vec<Vec<DVec3>> {
    let n = polygon.len();
    let apex = if n == 4 && polygon[1].distance(polygon[3]) < polygon[0].distance(polygon[2]) {
        1
    } else {
        0
    };
    (1..n - 1)
        .map(|k| {
            vec![
                polygon[apex],
                polygon[(apex + k) % n],
                polygon[(apex + k + 1) % n],
            ]
        })
        .collect()
}
