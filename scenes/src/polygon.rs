//! Planar polygon geometry: normals, areas, simplicity, convexity and triangulation.
//!
//! Combinatorial decisions (does an edge cross another, is a vertex an ear) use Shewchuk's exact
//! `orient2d`, so a polygon's topology is decided the same way however it was rounded.

use glam::{DVec2, DVec3};
use robust::{Coord, orient2d};

/// Newell's normal: its direction is the right-hand-rule normal and its length twice the area.
pub fn newell_normal(points: &[DVec3]) -> DVec3 {
    let Some(&anchor) = points.first() else {
        return DVec3::ZERO;
    };
    // Relative to the first vertex, so that far-away polygons keep their digits.
    let mut n = DVec3::ZERO;
    for i in 1..points.len().saturating_sub(1) {
        n += (points[i] - anchor).cross(points[i + 1] - anchor);
    }
    n
}

/// Largest distance between two vertices.
pub fn diameter(points: &[DVec3]) -> f64 {
    let mut d2: f64 = 0.0;
    for (i, &a) in points.iter().enumerate() {
        for &b in &points[i + 1..] {
            d2 = d2.max(a.distance_squared(b));
        }
    }
    d2.sqrt()
}

pub fn centroid(points: &[DVec3]) -> DVec3 {
    points.iter().copied().sum::<DVec3>() / points.len().max(1) as f64
}

/// Twice the signed area would lose a bit; this is the signed area itself (positive if CCW).
pub fn signed_area_2d(points: &[DVec2]) -> f64 {
    let Some(&anchor) = points.first() else {
        return 0.0;
    };
    let mut a = 0.0;
    for i in 1..points.len().saturating_sub(1) {
        a += (points[i] - anchor).perp_dot(points[i + 1] - anchor);
    }
    0.5 * a
}

fn coord(p: DVec2) -> Coord<f64> {
    Coord { x: p.x, y: p.y }
}

/// Exact orientation: > 0 if `c` is left of `a -> b`, < 0 if right, 0 if collinear.
pub fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    orient2d(coord(a), coord(b), coord(c))
}

/// Whether the closed segments `a-b` and `c-d` share at least one point (exact).
pub fn segments_touch(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let o1 = orient(a, b, c);
    let o2 = orient(a, b, d);
    let o3 = orient(c, d, a);
    let o4 = orient(c, d, b);
    if ((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0))
        && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0))
    {
        return true;
    }
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        // r collinear with p-q: is it within the segment's box?
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    (o1 == 0.0 && on(a, b, c))
        || (o2 == 0.0 && on(a, b, d))
        || (o3 == 0.0 && on(c, d, a))
        || (o4 == 0.0 && on(c, d, b))
}

/// The first pair of edges that makes a polygon non-simple: two non-adjacent edges that touch,
/// or two adjacent edges that fold back onto each other. Edge `i` runs from vertex `i` to `i+1`.
pub fn first_self_intersection(points: &[DVec2]) -> Option<(usize, usize)> {
    let n = points.len();
    if n < 3 {
        return None;
    }
    let edge = |i: usize| (points[i], points[(i + 1) % n]);
    for i in 0..n {
        let (a, b) = edge(i);
        // Adjacent edge i, i+1 folds back if it is collinear and reverses direction.
        let c = points[(i + 2) % n];
        if orient(a, b, c) == 0.0 && (b - a).dot(c - b) < 0.0 {
            return Some((i, (i + 1) % n));
        }
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue; // adjacent through vertex 0
            }
            let (c, d) = edge(j);
            if segments_touch(a, b, c, d) {
                return Some((i, j));
            }
        }
    }
    None
}

/// Convex (interior angles at most 180 degrees) for a counter-clockwise polygon.
pub fn is_convex_ccw(points: &[DVec2]) -> bool {
    let n = points.len();
    (0..n).all(|i| orient(points[i], points[(i + 1) % n], points[(i + 2) % n]) >= 0.0)
}

/// Ear-clipping triangulation of a simple counter-clockwise polygon, as index triples.
///
/// Zero-area triangles (from vertices on a straight angle) are left out, so the triangles may be
/// fewer than `n - 2`; their areas always sum to the polygon's.
pub fn triangulate_ccw(points: &[DVec2]) -> Vec<[usize; 3]> {
    let mut remaining: Vec<usize> = (0..points.len()).collect();
    let mut triangles = Vec::with_capacity(points.len().saturating_sub(2));
    // Every pass removes one vertex; the cap guards against malformed (non-simple) input.
    let mut guard = points.len() * points.len() + 8;
    while remaining.len() > 3 && guard > 0 {
        guard -= 1;
        let m = remaining.len();
        let ear = (0..m).find(|&k| {
            let (a, b, c) = (
                remaining[(k + m - 1) % m],
                remaining[k],
                remaining[(k + 1) % m],
            );
            let (pa, pb, pc) = (points[a], points[b], points[c]);
            if orient(pa, pb, pc) <= 0.0 {
                return false;
            }
            remaining.iter().all(|&o| {
                o == a
                    || o == b
                    || o == c
                    || points[o] == pa
                    || points[o] == pb
                    || points[o] == pc
                    || !(orient(pa, pb, points[o]) >= 0.0
                        && orient(pb, pc, points[o]) >= 0.0
                        && orient(pc, pa, points[o]) >= 0.0)
            })
        });
        match ear {
            Some(k) => {
                let a = remaining[(k + m - 1) % m];
                let c = remaining[(k + 1) % m];
                triangles.push([a, remaining[k], c]);
                remaining.remove(k);
            }
            None => {
                // Only straight-angle vertices are left to cut: drop one, it adds no area.
                let Some(k) = (0..m).find(|&k| {
                    orient(
                        points[remaining[(k + m - 1) % m]],
                        points[remaining[k]],
                        points[remaining[(k + 1) % m]],
                    ) == 0.0
                }) else {
                    break;
                };
                remaining.remove(k);
            }
        }
    }
    if remaining.len() == 3
        && orient(
            points[remaining[0]],
            points[remaining[1]],
            points[remaining[2]],
        ) > 0.0
    {
        triangles.push([remaining[0], remaining[1], remaining[2]]);
    }
    triangles
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn triangulates_non_convex_polygons_exactly() {
        let l = [
            v(-1.0, -1.0),
            v(1.0, -1.0),
            v(1.0, 0.0),
            v(0.0, 0.0),
            v(0.0, 1.0),
            v(-1.0, 1.0),
        ];
        let tris = triangulate_ccw(&l);
        assert_eq!(tris.len(), 4);
        let area: f64 = tris
            .iter()
            .map(|t| signed_area_2d(&[l[t[0]], l[t[1]], l[t[2]]]))
            .sum();
        assert!((area - 3.0).abs() < 1e-15);
        assert!(tris.iter().all(|t| orient(l[t[0]], l[t[1]], l[t[2]]) > 0.0));
        assert!(!is_convex_ccw(&l));
    }

    #[test]
    fn straight_angles_do_not_make_slivers() {
        let sq = [
            v(0.0, 0.0),
            v(1.0, 0.0),
            v(2.0, 0.0),
            v(2.0, 2.0),
            v(0.0, 2.0),
        ];
        let tris = triangulate_ccw(&sq);
        let area: f64 = tris
            .iter()
            .map(|t| signed_area_2d(&[sq[t[0]], sq[t[1]], sq[t[2]]]))
            .sum();
        assert!((area - 4.0).abs() < 1e-15);
        assert!(
            tris.iter()
                .all(|t| orient(sq[t[0]], sq[t[1]], sq[t[2]]) > 0.0)
        );
        assert!(is_convex_ccw(&sq));
    }

    #[test]
    fn finds_self_intersections() {
        let bowtie = [v(0.0, 0.0), v(1.0, 1.0), v(1.0, 0.0), v(0.0, 1.0)];
        assert!(first_self_intersection(&bowtie).is_some());
        let square = [v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)];
        assert_eq!(first_self_intersection(&square), None);
        // A vertex touching a non-adjacent edge.
        let touching = [
            v(0.0, 0.0),
            v(2.0, 0.0),
            v(2.0, 2.0),
            v(1.0, 0.0),
            v(0.0, 2.0),
        ];
        assert!(first_self_intersection(&touching).is_some());
        // A spike folding back along its own edge.
        let spike = [v(0.0, 0.0), v(2.0, 0.0), v(1.0, 0.0), v(1.0, 1.0)];
        assert!(first_self_intersection(&spike).is_some());
    }
}
