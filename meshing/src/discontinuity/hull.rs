//! Convex hulls of a few points as planes: the shaft between an emitter and a receiver, and the
//! region an EEE event's second edge must reach into.

use glam::DVec3;

/// The outward planes (normal, point) of the convex hull of `points`: every plane through three
/// of them with all the others on one side (within `tol`). Quartic in the count, for the handful
/// of corners of two polygons.
pub fn hull_planes(points: &[DVec3], tol: f64) -> Vec<(DVec3, DVec3)> {
    let n = points.len();
    let mut planes = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let Some(normal) = (points[j] - points[i])
                    .cross(points[k] - points[i])
                    .try_normalize()
                else {
                    continue;
                };
                let (lo, hi) = points.iter().fold((0.0f64, 0.0f64), |(lo, hi), &p| {
                    let h = normal.dot(p - points[i]);
                    (lo.min(h), hi.max(h))
                });
                if hi <= tol {
                    planes.push((normal, points[i]));
                } else if lo >= -tol {
                    planes.push((-normal, points[i]));
                }
            }
        }
    }
    planes
}

/// Whether all of `points` lie more than `tol` beyond one of the `planes`: then nothing spanned by
/// them meets the hull.
pub fn beyond_a_face(planes: &[(DVec3, DVec3)], points: &[DVec3], tol: f64) -> bool {
    planes
        .iter()
        .any(|&(n, o)| points.iter().all(|&x| n.dot(x - o) > tol))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_has_its_faces_and_separates_what_is_outside() {
        let corners: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
            .collect();
        let planes = hull_planes(&corners, 1e-12);
        // Every face is found (twice per face from its two triangles, and more from coplanar
        // triples), and every plane is one of the six faces.
        for (n, o) in &planes {
            assert!(corners.iter().all(|&p| n.dot(p - *o) <= 1e-12));
            assert!((n.abs().max_element() - 1.0).abs() < 1e-12, "{n}");
        }
        let inside = [DVec3::splat(0.5)];
        let crossing = [DVec3::new(-1.0, 0.5, 0.5), DVec3::new(2.0, 0.5, 0.5)];
        let outside = [DVec3::new(2.0, 0.5, 0.5), DVec3::new(3.0, 2.0, 0.1)];
        assert!(!beyond_a_face(&planes, &inside, 1e-12));
        assert!(!beyond_a_face(&planes, &crossing, 1e-12));
        assert!(beyond_a_face(&planes, &outside, 1e-12));
    }
}
