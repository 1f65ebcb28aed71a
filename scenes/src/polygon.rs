//! Planar polygon geometry: normals, areas, simplicity, convexity, triangulation, point in
//! polygon and segment clipping.
//!
//! Combinatorial decisions (does an edge cross another, is a vertex an ear) use Shewchuk's exact
//! `orient2d`, so a polygon's topology is decided the same way however it was rounded.

use std::ops::{Add, Mul, Sub};

use glam::{DVec2, DVec3};
use robust::{Coord, orient2d};

/// Lengths that agree to this fraction of a polygon's longest edge are equal when
/// [`canonical_starts`] compares its corners (about 2e-10): a square stays a square after the
/// rounding of a move or a turn, so the moved square starts at the same corner.
pub const START_LENGTH_QUANTUM: f64 = 1.0 / (1u64 << 32) as f64;

/// The corners a polygon's own computations (its frame, its mesh) may start at, whichever
/// vertex its list starts at, in list order.
///
/// Each corner `i` is described by the lengths of its edge `i -> i+1` and of the diagonal
/// `i -> i+2`, in units of [`START_LENGTH_QUANTUM`]; but for the sense of each turn, these
/// determine the polygon up to a rigid motion. The starts are the corners whose sequence of
/// descriptions, read round the polygon from them, is greatest: each starts a longest edge.
/// Rotating the list moves them along with the vertices, and moving, turning or scaling the
/// polygon keeps them (lengths change by rounding, far less than the quantum). There is more
/// than one only when the polygon has a rotational symmetry (a rectangle has two, a square
/// four): the polygon looks the same from each.
pub fn canonical_starts(points: &[DVec3]) -> Vec<usize> {
    let n = points.len();
    let length = |a: usize, b: usize| points[a % n].distance(points[b % n]);
    // The longest edge as the unit: a maximum, so the same whatever order the edges come in.
    let longest = (0..n).map(|i| length(i, i + 1)).fold(0.0, f64::max);
    let quantum = START_LENGTH_QUANTUM * longest;
    if !(quantum > 0.0 && quantum.is_finite()) {
        return vec![0];
    }
    let units = |a: usize, b: usize| (length(a, b) / quantum).round() as u64;
    let corners: Vec<(u64, u64)> = (0..n).map(|i| (units(i, i + 1), units(i, i + 2))).collect();
    let corners = &corners;
    let read_from = |start: usize| (0..n).map(move |k| corners[(start + k) % n]);
    let best = (1..n).fold(0, |best, i| {
        if read_from(i).cmp(read_from(best)) == std::cmp::Ordering::Greater {
            i
        } else {
            best
        }
    });
    (0..n)
        .filter(|&i| read_from(i).eq(read_from(best)))
        .collect()
}

/// The first of [`canonical_starts`] in list order: the corner a polygon's frame starts at.
/// Where the polygon has a rotational symmetry, the list decides among equivalent corners, so
/// that a moved scene keeps its frames (see [`crate::PlaneFrame`]).
pub(crate) fn canonical_start(points: &[DVec3]) -> usize {
    canonical_starts(points).first().copied().unwrap_or(0)
}

/// Newell's normal: its direction is the right-hand-rule normal and its length twice the area.
/// It is summed from one of [`canonical_starts`], the one with the least coordinates, so that
/// its rounding does not depend on where the polygon's list starts.
pub fn newell_normal(points: &[DVec3]) -> DVec3 {
    if points.is_empty() {
        return DVec3::ZERO;
    }
    let n = points.len();
    let least = |i: &usize, j: &usize| {
        let (p, q) = (points[*i], points[*j]);
        (p.x.total_cmp(&q.x))
            .then(p.y.total_cmp(&q.y))
            .then(p.z.total_cmp(&q.z))
    };
    let start = canonical_starts(points)
        .into_iter()
        .min_by(least)
        .unwrap_or(0);
    let at = |i: usize| points[(start + i) % n];
    // Relative to the start vertex, so that far-away polygons keep their digits.
    let anchor = at(0);
    let mut normal = DVec3::ZERO;
    for i in 1..n.saturating_sub(1) {
        normal += (at(i) - anchor).cross(at(i + 1) - anchor);
    }
    normal
}

/// Largest distance between two vertices, of a polygon in 3D or in its plane.
pub fn diameter<V: Vector>(points: &[V]) -> f64 {
    let mut d2: f64 = 0.0;
    for (i, &a) in points.iter().enumerate() {
        for &b in &points[i + 1..] {
            let d = a - b;
            d2 = d2.max(d.dot(d));
        }
    }
    d2.sqrt()
}

/// The mean of the vertices (not the area centroid); the origin for no vertices.
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
pub(crate) fn segments_touch(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
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
pub(crate) fn first_self_intersection(points: &[DVec2]) -> Option<(usize, usize)> {
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

/// Even-odd point-in-polygon test whose crossing decisions are exact.
pub fn inside_polygon(p: DVec2, polygon: &[DVec2]) -> bool {
    let n = polygon.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            // The edge crosses the horizontal through p; is the crossing right of p?
            let o = orient(a, b, p);
            if (b.y > a.y && o > 0.0) || (b.y < a.y && o < 0.0) {
                inside = !inside;
            }
        }
    }
    inside
}

/// The parameters in `[0, 1]` along `a -> b` of the pieces of that segment inside the polygon.
pub fn clip_segment(a: DVec2, b: DVec2, polygon: &[DVec2]) -> Vec<[f64; 2]> {
    let d = b - a;
    let mut cuts = vec![0.0, 1.0];
    let n = polygon.len();
    for i in 0..n {
        let (c, e) = (polygon[i], polygon[(i + 1) % n]);
        let f = e - c;
        let den = d.perp_dot(f);
        if den == 0.0 {
            continue;
        }
        let t = (c - a).perp_dot(f) / den;
        let u = (c - a).perp_dot(d) / den;
        if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
            cuts.push(t);
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    cuts.windows(2)
        .filter(|w| w[1] > w[0] && inside_polygon(a + d * (0.5 * (w[0] + w[1])), polygon))
        .map(|w| [w[0], w[1]])
        .collect()
}

/// The point of a polygon (inside or on its outline) nearest to `p`.
pub fn closest_point_in_polygon(polygon: &[DVec2], p: DVec2) -> DVec2 {
    if polygon.len() < 3 || inside_polygon(p, polygon) {
        return p;
    }
    let n = polygon.len();
    (0..n)
        .map(|i| closest_point_on_segment(p, polygon[i], polygon[(i + 1) % n]))
        .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
        .unwrap_or(p)
}

/// The vectors [`closest_point_on_segment`] and [`diameter`] work in: [`DVec2`] and [`DVec3`].
pub trait Vector: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<f64, Output = Self> {
    /// The dot product.
    fn dot(self, other: Self) -> f64;
}

impl Vector for DVec2 {
    fn dot(self, other: Self) -> f64 {
        DVec2::dot(self, other)
    }
}

impl Vector for DVec3 {
    fn dot(self, other: Self) -> f64 {
        DVec3::dot(self, other)
    }
}

/// The point of the segment `a-b` closest to `p`: the projection of `p` onto the segment's
/// line, clamped to its ends; `a` when the segment has no length.
pub fn closest_point_on_segment<V: Vector>(p: V, a: V, b: V) -> V {
    let d = b - a;
    let length_squared = d.dot(d);
    let t = if length_squared > 0.0 {
        ((p - a).dot(d) / length_squared).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + d * t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    fn v3(x: f64, y: f64) -> DVec3 {
        DVec3::new(x, y, 0.0)
    }

    fn rotated(points: &[DVec3], k: usize) -> Vec<DVec3> {
        (0..points.len())
            .map(|i| points[(i + k) % points.len()])
            .collect()
    }

    #[test]
    fn the_start_moves_with_the_list() {
        let polygons = [
            // A right triangle: its hypotenuse is the longest edge.
            vec![v3(0.0, 0.0), v3(3.0, 0.0), v3(3.0, 2.0)],
            // An isosceles triangle: of its two longest sides, the one followed by the base.
            vec![v3(0.0, 0.0), v3(4.0, -1.0), v3(4.0, 1.0)],
            // A non-convex hexagon: its longest edge closes it.
            vec![
                v3(0.0, 0.0),
                v3(2.0, 0.0),
                v3(2.0, 1.0),
                v3(1.0, 1.0),
                v3(1.0, 3.0),
                v3(-1.0, 3.0),
            ],
        ];
        let expected = [2, 0, 5];
        for (polygon, start) in polygons.iter().zip(expected) {
            assert_eq!(canonical_start(polygon), start, "{polygon:?}");
            for k in 1..polygon.len() {
                let turned = rotated(polygon, k);
                let moved = (start + polygon.len() - k) % polygon.len();
                assert_eq!(canonical_start(&turned), moved, "{polygon:?} from {k}");
                assert_eq!(newell_normal(&turned), newell_normal(polygon));
            }
        }
    }

    /// A square looks the same from each corner: its list's first corner is taken, and stays
    /// taken when the rounding of a turn makes its sides differ in the last bits.
    #[test]
    fn symmetric_polygons_start_at_their_first_corner_however_turned() {
        let square = [v3(0.0, 0.0), v3(1.0, 0.0), v3(1.0, 1.0), v3(0.0, 1.0)];
        let rectangle = [v3(0.0, 0.0), v3(0.3, 0.0), v3(0.3, 1.7), v3(0.0, 1.7)];
        let turn = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.7, -0.4, 2.1);
        for scale in [1e-6, 1.0, 1e6] {
            let map = |p: &DVec3| turn * (*p * scale) + DVec3::new(1.3, -2.9, 0.6) * scale;
            let moved: Vec<DVec3> = square.iter().map(map).collect();
            assert_eq!(canonical_start(&moved), 0);
            let moved: Vec<DVec3> = rectangle.iter().map(map).collect();
            assert_eq!(canonical_start(&moved), 1);
        }
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
