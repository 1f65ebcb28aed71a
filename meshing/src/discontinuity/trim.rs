//! Trimming: a wedge's line on a receiver is a discontinuity only where the ray that generates it
//! really passes — from the emitter, grazing the blocker, to the receiver — without other geometry
//! in the way. Samples along the segment find the visible runs; bisection places their ends.

use glam::DVec3;
use penumbra_scenes::{SurfaceId, Visibility};

use super::wedge::Wedge;

/// Whether the generating ray of `wedge` through the receiver point `x` is unobstructed.
pub(super) fn generator_visible(
    visibility: &Visibility,
    wedge: &Wedge,
    x: DVec3,
    receiver: SurfaceId,
) -> bool {
    let (graze, source) = wedge.generator(x);
    // Hits within the contact distance of the grazing point are the blocker feature itself.
    !visibility.occluded(x, graze, [receiver, receiver])
        && !visibility.occluded(graze, source, [wedge.emitter, wedge.emitter])
}

/// Whether the generating ray of `wedge` through the receiver point `x` is unobstructed when it
/// also passes the blocker edge `edge` (a wedge between two blockers): piece by piece, from `x`
/// to the vertex and the edge's point in the order the ray meets them, to the emitter.
pub(super) fn generator_visible_past(
    visibility: &Visibility,
    wedge: &Wedge,
    x: DVec3,
    receiver: SurfaceId,
    edge: [DVec3; 2],
) -> bool {
    let (graze, source) = wedge.generator(x);
    let on_edge = super::wedge::line_meet(x, graze, edge[0], edge[1]);
    let [near, far] = if x.distance_squared(on_edge) < x.distance_squared(graze) {
        [on_edge, graze]
    } else {
        [graze, on_edge]
    };
    !visibility.occluded(x, near, [receiver, receiver])
        && !visibility.occluded(near, far, [receiver, receiver])
        && !visibility.occluded(far, source, [wedge.emitter, wedge.emitter])
}

/// The runs of `from -> to` where `holds`, with ends located to `tol` (a length) by bisection.
/// `samples` points along the segment find the runs.
pub(super) fn runs_where(
    from: DVec3,
    to: DVec3,
    samples: usize,
    tol: f64,
    holds: impl Fn(DVec3) -> bool,
) -> Vec<[DVec3; 2]> {
    let samples = samples.max(2);
    let at = |t: f64| from.lerp(to, t);
    let visible = |t: f64| holds(at(t));
    let length = from.distance(to);
    // Where the visibility changes between two parameters, to within `tol`.
    let bisect = |mut lo: f64, mut hi: f64, lo_visible: bool| {
        while (hi - lo) * length > tol {
            let mid = 0.5 * (lo + hi);
            if visible(mid) == lo_visible {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        if lo_visible { lo } else { hi }
    };
    // Samples at the cell centres of `samples` equal cells: the ends themselves sit on other
    // geometry (the receiver's boundary) and are decided by their neighbourhood.
    let params: Vec<f64> = (0..samples)
        .map(|k| (k as f64 + 0.5) / samples as f64)
        .collect();
    let states: Vec<bool> = params.iter().map(|&t| visible(t)).collect();
    let mut runs = Vec::new();
    let mut start: Option<f64> = None;
    for k in 0..samples {
        let t = params[k];
        match (states[k], start) {
            (true, None) => {
                start = Some(if k == 0 {
                    0.0
                } else {
                    bisect(params[k - 1], t, false)
                });
            }
            (false, Some(s)) => {
                runs.push([s, bisect(params[k - 1], t, true)]);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        runs.push([s, 1.0]);
    }
    runs.into_iter()
        .filter(|[a, b]| (b - a) * length > tol)
        .map(|[a, b]| [at(a), at(b)])
        .collect()
}
