//! glTF 2.0 import (`.gltf` with its buffers, or `.glb`): the triangles of every mesh primitive
//! in the default scene's node tree, placed by their nodes' world transforms, become faces named
//! `node/material/index` (`index` counts that node's faces of that material), repaired and merged
//! into surfaces as OBJ faces are ([`crate::mesh_file`]). Materials give reflectance and
//! emission ([`materials`]). Triangle strips and fans are read as their triangles; points and
//! lines are skipped with a warning, as are punctual lights. The first perspective camera in the
//! tree becomes the scene's camera. Coordinates stay the file's: metres, +y up.
//!
//! Accessors are read with their bounds checked ([`accessors`]): a truncated buffer, an index past
//! the vertices or a position that is not a number is an error naming the accessor, the mesh and
//! the node.

mod accessors;
mod buffers;
mod materials;

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DVec3};
use gltf::mesh::{Mode, Semantic};

use crate::error::SceneError;
use crate::load::{read_bytes, scene_name};
use crate::mesh_file::into_surfaces;
use crate::mesh_file::repair::Face;
use crate::mesh_file::tally::{FaceSource, Tally};
use crate::model::{Camera, LengthUnit, Scene};
use crate::obj::ObjOptions;
use accessors::Buffers;

/// The length of a GLB's header: magic, version, length.
const GLB_HEADER: usize = 12;

/// Reads a glTF file and the buffers it names, looked for beside it.
pub(crate) fn read_gltf_with(
    path: &Path,
    options: &ObjOptions,
) -> Result<(Scene, Vec<String>), SceneError> {
    let bytes = read_bytes(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    parse_gltf(&bytes, dir, &scene_name(path), options).map_err(|message| SceneError::Gltf {
        path: path.to_path_buf(),
        message,
    })
}

/// Reads glTF (JSON or GLB) `bytes` as the scene `name`; relative buffer URIs are looked for in
/// `dir`.
pub(crate) fn parse_gltf(
    bytes: &[u8],
    dir: &Path,
    name: &str,
    options: &ObjOptions,
) -> Result<(Scene, Vec<String>), String> {
    check_glb_length(bytes)?;
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| format!("not a valid glTF 2.0 file: {e}"))?;
    validate(&document)?;
    let buffers = buffers::read_buffers(&document, dir, blob)?;
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or("the file has no scene: nothing in it is placed to be lit")?;
    let materials = materials::materials(&document);
    let default_material = materials.len() - 1;
    let mut walk = Walk {
        buffers: &buffers,
        materials: &materials,
        nodes: document.nodes().len(),
        ..Walk::default()
    };
    for node in scene.nodes() {
        walk.visit(&node, DMat4::IDENTITY, 0)?;
    }
    let mut warnings: Vec<String> = [
        walk.not_triangles
            .describe("skipped", "primitives that are not triangles (points or lines)"),
        walk.skinned.describe(
            "read",
            "skinned or morphed meshes in their rest pose (skins and morph targets are not applied)",
        ),
    ]
    .into_iter()
    .flatten()
    .chain(walk.camera_warnings)
    .collect();
    if document
        .extensions_used()
        .any(|e| e == "KHR_lights_punctual")
    {
        warnings.push(
            "the file's point, spot and sun lights (KHR_lights_punctual) are not read: lights \
             here are surfaces, so give a polygon an emissive material"
                .to_string(),
        );
    }
    let material_of = |m: Option<usize>| {
        let m = &materials[m.unwrap_or(default_material).min(default_material)];
        (m.reflectance, m.emission)
    };
    let (surfaces, made) =
        into_surfaces(walk.faces, options.merge_coplanar, &material_of, |used| {
            materials::warnings(&materials, used)
        });
    warnings.extend(made);
    let scene = Scene {
        up: Some(DVec3::Y),
        unit: Some(LengthUnit::Metre),
        name: name.to_string(),
        camera: walk.camera,
        surfaces,
    };
    Ok((scene, warnings))
}

/// The document's references checked, as the format requires, but for positions' `min` and
/// `max`: some exporters leave them out, and they are not read here.
fn validate(document: &gltf::Document) -> Result<(), String> {
    use gltf::json::validation::Validate;
    let root = document.as_json();
    // gltf-json's own check of positions' bounds looks their accessor up unchecked.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, accessor) in &primitive.attributes {
                if accessor.value() >= root.accessors.len() {
                    let semantic = match semantic {
                        gltf::json::validation::Checked::Valid(s) => format!("{s:?}"),
                        gltf::json::validation::Checked::Invalid => "an attribute".to_string(),
                    };
                    return Err(format!(
                        "not a valid glTF 2.0 file: mesh {m} primitive {p} names accessor {} for \
                         {semantic}, but the file has {}",
                        accessor.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    let mut problems = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        problems.push((path(), error));
    });
    let bounds_missing = |path: &str, e: &gltf::json::validation::Error| {
        *e == gltf::json::validation::Error::Missing
            && (path.ends_with(".min") || path.ends_with(".max"))
    };
    let problems: Vec<String> = problems
        .iter()
        .filter(|(path, e)| !bounds_missing(path.as_str(), e))
        .map(|(path, e)| format!("{}: {e}", path.as_str()))
        .collect();
    if problems.is_empty() {
        return Ok(());
    }
    Err(format!(
        "not a valid glTF 2.0 file: {}",
        problems.join("; ")
    ))
}

/// A GLB shorter than its header says was cut short: said so, rather than the parser's words.
/// One that says it is shorter than its header is refused before the parser subtracts.
fn check_glb_length(bytes: &[u8]) -> Result<(), String> {
    let Some(header) = bytes.get(..GLB_HEADER).filter(|h| h.starts_with(b"glTF")) else {
        return Ok(());
    };
    let declared = u32::from_le_bytes([header[8], header[9], header[10], header[11]]) as usize;
    if declared < GLB_HEADER {
        return Err(format!(
            "the GLB header declares {declared} bytes, fewer than the header's own {GLB_HEADER}"
        ));
    }
    if declared > bytes.len() {
        return Err(format!(
            "the GLB header declares {declared} bytes, but the file holds {}: it is truncated",
            bytes.len()
        ));
    }
    Ok(())
}

/// The node tree's faces and camera, gathered depth first.
#[derive(Default)]
struct Walk<'b> {
    buffers: &'b Buffers,
    /// The file's materials, then the default ([`materials::materials`]).
    materials: &'b [materials::Material],
    /// The file's node count: a deeper tree has a cycle.
    nodes: usize,
    faces: Vec<Face>,
    /// Faces so far of each node and material, for their names.
    counters: HashMap<(String, usize), usize>,
    camera: Option<Camera>,
    camera_warnings: Vec<String>,
    not_triangles: Tally,
    skinned: Tally,
}

impl Walk<'_> {
    fn visit(&mut self, node: &gltf::Node, parent: DMat4, depth: usize) -> Result<(), String> {
        let name = node_name(node);
        if depth > self.nodes {
            return Err(format!("node \"{name}\" is its own ancestor"));
        }
        let local = node.transform().matrix().map(|c| c.map(f64::from));
        let world = parent * DMat4::from_cols_array_2d(&local);
        if !world.is_finite() {
            return Err(format!(
                "node \"{name}\" has a transform that is not finite"
            ));
        }
        if let Some(mesh) = node.mesh() {
            if node.skin().is_some() || mesh.weights().is_some() {
                self.skinned.note(&source(&name));
            }
            for primitive in mesh.primitives() {
                self.primitive(&name, &mesh, &primitive, world)?;
            }
        }
        if let Some(camera) = node.camera() {
            self.camera(&name, &camera, world);
        }
        for child in node.children() {
            self.visit(&child, world, depth + 1)?;
        }
        Ok(())
    }

    /// The faces of one primitive, placed by `world`.
    fn primitive(
        &mut self,
        node: &str,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        world: DMat4,
    ) -> Result<(), String> {
        let what = |part: &str, accessor: usize| {
            format!(
                "accessor {accessor} ({part} of mesh \"{}\" primitive {}, node \"{node}\")",
                mesh.name()
                    .map_or_else(|| mesh.index().to_string(), str::to_string),
                primitive.index()
            )
        };
        let mode = primitive.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.not_triangles.note(&source(&format!(
                "mesh {} primitive {} ({mode:?})",
                mesh.index(),
                primitive.index()
            )));
            return Ok(());
        }
        let Some(positions) = primitive.get(&Semantic::Positions) else {
            return Err(format!(
                "mesh {} primitive {} of node \"{node}\" has no POSITION attribute",
                mesh.index(),
                primitive.index()
            ));
        };
        let corners: Vec<DVec3> = accessors::vec3_f32(self.buffers, &positions)
            .map_err(|e| format!("{} {e}", what("POSITION", positions.index())))?
            .into_iter()
            .map(|p| world.transform_point3(DVec3::from_array(p)))
            .collect();
        if let Some(k) = corners.iter().position(|p| !p.is_finite()) {
            return Err(format!(
                "{} holds a position that is not a finite number at element {k}",
                what("POSITION", positions.index())
            ));
        }
        let order: Vec<u32> = match primitive.indices() {
            Some(a) => {
                let order = accessors::indices(self.buffers, &a)
                    .map_err(|e| format!("{} {e}", what("indices", a.index())))?;
                if let Some((k, i)) = order
                    .iter()
                    .enumerate()
                    .find(|&(_, &i)| i as usize >= corners.len())
                {
                    return Err(format!(
                        "{} holds index {i} at element {k}, but the primitive has {} vertices",
                        what("indices", a.index()),
                        corners.len()
                    ));
                }
                order
            }
            None => (0..corners.len() as u32).collect(),
        };
        // A mirroring transform turns counter-clockwise corners clockwise: the front is kept.
        let mirrored = world.determinant() < 0.0;
        // Without one, the default material, last of the list.
        let last = self.materials.len().saturating_sub(1);
        let material = primitive.material().index().map_or(last, |m| m.min(last));
        let material_name = self.materials.get(material).map_or("", |m| m.name.as_str());
        let counter = self
            .counters
            .entry((node.to_string(), material))
            .or_insert(0);
        for triangle in triangles(mode, &order) {
            let mut polygon: Vec<DVec3> = triangle.iter().map(|&i| corners[i as usize]).collect();
            if mirrored {
                polygon.reverse();
            }
            self.faces.push(Face {
                source: source(&format!("{node}/{material_name}/{counter}")),
                polygon,
                material: Some(material),
            });
            *counter += 1;
        }
        Ok(())
    }

    /// The first perspective camera becomes the scene's: it looks along its node's −z, with +y
    /// up.
    fn camera(&mut self, node: &str, camera: &gltf::Camera, world: DMat4) {
        if self.camera.is_some() {
            return;
        }
        let gltf::camera::Projection::Perspective(p) = camera.projection() else {
            self.camera_warnings.push(format!(
                "the camera of node \"{node}\" is orthographic, which the render does not \
                 draw: the default view is used"
            ));
            return;
        };
        let eye = world.transform_point3(DVec3::ZERO);
        let forward = world.transform_vector3(DVec3::NEG_Z).normalize_or_zero();
        let up = world.transform_vector3(DVec3::Y);
        let fov_deg = f64::from(p.yfov()).to_degrees();
        if forward == DVec3::ZERO || up.cross(forward).length_squared() == 0.0 || !(fov_deg > 0.0) {
            self.camera_warnings.push(format!(
                "the camera of node \"{node}\" is scaled to nothing or has no field of view: \
                 the default view is used"
            ));
            return;
        }
        self.camera = Some(Camera {
            eye,
            target: eye + forward,
            up,
            fov_deg: fov_deg.min(179.0),
        });
    }
}

/// The triangles of a primitive drawn as `mode` through `order`, counter-clockwise as drawn.
fn triangles(mode: Mode, order: &[u32]) -> Vec<[u32; 3]> {
    let n = order.len();
    match mode {
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|k| {
                // Every second triangle of a strip is drawn the other way round.
                let (a, b) = if k % 2 == 0 { (1, 2) } else { (2, 1) };
                [order[k], order[k + a], order[k + b]]
            })
            .collect(),
        Mode::TriangleFan => (1..n.saturating_sub(1))
            .map(|k| [order[k], order[k + 1], order[0]])
            .collect(),
        _ => order.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    }
}

fn node_name(node: &gltf::Node) -> String {
    node.name()
        .map_or_else(|| format!("node{}", node.index()), str::to_string)
}

fn source(name: &str) -> FaceSource {
    FaceSource {
        name: name.to_string(),
        line: None,
    }
}
