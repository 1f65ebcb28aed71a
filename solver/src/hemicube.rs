//! The hemicube (Cohen & Greenberg 1985): the form factors from a point to every patch at once,
//! by z-buffering the scene onto the five faces of a half cube standing on the point's tangent
//! plane and summing, under each patch, the delta form factors of the pixels that see it.
//!
//! A unit hemicube has a top face z = 1 over [-1, 1]² and four half faces of height 1. A pixel
//! of area ΔA at (a, b) on the top face carries ΔF = ΔA / (π (a² + b² + 1)²); on a side face,
//! with b the height above the tangent plane, ΔF = b ΔA / (π (a² + b² + 1)²). The deltas sum to
//! 1 as the pixels shrink. Occlusion is exact to the pixel; what the pixel grid cannot resolve is
//! the cost: a patch smaller than a pixel is seen whole or not at all (aliasing).

use std::f64::consts::PI;

use glam::DVec3;

use crate::error::SolveError;
use crate::option_id::OptionId;

/// The id of a triangle that hides what is behind it but receives no form factor (a patch seen
/// from behind).
pub const OCCLUDER: u32 = u32::MAX;

/// Largest accepted resolution: 3 N² pixels of depth and id per thread.
pub const MAX_RESOLUTION: usize = 2048;

/// The five faces as (right, up, forward) picked from the local frame (t1, t2, n): `(axis,
/// sign)` per camera axis. The top face looks along n; the side faces look along ±t1, ±t2 with
/// n up.
const FACES: [[(usize, f64); 3]; 5] = [
    [(0, 1.0), (1, 1.0), (2, 1.0)],
    [(1, 1.0), (2, 1.0), (0, 1.0)],
    [(1, -1.0), (2, 1.0), (0, -1.0)],
    [(0, -1.0), (2, 1.0), (1, 1.0)],
    [(0, 1.0), (2, 1.0), (1, -1.0)],
];

/// A hemicube's buffers and delta form factors, reused from point to point.
#[derive(Clone, Debug)]
pub struct Hemicube {
    resolution: usize,
    /// Pixel size on the unit hemicube.
    pixel: f64,
    /// Delta form factors of the top face (N × N) then of one side face (N × N/2), row by row.
    delta_top: Vec<f64>,
    delta_side: Vec<f64>,
    /// Per pixel, one over the depth of what it sees (0: nothing).
    nearness: Vec<f64>,
    id: Vec<u32>,
}

impl Hemicube {
    /// A hemicube with `resolution` pixels across its top face (even: the side faces are half
    /// as tall).
    pub fn new(resolution: usize) -> Result<Hemicube, SolveError> {
        if resolution < 2 || !resolution.is_multiple_of(2) || resolution > MAX_RESOLUTION {
            return Err(SolveError::InvalidOption {
                option: OptionId::HemicubeResolution,
                reason: "must be an even number from 2 to 2048",
            });
        }
        let n = resolution;
        let pixel = 2.0 / n as f64;
        let centre = |i: usize| -1.0 + (i as f64 + 0.5) * pixel;
        let kernel = |a: f64, b: f64| pixel * pixel / (PI * (a * a + b * b + 1.0).powi(2));
        let delta_top = (0..n * n)
            .map(|k| kernel(centre(k % n), centre(k / n)))
            .collect();
        let delta_side = (0..n * n / 2)
            .map(|k| {
                let b = (k / n) as f64 * pixel + 0.5 * pixel;
                b * kernel(centre(k % n), b)
            })
            .collect();
        Ok(Hemicube {
            resolution,
            pixel,
            delta_top,
            delta_side,
            nearness: vec![0.0; 3 * n * n],
            id: vec![OCCLUDER; 3 * n * n],
        })
    }

    /// Pixels across the top face.
    pub fn resolution(&self) -> usize {
        self.resolution
    }

    /// The sum of all delta form factors: 1 less the pixel grid's own quadrature error.
    pub fn delta_sum(&self) -> f64 {
        self.delta_top.iter().sum::<f64>() + 4.0 * self.delta_side.iter().sum::<f64>()
    }

    /// Renders `triangles` (each with the id its form factor goes to, or [`OCCLUDER`]) as seen
    /// from `eye` with unit `normal`. Geometry nearer than `near` along a face's axis is cut
    /// away, so the eye must be further than `near` from everything it should see.
    pub fn render(
        &mut self,
        eye: DVec3,
        normal: DVec3,
        near: f64,
        triangles: impl IntoIterator<Item = ([DVec3; 3], u32)>,
    ) {
        self.nearness.fill(0.0);
        self.id.fill(OCCLUDER);
        let (t1, t2) = normal.any_orthonormal_pair();
        let frame = [t1, t2, normal];
        for (tri, id) in triangles {
            let local = tri.map(|p| {
                let d = p - eye;
                [frame[0].dot(d), frame[1].dot(d), frame[2].dot(d)]
            });
            // Wholly at or below the tangent plane: on no face.
            if local.iter().all(|l| l[2] <= 0.0) {
                continue;
            }
            for (f, axes) in FACES.iter().enumerate() {
                let camera = local.map(|l| {
                    DVec3::new(
                        axes[0].1 * l[axes[0].0],
                        axes[1].1 * l[axes[1].0],
                        axes[2].1 * l[axes[2].0],
                    )
                });
                self.rasterize(f, camera, near, id);
            }
        }
    }

    /// Adds each id's form factor to `out[id]` (ids at or past `out.len()` are ignored).
    pub fn accumulate(&self, out: &mut [f64]) {
        let n = self.resolution;
        for (k, &id) in self.id.iter().enumerate() {
            if id == OCCLUDER {
                continue;
            }
            let delta = if k < n * n {
                self.delta_top[k]
            } else {
                self.delta_side[(k - n * n) % (n * n / 2)]
            };
            if let Some(slot) = out.get_mut(id as usize) {
                *slot += delta;
            }
        }
    }

    /// Z-buffers one triangle, in face `f`'s camera coordinates (x right, y up, z forward), into
    /// that face.
    fn rasterize(&mut self, f: usize, v: [DVec3; 3], near: f64, id: u32) {
        let n = self.resolution;
        let top = f == 0;
        // Outside one of the frustum's planes (|x| <= z, |y| <= z on the top face, 0 <= y <= z
        // on a side face): nothing to draw.
        let y_floor = |p: &DVec3| if top { -p.z } else { 0.0 };
        if v.iter().all(|p| p.z < near)
            || v.iter().all(|p| p.x > p.z)
            || v.iter().all(|p| -p.x > p.z)
            || v.iter().all(|p| p.y > p.z)
            || v.iter().all(|p| p.y < y_floor(p))
        {
            return;
        }
        // A pixel's ray (a, b, 1) meets the triangle's plane m·p = offset at depth
        // offset / m·(a, b, 1): its inverse is linear across the face, and larger is nearer.
        let m = (v[1] - v[0]).cross(v[2] - v[0]);
        let offset = m.dot(v[0]);
        if offset == 0.0 {
            return; // the plane holds the eye: seen edge-on
        }
        let inverse = m / offset;
        let (poly, count) = clip_near(&v, near);
        if count < 3 {
            return;
        }
        let projected: [[f64; 2]; 4] = poly.map(|p| [p.x / p.z, p.y / p.z]);
        let projected = &projected[..count];
        let area2: f64 = (0..count)
            .map(|i| {
                let (a, b) = (projected[i], projected[(i + 1) % count]);
                a[0] * b[1] - a[1] * b[0]
            })
            .sum();
        if area2 == 0.0 {
            return;
        }
        // Edge functions e(a, b) = ea·a + eb·b + ec, positive inside.
        let sign = area2.signum();
        let mut edges = [[0.0; 3]; 4];
        for (e, edge) in edges.iter_mut().enumerate().take(count) {
            let (p, q) = (projected[e], projected[(e + 1) % count]);
            let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
            *edge = [-dy * sign, dx * sign, (dy * p[0] - dx * p[1]) * sign];
        }
        let edges = &edges[..count];
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in projected {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        // Pixel centres: x = -1 + (i + ½) px on every face; y likewise on the top face and
        // y = (j + ½) px on a side face.
        let (y0, rows) = if top { (-1.0, n) } else { (0.0, n / 2) };
        let span = |lo: f64, hi: f64, origin: f64, count: usize| {
            let first = ((lo - origin) / self.pixel - 0.5).ceil().max(0.0);
            let last = ((hi - origin) / self.pixel - 0.5)
                .floor()
                .min(count as f64 - 1.0);
            (first as usize, last)
        };
        // A pixel centre on an edge shared by two triangles (seams through the eye's own
        // projection do pass through centres) must not be lost to rounding in both, so spans
        // get a millionth of a pixel of slack; a centre covered twice goes to the nearer.
        let slack = 1e-6 * self.pixel;
        let (i0, i1) = span(lo[0] - slack, hi[0] + slack, -1.0, n);
        let (j0, j1) = span(lo[1] - slack, hi[1] + slack, y0, rows);
        if i1 < i0 as f64 || j1 < j0 as f64 {
            return;
        }
        let j1 = j1 as usize;
        let base = if top {
            0
        } else {
            n * n + (f - 1) * (n * n / 2)
        };
        for j in j0..=j1 {
            let b = y0 + (j as f64 + 0.5) * self.pixel;
            // The row's covered span: each edge bounds a from one side.
            let (mut a_lo, mut a_hi) = (lo[0] - slack, hi[0] + slack);
            for e in edges {
                let c = e[1] * b + e[2];
                if e[0] > 0.0 {
                    a_lo = a_lo.max(-c / e[0] - slack);
                } else if e[0] < 0.0 {
                    a_hi = a_hi.min(-c / e[0] + slack);
                } else if c < -slack * e[1].abs() {
                    a_hi = f64::NEG_INFINITY;
                }
            }
            let (first, last) = span(a_lo, a_hi, -1.0, n);
            if last < first as f64 {
                continue;
            }
            let row = base + j * n;
            for i in first..=last as usize {
                let a = -1.0 + (i as f64 + 0.5) * self.pixel;
                let nearness = inverse.x * a + inverse.y * b + inverse.z;
                let k = row + i;
                if nearness > self.nearness[k] {
                    self.nearness[k] = nearness;
                    self.id[k] = id;
                }
            }
        }
    }
}

/// The part of a triangle with z >= `near` (Sutherland–Hodgman against one plane): up to four
/// corners, and how many there are.
fn clip_near(v: &[DVec3; 3], near: f64) -> ([DVec3; 4], usize) {
    let mut out = [DVec3::Z; 4];
    let mut count = 0;
    for i in 0..3 {
        let (p, q) = (v[i], v[(i + 1) % 3]);
        let (p_in, q_in) = (p.z >= near, q.z >= near);
        if p_in {
            out[count] = p;
            count += 1;
        }
        if p_in != q_in {
            let t = (near - p.z) / (q.z - p.z);
            out[count] = p + (q - p) * t;
            count += 1;
        }
    }
    (out, count)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(z: f64, lo: [f64; 2], hi: [f64; 2]) -> [[DVec3; 3]; 2] {
        let p = |x: f64, y: f64| DVec3::new(x, y, z);
        [
            [p(lo[0], lo[1]), p(hi[0], lo[1]), p(hi[0], hi[1])],
            [p(lo[0], lo[1]), p(hi[0], hi[1]), p(lo[0], hi[1])],
        ]
    }

    fn form_factor(cube: &mut Hemicube, tris: &[[DVec3; 3]]) -> f64 {
        cube.render(DVec3::ZERO, DVec3::Z, 1e-9, tris.iter().map(|&t| (t, 0)));
        let mut out = [0.0];
        cube.accumulate(&mut out);
        out[0]
    }

    #[test]
    fn deltas_sum_to_one_as_pixels_shrink() {
        let errors: Vec<f64> = [16, 64, 256]
            .map(|n| (Hemicube::new(n).expect("valid").delta_sum() - 1.0).abs())
            .to_vec();
        // Midpoint rule: second order in the pixel size.
        assert!(errors[0] < 1e-2 && errors[1] < errors[0] / 10.0 && errors[2] < errors[1] / 10.0);
    }

    #[test]
    fn a_plane_covering_the_hemisphere_gets_the_delta_sum() {
        // A huge square just above the eye covers the whole top face and nearly all the sides.
        let mut cube = Hemicube::new(64).expect("valid");
        let f = form_factor(&mut cube, &square(1e-3, [-1e4, -1e4], [1e4, 1e4]));
        assert!((f - cube.delta_sum()).abs() < 1e-6, "{f}");
    }

    #[test]
    fn parallel_unit_square_corner_on_the_normal() {
        // `docs/closed-forms.md`, "Rectangles by superposition": a = b = c = 1.
        let exact = 0.138531605994893;
        let errors: Vec<f64> = [32, 128, 512]
            .map(|n| {
                let mut cube = Hemicube::new(n).expect("valid");
                (form_factor(&mut cube, &square(1.0, [0.0, 0.0], [1.0, 1.0])) - exact).abs()
            })
            .to_vec();
        assert!(errors[2] < 2e-4, "{errors:?}");
        assert!(errors[2] < errors[0], "{errors:?}");
    }

    #[test]
    fn the_nearer_patch_hides_the_farther() {
        let mut cube = Hemicube::new(64).expect("valid");
        let near = square(1.0, [-10.0, -10.0], [10.0, 10.0]);
        let far = square(2.0, [-10.0, -10.0], [10.0, 10.0]);
        // Drawn far first then near, and the other way round: the near one wins both times.
        for order in [[0u32, 1], [1, 0]] {
            let tris: Vec<([DVec3; 3], u32)> = order
                .iter()
                .flat_map(|&o| {
                    let s = if o == 0 { far } else { near };
                    s.into_iter().map(move |t| (t, o))
                })
                .collect();
            cube.render(DVec3::ZERO, DVec3::Z, 1e-9, tris);
            let mut out = [0.0; 2];
            cube.accumulate(&mut out);
            assert_eq!(out[0], 0.0);
            assert!(out[1] > 0.9, "{out:?}");
        }
    }

    #[test]
    fn bad_resolutions_are_refused() {
        for n in [0, 1, 3, 4096] {
            assert!(Hemicube::new(n).is_err(), "{n}");
        }
    }
}
