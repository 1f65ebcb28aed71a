//! Every validation error names the surface and the problem, and suggests the fix.

use std::path::Path;

use glam::DVec3;
use penumbra_scenes::parse_json;
use penumbra_scenes::{
    ProblemKind, Rgb, Scene, SceneError, Surface, builtin, load_scene, validate,
};

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

fn square(name: &str, z: f64) -> Surface {
    Surface::new(
        name,
        vec![v(0., 0., z), v(1., 0., z), v(1., 1., z), v(0., 1., z)],
        Rgb::splat(0.5),
    )
}

/// A valid scene: an emitter above a floor.
fn base() -> Scene {
    let mut light = square("light", 2.0);
    light.polygon.reverse();
    Scene {
        up: None,
        unit: None,
        name: "t".into(),
        camera: None,
        surfaces: vec![light.with_emission(Rgb::splat(1.0)), square("floor", 0.0)],
    }
}

/// The single problem of `scene`, as a message; asserts there is exactly one.
fn only_problem(scene: &Scene) -> (ProblemKind, String) {
    let problems = validate(scene);
    assert_eq!(problems.len(), 1, "{problems:#?}");
    (problems[0].kind.clone(), problems[0].to_string())
}

#[test]
fn the_base_scene_is_valid() {
    assert!(validate(&base()).is_empty());
}

#[test]
fn non_finite_numbers() {
    let mut s = base();
    s.surfaces[1].polygon[2].y = f64::NAN;
    let (kind, msg) = only_problem(&s);
    assert!(matches!(kind, ProblemKind::NonFinite { field: "polygon" }));
    assert!(
        msg.contains("surface \"floor\"") && msg.contains("non-finite") && msg.contains("replace"),
        "{msg}"
    );
    let mut s = base();
    s.surfaces[1].reflectance.g = f64::INFINITY;
    let (_, msg) = only_problem(&s);
    assert!(
        msg.contains("\"floor\"") && msg.contains("reflectance") && msg.contains("non-finite"),
        "{msg}"
    );
}

#[test]
fn fewer_than_three_distinct_vertices() {
    let mut s = base();
    s.surfaces[1].polygon = vec![v(0., 0., 0.), v(1., 0., 0.), v(1e-20, 0., 0.)];
    let (kind, msg) = only_problem(&s);
    assert!(
        matches!(kind, ProblemKind::TooFewVertices { distinct: 2 }),
        "{kind:?}"
    );
    assert!(
        msg.contains("\"floor\"")
            && msg.contains("2 distinct vertices")
            && msg.contains("at least 3"),
        "{msg}"
    );
}

#[test]
fn zero_or_tiny_area() {
    let mut s = base();
    s.surfaces[1].polygon = vec![v(0., 0., 0.), v(1., 0., 0.), v(2., 1e-12, 0.)];
    let (kind, msg) = only_problem(&s);
    assert!(matches!(kind, ProblemKind::TinyArea { .. }), "{kind:?}");
    assert!(
        msg.contains("\"floor\"") && msg.contains("area") && msg.contains("collinear"),
        "{msg}"
    );
    // Tiny relative to the scene: a speck 1e-11 of the scene's size.
    let mut s = base();
    s.surfaces.push(Surface::new(
        "speck",
        vec![v(0., 0., 1.), v(1e-11, 0., 1.), v(0., 1e-11, 1.)],
        Rgb::splat(0.5),
    ));
    let (kind, msg) = only_problem(&s);
    assert!(matches!(kind, ProblemKind::TinyArea { .. }), "{kind:?}");
    assert!(msg.contains("\"speck\""), "{msg}");
    // But a light a millionth of the scene is legitimate.
    let mut s = base();
    s.surfaces.push(Surface::new(
        "small",
        vec![v(0., 0., 1.), v(1e-6, 0., 1.), v(0., 1e-6, 1.)],
        Rgb::splat(0.5),
    ));
    assert!(validate(&s).is_empty());
}

#[test]
fn non_planar_polygon() {
    let mut s = base();
    s.surfaces[1].polygon[2].z = 0.2;
    let (kind, msg) = only_problem(&s);
    assert!(matches!(kind, ProblemKind::NonPlanar { .. }), "{kind:?}");
    assert!(
        msg.contains("\"floor\"") && msg.contains("not planar") && msg.contains("split"),
        "{msg}"
    );
    // Within the tolerance relative to the polygon's size: accepted, at any scale.
    for scale in [1e-6, 1.0, 1e6] {
        let mut s = base().transformed(&glam::DAffine3::from_scale(DVec3::splat(scale)));
        s.surfaces[1].polygon[2].z += 1e-8 * scale;
        assert!(validate(&s).is_empty(), "scale {scale}");
    }
}

#[test]
fn self_intersecting_polygon() {
    let mut s = base();
    // A vertex touching a non-adjacent edge.
    s.surfaces[1].polygon = vec![
        v(0., 0., 0.),
        v(2., 0., 0.),
        v(2., 2., 0.),
        v(1., 0., 0.),
        v(0., 2., 0.),
    ];
    let (kind, msg) = only_problem(&s);
    assert!(
        matches!(kind, ProblemKind::SelfIntersecting { .. }),
        "{kind:?}"
    );
    assert!(
        msg.contains("\"floor\"") && msg.contains("intersects itself") && msg.contains("reorder"),
        "{msg}"
    );
}

#[test]
fn reflectance_outside_zero_one() {
    for bad in [1.0, 1.2, -0.1] {
        let mut s = base();
        s.surfaces[1].reflectance = Rgb::new(0.5, bad, 0.5);
        let (kind, msg) = only_problem(&s);
        assert!(
            matches!(
                kind,
                ProblemKind::ReflectanceOutOfRange { channel: "g", .. }
            ),
            "{kind:?}"
        );
        assert!(
            msg.contains("\"floor\"") && msg.contains("outside [0, 1)") && msg.contains("below 1"),
            "{msg}"
        );
    }
}

#[test]
fn negative_emission() {
    let mut s = base();
    s.surfaces[1].emission = Rgb::new(0.0, 0.0, -2.0);
    let (kind, msg) = only_problem(&s);
    assert!(
        matches!(kind, ProblemKind::NegativeEmission { channel: "b", .. }),
        "{kind:?}"
    );
    assert!(
        msg.contains("\"floor\"") && msg.contains("negative") && msg.contains("zero or positive"),
        "{msg}"
    );
}

#[test]
fn duplicate_names() {
    let mut s = base();
    s.surfaces.push(square("floor", 0.5));
    let (kind, msg) = only_problem(&s);
    assert!(
        matches!(
            kind,
            ProblemKind::DuplicateName {
                first: 1,
                second: 2
            }
        ),
        "{kind:?}"
    );
    assert!(
        msg.contains("\"floor\"") && msg.contains("unique name"),
        "{msg}"
    );
}

#[test]
fn no_emitter_at_all() {
    let mut s = base();
    s.surfaces[0].emission = Rgb::ZERO;
    let (kind, msg) = only_problem(&s);
    assert_eq!(kind, ProblemKind::NoEmitter);
    assert!(
        msg.contains("no surface emits") && msg.contains("\"emission\""),
        "{msg}"
    );
}

#[test]
fn every_problem_is_reported_at_once() {
    let mut s = base();
    s.surfaces[1].reflectance = Rgb::splat(1.5);
    s.surfaces[0].polygon[0].x = f64::NAN;
    s.surfaces.push(square("floor", 3.0));
    let problems = validate(&s);
    // Three reflectance channels, one non-finite polygon, one duplicate name.
    assert_eq!(problems.len(), 5, "{problems:#?}");
    let err = SceneError::Invalid {
        source_name: "x.json".into(),
        problems,
        warnings: Vec::new(),
    };
    let text = err.to_string();
    assert!(text.starts_with("x.json: 5 problems:"), "{text}");
}

#[test]
fn json_errors_have_line_and_column_and_unknown_keys_are_rejected() {
    let path = Path::new("scene.json");
    let text = "{\n  \"surfaces\": [\n    {\"name\": \"a\", \"polygon\": [], \"reflectance\": [0.5, 0.5, 0.5], \"colour\": 1}\n  ]\n}";
    match parse_json(text, path) {
        Err(SceneError::Json {
            line,
            column,
            message,
            ..
        }) => {
            assert_eq!(line, 3);
            assert!(column > 60, "{column}");
            assert!(message.contains("unknown field `colour`"), "{message}");
        }
        other => panic!("expected a JSON error, got {other:?}"),
    }
    let err = parse_json("{\"surfaces\": [}", path).expect_err("syntax error");
    assert!(err.to_string().starts_with("scene.json:1:"), "{err}");
}

#[test]
fn json_round_trip_and_closing_vertex() {
    let scene = builtin::textbook();
    let text = penumbra_scenes::to_json(&scene);
    let back = parse_json(&text, Path::new("t.json")).expect("round trip");
    assert_eq!(back, scene);
    // A polygon written closed (first vertex repeated at the end) is the same polygon.
    let closed = r#"{"surfaces": [{"name": "q", "reflectance": [0.5, 0.5, 0.5], "emission": [1, 1, 1],
        "polygon": [[0,0,0],[1,0,0],[1,1,0],[0,1,0],[0,0,0]]}]}"#;
    let scene = parse_json(closed, Path::new("closed.json")).expect("parses");
    assert_eq!(scene.surfaces[0].polygon.len(), 4);
    assert_eq!(scene.name, "closed");
}

#[test]
fn unknown_scene_names_list_the_builtins() {
    let err = load_scene("cornel").expect_err("no such scene");
    let text = err.to_string();
    assert!(
        text.contains("\"cornel\"") && text.contains("cornell, textbook, furnace"),
        "{text}"
    );
    let err = load_scene("missing/dir/scene.json").expect_err("no such file");
    assert!(matches!(err, SceneError::Io { .. }), "{err:?}");
}

#[test]
fn obj_import_maps_materials_and_repairs_faces() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl white\nKd 0.7 0.7 0.7\nnewmtl lamp\nKd 0.0 0.0 0.0\nKe 5 5 5\n",
    )
    .expect("write mtl");
    let obj = "mtllib m.mtl\n\
        v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\nv 2 0 0\nv 3 0 0\nv 1 1 0.3\n\
        o floor\nusemtl white\nf 1 2 3 4\n\
        o lamp\nusemtl lamp\nf 5 8 7 6\n\
        o junk\nusemtl white\nf 1 9 10\nf 1 2 11 4\n";
    let path = dir.path().join("scene.obj");
    std::fs::write(&path, obj).expect("write obj");
    let loaded = load_scene(path.to_str().expect("utf-8 path")).expect("loads");
    let s = &loaded.scene;
    let floor = &s.surfaces[s.surface_id("floor/white/0").expect("floor face")];
    assert_eq!(floor.reflectance, Rgb::new(0.7, 0.7, 0.7));
    let lamp = &s.surfaces[s.surface_id("lamp/lamp/0").expect("lamp face")];
    assert_eq!(lamp.emission, Rgb::splat(5.0));
    assert!(lamp.normal().z < -0.99, "the lamp faces down");
    // The collinear face is dropped; the non-planar quad becomes two triangles.
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("dropped 1 faces")),
        "{:?}",
        loaded.warnings
    );
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("split 1 non-planar")),
        "{:?}",
        loaded.warnings
    );
    assert_eq!(s.surfaces.len(), 4);
}
