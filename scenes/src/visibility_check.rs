//! The visibility index checked against exhaustive search.
//!
//! [`Visibility::occluded`] and [`Visibility::closest_hit`] walk an f32 BVH to find the triangles
//! worth testing; [`Visibility::occluded_exhaustive`] and [`Visibility::closest_hit_exhaustive`]
//! test every triangle with the same exact f64 test. The two must agree on every query: the walk
//! may test too many triangles, never too few. This module samples queries of the kinds the
//! discontinuity search and the solvers make, where f32 boxes are most likely to lose a triangle:
//! segments from scene vertices (at the corners of the boxes around them), from points just beside
//! vertices (in the boxes' padding), from points on triangles and between points on edges. Shared
//! by the unit tests and the `visibility_leaks` example, which runs it on large scenes.

use glam::DVec3;

use crate::model::SurfaceId;
use crate::rng::SplitMix64;
use crate::visibility::Visibility;

/// Where the endpoints of a sampled segment lie.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ProbeKind {
    /// From a triangle's vertex to a point on another triangle.
    FromVertex,
    /// From a point just beside a triangle's vertex (up to [`NEAR_VERTEX_OFFSET`] away) to a point
    /// on another triangle.
    NearVertex,
    /// Between points on two triangles.
    BetweenTriangles,
    /// Between points on edges of two triangles (as the EEE search tests them).
    BetweenEdges,
}

impl ProbeKind {
    /// Every kind, in the order the `visibility_leaks` example reports them.
    pub const ALL: [ProbeKind; 4] = [
        ProbeKind::FromVertex,
        ProbeKind::NearVertex,
        ProbeKind::BetweenTriangles,
        ProbeKind::BetweenEdges,
    ];
}

/// How far from a vertex [`ProbeKind::NearVertex`] segments start, at most, relative to the
/// scene diagonal; the offset's size is drawn log-uniformly down to a millionth of this.
pub const NEAR_VERTEX_OFFSET: f64 = 1e-3;

/// A sampled segment query: `occluded(from, to, ignore)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSegment {
    /// The segment's start.
    pub from: DVec3,
    /// The segment's end.
    pub to: DVec3,
    /// The surfaces of the two triangles it joins, which the query ignores.
    pub ignore: [SurfaceId; 2],
    /// How the endpoints were drawn.
    pub kind: ProbeKind,
}

/// A segment of `kind` between two random triangles of `visibility` (`None` without triangles).
pub fn sample_segment(
    visibility: &Visibility,
    kind: ProbeKind,
    diagonal: f64,
    rng: &mut SplitMix64,
) -> Option<ProbeSegment> {
    let triangles = visibility.triangles();
    if triangles.is_empty() {
        return None;
    }
    let pick = |rng: &mut SplitMix64| {
        let index = (rng.next_u64() % triangles.len() as u64) as usize;
        &triangles[index]
    };
    let (a, b) = (pick(rng), pick(rng));
    let vertex = |rng: &mut SplitMix64, v: &[DVec3; 3]| v[(rng.next_u64() % 3) as usize];
    let on_triangle = |rng: &mut SplitMix64, v: &[DVec3; 3]| {
        let (mut s, mut t) = (rng.next_f64(), rng.next_f64());
        if s + t > 1.0 {
            (s, t) = (1.0 - s, 1.0 - t);
        }
        v[0] + (v[1] - v[0]) * s + (v[2] - v[0]) * t
    };
    let on_edge = |rng: &mut SplitMix64, v: &[DVec3; 3]| {
        let i = (rng.next_u64() % 3) as usize;
        v[i].lerp(v[(i + 1) % 3], rng.next_f64())
    };
    let (from, to) = match kind {
        ProbeKind::FromVertex => (vertex(rng, &a.vertices), on_triangle(rng, &b.vertices)),
        ProbeKind::NearVertex => {
            let offset = DVec3::new(
                rng.next_f64() - 0.5,
                rng.next_f64() - 0.5,
                rng.next_f64() - 0.5,
            )
            .normalize_or_zero()
                * NEAR_VERTEX_OFFSET
                * diagonal
                * 1e-6f64.powf(rng.next_f64());
            (
                vertex(rng, &a.vertices) + offset,
                on_triangle(rng, &b.vertices),
            )
        }
        ProbeKind::BetweenTriangles => {
            (on_triangle(rng, &a.vertices), on_triangle(rng, &b.vertices))
        }
        ProbeKind::BetweenEdges => (on_edge(rng, &a.vertices), on_edge(rng, &b.vertices)),
    };
    let (from, to) = if rng.next_u64().is_multiple_of(2) {
        (from, to)
    } else {
        (to, from)
    };
    Some(ProbeSegment {
        from,
        to,
        ignore: [a.surface, b.surface],
        kind,
    })
}

/// Whether the index and exhaustive search disagree on `segment`: `Some(true)` when a triangle
/// blocks it that the index misses (a leak), `Some(false)` for the opposite (which would be a
/// bug of a different kind), `None` when they agree.
pub fn occlusion_mismatch(visibility: &Visibility, segment: &ProbeSegment) -> Option<bool> {
    let indexed = visibility.occluded(segment.from, segment.to, segment.ignore);
    let exhaustive = visibility.occluded_exhaustive(segment.from, segment.to, segment.ignore);
    (indexed != exhaustive).then_some(exhaustive)
}

/// Whether [`Visibility::closest_hit`] and [`Visibility::closest_hit_exhaustive`] disagree on the
/// ray from `segment.from` through `segment.to` (unbounded, ignoring the first surface): a
/// different hit parameter, or a hit on one side only.
pub fn closest_hit_mismatch(visibility: &Visibility, segment: &ProbeSegment) -> bool {
    let direction = segment.to - segment.from;
    let ignore = Some(segment.ignore[0]);
    let indexed = visibility.closest_hit(segment.from, direction, 0.0, f64::INFINITY, ignore);
    let exhaustive =
        visibility.closest_hit_exhaustive(segment.from, direction, 0.0, f64::INFINITY, ignore);
    indexed.map(|h| h.t) != exhaustive.map(|h| h.t)
}
