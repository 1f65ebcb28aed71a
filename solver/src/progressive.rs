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
use serde::Serialize;

use crate::coupling::{Coupler, FormFactorMethod, PatchCoupling};
use crate::direct::DirectLight;
use crate::elements::{Discretization, Patch};
use crate::error::SolveError;
use crate::lambert::ReceivingPoint;
pub(crate) use crate::progress::Interrupt;
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
    /// Seeds every random stream of the solve (visibility rays, Monte Carlo samples).
    pub seed: u64,
    /// Memory allowed for caching vertex–patch form factors, in bytes.
    pub cache_bytes: usize,
    /// Stop shooting at this moment, converged or not (an anytime solve).
    pub deadline: Option<Instant>,
    /// Stop shooting as soon as this is set (from a signal handler: Ctrl-C), keeping the
    /// solution so far.
    pub interrupt: Option<Interrupt>,
    /// How vertex-to-patch form factors are computed.
    pub form_factors: FormFactorMethod,
    /// The hierarchical solver's link tolerance: the light a link may carry wrongly, as a
    /// fraction of the light the surfaces reflect of the direct light.
    pub link_tol: f64,
    /// The photon-map solver's photons, estimates and final gather.
    pub photon_map: crate::photon_map::PhotonMapOptions,
}

/// The default of [`SolverOptions::epsilon`].
pub const DEFAULT_EPSILON: f64 = 1e-3;

/// Most visibility rays per vertex–patch pair: stratified rays then resolve a visibility
/// fraction to about 1/4096, beyond what the form factors' other errors allow; more only makes a
/// run look hung.
pub(crate) const MAX_VISIBILITY_RAYS: usize = 4096;

/// Most Monte Carlo samples per vertex–patch pair, for the same reason.
pub(crate) const MAX_FORM_FACTOR_SAMPLES: usize = 65_536;

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
            interrupt: None,
            form_factors: FormFactorMethod::Analytic,
            link_tol: crate::hierarchical::DEFAULT_LINK_TOL,
            photon_map: crate::photon_map::PhotonMapOptions::default(),
        }
    }
}

impl SolverOptions {
    /// Whether long work must stop now, and why: an interrupt, or the deadline passed.
    pub fn stop_now(&self) -> Option<StopReason> {
        if self.interrupt.as_ref().is_some_and(Interrupt::is_set) {
            return Some(StopReason::Interrupted);
        }
        if self.deadline.is_some_and(|d| Instant::now() >= d) {
            return Some(StopReason::TimeBudget);
        }
        None
    }

    /// Checks every field's range; the error names the option in words.
    pub fn validate(&self) -> Result<(), SolveError> {
        let bad = |option: &'static str, reason: &'static str| {
            Err(SolveError::InvalidOption { option, reason })
        };
        if !(self.epsilon > 0.0 && self.epsilon < 1.0) {
            return bad("epsilon", "must be in (0, 1)");
        }
        if !(self.link_tol > 0.0 && self.link_tol < 1.0) {
            return bad("link tolerance", "must be in (0, 1)");
        }
        let photons = &self.photon_map;
        if !(1..=crate::photon_map::MAX_PHOTONS).contains(&photons.photons) {
            return bad("photons", "must be from 1 to 200,000,000");
        }
        if !(1..=crate::photon_map::MAX_GATHER_PHOTONS).contains(&photons.gather_photons) {
            return bad("gather photons", "must be from 1 to 100,000");
        }
        if photons.final_gather > MAX_FORM_FACTOR_SAMPLES {
            return bad("final gather", "must be from 0 to 65,536 rays");
        }
        if !(1..=MAX_VISIBILITY_RAYS).contains(&self.visibility_rays) {
            return bad("visibility rays", "must be from 1 to 4096");
        }
        if self.elements_per_patch == 0 {
            return bad("elements per patch", "must be at least 1");
        }
        if let FormFactorMethod::MonteCarlo { samples } = self.form_factors
            && !(1..=MAX_FORM_FACTOR_SAMPLES).contains(&samples)
        {
            return bad("form-factor samples", "must be from 1 to 65536");
        }
        if let FormFactorMethod::Hemicube { resolution } = self.form_factors {
            crate::hemicube::Hemicube::new(resolution)?;
        }
        Ok(())
    }
}

/// Why the solver stopped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// Unshot power fell below epsilon of the emitted power.
    #[default]
    Converged,
    /// The shot cap was reached first.
    ShotLimit,
    /// Direct light only: one exact bounce, nothing to iterate.
    DirectOnly,
    /// The time budget ran out: the solution is the best so far.
    TimeBudget,
    /// The run was interrupted (Ctrl-C, SIGTERM): the solution is the best so far.
    Interrupted,
}

/// Figures of a solve. Powers are in W per channel (radiosity times area in scene units).
#[derive(Clone, Debug, Default, Serialize)]
pub struct SolveStats {
    /// Why the solver stopped.
    pub stop: StopReason,
    /// Patches shot (progressive refinement).
    pub shots: usize,
    /// Patches of the discretization.
    pub patches: usize,
    /// Receivers (mesh vertices) of the discretization.
    pub receivers: usize,
    /// Visibility rays cast.
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
    /// Unshot power over emitted power (channel means; patch by patch in absolute value, since
    /// after a remesh a patch may owe negative power).
    pub unshot_fraction: f64,
    /// Seconds spent on the direct light.
    pub direct_seconds: f64,
    /// Vertices whose direct light was estimated by rays, not computed exactly: the deadline
    /// came first, or (`direct_beyond_cap` of them) their view of a light needed a polygon
    /// difference beyond the evaluator's cap.
    pub direct_estimated: usize,
    /// See `direct_estimated`.
    pub direct_beyond_cap: usize,
    /// Seconds spent shooting (or gathering, or solving the system).
    pub shooting_seconds: f64,
    /// Iterations of the solver (shots for progressive refinement, sweeps for gathering) and
    /// its final residual relative to the light put in: the unshot fraction for progressive
    /// refinement, ‖c + K B − B‖ / ‖c‖ for gathering and direct solves.
    pub iterations: usize,
    /// See `iterations`.
    pub residual: f64,
    /// Times the mesh was replaced by a refined one, and the vertices that then gathered the
    /// light shot so far.
    pub remeshes: usize,
    /// See `remeshes`.
    pub gathered: usize,
    /// Seconds those vertices spent gathering.
    pub gather_seconds: f64,
    /// The hierarchical solver's own figures.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hierarchy: Option<crate::hierarchical::HierarchyStats>,
    /// Whether every vertex lies inside a room, so that no light can leave the scene (see
    /// `Enclosures`); `None` where the solver does not find out.
    pub closed: Option<bool>,
    /// The photon-map solver's figures: photons emitted and stored, the map's memory.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub photon_map: Option<crate::photon_map::PhotonStats>,
}

/// One step of a solver: its residual relative to the light put in (for progressive refinement
/// the unshot fraction, for gathering ‖c + K B̄ − B̄‖ / ‖c‖) and the seconds since it began.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ConvergencePoint {
    /// Steps done (0: the start, before any).
    pub iteration: usize,
    /// The residual after it.
    pub residual: f64,
    /// Seconds since the solver began.
    pub seconds: f64,
}

/// Radiosity and irradiance at every mesh vertex, per surface.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Radiosity B at each vertex, per surface (W/m² per channel).
    pub radiosity: Vec<Vec<Rgb>>,
    /// Irradiance H at each vertex, per surface: B = E + ρ H.
    pub irradiance: Vec<Vec<Rgb>>,
    /// The part of `irradiance` that comes straight from the emitters, per surface: exact by
    /// backprojection (or estimated by rays where [`SolveStats::direct_estimated`] says so).
    /// The reflected light's part is `irradiance - direct_irradiance`.
    pub direct_irradiance: Vec<Vec<Rgb>>,
    /// Cohen et al.'s ambient term for display: an estimate of the light not yet shot, spread
    /// evenly. Never part of the radiosity.
    pub ambient: Rgb,
    /// Figures of the solve.
    pub stats: SolveStats,
    /// The residual after each iteration (each shot, each sweep).
    pub convergence: Vec<ConvergencePoint>,
}

/// Direct irradiance at every vertex from the exact evaluator, and how many vertices were
/// estimated by rays because their view of a light needed a polygon difference beyond the
/// evaluator's cap; stops early, with [`SolveError::Interrupted`], once `options.interrupt` is
/// set.
pub(crate) fn direct_irradiance(
    scene: &Scene,
    disc: &Discretization,
    visibility: &Visibility,
    options: &SolverOptions,
    progress: &dyn Progress,
) -> Result<(Vec<Rgb>, usize), SolveError> {
    let direct = DirectLight::new(scene, visibility).with_overlay_cap(OVERLAY_CAP);
    let limits = Limits {
        interrupt: options.interrupt.as_ref(),
        deadline: None,
        rays: options.visibility_rays,
    };
    let (values, estimated) = direct_on(&direct, disc, None, &limits, progress)?;
    Ok((values, estimated.beyond_cap))
}

/// The direct irradiance at the vertices of the surfaces `on` marks (all when `None`; the others
/// get zero), and how many vertices were estimated by rays instead. Each value is the one
/// computed when every vertex is lit, to the bit: where vertices of several surfaces share a
/// point and one evaluation, that evaluation is made for them all (see [`direct_at`]).
fn direct_on(
    direct: &DirectLight,
    disc: &Discretization,
    on: Option<&[bool]>,
    limits: &Limits,
    progress: &dyn Progress,
) -> Result<(Vec<Rgb>, Estimated), SolveError> {
    let all: Vec<usize> = (0..disc.receiver_count()).collect();
    let lit =
        |v: usize| on.is_none_or(|on| on.get(disc.receiver_surface[v]).copied().unwrap_or(false));
    // What the mesh measured is not evaluated again.
    let wanted = |v: usize| lit(v) && disc.measured_direct[v].is_none();
    let (mut values, estimated) = direct_at(direct, disc, &all, &wanted, limits, progress)?;
    for (v, h) in values.iter_mut().enumerate() {
        *h = match disc.measured_direct[v] {
            _ if !lit(v) => Rgb::ZERO,
            Some(known) => known,
            None => *h,
        };
    }
    Ok((values, estimated))
}

/// When the exact direct light must stop: at an interrupt (an error: no solution yet), or at a
/// deadline, after which the vertices not done yet are estimated with `rays` rays per emitter.
pub(crate) struct Limits<'o> {
    pub interrupt: Option<&'o Interrupt>,
    pub deadline: Option<Instant>,
    pub rays: usize,
}

/// Receivers closer than this fraction of the scene's diagonal share one evaluation of what
/// their light's occluders hide: the meshes of faces meeting at a vertex put their vertices
/// there a few ulps apart, and the light seen from points that close differs by as little.
pub const SHARED_POINT: f64 = 1e-12;

/// Edges one polygon difference of the direct light may hold; points that would need more get
/// the estimate by rays, and the report counts them. The overlay's cost grows with the
/// crossings of its edges, which the edges bound only by their square: a light seen through a
/// lattice of beams and rods crosses each new batch of shadows with the many holes left so far
/// (with 2^15 edges, one Sponza vertex took minutes and gigabytes in a single overlay).
pub const OVERLAY_CAP: usize = 1 << 13;

/// The exact direct irradiance at the `receivers` that `wanted` accepts (the others get zero),
/// computed once per point for receivers that share one (faces of a mesh meeting at a vertex;
/// see [`DirectLight::irradiance_group`]). Points within [`SHARED_POINT`] of the scene are one:
/// the view from the grid point they round to serves them all, so a receiver's value does not
/// depend on which others share its point, or are wanted.
pub(crate) fn direct_at(
    direct: &DirectLight,
    disc: &Discretization,
    receivers: &[usize],
    wanted: &(dyn Fn(usize) -> bool + Sync),
    limits: &Limits,
    progress: &dyn Progress,
) -> Result<(Vec<Rgb>, Estimated), SolveError> {
    // Groups in order of first appearance, so the work and its result do not depend on hashing.
    // Each group: the grid point its receivers round to, and the receivers.
    let mut groups: Vec<(DVec3, Vec<usize>)> = Vec::new();
    let mut at_point: HashMap<[i64; 3], usize> = HashMap::new();
    let quantum = SHARED_POINT * direct.scene_diagonal();
    let gridded = quantum > 0.0 && quantum.is_finite();
    for (i, &v) in receivers.iter().enumerate() {
        if !wanted(v) {
            continue;
        }
        let p = disc.receivers[v].point;
        let (key, at) = if gridded {
            let q = (p / quantum).round();
            ([q.x as i64, q.y as i64, q.z as i64], q * quantum)
        } else {
            (
                [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()].map(|b| b as i64),
                p,
            )
        };
        let g = *at_point.entry(key).or_insert_with(|| {
            groups.push((at, Vec::new()));
            groups.len() - 1
        });
        groups[g].1.push(i);
    }
    let members = |g: &[usize]| -> Vec<(ReceivingPoint, SurfaceId)> {
        g.iter()
            .map(|&i| {
                let v = receivers[i];
                (disc.receivers[v], disc.receiver_surface[v])
            })
            .collect()
    };
    let late = || limits.deadline.is_some_and(|d| Instant::now() >= d);
    let exact = par_map_with_progress(&groups, "direct light", limits.interrupt, progress, |g| {
        (!late()).then(|| direct.irradiance_group(g.0, &members(&g.1)))
    })?;
    // A point whose view of a light is beyond the overlay cap gets NaN: estimated, like the
    // points left at the deadline.
    let too_complex = |values: &Option<Vec<Rgb>>| {
        values.as_ref().is_some_and(|v| {
            v.iter()
                .any(|h| !(h.r.is_finite() && h.g.is_finite() && h.b.is_finite()))
        })
    };
    // Past the deadline, the evaluator also gives up on the points still in progress.
    let beyond_cap = if late() {
        0
    } else {
        (0..groups.len())
            .filter(|&g| too_complex(&exact[g]))
            .map(|g| groups[g].1.len())
            .sum()
    };
    let exact: Vec<Option<Vec<Rgb>>> = exact
        .into_iter()
        .map(|values| if too_complex(&values) { None } else { values })
        .collect();
    // What is left is estimated (quickly, and whatever the clock says, so every vertex has a
    // value).
    let left: Vec<usize> = (0..groups.len()).filter(|&g| exact[g].is_none()).collect();
    let estimates =
        par_map_with_progress(&left, "direct light, estimated", None, progress, |&g| {
            members(&groups[g].1)
                .iter()
                .map(|(x, r)| direct.irradiance_sampled(x, *r, limits.rays))
                .collect::<Vec<Rgb>>()
        })?;
    let estimated: usize = left.iter().map(|&g| groups[g].1.len()).sum();
    let mut estimates = estimates.into_iter();
    let mut out = vec![Rgb::ZERO; receivers.len()];
    for ((_, g), exact) in groups.iter().zip(exact) {
        let values = exact.or_else(|| estimates.next()).unwrap_or_default();
        for (&i, h) in g.iter().zip(values) {
            out[i] = h;
        }
    }
    Ok((
        out,
        Estimated {
            late: estimated - beyond_cap,
            beyond_cap,
        },
    ))
}

/// The exact direct light at the new vertices `fresh` of a refined mesh, run to its end: the
/// refinement loop checks for interrupts between rounds, and stopping here would lose the
/// solution it has.
pub(crate) fn direct_at_new(
    direct: &DirectLight,
    disc: &Discretization,
    fresh: &[usize],
    options: &SolverOptions,
    progress: &dyn Progress,
) -> Result<Vec<Rgb>, SolveError> {
    let limits = Limits {
        interrupt: None,
        deadline: None,
        rays: options.visibility_rays,
    };
    Ok(direct_at(direct, disc, fresh, &|_| true, &limits, progress)?.0)
}

/// Vertices whose direct light was estimated by rays: left at the deadline, or whose view of a
/// light was beyond the overlay cap.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Estimated {
    pub late: usize,
    pub beyond_cap: usize,
}

/// `f` at each of `receivers`, in parallel, with a progress bar; stops early, with
/// [`SolveError::Interrupted`], once `interrupt` is set.
fn irradiance_at(
    receivers: &[usize],
    stage: &str,
    interrupt: Option<&Interrupt>,
    progress: &dyn Progress,
    f: impl Fn(usize) -> Rgb + Sync,
) -> Result<Vec<Rgb>, SolveError> {
    par_map_with_progress(receivers, stage, interrupt, progress, |&v| f(v))
}

/// `f` of each item, in parallel and in order, with a progress bar; stops early, with
/// [`SolveError::Interrupted`], once `interrupt` is set.
fn par_map_with_progress<T: Sync, U: Send + Default>(
    items: &[T],
    stage: &str,
    interrupt: Option<&Interrupt>,
    progress: &dyn Progress,
    f: impl Fn(&T) -> U + Sync,
) -> Result<Vec<U>, SolveError> {
    let interrupted = || interrupt.is_some_and(Interrupt::is_set);
    progress.start(stage, items.len() as u64);
    let done = std::sync::atomic::AtomicU64::new(0);
    let out = items
        .par_iter()
        .map(|item| {
            if interrupted() {
                return U::default();
            }
            let h = f(item);
            let d = done.fetch_add(1, Ordering::Relaxed);
            if d.is_multiple_of(256) {
                progress.set(d);
            }
            h
        })
        .collect();
    progress.finish();
    if interrupted() {
        return Err(SolveError::Interrupted);
    }
    Ok(out)
}

/// The ambient term of a solution that left `unshot` power unshot: spread over `area` and
/// reflected on without end at the mean reflectance.
pub fn ambient_term(unshot: Rgb, area: f64, mean_reflectance: Rgb) -> Rgb {
    (unshot / area).mul_rgb(mean_reflectance.map(|r| 1.0 / (1.0 - r)))
}

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
            option: "direct only",
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
                option: "form factors",
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

pub(crate) fn check_mesh(scene: &Scene, mesh: &SceneMesh) -> Result<(), SolveError> {
    if mesh.surfaces.len() != scene.surfaces.len()
        || mesh
            .surfaces
            .iter()
            .enumerate()
            .any(|(s, m)| m.surface != s)
    {
        return Err(SolveError::MeshMismatch {
            surfaces: scene.surfaces.len(),
            meshes: mesh.surfaces.len(),
        });
    }
    Ok(())
}
