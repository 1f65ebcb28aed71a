//! Hierarchical radiosity with clustering on the discontinuity mesh (Hanrahan, Salzman &
//! Aupperle 1991; Smits, Arvo & Greenberg 1994; Sillion 1995; combined with discontinuity
//! meshing as in Lischinski, Tampieri & Greenberg 1993).
//!
//! 1. Every vertex of the display mesh gets the exact direct light, as in the other solvers; each
//!    triangle reflects its mean, exactly (the integral of the linear interpolant).
//! 2. The hierarchy ([`tree`]) is built over the mesh's triangles and the surfaces, and linked
//!    from the root cluster down, each link as coarse as the oracle allows ([`links`]), with
//!    visibility from shaft culling ([`shaft`]) and rays only where a shaft holds blockers.
//! 3. Jacobi sweeps with push–pull ([`iterate`]) carry the reflected light until the relative
//!    residual is below `epsilon`; the links are then judged again with the new radiosities,
//!    those carrying too much light wrongly are refined, and the sweeps go on, until no link
//!    changes.
//! 4. Every display vertex gathers the reflected light along the links of its leaf and the
//!    leaf's ancestors ([`final_gather`]).
//!
//! The light a link may carry wrongly is `link_tol` of the emitted power: a larger scene with the
//! same light gets links no finer where its light is weak, so the links grow about linearly with
//! the scene. Results do not depend on the thread count: every parallel step collects in order.

mod final_gather;
mod iterate;
mod links;
mod shaft;
mod transfer;
mod tree;

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use penumbra_meshing::SceneMesh;
use penumbra_scenes::{Rgb, Scene, Visibility};
use rayon::prelude::*;
use serde::Serialize;

use crate::elements::Discretization;
use crate::error::SolveError;
use crate::progress::Progress;
use crate::progressive::{
    ConvergencePoint, Solution, SolveStats, SolverOptions, StopReason, check_mesh,
    direct_irradiance,
};
use final_gather::{FinalGather, Gathered};
use iterate::{Field, System};
use links::{Link, RefineCounts, Refiner};
use shaft::Shafts;
use tree::{Hierarchy, NONE};

/// The light a link may carry wrongly by default, as a fraction of the emitted power.
pub const DEFAULT_LINK_TOL: f64 = 1e-5;

/// Refinement passes at most: link, solve, refine the links the new radiosities condemn, solve
/// again.
pub const MAX_PASSES: usize = 6;

/// Figures of a hierarchical solve, under `solver.hierarchy` in `report.json`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct HierarchyStats {
    pub link_tol: f64,
    /// Element nodes (parts of surfaces), of which leaves (the mesh's triangles).
    pub elements: usize,
    pub leaves: usize,
    pub clusters: usize,
    pub links: usize,
    /// Links by visibility: open (no blocker in the shaft), partial (rays decide).
    pub links_open: usize,
    pub links_partial: usize,
    /// Links from or to a cluster.
    pub links_with_clusters: usize,
    /// Links by the depth of their receiver (0: the root cluster).
    pub links_by_depth: Vec<usize>,
    /// Pairs of nodes found hidden by one polygon, and not linked.
    pub hidden_pairs: u64,
    pub refinement_passes: usize,
    /// Rays for the links' visibility, and for the final gather's partial links.
    pub link_rays: u64,
    pub gather_rays: u64,
    /// Jacobi sweeps, over all passes.
    pub sweeps: usize,
    pub link_seconds: f64,
    pub sweep_seconds: f64,
    /// Bytes held by the links.
    pub link_bytes: u64,
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
    options.validate()?;
    check_mesh(scene, mesh)?;
    let started = Instant::now();
    let disc = Discretization::new(scene, mesh, options.elements_per_patch);
    let (direct, direct_beyond_cap) =
        direct_irradiance(scene, &disc, visibility, options, progress)?;
    let direct_seconds = started.elapsed().as_secs_f64();

    let started = Instant::now();
    let hierarchy = Hierarchy::build(&disc, |s| scene.surfaces[s].reflectance);
    let mut leaf_direct = vec![Rgb::ZERO; hierarchy.nodes.len()];
    for (e, &leaf) in hierarchy.leaf_of_element.iter().enumerate() {
        if leaf != NONE {
            let el = &disc.elements[e];
            let mean = el.vertices.iter().map(|&v| direct[v]).sum::<Rgb>() / 3.0;
            leaf_direct[leaf as usize] = scene.surfaces[el.surface].reflectance.mul_rgb(mean);
        }
    }
    let mut system = System::new(&hierarchy, leaf_direct);
    let shafts = Shafts::new(scene, visibility);
    let emitted = scene.emitted_power();
    let refiner = Refiner {
        hierarchy: &hierarchy,
        shafts: &shafts,
        tolerance: options.link_tol * emitted.mean(),
        rays: options.visibility_rays,
        seed: options.seed,
        tol: visibility.contact_distance(),
    };
    let mut stats = HierarchyStats {
        link_tol: options.link_tol,
        elements: hierarchy.nodes.iter().filter(|n| !n.is_cluster()).count(),
        leaves: hierarchy.nodes.iter().filter(|n| n.is_leaf()).count(),
        clusters: system.clusters,
        ..HierarchyStats::default()
    };
    let mut field = system.initial_field();
    let mut history = Vec::new();
    let mut stop;
    let mut residual = f64::INFINITY;
    let mut link_seconds = 0.0;
    let mut sweep_seconds = 0.0;
    if let Some(root) = hierarchy.root {
        let t = Instant::now();
        progress.start("linking", 1);
        let (links, counts) = refine_pair(&refiner, root, root, &system.radiosities(&field));
        progress.finish();
        add_counts(&mut stats, counts);
        system.set_links(links);
        link_seconds += t.elapsed().as_secs_f64();
        'passes: loop {
            let t = Instant::now();
            progress.start("sweeps", 1000);
            let goal = -options.epsilon.log10();
            loop {
                if let Some(reason) = options.stop_now() {
                    stop = reason;
                    break 'passes;
                }
                if stats.sweeps >= options.max_shots {
                    stop = StopReason::ShotLimit;
                    break 'passes;
                }
                let next = system.sweep(&field);
                let (change, _) = system.change(&field, &next);
                field = next;
                stats.sweeps += 1;
                residual = change;
                history.push(ConvergencePoint {
                    iteration: stats.sweeps,
                    residual,
                    seconds: direct_seconds + started.elapsed().as_secs_f64(),
                });
                progress
                    .set(((-residual.max(1e-300).log10() / goal).clamp(0.0, 1.0) * 1000.0) as u64);
                if residual < options.epsilon {
                    stop = StopReason::Converged;
                    break;
                }
            }
            progress.finish();
            sweep_seconds += t.elapsed().as_secs_f64();
            stats.refinement_passes += 1;
            if stats.refinement_passes >= MAX_PASSES {
                break;
            }
            let t = Instant::now();
            let relinked = relink(&refiner, &system, &field);
            link_seconds += t.elapsed().as_secs_f64();
            match relinked {
                Some((links, counts)) => {
                    add_counts(&mut stats, counts);
                    system.set_links(links);
                }
                None => break,
            }
        }
    } else {
        stop = StopReason::Converged;
        residual = 0.0;
    }
    stats.link_seconds = link_seconds;
    stats.sweep_seconds = sweep_seconds;
    link_figures(&mut stats, &system);
    let solve_seconds = started.elapsed().as_secs_f64();

    // The final gather, unless the run must stop: then each vertex keeps its leaf's value.
    let t = Instant::now();
    let vertex_leaf = vertex_leaves(&disc, &hierarchy);
    let quick: Vec<Rgb> = vertex_leaf
        .iter()
        .map(|&l| {
            if l == NONE {
                Rgb::ZERO
            } else {
                field.irradiance[l as usize]
            }
        })
        .collect();
    let gather = FinalGather {
        system: &system,
        field: &field,
        visibility,
        elements: &disc.elements,
        rays: options.visibility_rays,
        seed: options.seed,
    };
    let gathered = if options.stop_now().is_some() {
        None
    } else {
        final_gather_all(&disc, &vertex_leaf, &direct, &gather, options, progress)
    };
    let reflected = match gathered {
        Some((values, rays)) => {
            stats.gather_rays = rays;
            values
        }
        None => {
            stop = options.stop_now().unwrap_or(stop);
            quick
        }
    };
    let gather_seconds = t.elapsed().as_secs_f64();

    let irradiance: Vec<Rgb> = direct
        .iter()
        .zip(&reflected)
        .map(|(&d, &r)| d + r)
        .collect();
    let radiosity: Vec<Rgb> = (0..disc.receiver_count())
        .map(|v| disc.emission[v] + disc.reflectance[v].mul_rgb(irradiance[v]))
        .collect();
    let absorbed = disc.integrate(&irradiance, |e| {
        Rgb::splat(1.0) - scene.surfaces[e.surface].reflectance
    });
    let reflected_power = disc.integrate(&irradiance, |e| scene.surfaces[e.surface].reflectance);
    let received = disc.integrate(&irradiance, |_| Rgb::splat(1.0));
    let sent: Rgb = hierarchy
        .nodes
        .iter()
        .enumerate()
        .filter(|(_, n)| n.is_leaf() && !n.is_cluster())
        .map(|(i, n)| field.b[i] * n.area)
        .sum();
    let unshot = reflected_power - sent;
    let solve_stats = SolveStats {
        stop,
        shots: 0,
        iterations: stats.sweeps,
        residual: if residual.is_finite() { residual } else { 1.0 },
        patches: stats.leaves,
        receivers: disc.receiver_count(),
        rays_cast: stats.link_rays + stats.gather_rays,
        emitted,
        absorbed,
        unshot,
        escaped: emitted + sent - received,
        unshot_fraction: unshot.mean().abs() / emitted.mean().max(f64::MIN_POSITIVE),
        direct_seconds,
        direct_estimated: direct_beyond_cap,
        direct_beyond_cap,
        shooting_seconds: solve_seconds,
        remeshes: 0,
        gathered: disc.receiver_count(),
        gather_seconds,
        hierarchy: Some(stats),
    };
    Ok(Solution {
        radiosity: disc.per_surface(&radiosity),
        irradiance: disc.per_surface(&irradiance),
        ambient: Rgb::ZERO,
        stats: solve_stats,
        convergence: history,
    })
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
/// than the tolerance is refined; `None` when none is.
fn relink(refiner: &Refiner, system: &System, field: &Field) -> Option<(Vec<Link>, RefineCounts)> {
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
    let parts: Vec<(Vec<Link>, RefineCounts)> = system
        .links
        .par_iter()
        .zip(&condemned)
        .map(|(l, &c)| {
            if c {
                refine_pair(refiner, l.receiver, l.source, &state)
            } else {
                (vec![*l], RefineCounts::default())
            }
        })
        .collect();
    let mut links = Vec::new();
    let mut counts = RefineCounts::default();
    for (part, c) in parts {
        links.extend(part);
        counts.add(c);
    }
    Some((links, counts))
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

/// Gathers of the near leaves again with linear radiosities, after the first final gather.
pub const LINEAR_PASSES: usize = 2;

/// The final gather at every vertex, in parallel and in order, with a progress bar, and the
/// rays it cast; `None` if the run must stop first. `direct` is the direct irradiance at every
/// vertex.
fn final_gather_all(
    disc: &Discretization,
    vertex_leaf: &[u32],
    direct: &[Rgb],
    gather: &FinalGather,
    options: &SolverOptions,
    progress: &dyn Progress,
) -> Option<(Vec<Rgb>, u64)> {
    let gather_at = |stage: &str, linear: Option<(&[Rgb], &[Gathered])>| {
        each_vertex(disc, stage, options, progress, |v| {
            let leaf = vertex_leaf[v];
            if leaf == NONE || disc.reflectance[v].max_channel() <= 0.0 {
                return Gathered::default();
            }
            let x = &disc.receivers[v];
            let linear = linear.map(|(b, first)| (b, &first[v]));
            gather.irradiance(x, disc.receiver_surface[v], leaf, v as u64, linear)
        })
    };
    let mut values = gather_at("final gather", None)?;
    let mut rays: u64 = values.iter().map(|g| g.rays).sum();
    let passes = std::env::var("LP")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(LINEAR_PASSES);
    for _ in 0..passes {
        let vertex_b: Vec<Rgb> = (0..disc.receiver_count())
            .map(|v| disc.reflectance[v].mul_rgb(direct[v] + values[v].near + values[v].far))
            .collect();
        let near = gather_at("final gather, near leaves", Some((&vertex_b, &values)))?;
        for (g, n) in values.iter_mut().zip(near) {
            g.near = n.near;
            rays += n.rays;
        }
    }
    Some((values.iter().map(|g| g.near + g.far).collect(), rays))
}

/// `f` at every vertex, in parallel and in order, with a progress bar; `None` if the run must
/// stop first.
fn each_vertex<T: Send>(
    disc: &Discretization,
    stage: &str,
    options: &SolverOptions,
    progress: &dyn Progress,
    f: impl Fn(usize) -> T + Sync,
) -> Option<Vec<T>> {
    let n = disc.receiver_count();
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
mod debug_tests {
    use super::*;
    use penumbra_meshing::mesh_scene_uniform;
    use penumbra_scenes::builtin;

    #[test]
    fn corner_sum() {
        let scene = builtin::furnace(1.0, 0.5);
        let vis = Visibility::build(&scene);
        let mesh = mesh_scene_uniform(&scene, 1200).unwrap();
        let disc = Discretization::new(&scene, &mesh, 24);
        let hierarchy = Hierarchy::build(&disc, |s| scene.surfaces[s].reflectance);
        let leaf_direct = vec![Rgb::splat(0.5); hierarchy.nodes.len()];
        let mut system = System::new(&hierarchy, leaf_direct);
        let shafts = Shafts::new(&scene, &vis);
        let refiner = Refiner {
            hierarchy: &hierarchy,
            shafts: &shafts,
            tolerance: 1e-5 * 6.0,
            rays: 16,
            seed: 1,
            tol: vis.contact_distance(),
        };
        let field = system.initial_field();
        let root = hierarchy.root.unwrap();
        let (links, _) = refine_pair(&refiner, root, root, &system.radiosities(&field));
        system.set_links(links);
        let leaves = vertex_leaves(&disc, &hierarchy);
        let mut rows = vec![];
        for (i, n) in hierarchy.nodes.iter().enumerate() {
            if !n.is_leaf() {
                continue;
            }
            let mut sum = 0.0;
            for node in hierarchy.ancestry(i as u32) {
                for l in system.links_of(node) {
                    match l.transfer {
                        links::Transfer::Factor { factor, .. } => sum += factor,
                        _ => sum += 1000.0,
                    }
                }
            }
            rows.push((sum, n.centroid, n.surface));
        }
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        for r in rows.iter().take(4).chain(rows.iter().rev().take(6)) {
            eprintln!("row {:?}", r);
        }
        let worst = hierarchy
            .nodes
            .iter()
            .position(|n| n.is_leaf() && n.centroid.distance(rows.last().unwrap().1) < 1e-12)
            .unwrap();
        let mut per = vec![0.0; 6];
        for node in hierarchy.ancestry(worst as u32) {
            for l in system.links_of(node) {
                let sn = hierarchy.node(l.source);
                if let links::Transfer::Factor { factor, spread } = l.transfer {
                    per[sn.surface.unwrap()] += factor;
                    if factor > 0.01 {
                        eprintln!(
                            "  recv depth {} src {} depth {} leaf {} c {:?} r {:.3} F {factor:.4} spread {spread:.4} partial {}",
                            hierarchy.node(node).depth,
                            l.source,
                            sn.depth,
                            sn.is_leaf(),
                            sn.centroid,
                            sn.radius,
                            l.partial
                        );
                    }
                }
            }
        }
        eprintln!("per surface {:?}", per);
        let mut ranges = vec![];
        for node in hierarchy.ancestry(worst as u32) {
            for l in system.links_of(node) {
                let sn = hierarchy.node(l.source);
                if sn.surface == Some(4) {
                    ranges.push((sn.first, sn.end, sn.area, l.source));
                }
            }
        }
        ranges.sort_by_key(|r| (r.0, r.1));
        let area: f64 = ranges.iter().map(|r| r.2).sum();
        eprintln!("wall sources {} area {area}", ranges.len());
        {
            let tol = vis.contact_distance();
            let rn = hierarchy.node(worst as u32);
            let t = hierarchy.triangles[rn.first as usize].points;
            let mut diffs = vec![];
            for node in hierarchy.ancestry(worst as u32) {
                for l in system.links_of(node) {
                    if let links::Transfer::Factor { factor, .. } = l.transfer {
                        let at = |p: glam::DVec3| {
                            transfer::point_factor(
                                &hierarchy,
                                &crate::lambert::ReceivingPoint::interior(p, rn.normal),
                                l.source,
                                tol,
                            )
                        };
                        let own = transfer::triangle_mean(&t, &at, 4);
                        diffs.push((
                            factor - own,
                            factor,
                            own,
                            hierarchy.node(node).depth,
                            l.source,
                            hierarchy.node(l.source).surface,
                        ));
                    }
                }
            }
            let total: f64 = diffs.iter().map(|d| d.0).sum();
            diffs.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()));
            eprintln!("total diff {total}");
            for d in diffs.iter().take(8) {
                eprintln!("diff {:?}", d);
            }
        }
        let wall_root = {
            let mut n = ranges[0].3;
            while hierarchy.node(n).parent != NONE
                && hierarchy.node(hierarchy.node(n).parent).surface == Some(4)
            {
                n = hierarchy.node(n).parent;
            }
            n
        };
        for (p, _) in hierarchy.quadrature(worst as u32) {
            let tol = vis.contact_distance();
            let x =
                crate::lambert::ReceivingPoint::interior(p, hierarchy.node(worst as u32).normal);
            let exact = crate::lambert::form_factor(&x, &scene.surfaces[4].polygon, tol);
            let pf = transfer::point_factor(&hierarchy, &x, wall_root, tol);
            let links_sum: f64 = ranges
                .iter()
                .map(|r| transfer::point_factor(&hierarchy, &x, r.3, tol))
                .sum();
            eprintln!("point {p:?}: exact {exact} root {pf} links {links_sum}");
        }
        for w in ranges.windows(2) {
            if w[0].1 > w[1].0 {
                eprintln!("overlap {:?} {:?}", w[0], w[1]);
            }
        }
        let rn = hierarchy.node(worst as u32);
        let tol = vis.contact_distance();
        let t = hierarchy.triangles[rn.first as usize].points;
        eprintln!("receiver tri {:?}", t);
        for src in [483u32, 481] {
            eprintln!(
                "src tri {:?}",
                hierarchy.triangles[hierarchy.node(src).first as usize].points
            );
            let at = |p: glam::DVec3| {
                transfer::point_factor(
                    &hierarchy,
                    &crate::lambert::ReceivingPoint::interior(p, rn.normal),
                    src,
                    tol,
                )
            };
            for d in 0..7 {
                eprintln!("depth {d}: {}", transfer::triangle_mean(&t, &at, d));
            }
            let mut rng = penumbra_scenes::rng::SplitMix64::new(3);
            let mut sum = 0.0;
            let n = 200000;
            for _ in 0..n {
                let (r1, r2) = (rng.next_f64().sqrt(), rng.next_f64());
                let p = t[0] * (1.0 - r1) + t[1] * (r1 * (1.0 - r2)) + t[2] * (r1 * r2);
                sum += at(p);
            }
            eprintln!("mc {}", sum / n as f64);
        }
        let tol = vis.contact_distance();
        for v in 0..disc.receiver_count() {
            let x = &disc.receivers[v];
            if x.point.length() > 1e-9 {
                continue;
            }
            let mut sum = 0.0;
            let mut per_surface = vec![0.0; 6];
            for node in hierarchy.ancestry(leaves[v]) {
                for l in system.links_of(node) {
                    let f = transfer::point_factor(&hierarchy, x, l.source, tol);
                    sum += f;
                    per_surface[hierarchy.node(l.source).surface.unwrap()] += f;
                }
            }
            eprintln!(
                "vertex {v} surface {} inward {:?}: {sum} {:?}",
                disc.receiver_surface[v], x.inward, per_surface
            );
        }
    }
}
