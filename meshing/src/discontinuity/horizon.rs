//! The emitter's own plane, where it cuts a receiver. Behind that plane no light comes; in front
//! of it the emitter is seen at an angle that grows from zero, so the light's slope jumps there
//! (order 1): an umbra boundary that no blocker casts (the walls of a box whose light hangs just
//! under the ceiling). It is kept where points on it see the emitter, edge-on, past other
//! geometry.

use glam::DVec3;

use super::pair::PairGeometry;
use super::trim::runs_where;
use super::{clip_to_polygon, emitter_samples};

/// One emitter and one receiver, and how to trim what the emitter's plane leaves on it.
pub(crate) struct Horizon<'a> {
    pub pair: PairGeometry<'a>,
    pub emitter_polygon: &'a [DVec3],
    pub receiver_polygon: &'a [DVec3],
    pub trim_samples: usize,
    /// Trim points are located to this fraction of the receiver's diameter.
    pub trim_fraction: f64,
}

impl Horizon<'_> {
    /// The segments where the emitter's plane cuts the receiver and the emitter is seen.
    pub(super) fn segments(&self) -> Vec<[DVec3; 2]> {
        let ef = &self.pair.emitter_frame;
        let p = self.receiver_polygon;
        let heights: Vec<f64> = p.iter().map(|&q| ef.height(q)).collect();
        let (lo, hi) = heights
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &h| {
                (lo.min(h), hi.max(h))
            });
        if !(lo < -self.pair.tol && hi > self.pair.tol) {
            return Vec::new();
        }
        let Some(along) = ef
            .normal
            .cross(self.pair.receiver_frame.normal)
            .try_normalize()
        else {
            return Vec::new();
        };
        // A point of both planes: where an edge of the receiver crosses the emitter's plane.
        let n = p.len();
        let Some(anchor) = (0..n).find_map(|i| {
            let (hi, hj) = (heights[i], heights[(i + 1) % n]);
            ((hi > 0.0) != (hj > 0.0)).then(|| p[i].lerp(p[(i + 1) % n], hi / (hi - hj)))
        }) else {
            return Vec::new();
        };
        let (a, b) = (
            anchor - along * self.pair.reach,
            anchor + along * self.pair.reach,
        );
        let trim_tolerance = self.trim_fraction * penumbra_scenes::polygon::diameter(p);
        // A point on the emitter's plane looks at the emitter edge-on.
        let samples = emitter_samples(self.emitter_polygon);
        let sees_emitter = |x: DVec3| {
            samples.iter().any(|&y| {
                !self
                    .pair
                    .visibility
                    .occluded(x, y, [self.pair.receiver, self.pair.emitter])
            })
        };
        clip_to_polygon(&self.pair.receiver_frame, p, a, b)
            .into_iter()
            .flat_map(|[s, t]| runs_where(s, t, self.trim_samples, trim_tolerance, sees_emitter))
            .collect()
    }
}
