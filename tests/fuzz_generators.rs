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
