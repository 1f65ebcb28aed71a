//! Discontinuity meshing, first half: where on each receiver the direct light from each emitter
//! changes its analytic form (Heckbert 1992; Lischinski, Tampieri & Greenberg 1992).
//!
//! For every emitter and receiver, the blockers inside the shaft between them (a BVH box query,
//! then the planes of the convex hull of the two polygons) contribute their silhouette features: EV wedges (emitter edge, blocker vertex) and VE wedges
//! (emitter vertex, blocker edge). Each wedge meets the receiver's plane in a line, clipped to the
//! receiver polygon and trimmed to where its generating rays are unobstructed. Coincident lines
//! (the parallel case) are merged. Blockers touching the receiver add contact (D0) lines. Every
//! segment is classified by what lies on either side: umbra, penumbra or lit.

mod between;
mod contact;
mod eee;
mod horizon;
mod hull;
mod merge;
mod pair;
mod patches;
mod shaft;
mod strength;
mod topology;
mod trim;
mod wedge;

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::{DVec2, DVec3};
use penumbra_scenes::polygon::closest_point_on_segment;
use penumbra_scenes::{PlaneFrame, Scene, SurfaceId, Visibility};
use rayon::prelude::*;
use serde::Serialize;

use crate::progress::{Interrupt, NoProgress, Progress};
use merge::{FlatSegment, merge_collinear};
use shaft::{PairEvents, SearchContext};
pub use wedge::Event;

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
    /// Every boundary, in the order the exports number them.
    pub const ALL: [Boundary; 3] = [Boundary::Umbra, Boundary::Penumbra, Boundary::Inner];

    /// The boundary's name in outputs: `umbra`, `penumbra` or `inner`.
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
    /// The receiver the segment lies on.
    pub surface: SurfaceId,
    /// The emitter whose light changes across it.
    pub emitter: SurfaceId,
    /// One end, on the receiver.
    pub from: DVec3,
    /// The other end.
    pub to: DVec3,
    /// The visual event that makes it.
    pub event: Event,
    /// What it bounds.
    pub boundary: Boundary,
    /// 0: the value jumps; 1: the slope jumps; 2: the curvature jumps.
    pub order: u8,
}

/// Which vertex–edge events discontinuity finding inserts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EventSet {
    /// Every one: an emitter edge with each blocker vertex on the blocker's outline as seen from
    /// the edge, each emitter vertex with each blocker edge on the outline as seen from it, and
    /// each blocker vertex with an edge of another blocker in a plane that cuts the emitter
    /// (events between blockers). The visible area's second derivative jumps across each.
    #[default]
    Complete,
    /// Only EV and VE events whose plane is tangent to both the emitter and the blocker: the
    /// umbra and outer penumbra boundaries.
    Extremal,
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
    /// Which EV and VE events to insert.
    pub events: EventSet,
    /// EEE curves become polylines within this fraction of the receiver's diameter.
    pub eee_tolerance: f64,
    /// Blocker patches (a blocker's connected coplanar faces) that can hide less than this
    /// fraction of an emitter from a receiver start no events there.
    pub event_tolerance: f64,
    /// The area of a typical element of the mesh to come, if known: receivers smaller than
    /// [`MIN_RECEIVER_ELEMENTS`] such elements get no events, and blocker patches whose shadow
    /// is smaller than one element start none.
    pub element_area: Option<f64>,
    /// Keep the lines where an emitter's plane cuts a receiver however close they come to its
    /// edge (meshes refined by bisection, which keep the thin triangles of such a strip thin);
    /// otherwise a line within an element of the edge is left out.
    pub horizons_near_edges: bool,
    /// When to stop starting new emitter–receiver pairs (a run's time budget).
    pub deadline: Option<Instant>,
    /// Stops the search early when set (Ctrl-C).
    pub interrupt: Option<Interrupt>,
    /// The receivers to search, by surface (all when `None`): a sharded run's surfaces. A
    /// receiver's segments do not depend on which others are searched.
    pub receivers: Option<Arc<[bool]>>,
}

impl DiscontinuityOptions {
    fn should_stop(&self) -> bool {
        self.interrupted() || self.deadline.is_some_and(|d| Instant::now() >= d)
    }

    fn interrupted(&self) -> bool {
        self.interrupt.as_ref().is_some_and(Interrupt::is_set)
    }

    /// Whether receiver `r` is searched.
    fn searches(&self, r: SurfaceId) -> bool {
        self.receivers
            .as_ref()
            .is_none_or(|on| on.get(r).copied().unwrap_or(false))
    }
}

/// The default [`DiscontinuityOptions::event_tolerance`]: a hundredth of the emitter.
pub const DEFAULT_EVENT_TOLERANCE: f64 = 0.01;
/// Receivers of fewer elements than this (of [`DiscontinuityOptions::element_area`]) get no
/// events: a constraint would only cut slivers from their one or two triangles.
pub const MIN_RECEIVER_ELEMENTS: f64 = 2.0;
/// Shafts with more blocker edges than this skip the EEE search (tessellated blockers, whose
/// EEE events are many and weak); they are counted.
pub const EEE_MAX_EDGES: usize = 2048;
/// Shafts with more blocker edges than this skip the events between two blockers, for the same
/// reason (a cathedral's shafts paired 200 million vertices and edges); they are counted.
pub const BETWEEN_MAX_EDGES: usize = 512;

impl Default for DiscontinuityOptions {
    fn default() -> Self {
        DiscontinuityOptions {
            trim_samples: 16,
            trim_tolerance: 1e-9,
            eee: true,
            events: EventSet::default(),
            eee_tolerance: 1e-4,
            event_tolerance: DEFAULT_EVENT_TOLERANCE,
            element_area: None,
            horizons_near_edges: false,
            deadline: None,
            interrupt: None,
            receivers: None,
        }
    }
}

/// What discontinuity finding did.
#[derive(Clone, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct DiscontinuityStats {
    /// Emitter–receiver pairs that face each other.
    pub pairs: usize,
    /// Pairs whose shaft holds no blocker: nothing to do for them.
    pub pairs_without_blockers: usize,
    /// Pairs not searched because the time budget ran out or the run was interrupted: their
    /// receivers lack those pairs' events.
    pub pairs_skipped: usize,
    /// Receivers too small for events ([`MIN_RECEIVER_ELEMENTS`]), counted once per emitter.
    pub receivers_too_small: usize,
    /// Blocker surfaces found in shafts, summed over pairs.
    pub blockers_in_shafts: usize,
    /// Of those, surfaces of patches too weak for events (see
    /// [`DiscontinuityOptions::event_tolerance`]), and the largest share
    /// of an emitter such a patch could hide: the most any dropped event changes the light by.
    pub blockers_weak: usize,
    /// See `blockers_weak`.
    pub weak_share_max: f64,
    /// Receivers cut by their emitter's plane within one element of their edge, which get no
    /// line there.
    pub horizons_within_an_element: usize,
    /// Shafts whose EEE search was skipped for their many blocker edges ([`EEE_MAX_EDGES`]).
    pub eee_shafts_skipped: usize,
    /// Shafts whose events between blockers were skipped for the same ([`BETWEEN_MAX_EDGES`]).
    pub between_shafts_skipped: usize,
    /// Feature pairs that could form a wedge (in front of both emitter and receiver), blocker
    /// vertex–blocker edge pairs included.
    pub wedges_considered: usize,
    /// Of those, not events of the set asked for ([`EventSet`]): with `Extremal`, not tangent
    /// to the emitter or the blocker's silhouette; with `Complete`, a blocker feature not on
    /// its outline.
    pub wedges_culled: usize,
    /// Wedges that left a segment on their receiver.
    pub wedges_kept: usize,
    /// Wedge segments shortened or split by trimming, and removed by it entirely.
    pub segments_trimmed: usize,
    /// See `segments_trimmed`.
    pub segments_hidden: usize,
    /// Contact lines where blockers touch receivers (those along a receiver's own edge are
    /// found too, then dropped: they are mesh edges already).
    pub contact_segments: usize,
    /// Emitter edge–blocker edge–blocker edge triples examined for EEE events (after silhouette
    /// and spatial culling), and those that left a curve on their receiver.
    pub eee_considered: usize,
    /// See `eee_considered`.
    pub eee_events: usize,
    /// Segments after merging coincident ones.
    pub segments: usize,
    /// Of those, by event (coincident events of several kinds count as the merged line's): EV.
    pub ev_segments: usize,
    /// VE segments.
    pub ve_segments: usize,
    /// EEE segments.
    pub eee_segments: usize,
    /// Segments of events between two blockers (complete events only).
    pub blocker_ev_segments: usize,
    /// Segments where an emitter's own plane cuts its receiver: only the part of the receiver
    /// in front of the emitter is lit.
    pub horizon_segments: usize,
    /// Contact lines (blockers touching or hovering over receivers).
    pub contact_lines: usize,
    /// The segments by order: where the value jumps (0).
    pub order_0_segments: usize,
    /// Where the slope jumps (1).
    pub order_1_segments: usize,
    /// Where the curvature jumps (2).
    pub order_2_segments: usize,
    /// Wall time of the search in seconds.
    pub seconds: f64,
}

impl DiscontinuityStats {
    /// Counts the merged segments, by event and by order.
    fn count_kinds<'s>(&mut self, segments: impl Iterator<Item = &'s DiscontinuitySegment>) {
        for g in segments {
            self.segments += 1;
            match g.event {
                Event::Ev => self.ev_segments += 1,
                Event::Ve => self.ve_segments += 1,
                Event::Eee => self.eee_segments += 1,
                Event::BlockerEv => self.blocker_ev_segments += 1,
                Event::Horizon => self.horizon_segments += 1,
                Event::Contact => self.contact_lines += 1,
            }
            match g.order {
                0 => self.order_0_segments += 1,
                1 => self.order_1_segments += 1,
                _ => self.order_2_segments += 1,
            }
        }
    }

    /// Adds the counts of another part of the search (times excepted).
    fn add(&mut self, other: &DiscontinuityStats) {
        self.pairs += other.pairs;
        self.pairs_without_blockers += other.pairs_without_blockers;
        self.pairs_skipped += other.pairs_skipped;
        self.receivers_too_small += other.receivers_too_small;
        self.blockers_in_shafts += other.blockers_in_shafts;
        self.blockers_weak += other.blockers_weak;
        self.weak_share_max = self.weak_share_max.max(other.weak_share_max);
        self.eee_shafts_skipped += other.eee_shafts_skipped;
        self.between_shafts_skipped += other.between_shafts_skipped;
        self.horizons_within_an_element += other.horizons_within_an_element;
        self.wedges_considered += other.wedges_considered;
        self.wedges_culled += other.wedges_culled;
        self.wedges_kept += other.wedges_kept;
        self.segments_trimmed += other.segments_trimmed;
        self.segments_hidden += other.segments_hidden;
        self.contact_segments += other.contact_segments;
        self.eee_considered += other.eee_considered;
        self.eee_events += other.eee_events;
        self.segments += other.segments;
    }
}

/// Every receiver's discontinuity segments (indexed by surface), and the figures of the search.
#[derive(Clone, Debug, Default)]
pub struct Discontinuities {
    /// Each surface's segments.
    pub segments: Vec<Vec<DiscontinuitySegment>>,
    /// Per surface, the contact lines cast by faces hovering over it (3D ends and the gap under
    /// the face): values at these lines are taken a few gaps off them. A face hovers when it
    /// is parallel to the receiver and closer than a thousandth of its own size, or when its
    /// foot stands above the receiver by no more than a file's rounding
    /// (`Visibility::meeting_distance`).
    pub hovering: Vec<Vec<(DVec3, DVec3, f64)>>,
    /// What the search did.
    pub stats: DiscontinuityStats,
}

/// Finds the discontinuities of the direct light on every surface of a scene.
pub fn find_discontinuities(
    scene: &Scene,
    visibility: &Visibility,
    options: &DiscontinuityOptions,
) -> Discontinuities {
    find_discontinuities_reporting(scene, visibility, options, &NoProgress)
}

/// [`find_discontinuities`], reporting each emitter–receiver pair done to `progress`. Pairs run
/// in parallel and are collected in order, so the result does not depend on the thread count.
/// Once `options.deadline` passes or `options.interrupt` is set, the pairs not yet started are
/// skipped (counted in [`DiscontinuityStats::pairs_skipped`]); an interrupted search also lets
/// go of the segments it found, without their contact lines and merging (no segments).
pub fn find_discontinuities_reporting(
    scene: &Scene,
    visibility: &Visibility,
    options: &DiscontinuityOptions,
    progress: &dyn Progress,
) -> Discontinuities {
    let started = Instant::now();
    let context = SearchContext::new(scene, visibility, options);
    let mut pairs = context.facing_pairs();
    pairs.retain(|&(_, r)| options.searches(r));
    progress.start("discontinuities", pairs.len() as u64);
    let done = AtomicU64::new(0);
    let found: Vec<Option<PairEvents>> = pairs
        .par_iter()
        .map(|&(e, r)| {
            if options.should_stop() {
                return None;
            }
            let events = context.pair_events(e, r);
            progress.set(done.fetch_add(1, Ordering::Relaxed) + 1);
            Some(events)
        })
        .collect();
    progress.finish();

    let mut stats = DiscontinuityStats::default();
    let mut raw: Vec<Vec<DiscontinuitySegment>> = vec![Vec::new(); scene.surfaces.len()];
    for (events, &(_, r)) in found.into_iter().zip(&pairs) {
        match events {
            Some(events) => {
                stats.add(&events.stats);
                raw[r].extend(events.segments);
            }
            None => stats.pairs_skipped += 1,
        }
    }
    stats.pairs = pairs.len();
    let receivers = scene.surfaces.len();
    if options.interrupted() {
        stats.seconds = started.elapsed().as_secs_f64();
        return Discontinuities {
            segments: vec![Vec::new(); receivers],
            hovering: vec![Vec::new(); receivers],
            stats,
        };
    }

    // Contact lines, for every receiver that something touches.
    let mut hovering = vec![Vec::new(); receivers];
    let emitters: Vec<SurfaceId> = scene.emitters().map(|(e, _)| e).collect();
    let searched = |r: SurfaceId| options.searches(r);
    for (r, contacts) in contact::contact_lines(scene, &context.frames, visibility, &searched) {
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

    let segments: Vec<Vec<DiscontinuitySegment>> = raw
        .into_par_iter()
        .enumerate()
        .map(|(r, list)| match context.frames[r] {
            Some(rf) => merge_and_classify(scene, visibility, &rf, r, list, context.tol),
            None => Vec::new(),
        })
        .collect();
    stats.count_kinds(segments.iter().flatten());
    stats.seconds = started.elapsed().as_secs_f64();
    Discontinuities {
        segments,
        hovering,
        stats,
    }
}

/// A receiver's segments merged where they coincide, those along its own edges dropped (they are
/// edges of every mesh of it already), and each classified.
fn merge_and_classify(
    scene: &Scene,
    visibility: &Visibility,
    rf: &PlaneFrame,
    r: SurfaceId,
    list: Vec<DiscontinuitySegment>,
    tol: f64,
) -> Vec<DiscontinuitySegment> {
    let merged = merge_on_receiver(rf, r, list, tol);
    let boundary: Vec<DVec2> = scene.surfaces[r]
        .polygon
        .iter()
        .map(|&p| rf.to_2d(p))
        .collect();
    merged
        .into_iter()
        .filter(|s| !on_polygon_edge(&boundary, rf.to_2d(s.from), rf.to_2d(s.to), tol))
        .map(|s| DiscontinuitySegment {
            boundary: classify(scene, visibility, rf, &s),
            ..s
        })
        .collect()
}

/// The pieces of segment `p-q` (on the polygon's plane) inside the polygon.
pub(crate) fn clip_to_polygon(
    frame: &PlaneFrame,
    polygon: &[DVec3],
    p: DVec3,
    q: DVec3,
) -> Vec<[DVec3; 2]> {
    let flat: Vec<DVec2> = polygon.iter().map(|&x| frame.to_2d(x)).collect();
    penumbra_scenes::polygon::clip_segment(frame.to_2d(p), frame.to_2d(q), &flat)
        .into_iter()
        .map(|[s, t]| [p.lerp(q, s), p.lerp(q, t)])
        .collect()
}

/// The part of segment `a-b` where `h >= 0` (h linear along it), if any length remains.
pub(crate) fn clip_by_height(a: DVec3, b: DVec3, h: impl Fn(DVec3) -> f64) -> Option<[DVec3; 2]> {
    let (ha, hb) = (h(a), h(b));
    match (ha >= 0.0, hb >= 0.0) {
        (true, true) => Some([a, b]),
        (false, false) => None,
        (true, false) => Some([a, a.lerp(b, ha / (ha - hb))]),
        (false, true) => Some([a.lerp(b, ha / (ha - hb)), b]),
    }
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
    /// Samples spread over emitter `emitter` of `scene`: its centroid, points near its vertices
    /// and edges, and points halfway to its vertices.
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
pub(crate) fn emitter_samples(polygon: &[DVec3]) -> Vec<DVec3> {
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
    let near = |p: DVec2, c: DVec2, d: DVec2| p.distance(closest_point_on_segment(p, c, d)) <= tol;
    (0..n).any(|i| {
        let (c, d) = (polygon[i], polygon[(i + 1) % n]);
        near(a, c, d) && near(b, c, d)
    })
}
