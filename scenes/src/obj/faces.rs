//! tobj's models as named faces.
//!
//! tobj splits an object at every change of material into models of the same name, so a face is
//! named `object/material/index`: `index` counts the faces of that object and material in file
//! order. Names are therefore unique and stable: they do not depend on whether the material
//! library was found (the material is named as `usemtl` wrote it), nor on other objects.

use std::collections::HashMap;

use glam::DVec3;

use super::source_lines::SourceLines;
use crate::mesh_file::repair::Face;
use crate::mesh_file::tally::{FaceSource, Tally};

/// The material segment of names of faces that no `usemtl` covers.
const NO_MATERIAL: &str = "no-material";

/// The faces of an OBJ file, and the faces left out or left bare.
#[derive(Debug, Default)]
pub(crate) struct Collected {
    pub faces: Vec<Face>,
    /// `l` statements of three or more points: tobj reads them as faces, but a polyline is not
    /// a surface, so they are left out.
    pub polylines: Tally,
    /// Faces without a material the libraries define.
    pub without_material: Tally,
}

pub(crate) fn collect_faces(
    models: &[tobj::Model],
    materials: &[tobj::Material],
    lines: &SourceLines,
) -> Collected {
    let total: usize = models.iter().map(|m| arities(&m.mesh).len()).sum();
    // Line numbers only when the scan saw the faces tobj saw; otherwise none rather than wrong.
    let lines_agree = total == lines.faces.len();
    let mut collected = Collected::default();
    let mut counters: HashMap<(&str, &str), usize> = HashMap::new();
    let mut tobj_index = 0;
    for model in models {
        let mesh = &model.mesh;
        let material = mesh.material_id.filter(|&m| m < materials.len());
        let mut start = 0;
        for arity in arities(mesh) {
            let Some(indices) = mesh.indices.get(start..start + arity) else {
                break;
            };
            start += arity;
            let at = lines.face(tobj_index).filter(|_| lines_agree);
            tobj_index += 1;
            let material_name = at
                .and_then(|f| f.material)
                .and_then(|m| lines.materials_used.get(m))
                .map(|(name, _)| name.as_str())
                .or_else(|| material.map(|m| materials[m].name.as_str()))
                .unwrap_or(NO_MATERIAL);
            let counter = counters.entry((&model.name, material_name)).or_insert(0);
            let source = FaceSource {
                name: format!("{}/{material_name}/{counter}", model.name),
                line: at.map(|f| f.line),
            };
            *counter += 1;
            if at.is_some_and(|f| f.polyline) {
                collected.polylines.note(&source);
                continue;
            }
            if material.is_none() {
                collected.without_material.note(&source);
            }
            collected.faces.push(Face {
                source,
                polygon: indices.iter().map(|&i| position(mesh, i)).collect(),
                material,
            });
        }
    }
    collected
}

/// Corners per face; tobj leaves `face_arities` empty when every face is a triangle.
fn arities(mesh: &tobj::Mesh) -> Vec<usize> {
    if mesh.face_arities.is_empty() {
        vec![3; mesh.indices.len() / 3]
    } else {
        mesh.face_arities.iter().map(|&a| a as usize).collect()
    }
}

/// A corner's position; an index past the end (tobj checks, so never) reads as NaN, which
/// validation reports rather than this panicking.
fn position(mesh: &tobj::Mesh, index: u32) -> DVec3 {
    let i = index as usize * 3;
    match mesh.positions.get(i..i + 3) {
        Some(p) => DVec3::new(p[0], p[1], p[2]),
        None => DVec3::NAN,
    }
}
