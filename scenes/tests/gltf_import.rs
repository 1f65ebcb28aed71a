//! glTF import against what the format defines: node transforms compose parent first, a
//! mirroring transform keeps the drawn front, strips and fans are their triangles, and materials
//! give reflectance and emission by the documented convention.

use std::f64::consts::PI;

use base64::Engine;
use glam::DVec3;
use penumbra_scenes::{LoadedScene, ObjOptions, Rgb, load_scene_with};
use serde_json::{Value, json};

/// A .gltf whose one buffer (a data URI) holds `points` (f32) then `order` (u16), drawn as
/// `mode` by a mesh that `nodes` place; `material` is the file's only material.
fn gltf(points: &[[f32; 3]], order: &[u16], mode: u32, nodes: &Value, material: &Value) -> Value {
    let mut bytes: Vec<u8> = points
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let positions = bytes.len();
    bytes.extend(order.iter().flat_map(|i| i.to_le_bytes()));
    bytes.resize(bytes.len().next_multiple_of(4), 0);
    let low = (0..3).map(|k| points.iter().map(|p| p[k]).fold(f32::MAX, f32::min));
    let high = (0..3).map(|k| points.iter().map(|p| p[k]).fold(f32::MIN, f32::max));
    let uri = base64::engine::general_purpose::STANDARD.encode(&bytes);
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": [{"name": "shape", "primitives": [
            {"attributes": {"POSITION": 0}, "indices": 1, "mode": mode, "material": 0},
        ]}],
        "materials": [material],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": points.len(), "type": "VEC3",
             "min": low.collect::<Vec<_>>(), "max": high.collect::<Vec<_>>()},
            {"bufferView": 1, "componentType": 5123, "count": order.len(), "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": positions},
            {"buffer": 0, "byteOffset": positions, "byteLength": order.len() * 2},
        ],
        "buffers": [{"byteLength": bytes.len(), "uri": format!("data:application/octet-stream;base64,{uri}")}],
    })
}

/// A grey material that glows a little: a scene needs a light to load.
fn grey() -> Value {
    json!({"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0]},
           "emissiveFactor": [0.1, 0.1, 0.1]})
}

fn load(document: &Value, merge_coplanar: bool) -> LoadedScene {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("scene.gltf");
    std::fs::write(&path, document.to_string()).expect("the scene is written");
    let options = ObjOptions { merge_coplanar };
    load_scene_with(path.to_str().expect("a UTF-8 path"), &options).expect("the scene loads")
}

/// Fails unless a warning of `loaded` says `words`.
fn assert_warned(loaded: &LoadedScene, words: &str) {
    assert!(
        loaded.warnings.iter().any(|w| w.contains(words)),
        "no warning says {words:?}: {:?}",
        loaded.warnings
    );
}

/// The unit square in z = 0, counter-clockwise seen from +z, as the corners of a strip.
const STRIP: [[f32; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [1.0, 1.0, 0.0],
];

#[test]
fn strips_and_fans_are_their_triangles_each_facing_as_drawn() {
    let fan = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    for (points, mode) in [(STRIP, 5), (fan, 6)] {
        let document = gltf(&points, &[0, 1, 2, 3], mode, &json!([{"mesh": 0}]), &grey());
        let apart = load(&document, false).scene;
        assert_eq!(apart.surfaces.len(), 2, "mode {mode}");
        for s in &apart.surfaces {
            assert!((s.area() - 0.5).abs() < 1e-12, "mode {mode}");
            assert!((s.normal() - DVec3::Z).length() < 1e-12, "mode {mode}");
        }
        let merged = load(&document, true).scene;
        assert_eq!(merged.surfaces.len(), 1, "mode {mode}");
        assert!((merged.surfaces[0].area() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn a_mirroring_node_keeps_the_front_it_draws() {
    let plain = gltf(&STRIP, &[0, 1, 2], 4, &json!([{"mesh": 0}]), &grey());
    let front = load(&plain, true).scene.surfaces[0].normal();
    assert!((front - DVec3::Z).length() < 1e-12);
    // Mirrored in z, the front a viewer sees is the mirror image of +z.
    let mirrored = gltf(
        &STRIP,
        &[0, 1, 2],
        4,
        &json!([{"mesh": 0, "scale": [1, 1, -1]}]),
        &grey(),
    );
    let front = load(&mirrored, true).scene.surfaces[0].normal();
    assert!((front - DVec3::NEG_Z).length() < 1e-12);
}

#[test]
fn transforms_compose_parent_first() {
    // The child turns the square a quarter turn about z, then the parent lifts it by 2 and
    // doubles it: corner (1, 0, 0) lands at (0, 2, 2).
    let quarter = [
        0.0,
        0.0,
        std::f64::consts::FRAC_1_SQRT_2,
        std::f64::consts::FRAC_1_SQRT_2,
    ];
    let nodes = json!([
        {"name": "parent", "children": [1], "translation": [0, 0, 2], "scale": [2, 2, 2]},
        {"name": "child", "mesh": 0, "rotation": quarter},
    ]);
    let loaded = load(&gltf(&STRIP, &[0, 1, 2], 4, &nodes, &grey()), true);
    let s = &loaded.scene.surfaces[0];
    assert!(s.name.starts_with("child/grey/"), "{}", s.name);
    let expected = [
        DVec3::new(0.0, 0.0, 2.0),
        DVec3::new(0.0, 2.0, 2.0),
        DVec3::new(-2.0, 0.0, 2.0),
    ];
    for e in expected {
        let nearest = s
            .polygon
            .iter()
            .map(|p| (*p - e).length())
            .fold(f64::MAX, f64::min);
        assert!(nearest < 1e-6, "{e} not among {:?}", s.polygon);
    }
}

#[test]
fn materials_give_reflectance_and_emission_as_documented() {
    let light = json!({
        "name": "panel",
        "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.5, 0.2, 1.0]},
        "emissiveFactor": [1.0, 0.5, 0.25],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
    });
    let mut document = gltf(&STRIP, &[0, 1, 2], 4, &json!([{"mesh": 0}]), &light);
    document["extensionsUsed"] = json!(["KHR_materials_emissive_strength"]);
    let loaded = load(&document, true);
    let s = &loaded.scene.surfaces[0];
    // Radiance 4 x the factor; exitance pi times the radiance.
    let expected = Rgb::new(4.0 * PI, 2.0 * PI, PI);
    assert!(
        (s.emission - expected).max_channel().abs() < 1e-9,
        "{:?}",
        s.emission
    );
    assert!(
        (s.reflectance - Rgb::new(0.99, 0.5, 0.2))
            .max_channel()
            .abs()
            < 1e-7
    );
    let clamped = loaded
        .warnings
        .iter()
        .filter(|w| w.contains("\"panel\""))
        .count();
    assert_eq!(clamped, 1, "{:?}", loaded.warnings);
}

#[test]
fn points_and_lines_are_skipped_with_a_warning() {
    let mut document = gltf(&STRIP, &[0, 1, 2], 4, &json!([{"mesh": 0}]), &grey());
    let mut lines = document["meshes"][0]["primitives"][0].clone();
    lines["mode"] = json!(1);
    document["meshes"][0]["primitives"]
        .as_array_mut()
        .expect("primitives")
        .push(lines);
    let loaded = load(&document, true);
    assert_eq!(loaded.scene.surfaces.len(), 1);
    assert_warned(&loaded, "skipped 1 primitives");
}

#[test]
fn punctual_lights_are_skipped_with_a_warning_even_when_required() {
    let mut document = gltf(&STRIP, &[0, 1, 2], 4, &json!([{"mesh": 0}]), &grey());
    document["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    document["extensionsRequired"] = json!(["KHR_lights_punctual"]);
    document["extensions"] =
        json!({"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1000}]}});
    document["nodes"]
        .as_array_mut()
        .expect("nodes")
        .push(json!({"name": "Light", "extensions": {"KHR_lights_punctual": {"light": 0}}}));
    document["scenes"][0]["nodes"] = json!([0, 1]);
    let loaded = load(&document, true);
    assert_eq!(loaded.scene.surfaces.len(), 1);
    assert_warned(&loaded, "KHR_lights_punctual");
}
