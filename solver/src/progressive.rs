//! Progressive refinement radiosity (Cohen, Chen, Wallace & Greenberg 1988) with vertex
//! receivers (Wallace, Elmquist & Haines 1989).
//!
//! 1. Emitters shoot first, exactly: every vertex gets its direct irradiance from the exact
//!    evaluator (visible part of each emitter by backprojection, Lambert's formula).
//! 2. Then the patch with the most unshot power shoots it to every vertex. The form factor from a
//!    vertex to the patch is Lambert's formula over the patch outline times a visibility fraction
//!    from stratified rays. Received irradiance is reflected into the unshot radiosity of the
//!    elements around the vertex (the linear interpolant's integral), and so on, until the unshot
//!    power is below `epsilon` of the emitted power or the shot cap is reached.
//!
//! Results do not depend on the thread count: receivers are evaluated in parallel, but every
//! sum is taken in a fixed order.

use std::collections::HashMap;
use std::time::Instant;

use penumbra_meshing::SceneMesh;
use penumbra_scenes::{Rgb, Scene, Visibility};
use rayon::prelude::*;
use serde::Serialize;

use crate::coupling::PatchCoupling;
use crate::direct::DirectLight;
use crate::elements::Discretization;
use crate::error::SolveError;
use crate::progress::Progress;

/// Options of the progressive solver; every field is checked by [`SolverOptions::validate`].
#[derive(Clone, Debug, PartialEq)]
pub struct SolverOptions {
    /// Stop when the unshot power falls below this fraction of the emitted power.
    pub epsilon: f64,
    /// Stop after this many patch shots even if not converged.
    pub max_shots: usize,
    /// Rays per vertex–patch pair for visibility fractions.
    pub visibility_rays: usize,
    /// Elements grouped into one shooting patch.
    pub elements_per_patch: usize,
    /// One bounce only: B = E + ρ H_direct, exact.
    pub direct_only: bool,
    pub seed: u64,
    /// Memory allowed for caching vertex–patch form factors, in bytes.
    pub cache_bytes: usize,
    /// Stop shooting at this moment, converged or not (an anytime solve).
    pub deadline: Option<Instant>,
}

pub const DEFAULT_EPSILON: f64 = 1e-3;

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            epsilon: DEFAULT_EPSILON,
            max_shots: 100_000,
            visibility_rays: 16,
            elements_per_patch: 24,
            direct_only: false,
            seed: 0x5EED,
            cache_bytes: 1 << 30,
            deadline: None,
        }
    }
}

impl SolverOptions {
    pub fn validate(&self) -> Result<(), SolveError> {
        let bad = |option: &'static str, reason: &'static str| {
            Err(SolveError::InvalidOption { option, reason })
        };
        if !(self.epsilon > 0.0 && self.epsilon < 1.0) {
            return bad("epsilon", "must be in (0, 1)");
        }
        if self.visibility_rays == 0 {
            return bad("visibility rays", "must be at least 1");
        }
        if self.elements_per_patch == 0 {
            return bad("elements per patch", "must be at least 1");
        }
        Ok(())
    }
}

/// Why the solver stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// Unshot power fell below epsilon of the emitted power.
    Converged,
    /// The shot cap was reached first.
    ShotLimit,
    /// Direct light only: one exact bounce, nothing to iterate.
    DirectOnly,
    /// The time budget ran out: the solution is the best so far.
    TimeBudget,
}

/// Figures of a solve. Powers are in W per channel (radiosity times area in scene units).
#[derive(Clone, Debug, Serialize)]
pub struct SolveStats {
    pub stop: StopReason,
    pub shots: usize,
    pub patches: usize,
    pub receivers: usize,
    pub rays_cast: u64,
    /// Power leaving the emitters by their own emission.
    pub emitted: Rgb,
    /// Power absorbed by all surfaces: ∫ (1 - ρ) H.
    pub absorbed: Rgb,
    /// Reflected power not shot yet.
    pub unshot: Rgb,
    /// Shot power that no vertex received: light leaving an open scene, plus the discretization
    /// error of vertex-sampled form factors (in a closed scene, only the latter).
    pub escaped: Rgb,
    /// Unshot power over emitted power (channel means).
    pub unshot_fraction: f64,
    pub direct_seconds: f64,
    pub shooting_seconds: f64,
}

/// Radiosity and irradiance at every mesh vertex, per surface.
#[derive(Clone, Debug)]
pub struct Solution {
    pub radiosity: Vec<Vec<Rgb>>,
    pub irradiance: Vec<Vec<Rgb>>,
    /// Cohen et al.'s ambient term for display: an estimate of the light not yet shot, spread
    /// evenly. Never part of the radiosity.
    pub ambient: Rgb,
    pub stats: SolveStats,
}

/// Direct irradiance at every vertex from the exact evaluator.
pub fn direct_irradiance(
    scene: &Scene,
    disc: &Discretization,
    visibility: &Visibility,
    progress: &dyn Progress,
) -> Vec<Rgb> {
    let direct = DirectLight::new(scene, visibility);
    let n = disc.receiver_count();
    progress.start("direct light", n as u64);
    let done = std::sync::atomic::AtomicU64::new(0);
    let out = (0..n)
        .into_par_iter()
        .map(|v| {
            let h = direct.irradiance(&disc.receivers[v], disc.receiver_surface[v]);
            let d = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            if d.is_multiple_of(256) {
                progress.set(d);
            }
            h
        })
        .collect();
    progress.finish();
    out
}

/// Solves a meshed scene by progressive refinement.
pub fn solve_progressive(
    scene: &Scene,
    mesh: &SceneMesh,
    visibility: &Visibility,
    options: &SolverOptions,
    progress: &dyn Progress,
) -> Result<Solution, SolveError> {
    options.validate()?;
    if mesh.surfaces.len() != scene.surfaces.len() {
        return Err(SolveError::MeshMismatch {
            surfaces: scene.surfaces.len(),
            meshes: mesh.surfaces.len(),
        });
    }
    let disc = Discretization::new(scene, mesh, options.elements_per_patch);
    let n = disc.receiver_count();

    let started = Instant::now();
    let mut irradiance = direct_irradiance(scene, &disc, visibility, progress);
    let direct_seconds = started.elapsed().as_secs_f64();

    let emitted = scene.emitted_power();
    let radiosity_of = |h: &[Rgb]| -> Vec<Rgb> {
        (0..n)
            .map(|v| disc.emission[v] + disc.reflectance[v].mul_rgb(h[v]))
            .collect()
    };
    let received_direct = disc.integrate(&irradiance, |_| Rgb::splat(1.0));
    let mut escaped = emitted - received_direct;

    // Unshot radiosity per element: the mean of its vertices' reflected irradiance.
    let mut element_unshot: Vec<Rgb> = disc
        .elements
        .iter()
        .map(|e| {
            let rho = scene.surfaces[e.surface].reflectance;
            e.vertices
                .iter()
                .map(|&v| irradiance[v])
                .sum::<Rgb>()
                .mul_rgb(rho)
                / 3.0
        })
        .collect();

    let shooting_started = Instant::now();
    let mut shots = 0usize;
    let mut rays_cast = 0u64;
    let stop;
    if options.direct_only {
        stop = StopReason::DirectOnly;
    } else {
        let coupling = PatchCoupling {
            disc: &disc,
            visibility,
            rays: options.visibility_rays,
            seed: options.seed,
        };
        let mut cache: HashMap<usize, Vec<f32>> = HashMap::new();
        let cache_limit = options.cache_bytes / (4 * n.max(1));
        let emitted_mean = emitted.mean().max(f64::MIN_POSITIVE);
        let goal = -options.epsilon.log10();
        progress.start("shooting", 1000);
        stop = loop {
            let patch_power: Vec<Rgb> = patch_unshot_power(&disc, &element_unshot);
            let total_unshot: Rgb = patch_power.iter().copied().sum();
            let fraction = total_unshot.mean() / emitted_mean;
            progress.set(((-fraction.max(1e-300).log10() / goal).clamp(0.0, 1.0) * 1000.0) as u64);
            if fraction < options.epsilon {
                break StopReason::Converged;
            }
            if shots >= options.max_shots {
                break StopReason::ShotLimit;
            }
            if options.deadline.is_some_and(|d| Instant::now() >= d) {
                break StopReason::TimeBudget;
            }
            // The patch with the most unshot power (ties: the lowest index).
            let Some((p, power)) = patch_power
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.mean().total_cmp(&b.1.mean()).then(b.0.cmp(&a.0)))
                .map(|(p, &w)| (p, w))
            else {
                break StopReason::Converged;
            };
            let patch = &disc.patches[p];
            let shot_radiosity = power / patch.area;

            let column = match cache.get(&p) {
                Some(c) => c.clone(),
                None => {
                    let computed: Vec<(f32, u32)> = (0..n)
                        .into_par_iter()
                        .map(|v| {
                            let (f, r) = coupling.coupling(v, p);
                            (f as f32, r)
                        })
                        .collect();
                    rays_cast += computed.iter().map(|&(_, r)| r as u64).sum::<u64>();
                    let column: Vec<f32> = computed.into_iter().map(|(f, _)| f).collect();
                    if cache.len() < cache_limit {
                        cache.insert(p, column.clone());
                    }
                    column
                }
            };
            let delta: Vec<Rgb> = column.iter().map(|&f| shot_radiosity * f as f64).collect();
            for v in 0..n {
                irradiance[v] += delta[v];
            }
            for &e in &patch.elements {
                element_unshot[e] = Rgb::ZERO;
            }
            for (e, unshot) in disc.elements.iter().zip(element_unshot.iter_mut()) {
                let rho = scene.surfaces[e.surface].reflectance;
                *unshot += e
                    .vertices
                    .iter()
                    .map(|&v| delta[v])
                    .sum::<Rgb>()
                    .mul_rgb(rho)
                    / 3.0;
            }
            escaped += power - disc.integrate(&delta, |_| Rgb::splat(1.0));
            shots += 1;
        };
        progress.finish();
    }
    let shooting_seconds = shooting_started.elapsed().as_secs_f64();

    let radiosity = radiosity_of(&irradiance);
    let unshot: Rgb = patch_unshot_power(&disc, &element_unshot).into_iter().sum();
    let absorbed = disc.integrate(&irradiance, |e| {
        Rgb::splat(1.0) - scene.surfaces[e.surface].reflectance
    });
    let total_area: f64 = disc.elements.iter().map(|e| e.area).sum();
    let mean_rho: Rgb = disc
        .elements
        .iter()
        .map(|e| scene.surfaces[e.surface].reflectance * e.area)
        .sum::<Rgb>()
        / total_area;
    let ambient = (unshot / total_area).mul_rgb(mean_rho.map(|r| 1.0 / (1.0 - r)));
    let stats = SolveStats {
        stop,
        shots,
        patches: disc.patches.len(),
        receivers: n,
        rays_cast,
        emitted,
        absorbed,
        unshot,
        escaped,
        unshot_fraction: unshot.mean() / emitted.mean().max(f64::MIN_POSITIVE),
        direct_seconds,
        shooting_seconds,
    };
    Ok(Solution {
        radiosity: disc.per_surface(&radiosity),
        irradiance: disc.per_surface(&irradiance),
        ambient,
        stats,
    })
}

/// Unshot power of every patch: Σ area × unshot radiosity of its elements.
fn patch_unshot_power(disc: &Discretization, element_unshot: &[Rgb]) -> Vec<Rgb> {
    disc.patches
        .iter()
        .map(|p| {
            p.elements
                .iter()
                .map(|&e| element_unshot[e] * disc.elements[e].area)
                .sum()
        })
        .collect()
}
