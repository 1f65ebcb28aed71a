//! Which pixels a triangle covers: edge functions, the top-left fill rule, and widened outlines.
//!
//! A pixel is covered when its centre lies inside the triangle. Triangles of one surface share
//! vertices, and each pixel centre on a shared edge must go to exactly one of the two triangles:
//! the edge function of an edge is evaluated from its endpoints in a fixed (lexicographic) order,
//! so the two triangles see exactly opposite values, and a centre exactly on the edge goes to the
//! triangle for which the edge is a "top-left" edge (Pineda 1988; the rule of Direct3D and
//! OpenGL), which is true for exactly one of the two directions of an edge.
//!
//! Different surfaces meet along seams without sharing vertices (each surface is meshed on its
//! own), so their outlines agree only up to rounding. Outline edges are therefore widened by
//! [`OUTLINE_OVERLAP_PX`]; where two surfaces then overlap, the depth test decides.

use std::ops::Range;

use glam::DVec2;

/// How far outline edges (a surface's boundary, or the near-plane cut) reach past the exact
/// edge, in pixels. It must exceed the rounding by which seams between separately meshed
/// surfaces disagree (relative 1e-12 of a surface's size) and stays far below a visible size.
pub(crate) const OUTLINE_OVERLAP_PX: f64 = 1e-3;

/// A triangle in pixel coordinates (x right, y down). Edge `i` runs from corner `i` to `i + 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ScreenTriangle {
    pub(crate) corners: [DVec2; 3],
    pub(crate) outline: [bool; 3],
}

/// Edge function of `a -> b` at `p`: twice the signed area of `(a, b, p)`. Swapping `a` and `b`
/// negates the value exactly, because it is always computed from the lexicographically smaller
/// endpoint.
fn edge_function(a: DVec2, b: DVec2, p: DVec2) -> f64 {
    let raw = |a: DVec2, b: DVec2| (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    if a.x < b.x || (a.x == b.x && a.y <= b.y) {
        raw(a, b)
    } else {
        -raw(b, a)
    }
}

/// The tie-break for centres exactly on an edge: true for exactly one of `d` and `-d` (`d != 0`).
fn is_top_left(d: DVec2) -> bool {
    d.y > 0.0 || (d.y == 0.0 && d.x < 0.0)
}

/// Calls `visit(x, y, weights)` for every pixel of the rows `rows` (and of an image `width`
/// pixels wide) whose centre the triangle covers. `weights[k]` is proportional to the
/// barycentric coordinate of corner `k` (the three share one positive factor), so values
/// interpolate as `sum(weights[k] * value[k]) / sum(weights)`.
pub(crate) fn rasterize(
    triangle: &ScreenTriangle,
    rows: Range<u32>,
    width: u32,
    mut visit: impl FnMut(u32, u32, [f64; 3]),
) {
    let p = triangle.corners;
    if !p.iter().all(|c| c.is_finite()) {
        return;
    }
    let area = edge_function(p[0], p[1], p[2]);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    // Orient every edge as if the triangle were counter-clockwise in this sign convention.
    let sign = area.signum();
    let mut slack = [0.0; 3];
    let mut top_left = [false; 3];
    for i in 0..3 {
        let d = p[(i + 1) % 3] - p[i];
        top_left[i] = is_top_left(d * sign);
        if triangle.outline[i] {
            slack[i] = OUTLINE_OVERLAP_PX * d.length();
        }
    }
    let inside = |i: usize, value: f64| {
        if triangle.outline[i] {
            value >= -slack[i]
        } else {
            value > 0.0 || (value == 0.0 && top_left[i])
        }
    };

    let y_min = p[0].y.min(p[1].y).min(p[2].y);
    let y_max = p[0].y.max(p[1].y).max(p[2].y);
    let x_min = p[0].x.min(p[1].x).min(p[2].x);
    let x_max = p[0].x.max(p[1].x).max(p[2].x);
    for y in row_range(triangle, rows.start, rows.end) {
        let yc = f64::from(y) + 0.5;
        let Some((left, right)) = row_span(&p, yc.clamp(y_min, y_max)) else {
            continue;
        };
        // The same margin of one pixel as for rows.
        let first_col = pixel_index(left.max(x_min) - 1.5, 0, width);
        let end_col = pixel_index(right.min(x_max) + 0.5, 0, width);
        for x in first_col..end_col {
            let centre = DVec2::new(f64::from(x) + 0.5, yc);
            let e = [0, 1, 2].map(|i| sign * edge_function(p[i], p[(i + 1) % 3], centre));
            if (0..3).all(|i| inside(i, e[i])) {
                // The weight of a corner is the edge function of the edge opposite it.
                visit(x, y, [e[1], e[2], e[0]]);
            }
        }
    }
}

/// The rows in `[first, end)` that the triangle may cover (empty if its corners are not finite).
pub(crate) fn row_range(triangle: &ScreenTriangle, first: u32, end: u32) -> Range<u32> {
    let ys = triangle.corners.map(|c| c.y);
    if !ys.iter().all(|y| y.is_finite()) {
        return first..first;
    }
    let y_min = ys[0].min(ys[1]).min(ys[2]);
    let y_max = ys[0].max(ys[1]).max(ys[2]);
    // Pixel j has its centre at j + 0.5; one pixel of margin covers rounding and the widening of
    // outlines, and the exact test decides.
    pixel_index(y_min - 1.5, first, end)..pixel_index(y_max + 0.5, first, end)
}

/// The first pixel whose centre lies above `coordinate`, clamped to `[lo, hi]`.
fn pixel_index(coordinate: f64, lo: u32, hi: u32) -> u32 {
    let c = coordinate.ceil().clamp(f64::from(lo), f64::from(hi));
    // In range by the clamp, so the cast is exact.
    c as u32
}

/// Where the horizontal line at `y` (within the triangle's height) crosses the triangle.
fn row_span(p: &[DVec2; 3], y: f64) -> Option<(f64, f64)> {
    let mut span: Option<(f64, f64)> = None;
    let mut include = |x: f64| {
        span = Some(match span {
            None => (x, x),
            Some((lo, hi)) => (lo.min(x), hi.max(x)),
        });
    };
    for i in 0..3 {
        let (a, b) = (p[i], p[(i + 1) % 3]);
        if a.y == b.y {
            if a.y == y {
                include(a.x);
                include(b.x);
            }
        } else if (a.y.min(b.y)..=a.y.max(b.y)).contains(&y) {
            include(a.x + (y - a.y) * ((b.x - a.x) / (b.y - a.y)));
        }
    }
    span
}

#[cfg(test)]
mod tests {
    use super::*;
    use penumbra_scenes::SplitMix64;

    fn coverage(triangles: &[ScreenTriangle], size: u32) -> Vec<u32> {
        let mut count = vec![0; (size * size) as usize];
        for t in triangles {
            rasterize(t, 0..size, size, |x, y, w| {
                assert!(w.iter().sum::<f64>() > 0.0);
                count[(y * size + x) as usize] += 1;
            });
        }
        count
    }

    /// A grid of `n x n` cells from `origin` with cell size `cell`, each cut along a diagonal
    /// whose direction alternates.
    fn grid(origin: DVec2, cell: f64, n: usize, clockwise: bool) -> Vec<ScreenTriangle> {
        let at = |i: usize, j: usize| origin + DVec2::new(i as f64, j as f64) * cell;
        let mut out = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                let halves = if (i + j) % 2 == 0 {
                    [[a, b, c], [a, c, d]]
                } else {
                    [[a, b, d], [b, c, d]]
                };
                for mut corners in halves {
                    if clockwise {
                        corners.swap(1, 2);
                    }
                    out.push(ScreenTriangle {
                        corners,
                        outline: [false; 3],
                    });
                }
            }
        }
        out
    }

    #[test]
    fn shared_edges_through_pixel_centres_cover_each_pixel_once() {
        // Vertices on pixel centres put every tie case on the edges: each centre inside the grid
        // must be covered exactly once, whatever the winding.
        for clockwise in [false, true] {
            let count = coverage(&grid(DVec2::splat(2.5), 3.0, 6, clockwise), 24);
            for y in 0..24u32 {
                for x in 0..24u32 {
                    let c = count[(y * 24 + x) as usize];
                    let strictly_inside = (3..20).contains(&x) && (3..20).contains(&y);
                    let outside = !(2..=20).contains(&x) || !(2..=20).contains(&y);
                    if strictly_inside {
                        assert_eq!(c, 1, "pixel ({x}, {y})");
                    } else if outside {
                        assert_eq!(c, 0, "pixel ({x}, {y})");
                    } else {
                        assert!(c <= 1, "pixel ({x}, {y})");
                    }
                }
            }
        }
    }

    #[test]
    fn random_fans_cover_each_pixel_once() {
        let mut rng = SplitMix64::new(7);
        for _ in 0..20 {
            // A convex polygon around a centre, fanned from an interior point.
            let centre = DVec2::new(16.0 + rng.next_f64(), 16.0 + rng.next_f64());
            let n = 5 + (rng.next_f64() * 8.0) as usize;
            let ring: Vec<DVec2> = (0..n)
                .map(|k| {
                    let angle =
                        (k as f64 + 0.8 * rng.next_f64()) / n as f64 * std::f64::consts::TAU;
                    centre + DVec2::from_angle(angle) * 13.0
                })
                .collect();
            let hub = centre + DVec2::new(rng.next_f64() - 0.5, rng.next_f64() - 0.5) * 4.0;
            let triangles: Vec<ScreenTriangle> = (0..n)
                .map(|k| ScreenTriangle {
                    corners: [hub, ring[k], ring[(k + 1) % n]],
                    outline: [false; 3],
                })
                .collect();
            let count = coverage(&triangles, 32);
            for y in 0..32u32 {
                for x in 0..32u32 {
                    let c = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                    let inside = (0..n).all(|k| {
                        let (a, b) = (ring[k], ring[(k + 1) % n]);
                        (b - a).perp_dot(c - a) > 1e-9
                    });
                    let got = count[(y * 32 + x) as usize];
                    if inside {
                        assert_eq!(got, 1, "pixel ({x}, {y})");
                    } else {
                        assert!(got <= 1, "pixel ({x}, {y})");
                    }
                }
            }
        }
    }

    #[test]
    fn outline_edges_reach_a_little_further() {
        // The centre (4.5, 4.5) lies 1e-4 px outside the edge x = 4.5001.
        let corners = [
            DVec2::new(4.5001, 0.0),
            DVec2::new(4.5001, 10.0),
            DVec2::new(9.0, 5.0),
        ];
        let covered = |outline| {
            let mut hit = false;
            let t = ScreenTriangle { corners, outline };
            rasterize(&t, 0..10, 10, |x, y, _| hit |= (x, y) == (4, 4));
            hit
        };
        assert!(!covered([false; 3]));
        assert!(covered([true; 3]));
    }

    #[test]
    fn rows_outside_the_band_are_left_alone() {
        let t = ScreenTriangle {
            corners: [DVec2::ZERO, DVec2::new(10.0, 0.0), DVec2::new(0.0, 10.0)],
            outline: [true; 3],
        };
        rasterize(&t, 3..5, 10, |_, y, _| assert!((3..5).contains(&y)));
    }
}
