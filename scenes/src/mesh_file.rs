//! Faces read from a mesh file (OBJ, glTF) made into surfaces: repaired where that cannot change
//! the lighting ([`repair`]), coplanar neighbours of one material merged
//! ([`crate::coplanar`]), names made unique, each step counted for a warning ([`tally`]).

pub(crate) mod repair;
pub(crate) mod tally;

use std::collections::HashSet;

use crate::color::Rgb;
use crate::coplanar::merge_coplanar;
use crate::model::{Bounds, Surface};
use repair::{Face, Repairs, repair_face};
use tally::{FaceSource, Tally, thousands};

/// What a format says of a material: its reflectance and emission (exitance, W/m²), by the
/// index a [`Face`] holds, or for faces without one.
pub(crate) type MaterialOf<'a> = dyn Fn(Option<usize>) -> (Rgb, Rgb) + 'a;

/// The surfaces of `faces` and the warnings saying what was repaired, merged or renamed; between
/// the repairs' and the merge's warnings come `material_warnings` of the materials the repaired
/// faces use (their indices, ascending).
pub(crate) fn into_surfaces(
    faces: Vec<Face>,
    merge_coplanar: bool,
    material_of: &MaterialOf,
    material_warnings: impl FnOnce(&[usize]) -> Vec<String>,
) -> (Vec<Surface>, Vec<String>) {
    let scene_diagonal = finite_diagonal(&faces);
    let (faces, mut warnings) = repaired_faces(faces, scene_diagonal);
    let mut used: Vec<usize> = faces.iter().filter_map(|f| f.material).collect();
    used.sort_unstable();
    used.dedup();
    warnings.extend(material_warnings(&used));
    let (surfaces, summary) = if merge_coplanar {
        merged_surfaces(&faces, scene_diagonal, material_of)
    } else {
        unmerged_surfaces(&faces, material_of)
    };
    warnings.extend(summary);
    let (surfaces, renamed) = unique_names(surfaces);
    warnings.extend(renamed);
    (surfaces, warnings)
}

/// The diagonal of the box around the faces whose corners are all finite: a corner that is not
/// is validation's to refuse, and must not make the scene's scale infinite.
fn finite_diagonal(faces: &[Face]) -> f64 {
    Bounds::from_points(
        faces
            .iter()
            .filter(|f| f.polygon.iter().all(|p| p.is_finite()))
            .flat_map(|f| &f.polygon),
    )
    .diagonal()
}

/// `faces` repaired ([`repair_face`]), and the warnings saying what was repaired.
fn repaired_faces(faces: Vec<Face>, scene_diagonal: f64) -> (Vec<Face>, Vec<String>) {
    let mut repairs = Repairs::default();
    let faces = faces
        .into_iter()
        .flat_map(|f| repair_face(f, scene_diagonal, &mut repairs))
        .collect();
    (faces, repairs.warnings())
}

/// A face as a surface of the given polygon, named after the face.
fn surface(face: &Face, polygon: Vec<glam::DVec3>, material_of: &MaterialOf) -> Surface {
    let (reflectance, emission) = material_of(face.material);
    Surface {
        name: face.source.name.clone(),
        polygon,
        emission,
        reflectance,
    }
}

/// Every face as a surface of its own, and a line saying merging was off.
fn unmerged_surfaces(faces: &[Face], material_of: &MaterialOf) -> (Vec<Surface>, Option<String>) {
    let line = (!faces.is_empty()).then(|| {
        "coplanar faces were not merged (merging is off): every face is a surface".to_string()
    });
    let surfaces = faces
        .iter()
        .map(|f| surface(f, f.polygon.clone(), material_of))
        .collect();
    (surfaces, line)
}

/// The surfaces of `faces` with coplanar neighbours of one material merged, and a line saying
/// what was merged.
fn merged_surfaces(
    faces: &[Face],
    scene_diagonal: f64,
    material_of: &MaterialOf,
) -> (Vec<Surface>, Option<String>) {
    let polygons: Vec<_> = faces.iter().map(|f| f.polygon.clone()).collect();
    let groups: Vec<usize> = faces
        .iter()
        .map(|f| f.material.map_or(0, |m| m + 1))
        .collect();
    let (pieces, summary) = merge_coplanar(&polygons, &groups, scene_diagonal);
    let surfaces = pieces
        .into_iter()
        .filter_map(|piece| {
            let first = &faces[*piece.faces.first()?];
            Some(surface(first, piece.polygon, material_of))
        })
        .collect();
    let line = (summary.merged_faces > 0).then(|| {
        let mut line = format!(
            "merged {} coplanar faces into {} surfaces",
            thousands(summary.merged_faces),
            thousands(summary.merged_surfaces)
        );
        if summary.split_regions > 0 {
            line += &format!(
                "; {} regions of coplanar faces stay in several pieces (one polygon would have holes or \
                 touch itself)",
                thousands(summary.split_regions)
            );
        }
        line
    });
    (surfaces, line)
}

/// Surfaces with unique names: a name already taken (object or material names with `/` can
/// collide) gets `#2`, `#3`, ... appended.
fn unique_names(mut surfaces: Vec<Surface>) -> (Vec<Surface>, Option<String>) {
    let mut taken: HashSet<String> = surfaces.iter().map(|s| s.name.clone()).collect();
    if taken.len() == surfaces.len() {
        return (surfaces, None);
    }
    let mut seen: HashSet<String> = HashSet::new();
    let mut renamed = Tally::default();
    for surface in &mut surfaces {
        if seen.insert(surface.name.clone()) {
            continue;
        }
        let mut k = 2;
        while taken.contains(&format!("{}#{k}", surface.name)) {
            k += 1;
        }
        surface.name = format!("{}#{k}", surface.name);
        taken.insert(surface.name.clone());
        seen.insert(surface.name.clone());
        renamed.note(&FaceSource {
            name: surface.name.clone(),
            line: None,
        });
    }
    (
        surfaces,
        renamed.describe("renamed", "surfaces whose names were taken"),
    )
}
