//! The scene parsers and the validator: any bytes, read as JSON, OBJ+MTL or glTF, give a scene, its
//! problems or an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = penumbra_scenes::fuzzing::parse_any(data);
});
