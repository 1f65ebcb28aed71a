//! Arbitrary bytes turned into meshing input, shared by the fuzz targets and the regression
//! tests that keep what they found. Hidden from the documentation: support for those, not part
//! of the crate's API.

use glam::DVec2;

use crate::constrained::Constraint;

/// Reads a refinement target and up to 64 segments in the unit square (and a little beyond it)
/// from `data`: byte 0 sets the target, byte 1 which segments split, then 8 bytes per segment.
/// Coordinates lie on a coarse grid, so that coincidences and collinearities are common, and are
/// nudged by a few units in the last place when their high bit is set.
pub fn constraints_from_bytes(data: &[u8]) -> Option<(usize, Vec<Constraint>)> {
    let (&target, rest) = data.split_first()?;
    let (&splits, rest) = rest.split_first()?;
    let coordinate = |b: &[u8]| {
        let raw = u16::from_le_bytes([b[0], b[1]]);
        let grid = f64::from(raw & 0x3ff) / 1023.0 * 1.2 - 0.1;
        if raw & 0x8000 != 0 {
            grid + f64::from((raw >> 10) & 0x1f) * f64::EPSILON
        } else {
            grid
        }
    };
    let segments = rest
        .chunks_exact(8)
        .take(64)
        .enumerate()
        .map(|(i, c)| Constraint {
            from: DVec2::new(coordinate(&c[0..2]), coordinate(&c[2..4])),
            to: DVec2::new(coordinate(&c[4..6]), coordinate(&c[6..8])),
            splits: (splits >> (i % 8)) & 1 == 1,
        })
        .collect();
    Some((50 + usize::from(target) * 4, segments))
}
