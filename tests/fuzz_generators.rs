//! The fuzz targets' generators, seeded, in the normal test command: random bytes through the
//! scene parsers and through the whole pipeline on small scenes. Nothing may panic; a parsed and
//! solved scene must be physical (see `penumbra::fuzzing`).

use penumbra_scenes::SplitMix64;

fn random_bytes(rng: &mut SplitMix64, len: usize) -> Vec<u8> {
    (0..len).map(|_| rng.next_u64() as u8).collect()
}

#[test]
fn random_bytes_never_crash_the_parsers() {
    let mut rng = SplitMix64::new(6);
    for case in 0..2000 {
        let len = (rng.next_u64() % 300) as usize;
        let data = random_bytes(&mut rng, len);
        // Errors are answers; only a panic fails.
        let _ = penumbra_scenes::fuzzing::parse_any(&data);
        let _ = case;
    }
    // Mostly well-formed text too: a valid scene with one byte changed.
    let valid = penumbra_scenes::to_json(&penumbra_scenes::builtin::textbook());
    for _ in 0..500 {
        let mut text = valid.clone().into_bytes();
        let at = (rng.next_u64() as usize) % text.len();
        text[at] = rng.next_u64() as u8;
        let mut data = vec![0u8];
        data.extend(text);
        let _ = penumbra_scenes::fuzzing::parse_any(&data);
    }
}

/// A GLB of two quads, a light over a floor, each an indexed primitive of its own node.
fn two_quads_glb() -> Vec<u8> {
    // The floor faces +y, the light (clockwise seen from above) -y.
    let quads = [
        [
            0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, -1.0,
        ],
        [
            0.2f32, 1.0, -0.2, 0.2, 1.0, -0.8, 0.8, 1.0, -0.8, 0.8, 1.0, -0.2,
        ],
    ];
    let mut bin: Vec<u8> = quads
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let indices: [u16; 6] = [0, 1, 2, 0, 2, 3];
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    bin.extend([0, 0, 0, 0]);
    let accessor = |view: usize, count: usize, kind: &str, component: u32| serde_json::json!({"bufferView": view, "componentType": component, "count": count, "type": kind});
    let mesh = |m: usize| serde_json::json!({"primitives": [{"attributes": {"POSITION": m}, "indices": 2, "material": m}]});
    let document = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"name": "floor", "mesh": 0}, {"name": "light", "mesh": 1, "translation": [0, 0.01, 0]}],
        "meshes": [mesh(0), mesh(1)],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}},
            {"emissiveFactor": [1, 1, 1]},
        ],
        "accessors": [accessor(0, 4, "VEC3", 5126), accessor(1, 4, "VEC3", 5126), accessor(2, 6, "SCALAR", 5123)],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 12},
        ],
        "buffers": [{"byteLength": bin.len()}],
    });
    let mut json = document.to_string().into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut glb = Vec::new();
    for word in [
        u32::from_le_bytes(*b"glTF"),
        2,
        total as u32,
        json.len() as u32,
    ] {
        glb.extend(word.to_le_bytes());
    }
    glb.extend(b"JSON");
    glb.extend(json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(bin);
    glb
}

#[test]
fn changed_and_cut_glb_files_never_crash_the_parser() {
    let mut valid = vec![2u8];
    valid.extend(two_quads_glb());
    // The unchanged file is a scene: the mutations start from something the parser accepts.
    let parsed = penumbra_scenes::fuzzing::parse_any(&valid);
    assert!(matches!(&parsed, Ok(p) if p.is_empty()), "{parsed:?}");
    let mut rng = SplitMix64::new(8);
    for _ in 0..3000 {
        let mut data = valid.clone();
        for _ in 0..1 + rng.next_u64() % 3 {
            let at = 1 + (rng.next_u64() as usize) % (data.len() - 1);
            data[at] = rng.next_u64() as u8;
        }
        let _ = penumbra_scenes::fuzzing::parse_any(&data);
    }
    for len in 1..valid.len() {
        let _ = penumbra_scenes::fuzzing::parse_any(&valid[..len]);
    }
}

#[test]
fn small_random_scenes_solve_physically() {
    let mut rng = SplitMix64::new(7);
    let mut solved = 0;
    for case in 0..60 {
        let data = random_bytes(&mut rng, 67);
        let Some(scene) = penumbra_scenes::fuzzing::scene_from_bytes(&data) else {
            continue;
        };
        if penumbra_scenes::validate(&scene).is_empty() {
            solved += 1;
        }
        if let Err(e) = penumbra::fuzzing::run_small(scene) {
            panic!("case {case} ({data:?}): {e}");
        }
    }
    // The generator must reach the pipeline, not only the validator.
    assert!(solved >= 10, "only {solved} valid scenes");
}
