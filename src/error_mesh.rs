//! Error-driven meshes: the exact direct light can be evaluated anywhere, so a mesh's
//! interpolation error is measured, not guessed. Every triangle is checked at its edge midpoints
//! against the linear interpolation of its vertices; the deviations give the quadratic that
//! the linear interpolation misses, and so the triangle's squared error integrated over it. The
//! triangles with the largest squared error relative to their surface's mean reflected direct
//! light are split first, over all surfaces at once through one priority queue, until every
//! surface's RMS error is within the tolerance of that mean, or the element budget is spent.
//! (Weighed absolutely, the queue spent a large scene's budget on the surfaces nearest its
//! light: Sponza's floors kept 10.6 % RMS, against 6.8 % weighed relatively.)
//!
//! A triangle is measured when it first comes to the top of the queue, which holds it until
//! then by a prior on its error: a tenth of the light it would reflect unoccluded for a
//! triangle of the budget's typical size, and less in proportion to area for smaller ones
//! (interpolation error goes as the square of the size). The many small faces of a scanned
//! statue, whose prior is below what the budget reaches, are never measured.
//!
//! Triangles are split by conforming longest-edge bisection ([`BisectionMesh`]): the new vertex
//! is the midpoint of an edge that was checked, and takes that check's value, so no point is
//! evaluated twice. Splits never cross a mesh edge, so the discontinuities built into the mesh
//! stay edges, and thin triangles along them stay thin: they interpolate well.
//!
//! Most check points never become vertices: a split uses one of a triangle's three, and the
//! triangles last measured are not split at all (on Sponza, 62 % of the points evaluated).
//! When measuring has spent the budget, refinement goes on splitting at those points, worst
//! first, with no new evaluations ([`Refiner::split_at_measured`]), up to what the budget allows
//! it ([`ErrorBudget::splitting_measured`]): the edges such a split makes take the deviations
//! the bisected triangle's quadratic predicts.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap, HashSet};
use std::time::Instant;

use glam::DVec3;
use penumbra_meshing::{BisectionMesh, SceneMesh, Split, SurfaceMesh};
use penumbra_scenes::{
    AreaSampler, Rgb, Scene, SceneTriangle, SplitMix64, Surface, SurfaceId, Visibility,
};
use penumbra_solver::{
    DirectLight, Interrupt, OVERLAY_CAP, Progress, ReceivingPoint, Solution, form_factor,
    hover_lift, hover_lifts, irradiance_shared, on_line_distance,
};
use rayon::prelude::*;
use serde::Serialize;

use crate::reflected_mesh::{ReflectedRefinement, SurfaceEstimate};

/// The error a run aims for by default: each refined surface's estimated RMS interpolation
/// error of the direct light, relative to its mean reflected direct light. On the
/// CornellBox-Sphere and CornellBox-Lucy floors it left 0.42 % and 0.31 % RMS at random points
/// (`penumbra sweep SCENE --direct-only --surfaces Floor/Floor/0 --methods error-driven`).
pub const DEFAULT_TOLERANCE: f64 = 5e-3;

/// A batch of splits takes at most this fraction of the triangles the mesh has: the queue's order
/// is kept to within a batch, and each batch's checks are evaluated in parallel.
const BATCH_FRACTION: f64 = 1.0 / 64.0;

/// A triangle's squared error over its area, before it is measured, in units of the square of
/// its prior error (below): the estimate of [`Refined::squared_error`] when every check point
/// is off by it, (4/45)·(9 + 3).
const PRIOR_SQUARED_ERROR: f64 = 48.0 / 45.0;

/// A triangle of the budget's typical size is presumed off by this fraction of the light it
/// would reflect unoccluded until it is measured.
const PRIOR_RELATIVE_ERROR: f64 = 0.1;

/// Surfaces smaller than this many of the budget's typical elements keep their least mesh,
/// counted by area or laid end to end along their longest edge: the faces of a scanned statue
/// are small both ways, but a long thin face (a roof tile, a column's facet) spans a wide range
/// of light. (Counted by area alone, the Crytek Sponza's roof tiles, each a 12 × 213 cm
/// triangle under the sky, kept their two ends' light, 0.22 and 0.02: they held 77 % of the
/// scene's RMS error at random points and overshot the light emitted by 4 %.)
const REFINED_ELEMENTS: f64 = 8.0;

/// Triangles smaller than this share of the budget's typical element are not split: a jump
/// across a triangle (a value discontinuity the mesh does not follow) keeps its error however
/// small the triangle, and would take the whole budget down to rounding.
const SMALLEST_SHARE: f64 = 1.0 / 64.0;

/// A surface darker than this share of the scene's mean reflected direct light is held to the
/// tolerance of one that bright: the relative error of a surface in shadow is not worth a budget.
const DARK_SHARE: f64 = 0.1;

/// Points closer than this fraction of the scene's diagonal to an emitter's edge or plane
/// count as on it, for the unoccluded light of a triangle's prior.
const UNOCCLUDED_TOLERANCE: f64 = 1e-9;

/// Points the scene's mean reflected direct light is sampled at (seeded, spread by area): the
/// scale of the tolerance and of the report's relative errors.
const MEAN_SAMPLES: usize = 2048;

/// A surface with this many of those points takes their mean as its own.
const MIN_SURFACE_SAMPLES: usize = 64;

/// The seed of those points.
const MEAN_SEED: u64 = 0x6d65_616e;

/// What [`ErrorBudget::splitting_measured`] lets splits at measured check points take a mesh
/// to, as a multiple of the triangles measured: on the Dabrovic Sponza under its sky (109,810
/// measured), they stop by themselves at 196,193, and take the floors from 6.2 % RMS to 3.0 %.
pub const SPLITS_AT_MEASURED: f64 = 2.0;

/// Room kept below the budget: a split's propagation path adds a few triangles more than the
/// two of the split itself.
const SPLIT_MARGIN: usize = 32;

/// Why error-driven refinement stopped (`mesh_error.stop` in `report.json`), from the most
/// ordinary to the least (shards joined report the least ordinary).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ErrorStop {
    /// Every refined surface's estimated RMS error is within the tolerance.
    Tolerance,
    /// The element budget is spent.
    Budget,
    /// The time budget ran out.
    TimeBudget,
    /// The run was interrupted.
    Interrupted,
}

/// One surface's measured interpolation error of the direct light (an entry of
/// `mesh_error.surfaces` in `report.json`).
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct SurfaceError {
    /// The surface's name.
    pub surface: String,
    /// Its index in the scene.
    #[serde(skip)]
    pub id: SurfaceId,
    /// Its triangles.
    pub triangles: usize,
    /// Of those, how many were measured at their check points, or split at measured points
    /// from one that was (the others' prior stayed below what refinement reached).
    pub measured: usize,
    /// Its mean reflected direct light (ρ·H, channel mean), W/m²: from the scene's samples on
    /// it when it has enough of them, else from its vertices.
    pub mean_reflected: f64,
    /// Its estimated RMS interpolation error (of the measured triangles, from their check
    /// points, and of the others, from their priors), relative to `mean_reflected`.
    pub rms: f64,
    /// The largest check point error, relative to `mean_reflected`.
    pub max: f64,
    /// Whether its estimated RMS error (of its measured triangles and the priors of the others)
    /// is within the tolerance of its mean (or of a tenth of the scene's, if darker).
    pub within_tolerance: bool,
    /// Full solutions: the estimated RMS interpolation error of the light it reflects more than
    /// once (from the jumps of that light's gradient across its triangles' edges), relative to
    /// the mean of all the light it reflects (B − E).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reflected_rms: Option<f64>,
}

/// What error-driven refinement did and the error it measured (`mesh_error` in `report.json`).
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct MeshErrorReport {
    /// The tolerance asked for, relative to the scene's mean reflected direct light.
    pub tolerance: f64,
    /// The scene's mean reflected direct light (channel mean) over the reflecting surfaces,
    /// W/m², sampled at [`MEAN_SAMPLES`] points spread by area.
    pub mean_reflected: f64,
    /// Why refinement stopped.
    pub stop: ErrorStop,
    /// Triangles of the mesh refinement started from.
    pub triangles_before: usize,
    /// Triangles of the refined mesh.
    pub triangles: usize,
    /// Points where the exact direct light was evaluated (vertices and check points; surfaces
    /// meeting at a point share one).
    pub evaluations: usize,
    /// Splits made, once measuring stopped, at check points already measured (no new
    /// evaluations).
    #[serde(default)]
    pub splits_at_measured_points: usize,
    /// Area-weighted RMS of the check points' errors over the measured triangles, relative to
    /// `mean_reflected`.
    pub rms: f64,
    /// The share of the reflecting surfaces' area in triangles never measured.
    pub unmeasured_area: f64,
    /// The area of the measured triangles, m² (what `rms` is weighted over).
    #[serde(default)]
    pub measured_area: f64,
    /// The largest check point error, relative to `mean_reflected`.
    pub max: f64,
    /// Each refined surface, in the scene's order.
    pub surfaces: Vec<SurfaceError>,
    /// Full solutions: the refined surfaces' estimated RMS interpolation error of the light
    /// reflected more than once, relative to the mean of all the light they reflect (see
    /// [`SurfaceError::reflected_rms`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reflected_rms: Option<f64>,
    /// Full solutions with the hierarchical solver: what refinement for the light reflected
    /// more than once did after the first solve.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reflected_refinement: Option<ReflectedRefinement>,
}

impl MeshErrorReport {
    /// Adds the estimated interpolation error of the light reflected more than once, from a full
    /// solution on `mesh`: the jumps of its gradient across each triangle's inner edges times
    /// the edge's length over 8, the error of a quadratic's interpolant (the measured check
    /// points cover only the direct light).
    pub fn estimate_reflected(&mut self, scene: &Scene, mesh: &SceneMesh, solution: &Solution) {
        let (mut squared, mut reflected, mut area) = (0.0, 0.0, 0.0);
        for entry in &mut self.surfaces {
            let id = entry.id;
            let surface = &scene.surfaces[id];
            let direct: Vec<Rgb> = solution.direct_irradiance[id]
                .iter()
                .map(|&h| surface.emission + surface.reflectance.mul_rgb(h))
                .collect();
            let e =
                SurfaceEstimate::of(scene, &mesh.surfaces[id], &solution.radiosity[id], &direct);
            let (s2, sum) = (e.squared.iter().sum::<f64>(), e.mean * e.area);
            entry.reflected_rms = (sum > 0.0).then(|| (s2 * e.area).sqrt() / sum);
            (squared, reflected, area) = (squared + s2, reflected + sum, area + e.area);
        }
        self.reflected_rms = (reflected > 0.0).then(|| (squared * area).sqrt() / reflected);
    }

    /// The reports of shards that each refined their own surfaces alone (with the scene's
    /// reflecting `area`, m²), joined: counts summed, errors weighted by measured area,
    /// surfaces in shard order (the scene's).
    pub fn join(shards: &[&MeshErrorReport], area: f64) -> Option<MeshErrorReport> {
        let first = shards.first()?;
        let measured: f64 = shards.iter().map(|r| r.measured_area).sum();
        let squared: f64 = shards.iter().map(|r| r.rms.powi(2) * r.measured_area).sum();
        Some(MeshErrorReport {
            stop: shards.iter().map(|r| r.stop).max().unwrap_or(first.stop),
            triangles_before: shards.iter().map(|r| r.triangles_before).sum(),
            triangles: shards.iter().map(|r| r.triangles).sum(),
            evaluations: shards.iter().map(|r| r.evaluations).sum(),
            splits_at_measured_points: shards.iter().map(|r| r.splits_at_measured_points).sum(),
            rms: if measured > 0.0 {
                (squared / measured).sqrt()
            } else {
                0.0
            },
            unmeasured_area: if area > 0.0 {
                1.0 - measured / area
            } else {
                0.0
            },
            measured_area: measured,
            max: shards.iter().map(|r| r.max).fold(0.0, f64::max),
            surfaces: shards.iter().flat_map(|r| r.surfaces.clone()).collect(),
            ..(*first).clone()
        })
    }

    /// The surfaces left above the tolerance: where the budget or the time ran out first.
    pub fn above_tolerance(&self) -> Vec<&SurfaceError> {
        self.surfaces
            .iter()
            .filter(|s| !s.within_tolerance)
            .collect()
    }
}

/// When refinement must stop early.
#[derive(Clone, Debug, Default)]
pub struct StopWhen {
    /// At this instant (a run's time budget).
    pub deadline: Option<Instant>,
    /// When this is set (Ctrl-C).
    pub interrupt: Option<Interrupt>,
}

impl StopWhen {
    fn now(&self) -> Option<ErrorStop> {
        if self.interrupt.as_ref().is_some_and(Interrupt::is_set) {
            Some(ErrorStop::Interrupted)
        } else if self.deadline.is_some_and(|d| Instant::now() >= d) {
            Some(ErrorStop::TimeBudget)
        } else {
            None
        }
    }
}

/// Whether a face of `area` whose triangles' longest edge is `longest_edge` is refined in a mesh
/// of typical elements of `element` area: it spans at least [`REFINED_ELEMENTS`] of them, by area
/// or laid end to end along that edge (the side of an equilateral triangle of their area).
pub fn refinable(area: f64, longest_edge: f64, element: f64) -> bool {
    let typical_edge = (element * 4.0 / 3f64.sqrt()).sqrt();
    area >= REFINED_ELEMENTS * element || longest_edge >= REFINED_ELEMENTS * typical_edge
}

/// The triangles error-driven refinement may reach, and the typical element it judges faces
/// and triangles by: the area meshed over those triangles, or less.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorBudget {
    /// Triangles in all, while refinement measures.
    pub triangles: usize,
    /// Triangles that splits at check points already measured may take the mesh to when
    /// measuring stops at `triangles`: no new evaluations ([`ErrorBudget::splitting_measured`]).
    pub split_at_measured: usize,
    /// The largest typical element, in the scene's units of area: a shard meshing part of a
    /// scene judges its faces by no larger an element than the whole scene's
    /// ([`ErrorBudget::for_shard`]), however few triangles its part of the budget has for its
    /// area.
    pub largest_element: Option<f64>,
}

impl ErrorBudget {
    /// A budget of `triangles`, the typical element that of the area they mesh.
    pub fn triangles(triangles: usize) -> ErrorBudget {
        ErrorBudget {
            triangles,
            split_at_measured: triangles,
            largest_element: None,
        }
    }

    /// A shard's budget of `triangles` in a scene of `area` whose polygons' fitted budget is
    /// `planned` triangles: its typical element is at most `area / planned`. (A shard's part of
    /// the budget follows the lit area of its faces large enough to refine; much of its area may
    /// be in other faces, and judged by its own element a long face beside them would be too
    /// short to refine.) A whole run's element is never larger: its budget fits its least mesh,
    /// which holds at least the polygons'.
    pub fn for_shard(triangles: usize, area: f64, planned: usize) -> ErrorBudget {
        ErrorBudget {
            triangles,
            split_at_measured: triangles,
            largest_element: (planned > 0).then(|| area / planned as f64),
        }
    }

    /// This budget, and once measuring stops at it, splits at the check points measured (worst
    /// first, on surfaces still above the tolerance) up to [`SPLITS_AT_MEASURED`] times as many
    /// triangles: where evaluations are the cost (the direct light alone), not triangles.
    pub fn splitting_measured(self) -> ErrorBudget {
        let most = (self.triangles as f64 * SPLITS_AT_MEASURED) as usize;
        ErrorBudget {
            split_at_measured: most,
            ..self
        }
    }

    /// The typical element of `area` meshed with this budget.
    fn element(self, area: f64) -> f64 {
        let own = area / self.triangles.max(1) as f64;
        self.largest_element.map_or(own, |most| own.min(most))
    }
}

/// Refines `mesh` where its interpolation of the exact direct light is worst, up to `budget`
/// triangles in all or until every refined surface's estimated RMS error is within `tolerance`
/// of its mean reflected direct light (or of [`DARK_SHARE`] of the scene's, if darker). The
/// refined mesh keeps no triangulations to refine further ([`SceneMesh::refinable`] is emptied).
pub fn refine_by_error(
    scene: &Scene,
    visibility: &Visibility,
    mesh: &mut SceneMesh,
    budget: ErrorBudget,
    tolerance: f64,
    stop: &StopWhen,
    progress: &dyn Progress,
) -> MeshErrorReport {
    let direct = DirectLight::new(scene, visibility).with_overlay_cap(OVERLAY_CAP);
    let triangles_before = mesh.triangle_count();
    let mut refiner = Refiner::new(scene, mesh, &direct);
    // Out of time before it starts: the mesh stays as it is, measured nowhere.
    if let Some(reason) = stop.now() {
        return refiner.report(scene, tolerance, 0.0, reason, triangles_before);
    }
    let mean = refiner.sampled_mean(scene, visibility);
    refiner.start(scene, budget, tolerance, mean);
    let (error_budget, budget) = (budget, budget.triangles);
    progress.start("refining by error", budget as u64);
    let reason = loop {
        progress.set(refiner.triangles as u64);
        if let Some(reason) = stop.now() {
            break reason;
        }
        let room = budget.saturating_sub(refiner.triangles);
        if room < SPLIT_MARGIN + 4 {
            break ErrorStop::Budget;
        }
        let batch = ((refiner.triangles as f64 * BATCH_FRACTION) as usize).clamp(1, room / 4);
        if !refiner.step(batch, budget - SPLIT_MARGIN) {
            break ErrorStop::Tolerance;
        }
    };
    let free_splits = match reason {
        ErrorStop::Budget => refiner.split_at_measured(error_budget.split_at_measured),
        _ => 0,
    };
    progress.finish();
    let mut report = refiner.report(scene, tolerance, mean, reason, triangles_before);
    report.splits_at_measured_points = free_splits;
    mesh.measured_direct = vec![Vec::new(); mesh.surfaces.len()];
    for s in refiner.surfaces {
        let m = s.mesh.mesh();
        // The solvers lift a vertex on a hovering face's contact line by less where its edges
        // are short; they measure those vertices themselves.
        let lifts = hover_lifts(m, &s.hovering, refiner.on_line);
        mesh.measured_direct[s.id] = (s.vertex.iter().zip(&s.irradiance).enumerate())
            .map(|(v, (x, &h))| {
                let lifted = lifts[v] == hover_lift(&s.hovering, m.points3[v], refiner.on_line);
                (x.is_finite() && lifted).then_some(h)
            })
            .collect();
        mesh.surfaces[s.id] = s.mesh.into_mesh();
    }
    mesh.refinable = Vec::new();
    report
}

/// A reflecting surface being refined, with the values measured on it: the reflected direct
/// light (ρ·H, channel mean) at its vertices and edge midpoints.
struct Refined {
    id: SurfaceId,
    mesh: BisectionMesh,
    reflectance: Rgb,
    /// NaN until measured.
    vertex: Vec<f64>,
    /// The exact direct irradiance at the measured vertices (what solvers take).
    irradiance: Vec<Rgb>,
    /// By the edge's vertices, smaller first: the two sides of a jump have their own. The
    /// irradiance, and the reflected light.
    midpoint: HashMap<(u32, u32), (Rgb, f64)>,
    /// The deviation the quadratic of the triangle split predicts at the midpoint of each edge
    /// that a split at a measured point made and that was not measured, by its vertices.
    predicted: HashMap<(u32, u32), f64>,
    /// Whether each triangle was measured (or is being measured).
    measured: Vec<bool>,
    /// Each measured triangle's largest check point error, W/m².
    error: Vec<f64>,
    /// Each triangle's squared error integrated over it: measured ([`Self::squared_error`]),
    /// or its prior.
    squared: SquaredErrors,
    /// The surface's area: bisection keeps it (but for rounding).
    area: f64,
    /// Whether the surface is refined: faces smaller than [`REFINED_ELEMENTS`] typical elements
    /// (by area and along their longest edge) keep their least mesh.
    refined: bool,
    /// The sum and count of the scene's samples of the mean on it.
    samples: (f64, usize),
    /// The RMS error it may keep, W/m²: the tolerance times its mean reflected direct light (or
    /// [`DARK_SHARE`] of the scene's, if darker).
    target: f64,
    /// Whether its estimated RMS error is within `target`.
    done: bool,
    /// What its triangles' squared errors weigh in the queue: one over the square of the light
    /// its target is relative to, so that a dim surface's relative error counts as much as a
    /// bright one's (by area), not less by the square of its brightness.
    weight: f64,
    /// Bumped when a triangle changes, so that its old queue entries are passed over.
    version: Vec<u32>,
    /// The contact lines of faces hovering over it (ends and gap): points on them are
    /// evaluated a few gaps off them ([`hover_lift`]), as the solvers evaluate its vertices.
    hovering: Vec<(DVec3, DVec3, f64)>,
}

/// Each triangle's squared error, and their sum kept as they change with a bound on how far
/// rounding has taken it from summing them anew: whether a surface of hundreds of thousands of
/// triangles is done is decided at each split without a pass over them.
#[derive(Debug, Default)]
struct SquaredErrors {
    each: Vec<f64>,
    sum: f64,
    drift: f64,
}

impl SquaredErrors {
    fn new(n: usize) -> Self {
        SquaredErrors {
            each: vec![0.0; n],
            ..SquaredErrors::default()
        }
    }

    fn get(&self, t: usize) -> f64 {
        self.each[t]
    }

    /// The errors summed anew (for a report, not the running sum).
    fn total(&self) -> f64 {
        self.each.iter().sum()
    }

    fn set(&mut self, t: usize, value: f64) {
        let old = std::mem::replace(&mut self.each[t], value);
        self.sum += value - old;
        self.drift += 2.0 * f64::EPSILON * (value.abs() + old.abs() + self.sum.abs());
    }

    /// Room for `n` triangles, the new ones without error.
    fn resize(&mut self, n: usize) {
        self.each.resize(n, 0.0);
    }

    /// Whether the errors sum to at most `limit`, as summing them anew against `exact_limit`
    /// (`limit` with its terms summed anew too) would say: the kept sum decides unless it lies
    /// within the rounding of either of `limit`; then they are summed anew.
    fn at_most(&mut self, limit: f64, exact_limit: impl FnOnce() -> f64) -> bool {
        let terms = self.each.len() as f64;
        let rounding = self.drift + 4.0 * f64::EPSILON * terms * (self.sum.abs() + limit.abs());
        if (self.sum - limit).abs() > rounding {
            return self.sum <= limit;
        }
        self.sum = self.total();
        self.drift = 0.0;
        self.sum <= exact_limit()
    }
}

/// Where an edge's midpoint is kept: by its two vertices, smaller first.
fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// The deviations at the midpoints of the edges that bisecting a triangle at its edge `k` makes
/// (the edge's halves, and the median), predicted from the deviations `d` at its edges'
/// midpoints by the quadratic through its corners and midpoints. A quadratic's deviation on a
/// segment is an eighth of its second derivative along the segment, so the halves take a
/// quarter of the edge's, and the median half the other two edges' less a quarter of the
/// edge's.
fn bisected_deviations(d: [f64; 3], k: usize) -> [f64; 2] {
    let others = d[(k + 1) % 3] + d[(k + 2) % 3];
    [d[k] / 4.0, others / 2.0 - d[k] / 4.0]
}

/// A point to evaluate, on a surface being refined.
#[derive(Clone, Copy, Debug)]
enum Check {
    /// A vertex, approached from the given point's side (inside its triangles).
    Vertex(u32, DVec3),
    /// The midpoint of edge `[a, b]`, from the side of the corner `c` across it; for a vertex
    /// made there, `Some(vertex)`.
    Edge([u32; 3], Option<u32>),
}

/// A queue entry: a triangle's squared error, measured or its prior.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    priority: f64,
    surface: u32,
    triangle: u32,
    version: u32,
}

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        self.priority
            .total_cmp(&other.priority)
            .then((other.surface, other.triangle).cmp(&(self.surface, self.triangle)))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

struct Refiner<'a> {
    direct: &'a DirectLight<'a>,
    /// Within this distance, a point lies on a hovering face's contact line.
    on_line: f64,
    /// No triangle smaller than this (in the scene's units) is split.
    smallest: f64,
    surfaces: Vec<Refined>,
    queue: BinaryHeap<Entry>,
    /// Triangles of the whole scene, reflecting or not.
    triangles: usize,
    evaluations: usize,
}

impl<'a> Refiner<'a> {
    /// Takes the reflecting surfaces of `mesh`, none measured yet.
    fn new(scene: &Scene, mesh: &SceneMesh, direct: &'a DirectLight<'a>) -> Refiner<'a> {
        let surfaces = mesh
            .surfaces
            .iter()
            .filter(|m| {
                scene.surfaces[m.surface].reflectance.mean() > 0.0 && m.triangle_count() > 0
            })
            .map(|m| {
                let reflectance = scene.surfaces[m.surface].reflectance;
                let n = m.triangle_count();
                Refined {
                    id: m.surface,
                    reflectance,
                    vertex: vec![f64::NAN; m.vertex_count()],
                    irradiance: vec![Rgb::ZERO; m.vertex_count()],
                    midpoint: HashMap::new(),
                    predicted: HashMap::new(),
                    measured: vec![false; n],
                    error: vec![0.0; n],
                    squared: SquaredErrors::new(n),
                    area: m.area(),
                    refined: false,
                    target: 0.0,
                    samples: (0.0, 0),
                    done: false,
                    weight: 1.0,
                    version: vec![0; n],
                    hovering: mesh.hovering[m.surface].clone(),
                    mesh: BisectionMesh::new(m.clone()),
                }
            })
            .collect();
        Refiner {
            direct,
            on_line: on_line_distance(scene),
            smallest: 0.0,
            surfaces,
            queue: BinaryHeap::new(),
            triangles: mesh.triangle_count(),
            evaluations: 0,
        }
    }

    /// The mean reflected direct light over the scene's reflecting surfaces, sampled at seeded
    /// points spread by area over their polygons (not the mesh: a shard that meshes its own
    /// surfaces alone samples the same points as the run not split).
    fn sampled_mean(&mut self, scene: &Scene, visibility: &Visibility) -> f64 {
        let reflects = |s: SurfaceId| scene.surfaces[s].reflectance.mean() > 0.0;
        let triangles: Vec<&SceneTriangle> = (visibility.triangles().iter())
            .filter(|t| reflects(t.surface))
            .collect();
        let sampler = AreaSampler::new(triangles.iter().map(|t| {
            let [a, b, c] = t.vertices;
            (b - a).cross(c - a).length() / 2.0
        }));
        let mut rng = SplitMix64::keyed(MEAN_SEED, &[]);
        let points: Vec<(SurfaceId, ReceivingPoint)> = (0..MEAN_SAMPLES)
            .map_while(|_| {
                let (k, w) = sampler.pick(&mut rng)?;
                let t = triangles[k];
                let p: DVec3 = (0..3).map(|j| t.vertices[j] * w[j]).sum();
                let normal = scene.surfaces[t.surface].normal();
                Some((t.surface, ReceivingPoint::interior(p, normal)))
            })
            .collect();
        let values: Vec<f64> = points
            .par_iter()
            .map(|(s, x)| {
                let h = self.direct.irradiance(x, *s);
                scene.surfaces[*s].reflectance.mul_rgb(h).mean()
            })
            .collect();
        self.evaluations += values.len();
        let refined: HashMap<SurfaceId, usize> = (self.surfaces.iter().enumerate())
            .map(|(i, s)| (s.id, i))
            .collect();
        let (mut sum, mut count) = (0.0, 0usize);
        for (&(surface, _), v) in points.iter().zip(values) {
            if v.is_finite() {
                if let Some(&i) = refined.get(&surface) {
                    let s = &mut self.surfaces[i];
                    s.samples.0 += v;
                    s.samples.1 += 1;
                }
                sum += v;
                count += 1;
            }
        }
        sum / count.max(1) as f64
    }

    /// Measures the vertices of the surfaces to refine, sets each one's target, and queues
    /// every triangle that may need splitting by the prior on its error.
    fn start(&mut self, scene: &Scene, budget: ErrorBudget, tolerance: f64, mean: f64) {
        let area: f64 = self.surfaces.iter().map(|s| s.mesh().area()).sum();
        let element = budget.element(area);
        self.smallest = SMALLEST_SHARE * element;
        // Once, not per triangle: a scanned statue's scene has tens of thousands of surfaces.
        let on_emitter = UNOCCLUDED_TOLERANCE * scene.diagonal();
        let emitters: Vec<&Surface> = scene.emitters().map(|(_, e)| e).collect();
        for s in self.surfaces.iter_mut() {
            // A face the budget would give only a few triangles keeps its least mesh: the
            // faces of a tessellated statue.
            s.refined = refinable(s.mesh().area(), s.longest_edge(), element);
            if !s.refined {
                continue;
            }
            for t in 0..s.mesh().triangle_count() {
                let a = s.mesh().triangle_area(t);
                let e = PRIOR_RELATIVE_ERROR
                    * s.unoccluded(&emitters, t, on_emitter)
                    * (a / element).min(1.0);
                s.squared.set(t, PRIOR_SQUARED_ERROR * a * e * e);
            }
        }
        let mut checks = Vec::new();
        for (i, s) in self.surfaces.iter().enumerate().filter(|(_, s)| s.refined) {
            let inward = s.mesh().interior_directions();
            checks.extend((0..s.mesh().vertex_count()).map(|v| {
                let towards = s.mesh().points3[v] + inward[v];
                (i, Check::Vertex(v as u32, towards))
            }));
        }
        self.evaluate(&checks);
        let dark = DARK_SHARE * mean;
        for (i, s) in self
            .surfaces
            .iter_mut()
            .enumerate()
            .filter(|(_, s)| s.refined)
        {
            let light = s.mean().max(dark);
            s.target = tolerance * light;
            s.weight = if light > 0.0 { light.powi(-2) } else { 1.0 };
            s.update_done();
            for t in 0..s.mesh().triangle_count() {
                if s.squared.get(t) > 0.0 {
                    self.queue.push(Entry {
                        priority: s.weight * s.squared.get(t),
                        surface: i as u32,
                        triangle: t as u32,
                        version: 0,
                    });
                }
            }
        }
    }

    /// Takes the worst triangles off the queue: measures those not measured yet and splits
    /// the others, up to `batch` of each (while the scene has fewer than `most` triangles);
    /// then measures what changed and queues it again. Returns false when the queue is empty.
    fn step(&mut self, batch: usize, most: usize) -> bool {
        // What the step changed or is to measure, on each surface.
        let mut changed: Vec<Split> = vec![Split::default(); self.surfaces.len()];
        let (mut splits, mut measures) = (0, 0);
        while splits < batch && measures < batch && self.triangles < most {
            let Some((i, t)) = self.pop_current() else {
                break;
            };
            let s = &mut self.surfaces[i];
            if !s.measured[t] {
                s.measured[t] = true;
                changed[i].triangles.push(t as u32);
                measures += 1;
                continue;
            }
            if !s.splittable(t, self.smallest) {
                continue;
            }
            let mut split = Split::default();
            s.mesh.split(t, &mut split);
            s.grow(&split);
            // Each half replaces or joins a triangle.
            self.triangles += split.triangles.len() / 2;
            splits += 1;
            changed[i].triangles.extend(split.triangles);
            changed[i].vertices.extend(split.vertices);
        }
        if splits + measures == 0 {
            return false;
        }
        let mut checks = Vec::new();
        for (i, split) in changed.iter().enumerate() {
            checks.extend(
                self.surfaces[i]
                    .checks_missing(split)
                    .into_iter()
                    .map(|c| (i, c)),
            );
        }
        self.evaluate(&checks);
        for (i, split) in changed.into_iter().enumerate() {
            if !split.triangles.is_empty() {
                self.requeue(i, split.triangles);
            }
        }
        true
    }

    /// Takes the worst triangles off the queue and splits those whose split needs no new point
    /// ([`Refined::split_at_measured`]), until the scene has `most` triangles or the queue is
    /// empty; the others are dropped. Returns the splits made.
    fn split_at_measured(&mut self, most: usize) -> usize {
        let mut splits = 0;
        while self.triangles + SPLIT_MARGIN <= most {
            let Some((i, t)) = self.pop_current() else {
                break;
            };
            let s = &mut self.surfaces[i];
            if !s.measured[t] || !s.splittable(t, self.smallest) {
                continue;
            }
            let Some(split) = s.split_at_measured(t) else {
                continue;
            };
            self.triangles += split.triangles.len() / 2;
            splits += 1;
            self.requeue(i, split.triangles);
        }
        splits
    }

    /// The next triangle off the queue, as (surface, triangle), that has not changed since it
    /// was queued and whose surface is not done yet; `None` when the queue is empty.
    fn pop_current(&mut self) -> Option<(usize, usize)> {
        while let Some(e) = self.queue.pop() {
            let (i, t) = (e.surface as usize, e.triangle as usize);
            let s = &self.surfaces[i];
            if s.version[t] == e.version && !s.done {
                return Some((i, t));
            }
        }
        None
    }

    /// Estimates the errors of surface `i`'s `triangles` (new or changed, possibly repeated)
    /// from their check points, and queues them again.
    fn requeue(&mut self, i: usize, mut triangles: Vec<u32>) {
        let s = &mut self.surfaces[i];
        triangles.sort_unstable();
        triangles.dedup();
        for &t in &triangles {
            let t = t as usize;
            s.measured[t] = true;
            s.error[t] = s.triangle_error(t);
            let squared = s.squared_error(t);
            s.squared.set(t, squared);
            if squared > 0.0 {
                self.queue.push(Entry {
                    priority: s.weight * squared,
                    surface: i as u32,
                    triangle: t as u32,
                    version: s.version[t],
                });
            }
        }
        s.update_done();
    }

    /// Evaluates the exact light at `checks` (in parallel) and stores the values.
    fn evaluate(&mut self, checks: &[(usize, Check)]) {
        let points: Vec<(ReceivingPoint, SurfaceId)> = checks
            .iter()
            .map(|&(i, c)| {
                let s = &self.surfaces[i];
                (s.point(c, self.on_line), s.id)
            })
            .collect();
        let (values, evaluated) = irradiance_shared(self.direct, &points);
        self.evaluations += evaluated;
        for (&(i, c), value) in checks.iter().zip(values) {
            self.surfaces[i].store(c, value);
        }
    }

    fn report(
        &self,
        scene: &Scene,
        tolerance: f64,
        mean: f64,
        stop: ErrorStop,
        triangles_before: usize,
    ) -> MeshErrorReport {
        let surfaces: Vec<SurfaceError> = self
            .surfaces
            .iter()
            .filter(|s| s.refined)
            .map(|s| s.summary(scene))
            .collect();
        let (mut area, mut measured, mut sum2, mut max) = (0.0, 0.0, 0.0, 0.0f64);
        for s in &self.surfaces {
            let m = s.mesh();
            for t in 0..m.triangle_count() {
                let a = m.triangle_area(t);
                area += a;
                if s.measured[t] {
                    measured += a;
                    sum2 += s.squared.get(t);
                    max = max.max(s.error[t]);
                }
            }
        }
        let relative = |e: f64| if mean > 0.0 { e / mean } else { 0.0 };
        MeshErrorReport {
            tolerance,
            mean_reflected: mean,
            stop,
            triangles_before,
            triangles: self.triangles,
            evaluations: self.evaluations,
            splits_at_measured_points: 0,
            rms: relative((sum2 / measured.max(f64::MIN_POSITIVE)).sqrt()),
            unmeasured_area: if area > 0.0 {
                1.0 - measured / area
            } else {
                0.0
            },
            measured_area: measured,
            max: relative(max),
            surfaces,
            reflected_rms: None,
            reflected_refinement: None,
        }
    }
}

impl Refined {
    fn mesh(&self) -> &SurfaceMesh {
        self.mesh.mesh()
    }

    /// The length of the longest edge of its triangles.
    fn longest_edge(&self) -> f64 {
        (0..self.mesh().triangle_count())
            .flat_map(|t| {
                let [a, b, c] = self.mesh().triangle_points3(t);
                [a.distance(b), b.distance(c), c.distance(a)]
            })
            .fold(0.0, f64::max)
    }

    /// The light triangle `t` would reflect at its centroid if nothing stood between it and
    /// the emitters (points within `tol` of an emitter's edge or plane count as on it).
    fn unoccluded(&self, emitters: &[&Surface], t: usize, tol: f64) -> f64 {
        let p = self.mesh().triangle_points3(t);
        let x = ReceivingPoint::interior((p[0] + p[1] + p[2]) / 3.0, self.mesh().frame.normal);
        let h: Rgb = emitters
            .iter()
            .filter(|e| e.normal().dot(x.point - e.polygon[0]) > 0.0)
            .map(|e| e.emission * form_factor(&x, &e.polygon, tol))
            .sum();
        self.value(h)
    }

    /// The mean of the reflected direct light: its samples' when it has enough, else the
    /// area-weighted mean of its vertex values (which a coarse mesh can miss by far).
    fn mean(&self) -> f64 {
        if self.samples.1 >= MIN_SURFACE_SAMPLES {
            return self.samples.0 / self.samples.1 as f64;
        }
        let m = self.mesh();
        let sum: f64 = (0..m.triangle_count())
            .map(|t| {
                // A value beyond the evaluator's cap counts as dark.
                let v = m.triangles[t].map(|v| self.vertex[v as usize]);
                let v = v.map(|x| if x.is_finite() { x } else { 0.0 });
                m.triangle_area(t) * (v[0] + v[1] + v[2]) / 3.0
            })
            .sum();
        sum / m.area().max(f64::MIN_POSITIVE)
    }

    /// Whether the estimated RMS error (measured, or prior) is within the target.
    fn update_done(&mut self) {
        let limit = self.target * self.target * self.area;
        let exact_limit = || self.target * self.target * self.mesh.mesh().area();
        self.done = self.squared.at_most(limit, exact_limit);
    }

    /// The reflected light (channel mean) of irradiance `h`.
    fn value(&self, h: Rgb) -> f64 {
        self.reflectance.mul_rgb(h).mean()
    }

    /// The checks not measured yet of the triangles `changed` lists and of the vertices it
    /// made (which take their edges' values when those were measured): each triangle's
    /// vertices and its edges' midpoints, each once.
    fn checks_missing(&self, changed: &Split) -> Vec<Check> {
        let m = self.mesh();
        let mut checks = Vec::new();
        let mut vertices = HashSet::new();
        for &(v, edge) in &changed.vertices {
            if self.vertex[v as usize].is_nan() && vertices.insert(v) {
                checks.push(Check::Edge(edge, Some(v)));
            }
        }
        let (mut triangles, mut edges) = (HashSet::new(), HashSet::new());
        for &t in &changed.triangles {
            if !triangles.insert(t) {
                continue;
            }
            let p = m.triangle_points3(t as usize);
            let centroid = (p[0] + p[1] + p[2]) / 3.0;
            for k in 0..3 {
                let [a, b] = self.mesh.edge(t as usize, k);
                if self.vertex[a as usize].is_nan() && vertices.insert(a) {
                    checks.push(Check::Vertex(a, centroid));
                }
                let key = edge_key(a, b);
                if !self.midpoint.contains_key(&key) && edges.insert(key) {
                    checks.push(Check::Edge([a, b, self.mesh.opposite(t, k)], None));
                }
            }
        }
        checks
    }

    /// Room for the triangles and vertices `split` made; the vertices take their edges' values.
    fn grow(&mut self, split: &Split) {
        let m = self.mesh.mesh();
        self.vertex.resize(m.vertex_count(), f64::NAN);
        self.irradiance.resize(m.vertex_count(), Rgb::ZERO);
        self.measured.resize(m.triangle_count(), false);
        self.error.resize(m.triangle_count(), 0.0);
        self.squared.resize(m.triangle_count());
        self.version.resize(m.triangle_count(), 0);
        for &t in &split.triangles {
            self.version[t as usize] += 1;
        }
        for &(v, [a, b, _]) in &split.vertices {
            if let Some(&(h, value)) = self.midpoint.get(&edge_key(a, b)) {
                self.irradiance[v as usize] = h;
                self.vertex[v as usize] = value;
            }
        }
    }

    /// Where check `c` is, approached from the side it belongs to (and lifted off a hovering
    /// face's contact line towards that side).
    fn point(&self, c: Check, on_line: f64) -> ReceivingPoint {
        let m = self.mesh();
        let normal = m.frame.normal;
        let towards = |p: DVec3, q: DVec3| {
            let inward = (q - p).normalize_or_zero();
            ReceivingPoint {
                point: p + inward * hover_lift(&self.hovering, p, on_line),
                normal,
                inward,
            }
        };
        match c {
            Check::Vertex(v, centroid) => towards(m.points3[v as usize], centroid),
            Check::Edge([a, b, c], _) => towards(
                (m.points3[a as usize] + m.points3[b as usize]) * 0.5,
                m.points3[c as usize],
            ),
        }
    }

    fn store(&mut self, c: Check, h: Rgb) {
        let value = self.value(h);
        match c {
            Check::Vertex(v, _) | Check::Edge(_, Some(v)) => {
                self.irradiance[v as usize] = h;
                self.vertex[v as usize] = value;
            }
            Check::Edge([a, b, _], None) => {
                self.midpoint.insert(edge_key(a, b), (h, value));
            }
        }
    }

    /// Triangle `t`'s check point errors, at its edges' midpoints in its edges' order: the
    /// exact value less the interpolated one, or the predicted one where the midpoint was not
    /// measured. A value the evaluator could not give (a view beyond its overlay cap) counts as
    /// no error.
    fn deviations(&self, t: usize) -> [f64; 3] {
        let mut d = [0.0; 3];
        for (k, dk) in d.iter_mut().enumerate() {
            let [a, b] = self.mesh.edge(t, k);
            let key = edge_key(a, b);
            if let Some(&(_, m)) = self.midpoint.get(&key) {
                let e = m - (self.vertex[a as usize] + self.vertex[b as usize]) * 0.5;
                *dk = if e.is_finite() { e } else { 0.0 };
            } else if let Some(&e) = self.predicted.get(&key) {
                *dk = e;
            }
        }
        d
    }

    /// Whether triangle `t` may be split: not too small for its midpoints to be exact
    /// ([`BisectionMesh::too_small`]), nor below `smallest` in area.
    fn splittable(&self, t: usize, smallest: f64) -> bool {
        !self.mesh.too_small(t) && self.mesh().triangle_area(t) >= smallest
    }

    /// Whether edge `k` of triangle `t` has a measured midpoint.
    fn midpoint_measured(&self, t: usize, k: usize) -> bool {
        let [a, b] = self.mesh.edge(t, k);
        self.midpoint.contains_key(&edge_key(a, b))
    }

    /// Splits triangle `t` as [`BisectionMesh::split`] would, while every edge that takes
    /// is one whose midpoints (each side's) were measured: each edge a bisection makes takes
    /// the deviation that the quadratic of the triangle bisected predicts (from its three check
    /// points, as [`Self::squared_error`] models it). Returns what changed, if anything did
    /// (when an edge on the way was not measured, the bisections before it stay: each one
    /// leaves the mesh conforming).
    fn split_at_measured(&mut self, t: usize) -> Option<Split> {
        let mut split = Split::default();
        loop {
            let end = self.mesh.terminal(t);
            if !end.sides().all(|(u, k)| self.midpoint_measured(u, k)) {
                break;
            }
            let quadratics: Vec<_> = end.sides().map(|(u, k)| self.quadratic(u, k)).collect();
            let mut step = Split::default();
            self.mesh.bisect_terminal(end, &mut step);
            self.grow(&step);
            for ([a, b], c, [half, median]) in quadratics {
                let made = step
                    .vertices
                    .iter()
                    .find(|(_, e)| edge_key(e[0], e[1]) == edge_key(a, b));
                let Some(&(m, _)) = made else { continue };
                self.predicted.insert(edge_key(a, m), half);
                self.predicted.insert(edge_key(m, b), half);
                self.predicted.insert(edge_key(m, c), median);
            }
            split.triangles.extend(step.triangles);
            split.vertices.extend(step.vertices);
            if end.splits(t) {
                break;
            }
        }
        (!split.triangles.is_empty()).then_some(split)
    }

    /// What bisecting triangle `t` at its edge `k` makes: the edge, the corner across it, and
    /// the deviations its quadratic predicts ([`bisected_deviations`]).
    fn quadratic(&self, t: usize, k: usize) -> ([u32; 2], u32, [f64; 2]) {
        let corner = self.mesh.opposite(t as u32, k);
        let predicted = bisected_deviations(self.deviations(t), k);
        (self.mesh.edge(t, k), corner, predicted)
    }

    /// Triangle `t`'s largest check point error.
    fn triangle_error(&self, t: usize) -> f64 {
        self.deviations(t).iter().fold(0.0, |e, d| e.max(d.abs()))
    }

    /// Triangle `t`'s squared interpolation error integrated over it, estimated from its check
    /// points: the light as the linear interpolant plus a quadratic bubble 4·λi·λj on each
    /// edge, weighted by the midpoint's deviation d_e, whose integral over a triangle of area A
    /// is (4A/45)((Σd)² + Σd²).
    fn squared_error(&self, t: usize) -> f64 {
        let d = self.deviations(t);
        let (sum, sum2) = (d[0] + d[1] + d[2], d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        self.mesh().triangle_area(t) * 4.0 / 45.0 * (sum * sum + sum2)
    }

    fn summary(&self, scene: &Scene) -> SurfaceError {
        let m = self.mesh();
        let mean = self.mean();
        let relative = |e: f64| if mean > 0.0 { e / mean } else { 0.0 };
        let squared = self.squared.total();
        SurfaceError {
            surface: scene.surfaces[self.id].name.clone(),
            id: self.id,
            triangles: m.triangle_count(),
            measured: self.measured.iter().filter(|&&m| m).count(),
            mean_reflected: mean,
            rms: relative((squared / m.area().max(f64::MIN_POSITIVE)).sqrt()),
            max: relative(self.error.iter().fold(0.0, |a, &b| a.max(b))),
            within_tolerance: self.done,
            reflected_rms: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    /// The kept sum decides as summing anew does, at every step of a long run of changes whose
    /// values span twelve orders of magnitude (large priors replaced by small measured errors),
    /// against limits on either side of the sum and at it; only a limit within rounding of the
    /// sum takes a pass over the errors.
    #[test]
    fn the_kept_sum_decides_as_summing_anew() {
        let mut rng = SplitMix64::new(7);
        let n = 2000;
        let mut errors = SquaredErrors::new(n);
        for step in 0..20_000 {
            let t = (rng.next_u64() % n as u64) as usize;
            let scale = 10f64.powf(-12.0 * rng.next_f64());
            errors.set(t, scale * rng.next_f64());
            let exact: f64 = errors.each.iter().sum();
            for (limit, near) in [
                (exact * (1.0 - 1e-6), false),
                (exact * 2.0, false),
                (exact * (1.0 + 1e-15), true),
                (exact, true),
            ] {
                let drift = errors.drift;
                let done = errors.at_most(limit, || limit);
                assert_eq!(done, exact <= limit, "step {step}, limit {limit:e}");
                let summed_anew = errors.drift == 0.0 && drift > 0.0;
                assert!(
                    near || !summed_anew,
                    "step {step}: a pass for a limit far off"
                );
            }
        }
    }

    /// A quadratic's deviation from its chord at the midpoint of segment `[p, q]`.
    fn deviation(f: impl Fn(DVec2) -> f64, p: DVec2, q: DVec2) -> f64 {
        f((p + q) * 0.5) - (f(p) + f(q)) * 0.5
    }

    #[test]
    fn bisection_predicts_a_quadratics_deviations_exactly() {
        let f = |p: DVec2| {
            0.3 + 1.7 * p.x - 0.4 * p.y + 2.9 * p.x * p.x - 1.3 * p.x * p.y + 0.8 * p.y * p.y
        };
        let corners = [
            DVec2::new(0.1, -0.2),
            DVec2::new(2.3, 0.4),
            DVec2::new(0.7, 1.9),
        ];
        let d: [f64; 3] = std::array::from_fn(|k| deviation(f, corners[k], corners[(k + 1) % 3]));
        for k in 0..3 {
            let (a, b, c) = (corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3]);
            let m = (a + b) * 0.5;
            let [half, median] = bisected_deviations(d, k);
            assert!((half - deviation(f, a, m)).abs() < 1e-12, "{half}");
            assert!((half - deviation(f, m, b)).abs() < 1e-12, "{half}");
            assert!((median - deviation(f, m, c)).abs() < 1e-12, "{median}");
        }
    }
}
