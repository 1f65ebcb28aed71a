//! `solution.obj` and `solution.mtl`: geometry and per-surface materials, for any tool.
//!
//! One object per surface, with its material: `Kd` its reflectance, `Ke` its emission. Each
//! vertex carries its colour as `render.png` shows it, in the common `v x y z r g b` extension
//! (MeshLab and Blender read it; sRGB values in [0, 1]). Positions are written in full
//! (shortest round-trip decimals). The discontinuity segments follow as line elements (`l`),
//! one object per class (D0, D1, D2), their vertices coloured by boundary.

use std::fmt::Write as _;

use crate::outputs::SurfaceSolution;

use super::mesh::FlatMesh;
use super::{Display, line_colour};

/// The material of the discontinuity lines.
const LINE_MATERIAL: &str = "discontinuity_lines";

/// `solution.obj` and `solution.mtl`.
pub fn obj(mesh: &FlatMesh, surfaces: &[SurfaceSolution], display: &Display) -> (String, String) {
    let mut obj = String::from("# penumbra solution: vertex colours as render.png shows them\n");
    obj += "mtllib solution.mtl\n";
    let mut mtl = String::from("# penumbra solution: each surface's reflectance and emission\n");
    for (s, surface) in surfaces.iter().enumerate() {
        let material = crate::outputs::file_safe_name(s, &surface.name);
        let _ = writeln!(obj, "o {material}\nusemtl {material}");
        for v in mesh.vertex_offsets[s]..mesh.vertex_offsets[s + 1] {
            let [x, y, z] = mesh.positions[v];
            let colour = display.srgb8(mesh.radiosity[v], mesh.reflectance_at(v));
            vertex(&mut obj, [x, y, z], colour);
        }
        for t in &mesh.triangles[mesh.triangle_offsets[s]..mesh.triangle_offsets[s + 1]] {
            let [a, b, c] = t.map(|i| u64::from(i) + 1);
            let _ = writeln!(obj, "f {a} {b} {c}");
        }
        let rgb = |c: Option<[f64; 3]>| {
            let [r, g, b] = c.unwrap_or_default();
            format!("{r} {g} {b}")
        };
        let _ = writeln!(
            mtl,
            "\nnewmtl {material}\nKd {}\nKe {}\nKa 0 0 0\nKs 0 0 0\nillum 1",
            rgb(surface.reflectance),
            rgb(surface.emission)
        );
    }
    if !mesh.lines.is_empty() {
        // The lines' colours are their vertices'; a material of their own keeps them from
        // taking the last surface's.
        mtl += &format!("\nnewmtl {LINE_MATERIAL}\nKd 1 1 1\nKa 0 0 0\nKs 0 0 0\nillum 0\n");
    }
    let mut next = mesh.positions.len() as u64 + 1;
    for (class, lines) in mesh.lines_by_class() {
        let _ = writeln!(obj, "o discontinuities_{class}\nusemtl {LINE_MATERIAL}");
        for line in &lines {
            let colour = line_colour(line);
            for end in line.ends {
                vertex(&mut obj, end, colour);
            }
        }
        for _ in &lines {
            let _ = writeln!(obj, "l {} {}", next, next + 1);
            next += 2;
        }
    }
    (obj, mtl)
}

/// `v x y z r g b`, the colour in [0, 1].
fn vertex(obj: &mut String, [x, y, z]: [f64; 3], colour: [u8; 3]) {
    let [r, g, b] = colour.map(|c| f64::from(c) / 255.0);
    let _ = writeln!(obj, "v {x} {y} {z} {r:.6} {g:.6} {b:.6}");
}
