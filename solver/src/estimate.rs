//! Where a mesh's linear interpolation is wrong: per-triangle residuals against the exact direct
//! radiosity, sampled at the edge midpoints and the centroid.
//!
//! The vertex values of a direct-only solution are exact, so the residual at a sample is the
//! interpolation error itself there. For full solutions the indirect part is smooth and the
//! direct residual is what marks the shadows' detail.

use glam::DVec3;
use penumbra_meshing::SurfaceMesh;
use penumbra_scenes::{Rgb, Scene};
use rayon::prelude::*;
use serde::Serialize;

use crate::direct::DirectLight;
use crate::lambert::ReceivingPoint;

/// Sample points are pulled this fraction of the way to the triangle's centroid, so that a sample
/// on a value discontinuity (a contact line along an edge) takes the triangle's own side. It must
/// clear the evaluator's junction offset (1e-7 of the scene) even for small triangles; the
/// interpolant and the light move by a thousandth of a triangle's own variation.
const INWARD: f64 = 1e-3;

/// Residuals of one surface's interpolation: the largest absolute difference (channel mean, in
/// radiosity units) at each triangle's samples.
pub fn direct_residuals(
    scene: &Scene,
    direct: &DirectLight,
    mesh: &SurfaceMesh,
    values: &[Rgb],
) -> Vec<f64> {
    let surface = &scene.surfaces[mesh.surface];
    let normal = mesh.frame.normal;
    let exact = |p: DVec3| {
        (surface.emission
            + surface
                .reflectance
                .mul_rgb(direct.irradiance(&ReceivingPoint::interior(p, normal), mesh.surface)))
        .mean()
    };
    mesh.triangles
        .par_iter()
        .map(|tri| {
            let p = tri.map(|i| mesh.points3[i as usize]);
            let v = tri.map(|i| values[i as usize].mean());
            let centroid = (p[0] + p[1] + p[2]) / 3.0;
            // Barycentric weights of the samples: the three edge midpoints and the centroid.
            let samples = [
                [0.5, 0.5, 0.0],
                [0.0, 0.5, 0.5],
                [0.5, 0.0, 0.5],
                [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
            ];
            samples
                .iter()
                .map(|w| {
                    let x: DVec3 = (0..3).map(|k| p[k] * w[k]).sum();
                    let interpolated: f64 = (0..3).map(|k| v[k] * w[k]).sum();
                    (interpolated - exact(x.lerp(centroid, INWARD))).abs()
                })
                .fold(0.0, f64::max)
        })
        .collect()
}

/// A scene's residuals summed up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ResidualSummary {
    /// The largest triangle residual.
    pub max: f64,
    /// Area-weighted root mean square of the triangle residuals: an estimate of the RMS
    /// interpolation error.
    pub rms: f64,
    /// Area-weighted mean of the vertex radiosity (channel mean), the scale errors are stated in.
    pub mean_radiosity: f64,
}

/// Summarises the residuals `residuals[s][t]` of every surface's triangles.
pub fn summarize(
    meshes: &[SurfaceMesh],
    values: &[Vec<Rgb>],
    residuals: &[Vec<f64>],
) -> ResidualSummary {
    let (mut area, mut sum2, mut max, mut weighted) = (0.0, 0.0, 0.0f64, 0.0);
    for ((mesh, r), vals) in meshes.iter().zip(residuals).zip(values) {
        for (t, &e) in r.iter().enumerate() {
            let a = mesh.triangle_area(t);
            area += a;
            sum2 += a * e * e;
            max = max.max(e);
            let mean: f64 = mesh.triangles[t]
                .iter()
                .map(|&i| vals[i as usize].mean())
                .sum::<f64>()
                / 3.0;
            weighted += a * mean;
        }
    }
    let area = area.max(f64::MIN_POSITIVE);
    ResidualSummary {
        max,
        rms: (sum2 / area).sqrt(),
        mean_radiosity: weighted / area,
    }
}
