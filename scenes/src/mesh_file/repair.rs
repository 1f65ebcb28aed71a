//! Repairs of single faces that cannot change the lighting, each counted for a warning.
//!
//! - Repeated corners: a corner equal to the one before it (or within
//!   [`SAME_POINT_TOLERANCE`] of the scene) is dropped, and a closing corner equal to the first.
//! - A face that returns to an earlier corner touches itself there: it is cut into the loops
//!   between the visits. A loop of two corners (a spike, `a b a`) has no area and is dropped, so
//!   `1 2 3 2 4` becomes `1 2 4`; `1 2 3 1 4 5` becomes the triangles `1 2 3` and `1 4 5`.
//! - Faces left with fewer than three corners, or with no area (slivers below [`MIN_THINNESS`], or
//!   smaller than [`MIN_RELATIVE_SIZE`] of the scene), are dropped.
//! - Non-planar faces are split into triangles: ear clipping of their projection onto the
//!   best-fit plane when that projection is simple, else a fan.

use std::collections::HashMap;

use glam::DVec3;

use super::tally::{FaceSource, Tally, thousands};
use crate::frame::PlaneFrame;
use crate::polygon;
use crate::validate::{MIN_RELATIVE_SIZE, MIN_THINNESS, PLANARITY_TOLERANCE, SAME_POINT_TOLERANCE};

/// One face of the file: where it came from, its corners and its material (an index into the
/// materials tobj read).
#[derive(Clone, Debug)]
pub(crate) struct Face {
    pub source: FaceSource,
    pub polygon: Vec<DVec3>,
    pub material: Option<usize>,
}

/// What the repairs did, for the warnings.
#[derive(Debug, Default)]
pub(crate) struct Repairs {
    repeated_corners: Tally,
    touching_themselves: Tally,
    loops_from_touching: usize,
    too_few_corners: Tally,
    zero_area: Tally,
    non_planar: Tally,
    triangles_from_non_planar: usize,
}

impl Repairs {
    pub(crate) fn warnings(&self) -> Vec<String> {
        [
            self.repeated_corners
                .describe("removed repeated corners from", "faces"),
            self.touching_themselves.describe(
                "split",
                &format!(
                    "faces that touch themselves at a corner into {} pieces",
                    thousands(self.loops_from_touching)
                ),
            ),
            self.too_few_corners
                .describe("dropped", "faces with fewer than 3 distinct corners"),
            self.zero_area.describe("dropped", "faces with zero area"),
            self.non_planar.describe(
                "split",
                &format!(
                    "non-planar faces into {} triangles",
                    thousands(self.triangles_from_non_planar)
                ),
            ),
        ]
        .into_iter()
        .flatten()
        .collect()
    }
}

/// The faces that replace `face`: itself, pieces of it, or none. `scene_diagonal` sets the
/// scale of the relative tolerances.
pub(crate) fn repair_face(face: Face, scene_diagonal: f64, repairs: &mut Repairs) -> Vec<Face> {
    if face.polygon.iter().any(|p| !p.is_finite()) {
        // Nothing to measure; validation names the face.
        return vec![face];
    }
    let same = SAME_POINT_TOLERANCE * scene_diagonal;
    let corners = without_repeated_corners(&face.polygon, same);
    let loops = split_where_touching(&corners);
    if loops.is_empty() {
        repairs.too_few_corners.note(&face.source);
        return Vec::new();
    }
    if loops.len() > 1 {
        repairs.touching_themselves.note(&face.source);
        repairs.loops_from_touching += loops.len();
    } else if loops[0].len() != face.polygon.len() {
        repairs.repeated_corners.note(&face.source);
    }
    let count = loops.len();
    let mut out = Vec::new();
    for (k, polygon) in loops.into_iter().enumerate() {
        let piece = Face {
            source: piece_source(&face.source, k, count),
            polygon,
            material: face.material,
        };
        out.extend(flatten(piece, scene_diagonal, repairs));
    }
    out
}

/// `name.k` for piece `k` of `count`, or the face itself when it is whole.
fn piece_source(source: &FaceSource, k: usize, count: usize) -> FaceSource {
    if count == 1 {
        source.clone()
    } else {
        FaceSource {
            name: format!("{}.{k}", source.name),
            line: source.line,
        }
    }
}

/// Drops `face` if it has no area, splits it into triangles if it is not planar.
fn flatten(face: Face, scene_diagonal: f64, repairs: &mut Repairs) -> Vec<Face> {
    let diameter = polygon::diameter(&face.polygon);
    if !has_area(&face.polygon, diameter, scene_diagonal) {
        repairs.zero_area.note(&face.source);
        return Vec::new();
    }
    if is_planar(&face.polygon, diameter) {
        return vec![face];
    }
    repairs.non_planar.note(&face.source);
    let triangles: Vec<Vec<DVec3>> = split_into_triangles(&face.polygon)
        .into_iter()
        .filter(|t| has_area(t, polygon::diameter(t), scene_diagonal))
        .collect();
    repairs.triangles_from_non_planar += triangles.len();
    let count = triangles.len();
    triangles
        .into_iter()
        .enumerate()
        .map(|(k, polygon)| Face {
            source: piece_source(&face.source, k, count),
            polygon,
            material: face.material,
        })
        .collect()
}

/// Corners without those equal (or within `same`) to the corner before them, cyclically.
fn without_repeated_corners(corners: &[DVec3], same: f64) -> Vec<DVec3> {
    let mut out: Vec<DVec3> = Vec::with_capacity(corners.len());
    for &p in corners {
        if out.last().is_none_or(|&q| q.distance(p) > same) {
            out.push(p);
        }
    }
    while out.len() > 1
        && out
            .first()
            .zip(out.last())
            .is_some_and(|(&a, &b)| a.distance(b) <= same)
    {
        out.pop();
    }
    out
}

/// The loops of a face that returns to earlier corners, each with at least three corners. A face
/// that never does is its own single loop.
fn split_where_touching(corners: &[DVec3]) -> Vec<Vec<DVec3>> {
    let key = |p: DVec3| [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
    let mut stack: Vec<DVec3> = Vec::with_capacity(corners.len());
    let mut on_stack: HashMap<[u64; 3], usize> = HashMap::new();
    let mut loops = Vec::new();
    for &p in corners {
        if let Some(&at) = on_stack.get(&key(p)) {
            // The corners after the earlier visit close a loop at `p`.
            let tail = stack.split_off(at + 1);
            for q in &tail {
                on_stack.remove(&key(*q));
            }
            let mut closed = vec![p];
            closed.extend(tail);
            if closed.len() >= 3 {
                loops.push(closed);
            }
        } else {
            on_stack.insert(key(p), stack.len());
            stack.push(p);
        }
    }
    if stack.len() >= 3 {
        loops.push(stack);
    }
    loops
}

fn has_area(points: &[DVec3], diameter: f64, scene_diagonal: f64) -> bool {
    let area = 0.5 * polygon::newell_normal(points).length();
    points.len() >= 3
        && diameter >= MIN_RELATIVE_SIZE * scene_diagonal
        && area >= MIN_THINNESS * diameter * diameter
}

/// The same test as validation: every corner within [`PLANARITY_TOLERANCE`] of the diameter from
/// the plane through the centroid.
fn is_planar(points: &[DVec3], diameter: f64) -> bool {
    let normal = polygon::newell_normal(points).normalize_or_zero();
    let centroid = polygon::centroid(points);
    points
        .iter()
        .all(|&p| (p - centroid).dot(normal).abs() <= PLANARITY_TOLERANCE * diameter)
}

/// Triangles covering a non-planar face: ear clipping of its projection onto the best-fit plane
/// when that is a simple counter-clockwise polygon (so that non-convex faces split without
/// overlaps), else a fan from the corner that gives the most even triangles.
fn split_into_triangles(points: &[DVec3]) -> Vec<Vec<DVec3>> {
    if let Some(frame) = PlaneFrame::of_polygon(points) {
        let flat: Vec<_> = points.iter().map(|&p| frame.to_2d(p)).collect();
        if polygon::first_self_intersection(&flat).is_none() && polygon::signed_area_2d(&flat) > 0.0
        {
            return polygon::triangulate_ccw(&flat)
                .into_iter()
                .map(|t| t.iter().map(|&i| points[i]).collect())
                .collect();
        }
    }
    fan(points)
}

/// A fan from one corner; for quads, from the end of the shorter diagonal.
fn fan(points: &[DVec3]) -> Vec<Vec<DVec3>> {
    let n = points.len();
    let apex = if n == 4 && points[1].distance(points[3]) < points[0].distance(points[2]) {
        1
    } else {
        0
    };
    (1..n.saturating_sub(1))
        .map(|k| {
            vec![
                points[apex],
                points[(apex + k) % n],
                points[(apex + k + 1) % n],
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec3 {
        DVec3::new(x, y, 0.0)
    }

    #[test]
    fn spikes_vanish_and_touching_faces_split() {
        let spike = [v(0., 0.), v(1., 0.), v(1., 1.), v(1., 0.), v(0., 1.)];
        assert_eq!(
            split_where_touching(&spike),
            vec![vec![v(0., 0.), v(1., 0.), v(0., 1.)]]
        );
        let pinched = [
            v(0., 0.),
            v(1., 0.),
            v(1., 1.),
            v(0., 0.),
            v(-1., 0.),
            v(-1., -1.),
        ];
        let loops = split_where_touching(&without_repeated_corners(&pinched, 0.0));
        assert_eq!(loops.len(), 2, "{loops:?}");
        let area: f64 = loops
            .iter()
            .map(|l| 0.5 * polygon::newell_normal(l).length())
            .sum();
        assert_eq!(area, 1.0);
    }

    #[test]
    fn closing_and_doubled_corners_are_dropped() {
        let square = [
            v(0., 0.),
            v(1., 0.),
            v(1., 0.),
            v(1., 1.),
            v(0., 1.),
            v(0., 0.),
        ];
        assert_eq!(without_repeated_corners(&square, 0.0).len(), 4);
    }
}
