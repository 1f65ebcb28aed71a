//! Events between two blockers (complete sets only): a vertex of one blocker and an edge of
//! another, in a plane that cuts the emitter.
//!
//! Seen from a receiver point, each blocker's image covers part of the emitter. Where a vertex of
//! one image crosses an edge of the other inside the emitter, the overlap of the two images, and
//! so the visible area, kinks in its derivative: the curvature of the light jumps (Drettakis &
//! Fiume 1994 count these among the EV events). The lines of such an event pass through the
//! vertex and the edge and meet the emitter: in the plane of vertex and edge, they come from a
//! segment of the chord that plane cuts from the emitter, through the vertex, to the receiver, an
//! EV wedge whose source is that segment. Each vertex is paired with the edges in the region
//! below it (between it and its shadow on the receiver's plane), each edge with the vertices
//! below it, so that the pairs found stay local however many blockers the shaft holds.

use std::collections::BTreeSet;

use glam::DVec3;
use penumbra_scenes::{Bounds, SurfaceId};

use super::eee::{NearBlockers, shadow_region};
use super::pair::PairGeometry;
use super::wedge::{Event, Wedge};
use super::{clip_by_height, clip_to_polygon};

/// One emitter–receiver pair: the geometry every vertex–edge pair of it shares.
pub(crate) struct BetweenSearch<'a> {
    pub pair: PairGeometry<'a>,
    /// The emitter's polygon.
    pub emitter_polygon: &'a [DVec3],
    /// Vertices inside a straight stretch of edges: no corner, so no event.
    pub straight: &'a [bool],
}

/// A wedge through a blocker vertex whose lines also pass through blocker edge `edge`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BetweenWedge {
    pub wedge: Wedge,
    pub edge: (usize, usize),
}

/// What the search over vertex–edge pairs did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct BetweenCount {
    /// Pairs whose plane was tested against the emitter.
    pub considered: usize,
    /// Of those, pairs whose edge is not on its blockers' outline in that plane.
    pub culled: usize,
}

impl BetweenSearch<'_> {
    /// The wedges of the blocker vertices `vertices` with the blocker edges `edges` of the
    /// surfaces `blockers`.
    pub(super) fn wedges(
        &self,
        vertices: &BTreeSet<usize>,
        edges: &BTreeSet<(usize, usize)>,
        blockers: &[SurfaceId],
    ) -> (Vec<BetweenWedge>, BetweenCount) {
        let emitter = self.emitter_front();
        let edges: BTreeSet<(usize, usize)> = edges
            .iter()
            .copied()
            .filter(|&e| self.may_be_on_outline(e, &emitter))
            .collect();
        let vertices: BTreeSet<usize> = vertices
            .iter()
            .copied()
            .filter(|&v| self.vertex_may_be_on_outline(v, &emitter))
            .collect();
        let mut count = BetweenCount::default();
        let mut out = Vec::new();
        for (v, edge) in self.nearby_pairs(&emitter, &vertices, &edges, blockers) {
            if self.share_a_face(v, edge) {
                continue;
            }
            count.considered += 1;
            match self.pair_wedges(&emitter, v, edge) {
                Some(wedges) => out.extend(wedges),
                None => count.culled += 1,
            }
        }
        (out, count)
    }

    /// The vertex–edge pairs where one lies in the region between the other and its shadow from
    /// `emitter` (the part of the emitter in front of the receiver), in order.
    fn nearby_pairs(
        &self,
        emitter: &[DVec3],
        vertices: &BTreeSet<usize>,
        edges: &BTreeSet<(usize, usize)>,
        blockers: &[SurfaceId],
    ) -> BTreeSet<(usize, (usize, usize))> {
        let t = self.pair.topology;
        let near = NearBlockers::indexed(t, blockers);
        // The blockers (by place in `blockers`) near the region below the points `through`.
        let below = |through: &[DVec3]| {
            let region = shadow_region(
                &self.pair.receiver_frame,
                self.pair.tol,
                self.pair.reach,
                emitter,
                through,
            );
            let mut found = Vec::new();
            near.find(
                self.pair.visibility,
                Bounds::from_points(region.iter()),
                self.pair.tol,
                |b| found.push(b),
            );
            found.sort_unstable();
            found.dedup();
            found
        };
        let usable_vertex = |v: usize| {
            !self.straight[v] && self.pair.in_front(t.points[v]) && !t.corners[v].is_empty()
        };
        let mut pairs = BTreeSet::new();
        for &v in vertices.iter().filter(|&&v| usable_vertex(v)) {
            for b in below(&[t.points[v]]) {
                for edge in loop_edges(&t.loops[blockers[b]]).filter(|e| edges.contains(e)) {
                    pairs.insert((v, edge));
                }
            }
        }
        for &(u, w) in edges {
            for b in below(&[t.points[u], t.points[w]]) {
                for &v in &t.loops[blockers[b]] {
                    if vertices.contains(&v) && usable_vertex(v) {
                        pairs.insert((v, (u, w)));
                    }
                }
            }
        }
        pairs
    }

    /// Whether edge `(u, w)` is on its faces' outline as seen from some point of the polygon
    /// `emitter`: its faces on one side of the plane through that point and the edge. For two
    /// faces, the side of each is linear in the point, so it is not only when at every corner of
    /// the emitter the two sides differ the same way.
    fn may_be_on_outline(&self, (u, w): (usize, usize), emitter: &[DVec3]) -> bool {
        let t = self.pair.topology;
        let faces = t.edge_faces(u, w, self.pair.not_pair());
        let [f1, f2] = faces.as_slice() else {
            return true;
        };
        let (a, d) = (t.points[u], t.points[w] - t.points[u]);
        let (n1, n2) = (f1.cross(d), f2.cross(d));
        let sides = |p: DVec3| ((p - a).dot(n1), (p - a).dot(n2));
        let splits = |first: bool| {
            emitter.iter().all(|&p| {
                let (g1, g2) = sides(p);
                if first {
                    g1 > 0.0 && g2 < 0.0
                } else {
                    g1 < 0.0 && g2 > 0.0
                }
            })
        };
        !splits(true) && !splits(false)
    }

    /// Whether vertex `v` is on its faces' outline as seen from some point of the polygon
    /// `emitter`. The points from which all its faces turn towards them, and those from which all
    /// turn away, are two convex cones; a polygon avoids the outline only inside one of them.
    fn vertex_may_be_on_outline(&self, v: usize, emitter: &[DVec3]) -> bool {
        let t = self.pair.topology;
        let include = self.pair.not_pair();
        if t.on_rim(v, &include) {
            return true;
        }
        let origin = t.points[v];
        let all_facing = |p: DVec3, sign: f64| {
            t.corners[v]
                .iter()
                .filter(|c| include(c.surface))
                .all(|c| sign * t.normals[c.surface].dot(p - origin) > 0.0)
        };
        !(emitter.iter().all(|&p| all_facing(p, 1.0))
            || emitter.iter().all(|&p| all_facing(p, -1.0)))
    }

    /// The emitter's polygon, cut to the part in front of the receiver.
    fn emitter_front(&self) -> Vec<DVec3> {
        let rf = &self.pair.receiver_frame;
        let p = self.emitter_polygon;
        let mut out = Vec::with_capacity(p.len() + 1);
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            let (ha, hb) = (rf.height(a) - self.pair.tol, rf.height(b) - self.pair.tol);
            if ha >= 0.0 {
                out.push(a);
            }
            if (ha >= 0.0) != (hb >= 0.0) {
                out.push(a.lerp(b, ha / (ha - hb)));
            }
        }
        out
    }

    /// Whether some face holds both vertex `v` and the edge: their plane is the face's.
    fn share_a_face(&self, v: usize, (u, w): (usize, usize)) -> bool {
        let t = self.pair.topology;
        if v == u || v == w {
            return true;
        }
        t.edges.get(&(u, w)).is_some_and(|faces| {
            faces
                .iter()
                .any(|&(s, _)| t.corners[v].iter().any(|c| c.surface == s))
        })
    }

    /// The wedges of vertex `v` with edge `(u, w)`: one per run of the emitter chord in their
    /// plane whose lines through `v` also meet the edge; `None` when the edge is not on the
    /// outline of its faces in that plane.
    fn pair_wedges(
        &self,
        emitter: &[DVec3],
        v: usize,
        (u, w): (usize, usize),
    ) -> Option<Vec<BetweenWedge>> {
        let t = self.pair.topology;
        let pv = t.points[v];
        let ends = clip_by_height(t.points[u], t.points[w], |p| {
            (self.pair.emitter_frame.height(p) - self.pair.tol)
                .min(self.pair.receiver_frame.height(p) - self.pair.tol)
        })?;
        let n = (ends[0] - pv).cross(ends[1] - pv).try_normalize()?;
        if !t.edge_is_tangent(u, w, n, self.pair.not_pair()) {
            return None;
        }
        let ef = &self.pair.emitter_frame;
        // The line where the plane meets the emitter's: its direction, and its point nearest
        // the vertex.
        let along = n.cross(ef.normal).try_normalize()?;
        let down = n.cross(along);
        let start = pv + down * (-ef.height(pv) / down.dot(ef.normal));
        let chord = [
            start - along * self.pair.reach,
            start + along * self.pair.reach,
        ];
        let order = if t.plane_holds_an_edge_at(v, n, self.pair.not_pair()) {
            1
        } else {
            2
        };
        let mut out = Vec::new();
        for [c0, c1] in clip_to_polygon(ef, emitter, chord[0], chord[1]) {
            // Where the line from a chord point through `pv` passes each end of the edge, the
            // sign of this product changes: the lines meeting the edge are where it is <= 0.
            let side = |q: DVec3, x: DVec3| n.dot((q - pv).cross(x - pv));
            let meets =
                |s: f64| side(c0.lerp(c1, s), ends[0]) * side(c0.lerp(c1, s), ends[1]) <= 0.0;
            for [s0, s1] in runs_of(
                &meets,
                |x| {
                    let (a, b) = (side(c0, x), side(c1, x));
                    (a != b).then(|| a / (a - b))
                },
                ends,
            ) {
                let run = [c0.lerp(c1, s0), c0.lerp(c1, s1)];
                // The parts of the run from which the vertex is on its blocker's outline.
                for [a, b] in t.outline_runs(v, run, self.pair.not_pair()) {
                    let source = [run[0].lerp(run[1], a), run[0].lerp(run[1], b)];
                    if source[0].distance(source[1]) <= self.pair.tol {
                        continue;
                    }
                    out.push(BetweenWedge {
                        wedge: Wedge {
                            emitter: self.pair.emitter,
                            event: Event::BlockerEv,
                            source,
                            through: [pv, pv],
                            order,
                        },
                        edge: (u, w),
                    });
                }
            }
        }
        Some(out)
    }
}

/// The runs of `[0, 1]` where `meets` holds, given `root`, where the line through one end of the
/// edge crosses the chord (a parameter, if it does anywhere).
fn runs_of(
    meets: &impl Fn(f64) -> bool,
    root: impl Fn(DVec3) -> Option<f64>,
    ends: [DVec3; 2],
) -> Vec<[f64; 2]> {
    let mut cuts = vec![0.0, 1.0];
    cuts.extend(
        ends.iter()
            .filter_map(|&x| root(x))
            .filter(|s| (0.0..=1.0).contains(s)),
    );
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let mut runs: Vec<[f64; 2]> = Vec::new();
    for k in 0..cuts.len() - 1 {
        let (a, b) = (cuts[k], cuts[k + 1]);
        if b <= a || !meets(0.5 * (a + b)) {
            continue;
        }
        match runs.last_mut() {
            Some(r) if r[1] == a => r[1] = b,
            _ => runs.push([a, b]),
        }
    }
    runs
}

/// The edges of a polygon loop as welded vertex pairs, smaller index first.
fn loop_edges(l: &[usize]) -> impl Iterator<Item = (usize, usize)> + '_ {
    (0..l.len()).filter_map(move |k| {
        let (u, w) = (l[k], l[(k + 1) % l.len()]);
        (u != w).then(|| (u.min(w), u.max(w)))
    })
}
