//! What every solver returns: radiosity and irradiance at the mesh vertices, with the figures
//! of the solve and its convergence.

use penumbra_scenes::Rgb;
use serde::Serialize;

/// Why the solver stopped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
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
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
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
    pub hierarchy: Option<HierarchyStats>,
    /// Whether every vertex lies inside a room, so that no light can leave the scene (see
    /// `Enclosures`); `None` where the solver does not find out.
    pub closed: Option<bool>,
    /// The photon-map solver's figures: photons emitted and stored, the map's memory.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub photon_map: Option<PhotonStats>,
}

/// One step of a solver: its residual relative to the light put in (for progressive refinement
/// the unshot fraction, for gathering ‖c + K B̄ − B̄‖ / ‖c‖) and the seconds since it began.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, serde::Deserialize)]
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

/// Figures of a hierarchical solve, under `solver.hierarchy` in `report.json`.
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct HierarchyStats {
    /// The link tolerance the solve refined to.
    pub link_tol: f64,
    /// Element nodes (parts of surfaces), of which leaves (the mesh's triangles).
    pub elements: usize,
    /// See `elements`.
    pub leaves: usize,
    /// Cluster nodes (groups of surfaces).
    pub clusters: usize,
    /// Links in the final hierarchy.
    pub links: usize,
    /// Links by visibility: open (no blocker in the shaft), partial (rays decide).
    pub links_open: usize,
    /// See `links_open`.
    pub links_partial: usize,
    /// Links from or to a cluster.
    pub links_with_clusters: usize,
    /// Links by the depth of their receiver (0: the root cluster).
    pub links_by_depth: Vec<usize>,
    /// Pairs of nodes found hidden by one polygon, and not linked.
    pub hidden_pairs: u64,
    /// Passes of link refinement, each followed by sweeps.
    pub refinement_passes: usize,
    /// Rays for the links' visibility, and for the final gather's partial links.
    pub link_rays: u64,
    /// See `link_rays`.
    pub gather_rays: u64,
    /// Jacobi sweeps, over all passes.
    pub sweeps: usize,
    /// Sweeps of the solve that balances the leaves' energy (see `links_lost`).
    pub balance_sweeps: usize,
    /// The share of the light the leaves send toward surfaces that their links lost, before it
    /// was given back as ambient light (channel means).
    pub links_lost: f64,
    /// The share of the light the balanced leaves receive that the final gather lost, before it
    /// was given back as ambient light (channel means).
    pub gather_lost: f64,
    /// Seconds spent making and refining links.
    pub link_seconds: f64,
    /// Seconds spent sweeping.
    pub sweep_seconds: f64,
    /// Bytes held by the links.
    pub link_bytes: u64,
}

/// What making the map did (`solver.photon_map` in `report.json`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct PhotonStats {
    /// Photons emitted.
    pub emitted: usize,
    /// Photons stored: landings after at least one reflection.
    pub stored: usize,
    /// Bytes the map holds: positions, powers, precomputed estimates and the trees.
    pub bytes: usize,
    /// Irradiance estimates made in advance at stored photons, which the final gather reads
    /// (none without a final gather).
    pub precomputed: usize,
    /// The power of the photons that reached no surface's front (they left the scene or met a
    /// back), W per channel: the photons' own tally of what the scene loses.
    pub escaped: Rgb,
    /// Seconds spent tracing the photons and building the trees.
    pub trace_seconds: f64,
    /// Seconds spent estimating the indirect light at the vertices (the final gather, if any).
    pub estimate_seconds: f64,
}

/// What a display shows for radiosity `b` on a surface of reflectance `reflectance`: `b` plus
/// the surface's share of the display-only ambient term, ρ·ambient. Never part of a solution.
pub fn displayed(b: Rgb, reflectance: Rgb, ambient: Rgb) -> Rgb {
    b + reflectance.mul_rgb(ambient)
}

/// The ambient term of a solution that left `unshot` power unshot: spread over `area` and
/// reflected on without end at the mean reflectance.
pub fn ambient_term(unshot: Rgb, area: f64, mean_reflectance: Rgb) -> Rgb {
    (unshot / area).mul_rgb(mean_reflectance.map(|r| 1.0 / (1.0 - r)))
}
