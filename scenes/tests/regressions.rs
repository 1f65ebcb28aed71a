//! Inputs the `parse_scene` fuzz target found, original and reduced (`tests/regressions/`),
//! kept as tests: each must now give an answer, not a panic.
//!
//! - `mtl_colour_short_of_numbers`: an MTL colour (`Ks`) with fewer than three numbers made the
//!   OBJ reader's MTL parser panic; such lines are now refused as a material error.
//! - `glb_length_below_its_header`: a GLB whose header declares fewer bytes than the header
//!   itself made the glTF parser subtract past zero (a panic where overflow is checked, as the
//!   fuzzer builds); it is now refused before the parser sees it.

use penumbra_scenes::fuzzing::parse_any;

#[test]
fn fuzz_regressions() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("regressions folder")
        .flatten()
        .map(|e| e.path())
        .collect();
    files.sort();
    assert!(files.len() >= 2);
    for path in files {
        let data = std::fs::read(&path).expect("readable input");
        let _ = parse_any(&data);
    }
}

/// The reduced MTL case is refused with a message that names the OBJ and the material, and the
/// same scene with a whole colour loads.
#[test]
fn a_short_mtl_colour_is_a_material_error() {
    let obj = "mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let refused = penumbra_scenes::parse_obj_text(obj, "newmtl a\nKs\n", "t.obj".as_ref());
    // tobj reports unreadable materials as a warning on the models it still returns.
    match refused {
        Ok((_, warnings)) => assert!(
            warnings
                .iter()
                .any(|w| w.contains("materials could not be read")),
            "{warnings:?}"
        ),
        Err(e) => assert!(e.to_string().contains("t.obj"), "{e}"),
    }
    let (scene, _) =
        penumbra_scenes::parse_obj_text(obj, "newmtl a\nKd 0.25 0.5 0.75\n", "t.obj".as_ref())
            .expect("parses");
    assert_eq!(scene.surfaces[0].reflectance.g, 0.5);
}

/// The reduced GLB case is refused with a message that says what its header declares.
#[test]
fn a_glb_shorter_than_its_header_is_refused() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions");
    let data = std::fs::read(dir.join("glb_length_below_its_header_reduced.bin")).expect("input");
    let refused = parse_any(&data).expect_err("refused");
    assert!(
        refused
            .to_string()
            .contains("declares 4 bytes, fewer than the header's own 12"),
        "{refused}"
    );
}
