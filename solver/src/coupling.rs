//! Vertex-to-patch form factors: the analytic unoccluded value (Lambert's formula over the patch
//! outline) times a visibility fraction estimated with stratified rays (Wallace, Elmquist &
//! Haines 1989).

use std::f64::consts::PI;

use glam::DVec3;

use penumbra_scenes::{SurfaceId, Visibility};

use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

use crate::elements::{Discretization, Patch};
use crate::error::SolveError;
use crate::hemicube::{Hemicube, OCCLUDER};
use crate::lambert::{ReceivingPoint, edge_term, form_factor};
pub use crate::options::FormFactorMethod;
use crate::progress::Interrupt;
use crate::progress::Progress;
use penumbra_scenes::SplitMix64;

/// Form factors from points to patches: Lambert's formula times a visibility fraction, or Monte
/// Carlo over the patch.
#[derive(Clone, Copy, Debug)]
pub struct Coupler<'a> {
    /// The scene's visibility index, for the rays.
    pub visibility: &'a Visibility,
    /// Rays per point–patch pair for the visibility fraction.
    pub rays: usize,
    /// Seeds every pair's own random stream.
    pub seed: u64,
    /// How the form factors are computed.
    pub method: FormFactorMethod,
}

impl Coupler<'_> {
    fn tol(&self) -> f64 {
        self.visibility.contact_distance()
    }

    /// The unoccluded form factor from `x` (on `surface`) to `patch` (zero if either faces away).
    pub fn unoccluded(&self, x: &ReceivingPoint, surface: SurfaceId, patch: &Patch) -> f64 {
        if surface == patch.surface || !x.in_front_of(patch.origin, patch.normal, self.tol()) {
            return 0.0;
        }
        patch_form_factor(x, patch, self.tol())
    }

    /// Whether nothing but the `own` surfaces is in the box around `x` and the patch: then
    /// nothing can block, and no ray need be cast.
    fn open(&self, x: &ReceivingPoint, own: [SurfaceId; 2], patch: &Patch) -> bool {
        let shaft = patch.bounds.including(x.point);
        !self
            .visibility
            .any_triangle_overlapping(shaft, |t| t.surface != own[0] && t.surface != own[1])
    }

    /// Fraction of `patch` visible from `x`, weighted by the form-factor kernel, and the number
    /// of rays cast for it. `key` seeds the pair's own random stream.
    pub fn visible_fraction(
        &self,
        x: &ReceivingPoint,
        surface: SurfaceId,
        patch: &Patch,
        key: [u64; 2],
    ) -> (f64, u32) {
        let own = [surface, patch.surface];
        if self.open(x, own, patch) {
            return (1.0, 0);
        }
        // Rays leave from just inside the receiving surface, so that a vertex on a junction sees
        // past (not along) the surfaces it touches: the one-sided limit again.
        let origin = x.point + x.inward * self.visibility.junction_offset();
        let mut rng = SplitMix64::keyed(self.seed, &key);
        let (mut seen, mut weight, mut count) = (0.0, 0.0, 0u32);
        // Samples that face away (behind x's tangent plane, or behind the patch) carry no weight
        // and cast no ray; a patch straddling x's plane may need a few more draws.
        let mut draws = 0;
        while count < self.rays as u32 && draws < 4 * self.rays {
            let y = sample_patch(patch, draws % self.rays, self.rays, &mut rng);
            draws += 1;
            let w = kernel(x, origin, patch, y);
            if !(w > 0.0) {
                continue;
            }
            count += 1;
            weight += w;
            if !self.visibility.occluded(origin, y, own) {
                seen += w;
            }
        }
        // No sample in front: the part of the patch x sees is too small to hit; take it as open.
        let fraction = if weight > 0.0 { seen / weight } else { 1.0 };
        (fraction, count)
    }

    /// Form factor times visibility, and the rays it took.
    pub fn coupling(
        &self,
        x: &ReceivingPoint,
        surface: SurfaceId,
        patch: &Patch,
        key: [u64; 2],
    ) -> (f64, u32) {
        if let FormFactorMethod::MonteCarlo { samples } = self.method {
            // A point on the patch's plane (a junction: the edge where a wall meets the floor)
            // sees the patch at grazing incidence, and its form factor, a one-sided limit, sits
            // in a vanishing neighbourhood of the point that no sample finds (half of a wall,
            // missed entirely). Lambert's formula takes the limit there.
            let on_plane = (x.point - patch.origin).dot(patch.normal).abs() <= self.tol();
            if !on_plane {
                return self.monte_carlo(x, surface, patch, key, samples);
            }
        }
        let f = self.unoccluded(x, surface, patch);
        if f <= 0.0 {
            return (0.0, 0);
        }
        let (vis, rays) = self.visible_fraction(x, surface, patch, key);
        (f * vis, rays)
    }
}

impl Coupler<'_> {
    /// The form factor by Monte Carlo: the kernel cos cos / (π r²) at `samples` points stratified
    /// over the patch's area, each counted if a ray reaches it.
    fn monte_carlo(
        &self,
        x: &ReceivingPoint,
        surface: SurfaceId,
        patch: &Patch,
        key: [u64; 2],
        samples: usize,
    ) -> (f64, u32) {
        if surface == patch.surface || !x.in_front_of(patch.origin, patch.normal, self.tol()) {
            return (0.0, 0);
        }
        let own = [surface, patch.surface];
        let open = self.open(x, own, patch);
        let origin = x.point + x.inward * self.visibility.junction_offset();
        let mut rng = SplitMix64::keyed(self.seed, &key);
        let (mut sum, mut rays) = (0.0, 0u32);
        let samples = samples.max(1);
        for k in 0..samples {
            let y = sample_patch(patch, k, samples, &mut rng);
            let w = kernel(x, origin, patch, y);
            if !(w > 0.0) {
                continue;
            }
            if open {
                sum += w;
                continue;
            }
            rays += 1;
            if !self.visibility.occluded(origin, y, own) {
                sum += w;
            }
        }
        (sum * patch.area / (PI * samples as f64), rays)
    }
}

/// A point of `patch` in stratum `k` of `strata` (equal shares of its area), uniform inside the
/// element the stratum's draw falls in.
fn sample_patch(patch: &Patch, k: usize, strata: usize, rng: &mut SplitMix64) -> DVec3 {
    let u = (k as f64 + rng.next_f64()) / strata as f64 * patch.area;
    let idx = patch
        .cumulative_area
        .partition_point(|&c| c < u)
        .min(patch.triangles.len() - 1);
    let t = &patch.triangles[idx];
    let (r1, r2) = (rng.next_f64().sqrt(), rng.next_f64());
    t[0] * (1.0 - r1) + t[1] * (r1 * (1.0 - r2)) + t[2] * (r1 * r2)
}

/// cos θ_x cos θ_y / r² from `x` (rays leaving from `origin`) to the point `y` of `patch`;
/// not positive where either faces away.
fn kernel(x: &ReceivingPoint, origin: DVec3, patch: &Patch, y: DVec3) -> f64 {
    let d = y - origin;
    x.normal.dot(d) * -patch.normal.dot(d) / d.length_squared().powi(2)
}

/// Per patch, the receivers that see it and their form factors.
pub type Columns = Vec<Vec<(u32, f32)>>;

/// Form factors from the receivers (mesh vertices) of a discretization to its patches.
#[derive(Debug)]
pub struct PatchCoupling<'a> {
    /// The receivers and patches.
    pub disc: &'a Discretization,
    /// The scene's visibility index.
    pub visibility: &'a Visibility,
    /// Rays per vertex–patch pair for the visibility fraction.
    pub rays: usize,
    /// Seeds every pair's own random stream.
    pub seed: u64,
    /// How the form factors are computed.
    pub method: FormFactorMethod,
    /// Computing columns stops early, with [`SolveError::Interrupted`], once this is set.
    pub interrupt: Option<Interrupt>,
}

impl<'a> PatchCoupling<'a> {
    /// The coupling a solve with `options` uses.
    pub fn new(
        disc: &'a Discretization,
        visibility: &'a Visibility,
        options: &crate::options::SolverOptions,
    ) -> PatchCoupling<'a> {
        PatchCoupling {
            disc,
            visibility,
            rays: options.visibility_rays,
            seed: options.seed,
            method: options.form_factors,
            interrupt: options.interrupt.clone(),
        }
    }

    fn interrupted(&self) -> bool {
        self.interrupt.as_ref().is_some_and(Interrupt::is_set)
    }

    fn coupler(&self) -> Coupler<'_> {
        Coupler {
            visibility: self.visibility,
            rays: self.rays,
            seed: self.seed,
            method: self.method,
        }
    }

    /// The unoccluded form factor from receiver `v` to patch `p`.
    pub fn unoccluded(&self, v: usize, p: usize) -> f64 {
        let d = self.disc;
        self.coupler()
            .unoccluded(&d.receivers[v], d.receiver_surface[v], &d.patches[p])
    }

    /// Form factor times visibility from receiver `v` to patch `p`, and the rays it took. The
    /// hemicube has no pairwise form: there, Lambert's formula with sampled visibility.
    pub fn coupling(&self, v: usize, p: usize) -> (f64, u32) {
        let d = self.disc;
        self.coupler().coupling(
            &d.receivers[v],
            d.receiver_surface[v],
            &d.patches[p],
            [v as u64, p as u64],
        )
    }

    /// Every patch's column of form factors: the receivers that see it, with their factors; and
    /// the rays cast for them.
    pub fn columns(&self, progress: &dyn Progress) -> Result<(Columns, u64), SolveError> {
        if let FormFactorMethod::Hemicube { resolution } = self.method {
            return Ok((self.hemicube_columns(resolution, progress)?, 0));
        }
        let (n, patches) = (self.disc.receiver_count(), self.disc.patches.len());
        progress.start("form factors", patches as u64);
        let done = AtomicU64::new(0);
        let computed: Vec<(Vec<(u32, f32)>, u64)> = (0..patches)
            .into_par_iter()
            .map(|q| {
                let mut rays = 0u64;
                if self.interrupted() {
                    return (Vec::new(), rays);
                }
                let column = (0..n)
                    .filter_map(|v| {
                        let (f, r) = self.coupling(v, q);
                        rays += r as u64;
                        (f > 0.0).then_some((v as u32, f as f32))
                    })
                    .collect();
                progress.set(done.fetch_add(1, Ordering::Relaxed) + 1);
                (column, rays)
            })
            .collect();
        progress.finish();
        if self.interrupted() {
            return Err(SolveError::Interrupted);
        }
        let rays = computed.iter().map(|c| c.1).sum();
        Ok((computed.into_iter().map(|c| c.0).collect(), rays))
    }

    /// The columns from a hemicube at every receiver (each gives a row), transposed.
    fn hemicube_columns(
        &self,
        resolution: usize,
        progress: &dyn Progress,
    ) -> Result<Columns, SolveError> {
        let disc = self.disc;
        let (n, patches) = (disc.receiver_count(), disc.patches.len());
        let template = Hemicube::new(resolution)?;
        progress.start("hemicubes", n as u64);
        let done = AtomicU64::new(0);
        let rows: Vec<Vec<(u32, f32)>> = (0..n)
            .into_par_iter()
            .map_init(
                || (template.clone(), vec![0.0; patches]),
                |(cube, row), v| {
                    if self.interrupted() {
                        return Vec::new();
                    }
                    row.fill(0.0);
                    hemicube_row(
                        cube,
                        disc,
                        self.visibility,
                        &disc.receivers[v],
                        disc.receiver_surface[v],
                        row,
                    );
                    progress.set(done.fetch_add(1, Ordering::Relaxed) + 1);
                    row.iter()
                        .enumerate()
                        .filter(|(_, f)| **f > 0.0)
                        .map(|(q, &f)| (q as u32, f as f32))
                        .collect()
                },
            )
            .collect();
        progress.finish();
        if self.interrupted() {
            return Err(SolveError::Interrupted);
        }
        let mut columns = vec![Vec::new(); patches];
        for (v, row) in rows.into_iter().enumerate() {
            for (q, f) in row {
                columns[q as usize].push((v as u32, f));
            }
        }
        Ok(columns)
    }
}

/// The hemicube's form factors from `x` (on `surface`) to every patch of `disc`, added to `row`
/// (one slot per patch). Every patch is drawn: the patches tile the scene, so they are its
/// occluders too.
pub fn hemicube_row(
    cube: &mut Hemicube,
    disc: &Discretization,
    visibility: &Visibility,
    x: &ReceivingPoint,
    surface: SurfaceId,
    row: &mut [f64],
) {
    // The eye moves into its surface like the rays of the other methods (a vertex on a junction
    // sees the one-sided limit), and everything nearer than a quarter of that is cut away.
    let offset = visibility.junction_offset();
    let tol = visibility.contact_distance();
    let eye = x.point + x.inward * offset;
    let triangles = disc
        .patches
        .iter()
        .enumerate()
        .filter(|(_, p)| {
            p.surface != surface && p.corners.iter().any(|&c| x.normal.dot(c - eye) > 0.0)
        })
        .flat_map(|(q, p)| {
            // A patch seen from behind hides what is behind it, and that is all.
            let id = if x.in_front_of(p.origin, p.normal, tol) {
                q as u32
            } else {
                OCCLUDER
            };
            p.triangles.iter().map(move |&t| (t, id))
        });
    cube.render(eye, x.normal, 0.25 * offset, triangles);
    cube.accumulate(row);
}

/// Lambert's formula over a patch: over its outline when the patch lies wholly in front of x,
/// else over its elements one by one, each clipped to x's tangent half-space.
pub fn patch_form_factor(x: &ReceivingPoint, patch: &Patch, tol: f64) -> f64 {
    let (mut any_front, mut any_behind) = (false, false);
    for &c in &patch.corners {
        let h = x.height(c, tol);
        any_front |= h > 0.0;
        any_behind |= h < 0.0;
    }
    if !any_front {
        return 0.0;
    }
    if !any_behind {
        let sum: f64 = patch
            .outline
            .iter()
            .map(|&[a, b]| edge_term(x, a, b, tol))
            .sum();
        return sum.abs() / (2.0 * PI);
    }
    patch.triangles.iter().map(|t| form_factor(x, t, tol)).sum()
}
