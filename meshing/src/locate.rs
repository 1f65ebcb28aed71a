//! Finding triangles of a surface mesh by position: a grid over the mesh coordinates, each cell
//! listing the triangles whose bounding boxes reach it.

use glam::{DVec2, DVec3};
use penumbra_scenes::Rgb;

use crate::SurfaceMesh;

/// Triangles of one mesh bucketed on a grid (in mesh coordinates).
#[derive(Clone, Debug)]
pub struct TriangleLocator {
    lo: DVec2,
    cell: f64,
    side: usize,
    buckets: Vec<Vec<u32>>,
}

impl TriangleLocator {
    /// Buckets the triangles of `mesh`, about one per cell.
    pub fn new(mesh: &SurfaceMesh) -> TriangleLocator {
        let (lo, hi) = mesh
            .local
            .iter()
            .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let lo = if lo.is_finite() { lo } else { DVec2::ZERO };
        let side = ((mesh.triangles.len() as f64).sqrt().ceil() as usize).clamp(1, 512);
        let cell = ((hi - lo).max_element() / side as f64).max(f64::MIN_POSITIVE);
        let mut locator = TriangleLocator {
            lo,
            cell,
            side,
            buckets: vec![Vec::new(); side * side],
        };
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let p = tri.map(|i| mesh.local[i as usize]);
            let (a, b) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
            let ([i0, j0], [i1, j1]) = (locator.index(a), locator.index(b));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    locator.buckets[j * side + i].push(t as u32);
                }
            }
        }
        locator
    }

    fn index(&self, p: DVec2) -> [usize; 2] {
        let at = |x: f64| ((x / self.cell).floor().max(0.0) as usize).min(self.side - 1);
        [at(p.x - self.lo.x), at(p.y - self.lo.y)]
    }

    /// The triangles whose boxes may meet the box `lo..hi` (mesh coordinates), each once, in
    /// ascending order.
    pub fn candidates(&self, lo: DVec2, hi: DVec2) -> Vec<u32> {
        let ([i0, j0], [i1, j1]) = (self.index(lo), self.index(hi));
        let mut out: Vec<u32> = (j0..=j1)
            .flat_map(|j| (i0..=i1).flat_map(move |i| self.buckets[j * self.side + i].iter()))
            .copied()
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The triangle that holds `q` (mesh coordinates), or the one it is least outside of, with
    /// the barycentric weights of `q` in it.
    pub fn locate(&self, mesh: &SurfaceMesh, q: DVec2) -> Option<(usize, [f64; 3])> {
        let [i, j] = self.index(q);
        let mut best: Option<(f64, usize, [f64; 3])> = None;
        for &t in &self.buckets[j * self.side + i] {
            let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.local[i as usize]);
            let area = (b - a).perp_dot(c - a);
            if area == 0.0 {
                continue;
            }
            let w = [
                (b - q).perp_dot(c - q) / area,
                (c - q).perp_dot(a - q) / area,
                (a - q).perp_dot(b - q) / area,
            ];
            let outside = -w.iter().copied().fold(f64::INFINITY, f64::min);
            if best.is_none_or(|(o, _, _)| outside < o) {
                best = Some((outside, t as usize, w));
            }
        }
        best.map(|(_, t, w)| (t, w))
    }

    /// The linear interpolation of per-vertex `values` at `point` (3D, on the mesh's surface).
    pub fn interpolate(&self, mesh: &SurfaceMesh, values: &[Rgb], point: DVec3) -> Rgb {
        let q = mesh.frame.to_2d(point) / mesh.scale;
        self.locate(mesh, q).map_or(Rgb::ZERO, |(t, w)| {
            let tri = mesh.triangles[t];
            (0..3).map(|k| values[tri[k] as usize] * w[k]).sum()
        })
    }
}

/// Carries a per-triangle density (a value per unit area) from one mesh of a surface to another
/// of the same polygon, conserving its integral: each new triangle gets the area-weighted mean of
/// the old triangles it overlaps (exact convex clipping in mesh coordinates).
pub fn transfer_density(
    old: &SurfaceMesh,
    old_values: &[Rgb],
    locator: &TriangleLocator,
    new: &SurfaceMesh,
) -> Vec<Rgb> {
    new.triangles
        .iter()
        .map(|tri| {
            let p = tri.map(|i| new.local[i as usize]);
            let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
            let (mut sum, mut area) = (Rgb::ZERO, 0.0);
            for t in locator.candidates(lo, hi) {
                let q = old.triangles[t as usize].map(|i| old.local[i as usize]);
                let overlap = overlap_area(&p, &q);
                if overlap > 0.0 {
                    sum += old_values[t as usize] * overlap;
                    area += overlap;
                }
            }
            if area > 0.0 { sum / area } else { Rgb::ZERO }
        })
        .collect()
}

/// Area of the intersection of two counter-clockwise triangles.
fn overlap_area(a: &[DVec2; 3], b: &[DVec2; 3]) -> f64 {
    let mut poly: Vec<DVec2> = a.to_vec();
    for k in 0..3 {
        let (p, q) = (b[k], b[(k + 1) % 3]);
        let d = q - p;
        let side = |x: DVec2| d.perp_dot(x - p);
        let mut next = Vec::with_capacity(poly.len() + 2);
        for i in 0..poly.len() {
            let (u, v) = (poly[i], poly[(i + 1) % poly.len()]);
            let (su, sv) = (side(u), side(v));
            if su >= 0.0 {
                next.push(u);
            }
            if (su > 0.0 && sv < 0.0) || (su < 0.0 && sv > 0.0) {
                next.push(u + (v - u) * (su / (su - sv)));
            }
        }
        poly = next;
        if poly.len() < 3 {
            return 0.0;
        }
    }
    let n = poly.len();
    0.5 * (0..n)
        .map(|i| poly[i].perp_dot(poly[(i + 1) % n]))
        .sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh_scene_uniform;

    #[test]
    fn overlap_of_triangles() {
        let a = [DVec2::ZERO, DVec2::X, DVec2::Y];
        assert!((overlap_area(&a, &a) - 0.5).abs() < 1e-15);
        let shifted = a.map(|p| p + DVec2::new(0.5, 0.0));
        // The overlap is the triangle (0.5,0) (1,0) (0.5,0.5).
        assert!((overlap_area(&a, &shifted) - 0.125).abs() < 1e-15);
        let far = a.map(|p| p + DVec2::new(3.0, 0.0));
        assert_eq!(overlap_area(&a, &far), 0.0);
    }

    #[test]
    fn transfer_conserves_the_integral_and_constants() {
        let scene = penumbra_scenes::builtin::textbook();
        let coarse = mesh_scene_uniform(&scene, 300).expect("meshes");
        let fine = mesh_scene_uniform(&scene, 3000).expect("meshes");
        for (old, new) in coarse.surfaces.iter().zip(&fine.surfaces) {
            let values: Vec<Rgb> = (0..old.triangle_count())
                .map(|t| Rgb::splat((t % 7) as f64 + 1.0))
                .collect();
            let locator = TriangleLocator::new(old);
            let moved = transfer_density(old, &values, &locator, new);
            let integral = |m: &SurfaceMesh, v: &[Rgb]| -> f64 {
                (0..m.triangle_count())
                    .map(|t| v[t].r * m.triangle_area(t))
                    .sum()
            };
            let (before, after) = (integral(old, &values), integral(new, &moved));
            assert!(
                (before - after).abs() <= 1e-9 * before,
                "{before} -> {after}"
            );
            let ones = vec![Rgb::splat(2.0); old.triangle_count()];
            for v in transfer_density(old, &ones, &locator, new) {
                assert!((v.g - 2.0).abs() < 1e-12);
            }
        }
    }
}
