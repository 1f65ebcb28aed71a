//! Discontinuity meshing, first half: where on each receiver the direct light from each emitter
//! changes its analytic form (Heckbert 1992; Lischinski, Tampieri & Greenberg 1992).
//!
//! For every emitter and receiver, the blockers inside the shaft between them (a BVH box query,
//! then the planes of the convex hull of the two polygons) contribute their silhouette features: EV wedges (emitter edge, blocker vertex) and VE wedges
//! (emitter vertex, blocker edge). Each wedge meets the receiver's plane in a line, clipped to the
//! receiver polygon and trimmed to where its generating rays are unobstructed. Coincident lines
//! (the parallel case) are merged. Blockers touching the receiver add contact (D0) lines. Every
//! segment is classified by what lies on either side: umbra, penumbra or lit.

pub mod contact;
pub mod eee;
pub mod hull;
pub mod merge;
pub mod topology;
pub mod trim;
pub mod wedge;

use std::collections::BTreeSet;
use std::time::Instant;

use glam::{DVec2, DVec3};
use penumbra_scenes::{Bounds, PlaneFrame, Scene, SurfaceId, Visibility};
use serde::Serialize;

use merge::{FlatSegment, merge_collinear};
use topology::Topology;
pub use wedge::{Event, Wedge};

/// What a discontinuity line bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Boundary {
    /// One side sees none of the emitter.
    Umbra,
    /// One side sees all of it: the outer edge of the penumbra.
    Penumbra,
    /// Inside the penumbra: both sides see part of the emitter.
    Inner,
}

impl Boundary {
    pub fn name(self) -> &'static str {
        match self {
            Boundary::Umbra => "umbra",
            Boundary::Penumbra => "penumbra",
            Boundary::Inner => "inner",
        }
    }
}

/// A segment on a receiver across which the direct light from `emitter` is not smooth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscontinuitySegment {
    pub surface: SurfaceId,
    pub emitter: SurfaceId,
    pub from: DVec3,
    pub to: DVec3,
    pub event: Event,
    pub boundary: Boundary,
    /// 0: the value jumps; 1: the slope jumps; 2: the curvature jumps.
    pub order: u8,
}

/// Options of discontinuity finding.
#[derive(Clone, Debug, PartialEq)]
pub struct DiscontinuityOptions {
    /// Samples along each wedge segment when trimming it.
    pub trim_samples: usize,
    /// Trim points are located to this fraction of the receiver's diameter.
    pub trim_tolerance: f64,
    /// Whether to find EEE events (emitter edge with two blocker edges).
    pub eee: bool,
    /// EEE curves become polylines within this fraction of the receiver's diameter.
    pub eee_tolerance: f64,
}

impl Default for DiscontinuityOptions {
    fn default() -> Self {
        DiscontinuityOptions {
            trim_samples: 16,
            trim_tolerance: 1e-9,
            eee: true,
            eee_tolerance: 1e-4,
        }
    }
}

/// What discontinuity finding did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DiscontinuityStats {
    /// Emitter–receiver pairs that face each other.
    pub pairs: usize,
    /// Pairs whose shaft holds no blocker: nothing to do for them.
    pub pairs_without_blockers: usize,
    /// Blocker surfaces found in shafts, summed over pairs.
    pub blockers_in_shafts: usize,
    /// Feature pairs that could form a wedge (in front of both emitter and receiver).
    pub wedges_considered: usize,
    /// Of those, not tangent to the emitter or the blocker's silhouette.
    pub wedges_culled: usize,
    /// Wedges that left a segment on their receiver.
    pub wedges_kept: usize,
    /// Wedge segments shortened or split by trimming, and removed by it entirely.
    pub segments_trimmed: usize,
    pub segments_hidden: usize,
    /// Contact lines where blockers touch receivers (those along a receiver's own edge are
    /// found too, then dropped: they are mesh edges already).
    pub contact_segments: usize,
    /// Emitter edge–blocker edge–blocker edge triples examined for EEE events (after silhouette
    /// and spatial culling), and those that left a curve on their receiver.
    pub eee_considered: usize,
    pub eee_events: usize,
    /// Segments after merging coincident ones.
    pub segments: usize,
    pub seconds: f64,
}

/// Every receiver's discontinuity segments (indexed by surface), and the figures of the search.
#[derive(Clone, Debug, Default)]
pub struct Discontinuities {
    pub segments: Vec<Vec<DiscontinuitySegment>>,
    /// Per surface, the contact lines cast by faces hovering over it, with their gaps: values
    /// at these lines are taken a few gaps off them (see [`contact::HOVER`]).
    pub hovering: Vec<Vec<contact::ContactLine>>,
    pub stats: DiscontinuityStats,
}

/// Finds the discontinuities of the direct light on every surface of a scene.
pub fn find_discontinuities(
    scene: &Scene,
    visibility: &Visibility,
    options: &DiscontinuityOptions,
) -> Discontinuities {
    let started = Instant::now();
    let tol = visibility.contact_distance();
    let topology = Topology::new(scene, tol);
    let reach = 4.0 * scene.diagonal();
    let mut stats = DiscontinuityStats::default();
    let mut raw: Vec<Vec<DiscontinuitySegment>> = vec![Vec::new(); scene.surfaces.len()];

    let frames: Vec<Option<PlaneFrame>> = scene
        .surfaces
        .iter()
        .map(|s| PlaneFrame::of_polygon(&s.polygon))
        .collect();

    for (e, emitter) in scene.emitters() {
        let Some(ef) = frames[e] else { continue };
        let e_loop = &topology.loops[e];
        for (r, receiver) in scene.surfaces.iter().enumerate() {
            if r == e {
                continue;
            }
            let Some(rf) = frames[r] else { continue };
            let faces = emitter.polygon.iter().any(|&p| rf.height(p) > tol)
                && receiver.polygon.iter().any(|&p| ef.height(p) > tol);
            if !faces {
                continue;
            }
            stats.pairs += 1;
            // The shaft: the convex hull of emitter and receiver. A blocker must have a vertex in
            // front of both and must not lie wholly beyond one of the hull's faces.
            let mut ends = emitter.polygon.clone();
            ends.extend(&receiver.polygon);
            let shaft = hull::hull_planes(&ends, tol);
            let blockers = shaft_blockers(
                visibility,
                [emitter.bounds(), receiver.bounds()],
                e,
                r,
                |s| {
                    let polygon = &scene.surfaces[s].polygon;
                    polygon
                        .iter()
                        .any(|&p| ef.height(p) > tol && rf.height(p) > tol)
                        && !hull::beyond_a_face(&shaft, polygon, tol)
                },
            );
            if blockers.is_empty() {
                stats.pairs_without_blockers += 1;
                continue;
            }
            stats.blockers_in_shafts += blockers.len();
            let mut vertices = BTreeSet::new();
            let mut edges = BTreeSet::new();
            for &b in &blockers {
                let l = &topology.loops[b];
                for k in 0..l.len() {
                    let (u, w) = (l[k], l[(k + 1) % l.len()]);
                    vertices.insert(u);
                    if u != w {
                        edges.insert((u.min(w), u.max(w)));
                    }
                }
            }
            let not_pair = |s: SurfaceId| s != e && s != r;
            let in_front = |p: DVec3| ef.height(p) > tol && rf.height(p) > tol;
            let mut wedges = Vec::new();
            // EV: each emitter edge with each silhouette vertex.
            for k in 0..e_loop.len() {
                let (ia, ib) = (e_loop[k], e_loop[(k + 1) % e_loop.len()]);
                let Some(source) = clip_segment(topology.points[ia], topology.points[ib], |p| {
                    rf.height(p) - tol
                }) else {
                    continue;
                };
                for &v in &vertices {
                    let pv = topology.points[v];
                    if !in_front(pv) || e_loop.contains(&v) {
                        continue;
                    }
                    let n =
                        (topology.points[ib] - topology.points[ia]).cross(pv - topology.points[ia]);
                    let Some(n) = n.try_normalize() else { continue };
                    stats.wedges_considered += 1;
                    if !topology.vertex_is_tangent(v, n, not_pair) {
                        stats.wedges_culled += 1;
                        continue;
                    }
                    let order = if topology.plane_holds_an_edge_at(v, n, not_pair) {
                        1
                    } else {
                        2
                    };
                    wedges.push(Wedge {
                        emitter: e,
                        event: Event::Ev,
                        source,
                        through: [pv, pv],
                        order,
                    });
                }
            }
            // VE: each emitter vertex with each silhouette edge.
            for &ia in e_loop {
                let pa = topology.points[ia];
                if rf.height(pa) <= tol {
                    continue;
                }
                for &(u, w) in &edges {
                    let Some(through) = clip_segment(topology.points[u], topology.points[w], |p| {
                        (ef.height(p) - tol).min(rf.height(p) - tol)
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
                    if !topology.vertex_is_tangent(ia, n, |s| s == e)
                        || !topology.edge_is_tangent(u, w, n, not_pair)
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
            if options.eee {
                let search = eee::EeeSearch {
                    topology: &topology,
                    visibility,
                    emitter: e,
                    receiver: r,
                    emitter_frame: ef,
                    receiver_frame: rf,
                    tol,
                    reach,
                    chord_tolerance: options.eee_tolerance
                        * penumbra_scenes::polygon::diameter(&receiver.polygon),
                    receiver_polygon: &receiver.polygon,
                    trim_samples: options.trim_samples,
                    trim_tolerance: options.trim_tolerance
                        * penumbra_scenes::polygon::diameter(&receiver.polygon),
                };
                let emitter_edges: Vec<(usize, usize)> = (0..e_loop.len())
                    .map(|k| (e_loop[k], e_loop[(k + 1) % e_loop.len()]))
                    .filter(|(a, b)| a != b)
                    .collect();
                let (curves, count) = search.curves(&emitter_edges, &edges, &blockers);
                stats.eee_considered += count.considered;
                stats.eee_events += count.events;
                for curve in curves {
                    for w in curve.points.windows(2) {
                        for [a, b] in clip_to_polygon(&rf, &receiver.polygon, w[0], w[1]) {
                            raw[r].push(DiscontinuitySegment {
                                surface: r,
                                emitter: e,
                                from: a,
                                to: b,
                                event: Event::Eee,
                                boundary: Boundary::Inner,
                                order: curve.order,
                            });
                        }
                    }
                }
            }
            for wedge in wedges {
                let Some([p, q]) = wedge.meet_plane(rf.origin, rf.normal, reach) else {
                    continue;
                };
                let pieces = clip_to_polygon(&rf, &receiver.polygon, p, q);
                let mut kept = false;
                let trim_tol =
                    options.trim_tolerance * penumbra_scenes::polygon::diameter(&receiver.polygon);
                for [a, b] in pieces {
                    let runs = trim::visible_runs(
                        visibility,
                        &wedge,
                        r,
                        a,
                        b,
                        options.trim_samples,
                        trim_tol,
                    );
                    match runs.as_slice() {
                        [] => stats.segments_hidden += 1,
                        [[x, y]] if x.distance(a) <= trim_tol && y.distance(b) <= trim_tol => {}
                        _ => stats.segments_trimmed += 1,
                    }
                    for [x, y] in runs {
                        kept = true;
                        raw[r].push(DiscontinuitySegment {
                            surface: r,
                            emitter: e,
                            from: x,
                            to: y,
                            event: wedge.event,
                            boundary: Boundary::Inner,
                            order: wedge.order,
                        });
                    }
                }
                stats.wedges_kept += usize::from(kept);
            }
        }
    }

    // Contact lines, for every receiver that something touches.
    let mut hovering = vec![Vec::new(); scene.surfaces.len()];
    let emitters: Vec<SurfaceId> = scene.emitters().map(|(e, _)| e).collect();
    for (r, contacts) in contact::contact_lines(scene, &frames, visibility) {
        stats.contact_segments += contacts.len();
        hovering[r].extend(contacts.iter().copied().filter(|c| c.2 > 0.0));
        for (from, to, _) in contacts {
            for &e in &emitters {
                raw[r].push(DiscontinuitySegment {
                    surface: r,
                    emitter: e,
                    from,
                    to,
                    event: Event::Contact,
                    boundary: Boundary::Umbra,
                    order: 0,
                });
            }
        }
    }

    let mut segments = Vec::with_capacity(raw.len());
    for (r, list) in raw.into_iter().enumerate() {
        let Some(rf) = frames[r] else {
            segments.push(Vec::new());
            continue;
        };
        let merged = merge_on_receiver(&rf, r, list, tol);
        let boundary: Vec<DVec2> = scene.surfaces[r]
            .polygon
            .iter()
            .map(|&p| rf.to_2d(p))
            .collect();
        let classified: Vec<DiscontinuitySegment> = merged
            .into_iter()
            // A line along the receiver's own edge is already an edge of every mesh of it.
            .filter(|s| !on_polygon_edge(&boundary, rf.to_2d(s.from), rf.to_2d(s.to), tol))
            .map(|s| DiscontinuitySegment {
                boundary: classify(scene, visibility, &rf, &s),
                ..s
            })
            .collect();
        stats.segments += classified.len();
        segments.push(classified);
    }
    stats.seconds = started.elapsed().as_secs_f64();
    Discontinuities {
        segments,
        hovering,
        stats,
    }
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

/// The part of segment `a-b` where `h >= 0` (h linear along it), if any length remains.
fn clip_segment(a: DVec3, b: DVec3, h: impl Fn(DVec3) -> f64) -> Option<[DVec3; 2]> {
    let (ha, hb) = (h(a), h(b));
    match (ha >= 0.0, hb >= 0.0) {
        (true, true) => Some([a, b]),
        (false, false) => None,
        (true, false) => Some([a, a.lerp(b, ha / (ha - hb))]),
        (false, true) => Some([a.lerp(b, ha / (ha - hb)), b]),
    }
}

/// The pieces of segment `p-q` (on the polygon's plane) inside the polygon.
pub(crate) fn clip_to_polygon(
    frame: &PlaneFrame,
    polygon: &[DVec3],
    p: DVec3,
    q: DVec3,
) -> Vec<[DVec3; 2]> {
    let flat: Vec<DVec2> = polygon.iter().map(|&x| frame.to_2d(x)).collect();
    crate::planar::clip_segment(frame.to_2d(p), frame.to_2d(q), &flat)
        .into_iter()
        .map(|[s, t]| [p.lerp(q, s), p.lerp(q, t)])
        .collect()
}

/// Merges a receiver's coincident segments (per emitter) in its plane frame. Where segments of
/// different kinds overlap, the most significant description wins: the lowest order, then the
/// first event kind; pieces of one order join.
fn merge_on_receiver(
    frame: &PlaneFrame,
    receiver: SurfaceId,
    list: Vec<DiscontinuitySegment>,
    tol: f64,
) -> Vec<DiscontinuitySegment> {
    let mut by_emitter: std::collections::BTreeMap<SurfaceId, Vec<FlatSegment<(u8, Event)>>> =
        Default::default();
    for s in list {
        by_emitter.entry(s.emitter).or_default().push(FlatSegment {
            from: frame.to_2d(s.from),
            to: frame.to_2d(s.to),
            tag: (s.order, s.event),
        });
    }
    let mut out = Vec::new();
    for (emitter, flat) in by_emitter {
        for m in merge_collinear(&flat, tol, std::cmp::min, |a, b| a.0 == b.0) {
            out.push(DiscontinuitySegment {
                surface: receiver,
                emitter,
                from: frame.to_3d(m.from),
                to: frame.to_3d(m.to),
                event: m.tag.1,
                boundary: Boundary::Inner,
                order: m.tag.0,
            });
        }
    }
    out
}

/// Classifies a segment by probing both sides of its midpoint: how much of the emitter each side
/// sees.
fn classify(
    scene: &Scene,
    visibility: &Visibility,
    frame: &PlaneFrame,
    s: &DiscontinuitySegment,
) -> Boundary {
    let mid = 0.5 * (s.from + s.to);
    let along = (s.to - s.from).normalize_or_zero();
    let across = frame.normal.cross(along);
    let step = 1e3 * visibility.contact_distance();
    let probe = EmitterProbe::new(scene, s.emitter);
    let fraction = |x: DVec3| probe.visible_fraction(visibility, x, frame.normal, s.surface);
    let (a, b) = (fraction(mid + across * step), fraction(mid - across * step));
    if a.min(b) == 0.0 {
        Boundary::Umbra
    } else if a.max(b) == 1.0 {
        Boundary::Penumbra
    } else {
        Boundary::Inner
    }
}

/// Estimates how much of an emitter a point sees, by rays to points spread over the emitter.
#[derive(Clone, Debug)]
pub struct EmitterProbe {
    emitter: SurfaceId,
    normal: DVec3,
    samples: Vec<DVec3>,
}

impl EmitterProbe {
    pub fn new(scene: &Scene, emitter: SurfaceId) -> EmitterProbe {
        let polygon = &scene.surfaces[emitter].polygon;
        EmitterProbe {
            emitter,
            normal: scene.surfaces[emitter].normal(),
            samples: emitter_samples(polygon),
        }
    }

    /// The fraction of the samples in front of the point `x` (on `receiver`, facing `normal`)
    /// that it sees: 0 in umbra (and when none is in front), 1 in full light.
    pub fn visible_fraction(
        &self,
        visibility: &Visibility,
        x: DVec3,
        normal: DVec3,
        receiver: SurfaceId,
    ) -> f64 {
        let usable: Vec<&DVec3> = self
            .samples
            .iter()
            .filter(|&&y| self.normal.dot(x - y) > 0.0 && normal.dot(y - x) > 0.0)
            .collect();
        if usable.is_empty() {
            return 0.0;
        }
        let open = usable
            .iter()
            .filter(|&&&y| !visibility.occluded(x, y, [receiver, self.emitter]))
            .count();
        open as f64 / usable.len() as f64
    }
}

/// Points spread over a polygon: its vertices pulled slightly inward and a few interior points.
fn emitter_samples(polygon: &[DVec3]) -> Vec<DVec3> {
    let c = penumbra_scenes::polygon::centroid(polygon);
    let mut out = vec![c];
    for &p in polygon {
        out.push(c.lerp(p, 0.98));
        out.push(c.lerp(p, 0.5));
    }
    let n = polygon.len();
    for i in 0..n {
        let m = 0.5 * (polygon[i] + polygon[(i + 1) % n]);
        out.push(c.lerp(m, 0.98));
    }
    out
}

/// Whether segment `a-b` lies along one edge of the polygon (within `tol`).
fn on_polygon_edge(polygon: &[DVec2], a: DVec2, b: DVec2, tol: f64) -> bool {
    let n = polygon.len();
    let near = |p: DVec2, c: DVec2, d: DVec2| {
        let e = d - c;
        let t = ((p - c).dot(e) / e.length_squared()).clamp(0.0, 1.0);
        p.distance(c + e * t) <= tol
    };
    (0..n).any(|i| {
        let (c, d) = (polygon[i], polygon[(i + 1) % n]);
        near(a, c, d) && near(b, c, d)
    })
}
