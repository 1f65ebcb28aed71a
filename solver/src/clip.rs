//! Convex clipping: polygons against half-spaces (3D) and half-planes (2D), and the difference of
//! two convex polygons as convex pieces.

use glam::{DVec2, DVec3};
use penumbra_scenes::polygon::orient;

/// The part of a polygon where `height(p) >= 0` (Sutherland–Hodgman). Convex in, convex out.
pub fn clip_polygon_3d(polygon: &[DVec3], height: impl Fn(DVec3) -> f64) -> Vec<DVec3> {
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
pub fn clip_left_of(polygon: &[DVec2], a: DVec2, b: DVec2) -> Vec<DVec2> {
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

pub fn area_2d(polygon: &[DVec2]) -> f64 {
    penumbra_scenes::polygon::signed_area_2d(polygon)
}

fn bounds_2d(polygon: &[DVec2]) -> (DVec2, DVec2) {
    polygon
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        })
}

/// `piece - hole` for convex counter-clockwise polygons, as convex pieces. Pieces with an area
/// at most `min_area` are dropped.
pub fn subtract_convex(piece: &[DVec2], hole: &[DVec2], min_area: f64, out: &mut Vec<Vec<DVec2>>) {
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
        // Right of a -> b is outside the hole: that part stays visible.
        let outside = clip_left_of(&rest, b, a);
        if outside.len() >= 3 && area_2d(&outside) > min_area {
            out.push(outside);
        }
        rest = clip_left_of(&rest, a, b);
        if rest.len() < 3 {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sq(x0: f64, y0: f64, s: f64) -> Vec<DVec2> {
        vec![
            DVec2::new(x0, y0),
            DVec2::new(x0 + s, y0),
            DVec2::new(x0 + s, y0 + s),
            DVec2::new(x0, y0 + s),
        ]
    }

    #[test]
    fn difference_of_squares_has_the_right_area() {
        let mut out = Vec::new();
        subtract_convex(&sq(0.0, 0.0, 10.0), &sq(5.0, 5.0, 10.0), 0.0, &mut out);
        let area: f64 = out.iter().map(|p| area_2d(p)).sum();
        assert!((area - 75.0).abs() < 1e-12);
        assert!(out.iter().all(|p| area_2d(p) > 0.0));

        let mut out = Vec::new();
        subtract_convex(&sq(0.0, 0.0, 10.0), &sq(2.0, 2.0, 1.0), 0.0, &mut out);
        let area: f64 = out.iter().map(|p| area_2d(p)).sum();
        assert!((area - 99.0).abs() < 1e-12);

        let mut out = Vec::new();
        subtract_convex(&sq(0.0, 0.0, 1.0), &sq(-1.0, -1.0, 5.0), 0.0, &mut out);
        assert!(out.is_empty());

        // Touching along an edge: nothing removed, nothing of zero area added.
        let mut out = Vec::new();
        subtract_convex(&sq(0.0, 0.0, 1.0), &sq(1.0, 0.0, 1.0), 0.0, &mut out);
        let area: f64 = out.iter().map(|p| area_2d(p)).sum();
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
