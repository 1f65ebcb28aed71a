//! Mesh coordinates: the 2D coordinates a surface's triangulation is built in.
//!
//! They are the surface's plane-frame coordinates divided by the polygon's extent and snapped to
//! a grid of 2^-36. The input to spade then depends only on the polygon's shape, so a scene that
//! is moved, rotated or scaled is meshed identically, and so is a polygon whose vertex list
//! starts at another corner (the frame and the boundary both start at one of
//! [`penumbra_scenes::polygon::canonical_starts`]; see `marked_start` for polygons with a
//! rotational symmetry).

use glam::{DVec2, DVec3};
use penumbra_scenes::polygon::{canonical_starts, signed_area_2d};
use penumbra_scenes::{PlaneFrame, Surface, SurfaceId};

use crate::error::MeshError;

/// Grid of mesh coordinates: 2^-36 of a polygon's extent (about 1.5e-11).
pub(crate) const SNAP_BITS: i32 = 36;
/// Marks (see [`MeshCoordinates::of_surface_marked`]) are compared on a grid of 2^-24 of the
/// polygon's diameter (about 6e-8): coarse against rounding, so that the frame a mark is seen
/// from does not change what is compared.
pub(crate) const MARK_QUANTUM: f64 = 1.0 / (1u64 << 24) as f64;

/// `x` rounded to the grid of mesh coordinates ([`SNAP_BITS`]).
pub(crate) fn snap(x: f64) -> f64 {
    let grid = 2f64.powi(SNAP_BITS);
    (x * grid).round() / grid
}

/// A surface's polygon in mesh coordinates, with the frame and scale that map it back.
#[derive(Clone, Debug)]
pub(crate) struct MeshCoordinates {
    pub frame: PlaneFrame,
    pub scale: f64,
    pub boundary: Vec<DVec2>,
}

impl MeshCoordinates {
    pub(crate) fn of_surface(
        id: SurfaceId,
        surface: &Surface,
    ) -> Result<MeshCoordinates, MeshError> {
        MeshCoordinates::of_surface_marked(id, surface, &[])
    }

    /// The mesh coordinates of a surface that carries `marks` (points on its plane, such as the
    /// ends of its discontinuity segments). They start at one of the polygon's
    /// [`canonical_starts`]: a polygon with a rotational symmetry has several, from which it
    /// looks the same, and of those the one from which the marks look greatest is taken, so that
    /// the mesh follows the marks, not the polygon's list.
    pub(crate) fn of_surface_marked(
        id: SurfaceId,
        surface: &Surface,
        marks: &[DVec3],
    ) -> Result<MeshCoordinates, MeshError> {
        let degenerate = || MeshError::Degenerate {
            surface: id,
            name: surface.name.clone(),
        };
        let polygon = &surface.polygon;
        let start = marked_start(polygon, marks);
        let frame = PlaneFrame::of_polygon_at(polygon, start).ok_or_else(degenerate)?;
        // The boundary starts where the frame does: spade's triangulation, and so the mesh,
        // depends on the order the boundary is inserted in, which then does not depend on the
        // corner the polygon's list starts at.
        let flat: Vec<DVec2> = polygon[start..]
            .iter()
            .chain(&polygon[..start])
            .map(|&p| frame.to_2d(p))
            .collect();
        let (lo, hi) = flat
            .iter()
            .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let scale = (hi - lo).max_element();
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(degenerate());
        }
        let mut boundary: Vec<DVec2> = flat
            .iter()
            .map(|&p| DVec2::new(snap(p.x / scale), snap(p.y / scale)))
            .collect();
        boundary.dedup();
        while boundary.len() > 1 && boundary.first() == boundary.last() {
            boundary.pop();
        }
        if boundary.len() < 3 || signed_area_2d(&boundary) <= 0.0 {
            return Err(degenerate());
        }
        Ok(MeshCoordinates {
            frame,
            scale,
            boundary,
        })
    }
}

/// Of the polygon's [`canonical_starts`], the one from which `marks` look greatest: their
/// coordinates in the frame starting there, in units of [`MARK_QUANTUM`], sorted, compared
/// lexicographically. With no marks, or marks as symmetric as the polygon, the first in list
/// order: the meshes from the others are then the same, turned by the symmetry. No choice could
/// do better there: one that did not depend on the list would have to pick the same corner of a
/// square in the square turned by a quarter, which is the same square with its list rotated, and
/// then a turned scene would not keep its frames.
fn marked_start(polygon: &[DVec3], marks: &[DVec3]) -> usize {
    let starts = canonical_starts(polygon);
    if starts.len() < 2 || marks.is_empty() {
        return starts.first().copied().unwrap_or(0);
    }
    let unit = MARK_QUANTUM * penumbra_scenes::polygon::diameter(polygon);
    let view = |start: usize| {
        let mut seen: Vec<(i64, i64)> = match PlaneFrame::of_polygon_at(polygon, start) {
            Some(frame) => marks
                .iter()
                .map(|&m| {
                    let q = frame.to_2d(m) / unit;
                    (q.x.round() as i64, q.y.round() as i64)
                })
                .collect(),
            None => Vec::new(),
        };
        seen.sort_unstable();
        seen
    };
    let mut best = (starts[0], view(starts[0]));
    for &start in &starts[1..] {
        let seen = view(start);
        if seen > best.1 {
            best = (start, seen);
        }
    }
    best.0
}
