//! The area a disc covers of a polygon, exactly: the sum, over the polygon's edges, of the signed
//! area the disc covers of the triangle the edge makes with the disc's centre.

use glam::DVec2;

/// The area of the disc of `radius` about `centre` inside `polygon` (a simple polygon, either
/// orientation).
pub(super) fn area_in_polygon(centre: DVec2, radius: f64, polygon: &[DVec2]) -> f64 {
    let n = polygon.len();
    let signed: f64 = (0..n)
        .map(|i| in_triangle(polygon[i] - centre, polygon[(i + 1) % n] - centre, radius))
        .sum();
    signed.abs()
}

/// The signed area the disc of `radius` about the origin covers of the triangle (0, a, b):
/// the edge ab is cut where it crosses the circle; a piece inside adds its triangle, a piece
/// outside the sector its ends span.
fn in_triangle(a: DVec2, b: DVec2, radius: f64) -> f64 {
    let r2 = radius * radius;
    let d = b - a;
    let (qa, qb, qc) = (d.dot(d), a.dot(d), a.dot(a) - r2);
    // The edge's parameters 0, where it crosses the circle (at most twice), and 1.
    let (mut cuts, mut n) = ([0.0; 4], 1);
    let discriminant = qb * qb - qa * qc;
    if qa > 0.0 && discriminant > 0.0 {
        let root = discriminant.sqrt();
        for t in [(-qb - root) / qa, (-qb + root) / qa] {
            if t > 0.0 && t < 1.0 {
                cuts[n] = t;
                n += 1;
            }
        }
    }
    cuts[n] = 1.0;
    cuts[..=n]
        .windows(2)
        .map(|w| {
            let (p, q) = (a + d * w[0], a + d * w[1]);
            let middle = a + d * (0.5 * (w[0] + w[1]));
            if middle.length_squared() <= r2 {
                0.5 * p.perp_dot(q)
            } else {
                0.5 * r2 * p.perp_dot(q).atan2(p.dot(q))
            }
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn square(side: f64) -> Vec<DVec2> {
        vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(side, 0.0),
            DVec2::new(side, side),
            DVec2::new(0.0, side),
        ]
    }

    #[test]
    fn a_disc_inside_covers_its_own_area() {
        let area = area_in_polygon(DVec2::new(2.0, 2.0), 1.0, &square(4.0));
        assert!((area - PI).abs() < 1e-12, "{area}");
    }

    #[test]
    fn a_disc_at_an_edge_or_a_corner_covers_a_half_or_a_quarter() {
        let half = area_in_polygon(DVec2::new(2.0, 0.0), 1.0, &square(4.0));
        assert!((half - PI / 2.0).abs() < 1e-12, "{half}");
        let quarter = area_in_polygon(DVec2::new(0.0, 0.0), 1.0, &square(4.0));
        assert!((quarter - PI / 4.0).abs() < 1e-12, "{quarter}");
        // Clockwise, the same.
        let mut clockwise = square(4.0);
        clockwise.reverse();
        let again = area_in_polygon(DVec2::new(0.0, 0.0), 1.0, &clockwise);
        assert!((again - quarter).abs() < 1e-12);
    }

    #[test]
    fn a_disc_larger_than_the_polygon_covers_all_of_it() {
        let area = area_in_polygon(DVec2::new(0.5, 0.5), 10.0, &square(1.0));
        assert!((area - 1.0).abs() < 1e-12, "{area}");
    }

    /// Against counting a fine grid of points, for a disc cutting two edges of an L-shaped
    /// (not convex) polygon.
    #[test]
    fn a_notched_polygon_against_a_grid_count() {
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]
        .map(|(x, y)| DVec2::new(x, y))
        .to_vec();
        let (centre, radius) = (DVec2::new(1.1, 1.2), 0.6);
        let exact = area_in_polygon(centre, radius, &l);
        let n = 2000;
        let h = 2.0 / n as f64;
        let mut inside = 0usize;
        for i in 0..n {
            for j in 0..n {
                let p = DVec2::new((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                let in_l = p.x < 1.0 || p.y < 1.0;
                if in_l && (p - centre).length() <= radius {
                    inside += 1;
                }
            }
        }
        let counted = inside as f64 * h * h;
        assert!((exact - counted).abs() < 2e-3, "{exact} against {counted}");
        assert!(
            exact < PI * radius * radius - 0.05,
            "the notch takes a part: {exact}"
        );
    }
}
