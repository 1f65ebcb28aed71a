//! Convex clipping: polygons against half-spaces (3D) and half-planes (2D), and the difference of
//! two convex polygons as convex pieces.

use glam::{DVec2, DVec3};
use penumbra_scenes::polygon::{diameter, orient, signed_area_2d};

/// The part of a polygon where `height(p) >= 0` (Sutherland–Hodgman). Convex in, convex out.
pub(crate) fn clip_polygon_3d(polygon: &[DVec3], height: impl Fn(DVec3) -> f64) -> Vec<DVec3> {
    let n = polygon.len();
    let mut out = Vec::with_capacity(n + 2);
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        let (ha, hb) = (height(a), height(b));
        if ha >= 0.0 {
            out.push(a);
        }
        if (ha > 0.0 && hb < 0.0) || (ha < 0.0 && hb > 0.0) {
            out.push(a + (b - a) * (ha / (ha - hb)));
        }
    }
    out
}

/// The part of a convex polygon left of (or on) the directed line `a -> b`. The side of each
/// vertex is decided exactly; only the new crossing points are rounded.
pub(crate) fn clip_left_of(polygon: &[DVec2], a: DVec2, b: DVec2) -> Vec<DVec2> {
    let n = polygon.len();
    let sides: Vec<f64> = polygon.iter().map(|&p| orient(a, b, p)).collect();
    if sides.iter().all(|&s| s >= 0.0) {
        return polygon.to_vec();
    }
    if sides.iter().all(|&s| s <= 0.0) {
        return Vec::new();
    }
    let d = b - a;
    let h = |p: DVec2| d.perp_dot(p - a);
    let mut out = Vec::with_capacity(n + 2);
    for i in 0..n {
        let j = (i + 1) % n;
        let (p, q) = (polygon[i], polygon[j]);
        if sides[i] >= 0.0 {
            out.push(p);
        }
        if (sides[i] > 0.0 && sides[j] < 0.0) || (sides[i] < 0.0 && sides[j] > 0.0) {
            let (hp, hq) = (h(p), h(q));
            let t = if hp == hq { 0.5 } else { hp / (hp - hq) };
            out.push(p + (q - p) * t.clamp(0.0, 1.0));
        }
    }
    out
}

/// The lowest and highest corner of a polygon's bounding box.
pub(crate) fn bounds_2d(polygon: &[DVec2]) -> (DVec2, DVec2) {
    polygon
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        })
}

/// Removes vertices within `tol` of the vertex before them (clipping makes such near-duplicates;
/// the line through two of them has no reliable direction).
pub(crate) fn merge_close_vertices(polygon: &mut Vec<DVec2>, tol: f64) {
    let mut out: Vec<DVec2> = Vec::with_capacity(polygon.len());
    for &p in polygon.iter() {
        if out.last().is_none_or(|&q| q.distance(p) > tol) {
            out.push(p);
        }
    }
    while out.len() > 1 && out[0].distance(out[out.len() - 1]) <= tol {
        out.pop();
    }
    *polygon = out;
}

/// Whether a convex polygon is wider than `min_width` (area over diameter estimates the width).
pub(crate) fn wider_than(polygon: &[DVec2], min_width: f64) -> bool {
    polygon.len() >= 3 && signed_area_2d(polygon) > min_width * diameter(polygon)
}

/// `piece - hole` for convex counter-clockwise polygons, as convex pieces. Pieces no wider than
/// `min_width` (slivers left by rounding) are dropped. The hole must not have repeated vertices
/// ([`merge_close_vertices`]).
pub(crate) fn subtract_convex(
    piece: &[DVec2],
    hole: &[DVec2],
    min_width: f64,
    out: &mut Vec<Vec<DVec2>>,
) {
    let (plo, phi) = bounds_2d(piece);
    let (hlo, hhi) = bounds_2d(hole);
    if plo.cmpgt(hhi).any() || hlo.cmpgt(phi).any() {
        out.push(piece.to_vec());
        return;
    }
    let m = hole.len();
    let mut rest = piece.to_vec();
    for i in 0..m {
        let (a, b) = (hole[i], hole[(i + 1) % m]);
        if a == b {
            continue; // no line to cut along
        }
        // Right of a -> b is outside the hole: that part stays visible.
        let outside = clip_left_of(&rest, b, a);
        if wider_than(&outside, min_width) {
            out.push(outside);
        }
        rest = clip_left_of(&rest, a, b);
        if rest.len() < 3 {
            return;
        }
    }
}

/// The convex hull of `points`, counter-clockwise, without collinear corners (Andrew's monotone
/// chain, turns decided exactly).
pub(crate) fn convex_hull_2d(mut points: Vec<DVec2>) -> Vec<DVec2> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let backwards: Vec<DVec2> = points.iter().rev().copied().collect();
    let mut hull: Vec<DVec2> = Vec::with_capacity(points.len() + 1);
    for chain in [&points, &backwards] {
        let base = hull.len();
        for &p in chain {
            while hull.len() >= base + 2
                && orient(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        // The chain's last point starts the other chain.
        hull.pop();
    }
    hull
}

/// Whether `p` lies inside or on a convex counter-clockwise polygon.
pub(crate) fn inside_convex(p: DVec2, polygon: &[DVec2]) -> bool {
    let n = polygon.len();
    (0..n).all(|i| orient(polygon[i], polygon[(i + 1) % n], p) >= 0.0)
}

/// A half-plane `{c : normal . c + offset >= 0}`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct HalfPlane {
    pub normal: DVec2,
    pub offset: f64,
}

impl HalfPlane {
    fn value(&self, p: DVec2) -> f64 {
        self.normal.dot(p) + self.offset
    }

    fn flipped(&self) -> HalfPlane {
        HalfPlane {
            normal: -self.normal,
            offset: -self.offset,
        }
    }
}

/// The part of a convex polygon inside a half-plane.
pub(crate) fn clip_half_plane(polygon: &[DVec2], h: &HalfPlane) -> Vec<DVec2> {
    let n = polygon.len();
    let values: Vec<f64> = polygon.iter().map(|&p| h.value(p)).collect();
    if values.iter().all(|&v| v >= 0.0) {
        return polygon.to_vec();
    }
    if values.iter().all(|&v| v <= 0.0) {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(n + 2);
    for i in 0..n {
        let j = (i + 1) % n;
        if values[i] >= 0.0 {
            out.push(polygon[i]);
        }
        if (values[i] > 0.0 && values[j] < 0.0) || (values[i] < 0.0 && values[j] > 0.0) {
            out.push(polygon[i].lerp(polygon[j], values[i] / (values[i] - values[j])));
        }
    }
    out
}

/// The part of a closed contour inside the box `[lo, hi]` (Sutherland–Hodgman, which keeps the
/// contour's winding inside), or `None` when none is. A cut corner takes the side's coordinate
/// exactly, so every corner on a side lies on one line whatever the rounding.
pub(crate) fn clip_to_box(contour: Vec<DVec2>, lo: DVec2, hi: DVec2) -> Option<Vec<DVec2>> {
    let (c_lo, c_hi) = bounds_2d(&contour);
    if c_lo.cmpgt(hi).any() || lo.cmpgt(c_hi).any() {
        return None;
    }
    let mut out = contour;
    // Each side: the axis, its coordinate, and whether the inside lies above it.
    for (axis, at, above) in [
        (0, lo.x, true),
        (0, hi.x, false),
        (1, lo.y, true),
        (1, hi.y, false),
    ] {
        let inside = |p: DVec2| if above { p[axis] >= at } else { p[axis] <= at };
        if out.iter().all(|&p| inside(p)) {
            continue;
        }
        let n = out.len();
        let mut cut = Vec::with_capacity(n + 4);
        for i in 0..n {
            let (p, q) = (out[i], out[(i + 1) % n]);
            if inside(p) {
                cut.push(p);
            }
            if inside(p) != inside(q) {
                let t = (at - p[axis]) / (q[axis] - p[axis]);
                let mut x = p.lerp(q, t);
                x[axis] = at;
                cut.push(x);
            }
        }
        if cut.len() < 3 {
            return None;
        }
        out = cut;
    }
    Some(out)
}

/// `piece` minus the convex region where every half-plane holds, as convex pieces no narrower
/// than `min_width`.
pub(crate) fn subtract_half_planes(
    piece: &[DVec2],
    region: &[HalfPlane],
    min_width: f64,
    out: &mut Vec<Vec<DVec2>>,
) {
    let mut rest = piece.to_vec();
    for h in region {
        let outside = clip_half_plane(&rest, &h.flipped());
        if wider_than(&outside, min_width) {
            out.push(outside);
        }
        rest = clip_half_plane(&rest, h);
        if rest.len() < 3 {
            return;
        }
    }
}

/// An axis-aligned square, counter-clockwise, for tests.
#[cfg(test)]
pub(crate) fn sq(x0: f64, y0: f64, s: f64) -> Vec<DVec2> {
    vec![
        DVec2::new(x0, y0),
        DVec2::new(x0 + s, y0),
        DVec2::new(x0 + s, y0 + s),
        DVec2::new(x0, y0 + s),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn difference_of_squares_has_the_right_area() {
        let mut out = Vec::new();
        subtract_convex(&sq(0.0, 0.0, 10.0), &sq(5.0, 5.0, 10.0), 0.0, &mut out);
        let area: f64 = out.iter().map(|p| signed_area_2d(p)).sum();
        assert!((area - 75.0).abs() < 1e-12);
        assert!(out.iter().all(|p| signed_area_2d(p) > 0.0));

        let mut out = Vec::new();
        subtract_convex(&sq(0.0, 0.0, 10.0), &sq(2.0, 2.0, 1.0), 0.0, &mut out);
        let area: f64 = out.iter().map(|p| signed_area_2d(p)).sum();
        assert!((area - 99.0).abs() < 1e-12);

        let mut out = Vec::new();
        subtract_convex(&sq(0.0, 0.0, 1.0), &sq(-1.0, -1.0, 5.0), 0.0, &mut out);
        assert!(out.is_empty());

        // A repeated vertex in the hole must not duplicate the piece.
        let mut hole = sq(2.0, 2.0, 1.0);
        hole.insert(1, hole[1]);
        let mut out = Vec::new();
        subtract_convex(&sq(0.0, 0.0, 10.0), &hole, 0.0, &mut out);
        let area: f64 = out.iter().map(|p| signed_area_2d(p)).sum();
        assert!((area - 99.0).abs() < 1e-12);

        // Touching along an edge: nothing removed, nothing of zero area added.
        let mut out = Vec::new();
        subtract_convex(&sq(0.0, 0.0, 1.0), &sq(1.0, 0.0, 1.0), 0.0, &mut out);
        let area: f64 = out.iter().map(|p| signed_area_2d(p)).sum();
        assert!((area - 1.0).abs() < 1e-15);
    }

    #[test]
    fn half_space_clipping() {
        let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let half = clip_polygon_3d(&tri, |p| 0.5 - p.x);
        assert_eq!(half.len(), 4);
        let area = 0.5 * penumbra_scenes::polygon::newell_normal(&half).length();
        assert!((area - 0.375).abs() < 1e-15);
    }
}
