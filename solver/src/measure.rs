//! How wrong a solution is: its linear interpolation over the mesh against the exact direct light
//! at random points of each surface.

use glam::DVec3;
use penumbra_meshing::SurfaceMesh;
use penumbra_scenes::{AreaSampler, SplitMix64};
use penumbra_scenes::{Rgb, Scene};
use serde::Serialize;

use crate::direct::DirectLight;
use crate::lambert::ReceivingPoint;

/// Errors of an interpolated radiosity over one surface, in radiosity units (channel means).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct InterpolationError {
    /// Points sampled.
    pub samples: usize,
    /// Root mean square of the errors at the samples.
    pub rms: f64,
    /// The largest error at a sample.
    pub max: f64,
    /// Mean of the exact values at the samples, to state errors relative to it.
    pub mean_exact: f64,
}

/// Compares the radiosity `values` (per vertex of `mesh`), interpolated linearly, with the exact
/// direct radiosity `E + ρ H_direct` at `samples` points drawn uniformly over the surface's area
/// (seeded, so the same points every time).
pub fn direct_interpolation_error(
    scene: &Scene,
    direct: &DirectLight,
    mesh: &SurfaceMesh,
    values: &[Rgb],
    samples: usize,
    seed: u64,
) -> InterpolationError {
    let surface = &scene.surfaces[mesh.surface];
    let sampler = AreaSampler::new((0..mesh.triangle_count()).map(|t| mesh.triangle_area(t)));
    let mut rng = SplitMix64::keyed(seed, &[mesh.surface as u64]);
    let (mut sum2, mut max, mut sum_exact) = (0.0f64, 0.0f64, 0.0);
    for _ in 0..samples {
        let Some((t, w)) = sampler.pick(&mut rng) else {
            break;
        };
        let tri = mesh.triangles[t];
        let point: DVec3 = (0..3).map(|k| mesh.points3[tri[k] as usize] * w[k]).sum();
        let interpolated: Rgb = (0..3).map(|k| values[tri[k] as usize] * w[k]).sum();
        let x = ReceivingPoint::interior(point, mesh.frame.normal);
        let exact = surface.emission
            + surface
                .reflectance
                .mul_rgb(direct.irradiance(&x, mesh.surface));
        let e = (interpolated - exact).mean();
        sum2 += e * e;
        max = max.max(e.abs());
        sum_exact += exact.mean();
    }
    let n = samples.max(1) as f64;
    InterpolationError {
        samples,
        rms: (sum2 / n).sqrt(),
        max,
        mean_exact: sum_exact / n,
    }
}
