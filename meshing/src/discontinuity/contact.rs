//! Contact lines: where a blocker touches or pierces a receiver, the light jumps (D0) — from
//! whatever reaches the open side to nothing under the blocker.
//!
//! A face that hovers over a receiver, parallel to it and closer than [`HOVER`] of its own size
//! (a light panel hung just below a ceiling), casts a shadow that is sharp from every direction
//! light comes from: under it the receiver sees almost nothing. Its outline, projected onto the
//! receiver, counts as a contact line too.
//!
//! So does the foot of a face that stands on a receiver only to a file's rounding (within
//! `Visibility::meeting_distance`): a pillar of a model written to six decimals stands up to
//! that far above or below its floor. Standing above, its foot is a hovering line with that gap,
//! whose vertices are evaluated a few gaps off it: right at the line, the side under the pillar
//! would see the light through the gap.

use glam::DVec3;
use penumbra_scenes::{Bounds, PlaneFrame, Scene, SurfaceId, Visibility};
use rayon::prelude::*;

use super::clip_to_polygon;

/// A contact line on a receiver: its ends (3D, on the receiver) and the gap under the face that
/// casts it (zero where the face touches the receiver, positive where it hovers).
pub(super) type ContactLine = (DVec3, DVec3, f64);

/// For each receiver with contacts, the segments where other surfaces stand on it, pass through
/// it from its front side, or hover over it.
pub(super) fn contact_lines(
    scene: &Scene,
    frames: &[Option<PlaneFrame>],
    visibility: &Visibility,
    searched: &(dyn Fn(SurfaceId) -> bool + Sync),
) -> Vec<(SurfaceId, Vec<ContactLine>)> {
    (0..scene.surfaces.len())
        .into_par_iter()
        .filter(|&r| searched(r))
        .filter_map(|r| {
            let lines = receiver_contacts(scene, frames[r]?, r, visibility);
            (!lines.is_empty()).then_some((r, lines))
        })
        .collect()
}

/// The contact lines on receiver `r`, whose plane frame is `rf`.
fn receiver_contacts(
    scene: &Scene,
    rf: PlaneFrame,
    r: SurfaceId,
    visibility: &Visibility,
) -> Vec<ContactLine> {
    let tol = visibility.contact_distance();
    // Files rounded to six decimals stand a pillar up to this far above or below the floor it
    // stands on: its foot casts a contact line too, with the gap it stands above the floor.
    let meeting = visibility.meeting_distance();
    let receiver = &scene.surfaces[r];
    let mut candidates = std::collections::BTreeSet::new();
    // Grown by the largest gap a face of the receiver's size may hover at.
    let b = receiver.bounds();
    let reach = DVec3::splat(HOVER * b.diagonal());
    let near = Bounds {
        min: b.min - reach,
        max: b.max + reach,
    };
    visibility.triangles_overlapping(near, |t| {
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
        if let Some(gap) = hovering(poly, &h, tol) {
            let n = poly.len();
            for i in 0..n {
                let (p, q) = (
                    poly[i] - rf.normal * gap,
                    poly[(i + 1) % n] - rf.normal * gap,
                );
                for [a, c] in clip_to_polygon(&rf, &receiver.polygon, p, q) {
                    if a.distance(c) > tol {
                        lines.push((a, c, gap));
                    }
                }
            }
            continue;
        }
        let standing: Vec<f64> = h
            .iter()
            .map(|&x| if x.abs() <= meeting { 0.0 } else { x })
            .collect();
        // A face reaching no further up than that stands on nothing.
        if !standing.iter().any(|&x| x > 0.0) {
            continue;
        }
        for (p, q, gap) in plane_section(poly, &standing, &h) {
            // Onto the plane: a foot standing near it stands that far off it.
            let (p, q) = (p - rf.normal * rf.height(p), q - rf.normal * rf.height(q));
            for [a, c] in clip_to_polygon(&rf, &receiver.polygon, p, q) {
                if a.distance(c) > tol {
                    lines.push((a, c, gap));
                }
            }
        }
    }
    lines
}

/// How close, relative to its diameter, a parallel face must hover over a receiver for its
/// shadow to count as a contact: the shadow's edge is then blurred over at most this fraction of
/// the face's size, whatever the light's direction (up to 45 degrees off the normal).
pub(super) const HOVER: f64 = 1e-3;

/// The gap under a polygon lying parallel to the plane, given its vertices' heights, if it hovers
/// within [`HOVER`] of its diameter.
fn hovering(poly: &[DVec3], h: &[f64], tol: f64) -> Option<f64> {
    let gap = h.first().copied()?;
    if !(gap > 0.0 && h.iter().all(|&x| (x - gap).abs() <= tol)) {
        return None;
    }
    // The diameter (quadratic in the vertex count) only for the rare parallel face.
    let diameter = poly
        .iter()
        .flat_map(|a| poly.iter().map(move |b| a.distance(*b)))
        .fold(0.0, f64::max);
    (gap <= HOVER * diameter).then_some(gap)
}

/// Where a planar polygon meets a plane, given its vertices' heights above it (zero: on it):
/// its edges lying in the plane, each with the gap it stands above the plane (from `raw`, the
/// heights before those near it were taken as on it), and the segments where it crosses the
/// plane (no gap).
fn plane_section(poly: &[DVec3], h: &[f64], raw: &[f64]) -> Vec<(DVec3, DVec3, f64)> {
    let n = poly.len();
    let mut out = Vec::new();
    // Edges in the plane.
    for i in 0..n {
        let j = (i + 1) % n;
        if h[i] == 0.0 && h[j] == 0.0 {
            out.push((poly[i], poly[j], raw[i].max(raw[j]).max(0.0)));
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
            out.push((pair[0], pair[1], 0.0));
        }
    }
    out
}
