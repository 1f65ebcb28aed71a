//! Contact lines: where a blocker touches or pierces a receiver, the light jumps (D0) — from
//! whatever reaches the open side to nothing under the blocker.

use glam::DVec3;
use penumbra_scenes::{PlaneFrame, Scene, SurfaceId, Visibility};

use super::clip_to_polygon;

/// For each receiver with contacts, the segments (in 3D, on the receiver) where other surfaces
/// stand on it or pass through it from its front side.
pub fn contact_lines(
    scene: &Scene,
    frames: &[Option<PlaneFrame>],
    visibility: &Visibility,
) -> Vec<(SurfaceId, Vec<(DVec3, DVec3)>)> {
    let tol = visibility.contact_distance();
    let mut out = Vec::new();
    for (r, receiver) in scene.surfaces.iter().enumerate() {
        let Some(rf) = frames[r] else { continue };
        let mut candidates = std::collections::BTreeSet::new();
        visibility.triangles_overlapping(receiver.bounds(), |t| {
            candidates.insert(visibility.triangles()[t].surface);
        });
        let mut lines = Vec::new();
        for b in candidates {
            if b == r {
                continue;
            }
            let poly = &scene.surfaces[b].polygon;
            let h: Vec<f64> = poly
                .iter()
                .map(|&p| {
                    let h = rf.height(p);
                    if h.abs() <= tol { 0.0 } else { h }
                })
                .collect();
            // Only blockers reaching the front matter, and coplanar ones hide nothing.
            if !h.iter().any(|&x| x > 0.0) {
                continue;
            }
            for (p, q) in plane_section(poly, &h) {
                for [a, c] in clip_to_polygon(&rf, &receiver.polygon, p, q) {
                    if a.distance(c) > tol {
                        lines.push((a, c));
                    }
                }
            }
        }
        if !lines.is_empty() {
            out.push((r, lines));
        }
    }
    out
}

/// Where a planar polygon meets a plane, given its vertices' heights above it (zero: on it):
/// its edges lying in the plane, and the segments where it crosses the plane.
fn plane_section(poly: &[DVec3], h: &[f64]) -> Vec<(DVec3, DVec3)> {
    let n = poly.len();
    let mut out = Vec::new();
    // Edges in the plane.
    for i in 0..n {
        let j = (i + 1) % n;
        if h[i] == 0.0 && h[j] == 0.0 {
            out.push((poly[i], poly[j]));
        }
    }
    // Crossings: points where an edge passes from one side to the other, paired in order along
    // the line of intersection (a simple polygon crosses a line an even number of times).
    let mut crossings: Vec<DVec3> = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        if (h[i] > 0.0 && h[j] < 0.0) || (h[i] < 0.0 && h[j] > 0.0) {
            crossings.push(poly[i].lerp(poly[j], h[i] / (h[i] - h[j])));
        } else if h[i] == 0.0 {
            // A vertex on the plane between vertices on opposite sides is a crossing too.
            let prev = h[(i + n - 1) % n];
            if (prev > 0.0 && h[j] < 0.0) || (prev < 0.0 && h[j] > 0.0) {
                crossings.push(poly[i]);
            }
        }
    }
    if crossings.len() >= 2 {
        let dir = crossings[1] - crossings[0];
        crossings.sort_by(|a, b| dir.dot(*a).total_cmp(&dir.dot(*b)));
        for pair in crossings.chunks_exact(2) {
            out.push((pair[0], pair[1]));
        }
    }
    out
}
