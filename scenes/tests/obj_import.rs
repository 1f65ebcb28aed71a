//! OBJ files as exported by modelling tools: several materials per object, tessellated walls,
//! repeated corners, missing libraries. Names stay unique, repairs are reported with where they
//! happened, and merging coplanar faces never changes the area of any material.

use std::collections::BTreeMap;
use std::path::Path;

use glam::DVec3;
use penumbra_scenes::polygon_problem;
use penumbra_scenes::{ObjOptions, parse_obj_text, parse_obj_text_with, read_scene_file};
use penumbra_scenes::{ProblemKind, Scene, SceneError, load_scene};

const MTL: &str =
    "newmtl wall\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.6 0.1 0.1\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n";

fn load(obj: &str) -> (Scene, Vec<String>) {
    parse_obj_text(obj, MTL, Path::new("t.obj")).expect("parses")
}

fn load_unmerged(obj: &str) -> (Scene, Vec<String>) {
    let options = ObjOptions {
        merge_coplanar: false,
    };
    parse_obj_text_with(obj, MTL, Path::new("t.obj"), &options).expect("parses")
}

/// Total area per material (reflectance and emission).
fn areas(scene: &Scene) -> BTreeMap<String, f64> {
    let mut out = BTreeMap::new();
    for s in &scene.surfaces {
        *out.entry(format!("{:?} {:?}", s.reflectance, s.emission))
            .or_insert(0.0) += s.area();
    }
    out
}

/// Merging keeps every material's area to 1e-12, and every surface is valid on its own.
fn assert_merge_is_exact(obj: &str) -> Scene {
    let (merged, warnings) = load(obj);
    let (faces, _) = load_unmerged(obj);
    let (before, after) = (areas(&faces), areas(&merged));
    assert_eq!(before.len(), after.len());
    for ((material, a), b) in before.iter().zip(after.values()) {
        assert!(
            (a - b).abs() <= 1e-12 * a,
            "{material}: {a} before, {b} after"
        );
    }
    let diagonal = merged.diagonal();
    for s in &merged.surfaces {
        assert_eq!(polygon_problem(&s.polygon, diagonal), None, "{}", s.name);
    }
    assert!(
        merged.surfaces.len() == faces.surfaces.len()
            || warnings.iter().any(|w| w.starts_with("merged ")),
        "{warnings:?}"
    );
    merged
}

/// An n x n grid of quads (or of triangles, the diagonals alternating) on a square of side 0.3
/// tilted in space, in material `wall`. Its vertices are listed in row order from the corner
/// `start` picks (0: (0, 0), 1: (n, n), 2: by columns), and each face starts at a different
/// corner, so that no merging can rely on the order of the file.
fn grid_obj(n: usize, triangles: bool, start: usize) -> (String, [DVec3; 4]) {
    let origin = DVec3::new(1.0, -0.5, 0.25);
    let du = DVec3::new(0.02, 0.02, 0.01) * (10.0 / n as f64);
    let dv = DVec3::new(0.02, -0.01, -0.02) * (10.0 / n as f64);
    let point = |i: usize, j: usize| origin + du * i as f64 + dv * j as f64;
    let m = n + 1;
    let mut order: Vec<(usize, usize)> = (0..m * m).map(|k| (k / m, k % m)).collect();
    match start {
        1 => order.reverse(),
        2 => order = (0..m * m).map(|k| (k % m, k / m)).collect(),
        _ => {}
    }
    let mut number = vec![0; m * m];
    let mut obj = String::from("mtllib m.mtl\no wall\nusemtl wall\n");
    for (k, &(i, j)) in order.iter().enumerate() {
        number[i * m + j] = k + 1;
        let p = point(i, j);
        obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    let v = |i: usize, j: usize| number[i * m + j];
    let mut face = 0;
    let mut write = |obj: &mut String, corners: &[usize]| {
        let mut corners = corners.to_vec();
        let len = corners.len();
        corners.rotate_left(face % len);
        face += 1;
        let list: Vec<String> = corners.iter().map(|c| c.to_string()).collect();
        *obj += &format!("f {}\n", list.join(" "));
    };
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
            if !triangles {
                write(&mut obj, &[a, b, c, d]);
            } else if (i + j) % 2 == 0 {
                write(&mut obj, &[a, b, c]);
                write(&mut obj, &[a, c, d]);
            } else {
                write(&mut obj, &[a, b, d]);
                write(&mut obj, &[b, c, d]);
            }
        }
    }
    (obj, [point(0, 0), point(n, 0), point(n, n), point(0, n)])
}

#[test]
fn one_object_with_two_materials_has_unique_names() {
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 0 1 1\n\
        o box\nusemtl wall\nf 1 2 3 4\nusemtl red\nf 1 4 6 5\nusemtl wall\nf 5 6 3\n";
    let (scene, _) = load(obj);
    let names: Vec<&str> = scene.surfaces.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["box/wall/0", "box/red/0", "box/wall/1"]);
    // The names do not depend on whether the library was found.
    let (bare, _) = parse_obj_text(obj, "", Path::new("t.obj")).expect("parses");
    let bare_names: Vec<&str> = bare.surfaces.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(bare_names, names);
}

#[test]
fn a_tessellated_wall_becomes_one_square() {
    for triangles in [false, true] {
        for start in 0..3 {
            let (obj, corners) = grid_obj(10, triangles, start);
            let (faces, _) = load_unmerged(&obj);
            assert_eq!(faces.surfaces.len(), if triangles { 200 } else { 100 });
            let scene = assert_merge_is_exact(&obj);
            assert_eq!(
                scene.surfaces.len(),
                1,
                "triangles {triangles}, start {start}"
            );
            let wall = &scene.surfaces[0];
            assert_eq!(wall.name, "wall/wall/0");
            // The outline is the square's four corners, counter-clockwise like the faces.
            assert_eq!(wall.polygon.len(), 4, "{:?}", wall.polygon);
            let first = corners
                .iter()
                .position(|&c| c == wall.polygon[0])
                .expect("a corner of the square");
            for (k, &p) in wall.polygon.iter().enumerate() {
                assert_eq!(p, corners[(first + k) % 4]);
            }
            let sum: f64 = faces.surfaces.iter().map(|s| s.area()).sum();
            assert!((wall.area() - sum).abs() <= 1e-12 * sum);
            assert!((wall.area() - 0.09).abs() <= 1e-12);
        }
    }
}

#[test]
fn an_l_of_squares_merges_into_an_l() {
    let obj = "mtllib m.mtl\nusemtl wall\n\
        v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nv 0 2 0\nv 1 2 0\n\
        f 1 2 5 4\nf 2 3 6 5\nf 4 5 8 7\n";
    let scene = assert_merge_is_exact(obj);
    assert_eq!(scene.surfaces.len(), 1);
    let l = &scene.surfaces[0].polygon;
    let expected = [
        DVec3::new(0., 0., 0.),
        DVec3::new(2., 0., 0.),
        DVec3::new(2., 1., 0.),
        DVec3::new(1., 1., 0.),
        DVec3::new(1., 2., 0.),
        DVec3::new(0., 2., 0.),
    ];
    let first = expected.iter().position(|&c| c == l[0]).expect("a corner");
    assert_eq!(l.len(), 6, "{l:?}");
    for (k, &p) in l.iter().enumerate() {
        assert_eq!(p, expected[(first + k) % 6]);
    }
    assert_eq!(scene.surfaces[0].area(), 3.0);
}

#[test]
fn a_ring_around_a_hole_is_not_one_polygon() {
    // A 3 x 3 grid of unit squares without the middle one.
    let mut obj = String::from("mtllib m.mtl\nusemtl wall\n");
    for j in 0..4 {
        for i in 0..4 {
            obj += &format!("v {i} {j} 0\n");
        }
    }
    let v = |i: usize, j: usize| 1 + i + 4 * j;
    for j in 0..3 {
        for i in 0..3 {
            if (i, j) != (1, 1) {
                obj += &format!(
                    "f {} {} {} {}\n",
                    v(i, j),
                    v(i + 1, j),
                    v(i + 1, j + 1),
                    v(i, j + 1)
                );
            }
        }
    }
    // Grown from the first square, seven squares make a C; the eighth would close the ring.
    let scene = assert_merge_is_exact(&obj);
    let mut areas: Vec<f64> = scene.surfaces.iter().map(|s| s.area()).collect();
    areas.sort_by(f64::total_cmp);
    assert_eq!(areas, [1.0, 7.0], "{:?}", scene.surfaces);
    let (_, warnings) = load(&obj);
    assert!(
        warnings
            .iter()
            .any(|w| w.starts_with("merged 7 coplanar faces into 1 surfaces")
                && w.contains("1 regions of coplanar faces stay in several pieces")),
        "{warnings:?}"
    );
}

#[test]
fn faces_that_only_look_alike_stay_apart() {
    // Two squares sharing an edge: folded by a thousandth, in different materials, and one
    // facing the other way.
    let base = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0.001\nv 2 1 0.001\nv 2 0 0\nv 2 1 0\n";
    let folded = format!("{base}usemtl wall\nf 1 2 3 4\nf 2 5 6 3\n");
    let two_materials = format!("{base}usemtl wall\nf 1 2 3 4\nusemtl red\nf 2 7 8 3\n");
    let flipped = format!("{base}usemtl wall\nf 1 2 3 4\nf 2 3 8 7\n");
    for obj in [folded, two_materials, flipped] {
        assert_eq!(assert_merge_is_exact(&obj).surfaces.len(), 2, "{obj}");
    }
}

#[test]
fn merging_can_be_turned_off() {
    let (obj, _) = grid_obj(4, true, 0);
    let (scene, warnings) = load_unmerged(&obj);
    assert_eq!(scene.surfaces.len(), 32);
    assert!(
        warnings.iter().any(|w| w.contains("not merged")),
        "{warnings:?}"
    );
}

#[test]
fn repeated_corners_are_repaired_and_reported_with_lines() {
    // v5 repeats v2's position; v6, v7 make a second triangle at v1.
    let obj = "mtllib m.mtl\nusemtl wall\n\
        v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 0\nv -1 0 0\nv -1 -1 0\n\
        o doubled\nf 1 2 2 3 4\n\
        o closed\nf 1 5 3 4 1\n\
        o spike\nf 1 2 3 2 4\n\
        o flat\nf 1 2 1\n\
        o pinched\nf 1 2 3 1 6 7\n";
    let (scene, warnings) = load_unmerged(obj);
    let find = |name: &str| {
        scene
            .surfaces
            .iter()
            .find(|s| s.name == name)
            .unwrap_or_else(|| panic!("{name} in {:?}", scene.surfaces))
    };
    assert_eq!(find("doubled/wall/0").polygon.len(), 4);
    assert_eq!(find("closed/wall/0").polygon.len(), 4);
    assert_eq!(find("spike/wall/0").polygon.len(), 3);
    assert_eq!(find("pinched/wall/0.0").area(), 0.5);
    assert_eq!(find("pinched/wall/0.1").area(), 0.5);
    assert!(scene.surface_id("flat/wall/0").is_none());
    let expected = [
        "removed repeated corners from 3 faces (first: doubled/wall/0 at line 11, closed/wall/0 at line 13, \
         spike/wall/0 at line 15)",
        "split 1 faces that touch themselves at a corner into 2 pieces (first: pinched/wall/0 at line 19)",
        "dropped 1 faces with fewer than 3 distinct corners (first: flat/wall/0 at line 17)",
    ];
    for line in expected {
        assert!(warnings.iter().any(|w| w == line), "{line}\n{warnings:#?}");
    }
}

#[test]
fn zero_area_and_non_planar_faces_name_where_they_are() {
    let obj = "mtllib m.mtl\nusemtl wall\nv 0 0 0\nv 1 0 0\nv 2 0 0\nv 1 1 0.3\nv 0 1 0\n\
        o a\nf 1 2 3\no b\nf 1 2 4 5\n";
    let (scene, warnings) = load(obj);
    assert_eq!(scene.surfaces.len(), 2);
    assert!(
        warnings
            .iter()
            .any(|w| w == "dropped 1 faces with zero area (first: a/wall/0 at line 9)"),
        "{warnings:#?}"
    );
    assert!(
        warnings
            .iter()
            .any(|w| w == "split 1 non-planar faces into 2 triangles (first: b/wall/0 at line 11)"),
        "{warnings:#?}"
    );
}

#[test]
fn polylines_are_not_surfaces() {
    let obj = "mtllib m.mtl\nusemtl wall\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nl 1 2 3 4\nf 1 2 3\n";
    let (scene, warnings) = load(obj);
    assert_eq!(scene.surfaces.len(), 1);
    assert!(
        warnings
            .iter()
            .any(|w| w.starts_with("ignored 1 polylines") && w.contains("line 7")),
        "{warnings:#?}"
    );
}

#[test]
fn a_missing_library_names_the_path_looked_for() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = "mtllib missing.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let path = dir.path().join("scene.obj");
    std::fs::write(&path, obj).expect("write obj");
    let (_, warnings) = read_scene_file(&path).expect("reads");
    let looked_for = dir.path().join("missing.mtl");
    let expected = format!(
        "material library not found: looked for {} (mtllib at line 1)",
        looked_for.display()
    );
    assert!(
        warnings.iter().any(|w| w.starts_with(&expected)),
        "{expected}\n{warnings:#?}"
    );
    assert!(
        warnings.iter().any(
            |w| w.contains("\"red\" at line 2") && w.contains("defined in no material library")
        ),
        "{warnings:#?}"
    );
}

#[test]
fn warnings_survive_a_failed_validation() {
    let dir = tempfile::tempdir().expect("temp dir");
    // No emitter, and a face with no area.
    let obj = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 1 2 3\n";
    let path = dir.path().join("dark.obj");
    std::fs::write(&path, obj).expect("write obj");
    match load_scene(path.to_str().expect("utf-8")) {
        Err(SceneError::Invalid {
            problems, warnings, ..
        }) => {
            assert!(
                problems.iter().any(|p| p.kind == ProblemKind::NoEmitter),
                "{problems:?}"
            );
            assert!(
                warnings
                    .iter()
                    .any(|w| w.starts_with("dropped 1 faces with zero area")),
                "{warnings:?}"
            );
            assert!(
                warnings.iter().any(|w| w.contains("have no material")),
                "{warnings:?}"
            );
        }
        other => panic!("expected a validation error, got {other:?}"),
    }
}

/// A room of many materials: tessellated walls, a checkerboard floor of two materials, a wall
/// folded along its middle, a ring and a lamp. Every material keeps its area.
#[test]
fn merging_keeps_each_materials_area() {
    let mut obj = String::from("mtllib m.mtl\n");
    let mut count = 0;
    let mut vertex = |obj: &mut String, p: DVec3| {
        *obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
        count += 1;
        count
    };
    // Floor: 6 x 6 squares of 0.5, alternating wall and red, each as two triangles.
    for j in 0..6 {
        for i in 0..6 {
            let p =
                |a: usize, b: usize| DVec3::new(0.5 * (i + a) as f64, 0.5 * (j + b) as f64, 0.0);
            let ids: Vec<usize> = [(0, 0), (1, 0), (1, 1), (0, 1)]
                .iter()
                .map(|&(a, b)| vertex(&mut obj, p(a, b)))
                .collect();
            let material = if (i + j) % 2 == 0 { "wall" } else { "red" };
            obj += &format!(
                "usemtl {material}\nf {} {} {}\nf {} {} {}\n",
                ids[0], ids[1], ids[2], ids[0], ids[2], ids[3]
            );
        }
    }
    // A wall at x = 0 of 5 x 4 quads whose far half leans out by 1e-3.
    let lean = |z: f64| if z > 1.0 { (z - 1.0) * 1e-3 } else { 0.0 };
    for k in 0..5 {
        for l in 0..4 {
            let p = |a: usize, b: usize| {
                let (y, z) = (0.6 * (k + a) as f64, 0.5 * (l + b) as f64);
                DVec3::new(lean(z), y, z)
            };
            let ids: Vec<usize> = [(0, 0), (0, 1), (1, 1), (1, 0)]
                .iter()
                .map(|&(a, b)| vertex(&mut obj, p(a, b)))
                .collect();
            obj += &format!(
                "usemtl wall\nf {} {} {} {}\n",
                ids[0], ids[1], ids[2], ids[3]
            );
        }
    }
    // A lamp of two triangles.
    let lamp: Vec<usize> = [(1.0, 1.0), (1.0, 2.0), (2.0, 2.0), (2.0, 1.0)]
        .iter()
        .map(|&(x, y)| vertex(&mut obj, DVec3::new(x, y, 2.0)))
        .collect();
    obj += &format!(
        "usemtl lamp\nf {} {} {}\nf {} {} {}\n",
        lamp[0], lamp[1], lamp[2], lamp[0], lamp[2], lamp[3]
    );
    let scene = assert_merge_is_exact(&obj);
    assert!(penumbra_scenes::validate(&scene).is_empty());
    // The checkerboard cannot merge across materials, but each square's two triangles can (36);
    // the wall is two planes meeting at a fold of a thousandth (2); the lamp is one square.
    assert_eq!(scene.surfaces.len(), 36 + 2 + 1, "{:#?}", scene.surfaces);
    assert!(scene.surfaces.iter().all(|s| s.polygon.len() == 4));
    let lamps: Vec<_> = scene.surfaces.iter().filter(|s| s.is_emitter()).collect();
    assert_eq!(lamps.len(), 1);
    assert_eq!(lamps[0].area(), 1.0);
}

/// Seeded random tessellations: squares of a tilted grid, some missing (holes, rings, squares
/// touching at a corner), each as a quad or two triangles, in one of two materials. Whatever
/// merges, every material keeps its area and every surface is valid.
#[test]
fn random_tessellations_merge_exactly() {
    let mut rng = penumbra_scenes::SplitMix64::new(11);
    let mut merged_any = 0;
    for case in 0..200 {
        let mut random = |n: u64| (rng.next_u64() % n) as usize;
        let n = 2 + random(7);
        let du = DVec3::new(0.3, 0.1 * random(3) as f64, 0.07);
        let dv = DVec3::new(-0.05, 0.2, 0.11 * random(2) as f64);
        let origin = DVec3::new(random(5) as f64, -1.3, 0.7);
        let mut obj = String::from("mtllib m.mtl\n");
        for j in 0..=n {
            for i in 0..=n {
                let p = origin + du * i as f64 + dv * j as f64;
                obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
            }
        }
        let v = |i: usize, j: usize| 1 + i + (n + 1) * j;
        let holes = random(4);
        for j in 0..n {
            for i in 0..n {
                if random(10) < holes {
                    continue;
                }
                let material = if random(6) == 0 { "red" } else { "wall" };
                let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                obj += &format!("usemtl {material}\n");
                obj += &match random(3) {
                    0 => format!("f {a} {b} {c} {d}\n"),
                    1 => format!("f {a} {b} {c}\nf {a} {c} {d}\n"),
                    _ => format!("f {b} {c} {d}\nf {d} {a} {b}\n"),
                };
            }
        }
        let scene = assert_merge_is_exact(&obj);
        let (faces, _) = load_unmerged(&obj);
        if scene.surfaces.len() < faces.surfaces.len() {
            merged_any += 1;
        }
        let _ = case;
    }
    assert!(merged_any > 150, "{merged_any}");
}

#[test]
fn names_that_collide_through_slashes_are_made_unique() {
    // "a/b" with material "c" and "a" with material "b/c" both give "a/b/c/0".
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
        o a/b\nusemtl c\nf 1 2 3\no a\nusemtl b/c\nf 1 2 4\n";
    let (scene, warnings) = load(obj);
    let names: Vec<&str> = scene.surfaces.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["a/b/c/0", "a/b/c/0#2"]);
    assert!(
        warnings.iter().any(|w| w.starts_with("renamed 1 surfaces")),
        "{warnings:?}"
    );
}

/// `Kd` at or above 1 (Sponza's bricks are `Kd 1 1 1`) is clamped to
/// `MAX_OBJ_REFLECTANCE` channel by channel, with one warning per material used, naming it and
/// its value, and the scene is valid; a material no face uses is not mentioned. JSON scenes
/// keep refusing reflectance 1.
#[test]
fn reflectance_of_one_or_more_is_clamped_with_a_warning_per_material() {
    use penumbra_scenes::MAX_OBJ_REFLECTANCE;
    let mtl = "newmtl bricks\nKd 1 1 1\nnewmtl red\nKd 1.2 0.5 0.25\nnewmtl unused\nKd 1 1 1\n\
               newmtl lamp\nKd 0 0 0\nKe 5 5 5\n";
    // Four faces of bricks and two of red, apart so that none merge.
    let mut obj = String::from("mtllib m.mtl\n");
    let mut v = 0;
    for (k, material) in ["bricks", "bricks", "bricks", "bricks", "red", "red", "lamp"]
        .iter()
        .enumerate()
    {
        let (x, z) = (2.0 * k as f64, if *material == "lamp" { 1.0 } else { 0.0 });
        obj += &format!(
            "v {x} 0 {z}\nv {} 0 {z}\nv {} 1 {z}\nusemtl {material}\nf {} {} {}\n",
            x + 1.0,
            x + 1.0,
            v + 1,
            v + 2,
            v + 3
        );
        v += 3;
    }
    let (scene, warnings) = parse_obj_text(&obj, mtl, Path::new("k.obj")).expect("parses");
    assert!(penumbra_scenes::validate(&scene).is_empty());
    let clamped: Vec<&String> = warnings.iter().filter(|w| w.contains("Kd")).collect();
    assert_eq!(clamped.len(), 2, "{warnings:?}");
    assert!(
        clamped[0].contains("\"bricks\" has Kd 1 1 1") && clamped[0].contains("0.99"),
        "{}",
        clamped[0]
    );
    assert!(
        clamped[1].contains("\"red\" has Kd 1.2 0.5 0.25"),
        "{}",
        clamped[1]
    );
    let reflectance = |name: &str| {
        scene
            .surfaces
            .iter()
            .find(|s| s.name.contains(name))
            .map(|s| s.reflectance.to_array())
            .expect("surface")
    };
    assert_eq!(reflectance("bricks"), [MAX_OBJ_REFLECTANCE; 3]);
    assert_eq!(reflectance("red"), [MAX_OBJ_REFLECTANCE, 0.5, 0.25]);

    let json = r#"{"surfaces": [
        {"name": "lamp", "polygon": [[0,0,2],[0,1,2],[1,1,2],[1,0,2]], "emission": [1,1,1], "reflectance": [0,0,0]},
        {"name": "floor", "polygon": [[0,0,0],[1,0,0],[1,1,0],[0,1,0]], "reflectance": [1, 1, 1]}
    ]}"#;
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("white.json");
    std::fs::write(&path, json).expect("writes");
    let refused = load_scene(path.to_str().expect("utf-8"));
    assert!(
        matches!(refused, Err(SceneError::Invalid { .. })),
        "{refused:?}"
    );
}
