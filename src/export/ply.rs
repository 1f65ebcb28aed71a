//! `solution.ply`: binary little-endian PLY, which MeshLab and Blender read.
//!
//! Each vertex has its position (`double` x, y, z), its colour as `render.png` shows it
//! (`uchar` red, green, blue) and its `quality`: the luminance of its radiosity (`double`,
//! Rec. 709), which MeshLab maps to colour and filters by. Each face has its three
//! `vertex_indices` and its `surface` (the index in `solution.json`).

use penumbra_scenes::Rgb;
use ply_rs_bw::ply::{
    Addable, ElementDef, Encoding, Header, PropertyAccess, PropertyDef, PropertyType, ScalarType,
};
use ply_rs_bw::writer::Writer;

use super::mesh::FlatMesh;
use super::{Display, ExportError};

struct Vertex {
    position: [f64; 3],
    colour: [u8; 3],
    quality: f64,
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex {
            position: [0.0; 3],
            colour: [0; 3],
            quality: 0.0,
        }
    }

    fn get_double(&self, name: &str) -> Option<f64> {
        match name {
            "x" => Some(self.position[0]),
            "y" => Some(self.position[1]),
            "z" => Some(self.position[2]),
            "quality" => Some(self.quality),
            _ => None,
        }
    }

    fn get_uchar(&self, name: &str) -> Option<u8> {
        match name {
            "red" => Some(self.colour[0]),
            "green" => Some(self.colour[1]),
            "blue" => Some(self.colour[2]),
            _ => None,
        }
    }
}

struct Face {
    corners: [i32; 3],
    surface: i32,
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Face {
            corners: [0; 3],
            surface: 0,
        }
    }

    fn get_list_int(&self, name: &str) -> Option<&[i32]> {
        (name == "vertex_indices").then_some(&self.corners[..])
    }

    fn get_int(&self, name: &str) -> Option<i32> {
        (name == "surface").then_some(self.surface)
    }
}

fn element(name: &str, count: usize, properties: &[(&str, PropertyType)]) -> ElementDef {
    let mut e = ElementDef::new(name.to_owned());
    e.count = count;
    for (name, kind) in properties {
        e.properties
            .add(PropertyDef::new((*name).to_owned(), kind.clone()));
    }
    e
}

/// The file's bytes.
pub fn ply(mesh: &FlatMesh, display: &Display) -> Result<Vec<u8>, ExportError> {
    let too_large = |reason: String| ExportError::TooLarge {
        format: "PLY",
        reason,
    };
    let index = |i: u32| i32::try_from(i).map_err(|_| too_large(format!("vertex index {i}")));
    let vertices: Vec<Vertex> = (0..mesh.positions.len())
        .map(|v| Vertex {
            position: mesh.positions[v],
            colour: display.srgb8(mesh.radiosity[v], mesh.reflectance_at(v)),
            quality: penumbra_viz::luminance(Rgb::from(mesh.radiosity[v])),
        })
        .collect();
    let faces = mesh
        .triangles
        .iter()
        .zip(&mesh.triangle_surface)
        .map(|(t, &s)| {
            Ok(Face {
                corners: [index(t[0])?, index(t[1])?, index(t[2])?],
                surface: index(s)?,
            })
        })
        .collect::<Result<Vec<Face>, ExportError>>()?;
    let header = header(vertices.len(), faces.len());
    let mut out = Vec::new();
    // Writing to memory fails only on a header that does not match its payload: a bug here.
    let failed = |e: std::io::Error| ExportError::Encode {
        format: "PLY",
        reason: e.to_string(),
    };
    let vertex_writer = Writer::<Vertex>::new();
    vertex_writer
        .write_header(&mut out, &header)
        .map_err(failed)?;
    vertex_writer
        .write_payload_of_element(&mut out, &vertices, &header.elements["vertex"], &header)
        .map_err(failed)?;
    Writer::<Face>::new()
        .write_payload_of_element(&mut out, &faces, &header.elements["face"], &header)
        .map_err(failed)?;
    Ok(out)
}

/// The header: binary little endian, the vertex and face elements and what they hold.
fn header(vertices: usize, faces: usize) -> Header {
    let double = PropertyType::Scalar(ScalarType::Double);
    let uchar = PropertyType::Scalar(ScalarType::UChar);
    let mut header = Header::new();
    header.encoding = Encoding::BinaryLittleEndian;
    header.comments.push(
        "penumbra solution: colour as render.png shows it, quality = luminance of the \
         radiosity in W/m^2"
            .into(),
    );
    header.elements.add(element(
        "vertex",
        vertices,
        &[
            ("x", double.clone()),
            ("y", double.clone()),
            ("z", double.clone()),
            ("red", uchar.clone()),
            ("green", uchar.clone()),
            ("blue", uchar),
            ("quality", double),
        ],
    ));
    header.elements.add(element(
        "face",
        faces,
        &[
            (
                "vertex_indices",
                PropertyType::List(ScalarType::UChar, ScalarType::Int),
            ),
            ("surface", PropertyType::Scalar(ScalarType::Int)),
        ],
    ));
    header
}
