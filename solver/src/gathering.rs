//! The discrete radiosity system solved whole: Jacobi and Gauss–Seidel gathering, and a dense
//! direct solve as the exact answer to the discrete system.
//!
//! The unknowns are the patches' mean reflected radiosities B̄ (the same patches the progressive
//! solver shoots from). A vertex v receives the exact direct irradiance Hd(v) plus
//! Σ_q F(v, q) B̄_q, with F the vertex-to-patch form factors of [`crate::coupling`]; a patch's
//! reflected radiosity is the area mean of ρ H over its elements, interpolated linearly. So
//!
//! B̄ = c + K B̄,   c_p = Σ_v A(p, v) ρ_v Hd(v),   K(p, q) = Σ_v A(p, v) ρ_v F(v, q),
//!
//! where A(p, v) is vertex v's weight in patch p's mean. Progressive refinement (Southwell
//! iteration) converges to the solution of exactly this system, so the direct solve is its truth.
//! F is stored sparse, a column per patch with only the vertices that see it; K is dense (one
//! matrix per colour channel), as small as the number of patches squared.

use std::time::Instant;

use penumbra_meshing::SceneMesh;
use penumbra_scenes::{Rgb, Scene, Visibility};
use rayon::prelude::*;
use serde::Serialize;

use crate::coupling::PatchCoupling;
use crate::direct_pass::direct_irradiance;
use crate::elements::Discretization;
use crate::error::SolveError;
use crate::options::SolverOptions;
use crate::progress::Progress;
use crate::solution::{ConvergencePoint, Solution, SolveStats, StopReason};

/// How the discrete system is solved.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SolverMethod {
    /// Progressive refinement: shoot the largest unshot power first (Southwell).
    #[default]
    Progressive,
    /// Jacobi gathering: every patch gathers from the previous iterate.
    Jacobi,
    /// Gauss–Seidel gathering: every patch gathers from the newest values.
    GaussSeidel,
    /// Gaussian elimination of the dense patch system: the discrete system's exact answer.
    Direct,
    /// Hierarchical radiosity with clustering, and a final gather at the vertices.
    Hierarchical,
    /// Photon mapping for the indirect light, the direct light exact.
    PhotonMap,
}

impl SolverMethod {
    /// The method's name on the command line and in sweeps.
    pub fn name(self) -> &'static str {
        match self {
            SolverMethod::Progressive => "progressive",
            SolverMethod::Jacobi => "jacobi",
            SolverMethod::GaussSeidel => "gauss-seidel",
            SolverMethod::Direct => "direct",
            SolverMethod::Hierarchical => "hierarchical",
            SolverMethod::PhotonMap => "photon-map",
        }
    }
}

/// What solving the patch system gives: B̄ per channel and patch, how the residual fell, and why
/// the iteration stopped.
#[derive(Clone, Debug)]
pub struct SystemSolution {
    /// B̄ per channel, per patch.
    pub patch_radiosity: [Vec<f64>; 3],
    /// The residual after each sweep.
    pub history: Vec<ConvergencePoint>,
    /// Why the iteration stopped.
    pub stop: StopReason,
}

/// The assembled system of a meshed scene.
#[derive(Debug)]
pub struct PatchSystem {
    /// The receivers, elements and patches.
    pub disc: Discretization,
    /// Direct irradiance at every vertex.
    pub direct: Vec<Rgb>,
    /// Per patch, the vertices that see it and their form factors.
    pub columns: crate::coupling::Columns,
    /// c and K, one per channel: `k[channel][p * patches + q]`.
    pub c: [Vec<f64>; 3],
    /// See `c`.
    pub k: [Vec<f64>; 3],
    /// Visibility rays cast for the form factors.
    pub rays_cast: u64,
    /// Seconds spent on the direct light, and on the form factors and K.
    pub direct_seconds: f64,
    /// Vertices whose direct light is an estimate by rays (their view of a light was beyond the
    /// exact evaluator's overlay cap).
    pub direct_beyond_cap: usize,
    /// See `direct_seconds`.
    pub assembly_seconds: f64,
}

impl PatchSystem {
    /// Assembles the system of `mesh`: the exact direct light at every vertex, the
    /// vertex-to-patch form factors by `options.form_factors`, then c and K.
    pub fn assemble(
        scene: &Scene,
        mesh: &SceneMesh,
        visibility: &Visibility,
        options: &SolverOptions,
        progress: &dyn Progress,
    ) -> Result<PatchSystem, SolveError> {
        let disc = Discretization::new(scene, mesh, options.elements_per_patch);
        let started = Instant::now();
        let (direct, direct_beyond_cap) =
            direct_irradiance(scene, &disc, visibility, options, progress)?;
        let direct_seconds = started.elapsed().as_secs_f64();
        let started = Instant::now();
        let n = disc.receiver_count();
        let patches = disc.patches.len();
        let coupling = PatchCoupling::new(&disc, visibility, options);
        let (columns, rays_cast) = coupling.columns(progress)?;

        // A(p, v): vertex v's weight in patch p's area mean (a third of each element around it).
        let mut weights: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for e in &disc.elements {
            let w = e.area / 3.0 / disc.patches[e.patch].area;
            for &v in &e.vertices {
                match weights[v].iter_mut().find(|(p, _)| *p == e.patch) {
                    Some(entry) => entry.1 += w,
                    None => weights[v].push((e.patch, w)),
                }
            }
        }
        let mut c: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; patches]);
        let mut k: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; patches * patches]);
        for v in 0..n {
            let rho = disc.reflectance[v];
            for &(p, w) in &weights[v] {
                for (ch, r) in [rho.r, rho.g, rho.b].into_iter().enumerate() {
                    c[ch][p] += w * r * [direct[v].r, direct[v].g, direct[v].b][ch];
                }
            }
        }
        for (q, column) in columns.iter().enumerate() {
            for &(v, f) in column {
                let v = v as usize;
                let rho = disc.reflectance[v];
                for &(p, w) in &weights[v] {
                    for (ch, r) in [rho.r, rho.g, rho.b].into_iter().enumerate() {
                        k[ch][p * patches + q] += w * r * f as f64;
                    }
                }
            }
        }
        Ok(PatchSystem {
            disc,
            direct,
            columns,
            c,
            k,
            rays_cast,
            direct_seconds,
            direct_beyond_cap,
            assembly_seconds: started.elapsed().as_secs_f64(),
        })
    }

    /// Patches of the system: its unknowns per channel.
    pub fn patches(&self) -> usize {
        self.disc.patches.len()
    }

    /// ‖c + K b − b‖ / ‖c‖ for one channel, area-weighted.
    fn residual(&self, ch: usize, b: &[f64]) -> f64 {
        let n = self.patches();
        let (mut r2, mut c2) = (0.0, 0.0);
        for p in 0..n {
            let row = &self.k[ch][p * n..(p + 1) * n];
            let kb: f64 = row.iter().zip(b).map(|(k, b)| k * b).sum();
            let a = self.disc.patches[p].area;
            r2 += a * (self.c[ch][p] + kb - b[p]).powi(2);
            c2 += a * self.c[ch][p].powi(2);
        }
        if c2 > 0.0 {
            (r2 / c2).sqrt()
        } else {
            r2.sqrt()
        }
    }

    /// Solves for B̄ with `method` (not progressive) to a relative residual of `tolerance`, at
    /// most `max_iterations` sweeps, or until `stop_now` gives a reason after a sweep; returns
    /// B̄ per channel and the convergence history.
    pub fn solve(
        &self,
        method: SolverMethod,
        tolerance: f64,
        max_iterations: usize,
        stop_now: &dyn Fn() -> Option<StopReason>,
    ) -> Result<SystemSolution, SolveError> {
        let n = self.patches();
        let started = Instant::now();
        let mut b: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; n]);
        let residual =
            |b: &[Vec<f64>; 3]| (0..3).map(|ch| self.residual(ch, &b[ch])).sum::<f64>() / 3.0;
        let mut history = vec![ConvergencePoint {
            iteration: 0,
            residual: residual(&b),
            seconds: 0.0,
        }];
        if method == SolverMethod::Direct {
            for ch in 0..3 {
                b[ch] = solve_dense(&self.k[ch], &self.c[ch], n).ok_or(SolveError::Singular)?;
            }
            history.push(ConvergencePoint {
                iteration: 1,
                residual: residual(&b),
                seconds: started.elapsed().as_secs_f64(),
            });
            return Ok(SystemSolution {
                patch_radiosity: b,
                history,
                stop: StopReason::Converged,
            });
        }
        let mut stop = StopReason::ShotLimit;
        for iteration in 1..=max_iterations {
            for ch in 0..3 {
                let k = &self.k[ch];
                let c = &self.c[ch];
                match method {
                    SolverMethod::Jacobi => {
                        let old = b[ch].clone();
                        b[ch] = (0..n)
                            .into_par_iter()
                            .map(|p| {
                                let row = &k[p * n..(p + 1) * n];
                                c[p] + row.iter().zip(&old).map(|(k, b)| k * b).sum::<f64>()
                            })
                            .collect();
                    }
                    _ => {
                        // Gauss–Seidel: each patch gathers from the values updated so far.
                        let x = &mut b[ch];
                        for p in 0..n {
                            let row = &k[p * n..(p + 1) * n];
                            let sum: f64 = row.iter().zip(x.iter()).map(|(k, b)| k * b).sum();
                            x[p] = c[p] + sum;
                        }
                    }
                }
            }
            let r = residual(&b);
            history.push(ConvergencePoint {
                iteration,
                residual: r,
                seconds: started.elapsed().as_secs_f64(),
            });
            if r < tolerance {
                stop = StopReason::Converged;
                break;
            }
            if let Some(reason) = stop_now() {
                stop = reason;
                break;
            }
        }
        Ok(SystemSolution {
            patch_radiosity: b,
            history,
            stop,
        })
    }

    /// Vertex irradiance from patch radiosities: Hd + F B̄.
    pub fn irradiance(&self, b: &[Vec<f64>; 3]) -> Vec<Rgb> {
        let mut h = self.direct.clone();
        for (q, column) in self.columns.iter().enumerate() {
            let bq = Rgb::new(b[0][q], b[1][q], b[2][q]);
            for &(v, f) in column {
                h[v as usize] += bq * f as f64;
            }
        }
        h
    }
}

/// Solves (I − K) x = c by Gaussian elimination with partial pivoting; `None` if singular.
fn solve_dense(k: &[f64], c: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut a: Vec<f64> = (0..n * n)
        .map(|i| if i / n == i % n { 1.0 } else { 0.0 } - k[i])
        .collect();
    let mut x = c.to_vec();
    for col in 0..n {
        let pivot =
            (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))?;
        if !(a[pivot * n + col].abs() > 0.0) {
            return None;
        }
        if pivot != col {
            for j in 0..n {
                a.swap(col * n + j, pivot * n + j);
            }
            x.swap(col, pivot);
        }
        let d = a[col * n + col];
        for i in col + 1..n {
            let factor = a[i * n + col] / d;
            if factor != 0.0 {
                for j in col..n {
                    a[i * n + j] -= factor * a[col * n + j];
                }
                x[i] -= factor * x[col];
            }
        }
    }
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|j| a[i * n + j] * x[j]).sum();
        x[i] = (x[i] - s) / a[i * n + i];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Solves a meshed scene by gathering (Jacobi, Gauss–Seidel) or directly, to a relative residual
/// of `options.epsilon`; the convergence history comes back with the solution.
pub fn solve_gathering(
    scene: &Scene,
    mesh: &SceneMesh,
    visibility: &Visibility,
    options: &SolverOptions,
    method: SolverMethod,
    progress: &dyn Progress,
) -> Result<Solution, SolveError> {
    options.validate()?;
    let started = Instant::now();
    let system = PatchSystem::assemble(scene, mesh, visibility, options, progress)?;
    let SystemSolution {
        patch_radiosity: b,
        history,
        stop,
    } = system.solve(method, options.epsilon, options.max_shots, &|| {
        options.stop_now()
    })?;
    let disc = &system.disc;
    let h = system.irradiance(&b);
    let radiosity: Vec<Rgb> = (0..disc.receiver_count())
        .map(|v| disc.emission[v] + disc.reflectance[v].mul_rgb(h[v]))
        .collect();
    let emitted = scene.emitted_power();
    let absorbed = disc.integrate(&h, |e| {
        Rgb::splat(1.0) - scene.surfaces[e.surface].reflectance
    });
    let reflected = disc.integrate(&h, |e| scene.surfaces[e.surface].reflectance);
    let sent: Rgb = (0..system.patches())
        .map(|p| Rgb::new(b[0][p], b[1][p], b[2][p]) * disc.patches[p].area)
        .sum();
    let received = disc.integrate(&h, |_| Rgb::splat(1.0));
    // What the patches reflect but B̄ does not carry yet: the system's residual, in power.
    let unshot = reflected - sent;
    let stats = SolveStats {
        stop,
        shots: 0,
        iterations: history.len() - 1,
        residual: history.last().map_or(0.0, |h| h.residual),
        patches: system.patches(),
        receivers: disc.receiver_count(),
        rays_cast: system.rays_cast,
        emitted,
        absorbed,
        unshot,
        escaped: emitted + sent - received,
        unshot_fraction: unshot.mean().abs() / emitted.mean().max(f64::MIN_POSITIVE),
        direct_seconds: system.direct_seconds,
        // The gathering solvers compute the direct light whatever the clock says, exactly but
        // where a point's view is beyond the overlay cap.
        direct_estimated: system.direct_beyond_cap,
        direct_beyond_cap: system.direct_beyond_cap,
        // Everything after the direct light: the form factors, K and the sweeps.
        shooting_seconds: started.elapsed().as_secs_f64() - system.direct_seconds,
        remeshes: 0,
        gathered: 0,
        gather_seconds: 0.0,
        hierarchy: None,
        photon_map: None,
        closed: Some(crate::solids::closed_scene(scene, visibility, disc)),
    };
    Ok(Solution {
        radiosity: disc.per_surface(&radiosity),
        irradiance: disc.per_surface(&h),
        direct_irradiance: disc.per_surface(&system.direct),
        ambient: Rgb::ZERO,
        stats,
        convergence: history,
    })
}
