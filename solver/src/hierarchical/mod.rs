//! Hierarchical radiosity with clustering on the discontinuity mesh (Hanrahan, Salzman &
//! Aupperle 1991; Smits, Arvo & Greenberg 1994; Sillion 1995; combined with discontinuity
//! meshing as in Lischinski, Tampieri & Greenberg 1993).
//!
//! 1. Every vertex of the display mesh gets the exact direct light, as in the other solvers; each
//!    triangle reflects its mean, exactly (the integral of the linear interpolant).
//! 2. The hierarchy (`tree.rs`) is built over the mesh's triangles and the surfaces, and linked
//!    from the root cluster down, each link as coarse as the oracle allows (`links.rs`), with
//!    visibility from shaft culling (`shaft.rs`) and rays only where a shaft holds blockers.
//! 3. Jacobi sweeps with push–pull (`iterate.rs`) carry the reflected light until the relative
//!    residual is below `epsilon`; the links are then judged again with the new radiosities,
//!    those carrying too much light wrongly are refined, and the sweeps go on, until no link
//!    changes.
//! 4. Every display vertex gathers the reflected light along the links of its leaf and the
//!    leaf's ancestors (`final_gather.rs`).
//!
//! The light a link may carry wrongly is `link_tol` of the light the surfaces reflect of the
//! direct light: a larger scene with the same light gets links no finer where its light is weak,
//! so the links grow about linearly with the scene. Results do not depend on the thread count:
//! every parallel step collects in order.

mod balance;
mod directions;
mod final_gather;
mod iterate;
mod links;
mod shaft;
mod totals;
mod transfer;
mod tree;

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use penumbra_meshing::{SceneMesh, SurfaceMesh, TriangleLocator};
use penumbra_scenes::{Rgb, Scene, Visibility};
use rayon::prelude::*;

use crate::direct::DirectLight;
use crate::direct_pass::{OVERLAY_CAP, check_mesh, direct_at_new, direct_irradiance};
use crate::elements::Discretization;
use crate::error::SolveError;
pub use crate::options::DEFAULT_LINK_TOL;
use crate::options::SolverOptions;
use crate::progress::Progress;
use crate::solids::Enclosures;
pub use crate::solution::HierarchyStats;
use crate::solution::{ConvergencePoint, Solution, SolveStats, StopReason};
use final_gather::{FinalGather, Gathered};
use iterate::{Field, System};
use links::{Link, RefineCounts, Refiner};
use shaft::Shafts;
use tree::{Hierarchy, NONE};

/// Refinement passes at most: link, solve, refine the links the new radiosities condemn, solve
/// again.
pub const MAX_PASSES: usize = 6;

/// Links per mesh triangle at [`DEFAULT_LINK_TOL`], rounded up from the Cornell box (6),
/// boxworld (2 to 6) and CornellBox-Lucy (12), and how they grow as the tolerance shrinks:
/// about as its inverse to the power 0.7 (the Cornell box at 6.5·10⁻⁸: 325 per triangle).
const LINKS_PER_TRIANGLE: f64 = 10.0;
const LINK_GROWTH: f64 = 0.7;

/// Links held at once, over those kept: refinement collects its parts before joining them, and
/// sorting them by receiver takes a buffer (7.9 million links of 512 MiB peaked at 1.7 GiB).
const LINK_PEAK: f64 = 3.0;

/// Fields of light held at once per node: the solution, the next sweep's, the response that
/// balances the energy, and the two fields of unit radiosity.
const FIELDS: usize = 5;

/// Bytes the hierarchy and its links take at their peak for a mesh of `triangles` over
/// `surfaces` at `link_tol`: two nodes per triangle, their light (fields of five colours a node,
/// and four numbers: scale, totals, sums), the links, and the tables of intensities of the
/// clusters of more than [`links::EXACT_CLUSTER_SURFACES`] surfaces (at most two per that many
/// surfaces, in each field).
pub fn estimated_bytes(triangles: u64, surfaces: u64, link_tol: f64) -> u64 {
    let node = (size_of::<tree::Node>() + FIELDS * 5 * size_of::<Rgb>() + 4 * 8) as f64;
    let ratio = DEFAULT_LINK_TOL / link_tol.max(f64::MIN_POSITIVE);
    let links = LINKS_PER_TRIANGLE * ratio.max(1.0).powf(LINK_GROWTH);
    let per_triangle = 2.0 * node + LINK_PEAK * links * size_of::<Link>() as f64;
    let tables = 2.0 * surfaces as f64 / f64::from(links::EXACT_CLUSTER_SURFACES)
        * (FIELDS * size_of::<directions::Table>()) as f64;
    (triangles as f64 * per_triangle + tables).min(u64::MAX as f64) as u64
}

/// Solves a meshed scene by hierarchical radiosity; the display values come from a final gather
/// at every vertex.
pub fn solve_hierarchical(
    scene: &Scene,
    mesh: &SceneMesh,
    visibility: &Visibility,
    options: &SolverOptions,
    progress: &dyn Progress,
) -> Result<Solution, SolveError> {
    let (_, solution) =
        solve_hierarchical_refining(scene, mesh, visibility, options, progress, &mut |_| {
            Ok(None)
        })?;
    Ok(solution)
}

/// What a round of adaptive refinement sees: the meshes, the radiosity and its direct part at
/// their vertices, and the exact direct light.
#[derive(Debug)]
pub struct Round<'r> {
    /// The round's meshes, one per surface.
    pub meshes: &'r [SurfaceMesh],
    /// The radiosity at each mesh vertex, per surface.
    pub radiosity: Vec<Vec<Rgb>>,
    /// The direct part of that radiosity, E + ρ H_direct, per surface.
    pub direct: Vec<Vec<Rgb>>,
    /// The exact direct light, for new vertices.
    pub direct_light: &'r DirectLight<'r>,
}

/// [`solve_hierarchical`], then rounds of refinement of the display mesh: `refine` looks at each
/// round's solution and gives a refined mesh (the same surfaces, every vertex kept) or `None` to
/// stop. The hierarchy stays that of the first mesh: a new vertex gets the exact direct light
/// and gathers along the links of the leaf it lies in. Returns the last mesh and its solution.
pub fn solve_hierarchical_refining(
    scene: &Scene,
    mesh: &SceneMesh,
    visibility: &Visibility,
    options: &SolverOptions,
    progress: &dyn Progress,
    refine: &mut dyn FnMut(&Round) -> Result<Option<SceneMesh>, SolveError>,
) -> Result<(SceneMesh, Solution), SolveError> {
    options.validate()?;
    check_mesh(scene, mesh)?;
    let run = Run {
        scene,
        visibility,
        options,
        progress,
    };
    let started = Instant::now();
    let first = Discretization::new(scene, mesh, options.elements_per_patch);
    let (direct, direct_beyond_cap) =
        direct_irradiance(scene, &first, visibility, options, progress)?;
    let mut figures = Figures {
        direct_seconds: started.elapsed().as_secs_f64(),
        direct_beyond_cap,
        gathered: first.receiver_count(),
        ..Figures::default()
    };

    let started = Instant::now();
    let hierarchy = Hierarchy::build(&first, |s| scene.surfaces[s].reflectance);
    let enclosures = Enclosures::new(scene, visibility);
    let (mut system, enclosed) = new_system(run, &first, &hierarchy, &direct, &enclosures);
    let clock = || figures.direct_seconds + started.elapsed().as_secs_f64();
    let (mut solved, mut stats) = solve_system(run, &mut system, &clock);
    figures.solve_seconds = started.elapsed().as_secs_f64();

    // The final gather, unless the run must stop: then each vertex keeps its leaf's value.
    let t = Instant::now();
    let gathering = Gathering::new(run, &system, &solved.field, &first);
    let (light, display_gain, stop) =
        gathering.first_mesh(&first, &direct, &enclosed, solved.stop, &mut stats);
    let PointLight {
        reflected,
        totals,
        first_b,
        ..
    } = light;
    figures.gather_seconds = t.elapsed().as_secs_f64();
    let mut current = Current {
        mesh: mesh.clone(),
        disc: first.clone(),
        direct,
        reflected,
        totals,
    };

    // Rounds of refinement: new vertices gather through the links of the first mesh's leaves.
    if !first_b.is_empty() {
        let rounds = Rounds {
            gathering: &gathering,
            exact: DirectLight::new(scene, visibility).with_overlay_cap(OVERLAY_CAP),
            locate: LeafLocator::new(mesh, &first, &hierarchy),
            enclosures: &enclosures,
            first_b: &first_b,
            display_gain,
        };
        current = rounds.run(current, refine, &mut figures, &mut stats)?;
    }
    solved.stop = stop;
    let closed = enclosed.iter().all(|&e| e);
    Ok(into_solution(
        scene, current, closed, solved, stats, &figures,
    ))
}

/// What a hierarchical solve works from, borrowed.
#[derive(Clone, Copy)]
struct Run<'a> {
    scene: &'a Scene,
    visibility: &'a Visibility,
    options: &'a SolverOptions,
    progress: &'a dyn Progress,
}

/// What the run did beside the hierarchy's own figures ([`HierarchyStats`]), for its
/// statistics: the time of each part, the direct light's estimates, the rounds of refinement.
#[derive(Debug, Default)]
struct Figures {
    direct_seconds: f64,
    /// Vertices of the first mesh whose direct light was estimated by rays: their view of a
    /// light needed a polygon difference beyond the evaluator's cap.
    direct_beyond_cap: usize,
    /// Building, linking and sweeping the hierarchy.
    solve_seconds: f64,
    gather_seconds: f64,
    remeshes: usize,
    /// Vertices that gathered: all of the first mesh's, and those each round added.
    gathered: usize,
}

/// The system of `hierarchy` over the first mesh `first`, whose leaves reflect their share of
/// the `direct` irradiance at its vertices, and whether each of those vertices lies inside a
/// closed solid.
fn new_system<'h>(
    run: Run,
    first: &Discretization,
    hierarchy: &'h Hierarchy,
    direct: &[Rgb],
    enclosures: &Enclosures,
) -> (System<'h>, Vec<bool>) {
    let (enclosed_leaves, enclosed) = totals::enclosed_leaves(
        first,
        &hierarchy.leaf_of_element,
        hierarchy.nodes.len(),
        enclosures,
    );
    let system = System::new(
        hierarchy,
        leaf_direct(run.scene, first, hierarchy, direct),
        enclosed_leaves,
        run.visibility.contact_distance(),
    );
    (system, enclosed)
}

/// Links the hierarchy of `system` and sweeps it to its solution ([`link_and_sweep`]), with
/// visibility from shafts; returns the solution and the hierarchy's figures. `clock` gives the
/// seconds since the run began.
fn solve_system(
    run: Run,
    system: &mut System,
    clock: &dyn Fn() -> f64,
) -> (Solved, HierarchyStats) {
    let options = run.options;
    let hierarchy = system.hierarchy;
    let shafts = Shafts::new(run.scene, run.visibility);
    let refiner = Refiner {
        hierarchy,
        shafts: &shafts,
        tolerance: options.link_tol * reflected_power(system),
        rays: options.visibility_rays,
        seed: options.seed,
        tol: system.tol,
        stop: Some(options),
    };
    let mut stats = HierarchyStats {
        link_tol: options.link_tol,
        elements: hierarchy.nodes.iter().filter(|n| !n.is_cluster()).count(),
        leaves: hierarchy.nodes.iter().filter(|n| n.is_leaf()).count(),
        clusters: system.clusters,
        ..HierarchyStats::default()
    };
    let solved = link_and_sweep(system, &refiner, options, &mut stats, clock, run.progress);
    link_figures(&mut stats, system);
    (solved, stats)
}

/// The final gather along the links of the solved hierarchy.
struct Gathering<'a> {
    run: Run<'a>,
    gather: FinalGather<'a>,
}

impl<'a> Gathering<'a> {
    /// The final gather along the links of `system`, solved to `field`, at vertices of meshes
    /// over the first mesh `first`.
    fn new(
        run: Run<'a>,
        system: &'a System<'a>,
        field: &'a Field,
        first: &'a Discretization,
    ) -> Gathering<'a> {
        let gather = FinalGather {
            system,
            field,
            visibility: run.visibility,
            elements: &first.elements,
            rays: run.options.visibility_rays,
            seed: run.options.seed,
        };
        Gathering { run, gather }
    }

    /// The final gather at every vertex of the first mesh `disc` (their `direct` irradiance,
    /// whether each is `enclosed`), with the ambient light that balances what the gather loses
    /// (returned too), and the reason the run stops, `stop` unless the gather must stop first:
    /// then each vertex keeps its leaf's value, with no ambient light.
    fn first_mesh(
        &self,
        disc: &Discretization,
        direct: &[Rgb],
        enclosed: &[bool],
        stop: StopReason,
        stats: &mut HierarchyStats,
    ) -> (PointLight, Rgb, StopReason) {
        let (system, field, options) = (self.gather.system, self.gather.field, self.run.options);
        let all: Vec<usize> = (0..disc.receiver_count()).collect();
        let leaves = vertex_leaves(disc, system.hierarchy);
        let mut stop = stop;
        let gathered = final_gather_at(
            disc,
            &all,
            &leaves,
            direct,
            enclosed,
            &self.gather,
            None,
            options,
            self.run.progress,
        );
        let mut light = gathered.unwrap_or_else(|| {
            stop = options.stop_now().unwrap_or(stop);
            leaf_values(&leaves, field, system)
        });
        stats.gather_rays += light.rays;
        let display_gain = if light.first_b.is_empty() {
            Rgb::ZERO
        } else {
            let (gain, lost) =
                balance::display_gain(system, field, disc, &light.reflected, &light.totals);
            stats.gather_lost = lost;
            gain
        };
        light.add_ambient(disc, &all, display_gain);
        (light, display_gain, stop)
    }
}

/// Rounds of refinement of the display mesh over the first mesh's hierarchy: a new vertex gets
/// the exact direct light and gathers along the links of the first mesh's leaf it lies in.
struct Rounds<'a> {
    gathering: &'a Gathering<'a>,
    exact: DirectLight<'a>,
    locate: LeafLocator<'a>,
    enclosures: &'a Enclosures<'a>,
    /// The reflected radiosity at the first mesh's vertices, for the gathers' near leaves.
    first_b: &'a [Rgb],
    /// The ambient light of the first mesh's gather, added at new vertices alike.
    display_gain: Rgb,
}

impl Rounds<'_> {
    /// The meshes `refine` gives after `current`, each with the light at its vertices, until it
    /// gives none; returns the last.
    fn run(
        &self,
        mut current: Current,
        refine: &mut dyn FnMut(&Round) -> Result<Option<SceneMesh>, SolveError>,
        figures: &mut Figures,
        stats: &mut HierarchyStats,
    ) -> Result<Current, SolveError> {
        while let Some(next) = refine(&current.round(&self.exact))? {
            check_mesh(self.gathering.run.scene, &next)?;
            current = self.refined(&current, next, figures, stats)?;
        }
        Ok(current)
    }

    /// The mesh `next`, a refinement of `current`'s, with the light at its vertices: carried
    /// over where a vertex matches one of `current`, found for the others.
    fn refined(
        &self,
        current: &Current,
        next: SceneMesh,
        figures: &mut Figures,
        stats: &mut HierarchyStats,
    ) -> Result<Current, SolveError> {
        let run = self.gathering.run;
        let disc = Discretization::new(run.scene, &next, run.options.elements_per_patch);
        let matching = disc.matching_receivers(&current.disc);
        let fresh = matching.fresh();
        let mut direct = matching.carry(&current.direct);
        let mut reflected = matching.carry(&current.reflected);
        let mut totals = matching.carry(&current.totals);
        let t = Instant::now();
        let new_direct = direct_at_new(&self.exact, &disc, &fresh, run.options, run.progress)?;
        figures.direct_seconds += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let light = self.gather_at(&disc, &fresh, &new_direct);
        stats.gather_rays += light.rays;
        figures.gather_seconds += t.elapsed().as_secs_f64();
        for (k, &v) in fresh.iter().enumerate() {
            direct[v] = new_direct[k];
            reflected[v] = light.reflected[k];
            totals[v] = light.totals[k];
        }
        figures.gathered += fresh.len();
        figures.remeshes += 1;
        Ok(Current {
            mesh: next,
            disc,
            direct,
            reflected,
            totals,
        })
    }

    /// The final gather at the `fresh` vertices of `disc` (their `direct` irradiance), with the
    /// ambient light. It does not stop for the deadline or an interrupt: every vertex of the
    /// mesh must have its light.
    fn gather_at(&self, disc: &Discretization, fresh: &[usize], direct: &[Rgb]) -> PointLight {
        let run = self.gathering.run;
        let leaves: Vec<u32> = fresh.iter().map(|&v| self.locate.leaf(disc, v)).collect();
        let enclosed: Vec<bool> = fresh
            .par_iter()
            .map(|&v| {
                self.enclosures
                    .encloses(&disc.receivers[v], disc.receiver_surface[v])
            })
            .collect();
        let unstoppable = SolverOptions {
            deadline: None,
            interrupt: None,
            ..run.options.clone()
        };
        let mut light = final_gather_at(
            disc,
            fresh,
            &leaves,
            direct,
            &enclosed,
            &self.gathering.gather,
            Some(self.first_b),
            &unstoppable,
            run.progress,
        )
        .unwrap_or_default();
        light.add_ambient(disc, fresh, self.display_gain);
        light
    }
}

/// The solution at the vertices of `current`, the last mesh, with the run's statistics and its
/// energy account ([`Account`]); `closed` says whether every vertex of the first mesh lies
/// inside a room.
fn into_solution(
    scene: &Scene,
    current: Current,
    closed: bool,
    solved: Solved,
    stats: HierarchyStats,
    figures: &Figures,
) -> (SceneMesh, Solution) {
    let disc = &current.disc;
    // A vertex in the dark gathers what its links carry to rounding, which may leave it a
    // few ulps below zero; no irradiance is negative.
    let irradiance: Vec<Rgb> = current
        .direct
        .iter()
        .zip(&current.reflected)
        .map(|(&d, &r)| (d + r).max(Rgb::ZERO))
        .collect();
    let account = Account {
        scene,
        disc,
        irradiance: &irradiance,
        totals: &current.totals,
        closed,
    };
    let solve_stats = SolveStats {
        stop: solved.stop,
        iterations: stats.sweeps,
        residual: solved.residual,
        direct_seconds: figures.direct_seconds,
        direct_estimated: figures.direct_beyond_cap,
        direct_beyond_cap: figures.direct_beyond_cap,
        shooting_seconds: figures.solve_seconds,
        remeshes: figures.remeshes,
        gathered: figures.gathered,
        gather_seconds: figures.gather_seconds,
        ..account.stats(solved.unshot, &stats)
    };
    let radiosity: Vec<Rgb> = (0..disc.receiver_count())
        .map(|v| disc.emission[v] + disc.reflectance[v].mul_rgb(irradiance[v]))
        .collect();
    let solution = Solution {
        radiosity: disc.per_surface(&radiosity),
        irradiance: disc.per_surface(&irradiance),
        direct_irradiance: disc.per_surface(&current.direct),
        ambient: Rgb::ZERO,
        stats: SolveStats {
            hierarchy: Some(stats),
            ..solve_stats
        },
        convergence: solved.history,
    };
    (current.mesh, solution)
}

/// The display mesh of the latest round and the light at its vertices, with each vertex's total.
struct Current {
    mesh: SceneMesh,
    disc: Discretization,
    direct: Vec<Rgb>,
    reflected: Vec<Rgb>,
    totals: Vec<f64>,
}

impl Current {
    fn round<'r>(&'r self, exact: &'r DirectLight<'r>) -> Round<'r> {
        let disc = &self.disc;
        let radiosity_of = |h: &dyn Fn(usize) -> Rgb| -> Vec<Vec<Rgb>> {
            let values: Vec<Rgb> = (0..disc.receiver_count())
                .map(|v| disc.emission[v] + disc.reflectance[v].mul_rgb(h(v)))
                .collect();
            disc.per_surface(&values)
        };
        Round {
            meshes: &self.mesh.surfaces,
            radiosity: radiosity_of(&|v| self.direct[v] + self.reflected[v]),
            direct: radiosity_of(&|v| self.direct[v]),
            direct_light: exact,
        }
    }
}

/// Finds the first mesh's leaf that holds a vertex of a refined mesh.
struct LeafLocator<'h> {
    mesh: &'h SceneMesh,
    locators: Vec<TriangleLocator>,
    /// Per surface and triangle of the first mesh, its leaf.
    leaf: Vec<Vec<u32>>,
}

impl<'h> LeafLocator<'h> {
    fn new(mesh: &'h SceneMesh, first: &Discretization, hierarchy: &Hierarchy) -> LeafLocator<'h> {
        let mut leaf: Vec<Vec<u32>> = mesh
            .surfaces
            .iter()
            .map(|m| vec![NONE; m.triangle_count()])
            .collect();
        for (e, el) in first.elements.iter().enumerate() {
            leaf[el.surface][el.triangle] = hierarchy.leaf_of_element[e];
        }
        LeafLocator {
            mesh,
            locators: mesh.surfaces.iter().map(TriangleLocator::new).collect(),
            leaf,
        }
    }

    /// The leaf of vertex `v` of `disc`, looked for a little way into its own triangles (a
    /// vertex on a contact line belongs to its own side).
    fn leaf(&self, disc: &Discretization, v: usize) -> u32 {
        let s = disc.receiver_surface[v];
        let m = &self.mesh.surfaces[s];
        let x = &disc.receivers[v];
        let nudge = LOCATE_NUDGE * m.scale;
        [x.point + x.inward * nudge, x.point]
            .iter()
            .find_map(|&p| self.locators[s].locate(m, m.frame.to_2d(p) / m.scale))
            .map_or(NONE, |(t, _)| self.leaf[s][t])
    }
}

/// How far into its own triangles a new vertex is looked for, in its surface's scale.
const LOCATE_NUDGE: f64 = 1e-9;

/// Each vertex's leaf's own irradiance and total (zero and one where it has no leaf): what a
/// vertex keeps when the run stops before the final gather.
fn leaf_values(leaves: &[u32], field: &Field, system: &System) -> PointLight {
    let (reflected, totals) = leaves
        .iter()
        .map(|&l| match l {
            NONE => (Rgb::ZERO, 1.0),
            l => (field.irradiance[l as usize], system.totals[l as usize]),
        })
        .unzip();
    PointLight {
        reflected,
        totals,
        ..PointLight::default()
    }
}

/// The power the leaves reflect of the direct light (W, channel mean): the light the hierarchy
/// carries in the first place.
fn reflected_power(system: &System) -> f64 {
    let h = system.hierarchy;
    h.nodes
        .iter()
        .enumerate()
        .filter(|(_, n)| n.is_leaf() && !n.is_cluster())
        .map(|(i, n)| system.direct[i].mean() * n.area)
        .sum()
}

/// What each leaf reflects of the exact direct light: ρ times the mean of its vertices' direct
/// irradiance (the integral of the linear interpolant over the triangle).
fn leaf_direct(
    scene: &Scene,
    disc: &Discretization,
    hierarchy: &Hierarchy,
    direct: &[Rgb],
) -> Vec<Rgb> {
    let mut out = vec![Rgb::ZERO; hierarchy.nodes.len()];
    for (e, &leaf) in hierarchy.leaf_of_element.iter().enumerate() {
        if leaf != NONE {
            let el = &disc.elements[e];
            let mean = el.vertices.iter().map(|&v| direct[v]).sum::<Rgb>() / 3.0;
            out[leaf as usize] = scene.surfaces[el.surface].reflectance.mul_rgb(mean);
        }
    }
    out
}

/// The hierarchy's solution, how it ended and how it got there.
struct Solved {
    field: Field,
    stop: StopReason,
    residual: f64,
    /// The leaves' power still to be propagated: Σ area × the last sweep's change (W).
    unshot: Rgb,
    history: Vec<ConvergencePoint>,
}

impl Solved {
    /// `field` before any sweep, with no history yet.
    fn new(field: Field) -> Solved {
        Solved {
            field,
            stop: StopReason::Converged,
            residual: 0.0,
            unshot: Rgb::ZERO,
            history: Vec::new(),
        }
    }
}

/// Links the hierarchy from its root, sweeps until the residual is below `epsilon`, judges the
/// links again with the new radiosities and refines those that carry too much light wrongly,
/// and sweeps again, until no link changes (or [`MAX_PASSES`], the sweep cap, the deadline or an
/// interrupt). `clock` gives the seconds since the run began.
fn link_and_sweep(
    system: &mut System,
    refiner: &Refiner,
    options: &SolverOptions,
    stats: &mut HierarchyStats,
    clock: &dyn Fn() -> f64,
    progress: &dyn Progress,
) -> Solved {
    // Before the first sweep none of the reflected light is gathered: a residual of one.
    let mut solved = Solved::new(system.initial_field());
    solved.history.push(ConvergencePoint {
        iteration: 0,
        residual: 1.0,
        seconds: clock(),
    });
    let Some(root) = system.hierarchy.root else {
        return solved;
    };
    let t = Instant::now();
    progress.start("linking", 1);
    let (links, counts) = refine_pair(refiner, root, root, &system.radiosities(&solved.field));
    progress.finish();
    add_counts(stats, counts);
    system.set_links(links, None);
    stats.link_seconds += t.elapsed().as_secs_f64();
    loop {
        let stop = timed_sweeps(system, &mut solved, options, stats, clock, progress);
        stats.refinement_passes += 1;
        if let Some(stop) = stop {
            solved.stop = stop;
            return solved;
        }
        let t = Instant::now();
        let relinked = (stats.refinement_passes < MAX_PASSES)
            .then(|| relink(refiner, system, &solved.field))
            .flatten();
        if let Some((links, counts, changed)) = relinked {
            add_counts(stats, counts);
            system.set_links(links, Some(&changed));
            stats.link_seconds += t.elapsed().as_secs_f64();
            continue;
        }
        // The links are final: the totals of the leaves whose links changed are found along
        // them, and the sweeps go on to the solution with those.
        let settled = system.settle_totals();
        stats.link_seconds += t.elapsed().as_secs_f64();
        let stop = settled
            .then(|| timed_sweeps(system, &mut solved, options, stats, clock, progress))
            .flatten();
        if let Some(stop) = stop {
            solved.stop = stop;
            return solved;
        }
        balance_energy(system, &mut solved, options, stats, clock, progress);
        return solved;
    }
}

/// [`sweep_until`], counting the sweeps and their time in `stats`.
fn timed_sweeps(
    system: &System,
    solved: &mut Solved,
    options: &SolverOptions,
    stats: &mut HierarchyStats,
    clock: &dyn Fn() -> f64,
    progress: &dyn Progress,
) -> Option<StopReason> {
    let t = Instant::now();
    let stop = sweep_until(system, solved, options, &mut stats.sweeps, clock, progress);
    stats.sweep_seconds += t.elapsed().as_secs_f64();
    stop
}

/// Corrects a converged solution by the light its links lose, received as ambient light
/// ([`balance`]): the response to that light is solved by the same sweeps, and added so that
/// what the leaves send is what they receive. Left as it is if the sweeps must stop first.
fn balance_energy(
    system: &mut System,
    solved: &mut Solved,
    options: &SolverOptions,
    stats: &mut HierarchyStats,
    clock: &dyn Fn() -> f64,
    progress: &dyn Progress,
) {
    let t = Instant::now();
    let direct = system.set_direct(system.ambient_source());
    let mut response = Solved::new(system.initial_field());
    let stop = sweep_until(
        system,
        &mut response,
        options,
        &mut stats.balance_sweeps,
        clock,
        progress,
    );
    system.set_direct(direct);
    if stop.is_none() {
        let (sent, received) = system.transport(&solved.field);
        stats.links_lost = 1.0 - received.mean() / sent.mean().max(f64::MIN_POSITIVE);
        let gain = balance::ambient_gain(system, &solved.field, &response.field);
        solved
            .field
            .add_scaled(&response.field, gain, &system.reflecting);
    }
    stats.sweep_seconds += t.elapsed().as_secs_f64();
}

/// Jacobi sweeps, each followed by the coarse correction ([`System::correct`]), until the
/// relative residual is below `epsilon`; `Some` reason if the sweeps must stop before that (the
/// sweep cap, the deadline, an interrupt). Should a correction ever make the residual grow, the
/// sweeps go on without it: plain sweeps are a contraction.
fn sweep_until(
    system: &System,
    solved: &mut Solved,
    options: &SolverOptions,
    sweeps: &mut usize,
    clock: &dyn Fn() -> f64,
    progress: &dyn Progress,
) -> Option<StopReason> {
    progress.start("sweeps", 1000);
    let goal = -options.epsilon.log10();
    let (mut correcting, mut previous) = (true, f64::INFINITY);
    let stop = loop {
        if let Some(reason) = options.stop_now() {
            break Some(reason);
        }
        if *sweeps >= options.max_shots {
            break Some(StopReason::ShotLimit);
        }
        let mut next = system.sweep(&solved.field);
        if correcting {
            system.correct(&solved.field, &mut next);
        }
        let (change, signed) = system.change(&solved.field, &next);
        correcting &= change <= previous;
        previous = change;
        solved.field = next;
        solved.residual = change;
        solved.unshot = signed;
        *sweeps += 1;
        solved.history.push(ConvergencePoint {
            iteration: *sweeps,
            residual: change,
            seconds: clock(),
        });
        progress.set(((-change.max(1e-300).log10() / goal).clamp(0.0, 1.0) * 1000.0) as u64);
        if change < options.epsilon {
            break None;
        }
    };
    progress.finish();
    stop
}

/// The energy account of a solution, each term from what the solution itself sends where: the
/// power absorbed, ∫ (1 − ρ) H, and the power sent out of the scene, ∫ B (1 − T) with T each
/// vertex's total (the share of its view that fronts of surfaces cover: one inside a room, what
/// the final gather's form factors sum to elsewhere). Nothing is a difference of other terms, so
/// emitted − absorbed − escaped − unshot measures the solution's own error. `closed` says
/// whether every vertex of the first mesh lies inside a room.
struct Account<'a> {
    scene: &'a Scene,
    disc: &'a Discretization,
    irradiance: &'a [Rgb],
    totals: &'a [f64],
    closed: bool,
}

impl Account<'_> {
    fn stats(&self, unshot: Rgb, stats: &HierarchyStats) -> SolveStats {
        let (scene, disc) = (self.scene, self.disc);
        let emitted = scene.emitted_power();
        let absorbed = disc.integrate(self.irradiance, |e| {
            Rgb::splat(1.0) - scene.surfaces[e.surface].reflectance
        });
        let radiosity: Vec<Rgb> = (0..disc.receiver_count())
            .map(|v| disc.emission[v] + disc.reflectance[v].mul_rgb(self.irradiance[v]))
            .collect();
        let open: Vec<f64> = self.totals.iter().map(|&t| 1.0 - t).collect();
        let escaped = disc.integrate_product(&radiosity, &open);
        SolveStats {
            patches: stats.leaves,
            receivers: disc.receiver_count(),
            rays_cast: stats.link_rays + stats.gather_rays,
            emitted,
            absorbed,
            unshot,
            escaped,
            unshot_fraction: unshot.mean().abs() / emitted.mean().max(f64::MIN_POSITIVE),
            closed: Some(self.closed),
            ..SolveStats::default()
        }
    }
}

fn add_counts(stats: &mut HierarchyStats, counts: RefineCounts) {
    stats.hidden_pairs += counts.hidden;
    stats.link_rays += counts.rays;
}

/// Counts of the links as they are.
fn link_figures(stats: &mut HierarchyStats, system: &System) {
    let h = system.hierarchy;
    stats.links = system.links.len();
    stats.links_partial = system.links.iter().filter(|l| l.partial).count();
    stats.links_open = stats.links - stats.links_partial;
    stats.links_with_clusters = system
        .links
        .iter()
        .filter(|l| h.node(l.receiver).is_cluster() || h.node(l.source).is_cluster())
        .count();
    let mut by_depth = Vec::new();
    for l in &system.links {
        let d = h.node(l.receiver).depth as usize;
        if by_depth.len() <= d {
            by_depth.resize(d + 1, 0);
        }
        by_depth[d] += 1;
    }
    stats.links_by_depth = by_depth;
    stats.link_bytes =
        (system.links.capacity() * size_of::<Link>() + system.first_link.capacity() * 4) as u64;
}

/// The links that replace the link from `s` to `r`, and what finding them counted; the children
/// of shallow pairs are refined in parallel, and collected in order.
fn refine_pair(
    refiner: &Refiner,
    r: u32,
    s: u32,
    state: &links::Radiosities,
) -> (Vec<Link>, RefineCounts) {
    let mut out = Vec::new();
    let mut counts = RefineCounts::default();
    refiner.refine(r, s, None, state, &mut out, &mut counts);
    (out, counts)
}

/// The links judged again with the radiosities of `field`: each link carrying more light wrongly
/// than the tolerance is refined; `None` when none is. With the links, what finding them counted
/// and the receivers whose links changed.
fn relink(
    refiner: &Refiner,
    system: &System,
    field: &Field,
) -> Option<(Vec<Link>, RefineCounts, Vec<u32>)> {
    let state = system.radiosities(field);
    let h = system.hierarchy;
    let splittable = |l: &Link| !(h.node(l.receiver).is_leaf() && h.node(l.source).is_leaf());
    let condemned: Vec<bool> = system
        .links
        .par_iter()
        .map(|l| splittable(l) && refiner.error_of(l, &state) > refiner.tolerance)
        .collect();
    if !condemned.iter().any(|&c| c) {
        return None;
    }
    // Only the condemned links are refined (in parallel); the others are copied as they are,
    // in order, so no more than the old and the new links are held at once.
    let condemned: Vec<usize> = (0..system.links.len()).filter(|&i| condemned[i]).collect();
    let parts: Vec<(Vec<Link>, RefineCounts)> = condemned
        .par_iter()
        .map(|&i| {
            let l = &system.links[i];
            refine_pair(refiner, l.receiver, l.source, &state)
        })
        .collect();
    let mut changed: Vec<u32> = condemned
        .iter()
        .map(|&i| system.links[i].receiver)
        .collect();
    changed.dedup();
    let added: usize = parts.iter().map(|p| p.0.len()).sum();
    let mut links = Vec::with_capacity(system.links.len() - condemned.len() + added);
    let mut counts = RefineCounts::default();
    let mut next = condemned.iter().zip(parts).peekable();
    for (i, l) in system.links.iter().enumerate() {
        match next.next_if(|(c, _)| **c == i) {
            Some((_, (part, c))) => {
                links.extend(part);
                counts.add(c);
            }
            None => links.push(*l),
        }
    }
    Some((links, counts, changed))
}

/// For each vertex, the leaf of the first element (in the discretization's order) that holds it;
/// `NONE` on surfaces that reflect nothing.
fn vertex_leaves(disc: &Discretization, hierarchy: &Hierarchy) -> Vec<u32> {
    let mut leaf = vec![NONE; disc.receiver_count()];
    for (e, el) in disc.elements.iter().enumerate() {
        let l = hierarchy.leaf_of_element[e];
        if l == NONE {
            continue;
        }
        for &v in &el.vertices {
            if leaf[v] == NONE {
                leaf[v] = l;
            }
        }
    }
    leaf
}

/// Gathers of the near leaves again with linear radiosities, after the first final gather (on
/// the Cornell box one pass gets nearest the path-traced reference; a second overshoots).
pub const LINEAR_PASSES: usize = 1;

/// What a final gather found at its points.
#[derive(Debug, Default)]
struct PointLight {
    /// The reflected irradiance at each point, scaled to its total.
    reflected: Vec<Rgb>,
    /// Each point's total: the share of its view that surfaces cover.
    totals: Vec<f64>,
    rays: u64,
    /// The reflected radiosity at every point, for later gathers (empty for those).
    first_b: Vec<Rgb>,
}

impl PointLight {
    /// Adds an ambient irradiance of `gain` times each point's total (points of `disc`, on
    /// surfaces that reflect).
    fn add_ambient(&mut self, disc: &Discretization, points: &[usize], gain: Rgb) {
        for (k, &v) in points.iter().enumerate() {
            if disc.reflectance[v].max_channel() <= 0.0 {
                continue;
            }
            let lift = gain * self.totals[k];
            self.reflected[k] += lift;
            if let Some(b) = self.first_b.get_mut(k) {
                *b += disc.reflectance[v].mul_rgb(lift);
            }
        }
    }
}

/// The final gather at `points` of `disc` (the `leaves` they lie in, their `direct`
/// irradiance, whether each is `enclosed` by a closed solid), in parallel and in order, with a
/// progress bar. Each point's light is scaled so that the form factors it gathered along sum to
/// its total: one where it is enclosed; elsewhere their own sum, at most one. Near leaves are
/// gathered again with linear radiosities from `linear` (the reflected radiosity at the first
/// mesh's vertices), or, when `None` (the points are all of the first mesh's vertices), from
/// this gather. `None` if the run must stop first.
#[allow(clippy::too_many_arguments)]
fn final_gather_at(
    disc: &Discretization,
    points: &[usize],
    leaves: &[u32],
    direct: &[Rgb],
    enclosed: &[bool],
    gather: &FinalGather,
    linear: Option<&[Rgb]>,
    options: &SolverOptions,
    progress: &dyn Progress,
) -> Option<PointLight> {
    let gather_at = |stage: &str, linear: Option<(&[Rgb], &[Gathered])>| {
        each_point(points, stage, options, progress, |k| {
            let v = points[k];
            if leaves[k] == NONE {
                return Gathered::default();
            }
            let x = &disc.receivers[v];
            let linear = linear.map(|(b, first)| (b, &first[k]));
            gather.irradiance(x, disc.receiver_surface[v], leaves[k], v as u64, linear)
        })
    };
    let mut values = gather_at("final gather", None)?;
    let totals: Vec<f64> = values
        .iter()
        .zip(enclosed)
        .map(|(g, &enclosed)| iterate::bounded(g.unit, enclosed))
        .collect();
    let scaled = |g: &Gathered, total: f64| {
        let sum = g.near + g.far;
        if g.unit > 0.0 {
            sum * (total / g.unit)
        } else {
            sum
        }
    };
    let mut rays: u64 = values.iter().map(|g| g.rays).sum();
    let own: Vec<Rgb>;
    let vertex_b = match linear {
        Some(b) => b,
        None => {
            own = points
                .iter()
                .zip(values.iter().zip(&totals))
                .zip(direct)
                .map(|((&v, (g, &t)), &d)| disc.reflectance[v].mul_rgb(d + scaled(g, t)))
                .collect();
            &own
        }
    };
    for _ in 0..LINEAR_PASSES {
        let near = gather_at("final gather, near leaves", Some((vertex_b, &values)))?;
        for (g, n) in values.iter_mut().zip(near) {
            g.near = n.near;
            rays += n.rays;
        }
    }
    let reflected: Vec<Rgb> = values
        .iter()
        .zip(&totals)
        .map(|(g, &t)| scaled(g, t))
        .collect();
    let first_b = match linear {
        Some(_) => Vec::new(),
        None => points
            .iter()
            .zip(&reflected)
            .zip(direct)
            .map(|((&v, &r), &d)| disc.reflectance[v].mul_rgb(d + r))
            .collect(),
    };
    Some(PointLight {
        reflected,
        totals,
        rays,
        first_b,
    })
}

/// `f` of each index into `points`, in parallel and in order, with a progress bar; `None` if the
/// run must stop first.
fn each_point<T: Send>(
    points: &[usize],
    stage: &str,
    options: &SolverOptions,
    progress: &dyn Progress,
    f: impl Fn(usize) -> T + Sync,
) -> Option<Vec<T>> {
    let n = points.len();
    progress.start(stage, n as u64);
    let done = AtomicU64::new(0);
    let values: Vec<Option<T>> = (0..n)
        .into_par_iter()
        .map(|v| {
            if options.stop_now().is_some() {
                return None;
            }
            let value = f(v);
            let d = done.fetch_add(1, Ordering::Relaxed);
            if d.is_multiple_of(256) {
                progress.set(d);
            }
            Some(value)
        })
        .collect();
    progress.finish();
    values.into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;
    use penumbra_meshing::mesh_scene_uniform;
    use penumbra_scenes::builtin;

    /// A scene meshed uniformly, with what a hierarchical solve of it starts from.
    struct Setup {
        scene: Scene,
        vis: Visibility,
        disc: Discretization,
        direct: Vec<Rgb>,
        hierarchy: Hierarchy,
        options: SolverOptions,
    }

    impl Setup {
        fn new(scene: Scene, triangles: usize, options: SolverOptions) -> Setup {
            let vis = Visibility::build(&scene);
            let mesh = mesh_scene_uniform(&scene, triangles).expect("meshes");
            let disc = Discretization::new(&scene, &mesh, options.elements_per_patch);
            let (direct, _) = direct_irradiance(&scene, &disc, &vis, &options, &NoProgress)
                .expect("direct light");
            let hierarchy = Hierarchy::build(&disc, |s| scene.surfaces[s].reflectance);
            Setup {
                scene,
                vis,
                disc,
                direct,
                hierarchy,
                options,
            }
        }

        /// The system with no leaf taken for enclosed.
        fn system(&self) -> System<'_> {
            System::new(
                &self.hierarchy,
                self.leaf_direct(),
                vec![false; self.hierarchy.nodes.len()],
                self.vis.contact_distance(),
            )
        }

        fn leaf_direct(&self) -> Vec<Rgb> {
            leaf_direct(&self.scene, &self.disc, &self.hierarchy, &self.direct)
        }

        /// Links `system` at `tolerance` (power) and sweeps it, as a run does.
        fn solve(&self, system: &mut System, tolerance: f64) -> (Solved, HierarchyStats) {
            let shafts = Shafts::new(&self.scene, &self.vis);
            let mut stats = HierarchyStats::default();
            let solved = link_and_sweep(
                system,
                &self.refiner(&shafts, tolerance),
                &self.options,
                &mut stats,
                &|| 0.0,
                &NoProgress,
            );
            (solved, stats)
        }

        fn refiner<'r>(&'r self, shafts: &'r Shafts, tolerance: f64) -> Refiner<'r> {
            Refiner {
                hierarchy: &self.hierarchy,
                shafts,
                tolerance,
                rays: self.options.visibility_rays,
                seed: self.options.seed,
                tol: self.vis.contact_distance(),
                stop: None,
            }
        }
    }

    /// The links between two faces of the unit cube carry its face-to-face form factors
    /// (`docs/closed-forms.md`, "Two rectangles"): Σ area × form factor over the links from one
    /// face's elements to the other's, over the first face's area.
    #[test]
    fn links_carry_the_unit_cubes_face_factors() {
        const OPPOSITE: f64 = 0.199_824_895_698_387;
        const ADJACENT: f64 = 0.200_043_776_075_403;
        let setup = Setup::new(builtin::furnace(1.0, 0.5), 1200, SolverOptions::default());
        let mut system = setup.system();
        setup.solve(&mut system, 1e-6 * setup.scene.emitted_power().mean());
        let (scene, hierarchy) = (&setup.scene, &setup.hierarchy);
        let n = scene.surfaces.len();
        let mut factors = vec![vec![0.0; n]; n];
        for l in &system.links {
            let (rn, sn) = (hierarchy.node(l.receiver), hierarchy.node(l.source));
            if let (Some(i), Some(j), links::Transfer::Factor { factor, .. }) =
                (rn.surface, sn.surface, l.transfer)
            {
                factors[i][j] += rn.area * factor / scene.surfaces[i].area();
            }
        }
        let mut worst = 0.0f64;
        for (i, row) in factors.iter().enumerate() {
            for (j, &f) in row.iter().enumerate() {
                let opposite = scene.surfaces[i].normal().dot(scene.surfaces[j].normal()) < -0.5;
                let expected = match (i == j, opposite) {
                    (true, _) => 0.0,
                    (false, true) => OPPOSITE,
                    (false, false) => ADJACENT,
                };
                worst = worst.max((f - expected).abs());
            }
        }
        eprintln!("worst face factor off by {worst:.2e}");
        assert!(worst < 1e-3, "{worst}");
    }

    /// On the Cornell box (open, so each leaf's total is its own links' sum), the balanced
    /// solution's leaves receive along their links what they send toward surfaces that reflect,
    /// to rounding, though the links alone lose some of it; and every leaf's form factors sum to
    /// its total after scaling.
    #[test]
    fn the_balanced_leaves_receive_what_they_send() {
        let setup = Setup::new(builtin::cornell(), 3000, SolverOptions::default());
        let mut system = setup.system();
        let tolerance = setup.options.link_tol * reflected_power(&system);
        let (solved, stats) = setup.solve(&mut system, tolerance);
        let hierarchy = &setup.hierarchy;
        let (sent, received) = system.transport(&solved.field);
        eprintln!(
            "links lost {:.3e} before the balance; sent {sent:?}, received {received:?}",
            stats.links_lost
        );
        assert!(stats.links_lost.abs() > 1e-5, "{}", stats.links_lost);
        for (s, r) in sent.to_array().into_iter().zip(received.to_array()) {
            assert!((s - r).abs() <= 1e-9 * s, "{s} sent, {r} received");
        }
        let sums = system.row_sums();
        for (i, n) in hierarchy.nodes.iter().enumerate() {
            if n.is_leaf() && !n.is_cluster() && sums[i] > 0.0 {
                let total = sums[i] * system.scale[i];
                assert!((total - system.totals[i]).abs() <= 1e-12, "{total}");
                assert!(system.totals[i] <= 1.0);
            }
        }
    }

    /// As the link tolerance shrinks, the leaves' radiosities approach those of the dense
    /// system the hierarchy stands for: every pair of leaves linked, with the same form factors
    /// and visibility, solved to rounding.
    #[test]
    fn shrinking_link_tolerance_approaches_the_dense_leaf_system() {
        let options = SolverOptions {
            epsilon: 1e-9,
            ..SolverOptions::default()
        };
        let setup = Setup::new(builtin::cornell(), 400, options);
        let (scene, hierarchy) = (&setup.scene, &setup.hierarchy);
        let shafts = Shafts::new(scene, &setup.vis);
        let leaves: Vec<u32> = (0..hierarchy.nodes.len() as u32)
            .filter(|&i| hierarchy.node(i).is_leaf())
            .collect();
        let e = setup.leaf_direct();
        let system = setup.system();
        let field = system.initial_field();
        let whole = setup.refiner(&shafts, f64::INFINITY);
        let rows: Vec<Vec<(usize, f64)>> = leaves
            .iter()
            .map(|&r| {
                let mut row = Vec::new();
                for (j, &s) in leaves.iter().enumerate() {
                    let mut links = Vec::new();
                    let mut counts = RefineCounts::default();
                    whole.refine(
                        r,
                        s,
                        None,
                        &system.radiosities(&field),
                        &mut links,
                        &mut counts,
                    );
                    for l in links {
                        if let links::Transfer::Factor { factor, .. } = l.transfer {
                            row.push((j, factor));
                        }
                    }
                }
                row
            })
            .collect();
        let mut b: Vec<Rgb> = leaves.iter().map(|&l| e[l as usize]).collect();
        for _ in 0..500 {
            for (i, row) in rows.iter().enumerate() {
                let gathered: Rgb = row.iter().map(|&(j, f)| b[j] * f).sum();
                let leaf = hierarchy.node(leaves[i]);
                b[i] = e[leaves[i] as usize] + leaf.reflectance.mul_rgb(gathered);
            }
        }
        let area: f64 = leaves.iter().map(|&l| hierarchy.node(l).area).sum();
        let mean = leaves
            .iter()
            .zip(&b)
            .map(|(&l, b)| b.mean() * hierarchy.node(l).area)
            .sum::<f64>()
            / area;
        let mut previous = f64::INFINITY;
        for tol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7] {
            let mut system = setup.system();
            let (solved, _) = setup.solve(&mut system, tol * scene.emitted_power().mean());
            let rms = (leaves
                .iter()
                .zip(&b)
                .map(|(&l, b)| {
                    (solved.field.b[l as usize] - *b).mean().powi(2) * hierarchy.node(l).area
                })
                .sum::<f64>()
                / area)
                .sqrt()
                / mean;
            eprintln!(
                "link tol {tol}: {} links, {rms:.6} of the mean from the dense system",
                system.links.len()
            );
            assert!(rms < previous, "{tol}: {rms} after {previous}");
            previous = rms;
        }
        assert!(previous < 1e-3, "{previous}");
    }
}
