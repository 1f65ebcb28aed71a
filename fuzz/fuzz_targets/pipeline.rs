//! The whole pipeline on small scenes made of random polygons and lights: rejected, or solved
//! with finite, non-negative radiosity and balanced energy, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some(scene) = penumbra_scenes::fuzzing::scene_from_bytes(data) else {
        return;
    };
    if let Err(e) = penumbra::fuzzing::run_small(scene) {
        panic!("{e}");
    }
});
