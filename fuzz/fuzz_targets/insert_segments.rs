//! Segment insertion into a surface's constrained triangulation: any set of segments (crossing,
//! overlapping, sharing ends, a rounding error apart, sticking out of the polygon) must give a
//! sane mesh, never a panic or an error, refined uniformly or graded.
#![no_main]

use glam::DVec3;
use libfuzzer_sys::fuzz_target;
use penumbra_meshing::ConstrainedSurface;
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
    let mesh = constrained.clone().into_mesh(&square, target);
    if let Err(e) = mesh.sanity_check() {
        panic!("{e}");
    }
    // Graded refinement inserts its own points: the light "varies" on the left half.
    let varies = |points: &[DVec3]| points.iter().any(|p| p.x < 0.5);
    let graded = constrained.into_graded_mesh(&square, target, 8.0, &varies);
    if let Err(e) = graded.sanity_check() {
        panic!("graded: {e}");
    }
});
