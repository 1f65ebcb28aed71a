//! Planar helpers shared by the meshers: point in polygon and segment clipping, both deciding
//! inside from outside with exact orientation tests.

use glam::DVec2;
use penumbra_scenes::polygon::orient;

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
        .map(|i| {
            let (a, b) = (polygon[i], polygon[(i + 1) % n]);
            let d = b - a;
            let t = if d == DVec2::ZERO {
                0.0
            } else {
                ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
            };
            a + d * t
        })
        .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
        .unwrap_or(p)
}
