//! The outline of merged faces: tracing their boundary into one loop, dropping corners that lie
//! on a straight line to within rounding, and checking the result before it replaces the faces.

use std::collections::HashMap;

use glam::DVec3;

use super::{Mesh, NO_TWIN};
use crate::polygon;
use crate::validate::{PLANARITY_TOLERANCE, polygon_problem};

/// A corner lies on the line through its neighbours "to within rounding" when its distance from
/// the line is at most this many units of the last place of the largest coordinate involved:
/// parsing and subtraction round each coordinate by half a unit, so points exactly on the line in
/// the file's decimals land within a few units of it, and points visibly off it do not.
pub(super) const COLLINEAR_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// Merged polygons must have the area of their faces to this relative accuracy. Rounding makes
/// differences near 1e-15; this only guards against a merge that would change the geometry.
pub(super) const AREA_TOLERANCE: f64 = 1e-9;

/// The boundary of `faces` as one loop of corner ids, counter-clockwise like the faces; `None`
/// when it is several loops (holes) or touches itself (a corner visited twice). An edge is
/// interior when it has a twin face for which `inside` holds.
pub(super) fn trace(
    mesh: &Mesh,
    faces: &[usize],
    inside: impl Fn(usize) -> bool,
) -> Option<Vec<u32>> {
    let mut next: HashMap<u32, u32> = HashMap::new();
    let mut start = None;
    for &f in faces {
        for edge in mesh.edges_of(f) {
            let twin = mesh.twins[edge];
            if twin != NO_TWIN && inside(twin as usize) {
                continue;
            }
            let (a, b) = mesh.edge(edge);
            if next.insert(a, b).is_some() {
                return None;
            }
            start.get_or_insert(a);
        }
    }
    let start = start?;
    let mut boundary = vec![start];
    let mut at = *next.get(&start)?;
    while at != start {
        if boundary.len() >= next.len() {
            return None;
        }
        boundary.push(at);
        at = *next.get(&at)?;
    }
    (boundary.len() == next.len()).then_some(boundary)
}

/// The polygon of a traced boundary, with straight-angle corners dropped when that is exact,
/// or as traced if only that passes; `None` when neither is a valid surface that covers the
/// faces exactly.
pub(super) fn polygon(
    mesh: &Mesh,
    faces: &[usize],
    boundary: &[u32],
    scene_diagonal: f64,
) -> Option<Vec<DVec3>> {
    let traced: Vec<DVec3> = boundary
        .iter()
        .map(|&id| mesh.positions[id as usize])
        .collect();
    let area: f64 = faces
        .iter()
        .map(|&f| 0.5 * polygon::newell_normal(&mesh.polygons[f]).length())
        .sum();
    let straightened = without_straight_corners(&traced);
    let covers = |candidate: &[DVec3]| {
        polygon_problem(candidate, scene_diagonal).is_none()
            && same_area(candidate, area)
            && holds_corners(
                candidate,
                faces.iter().map(|&f| mesh.polygons[f].as_slice()),
            )
    };
    if covers(&straightened) {
        Some(straightened)
    } else if straightened.len() != traced.len() && covers(&traced) {
        Some(traced)
    } else {
        None
    }
}

fn same_area(candidate: &[DVec3], area: f64) -> bool {
    let merged = 0.5 * polygon::newell_normal(candidate).length();
    (merged - area).abs() <= AREA_TOLERANCE * area
}

/// Every corner of every face lies within the planarity tolerance of the merged polygon's plane
/// (its own corners are checked by validation; the faces' inner corners must be too).
fn holds_corners<'a>(candidate: &[DVec3], mut faces: impl Iterator<Item = &'a [DVec3]>) -> bool {
    let Some(normal) = polygon::newell_normal(candidate).try_normalize() else {
        return false;
    };
    let centroid = polygon::centroid(candidate);
    let tolerance = PLANARITY_TOLERANCE * polygon::diameter(candidate);
    faces.all(|face| {
        face.iter()
            .all(|&p| (p - centroid).dot(normal).abs() <= tolerance)
    })
}

/// The polygon without corners that lie, to within rounding, on the straight line between the
/// corners kept around them. Each run of straight-angle corners is checked against the line
/// between the corners at its ends, so rounding cannot accumulate along a long edge; a run that
/// fails keeps all its corners.
pub(super) fn without_straight_corners(points: &[DVec3]) -> Vec<DVec3> {
    let n = points.len();
    let straight: Vec<bool> = (0..n)
        .map(|i| between(points[(i + n - 1) % n], points[i], points[(i + 1) % n]))
        .collect();
    // Start at a corner that stays, so that no run wraps around the start.
    let Some(first_kept) = straight.iter().position(|&s| !s) else {
        return points.to_vec();
    };
    let mut keep = vec![true; n];
    let mut k = 0;
    while k < n {
        let i = (first_kept + k) % n;
        if !straight[i] {
            k += 1;
            continue;
        }
        // A run of straight corners from `i`, between the kept corners `before` and `after`.
        let before = points[(i + n - 1) % n];
        let mut run = Vec::new();
        while k < n && straight[(first_kept + k) % n] {
            run.push((first_kept + k) % n);
            k += 1;
        }
        let after = points[(first_kept + k) % n];
        if run.iter().all(|&j| between(before, points[j], after)) {
            for j in run {
                keep[j] = false;
            }
        }
    }
    points
        .iter()
        .zip(keep)
        .filter_map(|(&p, keep)| keep.then_some(p))
        .collect()
}

/// Whether `p` lies strictly between `a` and `b`, on the line through them to within rounding.
fn between(a: DVec3, p: DVec3, b: DVec3) -> bool {
    let along = b - a;
    let length = along.length();
    let scale = a.abs().max(p.abs()).max(b.abs()).max_element();
    let off_line = (p - a).cross(along).length() / length;
    length > 0.0
        && (p - a).dot(along) > 0.0
        && (b - p).dot(along) > 0.0
        && off_line <= COLLINEAR_ROUNDING * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec3 {
        DVec3::new(x, y, 0.0)
    }

    #[test]
    fn drops_only_corners_on_the_line() {
        let square = [
            v(0., 0.),
            v(0.1, 0.),
            v(0.2, 0.),
            v(0.3, 0.),
            v(0.3, 0.3),
            v(0.2, 0.2),
            v(0.1, 0.1),
            v(0., 0.),
        ];
        // The last corner repeats the first: not between, so it stays (validation reports it).
        let kept = without_straight_corners(&square[..7]);
        assert_eq!(kept, vec![v(0., 0.), v(0.3, 0.), v(0.3, 0.3)]);
        // A corner a thousandth off the line stays.
        let bent = [v(0., 0.), v(1., 1e-3), v(2., 0.), v(1., 1.)];
        assert_eq!(without_straight_corners(&bent).len(), 4);
        // A spike folding back is not a straight angle.
        let spike = [v(0., 0.), v(2., 0.), v(1., 0.), v(1., 1.)];
        assert_eq!(without_straight_corners(&spike).len(), 4);
    }
}
