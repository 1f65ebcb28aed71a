//! The exact direct light at the mesh vertices, shared by every solver: one evaluation per point
//! where faces of several surfaces meet, in parallel, with a progress bar; at a deadline the
//! vertices left are estimated by rays.

use std::collections::HashMap;
use std::sync::atomic::Ordering;
use std::time::Instant;

use glam::DVec3;
use penumbra_meshing::SceneMesh;
use penumbra_scenes::{Rgb, Scene, SurfaceId, Visibility};
use rayon::prelude::*;

use crate::direct::DirectLight;
use crate::elements::Discretization;
use crate::error::SolveError;
use crate::lambert::ReceivingPoint;
use crate::options::SolverOptions;
use crate::progress::{Interrupt, Progress};

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
pub(crate) fn direct_on(
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
    let wanted: Vec<usize> = (0..receivers.len())
        .filter(|&i| wanted(receivers[i]))
        .collect();
    let groups: Vec<(DVec3, Vec<usize>)> = shared_points(
        wanted.iter().map(|&i| disc.receivers[receivers[i]].point),
        direct.scene_diagonal(),
    )
    .into_iter()
    .map(|(at, members)| (at, members.into_iter().map(|k| wanted[k]).collect()))
    .collect();
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

/// The points of `points` that share one evaluation ([`SHARED_POINT`] of the scene's
/// `diagonal` apart at most): each the grid point they round to and their indices, in order of
/// first appearance, so that the work and its result do not depend on hashing.
pub fn shared_points(
    points: impl Iterator<Item = DVec3>,
    diagonal: f64,
) -> Vec<(DVec3, Vec<usize>)> {
    let mut groups: Vec<(DVec3, Vec<usize>)> = Vec::new();
    let mut at_point: HashMap<[i64; 3], usize> = HashMap::new();
    let quantum = SHARED_POINT * diagonal;
    let gridded = quantum > 0.0 && quantum.is_finite();
    for (i, p) in points.enumerate() {
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
    groups
}

/// The exact direct irradiance at each receiving point of a surface, in parallel, one
/// evaluation for the points that share one ([`shared_points`], [`DirectLight::irradiance_group`]):
/// each value is the one the direct-light pass gives a vertex there, to the bit. Also returns
/// how many points were evaluated.
pub fn irradiance_shared(
    direct: &DirectLight,
    points: &[(ReceivingPoint, SurfaceId)],
) -> (Vec<Rgb>, usize) {
    let groups = shared_points(points.iter().map(|(x, _)| x.point), direct.scene_diagonal());
    let values: Vec<Vec<Rgb>> = groups
        .par_iter()
        .map(|(at, members)| {
            let group: Vec<(ReceivingPoint, SurfaceId)> =
                members.iter().map(|&i| points[i]).collect();
            direct.irradiance_group(*at, &group)
        })
        .collect();
    let mut out = vec![Rgb::ZERO; points.len()];
    for ((_, members), values) in groups.iter().zip(values) {
        for (&i, h) in members.iter().zip(values) {
            out[i] = h;
        }
    }
    (out, groups.len())
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
pub(crate) fn irradiance_at(
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
