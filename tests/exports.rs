//! The exports (`--export`, `penumbra export`): the same bytes from a run and from its
//! directory, read back by other parsers (tobj for OBJ, ply-rs-bw's for PLY, gltf-json for
//! GLB), and refused input that names what is wrong. The Python tests read them with ParaView's
//! VTK, plyfile, pygltflib and trimesh, and open the viewer page in a browser.

use std::path::Path;

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;
use serde_json::Value;

mod common;
use common::{json, path, penumbra, run_quietly, stderr, succeeds};

/// Every vertex of a solution.json, surface after surface.
fn vertices(solution: &Value) -> Vec<[f64; 3]> {
    per_vertex(solution, "vertices")
}

/// A per-vertex triple field of every surface, joined.
fn per_vertex(solution: &Value, field: &str) -> Vec<[f64; 3]> {
    solution["surfaces"]
        .as_array()
        .expect("surfaces")
        .iter()
        .flat_map(|s| s[field].as_array().expect(field).clone())
        .map(|v| serde_json::from_value(v).expect("a triple"))
        .collect()
}

fn count(solution: &Value, field: &str) -> usize {
    let surfaces = solution["surfaces"].as_array().expect("surfaces");
    surfaces
        .iter()
        .map(|s| s[field].as_array().expect(field).len())
        .sum()
}

/// Segments of each order (D0, D1, D2).
fn segments_by_order(solution: &Value) -> [usize; 3] {
    let mut by = [0; 3];
    for s in solution["surfaces"].as_array().expect("surfaces") {
        for d in s["discontinuities"].as_array().expect("segments") {
            by[d["order"].as_u64().expect("order") as usize] += 1;
        }
    }
    by
}

const EXPORTS: [&str; 6] = [
    "solution.vtp",
    "solution.ply",
    "solution.glb",
    "solution.obj",
    "solution.mtl",
    "index.html",
];

#[test]
fn a_run_and_its_directory_export_the_same_bytes() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let options = ["--max-elements", "1200", "--export", "all"];
    run_quietly("textbook", &a, &options);
    run_quietly(
        "textbook",
        &b,
        &["--max-elements", "1200", "--export", "none"],
    );
    for name in EXPORTS {
        assert!(a.join(name).is_file(), "{name} written");
        assert!(!b.join(name).exists(), "--export none writes no {name}");
    }
    succeeds(&["export", path(&b), "--format", "vtp,ply,glb,obj", "--quiet"]);
    // The page embeds its run's report, which records the command line: the others match.
    for name in &EXPORTS[..5] {
        let (x, y) = (read(&a.join(name)), read(&b.join(name)));
        assert!(x == y, "{name} differs between run --export and export");
    }
    let before: Vec<Vec<u8>> = EXPORTS.iter().map(|n| read(&a.join(n))).collect();
    succeeds(&["export", path(&a), "--quiet"]);
    for (name, bytes) in EXPORTS.iter().zip(before) {
        assert!(
            read(&a.join(name)) == bytes,
            "{name} differs when exported again"
        );
    }
    // By default a run writes the viewer page, and no other export.
    let c = dir.path().join("c");
    run_quietly("textbook", &c, &["--max-elements", "1200"]);
    assert!(c.join("index.html").is_file());
    assert!(!c.join("solution.vtp").exists());
}

/// The data a viewer page embeds, with both of the template's slots filled.
fn page_data(page: &Path) -> Value {
    let page = String::from_utf8(read(page)).expect("utf-8");
    assert!(!page.contains("/*PENUMBRA_DATA*/") && !page.contains("/*PENUMBRA_VIEWER_JS*/"));
    let start = page.find("id=\"penumbra-data\"").expect("the data element");
    let body = &page[start..];
    let body = &body[body.find('>').expect("tag end") + 1..];
    serde_json::from_str(&body[..body.find("</script>").expect("end")]).expect("the data is JSON")
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("cannot read {}: {e}", p.display()))
}

/// Direct-only, B = E + ρ·H_direct, so `direct` is the radiosity less the emission; in the full
/// run on the same mesh, `direct` is the same, the rest is the indirect light, and it is not
/// negative.
#[test]
fn direct_light_in_solution_json_is_the_direct_only_runs() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (d, f) = (dir.path().join("direct"), dir.path().join("full"));
    let mesh = [
        "--mesh",
        "uniform",
        "--max-elements",
        "900",
        "--export",
        "none",
    ];
    run_quietly("cornell", &d, &[&mesh[..], &["--direct-only"]].concat());
    run_quietly(
        "cornell",
        &f,
        &[&mesh[..], &["--solver", "gauss-seidel"]].concat(),
    );
    let (direct_only, full) = (
        json(&d.join("solution.json")),
        json(&f.join("solution.json")),
    );
    assert_eq!(vertices(&direct_only), vertices(&full), "the same mesh");
    let largest = per_vertex(&full, "radiosity")
        .iter()
        .flatten()
        .fold(0.0_f64, |m, v| m.max(*v));
    for (s, (a, b)) in direct_only["surfaces"]
        .as_array()
        .expect("surfaces")
        .iter()
        .zip(full["surfaces"].as_array().expect("surfaces"))
        .enumerate()
    {
        let e: [f64; 3] = serde_json::from_value(a["emission"].clone()).expect("emission");
        let triples = |v: &Value, f: &str| -> Vec<[f64; 3]> {
            serde_json::from_value(v[f].clone()).expect("triples")
        };
        let (b_direct, d_direct) = (triples(a, "radiosity"), triples(a, "direct"));
        let (b_full, d_full) = (triples(b, "radiosity"), triples(b, "direct"));
        for v in 0..b_direct.len() {
            for c in 0..3 {
                let lone = b_direct[v][c] - e[c];
                assert!(
                    (d_direct[v][c] - lone).abs() <= 1e-12 * largest,
                    "surface {s}"
                );
                assert!((d_full[v][c] - d_direct[v][c]).abs() <= 1e-12 * largest);
                let indirect = b_full[v][c] - e[c] - d_full[v][c];
                assert!(
                    indirect >= -1e-12 * largest,
                    "negative indirect light {indirect}"
                );
            }
        }
    }
    // The Cornell box's walls light one another: the full run has indirect light.
    let sum = |s: &Value, f| per_vertex(s, f).iter().flatten().sum::<f64>();
    assert!(sum(&full, "radiosity") > 1.2 * sum(&direct_only, "radiosity"));
}

#[test]
fn the_obj_export_reads_back_with_tobj() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    // Direct light only: the render adds an ambient term, each surface ρ times it.
    let options = ["--max-elements", "2000", "--direct-only", "--export", "obj"];
    run_quietly("cornell", &out, &options);
    let solution = json(&out.join("solution.json"));
    let report = json(&out.join("report.json"));
    let options = tobj::LoadOptions {
        ignore_lines: false,
        ..tobj::LoadOptions::default()
    };
    let (models, materials) = tobj::load_obj(out.join("solution.obj"), &options).expect("loads");
    let materials = materials.expect("solution.mtl loads");
    let surfaces = solution["surfaces"].as_array().expect("surfaces");
    let by_order = segments_by_order(&solution);
    let classes = by_order.iter().filter(|&&n| n > 0).count();
    assert_eq!(models.len(), surfaces.len() + classes);
    let exposure = report["render"]["exposure"].as_f64().expect("exposure");
    let ambient: [f64; 3] = serde_json::from_value(report["render"]["ambient"].clone()).expect("");
    assert!(ambient.iter().all(|a| *a > 0.0), "an ambient term to show");
    for (model, surface) in models.iter().zip(surfaces) {
        let m = &model.mesh;
        let expected: Vec<[f64; 3]> =
            serde_json::from_value(surface["vertices"].clone()).expect("vertices");
        let positions: Vec<[f64; 3]> = m.positions.chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
        // tobj keeps vertices in first-use order; every one is used by a triangle.
        let mut sorted = positions.clone();
        let mut want = expected.clone();
        let key = |a: &[f64; 3], b: &[f64; 3]| a.partial_cmp(b).expect("finite");
        sorted.sort_by(key);
        want.sort_by(key);
        want.dedup();
        sorted.dedup();
        assert_eq!(sorted, want, "{}: positions to the bit", model.name);
        assert_eq!(
            m.indices.len(),
            3 * surface["triangles"].as_array().expect("").len()
        );
        let material = &materials[m.material_id.expect("a material")];
        let rgb = |f: &str| -> [f64; 3] { serde_json::from_value(surface[f].clone()).expect(f) };
        assert_eq!(material.diffuse, Some(rgb("reflectance")));
        assert_eq!(material.emissive.unwrap_or_default(), rgb("emission"));
        // Colours are render.png's: sRGB of (B + ρ·ambient) × exposure, in 8 bits.
        let radiosity: Vec<[f64; 3]> =
            serde_json::from_value(surface["radiosity"].clone()).expect("radiosity");
        let mut checked = 0;
        for (p, c) in positions.iter().zip(m.vertex_color.chunks(3)).take(50) {
            // Both sides of a contact line share a position: leave those out.
            let mut at = expected.iter().enumerate().filter(|(_, q)| *q == p);
            let (Some((v, _)), None) = (at.next(), at.next()) else {
                continue;
            };
            for ch in 0..3 {
                let lifted = radiosity[v][ch] + rgb("reflectance")[ch] * ambient[ch];
                let shown = penumbra_viz::srgb_encode(lifted * exposure);
                assert!((c[ch] - (shown * 255.0).round() / 255.0).abs() < 1e-6);
            }
            checked += 1;
        }
        assert!(checked > 0, "{}: no vertex of its own position", model.name);
    }
    for (model, order) in models[surfaces.len()..]
        .iter()
        .zip([0, 1, 2].iter().filter(|&&o| by_order[o] > 0))
    {
        assert_eq!(model.name, format!("discontinuities_D{order}"));
        assert_eq!(model.mesh.indices.len(), 2 * by_order[*order]);
    }
}

#[test]
fn the_ply_export_reads_back_with_its_parser() {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    run_quietly(
        "textbook",
        &out,
        &["--max-elements", "1500", "--export", "ply"],
    );
    let solution = json(&out.join("solution.json"));
    let bytes = read(&out.join("solution.ply"));
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut bytes.as_slice())
        .expect("parses");
    let (vertex, face) = (&ply.payload["vertex"], &ply.payload["face"]);
    assert_eq!(vertex.len(), count(&solution, "vertices"));
    assert_eq!(face.len(), count(&solution, "triangles"));
    let radiosity = per_vertex(&solution, "radiosity");
    for ((v, p), b) in vertex.iter().zip(vertices(&solution)).zip(&radiosity) {
        let double = |k: &str| match v[k] {
            Property::Double(x) => x,
            ref other => panic!("{k}: {other:?}"),
        };
        assert_eq!([double("x"), double("y"), double("z")], p);
        let luminance = 0.2126 * b[0] + 0.7152 * b[1] + 0.0722 * b[2];
        assert_eq!(double("quality"), luminance);
    }
    let offsets: Vec<usize> = solution["surfaces"]
        .as_array()
        .expect("surfaces")
        .iter()
        .scan(0, |n, s| {
            let first = *n;
            *n += s["vertices"].as_array().expect("").len();
            Some(first)
        })
        .collect();
    let mut f = 0;
    for (s, surface) in solution["surfaces"]
        .as_array()
        .expect("")
        .iter()
        .enumerate()
    {
        for t in surface["triangles"].as_array().expect("triangles") {
            let want: Vec<i32> = t
                .as_array()
                .expect("")
                .iter()
                .map(|i| (i.as_u64().expect("") as usize + offsets[s]) as i32)
                .collect();
            assert_eq!(face[f]["vertex_indices"], Property::ListInt(want));
            assert_eq!(face[f]["surface"], Property::Int(s as i32));
            f += 1;
        }
    }
}

/// The GLB container and its glTF document: a node and triangle primitive with colours per
/// object (each surface of the Cornell box, whose names have no `/`), a LINES primitive per
/// discontinuity class holding its segments, accessors inside the buffer, all under one root.
#[test]
fn the_glb_export_is_a_valid_gltf_document() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    run_quietly(
        "cornell",
        &out,
        &["--max-elements", "2000", "--export", "glb"],
    );
    let solution = json(&out.join("solution.json"));
    let glb = read(&out.join("solution.glb"));
    let u32_at = |i: usize| u32::from_le_bytes(glb[i..i + 4].try_into().expect("4 bytes"));
    assert_eq!(&glb[..4], b"glTF");
    assert_eq!(u32_at(4), 2);
    assert_eq!(u32_at(8) as usize, glb.len());
    let json_len = u32_at(12) as usize;
    assert_eq!(&glb[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let root = gltf_json::Root::from_slice(&glb[20..20 + json_len]).expect("a glTF document");
    let bin_len = u32_at(20 + json_len) as usize;
    assert_eq!(&glb[24 + json_len..28 + json_len], b"BIN\0");
    assert_eq!(28 + json_len + bin_len, glb.len());
    for view in &root.buffer_views {
        let end = view.byte_offset.map_or(0, |o| o.0) + view.byte_length.0;
        assert!(end as usize <= bin_len);
    }
    let attribute = |p: &gltf_json::mesh::Primitive, name: &str| {
        let found = p
            .attributes
            .iter()
            .find(|(s, _)| serde_json::to_value(s).expect("a name") == name);
        root.accessors[found.expect(name).1.value()].count.0 as usize
    };
    let (objects, rest) = root.meshes.split_at(root.meshes.len() - 1);
    let names: Vec<&str> = objects.iter().filter_map(|m| m.name.as_deref()).collect();
    let surfaces = solution["surfaces"].as_array().expect("surfaces");
    let surface_names: Vec<&str> = surfaces.iter().filter_map(|s| s["name"].as_str()).collect();
    assert_eq!(names, surface_names);
    for (object, surface) in objects.iter().zip(surfaces) {
        assert_eq!(object.primitives.len(), 1);
        let primitive = &object.primitives[0];
        let indices = &root.accessors[primitive.indices.expect("indexed").value()];
        let triangles = surface["triangles"].as_array().expect("triangles").len();
        assert_eq!(indices.count.0 as usize, 3 * triangles);
        let vertices = surface["vertices"].as_array().expect("vertices").len();
        for name in [
            "POSITION",
            "NORMAL",
            "COLOR_0",
            "_RADIOSITY",
            "_DIRECT",
            "_INDIRECT",
        ] {
            assert_eq!(attribute(primitive, name), vertices, "{name}");
        }
    }
    // One root: the objects' nodes and the lines' under it.
    let scene = &root.scenes[root.scene.expect("a default scene").value()];
    assert_eq!(scene.nodes.len(), 1);
    let top = &root.nodes[scene.nodes[0].value()];
    assert_eq!(top.children.as_ref().map(Vec::len), Some(root.meshes.len()));
    let by_order = segments_by_order(&solution);
    assert_eq!(rest[0].name.as_deref(), Some("discontinuities"));
    let lines = &rest[0].primitives;
    let classes: Vec<usize> = (0..3).filter(|&o| by_order[o] > 0).collect();
    assert_eq!(lines.len(), classes.len());
    for (p, &order) in lines.iter().zip(&classes) {
        assert_eq!(
            serde_json::to_value(p.mode).expect("mode"),
            Value::from(1),
            "LINES"
        );
        assert_eq!(attribute(p, "POSITION"), 2 * by_order[order]);
    }
    assert!(by_order[2] > 0, "the Cornell box's blocks cast D2 lines");
}

/// The page embeds the data the viewer reads, whole, and nothing ends its script early.
#[test]
fn the_viewer_page_holds_the_solution() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    run_quietly(
        "textbook",
        &out,
        &[
            "--max-elements",
            "1500",
            "--refine-tol",
            "0.05",
            "--export",
            "html,vtp",
        ],
    );
    let solution = json(&out.join("solution.json"));
    let data = page_data(&out.join("index.html"));
    assert_eq!(data["format"], "penumbra-viewer/1");
    assert_eq!(data["report"], json(&out.join("report.json")));
    let (v, t) = (count(&solution, "vertices"), count(&solution, "triangles"));
    let l: usize = segments_by_order(&solution).iter().sum();
    let bytes = |name: &str| {
        let text = data["arrays"][name]
            .as_str()
            .unwrap_or_else(|| panic!("{name}"));
        STANDARD.decode(text).expect("base64").len()
    };
    for (name, expected) in [
        ("position", 12 * v),
        ("radiosity", 12 * v),
        ("direct", 12 * v),
        ("indirect", 12 * v),
        ("index", 12 * t),
        ("triangle_surface", 4 * t),
        ("error", 4 * t),
        ("line_position", 24 * l),
        ("line_order", l),
        ("line_event", l),
        ("line_boundary", l),
        ("line_surface", 4 * l),
    ] {
        assert_eq!(bytes(name), expected, "{name}");
    }
    // An adaptive run's error indicator: one per triangle, not negative, in the VTP too.
    let errors: Vec<f64> = solution["surfaces"]
        .as_array()
        .expect("")
        .iter()
        .flat_map(|s| s["error_indicator"].as_array().expect("indicators").clone())
        .map(|e| e.as_f64().expect("a number"))
        .collect();
    assert_eq!(errors.len(), t);
    assert!(errors.iter().all(|e| *e >= 0.0) && errors.iter().any(|e| *e > 0.0));
    let vtp = read(&out.join("solution.vtp"));
    let header = String::from_utf8_lossy(&vtp[..vtp.len().min(4000)]);
    assert!(header.contains("Name=\"error_indicator\""));
    // The mesh's vertices, then each segment's two ends.
    let points = v + 2 * l;
    assert!(
        header.contains(&format!("NumberOfPoints=\"{points}\"")),
        "{header}"
    );
}

#[test]
fn bad_exports_are_refused_and_change_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let o = penumbra(&[
        "run",
        "textbook",
        "--out",
        path(&out),
        "--export",
        "vtp,stl",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("\"stl\" is not a format"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists(), "nothing written");

    let shard = [
        "run",
        "textbook",
        "--direct-only",
        "--shard",
        "0/2",
        "--export",
        "vtp",
    ];
    let o = penumbra(&[&shard[..], &["--out", path(&out)]].concat());
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--shard with --export"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists(), "nothing written");

    let o = penumbra(&["export", path(&dir.path().join("nothing"))]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("solution.json"), "{}", stderr(&o));

    run_quietly(
        "textbook",
        &out,
        &["--max-elements", "600", "--export", "none"],
    );
    let solution_path = out.join("solution.json");
    let mut solution = json(&solution_path);
    let original = solution.clone();
    // A file of an earlier version: no direct light per vertex.
    for s in solution["surfaces"].as_array_mut().expect("surfaces") {
        s.as_object_mut().expect("object").remove("direct");
    }
    std::fs::write(&solution_path, solution.to_string()).expect("writes");
    let o = penumbra(&["export", path(&out), "--format", "vtp"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("has no direct"), "{}", stderr(&o));
    // A triangle that points past its surface's vertices; a position no f32 holds; no
    // triangles at all; a report of another run.
    let mut past = original.clone();
    past["surfaces"][2]["triangles"][0][1] = Value::from(1_000_000);
    let mut huge = original.clone();
    huge["surfaces"][2]["vertices"][0][0] = Value::from(1e308);
    let mut empty = original.clone();
    for s in empty["surfaces"].as_array_mut().expect("surfaces") {
        s["triangles"] = Value::Array(Vec::new());
    }
    let mut other = original.clone();
    other["scene"] = Value::from("cornell");
    let cases = [
        (past, "vertex 1000000 is not one of its"),
        (huge, "its vertices hold a number beyond"),
        (empty, "no triangles to export"),
        (other, "not the report of solution.json's run"),
    ];
    for (solution, message) in cases {
        std::fs::write(&solution_path, solution.to_string()).expect("writes");
        let o = penumbra(&["export", path(&out), "--format", "all"]);
        assert_eq!(o.status.code(), Some(2), "{message}");
        assert!(stderr(&o).contains(message), "{}", stderr(&o));
    }
    let left: Vec<String> = std::fs::read_dir(&out)
        .expect("the output directory")
        .map(|e| {
            e.expect("an entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    assert!(
        left.iter()
            .all(|n| !n.starts_with("solution.") || n == "solution.json"),
        "no export written: {left:?}"
    );
    assert!(
        left.iter().all(|n| !n.contains(".tmp-")),
        "no temporary left: {left:?}"
    );
}

/// A camera the page cannot use (no field of view, or looking nowhere) is left out: the page
/// frames the scene instead.
#[test]
fn an_unusable_camera_is_left_out_of_the_page() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    run_quietly(
        "textbook",
        &out,
        &["--max-elements", "600", "--export", "none"],
    );
    let report_path = out.join("report.json");
    let original = json(&report_path);
    let page_camera = || {
        succeeds(&["export", path(&out), "--format", "html", "--quiet"]);
        page_data(&out.join("index.html"))["camera"].clone()
    };
    assert_eq!(page_camera(), original["render"]["camera"]);
    let eye = original["render"]["camera"]["eye"].clone();
    for (key, value) in [("fov_deg", Value::from(0.0)), ("target", eye)] {
        let mut report = original.clone();
        report["render"]["camera"][key] = value;
        std::fs::write(&report_path, report.to_string()).expect("writes");
        assert_eq!(page_camera(), Value::Null, "{key}");
    }
}
