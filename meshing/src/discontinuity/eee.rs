//! EEE visual events: the lines that meet an emitter edge and two blocker edges.
//!
//! Seen from a receiver point, two blocker edges that cross in projection make a corner of the
//! visible part of the emitter; where that corner slides over an emitter edge the light changes
//! its analytic form. The lines through three edges form a ruled quadric; it meets the receiver's
//! plane in a conic arc. When the two blocker edges share a vertex they lie in one plane, and the
//! lines of that plane through the point where it cuts the emitter edge form a planar pencil: a
//! straight line on the receiver, of order 1 (a face of a box seen edge-on at its foot).
//!
//! The lines are parametrised by their point on the first blocker edge (the one nearer the
//! emitter). A line is an event where it meets all three segments in the order emitter, first
//! edge, second edge, receiver, grazes both blocker edges (their faces on one side), and is
//! unobstructed. Samples along the edge find the runs where this holds, bisection places their
//! ends, and each run's arc is split until every chord is within the tolerance.

use std::cell::OnceCell;
use std::collections::{BTreeSet, HashMap};

use glam::DVec3;
use penumbra_scenes::polygon::closest_point_on_segment;
use penumbra_scenes::{Bounds, IndexBox, PlaneFrame, SurfaceId, Visibility};
use rustc_hash::FxHashMap;

use super::pair::PairGeometry;
use super::topology::Topology;

/// Samples along the first blocker edge.
const SAMPLES: usize = 48;
/// Bisection steps placing the ends of a run (to 2^-40 of the edge).
const BISECTIONS: usize = 40;
/// Deepest subdivision of an arc into chords.
const MAX_DEPTH: u32 = 14;

/// A polyline on a receiver where an EEE event meets it.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct EeeCurve {
    pub points: Vec<DVec3>,
    /// The emitter edge, the blocker edge nearer the emitter, and the one nearer the receiver.
    pub edges: [[DVec3; 2]; 3],
    /// 1 for a planar pencil (the blocker edges share a plane), else 2.
    pub order: u8,
}

/// What the search over edge triples did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct EeeCount {
    /// Edge triples examined (after silhouette and spatial culling).
    pub considered: usize,
    /// Triples that left a curve.
    pub events: usize,
}

/// One emitter–receiver pair: the geometry every triple of it shares.
pub(crate) struct EeeSearch<'a> {
    pub pair: PairGeometry<'a>,
    /// Greatest distance of a chord from its arc.
    pub chord_tolerance: f64,
    pub receiver_polygon: &'a [DVec3],
    /// Each surface's leaf boxes in the visibility index ([`Visibility::leaf_boxes`], deduplicated),
    /// when the index has them.
    pub surface_leaves: Option<&'a [Vec<IndexBox>]>,
    /// Samples along a pencil's line when trimming it, and the length its trim points are
    /// located to.
    pub trim_samples: usize,
    pub trim_tolerance: f64,
}

/// Points whose convex hull holds every point beyond the points `through` on a line from the
/// points `sources` towards the receiver's plane (of frame `rf`): `through` and their shadows from
/// each source on that plane (the shadow of a convex set from a convex set is the hull of its
/// corners' shadows), followed out to `reach` where a line never comes down to it. Heights under
/// `tol` are on the plane.
pub(super) fn shadow_region(
    rf: &PlaneFrame,
    tol: f64,
    reach: f64,
    sources: &[DVec3],
    through: &[DVec3],
) -> Vec<DVec3> {
    let mut out = through.to_vec();
    for &p in sources {
        for &q in through {
            let d = q - p;
            let (hq, hd) = (rf.height(q), rf.normal.dot(d));
            out.push(if hq <= tol {
                // On the receiver's plane already: its own shadow.
                q - rf.normal * hq
            } else if hd < 0.0 {
                q + d * (hq / -hd).min(reach / d.length().max(f64::MIN_POSITIVE))
            } else {
                q + d.normalize_or_zero() * reach
            });
        }
    }
    out
}

/// A line through the three edges: its points on the emitter edge, the first and second blocker
/// edges, and the receiver's plane.
#[derive(Clone, Copy, Debug)]
struct Transversal {
    source: DVec3,
    first: DVec3,
    second: DVec3,
    receiver: DVec3,
}

/// Shafts with at most this many blockers test their boxes one by one.
const FEW_BLOCKERS: usize = 64;

/// How a shaft finds its blockers near a region (by their place in the shaft's list).
pub(super) enum NearBlockers {
    /// Few blockers: each blocker's box, grown by the tolerance, against the region's.
    Few(Vec<Bounds>),
    /// Many: the boxes of the visibility index's leaves holding each blocker's triangles,
    /// against the index's box of the region. A blocker is found exactly when the index's box
    /// query would visit one of its triangles (see [`Visibility::leaf_boxes`]), without
    /// walking the scene's other triangles that the region's box holds.
    Leaves(Vec<(IndexBox, usize)>),
    /// Many, where the index's leaves do not decide alone: the index's box query, its surfaces
    /// looked up among the blockers (by a fast hash: a large region's query visits hundreds of
    /// thousands of triangles, and hashing each surface id with the standard hasher took a
    /// third of the Crytek Sponza's search).
    Index(FxHashMap<SurfaceId, usize>),
}

impl NearBlockers {
    /// How a shaft with blockers `blockers` finds those near a region: one by one when they are
    /// few, else through the visibility index (`surface_leaves`: [`Visibility::leaf_boxes`] by
    /// surface, when the index has them).
    pub(super) fn new(
        topology: &Topology,
        blockers: &[SurfaceId],
        surface_leaves: Option<&[Vec<IndexBox>]>,
    ) -> NearBlockers {
        let t = topology;
        if blockers.len() <= FEW_BLOCKERS {
            return NearBlockers::Few(
                blockers
                    .iter()
                    .map(|&s| Bounds::from_points(t.loops[s].iter().map(|&v| &t.points[v])))
                    .collect(),
            );
        }
        match surface_leaves {
            Some(leaves) => {
                let mut boxes: Vec<(IndexBox, usize)> = blockers
                    .iter()
                    .enumerate()
                    .flat_map(|(b, &s)| leaves[s].iter().map(move |&x| (x, b)))
                    .collect();
                boxes.shrink_to_fit();
                NearBlockers::Leaves(boxes)
            }
            None => {
                NearBlockers::Index(blockers.iter().enumerate().map(|(b, &s)| (s, b)).collect())
            }
        }
    }

    /// Finds blockers near small regions through the visibility index's box query, whatever
    /// their number: for regions that hold few of the shaft's blockers, walking the leaves of
    /// all of them ([`NearBlockers::Leaves`]) would cost more than the query.
    pub(super) fn indexed(topology: &Topology, blockers: &[SurfaceId]) -> NearBlockers {
        if blockers.len() <= FEW_BLOCKERS {
            NearBlockers::new(topology, blockers, None)
        } else {
            NearBlockers::Index(blockers.iter().enumerate().map(|(b, &s)| (s, b)).collect())
        }
    }

    /// Calls `found` with each blocker near the box `region` (some maybe more than once).
    pub(super) fn find(
        &self,
        visibility: &Visibility,
        region: Bounds,
        tol: f64,
        mut found: impl FnMut(usize),
    ) {
        match self {
            NearBlockers::Few(boxes) => {
                let padded = Bounds {
                    min: region.min - tol,
                    max: region.max + tol,
                };
                for (b, bounds) in boxes.iter().enumerate() {
                    if bounds.overlaps(&padded) {
                        found(b);
                    }
                }
            }
            NearBlockers::Leaves(boxes) => {
                let query = visibility.query_box(region);
                for (leaf, b) in boxes {
                    if leaf.overlaps(&query) {
                        found(*b);
                    }
                }
            }
            NearBlockers::Index(place) => visibility.triangles_overlapping(region, |k| {
                if let Some(&b) = place.get(&visibility.triangles()[k].surface) {
                    found(b);
                }
            }),
        }
    }
}

/// The blocker edges of one search, indexed to find each edge's partners: the edges that share
/// a vertex with it, and those along the blockers near the region beyond it.
struct BlockerEdges {
    /// The edges (welded vertex pairs), in order; an edge's index is its place here.
    list: Vec<(usize, usize)>,
    /// The edges at each vertex.
    at_vertex: HashMap<usize, Vec<usize>>,
    /// Along each blocker (by its place in the search's blockers): its edges and its polygon.
    along_blocker: Vec<Vec<usize>>,
    polygons: Vec<Vec<DVec3>>,
    /// Each edge's faces ([`Topology::edge_faces`]).
    faces: Vec<Vec<DVec3>>,
    near: NearBlockers,
}

impl BlockerEdges {
    /// The edges `edges` of the surfaces `blockers`, in `search`'s pair.
    fn new(
        search: &EeeSearch,
        edges: &BTreeSet<(usize, usize)>,
        blockers: &[SurfaceId],
    ) -> BlockerEdges {
        let t = search.pair.topology;
        let list: Vec<(usize, usize)> = edges.iter().copied().collect();
        let index: HashMap<(usize, usize), usize> =
            list.iter().enumerate().map(|(i, &e)| (e, i)).collect();
        let mut at_vertex: HashMap<usize, Vec<usize>> = HashMap::new();
        for (i, &(u, w)) in list.iter().enumerate() {
            at_vertex.entry(u).or_default().push(i);
            at_vertex.entry(w).or_default().push(i);
        }
        let along_blocker: Vec<Vec<usize>> = blockers
            .iter()
            .map(|&s| {
                let l = &t.loops[s];
                (0..l.len())
                    .filter_map(|k| {
                        let (u, w) = (l[k], l[(k + 1) % l.len()]);
                        index.get(&(u.min(w), u.max(w))).copied()
                    })
                    .collect()
            })
            .collect();
        let polygons: Vec<Vec<DVec3>> = blockers
            .iter()
            .map(|&s| t.loops[s].iter().map(|&v| t.points[v]).collect())
            .collect();
        let not_pair = search.pair.not_pair();
        let faces: Vec<Vec<DVec3>> = list
            .iter()
            .map(|&(u, w)| t.edge_faces(u, w, &not_pair))
            .collect();
        BlockerEdges {
            list,
            at_vertex,
            along_blocker,
            polygons,
            faces,
            near: NearBlockers::new(t, blockers, search.surface_leaves),
        }
    }
}

/// The partners of one first edge after another. Blockers and edges already taken for the
/// current first edge are stamped with its round, to skip repeats without clearing the stamps.
struct Partners {
    round: usize,
    blocker_stamp: Vec<usize>,
    edge_stamp: Vec<usize>,
    /// The blockers near the current first edge's region.
    near: Vec<usize>,
    /// The current first edge's partners, in order.
    found: Vec<usize>,
}

impl Partners {
    /// Stamps for the blockers and the edges of `edges`, none taken yet.
    fn new(edges: &BlockerEdges) -> Partners {
        Partners {
            round: 0,
            blocker_stamp: vec![usize::MAX; edges.polygons.len()],
            edge_stamp: vec![usize::MAX; edges.list.len()],
            near: Vec::new(),
            found: Vec::new(),
        }
    }

    /// The usable edges (those with a region in `regions`) that may make a triple with edge
    /// `i1`, whose region has the corners `corners`: the edges that share a vertex with it, and
    /// those along the blockers near its region and not `outside` it.
    fn of(
        &mut self,
        search: &EeeSearch,
        edges: &BlockerEdges,
        i1: usize,
        corners: &[DVec3; 6],
        regions: &[Option<[DVec3; 6]>],
        outside: impl Fn(&[DVec3]) -> bool,
    ) -> &[usize] {
        let Partners {
            round,
            blocker_stamp,
            edge_stamp,
            near,
            found,
        } = self;
        *round += 1;
        let round = *round;
        found.clear();
        let mut take = |i: usize| {
            if edge_stamp[i] != round && i != i1 && regions[i].is_some() {
                edge_stamp[i] = round;
                found.push(i);
            }
        };
        let first = edges.list[i1];
        for v in [first.0, first.1] {
            for &i in edges.at_vertex.get(&v).into_iter().flatten() {
                take(i);
            }
        }
        near.clear();
        let region = Bounds::from_points(corners.iter());
        edges
            .near
            .find(search.pair.visibility, region, search.pair.tol, |b| {
                if blocker_stamp[b] != round {
                    blocker_stamp[b] = round;
                    near.push(b);
                }
            });
        for &b in near.iter() {
            if outside(&edges.polygons[b]) {
                continue;
            }
            for &i in &edges.along_blocker[b] {
                take(i);
            }
        }
        found.sort_unstable();
        found
    }
}

impl EeeSearch<'_> {
    /// The EEE curves of emitter edges `emitter_edges` with the blocker edges `edges` (welded
    /// vertex pairs) of the surfaces `blockers`, and what it took.
    pub(super) fn curves(
        &self,
        emitter_edges: &[(usize, usize)],
        edges: &BTreeSet<(usize, usize)>,
        blockers: &[SurfaceId],
    ) -> (Vec<EeeCurve>, EeeCount) {
        let mut count = EeeCount::default();
        let mut curves = Vec::new();
        let t = self.pair.topology;
        let edges = BlockerEdges::new(self, edges, blockers);
        let mut partners = Partners::new(&edges);
        for &(ia, ib) in emitter_edges {
            let source = [t.points[ia], t.points[ib]];
            let regions = self.regions_beyond(source, &edges.list);
            for (i1, region) in regions.iter().enumerate() {
                let Some(corners) = region else {
                    continue;
                };
                let hull = super::hull::hull_planes(corners, self.pair.tol);
                let outside =
                    |points: &[DVec3]| super::hull::beyond_a_face(&hull, points, self.pair.tol);
                let found = partners.of(self, &edges, i1, corners, &regions, outside);
                curves.extend(self.curves_with(source, &edges, i1, found, outside, &mut count));
            }
        }
        (curves, count)
    }

    /// For each blocker edge, when it can make an event on the receiver with the emitter edge
    /// `source`, the corners of the region beyond it ([`Self::beyond`]). Edges lying on the
    /// receiver are contact lines, not blockers of its light; edges whose shadow from the
    /// emitter edge misses the receiver cannot cast an event on it.
    fn regions_beyond(
        &self,
        source: [DVec3; 2],
        edges: &[(usize, usize)],
    ) -> Vec<Option<[DVec3; 6]>> {
        let t = self.pair.topology;
        edges
            .iter()
            .map(|&(u, w)| {
                let b = [t.points[u], t.points[w]];
                if !(b
                    .iter()
                    .any(|&p| self.pair.receiver_frame.height(p) > self.pair.tol)
                    && self.can_be_silhouette(u, w, source))
                {
                    return None;
                }
                let corners = self.beyond(source, b);
                self.shadow_meets_receiver(&corners[2..]).then_some(corners)
            })
            .collect()
    }

    /// The curves of the triples of emitter edge `source`, first edge `i1` and each of its
    /// `partners` that is not `outside` the region beyond the first edge and that each of the
    /// two blocker edges sweeps across as seen from the emitter edge; `count` counts them.
    fn curves_with(
        &self,
        source: [DVec3; 2],
        edges: &BlockerEdges,
        i1: usize,
        partners: &[usize],
        outside: impl Fn(&[DVec3]) -> bool,
        count: &mut EeeCount,
    ) -> Vec<EeeCurve> {
        let t = self.pair.topology;
        let first = edges.list[i1];
        let b1 = [t.points[first.0], t.points[first.1]];
        let planes = OnceCell::new();
        let mut curves = Vec::new();
        for &i2 in partners {
            let second = edges.list[i2];
            let b2 = [t.points[second.0], t.points[second.1]];
            if outside(&b2) || !sweeps_across(source, b1, b2) || !sweeps_across(source, b2, b1) {
                continue;
            }
            count.considered += 1;
            let faces = [&edges.faces[i1][..], &edges.faces[i2][..]];
            let found = self.triple(source, [first, second], faces, &planes);
            if !found.is_empty() {
                count.events += 1;
                curves.extend(found);
            }
        }
        curves
    }

    /// Whether blocker edge `(u, w)` is on the silhouette of its faces as seen from some point of
    /// the emitter edge `source`: one face turned towards that point and another away, or a face
    /// seen edge-on (each face's side is linear along the edge, so the ends and the roots tell).
    fn can_be_silhouette(&self, u: usize, w: usize, source: [DVec3; 2]) -> bool {
        let t = self.pair.topology;
        let Some(faces) = t.edges.get(&(u, w)) else {
            return true;
        };
        let faces: Vec<SurfaceId> = faces
            .iter()
            .map(|&(s, _)| s)
            .filter(|&s| s != self.pair.emitter && s != self.pair.receiver)
            .collect();
        if faces.len() < 2 {
            return true;
        }
        let a = t.points[u];
        let side = |s: SurfaceId, p: DVec3| t.normals[s].dot(p - a);
        let straddles = |p: DVec3| {
            let (lo, hi) = faces
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &s| {
                    let h = side(s, p);
                    (lo.min(h), hi.max(h))
                });
            lo <= 0.0 && hi >= 0.0
        };
        straddles(source[0])
            || straddles(source[1])
            || faces
                .iter()
                .any(|&s| (side(s, source[0]) > 0.0) != (side(s, source[1]) > 0.0))
    }

    /// Whether the box, in the receiver's plane, of the shadow corners `shadow` overlaps the
    /// receiver polygon's.
    fn shadow_meets_receiver(&self, shadow: &[DVec3]) -> bool {
        let rf = &self.pair.receiver_frame;
        let box_of = |points: &mut dyn Iterator<Item = DVec3>| {
            points.fold(
                (glam::DVec2::INFINITY, glam::DVec2::NEG_INFINITY),
                |(lo, hi), p| {
                    let q = rf.to_2d(p);
                    (lo.min(q), hi.max(q))
                },
            )
        };
        let (slo, shi) = box_of(&mut shadow.iter().copied());
        let (rlo, rhi) = box_of(&mut self.receiver_polygon.iter().copied());
        let tol = glam::DVec2::splat(self.pair.tol);
        slo.cmple(rhi + tol).all() && rlo.cmple(shi + tol).all()
    }

    /// Points whose convex hull holds every point beyond the blocker edge `first` on a line from
    /// `source` towards the receiver's plane ([`shadow_region`]).
    fn beyond(&self, source: [DVec3; 2], first: [DVec3; 2]) -> [DVec3; 6] {
        let mut out = [first[0]; 6];
        let region = shadow_region(
            &self.pair.receiver_frame,
            self.pair.tol,
            self.pair.reach,
            &source,
            &first,
        );
        out.copy_from_slice(&region);
        out
    }

    /// The curves of one triple.
    /// `faces` are the blocker edges' faces ([`Topology::edge_faces`]); `planes` the first edge's
    /// [`SamplePlanes`], made when first needed.
    fn triple(
        &self,
        source: [DVec3; 2],
        [first, second]: [(usize, usize); 2],
        faces: [&[DVec3]; 2],
        planes: &OnceCell<SamplePlanes>,
    ) -> Vec<EeeCurve> {
        let t = self.pair.topology;
        let b1 = [t.points[first.0], t.points[first.1]];
        let b2 = [t.points[second.0], t.points[second.1]];
        let shares_vertex = first.0 == second.0
            || first.0 == second.1
            || first.1 == second.0
            || first.1 == second.1;
        let coplanar = shares_vertex
            || plane_normal(b1, b2)
                .is_some_and(|n| b2.iter().all(|&p| n.dot(p - b1[0]).abs() <= self.pair.tol));
        if coplanar {
            return self.pencil(source, b1, b2, [first, second], faces);
        }
        // With the emitter edge parallel to a blocker edge, every line through the three lies in
        // the plane of those two: an edge–edge event, found as EV and VE wedges already.
        let e = source[1] - source[0];
        let parallel = |d: DVec3| e.cross(d).length() <= 1e-9 * e.length() * d.length();
        if parallel(b1[1] - b1[0]) || parallel(b2[1] - b2[0]) {
            return Vec::new();
        }
        let line = |u: f64| self.transversal(source, b1, b2, u);
        let holds =
            |x: &Transversal| self.grazes(x, [first, second], faces) && self.unobstructed(x);
        let event = |u: f64| line(u).filter(holds);
        let params = sample_parameters();
        // At the samples, the planes through the first edge's points are the same for every
        // second edge.
        let planes = planes.get_or_init(|| sample_planes(source, b1));
        let second_edge = SecondEdge::new(source, b2);
        let sampled: [bool; SAMPLES] = std::array::from_fn(|k| {
            let (first, n) = planes[k];
            n.and_then(|n| self.transversal_in(source, first, n, &second_edge))
                .is_some_and(|x| holds(&x))
        });
        // Beside each parameter where a condition of the event can change, the event is tried
        // too: a run shorter than the samples' spacing is found when it starts or ends there.
        let mut probes: Vec<(f64, bool)> = params.iter().copied().zip(sampled).collect();
        for c in critical_parameters(source, b1, b2, faces[1]) {
            for u in [c - CRITICAL_STEP, c + CRITICAL_STEP] {
                if (0.0..=1.0).contains(&u) {
                    probes.push((u, event(u).is_some()));
                }
            }
        }
        if !probes.iter().any(|&(_, s)| s) {
            return Vec::new();
        }
        probes.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Where the event starts or stops between a parameter where it holds and one where it
        // does not.
        let edge_of = |mut inside: f64, mut outside: f64| {
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (inside + outside);
                if event(mid).is_some() {
                    inside = mid;
                } else {
                    outside = mid;
                }
            }
            inside
        };
        let mut runs = Vec::new();
        let mut start = None;
        for k in 0..probes.len() {
            let (u, holds_here) = probes[k];
            match (holds_here, start) {
                (true, None) => {
                    start = Some(if k == 0 {
                        if event(0.0).is_some() {
                            0.0
                        } else {
                            edge_of(u, 0.0)
                        }
                    } else {
                        edge_of(u, probes[k - 1].0)
                    });
                }
                (false, Some(s)) => {
                    runs.push((s, edge_of(probes[k - 1].0, u)));
                    start = None;
                }
                _ => {}
            }
        }
        if let Some(s) = start {
            let last = probes[probes.len() - 1].0;
            let end = if event(1.0).is_some() {
                1.0
            } else {
                edge_of(last, 1.0)
            };
            runs.push((s, end));
        }
        runs.into_iter()
            .filter_map(|(u0, u1)| {
                let (a, b) = (line(u0)?.receiver, line(u1)?.receiver);
                let mut points = vec![a];
                self.subdivide(&line, (u0, a), (u1, b), 0, &mut points);
                (points.len() >= 2).then_some(EeeCurve {
                    points,
                    edges: [source, b1, b2],
                    order: 2,
                })
            })
            .collect()
    }

    /// The curves of two coplanar blocker edges: the lines of their plane through the point where
    /// it cuts the emitter edge, a straight line on the receiver. Its ends are the shadows of the
    /// edges' vertices from that point, so they are placed exactly; trimming then finds where the
    /// lines are unobstructed.
    fn pencil(
        &self,
        source: [DVec3; 2],
        b1: [DVec3; 2],
        b2: [DVec3; 2],
        edges: [(usize, usize); 2],
        faces: [&[DVec3]; 2],
    ) -> Vec<EeeCurve> {
        let Some(n) = plane_normal(b1, b2) else {
            return Vec::new();
        };
        let e = source[1] - source[0];
        let den = n.dot(e);
        if den.abs() <= 1e-12 * e.length() {
            return Vec::new();
        }
        let s = n.dot(b1[0] - source[0]) / den;
        if !(0.0..=1.0).contains(&s) {
            return Vec::new();
        }
        let apex = source[0] + e * s;
        let rf = &self.pair.receiver_frame;
        let h_apex = rf.height(apex);
        if h_apex <= self.pair.tol || self.pair.emitter_frame.height(apex).abs() > self.pair.tol {
            return Vec::new();
        }
        // The receiver's line: where the edges' plane meets the receiver's plane.
        let Some(dir) = n.cross(rf.normal).try_normalize() else {
            return Vec::new();
        };
        let foot = apex - rf.normal * h_apex;
        let across = rf.normal.cross(dir);
        let den = n.dot(across);
        if den.abs() <= 1e-12 {
            return Vec::new();
        }
        let base = foot + across * (n.dot(b1[0] - foot) / den);
        let at = |c: f64| base + dir * c;
        // Cuts: the shadows of the four vertices from the apex, and the far ends.
        let mut cuts = vec![-self.pair.reach, self.pair.reach];
        for v in [b1[0], b1[1], b2[0], b2[1]] {
            let hv = rf.height(v);
            if hv < h_apex {
                let x = apex + (v - apex) * (h_apex / (h_apex - hv));
                cuts.push(dir.dot(x - base).clamp(-self.pair.reach, self.pair.reach));
            }
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let holds = |x: DVec3| {
            self.pair.emitter_frame.height(x) > self.pair.tol
                && self
                    .pencil_line(apex, x, b1, b2)
                    .is_some_and(|l| self.grazes(&l, edges, faces))
        };
        let mut runs: Vec<(f64, f64)> = Vec::new();
        for w in cuts.windows(2) {
            if w[1] - w[0] <= self.pair.tol || !holds(at(0.5 * (w[0] + w[1]))) {
                continue;
            }
            match runs.last_mut() {
                Some(last) if last.1 == w[0] => last.1 = w[1],
                _ => runs.push((w[0], w[1])),
            }
        }
        let mut curves = Vec::new();
        for (c0, c1) in runs {
            for [a, b] in super::clip_to_polygon(rf, self.receiver_polygon, at(c0), at(c1)) {
                let visible =
                    super::trim::runs_where(a, b, self.trim_samples, self.trim_tolerance, |x| {
                        self.pencil_line(apex, x, b1, b2)
                            .is_some_and(|l| self.unobstructed(&l))
                    });
                curves.extend(visible.into_iter().map(|[p, q]| EeeCurve {
                    points: vec![p, q],
                    edges: [source, b1, b2],
                    order: 1,
                }));
            }
        }
        curves
    }

    /// The line from `apex` to the receiver point `x`, if it crosses `b1` and then `b2` (all in
    /// one plane) on its way.
    fn pencil_line(
        &self,
        apex: DVec3,
        x: DVec3,
        b1: [DVec3; 2],
        b2: [DVec3; 2],
    ) -> Option<Transversal> {
        let (l1, m1) = crossing(apex, x, b1)?;
        let (l2, m2) = crossing(apex, x, b2)?;
        let inside = |m: f64| (0.0..=1.0).contains(&m);
        if !(inside(m1) && inside(m2) && 0.0 < l1 && l1 < l2 && l2 < 1.0) {
            return None;
        }
        let second = b2[0].lerp(b2[1], m2);
        // The line must reach the receiver beyond the blocker, not touch it there.
        (self.pair.receiver_frame.height(second) > self.pair.tol).then(|| Transversal {
            source: apex,
            first: b1[0].lerp(b1[1], m1),
            second,
            receiver: x,
        })
    }

    /// Appends the points after `a` of the polyline from `a` to `b` whose chords are within the
    /// tolerance of the arc.
    fn subdivide(
        &self,
        line: &dyn Fn(f64) -> Option<Transversal>,
        a: (f64, DVec3),
        b: (f64, DVec3),
        depth: u32,
        points: &mut Vec<DVec3>,
    ) {
        let um = 0.5 * (a.0 + b.0);
        if let Some(m) = line(um).map(|x| x.receiver) {
            let off = m.distance(closest_point_on_segment(m, a.1, b.1));
            if (off > self.chord_tolerance || depth < 1) && depth < MAX_DEPTH {
                self.subdivide(line, a, (um, m), depth + 1, points);
                self.subdivide(line, (um, m), b, depth + 1, points);
                return;
            }
        }
        if b.1 != *points.last().unwrap_or(&a.1) {
            points.push(b.1);
        }
    }

    /// The line through the point at `u` along `b1` that meets the lines of `source` and `b2`,
    /// if it meets the three segments in the order emitter, `b1`, `b2`, and then the receiver's
    /// plane in front of the emitter.
    fn transversal(
        &self,
        source: [DVec3; 2],
        b1: [DVec3; 2],
        b2: [DVec3; 2],
        u: f64,
    ) -> Option<Transversal> {
        let (first, n) = plane_through(source, b1, u);
        self.transversal_in(source, first, n?, &SecondEdge::new(source, b2))
    }

    /// [`Self::transversal`] through the point `first` of the first blocker edge, with `n` the
    /// unit normal of the plane through it and the emitter edge's line ([`plane_through`]).
    fn transversal_in(
        &self,
        source: [DVec3; 2],
        first: DVec3,
        n: DVec3,
        b2: &SecondEdge,
    ) -> Option<Transversal> {
        let e = source[1] - source[0];
        // The plane through `first` and the emitter edge's line cuts `b2`'s line at `second`.
        let d2 = b2.along;
        let den = n.dot(d2);
        if den.abs() <= b2.flat {
            return None;
        }
        let s = n.dot(b2.to_source) / den;
        if !(0.0..=1.0).contains(&s) {
            return None;
        }
        let second = b2.start + d2 * s;
        let d = second - first;
        if d.length() <= self.pair.tol {
            return None;
        }
        // In that plane the line meets the emitter edge's line.
        let m = d.cross(n);
        let den = m.dot(e);
        if den.abs() <= f64::EPSILON * m.length() * b2.source_length {
            return None;
        }
        let v = m.dot(first - source[0]) / den;
        if !(0.0..=1.0).contains(&v) {
            return None;
        }
        let from = source[0] + e * v;
        // The emitter, then `first`, then `second`, along the line.
        if d.dot(first - from) <= 0.0 {
            return None;
        }
        let rf = &self.pair.receiver_frame;
        let (h, hd) = (rf.height(second), rf.normal.dot(d));
        if !(h > self.pair.tol && hd < 0.0) {
            return None;
        }
        let receiver = second + d * (h / -hd);
        let in_front = self.pair.emitter_frame.height(receiver) > self.pair.tol
            && self.pair.emitter_frame.height(first) > self.pair.tol
            && rf.height(from) > self.pair.tol
            && receiver.distance(from) <= self.pair.reach;
        in_front.then_some(Transversal {
            source: from,
            first,
            second,
            receiver,
        })
    }

    /// Whether the line grazes both blocker edges: their faces stay on one side of the plane
    /// through each edge and the line.
    /// `faces` are the edges' faces ([`Topology::edge_faces`], emitter and receiver excepted).
    fn grazes(&self, x: &Transversal, edges: [(usize, usize); 2], faces: [&[DVec3]; 2]) -> bool {
        let t = self.pair.topology;
        let d = x.receiver - x.source;
        edges.into_iter().zip(faces).all(|((a, b), faces)| {
            let along = t.points[b] - t.points[a];
            along
                .cross(d)
                .try_normalize()
                .is_some_and(|n| t.faces_are_tangent(faces, n))
        })
    }

    /// Whether nothing else crosses the line between the emitter and the receiver.
    fn unobstructed(&self, x: &Transversal) -> bool {
        let v = self.pair.visibility;
        let (e, r) = (self.pair.emitter, self.pair.receiver);
        // The short piece between the blocker edges first: it is the cheapest to follow and
        // the most often blocked (on Sibenik, 64 % of the lines that graze both edges).
        !v.occluded(x.second, x.first, [r, e])
            && !v.occluded(x.receiver, x.second, [r, r])
            && !v.occluded(x.first, x.source, [e, e])
    }
}

/// What [`EeeSearch::transversal_in`] needs of the second blocker edge, the same at every sample.
struct SecondEdge {
    start: DVec3,
    along: DVec3,
    /// Planes through the emitter edge's line closer to parallel to the edge than this (a dot
    /// product of the plane's unit normal with `along`) do not cut it.
    flat: f64,
    /// From the edge's start to the emitter edge's start.
    to_source: DVec3,
    /// The emitter edge's length.
    source_length: f64,
}

impl SecondEdge {
    fn new(source: [DVec3; 2], b2: [DVec3; 2]) -> SecondEdge {
        let along = b2[1] - b2[0];
        SecondEdge {
            start: b2[0],
            along,
            flat: f64::EPSILON * along.length(),
            to_source: source[0] - b2[0],
            source_length: (source[1] - source[0]).length(),
        }
    }
}

/// The point at `u` along the blocker edge `b1`, and the unit normal of the plane through it and
/// the line of the emitter edge `source` (`None` when they are collinear).
fn plane_through(source: [DVec3; 2], b1: [DVec3; 2], u: f64) -> (DVec3, Option<DVec3>) {
    let first = b1[0].lerp(b1[1], u);
    let e = source[1] - source[0];
    (first, e.cross(first - source[0]).try_normalize())
}

/// How far beside a critical parameter (a fraction of the first edge) the event is tried.
const CRITICAL_STEP: f64 = 1e-9;

/// The parameters along the first blocker edge `b1` where the transversal through the emitter
/// edge `source` and the second edge `b2` passes an end of either (the plane through that end
/// and the other edge cuts `b1` there), or lies in a face of `b2` (given as vectors from the edge
/// into each face): where the event can start or stop. Those in `[0, 1]`.
fn critical_parameters(
    source: [DVec3; 2],
    b1: [DVec3; 2],
    b2: [DVec3; 2],
    b2_faces: &[DVec3],
) -> Vec<f64> {
    let d1 = b1[1] - b1[0];
    // Where `b1`'s line cuts the plane through `origin` with normal `n`.
    let cut = |origin: DVec3, n: DVec3| {
        let den = n.dot(d1);
        (den != 0.0).then(|| n.dot(origin - b1[0]) / den)
    };
    let e = source[1] - source[0];
    let d2 = b2[1] - b2[0];
    let through_source_end = source
        .into_iter()
        .filter_map(|a| cut(a, (b2[0] - a).cross(b2[1] - a)));
    let through_b2_end = b2
        .into_iter()
        .filter_map(|b| cut(source[0], e.cross(b - source[0])));
    let in_b2_face = b2_faces.iter().filter_map(|&f| cut(b2[0], d2.cross(f)));
    through_source_end
        .chain(through_b2_end)
        .chain(in_b2_face)
        .filter(|u| (0.0..=1.0).contains(u))
        .collect()
}

/// The sample parameters along a first blocker edge.
fn sample_parameters() -> [f64; SAMPLES] {
    std::array::from_fn(|k| (k as f64 + 0.5) / SAMPLES as f64)
}

/// [`plane_through`] at every sample parameter: shared by all the second edges paired with one
/// first edge.
type SamplePlanes = [(DVec3, Option<DVec3>); SAMPLES];

fn sample_planes(source: [DVec3; 2], b1: [DVec3; 2]) -> SamplePlanes {
    sample_parameters().map(|u| plane_through(source, b1, u))
}

/// Whether, for some point `p` of the emitter edge `source`, segment `b` crosses the plane through
/// `p` and segment `a`: every line from `p` through `a` lies in that plane, so without a crossing no
/// line meets all three. The plane's side of each end of `b` is linear along `source`, so the ends
/// and the roots tell.
fn sweeps_across(source: [DVec3; 2], a: [DVec3; 2], b: [DVec3; 2]) -> bool {
    let d = a[1] - a[0];
    let (n0, n1) = (d.cross(source[0] - a[0]), d.cross(source[1] - source[0]));
    let side = |w: DVec3, s: f64| (n0 + n1 * s).dot(w);
    let (w0, w1) = (b[0] - a[0], b[1] - a[0]);
    let root_inside = |w: DVec3| {
        let (c0, c1) = (n0.dot(w), n1.dot(w));
        c1 != 0.0 && (0.0..=1.0).contains(&(-c0 / c1))
    };
    side(w0, 0.0) * side(w1, 0.0) <= 0.0
        || side(w0, 1.0) * side(w1, 1.0) <= 0.0
        || root_inside(w0)
        || root_inside(w1)
}

/// The unit normal of the plane through segment `a` and a point of segment `b`, from the best
/// conditioned of the cross products (for parallel segments the first is rounding noise).
fn plane_normal(a: [DVec3; 2], b: [DVec3; 2]) -> Option<DVec3> {
    let d = a[1] - a[0];
    [b[1] - b[0], b[0] - a[0], b[1] - a[0]]
        .into_iter()
        .map(|w| {
            let c = d.cross(w);
            (
                c.length() / (d.length() * w.length()).max(f64::MIN_POSITIVE),
                c,
            )
        })
        .max_by(|x, y| x.0.total_cmp(&y.0))
        .and_then(|(_, c)| c.try_normalize())
}

/// Where the line `a -> b` and the line of segment `c` come closest (for coplanar lines, where
/// they cross): the parameters along `a -> b` and along `c`.
fn crossing(a: DVec3, b: DVec3, c: [DVec3; 2]) -> Option<(f64, f64)> {
    let (u, v, w) = (b - a, c[1] - c[0], c[0] - a);
    let (uu, uv, vv, uw, vw) = (u.dot(u), u.dot(v), v.dot(v), u.dot(w), v.dot(w));
    let den = uu * vv - uv * uv;
    if den <= 1e-24 * uu * vv {
        return None;
    }
    Some(((uw * vv - uv * vw) / den, (uv * uw - uu * vw) / den))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transversals_meet_all_three_edges() {
        let scene = penumbra_scenes::builtin::crossed_bars();
        let vis = Visibility::build(&scene);
        let tol = vis.contact_distance();
        let topology = Topology::new(&scene, tol);
        let frame = |s: usize| PlaneFrame::of_polygon(&scene.surfaces[s].polygon).expect("flat");
        let search = EeeSearch {
            pair: PairGeometry {
                topology: &topology,
                visibility: &vis,
                emitter: 0,
                receiver: 3,
                emitter_frame: frame(0),
                receiver_frame: frame(3),
                tol,
                reach: 4.0 * scene.diagonal(),
            },
            chord_tolerance: 1e-6 * scene.diagonal(),
            receiver_polygon: &scene.surfaces[3].polygon,
            trim_samples: 16,
            trim_tolerance: 1e-9 * scene.diagonal(),
            surface_leaves: None,
        };
        let l = &topology.loops[0];
        let emitter_edges: Vec<(usize, usize)> =
            (0..l.len()).map(|k| (l[k], l[(k + 1) % l.len()])).collect();
        let mut edges = BTreeSet::new();
        for s in [1, 2] {
            let l = &topology.loops[s];
            for k in 0..l.len() {
                let (u, w) = (l[k], l[(k + 1) % l.len()]);
                edges.insert((u.min(w), u.max(w)));
            }
        }
        let (curves, count) = search.curves(&emitter_edges, &edges, &[1, 2]);
        assert!(count.events > 0 && !curves.is_empty(), "{count:?}");
        for c in &curves {
            let [e, b1, b2] = c.edges;
            for &x in &c.points {
                assert!(x.z.abs() < 1e-12, "{x} is off the floor");
                // From x: the plane through x and b2's line meets b1's line at q; the line x-q
                // must then meet e's line.
                let n = (b2[1] - b2[0]).cross(x - b2[0]);
                let dir = b1[1] - b1[0];
                let q = b1[0] + dir * (n.dot(b2[0] - b1[0]) / n.dot(dir));
                let c = (q - x).cross(e[1] - e[0]).normalize();
                let gap = (e[0] - x).dot(c).abs();
                assert!(
                    gap < 1e-9,
                    "{x}: the line through the blocker edges misses the emitter edge by {gap:e}"
                );
            }
        }
    }
}
