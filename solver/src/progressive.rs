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
//! The solver can be fed a refined mesh without restarting ([`ProgressiveSolver::remesh`], as in
//! Cohen et al.'s patches and elements): it keeps every patch that has shot, with the radiosity it
//! shot, and a new vertex gathers from all of them, so its value is consistent with the solution
//! so far; what each element has shot is carried over by area, so no power is lost or made.
//!
//! Results do not depend on the thread count: receivers are evaluated in parallel, but every
//! sum is taken in a fixed order.

use std::collections::HashMap;
use std::sync::atomic::Ordering;
use std::time::Instant;

use glam::DVec3;
use penumbra_meshing::{SceneMesh, SurfaceMesh, TriangleLocator, transfer_density};
use penumbra_scenes::{Rgb, Scene, SurfaceId, Visibility};
use rayon::prelude::*;

use crate::coupling::{Coupler, PatchCoupling};
use crate::direct::DirectLight;
use crate::direct_pass::{
    Estimated, Limits, OVERLAY_CAP, check_mesh, direct_at_new, direct_on, irradiance_at,
};
use crate::elements::{Discretization, Patch};
use crate::error::SolveError;
use crate::lambert::ReceivingPoint;
use crate::option_id::OptionId;
use crate::options::SolverOptions;
use crate::progress::Progress;
use crate::solution::{ConvergencePoint, Solution, SolveStats, StopReason, ambient_term};

/// Solves a meshed scene by progressive refinement.
pub fn solve_progressive(
    scene: &Scene,
    mesh: &SceneMesh,
    visibility: &Visibility,
    options: &SolverOptions,
    progress: &dyn Progress,
) -> Result<Solution, SolveError> {
    let mut solver = ProgressiveSolver::new(scene, mesh, visibility, options, progress)?;
    solver.shoot(options.epsilon, progress);
    Ok(solver.solution())
}

/// The direct light only (`options.direct_only` must be set), at the vertices of the surfaces
/// `on` marks; the other surfaces' vertices get their emission alone. The values on the marked
/// surfaces are those of [`solve_progressive`] on the same mesh, to the bit; the statistics
/// (absorbed and received power) count the marked surfaces only.
pub fn solve_direct_on(
    scene: &Scene,
    mesh: &SceneMesh,
    visibility: &Visibility,
    options: &SolverOptions,
    on: &[bool],
    progress: &dyn Progress,
) -> Result<Solution, SolveError> {
    if !options.direct_only {
        return Err(SolveError::InvalidOption {
            option: OptionId::DirectOnly,
            reason: "the light of some surfaces alone is exact only without interreflection",
        });
    }
    let solver = ProgressiveSolver::new_on(scene, mesh, visibility, options, Some(on), progress)?;
    Ok(solver.solution())
}

/// A patch that has shot: its geometry, kept after the mesh changes, and the radiosity it shot.
#[derive(Clone, Debug)]
struct Shooter {
    patch: Patch,
    radiosity: Rgb,
    /// Seeds its random streams: the patch's index in its mesh, and that mesh's generation, so a
    /// solve that never remeshes samples exactly what [`crate::coupling::PatchCoupling`] does.
    key: u64,
}

/// Progressive refinement as a process: shoot, look at the solution, refine the mesh, shoot on.
#[derive(Debug)]
pub struct ProgressiveSolver<'a> {
    scene: &'a Scene,
    visibility: &'a Visibility,
    direct: DirectLight<'a>,
    /// Vertices whose direct light was estimated ([`SolveStats::direct_estimated`]).
    direct_estimated: Estimated,
    options: SolverOptions,
    /// The surface meshes the state below belongs to.
    meshes: Vec<SurfaceMesh>,
    disc: Discretization,
    direct_irradiance: Vec<Rgb>,
    irradiance: Vec<Rgb>,
    /// Per element: the reflected radiosity its area has shot so far (its patch's shots).
    element_shot: Vec<Rgb>,
    shooters: Vec<Shooter>,
    /// Per patch of the current discretization: its shooter, once it has shot.
    patch_shooter: Vec<Option<usize>>,
    cache: HashMap<usize, Vec<f32>>,
    /// Every patch's column at once, for methods that give rows (the hemicube).
    columns: Option<crate::coupling::Columns>,
    shot_power: Rgb,
    escaped: Rgb,
    /// Whether every vertex lies inside a room (nothing may escape).
    closed: bool,
    stop: StopReason,
    shots: usize,
    convergence: Vec<ConvergencePoint>,
    rays_cast: u64,
    remeshes: usize,
    gathered: usize,
    direct_seconds: f64,
    shooting_seconds: f64,
    gather_seconds: f64,
}

impl<'a> ProgressiveSolver<'a> {
    /// Meshes are checked against the scene and the direct light is solved at every vertex.
    pub fn new(
        scene: &'a Scene,
        mesh: &SceneMesh,
        visibility: &'a Visibility,
        options: &SolverOptions,
        progress: &dyn Progress,
    ) -> Result<ProgressiveSolver<'a>, SolveError> {
        Self::new_on(scene, mesh, visibility, options, None, progress)
    }

    /// [`Self::new`], with the direct light at the vertices of the surfaces `on` marks only
    /// (see [`direct_on`]).
    fn new_on(
        scene: &'a Scene,
        mesh: &SceneMesh,
        visibility: &'a Visibility,
        options: &SolverOptions,
        on: Option<&[bool]>,
        progress: &dyn Progress,
    ) -> Result<ProgressiveSolver<'a>, SolveError> {
        options.validate()?;
        check_mesh(scene, mesh)?;
        let disc = Discretization::new(scene, mesh, options.elements_per_patch);
        let started = Instant::now();
        let direct = DirectLight::new(scene, visibility)
            .with_overlay_cap(OVERLAY_CAP)
            .with_deadline(options.deadline);
        let limits = Limits {
            interrupt: options.interrupt.as_ref(),
            deadline: options.deadline,
            rays: options.visibility_rays,
        };
        let (direct_irradiance, direct_estimated) =
            direct_on(&direct, &disc, on, &limits, progress)?;
        let direct_seconds = started.elapsed().as_secs_f64();
        let received = disc.integrate(&direct_irradiance, |_| Rgb::splat(1.0));
        // Methods that give whole rows compute every form factor up front.
        let columns = if options.form_factors.by_rows() && !options.direct_only {
            Some(
                PatchCoupling::new(&disc, visibility, options)
                    .columns(progress)?
                    .0,
            )
        } else {
            None
        };
        let closed = crate::solids::closed_scene(scene, visibility, &disc);
        Ok(ProgressiveSolver {
            scene,
            visibility,
            direct,
            direct_estimated,
            options: options.clone(),
            meshes: mesh.surfaces.clone(),
            element_shot: vec![Rgb::ZERO; disc.elements.len()],
            patch_shooter: vec![None; disc.patches.len()],
            irradiance: direct_irradiance.clone(),
            direct_irradiance,
            disc,
            shooters: Vec::new(),
            cache: HashMap::new(),
            columns,
            shot_power: Rgb::ZERO,
            escaped: scene.emitted_power() - received,
            closed,
            stop: if direct_estimated.late > 0 {
                StopReason::TimeBudget
            } else if options.direct_only {
                StopReason::DirectOnly
            } else {
                StopReason::ShotLimit
            },
            shots: 0,
            convergence: Vec::new(),
            rays_cast: 0,
            remeshes: 0,
            gathered: 0,
            direct_seconds,
            shooting_seconds: 0.0,
            gather_seconds: 0.0,
        })
    }

    fn coupler(&self) -> Coupler<'a> {
        Coupler {
            visibility: self.visibility,
            rays: self.options.visibility_rays,
            seed: self.options.seed,
            method: self.options.form_factors,
        }
    }

    /// Unshot reflected radiosity of every element: what it reflects (the mean of its vertices'
    /// irradiance times ρ) less what its area has shot.
    fn element_unshot(&self) -> Vec<Rgb> {
        self.disc
            .elements
            .iter()
            .zip(&self.element_shot)
            .map(|(e, &shot)| {
                let rho = self.scene.surfaces[e.surface].reflectance;
                e.vertices
                    .iter()
                    .map(|&v| self.irradiance[v])
                    .sum::<Rgb>()
                    .mul_rgb(rho)
                    / 3.0
                    - shot
            })
            .collect()
    }

    /// Unshot power of every patch: Σ area × unshot radiosity of its elements.
    fn patch_unshot_power(&self) -> Vec<Rgb> {
        let unshot = self.element_unshot();
        self.disc
            .patches
            .iter()
            .map(|p| {
                p.elements
                    .iter()
                    .map(|&e| unshot[e] * self.disc.elements[e].area)
                    .sum()
            })
            .collect()
    }

    /// Shoots until the unshot power is below `epsilon` of the emitted power, the shot cap or
    /// the deadline; returns why it stopped.
    pub fn shoot(&mut self, epsilon: f64, progress: &dyn Progress) -> StopReason {
        if self.options.direct_only {
            return StopReason::DirectOnly;
        }
        let started = Instant::now();
        let n = self.disc.receiver_count();
        let cache_limit = self.options.cache_bytes / (4 * n.max(1));
        let emitted_mean = self.scene.emitted_power().mean().max(f64::MIN_POSITIVE);
        let goal = -epsilon.log10();
        progress.start("shooting", 1000);
        self.stop = loop {
            let patch_power = self.patch_unshot_power();
            let fraction = unshot_magnitude(&patch_power) / emitted_mean;
            self.convergence.push(ConvergencePoint {
                iteration: self.shots,
                residual: fraction,
                seconds: self.shooting_seconds + started.elapsed().as_secs_f64(),
            });
            progress.set(((-fraction.max(1e-300).log10() / goal).clamp(0.0, 1.0) * 1000.0) as u64);
            if fraction < epsilon {
                break StopReason::Converged;
            }
            if self.shots >= self.options.max_shots {
                break StopReason::ShotLimit;
            }
            if let Some(reason) = self.options.stop_now() {
                break reason;
            }
            // The patch with the most unshot power (ties: the lowest index). After a remesh a
            // patch may have shot more than its finer elements now reflect: it shoots the
            // negative difference back, so that the light shot matches the light reflected.
            let Some((p, power)) = patch_power
                .iter()
                .enumerate()
                .max_by(|a, b| {
                    magnitude(*a.1)
                        .total_cmp(&magnitude(*b.1))
                        .then(b.0.cmp(&a.0))
                })
                .map(|(p, &w)| (p, w))
            else {
                break StopReason::Converged;
            };
            let k = match self.patch_shooter[p] {
                Some(k) => k,
                None => {
                    self.shooters.push(Shooter {
                        patch: self.disc.patches[p].clone(),
                        radiosity: Rgb::ZERO,
                        key: (self.remeshes as u64) << 32 | p as u64,
                    });
                    self.patch_shooter[p] = Some(self.shooters.len() - 1);
                    self.shooters.len() - 1
                }
            };
            let shot_radiosity = power / self.disc.patches[p].area;
            let column = self.column(p, k, cache_limit);
            let delta: Vec<Rgb> = column.iter().map(|&f| shot_radiosity * f as f64).collect();
            for (h, d) in self.irradiance.iter_mut().zip(&delta) {
                *h += *d;
            }
            for &e in &self.disc.patches[p].elements {
                self.element_shot[e] += shot_radiosity;
            }
            self.shooters[k].radiosity += shot_radiosity;
            self.shot_power += power;
            self.escaped += power - self.disc.integrate(&delta, |_| Rgb::splat(1.0));
            self.shots += 1;
        };
        progress.finish();
        self.shooting_seconds += started.elapsed().as_secs_f64();
        self.stop
    }

    /// Patch `p`'s form factors to every vertex (`k` is its shooter), from the cache when they
    /// are there.
    fn column(&mut self, p: usize, k: usize, cache_limit: usize) -> Vec<f32> {
        if let Some(c) = self.cache.get(&p) {
            return c.clone();
        }
        let n = self.disc.receiver_count();
        if self.options.form_factors.by_rows() {
            // Filled by `new` for these methods.
            let columns = self.columns.as_deref().unwrap_or_default();
            let mut column = vec![0.0; n];
            for &(v, f) in columns.get(p).map_or(&[][..], Vec::as_slice) {
                column[v as usize] = f;
            }
            return column;
        }
        let coupler = self.coupler();
        let disc = &self.disc;
        let patch = &disc.patches[p];
        let computed: Vec<(f32, u32)> = (0..n)
            .into_par_iter()
            .map(|v| {
                let (f, r) = coupler.coupling(
                    &disc.receivers[v],
                    disc.receiver_surface[v],
                    patch,
                    [v as u64, self.shooters[k].key],
                );
                (f as f32, r)
            })
            .collect();
        self.rays_cast += computed.iter().map(|&(_, r)| r as u64).sum::<u64>();
        let column: Vec<f32> = computed.into_iter().map(|(f, _)| f).collect();
        if self.cache.len() < cache_limit {
            self.cache.insert(p, column.clone());
        }
        column
    }

    /// Irradiance at `x` (on `surface`) from everything shot so far, less the direct light.
    fn gather(&self, x: &ReceivingPoint, surface: SurfaceId, key: u64) -> (Rgb, u64) {
        let coupler = self.coupler();
        let mut rays = 0u64;
        let h = self
            .shooters
            .iter()
            .map(|s| {
                let (f, r) = coupler.coupling(x, surface, &s.patch, [key, s.key]);
                rays += r as u64;
                s.radiosity * f
            })
            .sum();
        (h, rays)
    }

    /// Replaces the mesh by a refinement of it (the same surfaces, vertices kept where they
    /// were): vertices already solved keep their values, new ones get the exact direct light
    /// and gather the light shot so far, and what each element has shot is carried over by
    /// area. Shooting then goes on from where it was.
    pub fn remesh(&mut self, mesh: &SceneMesh, progress: &dyn Progress) -> Result<(), SolveError> {
        check_mesh(self.scene, mesh)?;
        if self.options.form_factors.by_rows() {
            // New vertices gather from shooters of older meshes, one pair at a time.
            return Err(SolveError::InvalidOption {
                option: OptionId::FormFactors,
                reason: "the hemicube gives the rows of a fixed mesh; refining needs analytic or monte-carlo",
            });
        }
        let disc = Discretization::new(self.scene, mesh, self.options.elements_per_patch);

        // What each element has shot, as a density over its surface, moved to the new triangles.
        let mut per_triangle: Vec<Vec<Rgb>> = self
            .meshes
            .iter()
            .map(|m| vec![Rgb::ZERO; m.triangle_count()])
            .collect();
        for (e, &shot) in self.disc.elements.iter().zip(&self.element_shot) {
            per_triangle[e.surface][e.triangle] = shot;
        }
        let moved: Vec<Vec<Rgb>> = mesh
            .surfaces
            .par_iter()
            .map(|new| {
                let old = &self.meshes[new.surface];
                transfer_density(
                    old,
                    &per_triangle[new.surface],
                    &TriangleLocator::new(old),
                    new,
                )
            })
            .collect();
        let element_shot: Vec<Rgb> = disc
            .elements
            .iter()
            .map(|e| moved[e.surface][e.triangle])
            .collect();

        // Vertices that were there before keep their values.
        let matching = disc.matching_receivers(&self.disc);
        let (mut direct, mut irradiance, fresh) = (
            matching.carry(&self.direct_irradiance),
            matching.carry(&self.irradiance),
            matching.fresh(),
        );
        let t = Instant::now();
        let new_direct = direct_at_new(&self.direct, &disc, &fresh, &self.options, progress)?;
        self.direct_seconds += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let rays = std::sync::atomic::AtomicU64::new(0);
        let gathered = if self.shooters.is_empty() {
            vec![Rgb::ZERO; fresh.len()]
        } else {
            irradiance_at(&fresh, "gathering", None, progress, |v| {
                let (h, r) = self.gather(&disc.receivers[v], disc.receiver_surface[v], v as u64);
                rays.fetch_add(r, Ordering::Relaxed);
                h
            })?
        };
        self.gather_seconds += t.elapsed().as_secs_f64();
        self.rays_cast += rays.into_inner();
        for ((&v, d), g) in fresh.iter().zip(new_direct).zip(gathered) {
            direct[v] = d;
            irradiance[v] = d + g;
        }
        self.gathered += fresh.len();

        // Every shot's power either reached a vertex of the new mesh or escaped.
        let received = disc.integrate(&irradiance, |_| Rgb::splat(1.0));
        self.escaped = self.scene.emitted_power() + self.shot_power - received;
        self.patch_shooter = vec![None; disc.patches.len()];
        self.cache.clear();
        self.meshes = mesh.surfaces.clone();
        self.disc = disc;
        self.direct_irradiance = direct;
        self.irradiance = irradiance;
        self.element_shot = element_shot;
        self.remeshes += 1;
        Ok(())
    }

    /// Radiosity at every vertex, per surface: E + ρ H.
    pub fn radiosity(&self) -> Vec<Vec<Rgb>> {
        self.disc.per_surface(&self.radiosity_of(&self.irradiance))
    }

    /// The direct part of the radiosity at every vertex, per surface: E + ρ H_direct.
    pub fn direct_radiosity(&self) -> Vec<Vec<Rgb>> {
        self.disc
            .per_surface(&self.radiosity_of(&self.direct_irradiance))
    }

    fn radiosity_of(&self, h: &[Rgb]) -> Vec<Rgb> {
        (0..self.disc.receiver_count())
            .map(|v| self.disc.emission[v] + self.disc.reflectance[v].mul_rgb(h[v]))
            .collect()
    }

    /// Irradiance at an interior point of `surface` from the patches shot so far (without the
    /// direct light), for error estimates; `key` picks the random stream.
    pub fn indirect_irradiance(&self, point: DVec3, surface: SurfaceId, key: u64) -> Rgb {
        let normal = self.meshes[surface].frame.normal;
        self.gather(&ReceivingPoint::interior(point, normal), surface, key)
            .0
    }

    /// Patch shots so far.
    pub fn shots(&self) -> usize {
        self.shots
    }

    /// The surface meshes the solution lives on.
    pub fn meshes(&self) -> &[SurfaceMesh] {
        &self.meshes
    }

    /// Whether any light has been shot beyond the direct light.
    pub fn has_indirect(&self) -> bool {
        !self.shooters.is_empty()
    }

    /// The exact direct light's evaluator.
    pub fn direct_light(&self) -> &DirectLight<'a> {
        &self.direct
    }

    /// The solution so far.
    pub fn solution(&self) -> Solution {
        let scene = self.scene;
        let disc = &self.disc;
        let patch_power = self.patch_unshot_power();
        let unshot: Rgb = patch_power.iter().copied().sum();
        let residual =
            unshot_magnitude(&patch_power) / scene.emitted_power().mean().max(f64::MIN_POSITIVE);
        let absorbed = disc.integrate(&self.irradiance, |e| {
            Rgb::splat(1.0) - scene.surfaces[e.surface].reflectance
        });
        let total_area: f64 = disc.elements.iter().map(|e| e.area).sum();
        let mean_rho: Rgb = disc
            .elements
            .iter()
            .map(|e| scene.surfaces[e.surface].reflectance * e.area)
            .sum::<Rgb>()
            / total_area;
        let ambient = ambient_term(unshot, total_area, mean_rho);
        let emitted = scene.emitted_power();
        let stats = SolveStats {
            stop: self.stop,
            shots: self.shots,
            patches: disc.patches.len(),
            receivers: disc.receiver_count(),
            rays_cast: self.rays_cast,
            emitted,
            absorbed,
            unshot,
            escaped: self.escaped,
            unshot_fraction: residual,
            iterations: self.shots,
            residual,
            direct_seconds: self.direct_seconds,
            direct_estimated: self.direct_estimated.late + self.direct_estimated.beyond_cap,
            direct_beyond_cap: self.direct_estimated.beyond_cap,
            shooting_seconds: self.shooting_seconds,
            remeshes: self.remeshes,
            gathered: self.gathered,
            gather_seconds: self.gather_seconds,
            hierarchy: None,
            photon_map: None,
            closed: Some(self.closed),
        };
        Solution {
            radiosity: self.radiosity(),
            irradiance: disc.per_surface(&self.irradiance),
            direct_irradiance: disc.per_surface(&self.direct_irradiance),
            ambient,
            stats,
            convergence: self.convergence.clone(),
        }
    }
}

/// Size of a patch's unshot power, whatever its sign: the channels' mean absolute value.
fn magnitude(power: Rgb) -> f64 {
    (power.r.abs() + power.g.abs() + power.b.abs()) / 3.0
}

/// How much power is left to shoot: the sum of the patches' [`magnitude`]s. Before any remesh
/// every patch's unshot power is non-negative and this is the mean of the total.
fn unshot_magnitude(patch_power: &[Rgb]) -> f64 {
    patch_power.iter().map(|&p| magnitude(p)).sum()
}
