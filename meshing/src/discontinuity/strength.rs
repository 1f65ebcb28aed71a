//! Which blockers' events are worth constraints. A tessellated statue puts thousands of small
//! faces into a shaft; each starts events, and most of them change the light by almost nothing
//! or over less than an element. A blocker patch (see [`super::patches`]) keeps its events on a
//! receiver only when
//! - its **share**, the fraction of the emitter's area it can hide from the receiver's point
//!   nearest to it (where its shadow is largest), is at least the event tolerance: the events of
//!   a weaker patch change the direct light by less than that share of the emitter's light
//!   anywhere, and
//! - its **footprint**, the extent of its whole shadow (umbra and penumbra) on the receiver's
//!   plane, is at least the receiver's element size: a smaller shadow lies within an element,
//!   where constraints would only make slivers.
//!
//! Weaker events are left to the mesh's grading and to adaptive refinement; the search counts
//! them and reports the largest share it dropped.

use glam::{DVec2, DVec3};
use penumbra_scenes::{PlaneFrame, Scene, SurfaceId};

use penumbra_scenes::polygon::closest_point_in_polygon;

/// What a blocker patch can do on a receiver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PatchStrength {
    /// Largest fraction of the emitter's area the patch can hide (1 when it cannot be bounded:
    /// the patch reaches the receiver's side of the point or beyond the emitter's plane).
    pub share: f64,
    /// Diagonal of the box around the patch's shadow on the receiver's plane (infinite when
    /// unbounded).
    pub footprint: f64,
}

/// A receiver and an emitter that face each other, in their own frames.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pair<'a> {
    pub scene: &'a Scene,
    pub emitter: SurfaceId,
    pub emitter_frame: &'a PlaneFrame,
    pub receiver: SurfaceId,
    pub receiver_frame: &'a PlaneFrame,
}

impl Pair<'_> {
    /// The strength of a patch with these corners (the points its outline turns at) on this
    /// pair's receiver.
    pub(super) fn strength(&self, corners: &[DVec3]) -> PatchStrength {
        PatchStrength {
            share: self.share(corners),
            footprint: self.footprint(corners),
        }
    }

    /// The area of the hull of the patch's corners projected from the receiver's nearest point
    /// onto the emitter's plane (at least the patch's own projection), over the emitter's area.
    fn share(&self, corners: &[DVec3]) -> f64 {
        let (ef, rf) = (self.emitter_frame, self.receiver_frame);
        let centroid = corners.iter().copied().sum::<DVec3>() / corners.len().max(1) as f64;
        let outline: Vec<DVec2> = self.scene.surfaces[self.receiver]
            .polygon
            .iter()
            .map(|&p| rf.to_2d(p))
            .collect();
        let x = rf.to_3d(closest_point_in_polygon(&outline, rf.to_2d(centroid)));
        let h_x = ef.height(x);
        let mut projected = Vec::with_capacity(corners.len());
        for &p in corners {
            let h = ef.height(p);
            if !(h >= 0.0 && h < h_x) {
                return 1.0;
            }
            projected.push(ef.to_2d(x + (p - x) * (h_x / (h_x - h))));
        }
        (hull_area(projected) / self.scene.surfaces[self.emitter].area()).min(1.0)
    }

    /// The box around the patch's shadows from every emitter corner on the receiver's plane.
    fn footprint(&self, corners: &[DVec3]) -> f64 {
        let rf = self.receiver_frame;
        let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
        for &a in &self.scene.surfaces[self.emitter].polygon {
            let h_a = rf.height(a);
            for &p in corners {
                let h = rf.height(p);
                if !(h < h_a) {
                    return f64::INFINITY;
                }
                let q = rf.to_2d(a + (p - a) * (h_a / (h_a - h)));
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
        (hi - lo).length()
    }
}

/// Area of the convex hull of points (Andrew's monotone chain).
fn hull_area(mut points: Vec<DVec2>) -> f64 {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return 0.0;
    }
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * points.len());
    for pass in [points.clone(), points.into_iter().rev().collect()] {
        let start = hull.len();
        for p in pass {
            while hull.len() >= start + 2
                && (hull[hull.len() - 1] - hull[hull.len() - 2]).perp_dot(p - hull[hull.len() - 2])
                    <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    penumbra_scenes::polygon::signed_area_2d(&hull).abs()
}

#[cfg(test)]
mod tests {
    use super::*;
    use penumbra_scenes::builtin;

    /// The strength of surface `blocker` between a scene's light and floor.
    fn strength_of(scene: &Scene, blocker: SurfaceId) -> PatchStrength {
        let e = scene.surface_id("light").expect("light");
        let r = scene.surface_id("floor").expect("floor");
        let frame =
            |s: SurfaceId| PlaneFrame::of_polygon(&scene.surfaces[s].polygon).expect("a plane");
        let (ef, rf) = (frame(e), frame(r));
        Pair {
            scene,
            emitter: e,
            emitter_frame: &ef,
            receiver: r,
            receiver_frame: &rf,
        }
        .strength(&scene.surfaces[blocker].polygon)
    }

    /// The textbook blocker (a unit square at height 1 under a unit light at height 3) seen from
    /// the floor point under it is magnified 3: it hides the whole light. Cast from the light's
    /// corners its shadow spans -1 to 1 along each axis.
    #[test]
    fn the_textbook_blocker_is_strong() {
        let scene = builtin::textbook();
        let s = strength_of(&scene, scene.surface_id("blocker").expect("blocker"));
        assert_eq!(s.share, 1.0);
        assert!((s.footprint - 2.0 * 2f64.sqrt()).abs() < 1e-12, "{s:?}");
    }

    /// A face a hundredth of the light's size, halfway up, is magnified 3/2 seen from the floor:
    /// it hides 2.25 ten-thousandths of the light.
    #[test]
    fn a_small_face_is_weak() {
        let mut scene = builtin::textbook();
        let small = scene.surface_id("blocker").expect("blocker");
        for p in &mut scene.surfaces[small].polygon {
            *p = DVec3::new(p.x * 0.01, p.y * 0.01, 2.0);
        }
        let s = strength_of(&scene, small);
        assert!((s.share - 2.25e-4).abs() < 1e-15, "{s:?}");
    }

    #[test]
    fn hulls_have_their_area() {
        let square = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 2.0),
            (0.0, 2.0),
            (1.0, 1.0),
            (1.0, 0.0),
        ];
        let points = square.iter().map(|&(x, y)| DVec2::new(x, y)).collect();
        assert_eq!(hull_area(points), 4.0);
        assert_eq!(hull_area(vec![DVec2::ZERO, DVec2::X, DVec2::X * 2.0]), 0.0);
    }
}
