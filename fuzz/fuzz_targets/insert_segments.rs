//! Segment insertion into a surface's constrained triangulation: any set of segments (crossing,
//! overlapping, sharing ends, a rounding error apart, sticking out of the polygon) must give a
//! sane mesh, never a panic or an error.
#![no_main]

use glam::{DVec2, DVec3};
use libfuzzer_sys::fuzz_target;
use penumbra_meshing::constrained::{ConstrainedSurface, Constraint};
use penumbra_scenes::{Rgb, Surface};

fuzz_target!(|data: &[u8]| {
    if data.len() < 2 {
        return;
    }
    // Coordinates on a coarse grid (many exact coincidences and collinearities), nudged by a
    // few units in the last place when the high bit is set.
    let coordinate = |b: &[u8]| {
        let raw = u16::from_le_bytes([b[0], b[1]]);
        let grid = f64::from(raw & 0x3ff) / 1023.0 * 1.2 - 0.1;
        if raw & 0x8000 != 0 {
            grid + f64::from((raw >> 10) & 0x1f) * f64::EPSILON
        } else {
            grid
        }
    };
    let target = 50 + usize::from(data[0]) * 20;
    let splits = data[1];
    let segments: Vec<Constraint> = data[2..]
        .chunks_exact(8)
        .take(64)
        .enumerate()
        .map(|(i, c)| Constraint {
            from: DVec2::new(coordinate(&c[0..2]), coordinate(&c[2..4])),
            to: DVec2::new(coordinate(&c[4..6]), coordinate(&c[6..8])),
            splits: (splits >> (i % 8)) & 1 == 1,
        })
        .collect();
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
