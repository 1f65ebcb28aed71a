//! Segment insertion into a surface's constrained triangulation: any set of segments (crossing,
//! overlapping, sharing ends, a rounding error apart, sticking out of the polygon) must give a
//! sane mesh, never a panic or an error.
#![no_main]

use glam::DVec3;
use libfuzzer_sys::fuzz_target;
use penumbra_meshing::constrained::ConstrainedSurface;
use penumbra_meshing::fuzzing::constraints_from_bytes;
use penumbra_scenes::{Rgb, Surface};

fuzz_target!(|data: &[u8]| {
    let Some((target, segments)) = constraints_from_bytes(data) else {
        return;
    };
    let square = Surface::new(
        "square",
        vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
        Rgb::splat(0.5),
    );
    let constrained = match ConstrainedSurface::new(0, &square, &segments) {
        Ok(c) => c,
        Err(e) => panic!("insertion failed: {e}"),
    };
    let mesh = constrained.into_mesh(&square, target);
    if let Err(e) = mesh.sanity_check() {
        panic!("{e}");
    }
});
