//! `solution.glb`: glTF 2.0 binary, which browsers (three.js, Babylon.js) and Blender read.
//!
//! A node per object of the scene, named as it: the surfaces' names up to their last two `/`
//! (OBJ and glTF surfaces are named `object/material/index`), or a surface's whole name. Each
//! holds an unlit mesh (`KHR_materials_unlit`) of its surfaces: positions, normals and
//! `COLOR_0`, the linear display value of `render.png` ((radiosity + ρ·ambient) × exposure,
//! clamped to [0, 1]: a glTF viewer's sRGB output then shows the render's colours), and the
//! light in W/m²: `_RADIOSITY`, its `_DIRECT` part (ρ·H of the light straight from the
//! emitters) and `_INDIRECT` (the rest of the reflected light). Then one mesh of discontinuity
//! lines, a `LINES` primitive per class (D0, D1, D2: the derivative that jumps), coloured by
//! boundary as the SVGs are. Everything is in `f32` (glTF allows nothing wider), in the scene's
//! coordinates, under one root node that turns them into glTF's frame: the scene's up to +y,
//! and its unit to metres ([`Frame`]). A glTF scene's frame is glTF's, so its root node does
//! nothing and the export overlays the file it came from.

use std::collections::{BTreeMap, HashMap};

use glam::{DQuat, DVec3};
use penumbra_scenes::LengthUnit;

use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use json::{Index, Root};

use super::mesh::FlatMesh;
use super::{Display, ExportError, line_colour};

/// Where the scene stands in glTF's frame (metres, +y up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Which way is up in the scene; `None` keeps its axes.
    pub up: Option<DVec3>,
    /// The unit of its coordinates; `None` is metres.
    pub unit: Option<LengthUnit>,
}

impl Frame {
    /// The root node's rotation (the scene's up to +y) and uniform scale (to metres), each
    /// `None` where it would do nothing.
    fn transform(self) -> (Option<[f32; 4]>, Option<f32>) {
        let rotation = self
            .up
            .and_then(|u| u.try_normalize())
            .map(|u| DQuat::from_rotation_arc(u, DVec3::Y))
            .filter(|q| !q.abs_diff_eq(DQuat::IDENTITY, 0.0))
            .map(|q| q.as_quat().to_array());
        let scale = self.unit.map(|u| u.metres() as f32).filter(|&s| s != 1.0);
        (rotation, scale)
    }
}

/// The file's bytes: `names` are the surfaces', in the order of `mesh`.
pub fn glb(
    mesh: &FlatMesh,
    names: &[&str],
    display: &Display,
    frame: Frame,
) -> Result<Vec<u8>, ExportError> {
    let mut gltf = Builder::default();
    let material = gltf.unlit("surfaces");
    let mut nodes = Vec::new();
    for (object, surfaces) in objects(names) {
        let part = mesh.part(&surfaces);
        let primitive = surface_primitive(&mut gltf, &part, display, material);
        let object_mesh = gltf.mesh(object, vec![primitive]);
        nodes.push(gltf.node(object, object_mesh));
    }
    let mut classes = Vec::new();
    for (class, lines) in mesh.lines_by_class() {
        let positions: Vec<[f32; 3]> = lines
            .iter()
            .flat_map(|l| l.ends.map(|e| e.map(|c| c as f32)))
            .collect();
        let colours: Vec<[f32; 3]> = lines
            .iter()
            .flat_map(|l| {
                let c = line_colour(l);
                let linear = c.map(|v| srgb_decode(f64::from(v) / 255.0) as f32);
                [linear, linear]
            })
            .collect();
        let position = gltf.vec3(&positions, "POSITION", true);
        let colour = gltf.vec3(&colours, "COLOR_0", false);
        let material = gltf.unlit(&format!("discontinuities {class}"));
        classes.push(json::mesh::Primitive {
            attributes: BTreeMap::from([
                (Valid(json::mesh::Semantic::Positions), position),
                (Valid(json::mesh::Semantic::Colors(0)), colour),
            ]),
            extensions: None,
            extras: extras(&serde_json::json!({"class": class, "segments": lines.len()})),
            indices: None,
            material: Some(material),
            mode: Valid(json::mesh::Mode::Lines),
            targets: None,
        });
    }
    if !classes.is_empty() {
        let lines = gltf.mesh("discontinuities", classes);
        nodes.push(gltf.node("discontinuities", lines));
    }
    let (rotation, scale) = frame.transform();
    let root = gltf.root.push(json::Node {
        name: Some("penumbra solution".into()),
        children: Some(nodes),
        rotation: rotation.map(json::scene::UnitQuaternion),
        scale: scale.map(|s| [s; 3]),
        ..Default::default()
    });
    gltf.finish(vec![root])
}

/// The scene's objects in the order they first appear, each with its surfaces: an object is a
/// surface's name up to its last two `/` (`object/material/index`), or the whole name.
fn objects<'n>(names: &[&'n str]) -> Vec<(&'n str, Vec<usize>)> {
    let mut order: Vec<(&str, Vec<usize>)> = Vec::new();
    let mut index: HashMap<&str, usize> = HashMap::new();
    for (s, name) in names.iter().enumerate() {
        let object = match name.rsplitn(3, '/').nth(2) {
            Some(object) if !object.is_empty() => object,
            _ => name,
        };
        let k = *index.entry(object).or_insert_with(|| {
            order.push((object, Vec::new()));
            order.len() - 1
        });
        order[k].1.push(s);
    }
    order
}

/// The triangles of every surface of `mesh`, as one primitive.
fn surface_primitive(
    gltf: &mut Builder,
    mesh: &FlatMesh,
    display: &Display,
    material: Index<json::Material>,
) -> json::mesh::Primitive {
    let f32s = |v: &[f64; 3]| v.map(|c| c as f32);
    let positions: Vec<[f32; 3]> = mesh.positions.iter().map(f32s).collect();
    let normals = vertex_normals(mesh);
    let colours: Vec<[f32; 3]> = (0..mesh.positions.len())
        .map(|v| display.linear(mesh.radiosity[v], mesh.reflectance_at(v)))
        .map(|c| c.map(|c| c as f32))
        .collect();
    let radiosity: Vec<[f32; 3]> = mesh.radiosity.iter().map(f32s).collect();
    let direct: Vec<[f32; 3]> = mesh.direct.iter().map(f32s).collect();
    let indirect: Vec<[f32; 3]> = mesh.indirect.iter().map(f32s).collect();
    let attributes = BTreeMap::from([
        (
            Valid(json::mesh::Semantic::Positions),
            gltf.vec3(&positions, "POSITION", true),
        ),
        (
            Valid(json::mesh::Semantic::Normals),
            gltf.vec3(&normals, "NORMAL", false),
        ),
        (
            Valid(json::mesh::Semantic::Colors(0)),
            gltf.vec3(&colours, "COLOR_0", false),
        ),
        (
            Valid(json::mesh::Semantic::Extras("RADIOSITY".into())),
            gltf.vec3(&radiosity, "_RADIOSITY", false),
        ),
        (
            Valid(json::mesh::Semantic::Extras("DIRECT".into())),
            gltf.vec3(&direct, "_DIRECT", false),
        ),
        (
            Valid(json::mesh::Semantic::Extras("INDIRECT".into())),
            gltf.vec3(&indirect, "_INDIRECT", false),
        ),
    ]);
    let indices = gltf.indices(&mesh.triangles);
    json::mesh::Primitive {
        attributes,
        extensions: None,
        extras: None,
        indices: Some(indices),
        material: Some(material),
        mode: Valid(json::mesh::Mode::Triangles),
        targets: None,
    }
}

/// Each vertex's surface's normal (a surface is planar: the normal of its largest triangle),
/// `+z` for a surface without triangles.
fn vertex_normals(mesh: &FlatMesh) -> Vec<[f32; 3]> {
    let mut normals = Vec::with_capacity(mesh.positions.len());
    for s in 0..mesh.vertex_offsets.len() - 1 {
        let triangles = &mesh.triangles[mesh.triangle_offsets[s]..mesh.triangle_offsets[s + 1]];
        let p = |i: u32| DVec3::from_array(mesh.positions[i as usize]);
        let normal = triangles
            .iter()
            .map(|t| (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])))
            .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))
            .and_then(|n| n.try_normalize())
            .unwrap_or(DVec3::Z);
        let count = mesh.vertex_offsets[s + 1] - mesh.vertex_offsets[s];
        normals.extend(std::iter::repeat_n(normal.as_vec3().to_array(), count));
    }
    normals
}

/// The sRGB curve's inverse, for line colours given in sRGB.
fn srgb_decode(v: f64) -> f64 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn extras(value: &serde_json::Value) -> json::Extras {
    serde_json::value::to_raw_value(value).ok()
}

/// The document and its one binary buffer, built up together.
#[derive(Default)]
struct Builder {
    root: Root,
    bin: Vec<u8>,
}

impl Builder {
    /// A buffer view over `bytes`, appended to the buffer at a 4-byte boundary.
    fn view(&mut self, bytes: &[u8], target: json::buffer::Target) -> Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: Some(Valid(target)),
            extensions: None,
            extras: None,
        })
    }

    /// An accessor of `f32` triples; with bounds when `bounded` (glTF requires them for
    /// positions).
    fn vec3(&mut self, values: &[[f32; 3]], name: &str, bounded: bool) -> Index<json::Accessor> {
        let bytes: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&bytes, json::buffer::Target::ArrayBuffer);
        let (min, max) = if bounded {
            bounds(values)
        } else {
            (None, None)
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: Some(USize64(0)),
            count: USize64::from(values.len()),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
            extensions: None,
            extras: None,
            type_: Valid(json::accessor::Type::Vec3),
            min,
            max,
            name: Some(name.to_owned()),
            normalized: false,
            sparse: None,
        })
    }

    /// The triangles' corners as `u32` indices.
    fn indices(&mut self, triangles: &[[u32; 3]]) -> Index<json::Accessor> {
        let bytes: Vec<u8> = triangles
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&bytes, json::buffer::Target::ElementArrayBuffer);
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: Some(USize64(0)),
            count: USize64::from(triangles.len() * 3),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::U32,
            )),
            extensions: None,
            extras: None,
            type_: Valid(json::accessor::Type::Scalar),
            min: None,
            max: None,
            name: Some("indices".into()),
            normalized: false,
            sparse: None,
        })
    }

    /// An unlit, double-sided, white material: vertex colours show as they are.
    fn unlit(&mut self, name: &str) -> Index<json::Material> {
        let mut material = json::Material {
            name: Some(name.to_owned()),
            double_sided: true,
            ..Default::default()
        };
        material.extensions = Some(json::extensions::material::Material {
            unlit: Some(json::extensions::material::Unlit {}),
            ..Default::default()
        });
        self.root.push(material)
    }

    fn mesh(&mut self, name: &str, primitives: Vec<json::mesh::Primitive>) -> Index<json::Mesh> {
        self.root.push(json::Mesh {
            extensions: None,
            extras: None,
            name: Some(name.to_owned()),
            primitives,
            weights: None,
        })
    }

    fn node(&mut self, name: &str, mesh: Index<json::Mesh>) -> Index<json::Node> {
        self.root.push(json::Node {
            mesh: Some(mesh),
            name: Some(name.to_owned()),
            ..Default::default()
        })
    }

    /// The GLB container: header, the JSON chunk (padded with spaces) and the binary chunk
    /// (padded with zeros).
    fn finish(mut self, nodes: Vec<Index<json::Node>>) -> Result<Vec<u8>, ExportError> {
        let scene = self.root.push(json::Scene {
            extensions: None,
            extras: None,
            name: Some("penumbra solution".into()),
            nodes,
        });
        self.root.scene = Some(scene);
        self.root.extensions_used = vec!["KHR_materials_unlit".into()];
        self.root.asset.generator = Some(format!("penumbra {}", crate::outputs::VERSION));
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.root.push(json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            name: None,
            uri: None,
            extensions: None,
            extras: None,
        });
        let mut text = json::serialize::to_vec(&self.root).map_err(|e| ExportError::Encode {
            format: "glTF",
            reason: e.to_string(),
        })?;
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let total = 12 + 8 + text.len() + 8 + self.bin.len();
        let length = |n: usize| {
            u32::try_from(n).map_err(|_| ExportError::TooLarge {
                format: "GLB",
                reason: format!("{n} bytes: at most 4 GiB"),
            })
        };
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2_u32.to_le_bytes());
        out.extend_from_slice(&length(total)?.to_le_bytes());
        out.extend_from_slice(&length(text.len())?.to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&text);
        out.extend_from_slice(&length(self.bin.len())?.to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&self.bin);
        Ok(out)
    }
}

/// Per-component minimum and maximum, as glTF wants them for positions.
fn bounds(values: &[[f32; 3]]) -> (Option<json::Value>, Option<json::Value>) {
    if values.is_empty() {
        return (None, None);
    }
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for v in values {
        for c in 0..3 {
            lo[c] = lo[c].min(v[c]);
            hi[c] = hi[c].max(v[c]);
        }
    }
    (Some(lo.to_vec().into()), Some(hi.to_vec().into()))
}
