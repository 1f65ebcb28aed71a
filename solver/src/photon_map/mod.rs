//! Photon mapping (Jensen 1996) for the light reflected more than once: photons leave the
//! emitters, stratified over their area and directions and carrying equal shares of their power,
//! bounce through the scene with Russian roulette, and are stored where they land after at
//! least one reflection. The direct light stays exact ([`crate::DirectLight`]); the map holds
//! only the indirect light, whose irradiance at a point is estimated from its nearest photons
//! on the same surface ([`PhotonMap::indirect_irradiance`]).
//!
//! Each photon has its own random stream, keyed by the seed, its emitter and its index, and
//! photons are stored in the order they were emitted, so the map does not depend on the thread
//! count.

mod disc;
mod emit;
mod solve;

use std::num::NonZero;

use glam::{DVec2, DVec3};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use penumbra_scenes::{PlaneFrame, Rgb, Scene, SplitMix64, SurfaceId, Visibility};
use rayon::prelude::*;

pub use crate::options::{
    DEFAULT_FINAL_GATHER, DEFAULT_GATHER_PHOTONS, DEFAULT_PHOTONS, MAX_GATHER_PHOTONS, MAX_PHOTONS,
    PhotonMapOptions,
};
use crate::rays::{cosine_direction, front_hit};
pub use crate::solution::PhotonStats;
use crate::{Interrupt, Progress, SolveError};
use emit::Emission;
pub use solve::solve_photon_map;

/// Paths whose power, relative to what they left their emitter with, falls below this play
/// Russian roulette with it as their survival chance.
const ROULETTE_BELOW: f64 = 0.5;
/// Bounces at most: a photon this old carries ρ^64 of its power.
const MAX_BOUNCES: usize = 64;
/// Photons traced, or estimates made, between two looks at the interrupt.
const CHUNK: usize = 4096;
/// For a final gather, irradiance is estimated in advance at every this many stored photons
/// (Christensen 1999: a quarter).
const PRECOMPUTE_EVERY: usize = 4;
/// Bytes a stored photon, or an estimate made in advance, holds: its position, its power or
/// value, and its tree's share.
const POINT_BYTES: usize = 3 * 8 + size_of::<Rgb>() + 3 * 8;

/// A photon where it landed: its position and the power it brought, W per channel.
#[derive(Clone, Copy, Debug)]
struct Landing {
    surface: SurfaceId,
    point: DVec3,
    power: Rgb,
}

/// The photons of one surface, and a k-d tree over their positions.
struct SurfacePhotons {
    tree: ImmutableKdTree<f64, 3>,
    power: Vec<Rgb>,
    /// The surface's polygon in its frame, for the disc's area, and its area.
    polygon: Vec<DVec2>,
    area: f64,
    /// Where estimates may be made in advance for a final gather: every
    /// [`PRECOMPUTE_EVERY`]th photon's position (none without a final gather).
    sites: Vec<[f64; 3]>,
    /// Estimates made in advance at the sites, for the final gather.
    precomputed: Option<Precomputed>,
}

/// Irradiance estimated in advance at a share of a surface's photons: the final gather reads
/// the nearest of them, one neighbour, instead of gathering k photons at every ray's end.
struct Precomputed {
    tree: ImmutableKdTree<f64, 3>,
    irradiance: Vec<Rgb>,
}

impl SurfacePhotons {
    /// The irradiance at `x` (on the surface, whose frame is `frame`) from the `k` nearest
    /// photons, over the part of the surface the disc through the farthest of them covers; when
    /// the surface holds fewer than `k`, all of them over all of it (a disc fitted to a few
    /// photons that landed close together would make a spike).
    fn estimate(&self, frame: &PlaneFrame, x: DVec3, k: NonZero<usize>) -> Rgb {
        let nearest = self
            .tree
            .query(&x.to_array())
            .nearest_n::<SquaredEuclidean<f64>>(k)
            .execute();
        let Some(radius_squared) = nearest.iter().map(|n| n.distance).reduce(f64::max) else {
            return Rgb::ZERO;
        };
        let area = match nearest.len() < k.get() {
            true => self.area,
            false => disc::area_in_polygon(frame.to_2d(x), radius_squared.sqrt(), &self.polygon),
        };
        if !(area > 0.0) {
            return Rgb::ZERO;
        }
        let power: Rgb = nearest.iter().map(|n| self.power[n.item as usize]).sum();
        power * (1.0 / area)
    }
}

/// The indirect photons of a scene, surface by surface.
pub struct PhotonMap<'a> {
    scene: &'a Scene,
    frames: Vec<Option<PlaneFrame>>,
    surfaces: Vec<Option<SurfacePhotons>>,
    gather: usize,
    /// What making it did.
    pub stats: PhotonStats,
}

impl std::fmt::Debug for PhotonMap<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PhotonMap")
            .field("scene", &self.scene.name)
            .field("stats", &self.stats)
            .finish()
    }
}

impl<'a> PhotonMap<'a> {
    /// Traces `options.photons` photons through `scene` (with `visibility` its index), their
    /// random streams keyed by `seed`, and stores where they land after a reflection;
    /// [`SolveError::Interrupted`] once `interrupt` is set.
    pub fn trace(
        scene: &'a Scene,
        visibility: &Visibility,
        options: &PhotonMapOptions,
        seed: u64,
        interrupt: Option<&Interrupt>,
        progress: &dyn Progress,
    ) -> Result<PhotonMap<'a>, SolveError> {
        let frames: Vec<Option<PlaneFrame>> = scene
            .surfaces
            .iter()
            .map(|s| PlaneFrame::of_polygon(&s.polygon))
            .collect();
        let emission = Emission::new(scene, &frames, options.photons, seed);
        let tracer = Tracer {
            scene,
            visibility,
            frames: &frames,
            offset: visibility.contact_distance(),
        };
        let started = std::time::Instant::now();
        let mut landings = Vec::new();
        let mut escaped = Rgb::ZERO;
        let mut start = 0;
        progress.start("photons", emission.count() as u64);
        while start < emission.count() {
            if interrupt.is_some_and(Interrupt::is_set) {
                return Err(SolveError::Interrupted);
            }
            let end = (start + CHUNK).min(emission.count());
            let chunk: Vec<(Vec<Landing>, Rgb)> = (start..end)
                .into_par_iter()
                .map(|i| {
                    let mut rng = SplitMix64::keyed(seed, &[i as u64]);
                    let photon = emission.photon(i);
                    tracer.landings(photon, &mut rng)
                })
                .collect();
            for (photon_landings, lost) in chunk {
                landings.extend(photon_landings);
                escaped += lost;
            }
            start = end;
            progress.set(start as u64);
        }
        progress.finish();
        let mut map = Self::store(scene, frames, landings, emission.count(), options);
        map.stats.escaped = escaped;
        map.stats.trace_seconds = started.elapsed().as_secs_f64();
        Ok(map)
    }

    /// For a final gather that will read the map `lookups` times: estimates the irradiance at
    /// the sites, surface by surface, for [`PhotonMap::gathered_irradiance`], unless there are
    /// at least as many sites as lookups (then each lookup gathers its own photons). Once `stop`
    /// says so (an interrupt, the time budget), the gather will not run, and it keeps none.
    pub(crate) fn precompute(
        &mut self,
        lookups: usize,
        stop: &(dyn Fn() -> bool + Sync),
        progress: &dyn Progress,
    ) {
        let sites: Vec<Vec<[f64; 3]>> = self
            .surfaces
            .iter_mut()
            .map(|p| {
                p.as_mut()
                    .map(|p| std::mem::take(&mut p.sites))
                    .unwrap_or_default()
            })
            .collect();
        let total = sites.iter().map(Vec::len).sum::<usize>();
        if total >= lookups {
            return;
        }
        let k = NonZero::new(self.gather).unwrap_or(NonZero::<usize>::MIN);
        progress.start("irradiance at photons", total as u64);
        // Kept only once every surface is done: a gather that is stopped reads none.
        let mut made = Vec::new();
        let mut done = 0;
        for (s, sites) in sites.into_iter().enumerate() {
            let (Some(Some(photons)), Some(Some(frame))) =
                (self.surfaces.get(s), self.frames.get(s))
            else {
                continue;
            };
            let mut irradiance = Vec::with_capacity(sites.len());
            for chunk in sites.chunks(CHUNK) {
                if stop() {
                    progress.finish();
                    return;
                }
                let values: Vec<Rgb> = chunk
                    .par_iter()
                    .map(|&p| photons.estimate(frame, DVec3::from_array(p), k))
                    .collect();
                irradiance.extend(values);
                done += chunk.len();
                progress.set(done as u64);
            }
            // An empty surface gives no tree: its readings gather their own photons.
            if let Ok(tree) = ImmutableKdTree::new_from_slice(&sites)
                && !sites.is_empty()
            {
                made.push((s, Precomputed { tree, irradiance }));
            }
        }
        progress.finish();
        for (s, precomputed) in made {
            self.stats.precomputed += precomputed.irradiance.len();
            self.stats.bytes += precomputed.irradiance.len() * POINT_BYTES;
            if let Some(Some(photons)) = self.surfaces.get_mut(s) {
                photons.precomputed = Some(precomputed);
            }
        }
    }

    /// The map of `landings`, sorted by surface in the order they came.
    fn store(
        scene: &'a Scene,
        frames: Vec<Option<PlaneFrame>>,
        landings: Vec<Landing>,
        emitted: usize,
        options: &PhotonMapOptions,
    ) -> PhotonMap<'a> {
        let stored = landings.len();
        let mut by_surface: Vec<Vec<Landing>> = vec![Vec::new(); scene.surfaces.len()];
        for l in landings {
            by_surface[l.surface].push(l);
        }
        let mut bytes = 0;
        let surfaces = by_surface
            .into_iter()
            .enumerate()
            .map(|(s, photons)| {
                let frame = frames[s]?;
                let points: Vec<[f64; 3]> = photons.iter().map(|l| l.point.to_array()).collect();
                let tree = ImmutableKdTree::new_from_slice(&points).ok()?;
                bytes += points.len() * POINT_BYTES;
                let polygon: Vec<DVec2> = scene.surfaces[s]
                    .polygon
                    .iter()
                    .map(|&p| frame.to_2d(p))
                    .collect();
                let sites = match options.final_gather {
                    0 => Vec::new(),
                    _ => points.iter().step_by(PRECOMPUTE_EVERY).copied().collect(),
                };
                Some(SurfacePhotons {
                    tree,
                    power: photons.iter().map(|l| l.power).collect(),
                    area: penumbra_scenes::polygon::signed_area_2d(&polygon).abs(),
                    polygon,
                    sites,
                    precomputed: None,
                })
            })
            .collect();
        PhotonMap {
            scene,
            frames,
            surfaces,
            gather: options.gather_photons.max(1),
            stats: PhotonStats {
                emitted,
                stored,
                bytes,
                ..PhotonStats::default()
            },
        }
    }

    /// The irradiance at `x` on surface `s` from light reflected at least once, W/m² per
    /// channel: the power of the nearest photons on `s` over the part of `s` the disc through
    /// the farthest of them covers (so a disc that reaches over the surface's edge is not
    /// diluted by area where no photon could land).
    pub fn indirect_irradiance(&self, x: DVec3, s: SurfaceId) -> Rgb {
        let (Some(Some(photons)), Some(Some(frame))) = (self.surfaces.get(s), self.frames.get(s))
        else {
            return Rgb::ZERO;
        };
        photons.estimate(
            frame,
            x,
            NonZero::new(self.gather).unwrap_or(NonZero::<usize>::MIN),
        )
    }

    /// The indirect irradiance at `x` on surface `s` as the final gather reads it: the estimate
    /// made in advance at the nearest of the surface's photons that have one, else
    /// [`PhotonMap::indirect_irradiance`] at `x`.
    fn gathered_irradiance(&self, x: DVec3, s: SurfaceId) -> Rgb {
        let Some(Some(SurfacePhotons {
            precomputed: Some(precomputed),
            ..
        })) = self.surfaces.get(s)
        else {
            return self.indirect_irradiance(x, s);
        };
        let nearest = precomputed
            .tree
            .query(&x.to_array())
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        // The tree holds the sites the estimates were made at, in their order.
        precomputed.irradiance[nearest.item as usize]
    }
}

/// A photon leaving its emitter.
#[derive(Clone, Copy, Debug)]
struct Photon {
    surface: SurfaceId,
    origin: DVec3,
    direction: DVec3,
    power: Rgb,
}

/// What traces photons.
struct Tracer<'s> {
    scene: &'s Scene,
    visibility: &'s Visibility,
    frames: &'s [Option<PlaneFrame>],
    /// Rays start this far off their surface, and hits this close to the start are ignored.
    offset: f64,
}

impl Tracer<'_> {
    /// Where `photon` lands after its first reflection, bounce after bounce, until it leaves the
    /// scene, reaches a surface's back or loses at Russian roulette; with the power it took out
    /// of the scene (leaving or at a back).
    fn landings(&self, photon: Photon, rng: &mut SplitMix64) -> (Vec<Landing>, Rgb) {
        let mut landings = Vec::new();
        let (mut s, mut x, mut d) = (photon.surface, photon.origin, photon.direction);
        let mut power = photon.power;
        let start_strength = power.max_channel();
        for bounce in 0..MAX_BOUNCES {
            let Some((hit, hit_frame)) =
                front_hit(self.visibility, self.frames, (x, s), d, self.offset)
            else {
                return (landings, power);
            };
            if bounce > 0 {
                landings.push(Landing {
                    surface: hit.surface,
                    point: hit.point,
                    power,
                });
            }
            power = power.mul_rgb(self.scene.surfaces[hit.surface].reflectance);
            let strength = power.max_channel() / start_strength;
            if !(strength > 0.0) {
                break;
            }
            if strength < ROULETTE_BELOW {
                if rng.next_f64() >= strength {
                    break;
                }
                power *= 1.0 / strength;
            }
            (s, x) = (hit.surface, hit.point);
            d = cosine_direction(&hit_frame, (rng.next_f64(), rng.next_f64()));
        }
        (landings, Rgb::ZERO)
    }
}

#[cfg(test)]
mod tests;
