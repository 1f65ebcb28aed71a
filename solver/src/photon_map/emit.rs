//! Where photons start: the emitters share the photons in proportion to their power, and each
//! emitter's photons cover its area and its hemisphere of directions evenly. The four numbers
//! that place a photon (two for the point, two for the direction) come from a randomly shifted
//! R4 sequence (Roberts 2018), which strata every projection of the 4D cube for any count; the
//! shift, one per emitter, keeps the estimate unbiased.

use glam::{DVec2, DVec3};
use penumbra_scenes::polygon::triangulate_ccw;
use penumbra_scenes::{PlaneFrame, Rgb, Scene, SplitMix64, SurfaceId};

use super::Photon;
use crate::rays::cosine_direction;

/// The R4 sequence's steps: the powers of 1/φ₄, where φ₄ = 1.1673... is the real root of
/// x⁵ = x + 1.
fn r4_steps() -> [f64; 4] {
    // Newton's method from 1.2 converges to the root in a few steps.
    let mut phi = 1.2_f64;
    for _ in 0..32 {
        phi -= (phi.powi(5) - phi - 1.0) / (5.0 * phi.powi(4) - 1.0);
    }
    [1, 2, 3, 4].map(|k| phi.powi(-k))
}

/// One emitter's photons.
struct Emitter {
    surface: SurfaceId,
    frame: PlaneFrame,
    /// Its polygon's triangles in the frame, and the running sum of their areas.
    triangles: Vec<[DVec2; 3]>,
    cumulative: Vec<f64>,
    /// The index of its first photon, and how many it has.
    first: usize,
    count: usize,
    /// Each photon's share of the emitter's power.
    power: Rgb,
    /// The random shift of its sequence.
    shift: [f64; 4],
}

/// Every emitter's photons, numbered one after another.
pub(super) struct Emission {
    emitters: Vec<Emitter>,
    count: usize,
    steps: [f64; 4],
}

/// Keys the emitters' shifts apart from the photons' own streams (keyed by their index).
const SHIFT_KEY: u64 = u64::MAX;

impl Emission {
    /// About `photons` photons (at least one per emitter that can emit), shared by power; the
    /// sequences' shifts come from `seed`.
    pub(super) fn new(
        scene: &Scene,
        frames: &[Option<PlaneFrame>],
        photons: usize,
        seed: u64,
    ) -> Emission {
        let candidates: Vec<(SurfaceId, PlaneFrame, Rgb)> = scene
            .emitters()
            .filter_map(|(s, surface)| Some((s, frames[s]?, surface.emitted_power())))
            .filter(|(_, _, power)| power.mean() > 0.0)
            .collect();
        let counts = shares(
            &candidates.iter().map(|c| c.2.mean()).collect::<Vec<_>>(),
            photons,
        );
        let mut emitters = Vec::new();
        let mut first = 0;
        for ((s, frame, power), count) in candidates.into_iter().zip(counts) {
            let polygon: Vec<DVec2> = scene.surfaces[s]
                .polygon
                .iter()
                .map(|&p| frame.to_2d(p))
                .collect();
            let triangles: Vec<[DVec2; 3]> = triangulate_ccw(&polygon)
                .into_iter()
                .map(|t| t.map(|i| polygon[i]))
                .collect();
            let mut sum = 0.0;
            let cumulative = triangles
                .iter()
                .map(|t| {
                    sum += 0.5 * (t[1] - t[0]).perp_dot(t[2] - t[0]).abs();
                    sum
                })
                .collect();
            emitters.push(Emitter {
                surface: s,
                frame,
                triangles,
                cumulative,
                first,
                count,
                power: power * (1.0 / count as f64),
                shift: {
                    let mut rng = SplitMix64::keyed(seed, &[SHIFT_KEY, s as u64]);
                    [0; 4].map(|_| rng.next_f64())
                },
            });
            first += count;
        }
        Emission {
            emitters,
            count: first,
            steps: r4_steps(),
        }
    }

    /// Photons in all.
    pub(super) fn count(&self) -> usize {
        self.count
    }

    /// Photon `i`, `i` below [`Emission::count`].
    pub(super) fn photon(&self, i: usize) -> Photon {
        let e = self.emitters.partition_point(|e| e.first + e.count <= i);
        let emitter = &self.emitters[e];
        let j = (i - emitter.first) as f64;
        let u = [0, 1, 2, 3].map(|k| (emitter.shift[k] + j * self.steps[k]).fract());
        Photon {
            surface: emitter.surface,
            origin: emitter.point(u[0], u[1]),
            direction: cosine_direction(&emitter.frame, (u[2], u[3])),
            power: emitter.power,
        }
    }
}

impl Emitter {
    /// The point of the emitter that (u1, u2), uniform in the unit square, picks: uniform over
    /// its area.
    fn point(&self, u1: f64, u2: f64) -> DVec3 {
        let total = self.cumulative.last().copied().unwrap_or(0.0);
        let target = u1 * total;
        let t = self
            .cumulative
            .partition_point(|&c| c <= target)
            .min(self.triangles.len().saturating_sub(1));
        let below = if t == 0 { 0.0 } else { self.cumulative[t - 1] };
        let width = self.cumulative[t] - below;
        // u1 rescaled within the chosen triangle's share keeps its stratification.
        let r1 = if width > 0.0 {
            ((target - below) / width).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let [a, b, c] = self.triangles[t];
        let s = r1.sqrt();
        self.frame
            .to_3d(a * (1.0 - s) + b * (s * (1.0 - u2)) + c * (s * u2))
    }
}

/// `total` shared in proportion to `weights` (largest remainders, ties to the first), at least
/// one each.
fn shares(weights: &[f64], total: usize) -> Vec<usize> {
    let sum: f64 = weights.iter().sum();
    if weights.is_empty() || !(sum > 0.0) {
        return vec![1; weights.len()];
    }
    let exact: Vec<f64> = weights.iter().map(|w| w / sum * total as f64).collect();
    let mut counts: Vec<usize> = exact.iter().map(|e| e.floor() as usize).collect();
    let mut order: Vec<usize> = (0..weights.len()).collect();
    order.sort_by(|&a, &b| {
        (exact[b] - exact[b].floor())
            .total_cmp(&(exact[a] - exact[a].floor()))
            .then(a.cmp(&b))
    });
    let short = total.saturating_sub(counts.iter().sum());
    for &k in order.iter().take(short) {
        counts[k] += 1;
    }
    counts.iter().map(|&c| c.max(1)).collect()
}
