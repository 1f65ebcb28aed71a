//! `index.html`: a page that shows the solution in 3D, self-contained: the viewer's script
//! (`viewer/`, three.js bundled in) and the mesh are inlined, so it opens from disk with no
//! network.
//!
//! The data sits in `<script id="penumbra-data" type="application/json">` as the
//! `penumbra-viewer/1` object `viewer/src` reads: the run's report, the display's exposure and
//! ambient term, the camera, the surfaces' names, materials and triangle ranges, and the arrays
//! in base64, little endian: `position`, `radiosity`, `direct`, `indirect` (`f32`, 3 per
//! vertex), `index` (`u32`, 3 per triangle), `triangle_surface` (`u32`), `error` (`f32` per
//! triangle, adaptive runs only) and the lines' `line_position` (`f32`, 6 per segment),
//! `line_order`, `line_event`, `line_boundary` (`u8`) and `line_surface` (`u32`).

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;
use serde_json::{Value, json};

use super::mesh::{FlatMesh, boundary_names, event_names};
use super::{Display, ExportSource};

/// The page around the data and the script.
const TEMPLATE: &str = include_str!("../../viewer/template.html");
/// The viewer's script: `viewer/src` bundled with three.js by `viewer/build`.
const SCRIPT: &str = include_str!("../../viewer/dist/viewer.js");
/// Where the script goes in [`TEMPLATE`].
const SCRIPT_SLOT: &str = "/*PENUMBRA_VIEWER_JS*/";
/// Where the data goes in [`TEMPLATE`].
const DATA_SLOT: &str = "/*PENUMBRA_DATA*/";
/// The `format` of the data.
pub const VIEWER_FORMAT: &str = "penumbra-viewer/1";

/// The page's text.
pub fn page(source: &ExportSource, mesh: &FlatMesh, display: &Display) -> String {
    // Markup in a name (`</script>`, `<!--`) would end or change the script element: `<` is
    // written `\u003c`, the same JSON string (outside strings, JSON has no `<`).
    let data = data(source, mesh, display)
        .to_string()
        .replace('<', "\\u003c");
    // The script first: the data may hold any text, the bundle holds no slot (`viewer/build`).
    TEMPLATE
        .replacen(SCRIPT_SLOT, SCRIPT, 1)
        .replacen(DATA_SLOT, &data, 1)
}

/// The `penumbra-viewer/1` object.
fn data(source: &ExportSource, mesh: &FlatMesh, display: &Display) -> Value {
    let surfaces: Vec<Value> = source
        .surfaces
        .iter()
        .enumerate()
        .map(|(s, surface)| {
            let first = mesh.triangle_offsets[s];
            json!({
                "name": surface.name,
                "first_triangle": first,
                "triangle_count": mesh.triangle_offsets[s + 1] - first,
                "emission": surface.emission.unwrap_or_default(),
                "reflectance": surface.reflectance.unwrap_or_default(),
            })
        })
        .collect();
    let lines = &mesh.lines;
    let mut arrays = json!({
        "position": f32s(mesh.positions.iter().flatten()),
        "radiosity": f32s(mesh.radiosity.iter().flatten()),
        "direct": f32s(mesh.direct.iter().flatten()),
        "indirect": f32s(mesh.indirect.iter().flatten()),
        "index": u32s(mesh.triangles.iter().flatten()),
        "triangle_surface": u32s(mesh.triangle_surface.iter()),
        "line_position": f32s(lines.iter().flat_map(|l| l.ends.iter().flatten())),
        "line_order": STANDARD.encode(lines.iter().map(|l| l.order).collect::<Vec<u8>>()),
        "line_event": STANDARD.encode(lines.iter().map(|l| l.event).collect::<Vec<u8>>()),
        "line_boundary": STANDARD.encode(lines.iter().map(|l| l.boundary).collect::<Vec<u8>>()),
        "line_surface": u32s(lines.iter().map(|l| &l.surface)),
    });
    if let Some(error) = &mesh.error {
        arrays["error"] = f32s(error.iter()).into();
    }
    json!({
        "format": VIEWER_FORMAT,
        "scene": source.scene,
        "report": source.report,
        "display": {"exposure": display.exposure, "ambient": display.ambient},
        "camera": source.camera(),
        "surfaces": surfaces,
        "vertex_count": mesh.positions.len(),
        "triangle_count": mesh.triangles.len(),
        "line_count": lines.len(),
        "events": event_names(),
        "boundaries": boundary_names(),
        "arrays": arrays,
    })
}

/// Base64 of the values as little-endian `f32`.
fn f32s<'a>(values: impl Iterator<Item = &'a f64>) -> String {
    let bytes: Vec<u8> = values.flat_map(|&v| (v as f32).to_le_bytes()).collect();
    STANDARD.encode(bytes)
}

/// Base64 of the values as little-endian `u32`.
fn u32s<'a>(values: impl Iterator<Item = &'a u32>) -> String {
    let bytes: Vec<u8> = values.flat_map(|v| v.to_le_bytes()).collect();
    STANDARD.encode(bytes)
}
