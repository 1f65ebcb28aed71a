//! The events of one emitter–receiver pair: the blockers in the shaft between them, their EV and
//! VE wedges and EEE curves, and what each leaves on the receiver once trimmed where other
//! geometry hides it. Pairs are independent, so the search runs them in parallel.

use std::collections::BTreeSet;

use glam::DVec3;
use penumbra_scenes::{Bounds, IndexBox, PlaneFrame, Scene, SurfaceId, Visibility};

use super::pair::PairGeometry;
use super::patches::Patches;
use super::strength::Pair;
use super::topology::Topology;
use super::wedge::{Event, Wedge};
use super::{
    BETWEEN_MAX_EDGES, Boundary, DiscontinuityOptions, DiscontinuitySegment, DiscontinuityStats,
    EEE_MAX_EDGES, EventSet, MIN_RECEIVER_ELEMENTS, between, clip_by_height, clip_to_polygon, eee,
    horizon, hull, trim,
};

/// What the whole search shares: the scene, its welded topology and every surface's frame.
#[derive(Debug)]
pub(crate) struct SearchContext<'a> {
    pub scene: &'a Scene,
    pub visibility: &'a Visibility,
    pub topology: Topology,
    /// Flat patches of welded coplanar faces, judged as one blocker.
    pub patches: Patches,
    /// Vertices inside a straight stretch of edges: no corner, so no EV event.
    pub straight: Vec<bool>,
    pub frames: Vec<Option<PlaneFrame>>,
    /// Each surface's distinct leaf boxes in the visibility index, if it has them
    /// ([`Visibility::leaf_boxes`]).
    pub surface_leaves: Option<Vec<Vec<IndexBox>>>,
    pub options: &'a DiscontinuityOptions,
    /// Points closer than this count as coincident.
    pub tol: f64,
    /// How far wedges are followed: beyond the scene, whatever its shape.
    pub reach: f64,
}

/// The segments one pair leaves on its receiver (before merging), and the figures of its search.
#[derive(Debug, Default)]
pub(crate) struct PairEvents {
    pub segments: Vec<DiscontinuitySegment>,
    pub stats: DiscontinuityStats,
}

/// A wedge to follow onto the receiver. A wedge between two blockers also passes `grazed_edge`,
/// which each generating ray must reach unobstructed too.
struct Candidate {
    wedge: Wedge,
    grazed_edge: Option<(usize, usize)>,
}

impl Candidate {
    fn plain(wedge: Wedge) -> Candidate {
        Candidate {
            wedge,
            grazed_edge: None,
        }
    }
}

/// One emitter–receiver pair with the blockers in the shaft between them.
struct Shaft<'a> {
    context: &'a SearchContext<'a>,
    pair: PairGeometry<'a>,
    blockers: Vec<SurfaceId>,
    /// The receiver polygon's diameter (quadratic in its vertex count: found once).
    receiver_diameter: f64,
    /// The blockers' welded vertices and edges (vertex pairs, smaller index first).
    vertices: BTreeSet<usize>,
    edges: BTreeSet<(usize, usize)>,
}

impl<'a> SearchContext<'a> {
    pub(super) fn new(
        scene: &'a Scene,
        visibility: &'a Visibility,
        options: &'a DiscontinuityOptions,
    ) -> SearchContext<'a> {
        let tol = visibility.contact_distance();
        let topology = Topology::new(scene, tol);
        SearchContext {
            scene,
            visibility,
            patches: Patches::new(&topology),
            straight: (0..topology.points.len())
                .map(|v| topology.is_straight(v))
                .collect(),
            topology,
            frames: scene
                .surfaces
                .iter()
                .map(|s| PlaneFrame::of_polygon(&s.polygon))
                .collect(),
            surface_leaves: surface_leaves(scene, visibility),
            options,
            tol,
            reach: 4.0 * scene.diagonal(),
        }
    }

    /// Emitter–receiver pairs that face each other, emitters outermost.
    pub(super) fn facing_pairs(&self) -> Vec<(SurfaceId, SurfaceId)> {
        let mut pairs = Vec::new();
        for (e, emitter) in self.scene.emitters() {
            let Some(ef) = self.frames[e] else { continue };
            for (r, receiver) in self.scene.surfaces.iter().enumerate() {
                let Some(rf) = self.frames[r] else { continue };
                let faces = r != e
                    && emitter.polygon.iter().any(|&p| rf.height(p) > self.tol)
                    && receiver.polygon.iter().any(|&p| ef.height(p) > self.tol);
                if faces {
                    pairs.push((e, r));
                }
            }
        }
        pairs
    }

    /// Every event of the pair `(e, r)` on `r`.
    pub(super) fn pair_events(&self, e: SurfaceId, r: SurfaceId) -> PairEvents {
        let mut out = PairEvents::default();
        if self
            .options
            .element_area
            .is_some_and(|a| self.scene.surfaces[r].area() < MIN_RECEIVER_ELEMENTS * a)
        {
            out.stats.receivers_too_small = 1;
            return out;
        }
        let Some(pair) = self.pair(e, r) else {
            out.stats.pairs_without_blockers = 1;
            return out;
        };
        out.segments
            .extend(self.horizon_segments(&pair, &mut out.stats));
        let Some(shaft) = self.shaft(pair, &mut out.stats) else {
            out.stats.pairs_without_blockers = 1;
            return out;
        };
        let mut wedges = shaft.ev_wedges(&mut out.stats);
        wedges.extend(
            shaft
                .ve_wedges(&mut out.stats)
                .into_iter()
                .map(Candidate::plain),
        );
        if self.options.events == EventSet::Complete {
            if shaft.edges.len() > BETWEEN_MAX_EDGES {
                out.stats.between_shafts_skipped += 1;
            } else {
                wedges.extend(shaft.between_wedges(&mut out.stats));
            }
        }
        if self.options.eee {
            if shaft.edges.len() > EEE_MAX_EDGES {
                out.stats.eee_shafts_skipped += 1;
            } else {
                shaft.eee_segments(&mut out);
            }
        }
        for candidate in wedges {
            // A pair with thousands of blockers takes a large share of a second; an interrupted
            // search lets go of its segments anyway.
            if self.options.interrupted() {
                break;
            }
            shaft.wedge_segments(&candidate, &mut out);
        }
        out
    }

    /// Where the emitter's plane cuts the receiver ([`horizon`]), of order 1; none where the
    /// part of the receiver behind that plane is narrower than an element of the mesh to come
    /// (the walls of a box whose light hangs just under the ceiling): the line would cut a strip
    /// of slivers off the receiver's edge.
    fn horizon_segments(
        &self,
        pair: &PairGeometry,
        stats: &mut DiscontinuityStats,
    ) -> Vec<DiscontinuitySegment> {
        let (e, r) = (pair.emitter, pair.receiver);
        let (ef, rf) = (pair.emitter_frame, pair.receiver_frame);
        let receiver_polygon = &self.scene.surfaces[r].polygon;
        if let Some(area) = self
            .options
            .element_area
            .filter(|_| !self.options.horizons_near_edges)
        {
            // How far the receiver reaches behind the plane, measured in the receiver's plane.
            let sine = ef.normal.cross(rf.normal).length();
            let behind = receiver_polygon
                .iter()
                .map(|&p| -ef.height(p))
                .fold(0.0, f64::max);
            if sine > 0.0 && behind > self.tol && behind / sine < area.sqrt() {
                stats.horizons_within_an_element += 1;
                return Vec::new();
            }
        }
        let horizon = horizon::Horizon {
            pair: *pair,
            emitter_polygon: &self.scene.surfaces[e].polygon,
            receiver_polygon,
            trim_samples: self.options.trim_samples,
            trim_fraction: self.options.trim_tolerance,
        };
        horizon
            .segments()
            .into_iter()
            .map(|[from, to]| DiscontinuitySegment {
                surface: r,
                emitter: e,
                from,
                to,
                event: Event::Horizon,
                boundary: Boundary::Umbra,
                order: 1,
            })
            .collect()
    }

    /// The pair `(e, r)` as its searches see it; `None` for a degenerate polygon.
    fn pair(&'a self, e: SurfaceId, r: SurfaceId) -> Option<PairGeometry<'a>> {
        Some(PairGeometry {
            topology: &self.topology,
            visibility: self.visibility,
            emitter: e,
            receiver: r,
            emitter_frame: self.frames[e]?,
            receiver_frame: self.frames[r]?,
            tol: self.tol,
            reach: self.reach,
        })
    }

    /// The pair's shaft (the convex hull of emitter and receiver) with the blockers in it strong
    /// enough for events, or `None` when nothing blocks.
    fn shaft(
        &'a self,
        pair: PairGeometry<'a>,
        stats: &mut DiscontinuityStats,
    ) -> Option<Shaft<'a>> {
        let (e, r) = (pair.emitter, pair.receiver);
        let (emitter, receiver) = (&self.scene.surfaces[e], &self.scene.surfaces[r]);
        let (ef, rf) = (pair.emitter_frame, pair.receiver_frame);
        let tol = self.tol;
        let hull = hull::HullPlanes::of_polygons(
            [(&emitter.polygon, &ef), (&receiver.polygon, &rf)],
            tol,
            self.reach,
        );
        // A blocker must have a vertex in front of both and must not lie wholly beyond one of
        // the hull's faces.
        let blockers = shaft_blockers(
            self.visibility,
            [emitter.bounds(), receiver.bounds()],
            e,
            r,
            |s| {
                let polygon = &self.scene.surfaces[s].polygon;
                polygon
                    .iter()
                    .any(|&p| ef.height(p) > tol && rf.height(p) > tol)
                    && !hull.beyond_a_face(polygon, tol)
            },
        );
        if blockers.is_empty() {
            return None;
        }
        stats.blockers_in_shafts = blockers.len();
        let blockers = self.strong_blockers(e, &ef, r, &rf, blockers, stats);
        let mut vertices = BTreeSet::new();
        let mut edges = BTreeSet::new();
        for &b in &blockers {
            let l = &self.topology.loops[b];
            for k in 0..l.len() {
                let (u, w) = (l[k], l[(k + 1) % l.len()]);
                vertices.insert(u);
                if u != w {
                    edges.insert((u.min(w), u.max(w)));
                }
            }
        }
        Some(Shaft {
            context: self,
            pair,
            receiver_diameter: penumbra_scenes::polygon::diameter(&receiver.polygon),
            blockers,
            vertices,
            edges,
        })
    }
}

impl SearchContext<'_> {
    /// The blockers whose patch is strong enough for events on `r` ([`super::strength`]).
    fn strong_blockers(
        &self,
        e: SurfaceId,
        ef: &PlaneFrame,
        r: SurfaceId,
        rf: &PlaneFrame,
        blockers: Vec<SurfaceId>,
        stats: &mut DiscontinuityStats,
    ) -> Vec<SurfaceId> {
        let pair = Pair {
            scene: self.scene,
            emitter: e,
            emitter_frame: ef,
            receiver: r,
            receiver_frame: rf,
        };
        let element_size = self.options.element_area.map_or(0.0, f64::sqrt);
        let mut judged: std::collections::HashMap<usize, bool> = Default::default();
        blockers
            .into_iter()
            .filter(|&b| {
                let patch = self.patches.of_surface[b];
                let strong = *judged.entry(patch).or_insert_with(|| {
                    let s = pair.strength(&self.patches.corners[patch]);
                    let strong =
                        s.share >= self.options.event_tolerance && s.footprint >= element_size;
                    if !strong {
                        stats.weak_share_max = stats.weak_share_max.max(s.share);
                    }
                    strong
                });
                stats.blockers_weak += usize::from(!strong);
                strong
            })
            .collect()
    }
}

impl Shaft<'_> {
    fn point(&self, v: usize) -> DVec3 {
        self.context.topology.points[v]
    }

    fn emitter_loop(&self) -> &[usize] {
        &self.context.topology.loops[self.pair.emitter]
    }

    /// EV: each emitter edge (the part in front of the receiver) with each blocker vertex on the
    /// silhouette as seen from it.
    fn ev_wedges(&self, stats: &mut DiscontinuityStats) -> Vec<Candidate> {
        let topology = &self.context.topology;
        let e_loop = self.emitter_loop();
        let tol = self.context.tol;
        let mut wedges = Vec::new();
        for k in 0..e_loop.len() {
            let (ia, ib) = (e_loop[k], e_loop[(k + 1) % e_loop.len()]);
            let Some(source) = clip_by_height(self.point(ia), self.point(ib), |p| {
                self.pair.receiver_frame.height(p) - tol
            }) else {
                continue;
            };
            for &v in &self.vertices {
                let pv = self.point(v);
                if !self.pair.in_front(pv) || e_loop.contains(&v) || self.context.straight[v] {
                    continue;
                }
                let n = (self.point(ib) - self.point(ia)).cross(pv - self.point(ia));
                let Some(n) = n.try_normalize() else { continue };
                stats.wedges_considered += 1;
                // A complete wedge keeps the parts of the edge from which the vertex is on the
                // outline: beyond them, the ray enters the blocker at the vertex.
                let sources: Vec<[DVec3; 2]> = match self.context.options.events {
                    EventSet::Complete => topology
                        .outline_runs(v, source, self.pair.not_pair())
                        .into_iter()
                        .map(|[s, t]| [source[0].lerp(source[1], s), source[0].lerp(source[1], t)])
                        .filter(|[a, b]| a.distance(*b) > tol)
                        .collect(),
                    EventSet::Extremal
                        if topology.vertex_is_tangent(v, n, self.pair.not_pair()) =>
                    {
                        vec![source]
                    }
                    EventSet::Extremal => Vec::new(),
                };
                if sources.is_empty() {
                    stats.wedges_culled += 1;
                    continue;
                }
                let order = if topology.plane_holds_an_edge_at(v, n, self.pair.not_pair()) {
                    1
                } else {
                    2
                };
                wedges.extend(sources.into_iter().map(|source| {
                    Candidate::plain(Wedge {
                        emitter: self.pair.emitter,
                        event: Event::Ev,
                        source,
                        through: [pv, pv],
                        order,
                    })
                }));
            }
        }
        wedges
    }

    /// VE: each emitter vertex in front of the receiver with each blocker edge (the part in front
    /// of both) on the silhouette as seen from it.
    fn ve_wedges(&self, stats: &mut DiscontinuityStats) -> Vec<Wedge> {
        let topology = &self.context.topology;
        let tol = self.context.tol;
        let e = self.pair.emitter;
        let mut wedges = Vec::new();
        for &ia in self.emitter_loop() {
            let pa = self.point(ia);
            if self.pair.receiver_frame.height(pa) <= tol {
                continue;
            }
            for &(u, w) in &self.edges {
                let Some(through) = clip_by_height(self.point(u), self.point(w), |p| {
                    (self.pair.emitter_frame.height(p) - tol)
                        .min(self.pair.receiver_frame.height(p) - tol)
                }) else {
                    continue;
                };
                if u == ia || w == ia {
                    continue;
                }
                let Some(n) = (through[0] - pa).cross(through[1] - pa).try_normalize() else {
                    continue;
                };
                stats.wedges_considered += 1;
                let extremal = self.context.options.events == EventSet::Extremal;
                if (extremal && !topology.vertex_is_tangent(ia, n, |s| s == e))
                    || !topology.edge_is_tangent(u, w, n, self.pair.not_pair())
                {
                    stats.wedges_culled += 1;
                    continue;
                }
                let order = if topology.plane_holds_an_edge_at(ia, n, |s| s == e) {
                    1
                } else {
                    2
                };
                wedges.push(Wedge {
                    emitter: e,
                    event: Event::Ve,
                    source: [pa, pa],
                    through,
                    order,
                });
            }
        }
        wedges
    }

    /// Between blockers: each blocker vertex with each edge of another blocker whose plane cuts
    /// the emitter ([`between`]).
    fn between_wedges(&self, stats: &mut DiscontinuityStats) -> Vec<Candidate> {
        let context = self.context;
        let search = between::BetweenSearch {
            pair: self.pair,
            emitter_polygon: &context.scene.surfaces[self.pair.emitter].polygon,
            straight: &context.straight,
        };
        let (found, count) = search.wedges(&self.vertices, &self.edges, &self.blockers);
        stats.wedges_considered += count.considered;
        stats.wedges_culled += count.culled;
        found
            .into_iter()
            .map(|b| Candidate {
                wedge: b.wedge,
                grazed_edge: Some(b.edge),
            })
            .collect()
    }

    /// The receiver's diameter times `fraction`: tolerances of this pair.
    fn on_receiver(&self, fraction: f64) -> f64 {
        fraction * self.receiver_diameter
    }

    /// EEE: each emitter edge with two blocker edges, as polylines on the receiver.
    fn eee_segments(&self, out: &mut PairEvents) {
        let context = self.context;
        let receiver_polygon = &context.scene.surfaces[self.pair.receiver].polygon;
        let search = eee::EeeSearch {
            pair: self.pair,
            chord_tolerance: self.on_receiver(context.options.eee_tolerance),
            receiver_polygon,
            surface_leaves: context.surface_leaves.as_deref(),
            trim_samples: context.options.trim_samples,
            trim_tolerance: self.on_receiver(context.options.trim_tolerance),
        };
        let e_loop = self.emitter_loop();
        let emitter_edges: Vec<(usize, usize)> = (0..e_loop.len())
            .map(|k| (e_loop[k], e_loop[(k + 1) % e_loop.len()]))
            .filter(|(a, b)| a != b)
            .collect();
        let (curves, count) = search.curves(&emitter_edges, &self.edges, &self.blockers);
        out.stats.eee_considered += count.considered;
        out.stats.eee_events += count.events;
        for curve in curves {
            for w in curve.points.windows(2) {
                for [a, b] in
                    clip_to_polygon(&self.pair.receiver_frame, receiver_polygon, w[0], w[1])
                {
                    out.segments
                        .push(self.segment(a, b, Event::Eee, curve.order));
                }
            }
        }
    }

    /// Where a wedge meets the receiver, clipped to its polygon and trimmed to where the wedge's
    /// rays are unobstructed.
    fn wedge_segments(&self, candidate: &Candidate, out: &mut PairEvents) {
        let context = self.context;
        let wedge = &candidate.wedge;
        let rf = &self.pair.receiver_frame;
        let Some([p, q]) = wedge.meet_plane(rf.origin, rf.normal, context.reach) else {
            return;
        };
        let receiver_polygon = &context.scene.surfaces[self.pair.receiver].polygon;
        let trim_tol = self.on_receiver(context.options.trim_tolerance);
        let generates = |x: DVec3| match candidate.grazed_edge {
            None => trim::generator_visible(context.visibility, wedge, x, self.pair.receiver),
            Some((u, w)) => {
                let edge = [context.topology.points[u], context.topology.points[w]];
                trim::generator_visible_past(context.visibility, wedge, x, self.pair.receiver, edge)
            }
        };
        let mut kept = false;
        for [a, b] in clip_to_polygon(rf, receiver_polygon, p, q) {
            let runs = trim::runs_where(a, b, context.options.trim_samples, trim_tol, generates);
            match runs.as_slice() {
                [] => out.stats.segments_hidden += 1,
                [[x, y]] if x.distance(a) <= trim_tol && y.distance(b) <= trim_tol => {}
                _ => out.stats.segments_trimmed += 1,
            }
            for [x, y] in runs {
                kept = true;
                out.segments
                    .push(self.segment(x, y, wedge.event, wedge.order));
            }
        }
        out.stats.wedges_kept += usize::from(kept);
    }

    fn segment(&self, from: DVec3, to: DVec3, event: Event, order: u8) -> DiscontinuitySegment {
        DiscontinuitySegment {
            surface: self.pair.receiver,
            emitter: self.pair.emitter,
            from,
            to,
            event,
            boundary: Boundary::Inner,
            order,
        }
    }
}

/// Each surface's distinct leaf boxes in the visibility index, if it has them.
fn surface_leaves(scene: &Scene, visibility: &Visibility) -> Option<Vec<Vec<IndexBox>>> {
    let leaves = visibility.leaf_boxes()?;
    let mut out: Vec<Vec<IndexBox>> = vec![Vec::new(); scene.surfaces.len()];
    for (t, leaf) in visibility.triangles().iter().zip(leaves) {
        let boxes = &mut out[t.surface];
        if !boxes.contains(leaf) {
            boxes.push(*leaf);
        }
    }
    Some(out)
}

/// Surfaces other than `e` and `r` with a triangle in the shaft between two boxes for which
/// `keep` holds, sorted.
fn shaft_blockers(
    visibility: &Visibility,
    [from, to]: [Bounds; 2],
    e: SurfaceId,
    r: SurfaceId,
    keep: impl Fn(SurfaceId) -> bool,
) -> Vec<SurfaceId> {
    let mut found = BTreeSet::new();
    visibility.triangles_overlapping_between(from, to, |t| {
        let s = visibility.triangles()[t].surface;
        if s != e && s != r {
            found.insert(s);
        }
    });
    found.into_iter().filter(|&s| keep(s)).collect()
}
