//! A full solution by photon mapping: the exact direct irradiance at every mesh vertex, plus the
//! indirect irradiance the photon map estimates there.

use std::time::Instant;

use glam::DVec3;
use penumbra_meshing::{SceneMesh, TriangleLocator};
use penumbra_scenes::{Rgb, Scene, SplitMix64, SurfaceId, Visibility};
use rayon::prelude::*;

use super::PhotonMap;
use crate::direct_pass::{check_mesh, direct_irradiance};
use crate::elements::Discretization;
use crate::lambert::ReceivingPoint;
use crate::rays::{cosine_direction, front_hit};
use crate::{Progress, Solution, SolveError, SolveStats, SolverOptions, StopReason};

/// Radiosity at every vertex of `mesh`: B = E + ρ (H_direct + H_indirect), the direct part
/// exact, the indirect part from a photon map made with `photons`; with the map's figures.
pub fn solve_photon_map(
    scene: &Scene,
    mesh: &SceneMesh,
    visibility: &Visibility,
    options: &SolverOptions,
    progress: &dyn Progress,
) -> Result<Solution, SolveError> {
    options.validate()?;
    let photons = &options.photon_map;
    check_mesh(scene, mesh)?;
    let started = Instant::now();
    let disc = Discretization::new(scene, mesh, options.elements_per_patch);
    let (direct, direct_beyond_cap) =
        direct_irradiance(scene, &disc, visibility, options, progress)?;
    let direct_seconds = started.elapsed().as_secs_f64();

    let started = Instant::now();
    let mut map = PhotonMap::trace(
        scene,
        visibility,
        photons,
        options.seed,
        options.interrupt.as_ref(),
        progress,
    )?;
    let estimating = Instant::now();
    let (indirect, stop, gathered) = if photons.final_gather > 0 {
        let lookups = disc.receiver_count().saturating_mul(photons.final_gather);
        map.precompute(lookups, &|| options.stop_now().is_some(), progress);
        let gather = FinalGather::new(scene, mesh, visibility, &map, disc.per_surface(&direct));
        gather_all(&gather, &disc, options, photons.final_gather, progress)
    } else {
        let raw = disc.receivers.par_iter().zip(&disc.receiver_surface);
        (
            raw.map(|(r, &s)| map.indirect_irradiance(r.point, s))
                .collect(),
            None,
            0,
        )
    };
    map.stats.estimate_seconds = estimating.elapsed().as_secs_f64();
    let irradiance: Vec<Rgb> = direct.iter().zip(&indirect).map(|(&d, &i)| d + i).collect();
    let mut stats = energy_stats(scene, &disc, &irradiance);
    stats.closed = Some(crate::solids::closed_scene(scene, visibility, &disc));
    stats.stop = stop.unwrap_or(StopReason::Converged);
    stats.gathered = gathered;
    stats.direct_seconds = direct_seconds;
    stats.direct_beyond_cap = direct_beyond_cap;
    stats.gather_seconds = started.elapsed().as_secs_f64();
    let irradiance = disc.per_surface(&irradiance);
    let radiosity = irradiance
        .iter()
        .enumerate()
        .map(|(s, h)| {
            let surface = &scene.surfaces[mesh.surfaces[s].surface];
            h.iter()
                .map(|&h| surface.emission + surface.reflectance.mul_rgb(h))
                .collect()
        })
        .collect();
    Ok(Solution {
        radiosity,
        irradiance,
        direct_irradiance: disc.per_surface(&direct),
        ambient: Rgb::ZERO,
        stats: SolveStats {
            photon_map: Some(map.stats),
            ..stats
        },
        convergence: Vec::new(),
    })
}

/// The energy account of `irradiance` at the vertices: what the surfaces absorb, and what
/// leaves the scene (what they emit and reflect, less what they receive).
fn energy_stats(scene: &Scene, disc: &Discretization, irradiance: &[Rgb]) -> SolveStats {
    let emitted = scene.emitted_power();
    let rho = |s: usize| scene.surfaces[s].reflectance;
    let absorbed = disc.integrate(irradiance, |e| Rgb::splat(1.0) - rho(e.surface));
    let reflected = disc.integrate(irradiance, |e| rho(e.surface));
    let received = disc.integrate(irradiance, |_| Rgb::splat(1.0));
    SolveStats {
        receivers: disc.receiver_count(),
        emitted,
        absorbed,
        escaped: emitted + reflected - received,
        ..SolveStats::default()
    }
}

/// Vertices gathered between two looks at the interrupt and the deadline.
const GATHER_CHUNK: usize = 512;

/// The final gather at every vertex, chunk by chunk; once the run must stop (an interrupt, the
/// time budget), the vertices left read the map where they are. With the reason it stopped, if
/// it did, and the vertices that gathered.
fn gather_all(
    gather: &FinalGather<'_>,
    disc: &Discretization,
    options: &SolverOptions,
    rays: usize,
    progress: &dyn Progress,
) -> (Vec<Rgb>, Option<StopReason>, usize) {
    let n = disc.receiver_count();
    let mut values = Vec::with_capacity(n);
    let (mut stop, mut gathered) = (None, 0);
    progress.start("final gather", n as u64);
    while values.len() < n {
        let range = values.len()..(values.len() + GATHER_CHUNK).min(n);
        stop = stop.or_else(|| options.stop_now());
        if stop.is_none() {
            gathered = range.end;
        }
        let chunk: Vec<Rgb> = range
            .into_par_iter()
            .map(|i| {
                let (r, s) = (&disc.receivers[i], disc.receiver_surface[i]);
                if stop.is_some() {
                    return gather.map.indirect_irradiance(r.point, s);
                }
                let mut rng = SplitMix64::keyed(options.seed, &[GATHER_KEY, i as u64]);
                gather.indirect(r, s, rays, &mut rng)
            })
            .collect();
        values.extend(chunk);
        progress.set(values.len() as u64);
    }
    progress.finish();
    (values, stop, gathered)
}

/// Keys the final gather's random streams apart from the photons' (keyed by their index alone).
const GATHER_KEY: u64 = u64::MAX - 1;

/// The final gather: at a vertex, rays in cosine-distributed directions read what the surfaces
/// they reach reflect, ρ (H_direct + H_indirect) there, the direct part interpolated over that
/// surface's mesh (exact at its vertices), the indirect part from the photon map. Reading the
/// map one bounce away blurs its noise and the bias of its estimates at the feet of blockers.
struct FinalGather<'a> {
    scene: &'a Scene,
    mesh: &'a SceneMesh,
    visibility: &'a Visibility,
    map: &'a PhotonMap<'a>,
    /// Per scene surface: its mesh's index, its locator and its vertices' direct irradiance.
    surfaces: Vec<Option<(usize, TriangleLocator)>>,
    direct: Vec<Vec<Rgb>>,
    offset: f64,
}

impl<'a> FinalGather<'a> {
    fn new(
        scene: &'a Scene,
        mesh: &'a SceneMesh,
        visibility: &'a Visibility,
        map: &'a PhotonMap<'a>,
        direct: Vec<Vec<Rgb>>,
    ) -> FinalGather<'a> {
        let mut surfaces: Vec<Option<(usize, TriangleLocator)>> =
            (0..scene.surfaces.len()).map(|_| None).collect();
        for (m, surface_mesh) in mesh.surfaces.iter().enumerate() {
            if let Some(slot) = surfaces.get_mut(surface_mesh.surface) {
                *slot = Some((m, TriangleLocator::new(surface_mesh)));
            }
        }
        FinalGather {
            scene,
            mesh,
            visibility,
            map,
            surfaces,
            direct,
            offset: visibility.contact_distance(),
        }
    }

    /// The indirect irradiance at `x` on surface `s` from `rays` rays (a stratified grid over
    /// the cosine-weighted hemisphere). Rays from a vertex on an edge start a little inside its
    /// surface, so that they cannot slip past the surface that meets it there.
    fn indirect(&self, x: &ReceivingPoint, s: SurfaceId, rays: usize, rng: &mut SplitMix64) -> Rgb {
        let Some(Some(frame)) = self.map.frames.get(s) else {
            return Rgb::ZERO;
        };
        let side = ((rays as f64).sqrt().ceil() as usize).max(1);
        let cell = 1.0 / side as f64;
        let inside = x.point + x.inward * self.visibility.junction_offset();
        let frames = &self.map.frames;
        let mut sum = Rgb::ZERO;
        for i in 0..side {
            for j in 0..side {
                let u = (
                    (i as f64 + rng.next_f64()) * cell,
                    (j as f64 + rng.next_f64()) * cell,
                );
                let d = cosine_direction(frame, u);
                if let Some((hit, _)) =
                    front_hit(self.visibility, frames, (inside, s), d, self.offset)
                {
                    sum += self.reflected(hit.point, hit.surface);
                }
            }
        }
        sum * (1.0 / (side * side) as f64)
    }

    /// What surface `t` reflects at `y` (on its front).
    fn reflected(&self, y: DVec3, t: SurfaceId) -> Rgb {
        let Some(Some((m, locator))) = self.surfaces.get(t) else {
            return Rgb::ZERO;
        };
        let direct = locator.interpolate(&self.mesh.surfaces[*m], &self.direct[*m], y);
        let h = direct + self.map.gathered_irradiance(y, t);
        self.scene.surfaces[t].reflectance.mul_rgb(h)
    }
}
